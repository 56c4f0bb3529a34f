/* The fixed-step simulation of pfx_sim.h. Per step and emitter, one pass
 * each: integrate the live particles, remove the dead by swap-remove, then
 * emit the births due in the step at their exact times. It allocates only
 * in pfx_sim_create. Gravity is the only force here: with a constant
 * acceleration the update x += v dt + a dt^2/2, v += a dt is exact. */
#include "sim/sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/hash.h"
#include "base/workers.h"
#include "sim/birth.h"
#include "sim/kill.h"
#include "sim/newborn.h"
#include "sim/pool.h"
#include "sim/sample.h"
#include "sim/schedule.h"
#include "sim/spawn.h"
#include "sim/step.h"

size_t pfx_sim_bytes_per_particle(const pfx_effect *e, size_t i) {
    return pfx_pool_bytes_per_particle(&e->emitters[i]);
}

size_t pfx_sim_scratch_bytes_per_particle(const pfx_effect *e, size_t i) {
    return pfx_pool_scratch_bytes_per_particle(&e->emitters[i]);
}

/* The capacity of e's largest pool. */
static size_t largest_pool(const pfx_effect *e) {
    size_t largest = 0;
    for (size_t i = 0; i < e->emitter_count; i++)
        largest = e->emitters[i].capacity > largest ? e->emitters[i].capacity : largest;
    return largest;
}

/* The threads e's simulation runs on. */
static int sim_threads(const pfx_effect *e) {
    return e->threads > 0 ? e->threads : pfx_workers_cores();
}

uint32_t pfx_sim_block(const pfx_effect *e) {
    const size_t largest = largest_pool(e);
    const int threads = sim_threads(e);
    uint32_t block = PFX_SIM_BLOCK_MAX;
    while (threads > 1 && block > PFX_SIM_BLOCK_MIN && largest / block + 1 < 4 * (size_t)threads)
        block /= 2;
    return block;
}

/* The bytes of the on_hit buffers of blocks of `block` particles. */
static size_t hit_buffer_bytes(const pfx_effect *e, uint32_t block) {
    bool hits = false;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        hits |= em->deflector_count && pfx_spawn_has(em, PFX_SPAWN_HIT);
    }
    return hits ? (largest_pool(e) / block + 1) * sizeof(pfx_hit_buffer) : 0;
}

size_t pfx_sim_hit_buffer_bytes(const pfx_effect *e) {
    return hit_buffer_bytes(e, pfx_sim_block(e));
}

/* Seeds every emitter's streams and schedule: the state at time 0. */
static void init_emitters(pfx_sim *s) {
    const pfx_effect *e = s->effect;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        pfx_emitter_state *st = &s->emitters[i];
        memset(st, 0, sizeof *st);
        uint64_t stream = pfx_rng_stream_for(em->name);
        pfx_rng_seed(&st->rng, e->seed, stream);
        st->rng_base = st->rng;
        st->draws_per_birth = 2 * pfx_birth_units(em); /* two outputs a unit */
        pfx_schedule_init(&st->sched, em, e->seed, stream);
        st->hit_key = pfx_mix64(e->seed ^ stream ^ 0xc011deULL);
        st->spawn_key = pfx_mix64(e->seed ^ stream ^ 0x5ba3ULL);
        st->lives_fixed = !em->kill;
        for (size_t d = 0; d < em->deflector_count; d++)
            st->lives_fixed &= em->deflectors[d].response != PFX_DEFLECT_KILL &&
                               !(em->deflectors[d].lifetime_loss > 0);
    }
}

/* Points every pool's columns into s->storage, one pool after another;
 * every pool is empty after. */
static void lay_out_pools(pfx_sim *s) {
    unsigned char *next = s->storage;
    for (size_t i = 0; i < s->effect->emitter_count; i++) {
        const pfx_emitter *em = &s->effect->emitters[i];
        pfx_pool_layout(&s->pools[i], em, next, em->capacity);
        next += pfx_pool_bytes(em, em->capacity);
    }
}

pfx_sim *pfx_sim_create(const pfx_effect *e, pfx_diags *d) {
    pfx_sim *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->effect = e;
    s->diags = d;
    s->dt = 1.0 / e->sim_rate;
    s->pools = calloc(e->emitter_count + 1, sizeof *s->pools);
    s->emitters = calloc(e->emitter_count + 1, sizeof *s->emitters);
    s->plans = calloc(e->emitter_count + 1, sizeof *s->plans);
    size_t bytes = 0;
    for (size_t i = 0; i < e->emitter_count; i++)
        bytes += pfx_pool_bytes(&e->emitters[i], e->emitters[i].capacity);
    s->block = pfx_sim_block(e);
    const size_t blocks = largest_pool(e) / s->block + 1; /* of the largest pool, at most */
    s->block_flags = calloc(blocks, 1);
    s->block_stats = calloc(blocks, sizeof *s->block_stats);
    s->births = calloc(1, sizeof *s->births);
    /* (of this block size: another count of online processors would
     * make another) */
    const size_t hit_bytes = hit_buffer_bytes(e, s->block);
    s->hit_buffers = hit_bytes ? malloc(hit_bytes) : NULL;
    /* More threads than blocks of the largest pool would only sleep. */
    int threads = sim_threads(e);
    if ((size_t)threads > blocks)
        threads = (int)blocks;
    s->workers = pfx_workers_create(threads);
    s->batch = pfx_birth_batch_create(pfx_workers_count(s->workers), s->births);
    /* One block behind every pool; malloc aligns it for any column. */
    s->storage = malloc(bytes ? bytes : 1);
    if (!s->pools || !s->emitters || !s->plans || !s->storage || !s->block_flags ||
        !s->block_stats || !s->births || (hit_bytes && !s->hit_buffers) || !s->workers ||
        (pfx_workers_count(s->workers) > 1 && !s->batch) || !pfx_spawn_queues_create(s)) {
        pfx_sim_destroy(s);
        return NULL;
    }
    s->bytes = bytes;
    lay_out_pools(s);
    for (size_t i = 0; i < e->emitter_count; i++)
        if (e->emitters[i].motion)
            pfx_motion_plan_init(&s->plans[i], e->emitters[i].motion);
    init_emitters(s);
    return s;
}

void pfx_sim_reset(pfx_sim *s) {
    lay_out_pools(s);
    init_emitters(s);
    s->step = 0;
    s->time = 0;
    s->failed = false;
}

void pfx_sim_destroy(pfx_sim *s) {
    if (!s)
        return;
    free(s->storage);
    free(s->pools);
    free(s->emitters);
    free(s->plans);
    free(s->block_flags);
    free(s->block_stats);
    free(s->births);
    pfx_birth_batch_destroy(s->batch);
    free(s->hit_buffers);
    pfx_workers_destroy(s->workers);
    pfx_spawn_queues_destroy(s);
    pfx_sim_destroy(s->loop_start);
    free(s);
}

/* Advances every emitter from s->time to t1. Per emitter: integrate (the
 * state check sees every particle), deflectors, trails (before deaths, so a
 * particle lays every trail birth of its last step), kill rules, deaths,
 * then the births due, each stepped from its birth time. */
static void advance(pfx_sim *s, double t1) {
    const pfx_effect *e = s->effect;
    const double t0 = s->time;
    const float dt = (float)(t1 - t0);
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        pfx_pool *p = &s->pools[i];
        if (dt > 0) {
            s->emitters[i].particle_steps +=
                (uint64_t)p->count * (em->motion ? em->motion->choice.steps : 1);
            /* Kill rules change lifetimes after the move; without them
             * the move pass finds the deaths, in parallel (the collide
             * pass notes the blocks where a deflector may have killed or
             * shortened a life). */
            const bool scan = !em->kill;
            uint32_t alarm = pfx_step_move(s, i, t0, t1, scan);
            p->time = t1;
            if (alarm < p->count)
                pfx_step_check_state(s, i, alarm, t1);
            if (em->deflector_count)
                pfx_step_collide_moved(s, i, t0, dt);
            if (em->spawn_count && pfx_spawn_has(em, PFX_SPAWN_TRAIL))
                pfx_spawn_trails(s, i, 0, p->count, t0, t1);
            if (em->kill) {
                emitter_pose pose;
                pfx_emitter_pose_at(em, t1, &pose);
                pfx_kill_apply(em->kill, p, pose.position, em->alpha_at_age);
            }
            if (scan)
                pfx_step_kill_flagged(s, i, t1);
            else
                pfx_step_kill_expired(s, i, t1);
        }
        p->time = t1;
        p->newborn = p->count;
        pfx_sim_emit(s, i, t1);
    }
    /* Sub-emitter births after every emitter has moved: file order does not
     * matter. */
    pfx_spawn_process(s, t1);
    /* Particles born in this step met their deflectors (a kill marks them
     * PFX_KILLED) and must meet the kill rules and the state check before
     * anyone sees them. */
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        pfx_pool *p = &s->pools[i];
        pfx_step_check_state(s, i, p->newborn, t1);
        if (p->count <= p->newborn || (!em->kill && !em->deflector_count))
            continue;
        if (em->kill) {
            pfx_pool born = pfx_pool_from(p, p->newborn);
            emitter_pose pose;
            pfx_emitter_pose_at(em, t1, &pose);
            pfx_kill_apply(em->kill, &born, pose.position, em->alpha_at_age);
        }
        pfx_step_kill_expired(s, i, t1);
    }
    s->time = t1;
}

void pfx_sim_step(pfx_sim *s) {
    if (s->failed)
        return;
    s->step++;
    advance(s, (double)s->step / s->effect->sim_rate);
}

void pfx_sim_run_to(pfx_sim *s, double t) {
    const double rate = s->effect->sim_rate;
    /* Compare in steps: (step + 1) <= t * rate, with a tolerance for a time
     * that is a whole number of steps but not exactly representable. */
    while (!s->failed && (double)(s->step + 1) <= t * rate + 1e-7)
        pfx_sim_step(s);
}

void pfx_sim_view_at(const pfx_sim *s, pfx_sim *view, double t) {
    const pfx_effect *e = s->effect;
    for (size_t i = 0; i < e->emitter_count; i++) {
        pfx_pool_copy(&view->pools[i], &s->pools[i]);
        view->emitters[i] = s->emitters[i];
    }
    view->step = s->step;
    view->time = s->time;
    if (t > s->time + 1e-12)
        advance(view, t);
}

double pfx_sim_frame_time(const pfx_effect *e, long frame) {
    /* A looping effect shows one period, from a time when every particle
     * alive belongs to the periodic regime: frame f is frame f mod N, so
     * frame N is frame 0 byte for byte. */
    if (e->loop)
        return e->loop_start + (double)(frame % e->loop_frames) / e->fps;
    return e->prewarm + (double)frame / e->fps;
}

uint64_t pfx_sim_hash(const pfx_sim *s) {
    uint64_t h = PFX_FNV_OFFSET;
    for (size_t i = 0; i < s->effect->emitter_count; i++)
        h = pfx_pool_hash(&s->pools[i], h);
    return h;
}

/* Before s's first step, s and its view trade storage. Frame 0 of an
 * effect with births at time 0 fills the view (a step of length zero),
 * so the view's pages are in memory while s's have never been touched,
 * and the first touch of a page is dear: about 1.1 us a 4 KB page on the
 * 2-core reference machine, 1.4 ms of a 4.6 ms run of 50 steps of 10^5
 * projectiles, spent again on the same births. s's pools are empty before
 * its first step, and the view's contents are this function's scratch,
 * made anew from s whenever it is returned, so nothing else changes. */
static void take_warm_storage(pfx_sim *s, pfx_sim *view) {
    if (s->step != 0 || view->effect != s->effect || view->bytes != s->bytes)
        return;
    void *mine = s->storage;
    s->storage = view->storage;
    view->storage = mine;
    lay_out_pools(s);
    lay_out_pools(view);
}

const pfx_sim *pfx_sim_frame(pfx_sim *s, pfx_sim *view, long frame) {
    double t = pfx_sim_frame_time(s->effect, frame);
    if (t > s->time + 1e-12)
        take_warm_storage(s, view);
    if (t < s->time - 1e-12) {
        /* A looping effect wrapped round: back to frame 0's state (kept when
         * first reached), not to time 0 and its whole warm-up again. */
        if (s->loop_start)
            pfx_sim_view_at(s->loop_start, s, s->loop_start->time);
        else
            pfx_sim_reset(s);
    }
    pfx_sim_run_to(s, t);
    if (s->effect->loop && !s->loop_start && frame % s->effect->loop_frames == 0 &&
        (s->loop_start = pfx_sim_create(s->effect, s->diags)))
        pfx_sim_view_at(s, s->loop_start, s->time);
    if (s->step == 0 && t <= s->time + 1e-12) {
        /* Births at exactly time 0 (a burst at 0) belong to frame 0, but no
         * step has ended there yet: a step of length zero emits them. */
        pfx_sim_view_at(s, view, s->time);
        advance(view, s->time);
        return view;
    }
    if (t <= s->time + 1e-12)
        return s;
    pfx_sim_view_at(s, view, t);
    return view;
}

void pfx_sim_note_dropped(const pfx_sim *s, pfx_diags *d) {
    for (size_t i = 0; i < s->effect->emitter_count; i++)
        if (s->emitters[i].dropped)
            pfx_diag_note(d, 0, 0, 0,
                          "emitter '%s' dropped %llu births: its pool of %u particles was full",
                          s->effect->emitters[i].name, (unsigned long long)s->emitters[i].dropped,
                          s->effect->emitters[i].capacity);
}

void pfx_sim_note_work(const pfx_sim *s, pfx_diags *d) {
    double steps = 0, events = 0;
    for (size_t i = 0; i < s->effect->emitter_count; i++) {
        steps += (double)s->emitters[i].particle_steps;
        events += (double)s->emitters[i].spawn_events;
    }
    if (events > 0)
        pfx_diag_note(d, 0, 0, 0,
                      "simulated %.4g particle-steps and %.4g sub-emitter events in %llu steps",
                      steps, events, (unsigned long long)s->step);
}
