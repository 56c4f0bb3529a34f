/* jobs/motion_next.h: the next frame's state, simulated one frame ahead by
 * a simulation of its own, and each sprite's end found in it by id. It
 * draws nothing (render/motion_vectors.c does) and chooses no scale
 * (jobs/motion_job.c). */
#include "jobs/motion_next.h"

#include <stdlib.h>
#include <string.h>

#include "base/radix.h"
#include "sim/pool.h"
#include "sim/spawn.h"

/* The ahead state's ids sorted, emitter by emitter (an emitter's run
 * starts at the sum of the capacities before it): ids[k] is particle
 * at[k] of the pool. Built by one radix sort per pool a frame, in the
 * sort's scratch sized for the largest pool. */
struct pfx_mv_next {
    const pfx_effect *e;
    pfx_sim *sim, *view;
    const pfx_sim *ahead; /* the next frame's state: sim or view */
    const pfx_sprite_feed *feed;
    size_t *run;                                    /* where emitter i's sorted ids begin */
    uint32_t *ids, *at;                             /* sum of the capacities each */
    uint32_t *key, *idx, *key_tmp, *idx_tmp, *hist; /* the largest capacity */
};

pfx_mv_next *pfx_mv_next_create(const pfx_effect *e, pfx_diags *d) {
    pfx_mv_next *n = calloc(1, sizeof *n);
    size_t total = 0, most = 1;
    for (size_t i = 0; i < e->emitter_count; i++) {
        total += e->emitters[i].capacity;
        most = e->emitters[i].capacity > most ? e->emitters[i].capacity : most;
    }
    bool ok = n != NULL;
    if (ok) {
        n->e = e;
        n->sim = pfx_sim_create(e, d);
        n->view = pfx_sim_create(e, d);
        n->run = malloc((e->emitter_count + 1) * sizeof *n->run);
        n->ids = malloc((total + 1) * sizeof *n->ids);
        n->at = malloc((total + 1) * sizeof *n->at);
        n->key = malloc(most * sizeof *n->key);
        n->idx = malloc(most * sizeof *n->idx);
        n->key_tmp = malloc(most * sizeof *n->key_tmp);
        n->idx_tmp = malloc(most * sizeof *n->idx_tmp);
        n->hist = malloc(pfx_radix_hist_words(most) * sizeof *n->hist);
        ok = n->sim && n->view && n->run && n->ids && n->at && n->key && n->idx && n->key_tmp &&
             n->idx_tmp && n->hist;
    }
    if (!ok) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY,
                       "out of memory for the next frame's %zu particles (motion vectors)", total);
        pfx_mv_next_destroy(n);
        return NULL;
    }
    for (size_t i = 0, at = 0; i <= e->emitter_count; i++) {
        n->run[i] = at;
        at += i < e->emitter_count ? e->emitters[i].capacity : 0;
    }
    return n;
}

double pfx_mv_next_bytes(const pfx_effect *e) {
    double pools = 0, total = 0, most = 1;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        pools += (double)pfx_pool_bytes(em, em->capacity) +
                 (double)pfx_spawn_queue_capacity(e, i) * sizeof(spawn_record);
        total += em->capacity;
        most = em->capacity > most ? em->capacity : most;
    }
    return 2 * pools + 8 * (total + 1) + 16 * most +
           4.0 * (double)pfx_radix_hist_words((size_t)most);
}

void pfx_mv_next_destroy(pfx_mv_next *n) {
    if (!n)
        return;
    pfx_sim_destroy(n->sim);
    pfx_sim_destroy(n->view);
    free(n->run);
    free(n->ids);
    free(n->at);
    free(n->key);
    free(n->idx);
    free(n->key_tmp);
    free(n->idx_tmp);
    free(n->hist);
    free(n);
}

/* Sorts pool i of the ahead state by id into its run. */
static void index_pool(pfx_mv_next *n, size_t i) {
    const pfx_pool *p = &n->ahead->pools[i];
    const size_t count = p->count;
    for (size_t j = 0; j < count; j++) {
        n->key[j] = p->id[j];
        n->idx[j] = (uint32_t)j;
    }
    const uint32_t *at =
        pfx_radix_sort(NULL, n->key, n->idx, n->key_tmp, n->idx_tmp, n->hist, count);
    const uint32_t *ids = at == n->idx ? n->key : n->key_tmp;
    memcpy(n->ids + n->run[i], ids, count * sizeof *ids);
    memcpy(n->at + n->run[i], at, count * sizeof *at);
}

bool pfx_mv_next_frame(pfx_mv_next *n, const pfx_sprite_feed *feed, long f) {
    const pfx_effect *e = n->e;
    const double t = pfx_sim_frame_time(e, f) + 1.0 / e->fps;
    /* Frames come in increasing order but for a looping effect's wrap,
     * where the simulation starts again from time 0: the same steps give
     * the same state whichever frame a job starts at. */
    if (t < n->sim->time - 1e-12)
        pfx_sim_reset(n->sim);
    pfx_sim_run_to(n->sim, t);
    n->ahead = n->sim;
    if (t > n->sim->time + 1e-12) {
        pfx_sim_view_at(n->sim, n->view, t);
        n->ahead = n->view;
    }
    if (n->sim->failed || n->view->failed)
        return false;
    n->feed = feed;
    for (size_t i = 0; i < e->emitter_count; i++)
        if (e->emitters[i].look.draw == PFX_DRAW_SPRITE && e->emitters[i].motion_vectors)
            index_pool(n, i);
    return true;
}

/* Particle `id` in emitter i's sorted run of the ahead state, or -1. */
static long find(const pfx_mv_next *n, size_t i, uint32_t id) {
    size_t lo = n->run[i], hi = lo + n->ahead->pools[i].count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (n->ids[mid] < id)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n->run[i] + n->ahead->pools[i].count && n->ids[lo] == id ? (long)n->at[lo] : -1;
}

static void ends_make(const void *ctx, size_t first, size_t count, float *xyzw) {
    const pfx_mv_next *n = ctx;
    const pfx_sprite_feed *feed = n->feed;
    const float dt = (float)(1.0 / n->e->fps);
    for (size_t k = 0, i = count ? pfx_sprite_feed_emitter(feed, first) : 0; k < count; i++) {
        const pfx_pool *p = &feed->sim->pools[i], *q = &n->ahead->pools[i];
        const bool drawn = n->e->emitters[i].motion_vectors;
        for (size_t m = first + k; m < feed->start[i + 1] && k < count; m++, k++) {
            const size_t j = m - feed->start[i];
            const long a = drawn ? find(n, i, p->id[j]) : -1;
            float *out = xyzw + 4 * k;
            if (a >= 0) {
                out[0] = q->px[a];
                out[1] = q->py[a];
                out[2] = q->pz[a];
            } else {
                out[0] = p->px[j] + p->vx[j] * dt;
                out[1] = p->py[j] + p->vy[j] * dt;
                out[2] = p->pz[j] + p->vz[j] * dt;
            }
            out[3] = drawn ? 1.0f : 0.0f;
        }
    }
}

pfx_sprite_ends pfx_mv_next_ends(const pfx_mv_next *n) { return (pfx_sprite_ends){ends_make, n}; }
