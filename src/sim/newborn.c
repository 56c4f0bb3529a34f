/* Births: every new particle, scheduled or from a sub-emitter event, is
 * drawn, written into its emitter's pool and stepped from its birth time to
 * the end of the step by the emitter's own method (with its deflectors,
 * trail and on_birth events), in blocks of up to 64 taken in birth order:
 * scheduled ones from the emitter's schedule, children from the queues of
 * spawn.c. */
#include "sim/newborn.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/clones.h"
#include "base/workers.h"
#include "sim/birth.h"
#include "sim/schedule.h"
#include "sim/spawn.h"
#include "sim/step.h"

/* The births of a block that are created, moved to its front in order:
 * those younger at t1 than the emitter's longest life and their own. The
 * others were drawn all the same (their draws are the stream's) and are
 * never created. Returns how many are kept. */
static uint32_t keep_alive(const pfx_emitter *em, pfx_birth_block *b, double t1, uint32_t *ids,
                           const pfx_parent **parents) {
    uint32_t keep[PFX_BIRTH_BLOCK], m = 0;
    for (uint32_t k = 0; k < b->n; k++) {
        const double age = t1 - b->t[k];
        if (age < em->max_lifetime && age < b->life[k])
            keep[m++] = k;
    }
    if (m == b->n)
        return m;
    double *cols[] = {b->t,      b->pos[0], b->pos[1], b->pos[2], b->vel[0], b->vel[1],
                      b->vel[2], b->life,   b->s0,     b->s1,     b->gs,     b->q,
                      b->mass,   b->tint,   b->angle,  b->spin};
    for (size_t c = 0; c < sizeof cols / sizeof *cols; c++)
        for (uint32_t r = 0; r < m; r++)
            cols[c][r] = cols[c][keep[r]];
    for (uint32_t r = 0; r < m; r++) {
        ids[r] = ids[keep[r]];
        if (parents)
            parents[r] = parents[keep[r]];
    }
    return b->n = m;
}

/* col[r] = x[r] rounded to float, r < m: one column of a block into its
 * pool. */
PFX_CLONES
static void put_floats(float *restrict col, const double *restrict x, uint32_t m) {
    for (uint32_t r = 0; r < m; r++)
        col[r] = (float)x[r];
}

PFX_CLONES
static void put_bytes(uint8_t *restrict col, uint8_t v, uint32_t m) {
    for (uint32_t r = 0; r < m; r++)
        col[r] = v;
}

/* Writes the block's births (all kept) into rows j0.. of pool p, column by
 * column: only the columns the pool has (the emitter's features decide
 * which); what a parent passes on (colour, size, generation, id) comes from
 * its parent, else the defaults. ids: the particles' birth numbers. */
static void write_newborns(pfx_pool *p, uint32_t j0, const pfx_birth_block *b, const uint32_t *ids,
                           const pfx_parent *const *parents) {
    const uint32_t m = b->n;
    put_floats(p->px + j0, b->pos[0], m), put_floats(p->py + j0, b->pos[1], m);
    put_floats(p->pz + j0, b->pos[2], m);
    put_floats(p->vx + j0, b->vel[0], m), put_floats(p->vy + j0, b->vel[1], m);
    put_floats(p->vz + j0, b->vel[2], m);
    if (p->ax) /* its partial step keeps none: the first full step evaluates it */
        for (uint32_t r = 0; r < m; r++)
            p->ax[j0 + r] = NAN;
    if (p->rest) /* awake: its first full step is swept */
        put_bytes(p->rest + j0, 0, m);
    memcpy(p->birth + j0, b->t, m * sizeof *b->t);
    put_floats(p->lifetime + j0, b->life, m);
    memcpy(p->id + j0, ids, m * sizeof *ids);
    if (p->gravity_scale)
        put_floats(p->gravity_scale + j0, b->gs, m);
    if (p->size0)
        put_floats(p->size0 + j0, b->s0, m);
    if (p->size1)
        put_floats(p->size1 + j0, b->s1, m);
    if (p->charge)
        put_floats(p->charge + j0, b->q, m);
    if (p->mass)
        put_floats(p->mass + j0, b->mass, m);
    if (p->bx) {
        put_floats(p->bx + j0, b->pos[0], m), put_floats(p->by + j0, b->pos[1], m);
        put_floats(p->bz + j0, b->pos[2], m);
    }
    if (p->stuck)
        put_bytes(p->stuck + j0, 0, m);
    if (p->hits)
        memset(p->hits + j0, 0, m * sizeof *p->hits);
    if (p->tint)
        put_floats(p->tint + j0, b->tint, m);
    if (p->angle0)
        put_floats(p->angle0 + j0, b->angle, m);
    if (p->spin)
        put_floats(p->spin + j0, b->spin, m);
    for (uint32_t r = 0; r < m; r++) {
        const uint32_t j = j0 + r;
        const pfx_parent *parent = parents ? parents[r] : NULL;
        if (p->generation)
            p->generation[j] = parent ? parent->generation + 1 : 0;
        if (p->pr) {
            bool inherit = parent && parent->inherit_color;
            p->pr[j] = inherit ? parent->color[0] : 1;
            p->pg[j] = inherit ? parent->color[1] : 1;
            p->pb[j] = inherit ? parent->color[2] : 1;
        }
        if (p->size_scale)
            p->size_scale[j] = parent && parent->inherit_size ? parent->size : 1;
        if (p->parent_id)
            p->parent_id[j] = parent ? parent->id : UINT32_MAX;
    }
}

/* c ? a : b by the bits: a select the compiler cannot turn back into a
 * branch around the arithmetic that makes a (with -ftrapping-math it
 * would not if-convert that arithmetic, and the loop would not vectorise). */
static inline float pick(bool c, float a, float b) {
    uint32_t x, y;
    memcpy(&x, &a, sizeof x);
    memcpy(&y, &b, sizeof y);
    const uint32_t m = (uint32_t)0 - (uint32_t)c;
    x = (x & m) | (y & ~m);
    memcpy(&a, &x, sizeof a);
    return a;
}

/* One axis of newborns under gravity alone, each over its own age t1 -
 * t[r] when positive: the constant-acceleration closed form, in double,
 * from the stored floats (age 0 keeps them as they are: x + 0 would turn
 * -0 into +0). */
PFX_CLONES
static void gravity_newborns(float *restrict x, float *restrict v, const double *restrict t,
                             const double *restrict gs, double accel, double t1, uint32_t m) {
    for (uint32_t r = 0; r < m; r++) {
        const double age = t1 - t[r], acc = accel * gs[r], x0 = x[r], u0 = v[r];
        const float xn = (float)(x0 + u0 * age + 0.5 * acc * age * age);
        const float vn = (float)(u0 + acc * age);
        x[r] = pick(age > 0, xn, x[r]);
        v[r] = pick(age > 0, vn, v[r]);
    }
}

/* The rest of the step after the birth for rows j0.., by the emitter's own
 * method: the state stored at birth is stepped over its age exactly as a
 * particle started alone at its birth would be (the same scheme, substeps
 * no longer than the full step's, operators included), newborns of one
 * birth time together. Gravity alone is the constant-acceleration closed
 * form. The start state is saved first for the collide pass, which sweeps
 * this partial step like a full one. */
static void advance_newborns(pfx_sim *s, size_t i, uint32_t j0, const pfx_birth_block *b,
                             double t1) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_pool *p = &s->pools[i];
    const uint32_t m = b->n;
    if (em->deflector_count) {
        const size_t bytes = m * sizeof(float);
        memcpy(p->start_px + j0, p->px + j0, bytes), memcpy(p->start_py + j0, p->py + j0, bytes);
        memcpy(p->start_pz + j0, p->pz + j0, bytes), memcpy(p->start_vx + j0, p->vx + j0, bytes);
        memcpy(p->start_vy + j0, p->vy + j0, bytes), memcpy(p->start_vz + j0, p->vz + j0, bytes);
    }
    if (!em->motion) {
        float *x[3] = {p->px, p->py, p->pz}, *v[3] = {p->vx, p->vy, p->vz};
        for (int a = 0; a < 3; a++)
            gravity_newborns(x[a] + j0, v[a] + j0, b->t, b->gs, em->accel[a], t1, m);
        return;
    }
    for (uint32_t r0 = 0, r1; r0 < m; r0 = r1) {
        for (r1 = r0 + 1; r1 < m && b->t[r1] == b->t[r0];)
            r1++;
        const double age = t1 - b->t[r0];
        if (age > 0) {
            pfx_motion_pool_f run = pfx_step_motion_view(p, j0 + r0, r1 - r0);
            pfx_motion_advance_f(&s->plans[i], &run, b->t[r0], age);
        }
    }
}

/* Whether every newborn of block b, at rows j0.. of p under gravity
 * `accel` times its scale, is far inside the state check's bounds
 * (pfx_step_far_inside): then none may run away, and only a block where
 * some is not asks pfx_step_may_run_away of each. */
PFX_CLONES
static bool far_inside(const pfx_pool *p, uint32_t j0, const pfx_birth_block *restrict b,
                       const double accel[3]) {
    const float *restrict px = p->px + j0, *restrict py = p->py + j0, *restrict pz = p->pz + j0;
    const float *restrict vx = p->vx + j0, *restrict vy = p->vy + j0, *restrict vz = p->vz + j0;
    const double ax = accel[0], ay = accel[1], az = accel[2];
    int all = 1;
    for (uint32_t r = 0; r < b->n; r++) {
        const float x[3] = {px[r], py[r], pz[r]}, v[3] = {vx[r], vy[r], vz[r]};
        const double gs = b->gs[r], a[3] = {ax * gs, ay * gs, az * gs};
        all &= pfx_step_far_inside(x, v, a, b->life[r]);
    }
    return all;
}

/* Whether some newborn of block b, at rows j0.. of p, could trip the
 * state check (gravity alone; pfx_step_may_run_away of each where the
 * block is not far inside). */
static bool newborns_may_run_away(const pfx_emitter *em, const pfx_pool *p, uint32_t j0,
                                  const pfx_birth_block *b) {
    if (far_inside(p, j0, b, em->accel))
        return false;
    for (uint32_t r = 0; r < b->n; r++) {
        const uint32_t j = j0 + r;
        const float x[3] = {p->px[j], p->py[j], p->pz[j]}, v[3] = {p->vx[j], p->vy[j], p->vz[j]};
        const double a[3] = {em->accel[0] * b->gs[r], em->accel[1] * b->gs[r],
                             em->accel[2] * b->gs[r]};
        if (pfx_step_may_run_away(x, v, a, b->life[r]))
            return true;
    }
    return false;
}

/* The deflector sweep of block b's newborns at rows j0.. (an emitter that
 * raises no events: nothing can come between two of them), in runs of one
 * birth time, counted in *stats. */
static void collide_newborns(pfx_sim *s, size_t i, uint32_t j0, const pfx_birth_block *b, double t1,
                             pfx_collide_stats *stats) {
    for (uint32_t r0 = 0, r1; r0 < b->n; r0 = r1) {
        for (r1 = r0 + 1; r1 < b->n && b->t[r1] == b->t[r0];)
            r1++;
        const double age = t1 - b->t[r0];
        if (age > 0)
            pfx_step_collide(s, i, j0 + r0, r1 - r0, b->t[r0], age, stats);
    }
}

/* What block b's newborns at rows j0.. of p add to the pool's summaries:
 * *floor lowered to their earliest death as the death scan reads it
 * (birth time plus the lifetime stored as a float: pfx_pool.death_floor),
 * and *run_away raised where one may run away (asked while it is not). */
static void note_newborns(const pfx_emitter *em, const pfx_pool *p, uint32_t j0,
                          const pfx_birth_block *b, double *floor, bool *run_away) {
    for (uint32_t r = 0; r < b->n; r++) {
        const double death = b->t[r] + (double)(float)b->life[r];
        *floor = death < *floor ? death : *floor;
    }
    if (!em->motion && !*run_away)
        *run_away = newborns_may_run_away(em, p, j0, b);
}

/* The part of a block's creation that reads nothing of other blocks: its
 * draws (b->u set), the births kept, written at rows j0.. of emitter i's
 * pool and stepped to t1. Returns how many were kept. */
static uint32_t draw_and_write(pfx_sim *s, size_t i, uint32_t j0, double t1, pfx_birth_block *b,
                               uint32_t *ids, const pfx_parent **parents) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_pool *p = &s->pools[i];
    pfx_birth_draw_block(em, b);
    if (parents)
        for (uint32_t k = 0; k < b->n; k++)
            if (parents[k]->inherit_velocity)
                for (int a = 0; a < 3; a++)
                    b->vel[a][k] += parents[k]->vel[a];
    const uint32_t m = keep_alive(em, b, t1, ids, parents);
    assert(j0 + m <= p->capacity);
    write_newborns(p, j0, b, ids, parents);
    advance_newborns(s, i, j0, b, t1);
    return m;
}

/* Creates the births of block b (times, units and, for children, their
 * parents' places and normals set) in emitter i's pool, which has room
 * for all of them, and steps them to t1: the draws, the partial step, the
 * runaway bound, the deflector sweep, trails and on_birth events. ids:
 * the particles' ids; parents: each child's parent, or NULL for scheduled
 * births. Births already dead at t1 are drawn and not created. */
static void make_particles(pfx_sim *s, size_t i, double t1, pfx_birth_block *b, uint32_t *ids,
                           const pfx_parent **parents) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_pool *p = &s->pools[i];
    s->emitters[i].born += b->n;
    const uint32_t j0 = p->count, m = draw_and_write(s, i, j0, t1, b, ids, parents);
    p->count += m;
    note_newborns(em, p, j0, b, &p->death_floor, &p->may_run_away);
    const bool trails = em->spawn_count && pfx_spawn_has(em, PFX_SPAWN_TRAIL);
    if (!em->spawn_count) {
        if (em->deflector_count)
            collide_newborns(s, i, j0, b, t1, &s->emitters[i].collisions);
        return;
    }
    /* Events are queued in birth order, each newborn's hits, trail and
     * birth in turn, as they would be one by one. */
    for (uint32_t r = 0; r < m; r++) {
        const uint32_t j = j0 + r;
        const double tb = b->t[r], age = t1 - tb;
        if (age > 0) {
            if (em->deflector_count)
                pfx_step_collide(s, i, j, 1, tb, age, &s->emitters[i].collisions);
            if (trails)
                pfx_spawn_trails(s, i, j, 1, tb, t1);
        }
        const double pos[3] = {b->pos[0][r], b->pos[1][r], b->pos[2][r]};
        const double v0[3] = {b->vel[0][r], b->vel[1][r], b->vel[2][r]};
        pfx_spawn_event_of(s, i, PFX_SPAWN_BIRTH, j, tb, pos, v0, NULL);
    }
}

/* Every unit of block b's births from the emitter's stream, birth after
 * birth: draws_per_birth outputs each, as one at a time would take them,
 * drawn in one run and dealt into their columns. */
static void draw_units(const pfx_emitter *em, pfx_rng *r, pfx_birth_block *b) {
    const unsigned units = pfx_birth_units(em);
    pfx_rng_units(r, b->drawn, (size_t)b->n * units);
    for (uint32_t k = 0; k < b->n; k++)
        for (unsigned d = 0; d < units; d++)
            b->u[d][k] = b->drawn[k * units + d];
}

/* A looping effect draws the same values in every period: at a period's
 * first birth the attribute stream starts over. */
static void repeat_draws(pfx_sim *s, size_t i) {
    pfx_emitter_state *st = &s->emitters[i];
    if (s->effect->loop && st->sched.period != st->rng_period) {
        st->rng = st->rng_base;
        st->rng_period = st->sched.period;
    }
}

/* ---- Scheduled births on every thread ----
 * A burst of 10^5 births was one thread's work (0.85 ms with the pool's
 * pages in memory, 0.68 on two threads) in a step whose motion takes both
 * threads. A block's creation reads nothing of another block's but its
 * place in the pool and its place in the stream, so where both are known
 * before its draws, blocks go to the threads in batches: the births are
 * taken from the schedule as one thread would take them (the same blocks:
 * each takes a whole PFX_BIRTH_BLOCK while the pool has room for one more
 * past the batch), each block notes the stream where its draws begin and
 * the stream jumps past them, and each lands right after the one before,
 * which holds when none is dead at t1 (none older than half the shortest
 * life the emitter draws). Only for an emitter that raises no events (an
 * event's place in its queue is its birth's turn) and, like everything
 * the threads run, with no result depending on which thread made what:
 * the runaway bound is an or, the collision counters sums, the death
 * floor a least. */
enum { BATCH_BLOCKS = 16 }; /* at most 1024 births a batch */

typedef struct batch_block {
    uint32_t n, first; /* births, and the first's place among the batch's */
    uint32_t id;       /* the first's id */
    pfx_rng rng;       /* the stream at its first draw */
} batch_block;

typedef struct birth_task {
    pfx_birth_block *block; /* its working columns: the sim's own for task 0 */
    pfx_collide_stats collisions;
    bool may_run_away;
    double first_death;
} birth_task;

struct pfx_birth_batch {
    uint32_t blocks, births, j0; /* taken so far, and where the first lands */
    batch_block block[BATCH_BLOCKS];
    double t[BATCH_BLOCKS * PFX_BIRTH_BLOCK];
    /* Per job: each task a run of blocks, one a thread, so that a thread
     * has one set of working columns (a page touched for the first time
     * costs a microsecond; 4 a thread put 0.1 ms on a burst of 10^4). */
    uint32_t tasks;
    birth_task task[];
};

/* The tasks of a batch on `threads` threads. */
static uint32_t batch_tasks(int threads) {
    return threads < BATCH_BLOCKS ? (uint32_t)threads : BATCH_BLOCKS;
}

pfx_birth_batch *pfx_birth_batch_create(int threads, pfx_birth_block *own) {
    if (threads <= 1)
        return NULL;
    const uint32_t tasks = batch_tasks(threads);
    pfx_birth_batch *batch = calloc(1, sizeof *batch + tasks * sizeof *batch->task);
    if (!batch)
        return NULL;
    batch->tasks = tasks;
    batch->task[0].block = own;
    for (uint32_t k = 1; k < tasks; k++)
        if (!(batch->task[k].block = calloc(1, sizeof *batch->task[k].block))) {
            pfx_birth_batch_destroy(batch);
            return NULL;
        }
    return batch;
}

void pfx_birth_batch_destroy(pfx_birth_batch *batch) {
    if (!batch)
        return;
    for (uint32_t k = 1; k < batch->tasks; k++)
        free(batch->task[k].block);
    free(batch);
}

typedef struct batch_job {
    pfx_sim *s;
    size_t emitter;
    double t1;
    uint32_t per_task; /* blocks a task takes */
    bool may_run_away; /* the pool's, before the batch */
} batch_job;

static void birth_task_run(void *arg, size_t k) {
    const batch_job *job = arg;
    pfx_sim *s = job->s;
    const size_t i = job->emitter;
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_birth_batch *batch = s->batch;
    birth_task *task = &batch->task[k];
    pfx_birth_block *b = task->block;
    task->collisions = (pfx_collide_stats){0};
    task->may_run_away = job->may_run_away; /* (then no block asks) */
    task->first_death = INFINITY;
    const uint32_t end = (uint32_t)(k + 1) * job->per_task;
    for (uint32_t q = (uint32_t)k * job->per_task; q < end && q < batch->blocks; q++) {
        const batch_block *bq = &batch->block[q];
        b->n = bq->n;
        b->placed = false;
        memcpy(b->t, batch->t + bq->first, bq->n * sizeof *b->t);
        pfx_rng rng = bq->rng;
        draw_units(em, &rng, b);
        uint32_t ids[PFX_BIRTH_BLOCK];
        for (uint32_t r = 0; r < bq->n; r++)
            ids[r] = bq->id + r;
        const uint32_t j0 = batch->j0 + bq->first;
        const uint32_t m = draw_and_write(s, i, j0, job->t1, b, ids, NULL);
        assert(m == bq->n);
        (void)m;
        note_newborns(em, &s->pools[i], j0, b, &task->first_death, &task->may_run_away);
        if (em->deflector_count)
            collide_newborns(s, i, j0, b, job->t1, &task->collisions);
    }
}

/* Creates the batch's births on the threads (none if it is empty). */
static void flush_batch(pfx_sim *s, size_t i, double t1) {
    pfx_birth_batch *batch = s->batch;
    if (!batch->blocks)
        return;
    pfx_pool *p = &s->pools[i];
    const uint32_t tasks = batch->blocks < batch->tasks ? batch->blocks : batch->tasks;
    batch_job job = {s, i, t1, (batch->blocks + tasks - 1) / tasks, p->may_run_away};
    batch->j0 = p->count;
    p->count += batch->births;
    pfx_workers_run(s->workers, tasks, birth_task_run, &job);
    for (uint32_t k = 0; k < tasks; k++) {
        pfx_collide_stats_add(&s->emitters[i].collisions, &batch->task[k].collisions);
        p->may_run_away |= batch->task[k].may_run_away;
        const double death = batch->task[k].first_death;
        p->death_floor = death < p->death_floor ? death : p->death_floor;
    }
    batch->blocks = batch->births = 0;
}

/* The age below which every birth of em is alive: half its shortest life
 * (0, none, where that is not positive). */
static double surely_alive(const pfx_emitter *em) {
    const double shortest = fmin(pfx_value_min(&em->lifetime), em->max_lifetime);
    return shortest > 0 ? 0.5 * shortest : 0;
}

/* Takes the block of births at `t` into the batch, noting its stream and
 * jumping the stream past its draws, if every one of them is alive at t1;
 * whether it did. */
static bool batch_block_taken(pfx_sim *s, size_t i, double t1, const double *t, uint32_t n) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_emitter_state *st = &s->emitters[i];
    pfx_birth_batch *batch = s->batch;
    double oldest = t[0];
    for (uint32_t k = 1; k < n; k++)
        oldest = t[k] < oldest ? t[k] : oldest;
    if (!(t1 - oldest < surely_alive(em)))
        return false;
    batch->block[batch->blocks++] = (batch_block){
        .n = n, .first = batch->births, .id = (uint32_t)st->scheduled, .rng = st->rng};
    batch->births += n;
    st->scheduled += n;
    st->born += n;
    pfx_rng_advance(&st->rng, n * st->draws_per_birth);
    if (batch->blocks == BATCH_BLOCKS)
        flush_batch(s, i, t1);
    return true;
}

/* Emits the scheduled births due up to t1. Births that cannot be alive at
 * t1 (older than the maximum lifetime) are skipped in closed form where the
 * rate allows and their draws jumped over, so a step's cost is bounded by
 * the births due in it, whatever they are. */
void pfx_sim_emit(pfx_sim *s, size_t i, double t1) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_emitter_state *st = &s->emitters[i];
    const pfx_pool *p = &s->pools[i];
    pfx_birth_batch *batch = s->batch && !em->spawn_count ? s->batch : NULL;
    for (;;) {
        repeat_draws(s, i);
        /* The batch's births count as in the pool; it stays open only
         * while the pool has room for a whole block past it, so that
         * what follows reads the pool as one thread would find it. */
        if (batch && p->capacity - p->count - batch->births < PFX_BIRTH_BLOCK)
            flush_batch(s, i, t1);
        /* Births at least a maximum lifetime old are dead at t1, and when
         * the pool is full none of the step's births can be kept: both are
         * passed over in bulk (bursts whole, rates in closed form), their
         * draws jumped, so no rate or burst size can make a step slow. */
        uint64_t n = pfx_schedule_drop_until(&st->sched, em, t1 - em->max_lifetime);
        if (!n && p->count == p->capacity) {
            n = pfx_schedule_drop_until(&st->sched, em, t1);
            st->dropped += n;
        }
        if (n) {
            pfx_rng_advance(&st->rng, n * st->draws_per_birth);
            st->born += n;
            st->scheduled += n;
            continue;
        }
        /* A block of the births due: no more than the pool has room for
         * (so none finds it full) and none past the end of a loop period
         * (the next one's draws start over). */
        pfx_birth_block *b = s->births;
        const uint32_t room = p->capacity - p->count - (batch ? batch->births : 0);
        const bool batched = batch && room >= PFX_BIRTH_BLOCK;
        double *t = batched ? batch->t + batch->births : b->t;
        const uint32_t n_due = pfx_schedule_take(
            &st->sched, em, t1, room < PFX_BIRTH_BLOCK ? room : PFX_BIRTH_BLOCK, t);
        if (!n_due)
            break;
        if (batched) {
            if (batch_block_taken(s, i, t1, t, n_due))
                continue;
            /* made alone, after the batch (whose first task works in b) */
            flush_batch(s, i, t1);
            memcpy(b->t, t, n_due * sizeof *t);
        }
        b->n = n_due;
        b->placed = false;
        uint32_t ids[PFX_BIRTH_BLOCK];
        for (uint32_t k = 0; k < b->n; k++)
            ids[k] = (uint32_t)st->scheduled++;
        draw_units(em, &st->rng, b);
        make_particles(s, i, t1, b, ids, NULL);
    }
    if (batch)
        flush_batch(s, i, t1);
}

/* Children a full pool cannot keep: counted (their ids and draws are their
 * events' own, so no stream moves). */
static void drop_births(pfx_emitter_state *st, uint64_t n) {
    st->dropped += n;
    st->born += n;
}

/* A block of sub-emitter children being gathered: each one's parent and
 * id beside the block. */
typedef struct children {
    pfx_birth_block *b;
    const pfx_parent *parents[PFX_BIRTH_BLOCK];
    uint32_t ids[PFX_BIRTH_BLOCK];
} children;

/* Adds child `child` of the event `parent` raised at time t to the block:
 * its id and draws from the event's key (spawn.h), so that it is the same
 * child at any sim.rate, whatever order the step's events come in, and the
 * scheduled births' ids and draws never depend on how many children came
 * between them. */
static void add_child(const pfx_emitter *em, children *kids, const pfx_parent *parent,
                      uint32_t child, double t) {
    pfx_birth_block *b = kids->b;
    const uint32_t k = b->n++;
    kids->parents[k] = parent;
    kids->ids[k] = pfx_child_id(parent->key, child);
    b->t[k] = t;
    for (int a = 0; a < 3; a++) {
        b->place[a][k] = parent->pos[a];
        b->hit_normal[a][k] = parent->normal[a];
    }
    b->has_normal[k] = parent->has_normal;
    pfx_rng rng;
    pfx_rng_seed(&rng, pfx_mix64(parent->key ^ ((uint64_t)child << 32)), 0xc41dULL);
    const unsigned units = pfx_birth_units(em);
    for (unsigned d = 0; d < units; d++)
        b->u[d][k] = pfx_rng_unit(&rng);
}

/* Makes the children gathered so far (none: nothing) and empties the
 * block. */
static void make_children(pfx_sim *s, size_t i, double t1, children *kids) {
    if (!kids->b->n)
        return;
    kids->b->placed = true;
    make_particles(s, i, t1, kids->b, kids->ids, kids->parents);
    kids->b->n = 0;
}

void pfx_spawn_process(pfx_sim *s, double t1) {
    const pfx_effect *e = s->effect;
    if (!s->queues)
        return;
    /* Births may queue further events (on_birth, cycles bounded by depth):
     * repeat until every queue is empty; each pass consumes what was queued. */
    for (int pass = 0; pass < 64; pass++) {
        bool any = false;
        for (size_t i = 0; i < e->emitter_count; i++) {
            pfx_spawn_queue *q = &s->queues[i];
            if (!q->count) {
                drop_births(&s->emitters[i], q->overflow);
                q->overflow = 0;
                continue;
            }
            any = true;
            /* Take the queued records; events the births queue for this same
             * emitter land in the queue again for the next pass. */
            uint32_t n = q->count;
            pfx_emitter_state *st = &s->emitters[i];
            const pfx_pool *p = &s->pools[i];
            children kids = {.b = s->births};
            kids.b->n = 0;
            for (uint32_t k = 0; k < n; k++) {
                const spawn_record *r = &q->items[k];
                for (uint64_t c = 0; c < r->births; c++) {
                    if (p->count + kids.b->n == p->capacity)
                        make_children(s, i, t1, &kids);
                    if (p->count == p->capacity) {
                        /* None of the rest can be kept: dropped at once. */
                        drop_births(st, r->births - c);
                        break;
                    }
                    add_child(&s->effect->emitters[i], &kids, &r->parent, (uint32_t)c, r->t);
                    if (kids.b->n == PFX_BIRTH_BLOCK)
                        make_children(s, i, t1, &kids);
                }
            }
            make_children(s, i, t1, &kids);
            /* The births that found the queue at the pool's capacity come
             * after every queued one, as they were raised after them. */
            drop_births(st, q->overflow);
            q->overflow = 0;
            memmove(q->items, q->items + n, (q->count - n) * sizeof *q->items);
            q->count -= n;
        }
        if (!any)
            break;
    }
    /* A new step: what is still queued (events raised after this pass, or
     * past the last pass) counts against the pool again. */
    for (size_t i = 0; i < e->emitter_count; i++) {
        pfx_spawn_queue *q = &s->queues[i];
        q->queued = 0;
        for (uint32_t k = 0; k < q->count; k++)
            q->queued += q->items[k].births;
    }
}
