/* The passes of one step over an emitter's live particles: motion (the
 * gravity kernel, or the emitter's motion plan), the state check,
 * deflectors, and deaths by swap-remove. sim.c runs them in order;
 * newborn.c runs the same ones over a newborn's partial step. */
#include "sim/step.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/clones.h"
#include "base/workers.h"
#include "sim/pool.h"
#include "sim/spawn.h"

/* The exact constant-acceleration step of particles [0, n), x += v dt + a
 * dt^2/2, v += a dt, with the per-emitter acceleration hoisted, or a per
 * particle gravity_scale g times it. With `check` it also returns whether
 * some particle may be non-finite or runaway: a branch-free OR over
 * per-component tests (|v_c| > 1e6/sqrt(3), |x_c| > 1e7 or NaN), for
 * check_state to confirm. Always inlined with a constant `check`, so the
 * loop without it has no compares at all. */
static inline __attribute__((always_inline)) bool
gravity_step(uint32_t n, float *restrict px, float *restrict py, float *restrict pz,
             float *restrict vx, float *restrict vy, float *restrict vz, const float *restrict gs,
             const float a[3], float dt, const bool check) {
    const float h = 0.5f * dt * dt, vlim = 5.7e5f, xlim = (float)PFX_MOTION_MAX_POSITION;
    const float ax = a[0], ay = a[1], az = a[2];
    int alarm = 0;
    for (uint32_t i = 0; i < n; i++) {
        const float g = gs ? gs[i] : 1.0f;
        px[i] += vx[i] * dt + g * ax * h;
        py[i] += vy[i] * dt + g * ay * h;
        pz[i] += vz[i] * dt + g * az * h;
        vx[i] += g * ax * dt;
        vy[i] += g * ay * dt;
        vz[i] += g * az * dt;
        if (check)
            alarm |= !(fabsf(vx[i]) <= vlim) | !(fabsf(vy[i]) <= vlim) | !(fabsf(vz[i]) <= vlim) |
                     !(fabsf(px[i]) <= xlim) | !(fabsf(py[i]) <= xlim) | !(fabsf(pz[i]) <= xlim);
    }
    return alarm;
}

/* Exact constant-acceleration motion over dt for particles [first, first +
 * n) of a gravity-only emitter. Ages need no update: the pool keeps birth
 * times. The state check rides along only when some particle's bound at
 * birth could reach it (pool->may_run_away); otherwise the state provably
 * stays finite and in range and the loop is the bare update. Returns
 * whether the check saw something. Cloned for AVX-512 and AVX2 (the same
 * bits): 10^4 particles, in the caches, took 5.9 us a step in SSE and 2.2
 * in AVX-512 on the reference machine. */
PFX_CLONES static bool step_gravity(const pfx_emitter *em, pfx_pool *p, uint32_t first, uint32_t n,
                                    float dt) {
    float *px = p->px + first, *py = p->py + first, *pz = p->pz + first;
    float *vx = p->vx + first, *vy = p->vy + first, *vz = p->vz + first;
    if (!p->gravity_scale) {
        /* The scale folded into the acceleration: one multiply-add chain. */
        const double gs = em->gravity_scale.a;
        const float a[3] = {(float)(em->accel[0] * gs), (float)(em->accel[1] * gs),
                            (float)(em->accel[2] * gs)};
        return p->may_run_away ? gravity_step(n, px, py, pz, vx, vy, vz, NULL, a, dt, true)
                               : gravity_step(n, px, py, pz, vx, vy, vz, NULL, a, dt, false);
    }
    const float a[3] = {(float)em->accel[0], (float)em->accel[1], (float)em->accel[2]};
    const float *gs = p->gravity_scale + first;
    return p->may_run_away ? gravity_step(n, px, py, pz, vx, vy, vz, gs, a, dt, true)
                           : gravity_step(n, px, py, pz, vx, vy, vz, gs, a, dt, false);
}

/* Whether a newborn of a gravity-only emitter could ever trip the state
 * check: under a constant acceleration a its speed stays within |v| + |a| L
 * for its lifetime L (a bounce takes speed away: resilience and friction
 * are at most 1; wrapping only moves it back), and its distance from the
 * origin within |x| + that speed times L. */
bool pfx_step_may_run_away(const float x[3], const float v[3], const double a[3], double life) {
    if (pfx_step_far_inside(x, v, a, life))
        return false;
    double speed = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]) +
                   sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) * life;
    double far =
        sqrt((double)x[0] * x[0] + (double)x[1] * x[1] + (double)x[2] * x[2]) + speed * life;
    return !(speed < 5.7e5 && far < 0.5 * PFX_MOTION_MAX_POSITION);
}

pfx_motion_pool_f pfx_step_motion_view(const pfx_pool *p, uint32_t first, uint32_t n) {
    return (pfx_motion_pool_f){.count = n,
                               .px = p->px + first,
                               .py = p->py + first,
                               .pz = p->pz + first,
                               .vx = p->vx + first,
                               .vy = p->vy + first,
                               .vz = p->vz + first,
                               .gravity_scale = p->gravity_scale ? p->gravity_scale + first : NULL,
                               .charge = p->charge ? p->charge + first : NULL,
                               .mass = p->mass ? p->mass + first : NULL,
                               .bx = p->bx ? p->bx + first : NULL,
                               .by = p->by ? p->by + first : NULL,
                               .bz = p->bz ? p->bz + first : NULL,
                               .birth_time = p->birth + first,
                               .lifetime = p->lifetime + first};
}

void pfx_step_state_before(const pfx_sim *s, size_t i, uint32_t j, double t1, double back,
                           double pos[3], double vel[3]) {
    const pfx_emitter *em = &s->effect->emitters[i];
    const pfx_pool *p = &s->pools[i];
    const double x[3] = {p->px[j], p->py[j], p->pz[j]}, v[3] = {p->vx[j], p->vy[j], p->vz[j]};
    if (!(back > 0) || !em->motion) {
        const double gs = p->gravity_scale ? p->gravity_scale[j] : em->gravity_scale.a;
        const double b = back > 0 ? back : 0;
        for (int a = 0; a < 3; a++) {
            const double acc = em->motion ? 0 : em->accel[a] * gs;
            pos[a] = x[a] - v[a] * b + 0.5 * acc * b * b;
            vel[a] = v[a] - acc * b;
        }
        return;
    }
    float fx = p->px[j], fy = p->py[j], fz = p->pz[j], fu = p->vx[j], fv = p->vy[j], fw = p->vz[j];
    pfx_motion_pool_f one = pfx_step_motion_view(p, j, 1);
    one.px = &fx, one.py = &fy, one.pz = &fz, one.vx = &fu, one.vy = &fv, one.vz = &fw;
    one.ax = one.ay = one.az = NULL;
    pfx_motion_advance_f(&s->plans[i], &one, t1, back);
    const double x1[3] = {fx, fy, fz}, v1[3] = {fu, fv, fw};
    pfx_motion_advance_f(&s->plans[i], &one, t1 + back, back);
    const double x2[3] = {fx, fy, fz}, v2[3] = {fu, fv, fw};
    for (int a = 0; a < 3; a++) {
        pos[a] = 3 * x[a] - 3 * x1[a] + x2[a];
        vel[a] = 3 * v[a] - 3 * v1[a] + v2[a];
    }
}

/* The state check: the first of particles [first, count) of emitter i that
 * is non-finite, faster than 1e6 m/s or farther than 1e7 m stops the
 * simulation, naming the emitter, the particle, the time and the stability
 * warning that predicted it. Every particle passes it after every step,
 * its birth step included. */
void pfx_step_check_state(pfx_sim *s, size_t i, uint32_t first, double t) {
    const pfx_pool *p = &s->pools[i];
    if (s->failed || first >= p->count)
        return;
    pfx_motion_pool_f view = pfx_step_motion_view(p, first, p->count - first);
    pfx_bad_kind why;
    size_t bad = pfx_motion_find_bad_f(&view, &why);
    if (bad == view.count)
        return;
    const pfx_emitter *em = &s->effect->emitters[i];
    char cause[320];
    if (em->motion)
        pfx_motion_blame(em->motion, why, cause, sizeof cause);
    else
        snprintf(cause, sizeof cause, "the emitter's speeds, gravity and lifetimes are too large");
    s->failed = true;
    pfx_diag_error(s->diags, PFX_RULE_SIMULATION_DIVERGED,
                   "%s: emitter '%s': particle %u became %s at t = %.4g s; likely cause: %s",
                   s->effect->path, em->name, p->id[first + bad],
                   why == PFX_BAD_NONFINITE ? "non-finite"
                   : why == PFX_BAD_SPEED   ? "faster than 1e6 m/s"
                                            : "farther than 1e7 m",
                   t, cause);
}

/* p's blocks of s->block particles, the last maybe short. */
static size_t block_count(const pfx_sim *s, const pfx_pool *p) {
    return ((size_t)p->count + s->block - 1) / s->block;
}

/* Particles in block b of p's blocks. */
static uint32_t block_size(const pfx_sim *s, const pfx_pool *p, size_t b) {
    const uint32_t first = (uint32_t)(b * s->block);
    return p->count - first < s->block ? p->count - first : s->block;
}

/* The collide pass's view of particles [first, first + n) of p. */
static pfx_collide_pool collide_view(const pfx_pool *p, uint32_t first, uint32_t n) {
    return (pfx_collide_pool){.count = n,
                              .px0 = p->start_px + first,
                              .py0 = p->start_py + first,
                              .pz0 = p->start_pz + first,
                              .vx0 = p->start_vx + first,
                              .vy0 = p->start_vy + first,
                              .vz0 = p->start_vz + first,
                              .px = p->px + first,
                              .py = p->py + first,
                              .pz = p->pz + first,
                              .vx = p->vx + first,
                              .vy = p->vy + first,
                              .vz = p->vz + first,
                              .lifetime = p->lifetime + first,
                              .id = p->id + first,
                              .stuck = p->stuck ? p->stuck + first : NULL,
                              .hits = p->hits ? p->hits + first : NULL,
                              .ax = p->ax ? p->ax + first : NULL,
                              .rest = p->rest ? p->rest + first : NULL,
                              .rest_px = p->rest_px ? p->rest_px + first : NULL,
                              .rest_py = p->rest_py ? p->rest_py + first : NULL,
                              .rest_pz = p->rest_pz ? p->rest_pz + first : NULL,
                              .rest_vx = p->rest_vx ? p->rest_vx + first : NULL,
                              .rest_vy = p->rest_vy ? p->rest_vy + first : NULL,
                              .rest_vz = p->rest_vz ? p->rest_vz + first : NULL};
}

/* One block of the motion pass: the start state the deflectors sweep from,
 * the step (the gravity kernel, or the emitter's motion plan: a view's
 * remainder runs the same scheme in substeps no longer than the prepared
 * ones, pfx_motion_advance_f, never a re-chosen one), and whether the
 * block may hold a bad state. Each block reads and writes its own
 * particles only, so any thread may run it. */
typedef struct move_job {
    pfx_sim *s;
    size_t emitter;
    double t0, span;
    double t1;        /* the step's end, for the death scan */
    bool scan_deaths; /* no later pass changes a lifetime outside the blocks it notes */
    bool none_die;    /* and no particle's death falls within the step: no scan */
} move_job;

/* Whether particles [first, first + n) hold one dead at t1 (age >=
 * lifetime): the test of pfx_step_kill_expired, branch-free so that it
 * vectorises (the baseline x86-64 build does not: the float lifetimes'
 * widening to double needs AVX, hence the clone). */
PFX_CLONES static bool block_has_death(const pfx_pool *p, uint32_t first, uint32_t n, double t1) {
    const double *birth = p->birth + first;
    const float *lifetime = p->lifetime + first;
    int dead = 0;
    for (uint32_t j = 0; j < n; j++)
        dead |= t1 - birth[j] >= lifetime[j];
    return dead;
}

/* ---- Particles at rest under gravity alone ----
 * A particle flagged at rest (pfx_collide_pool.rest) whose integrator end
 * state is bit for bit its flagged one ends the step exactly where it
 * began, its broad-phase mark cleared (pfx_collide_rest). Under gravity
 * alone that end state is a function of the particle's state, its
 * gravity scale (fixed at birth), the emitter's acceleration (fixed) and
 * dt alone; and a flagged particle's state is the one its flag was made
 * in (whatever else moves a particle clears its flag: collide.h), with a
 * dt the same (rest_dt). So its end state is its flagged one, and the flag
 * alone says it is held: nothing of it needs reading. Where every flag of
 * a chunk is set, the chunk is done: no start state saved, no end state
 * computed, stored and put back, no broad phase (the mark a held particle
 * would get is the one that sent it to the exact pass when its flag was
 * made: near, which pfx_collide_rest clears). A chunk with one particle
 * awake takes the whole path, which decides the same for each of its
 * particles. */
enum { HELD_CHUNK = 256 };

/* The sum of the m flags' (rest & 0x7f), 0 when one of them is not set
 * (then the chunk is not held). Straight and branch-free, so that the
 * clones run it at their width. */
PFX_CLONES static uint32_t held_flags(const uint8_t *restrict rest, uint32_t m) {
    uint32_t sum = 0, awake = 0;
    for (uint32_t j = 0; j < m; j++) {
        sum += rest[j] & 0x7fu;
        awake |= rest[j] == 0;
    }
    return awake ? 0 : sum;
}

/* Whether every particle of [first, first + m) of a gravity-only emitter
 * is held at rest over this step (their flags are of its dt); then their
 * marks are cleared and *contacts is what pfx_collide_rest would have
 * counted for them ((rest & 0x7f) - 1 each). */
static bool chunk_held(pfx_pool *p, uint32_t first, uint32_t m, uint32_t *contacts) {
    if (!p->rest[first]) /* most chunks with one awake (rows that rest nowhere) */
        return false;
    const uint32_t sum = held_flags(p->rest + first, m);
    if (!sum)
        return false;
    *contacts = sum - m;
    memset(p->near + first, 0, m);
    return true;
}

/* The move pass's work on particles [first, first + n) of block b: the
 * start state, the step, the broad phase and the resting restore; *bad
 * and *any_near or'ed with the range's, its contacts added to the
 * block's counters. */
static void move_range(const move_job *j, size_t b, uint32_t first, uint32_t n, bool *bad,
                       bool *any_near) {
    pfx_sim *s = j->s;
    const pfx_emitter *em = &s->effect->emitters[j->emitter];
    pfx_pool *p = &s->pools[j->emitter];
    if (em->deflector_count) {
        const size_t bytes = n * sizeof(float);
        memcpy(p->start_px + first, p->px + first, bytes);
        memcpy(p->start_py + first, p->py + first, bytes);
        memcpy(p->start_pz + first, p->pz + first, bytes);
        memcpy(p->start_vx + first, p->vx + first, bytes);
        memcpy(p->start_vy + first, p->vy + first, bytes);
        memcpy(p->start_vz + first, p->vz + first, bytes);
    }
    if (em->motion) {
        pfx_motion_pool_f view = pfx_step_motion_view(p, first, n);
        if (p->ax) { /* the carried accelerations: a full step, ending at t1 */
            view.ax = p->ax + first, view.ay = p->ay + first, view.az = p->az + first;
        }
        /* (its quick test of each motion block: pfx_step_check_state
         * confirms and names a bad particle) */
        *bad |= pfx_motion_move_f(&s->plans[j->emitter], &view, j->t0, j->t1);
    } else {
        *bad |= step_gravity(em, p, first, n, (float)j->span);
    }
    /* The deflectors' broad phase while the block is in this core's
     * caches; the serial collide pass visits only what it marks. With the
     * step's dt as the collide pass has it, a float. */
    if (em->deflector_count) {
        pfx_collide_pool view = collide_view(p, first, n);
        bool near = pfx_collide_near(em->deflectors, em->deflector_count, (float)j->span, &view,
                                     p->near + first);
        /* The particles at rest too, while the block is in the caches:
         * restored, their marks cleared; their contacts are the block's
         * first counters (collide_block adds the rest). */
        view.rest_valid = (float)j->span == s->emitters[j->emitter].rest_dt;
        if (near)
            s->block_stats[b].contacts += pfx_collide_rest(&view, p->near + first, &near);
        *any_near |= near;
    }
}

static void move_block(void *arg, size_t b) {
    const move_job *j = arg;
    pfx_sim *s = j->s;
    const pfx_emitter *em = &s->effect->emitters[j->emitter];
    pfx_pool *p = &s->pools[j->emitter];
    const uint32_t first = (uint32_t)(b * s->block), n = block_size(s, p, b);
    const float dt = (float)j->span;
    bool bad = false, any_near = false;
    if (em->deflector_count)
        s->block_stats[b] = (pfx_collide_stats){0};
    /* Gravity alone, with resting flags of this dt (and no carried
     * acceleration that a restore would mark unknown): a chunk of
     * particles all at rest is done by a test that writes nothing, and
     * each run of the other chunks takes the whole path at once (per
     * chunk, its calls cost 10-15 % of a row that hits nothing). A held
     * particle's state was checked when it got there, so the chunk adds
     * nothing to the state check's alarm either. */
    if (em->deflector_count && !em->motion && p->rest && !p->ax &&
        dt == s->emitters[j->emitter].rest_dt) {
        uint32_t awake = 0; /* the start of the run of chunks not held */
        for (uint32_t c = 0; c < n; c += HELD_CHUNK) {
            const uint32_t m = n - c < HELD_CHUNK ? n - c : HELD_CHUNK;
            uint32_t contacts;
            if (!chunk_held(p, first + c, m, &contacts))
                continue;
            s->block_stats[b].contacts += contacts;
            if (awake < c)
                move_range(j, b, first + awake, c - awake, &bad, &any_near);
            awake = c + m;
        }
        if (awake < n)
            move_range(j, b, first + awake, n - awake, &bad, &any_near);
    } else {
        move_range(j, b, first, n, &bad, &any_near);
    }
    /* Without the scan every block counts as holding a death, and the
     * serial pass looks at all of them. */
    const bool death = !j->scan_deaths || (!j->none_die && block_has_death(p, first, n, j->t1));
    const uint8_t flags = (uint8_t)((bad ? PFX_BLOCK_BAD : 0) | (death ? PFX_BLOCK_DEATH : 0) |
                                    (any_near ? PFX_BLOCK_NEAR : 0));
    /* Written only when they change: the flags of neighbouring blocks
     * share a cache line, which two cores writing every step would pass
     * back and forth (most steps change none). */
    if (s->block_flags[b] != flags)
        s->block_flags[b] = flags;
}

uint32_t pfx_step_move(pfx_sim *s, size_t i, double t0, double t1, bool scan_deaths) {
    pfx_pool *p = &s->pools[i];
    const size_t blocks = block_count(s, p);
    /* The floor is a sum rounded once, the scan's test a difference: a
     * margin far above either rounding. */
    const double floor = p->death_floor;
    const bool none_die =
        s->emitters[i].lives_fixed && (floor == INFINITY || t1 < floor - 1e-9 * (1 + fabs(floor)));
    move_job job = {s, i, t0, t1 - t0, t1, scan_deaths, none_die};
    pfx_workers_run(s->workers, blocks, move_block, &job);
    for (size_t b = 0; b < blocks; b++)
        if (s->block_flags[b] & PFX_BLOCK_BAD)
            return (uint32_t)(b * s->block);
    return p->count;
}

/* A deflector hit of particle `first + index` becomes an on_hit event at
 * the exact time and place, with the surface normal: queued at once, or
 * held in the block's buffer for the merge (pfx_hit_buffer). */
typedef struct hit_context {
    pfx_sim *s;
    size_t emitter;
    uint32_t first;
    double t0;
    pfx_hit_buffer *held; /* NULL: queue at once */
} hit_context;

static void on_hit(void *user, uint32_t index, size_t deflector, const double pos[3],
                   const double normal[3], double t_hit) {
    (void)deflector;
    hit_context *h = user;
    const pfx_pool *p = &h->s->pools[h->emitter];
    uint32_t j = h->first + index;
    const double vel[3] = {p->vx[j], p->vy[j], p->vz[j]};
    if (h->held) { /* room is certain: see collide_block */
        pfx_spawn_capture(h->s, h->emitter, PFX_SPAWN_HIT, j, h->t0 + t_hit, pos, vel, normal,
                          &h->held->items[h->held->count++]);
        return;
    }
    pfx_spawn_event_of(h->s, h->emitter, PFX_SPAWN_HIT, j, h->t0 + t_hit, pos, vel, normal);
}

/* Deflectors for particles [first, first + n) over the step of length dt
 * just integrated: each path is swept from its start state, so nothing
 * tunnels, and hits are resolved at their exact times (src/sim/collide.c).
 * near: the move pass's marks, or NULL; the counters go to stats; the
 * on_hit events to `held`, or (NULL) the queues. */
static void collide_range(pfx_sim *s, size_t i, uint32_t first, uint32_t n, double t0, double dt,
                          const uint8_t *near, pfx_collide_stats *stats, pfx_hit_buffer *held) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_collide_pool view = collide_view(&s->pools[i], first, n);
    view.key = s->emitters[i].hit_key;
    /* The resting flags are of the whole steps' dt; a newborn's part of a
     * step (near == NULL) neither reads nor makes them. */
    if (!near)
        view.rest = NULL;
    view.rest_valid = (float)dt == s->emitters[i].rest_dt;
    hit_context hc = {s, i, first, t0, held};
    bool hits = em->spawn_count && pfx_spawn_has(em, PFX_SPAWN_HIT);
    pfx_collide(em->deflectors, em->deflector_count, dt, &view, near, hits ? on_hit : NULL, &hc,
                stats);
}

void pfx_step_collide(pfx_sim *s, size_t i, uint32_t first, uint32_t n, double t0, double dt,
                      pfx_collide_stats *stats) {
    collide_range(s, i, first, n, t0, dt, NULL, stats, NULL);
}

typedef struct collide_job {
    pfx_sim *s;
    size_t emitter;
    double t0, dt;
    bool hits; /* the emitter's hits start particles: events held per block */
} collide_job;

/* Block b of the collide pass, when the move pass noted it near a
 * surface; noted as holding a death after (a deflector may kill or shorten
 * a life). Its own counters; with hits, its events held in runs of
 * particles whose events surely fit, up to where the next would not. */
static void collide_block(void *arg, size_t b) {
    const collide_job *j = arg;
    pfx_sim *s = j->s;
    const pfx_pool *p = &s->pools[j->emitter];
    const uint32_t first = (uint32_t)(b * s->block), n = block_size(s, p, b);
    const uint8_t *near = p->near + first;
    pfx_collide_stats *stats = &s->block_stats[b];
    pfx_hit_buffer *held = j->hits ? &s->hit_buffers[b] : NULL;
    if (held)
        held->count = 0, held->resume = n;
    if (!(s->block_flags[b] & PFX_BLOCK_NEAR))
        return;
    s->block_flags[b] |= PFX_BLOCK_DEATH;
    if (!held) {
        collide_range(s, j->emitter, first, n, j->t0, j->dt, near, stats, NULL);
        return;
    }
    uint32_t from = 0;
    while (from < n) {
        const uint32_t room = (PFX_BLOCK_HIT_EVENTS - held->count) / PFX_COLLIDE_MAX_HITS;
        uint32_t to = from, marked = 0;
        while (to < n && (marked < room || !near[to]))
            marked += near[to++] != 0;
        if (to == from)
            break; /* the next marked particle might not fit */
        collide_range(s, j->emitter, first + from, to - from, j->t0, j->dt, near + from, stats,
                      held);
        from = to;
    }
    held->resume = from;
}

void pfx_step_collide_moved(pfx_sim *s, size_t i, double t0, double dt) {
    const pfx_pool *p = &s->pools[i];
    const size_t blocks = block_count(s, p);
    const pfx_emitter *em = &s->effect->emitters[i];
    collide_job job = {s, i, t0, dt, em->spawn_count && pfx_spawn_has(em, PFX_SPAWN_HIT)};
    pfx_workers_run(s->workers, blocks, collide_block, &job);
    /* In block order, as a pass over the pool: each block's held events,
     * then the particles it left, their events queued as they come. */
    for (size_t b = 0; job.hits && b < blocks; b++) {
        const pfx_hit_buffer *held = &s->hit_buffers[b];
        for (uint32_t k = 0; k < held->count; k++)
            pfx_spawn_queue_source(s, i, PFX_SPAWN_HIT, &held->items[k]);
        const uint32_t first = (uint32_t)(b * s->block), n = block_size(s, p, b);
        if (held->resume < n)
            collide_range(s, i, first + held->resume, n - held->resume, t0, dt,
                          p->near + first + held->resume, &s->block_stats[b], NULL);
    }
    s->emitters[i].rest_dt = (float)dt; /* every flag is now of this dt */
    pfx_collide_stats *sum = &s->emitters[i].collisions;
    for (size_t b = 0; b < blocks; b++) {
        const pfx_collide_stats *c = &s->block_stats[b];
        pfx_collide_stats_add(sum, c);
    }
}

/* Death at age >= lifetime in particles [i, until); the last live particle
 * fills each hole and is tested where it lands, so the removals happen in
 * ascending index order whatever range is scanned. */
static void kill_range(pfx_sim *s, size_t emitter, double t1, uint32_t i, uint32_t until) {
    pfx_pool *p = &s->pools[emitter];
    const bool deaths = pfx_spawn_has(&s->effect->emitters[emitter], PFX_SPAWN_DEATH);
    const double *birth = p->birth;
    const float *lifetime = p->lifetime;
    /* Most blocks hold no death: block_has_death (vectorised) skips them,
     * and only a block with a death runs the swap-remove loop. */
    enum { BLOCK = 64 };
    while (i < p->count && i < until) {
        uint32_t end = p->count - i > BLOCK ? i + BLOCK : p->count;
        if (end > until)
            end = until;
        if (!block_has_death(p, i, end - i, t1)) {
            i = end;
            continue;
        }
        while (i < end) {
            if (t1 - birth[i] < lifetime[i]) {
                i++;
                continue;
            }
            if (deaths) {
                /* Died at t1 - (age - lifetime), where its path was then;
                 * killed ones (PFX_KILLED) at t1, where they are. A life a
                 * deflector shortened (lifetime_loss) can end before this
                 * step began: the death is then placed no further back
                 * than the step (nor the particle's birth), where
                 * pfx_step_state_before's backward step holds. */
                double over = p->lifetime[i] < 0 ? 0 : (t1 - birth[i]) - p->lifetime[i];
                over = fmin(over, fmin(s->dt, t1 - birth[i]));
                double pos[3], vel[3];
                pfx_step_state_before(s, emitter, i, t1, over, pos, vel);
                pfx_spawn_event_of(s, emitter, PFX_SPAWN_DEATH, i, t1 - over, pos, vel, NULL);
            }
            pfx_pool_move(p, i, --p->count);
            if (end > p->count)
                end = p->count;
        }
    }
}

void pfx_step_kill_expired(pfx_sim *s, size_t emitter, double t1) {
    kill_range(s, emitter, t1, 0, UINT32_MAX);
}

/* A block that held no death when the move pass scanned it holds none now:
 * nothing changed a lifetime since outside the blocks the collide pass
 * visited (it flags them as holding a death), and a swap-remove only fills
 * the hole being scanned. So skipping those blocks removes exactly the
 * particles, in exactly the order, of the scan over every particle. */
void pfx_step_kill_flagged(pfx_sim *s, size_t emitter, double t1) {
    const pfx_pool *p = &s->pools[emitter];
    const size_t blocks = block_count(s, p);
    for (size_t b = 0; b < blocks && b * s->block < p->count; b++)
        if (s->block_flags[b] & PFX_BLOCK_DEATH)
            kill_range(s, emitter, t1, (uint32_t)(b * s->block), (uint32_t)((b + 1) * s->block));
}
