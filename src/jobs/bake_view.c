/* The row view of jobs/bake_view.h: a pool's particles sorted by birth id,
 * each made into a row with its age, size and colour (sim/appearance.h,
 * the one place they are computed), handed to the writer a block at a
 * time. It writes no bytes itself; output/bake.c does. */
#include "jobs/bake_view.h"

#include <errno.h>
#include <stdlib.h>

#include "sim/appearance.h"

/* Rows are sorted by (id, pool index) pairs: qsort has no context argument
 * in C11, so the key travels with the index. */
struct pfx_bake_order {
    uint32_t id, index;
};

static int by_id(const void *a, const void *b) {
    uint32_t x = ((const struct pfx_bake_order *)a)->id, y = ((const struct pfx_bake_order *)b)->id;
    return x < y ? -1 : x > y;
}

/* Pool i's particles by id into v->order. False when out of memory. */
static bool sort_pool(pfx_bake_view *v, const pfx_pool *p) {
    if (p->count > v->order_cap) {
        struct pfx_bake_order *o = realloc(v->order, p->count * sizeof *o);
        if (!o)
            return false;
        v->order = o;
        v->order_cap = p->count;
    }
    bool sorted = true;
    for (uint32_t j = 0; j < p->count; j++) {
        v->order[j] = (struct pfx_bake_order){p->id[j], j};
        sorted &= j == 0 || p->id[j - 1] <= p->id[j];
    }
    /* A pool no death has reordered is in id order already (births take
     * ascending ids at its end): sorting it anyway was most of a bake's
     * time between frames at 1e5 particles. glibc's qsort is a stable
     * merge sort, so equal ids keep pool order either way. */
    if (p->count > 1 && !sorted)
        qsort(v->order, p->count, sizeof *v->order, by_id);
    return true;
}

bool pfx_bake_view_write(pfx_bake_view *v, pfx_bake *b, const pfx_sim *s, long frame, double time) {
    const pfx_effect *e = s->effect;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        const pfx_pool *p = &s->pools[i];
        if (!sort_pool(v, p))
            return pfx_bake_fail(b, ENOMEM);
        size_t n = 0;
        for (uint32_t k = 0; k < p->count; k++) {
            uint32_t j = v->order[k].index;
            pfx_bake_row *row = &v->rows[n++];
            *row = (pfx_bake_row){.frame = frame,
                                  .time = time,
                                  .age = pfx_particle_age(p, j),
                                  .emitter = (uint32_t)i,
                                  .id = p->id[j],
                                  .emitter_name = em->name,
                                  .pos = {p->px[j], p->py[j], p->pz[j]},
                                  .vel = {p->vx[j], p->vy[j], p->vz[j]},
                                  .lifetime = p->lifetime[j],
                                  .size = pfx_particle_size(em, p, j)};
            pfx_particle_color(em, p, j, row->color);
            if (n == PFX_BAKE_VIEW_BLOCK || k + 1 == p->count) {
                if (!pfx_bake_rows(b, v->rows, n))
                    return false;
                n = 0;
            }
        }
    }
    /* A frame with no particles still checks the writer's state. */
    return pfx_bake_rows(b, NULL, 0);
}

void pfx_bake_view_free(pfx_bake_view *v) {
    free(v->order);
    v->order = NULL;
    v->order_cap = 0;
}
