/* The passes of one step over an emitter's live particles: motion (the
 * gravity kernel, or the emitter's motion plan), the state check,
 * deflectors, and deaths by swap-remove. sim.c runs them in order;
 * newborn.c runs the same ones over a newborn's partial step. */
#include "sim/step.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

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

/* Exact constant-acceleration motion over dt for every live particle of a
 * gravity-only emitter. Ages need no update: the pool keeps birth times.
 * The state check rides along only when some particle's bound at birth
 * could reach it (pool->may_run_away); otherwise the state provably stays
 * finite and in range and the loop is the bare update. Returns whether the
 * check saw something. */
bool pfx_step_gravity(const pfx_emitter *em, pfx_pool *p, float dt) {
    float *px = p->px, *py = p->py, *pz = p->pz, *vx = p->vx, *vy = p->vy, *vz = p->vz;
    if (!p->gravity_scale) {
        /* The scale folded into the acceleration: one multiply-add chain. */
        const double gs = em->gravity_scale.a;
        const float a[3] = {(float)(em->accel[0] * gs), (float)(em->accel[1] * gs),
                            (float)(em->accel[2] * gs)};
        return p->may_run_away ? gravity_step(p->count, px, py, pz, vx, vy, vz, NULL, a, dt, true)
                               : gravity_step(p->count, px, py, pz, vx, vy, vz, NULL, a, dt, false);
    }
    const float a[3] = {(float)em->accel[0], (float)em->accel[1], (float)em->accel[2]};
    const float *gs = p->gravity_scale;
    return p->may_run_away ? gravity_step(p->count, px, py, pz, vx, vy, vz, gs, a, dt, true)
                           : gravity_step(p->count, px, py, pz, vx, vy, vz, gs, a, dt, false);
}

/* Whether a newborn of a gravity-only emitter could ever trip the state
 * check: under a constant acceleration a its speed stays within |v| + |a| L
 * for its lifetime L (a bounce takes speed away: resilience and friction
 * are at most 1; wrapping only moves it back), and its distance from the
 * origin within |x| + that speed times L. */
bool pfx_step_may_run_away(const float x[3], const float v[3], const double a[3], double life) {
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
    pfx_diag_error(s->diags,
                   "%s: emitter '%s': particle %u became %s at t = %.4g s; likely cause: %s",
                   s->effect->path, em->name, p->id[first + bad],
                   why == PFX_BAD_NONFINITE ? "non-finite"
                   : why == PFX_BAD_SPEED   ? "faster than 1e6 m/s"
                                            : "farther than 1e7 m",
                   t, cause);
}

/* Any other force set: the emitter's motion model, prepared once for the
 * fixed step; a view's remainder runs the same scheme in substeps no longer
 * than the prepared ones (pfx_motion_advance_f), never a re-chosen one. */
void pfx_step_motion(pfx_sim *s, size_t i, double span) {
    pfx_pool *p = &s->pools[i];
    pfx_motion_pool_f view = pfx_step_motion_view(p, 0, p->count);
    pfx_motion_advance_f(&s->plans[i], &view, s->time, span);
}

/* The start-of-step state the collision pass sweeps from. */
void pfx_step_save_start(pfx_pool *p) {
    const size_t n = p->count * sizeof(float);
    memcpy(p->start_px, p->px, n), memcpy(p->start_py, p->py, n), memcpy(p->start_pz, p->pz, n);
    memcpy(p->start_vx, p->vx, n), memcpy(p->start_vy, p->vy, n), memcpy(p->start_vz, p->vz, n);
}

/* A deflector hit of particle `first + index` becomes an on_hit event at
 * the exact time and place, with the surface normal. */
typedef struct hit_context {
    pfx_sim *s;
    size_t emitter;
    uint32_t first;
    double t0;
} hit_context;

static void on_hit(void *user, uint32_t index, size_t deflector, const double pos[3],
                   const double normal[3], double t_hit) {
    (void)deflector;
    hit_context *h = user;
    const pfx_pool *p = &h->s->pools[h->emitter];
    uint32_t j = h->first + index;
    const double vel[3] = {p->vx[j], p->vy[j], p->vz[j]};
    pfx_spawn_event_of(h->s, h->emitter, PFX_SPAWN_HIT, j, h->t0 + t_hit, pos, vel, normal);
}

/* Deflectors for particles [first, first + n) over the step of length dt
 * just integrated: each path is swept from its start state, so nothing
 * tunnels, and hits are resolved at their exact times (src/sim/collide.c). */
void pfx_step_collide(pfx_sim *s, size_t i, uint32_t first, uint32_t n, double t0, double dt) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_pool *p = &s->pools[i];
    pfx_emitter_state *st = &s->emitters[i];
    pfx_collide_pool view = {.count = n,
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
                             .stuck = p->stuck ? p->stuck + first : NULL};
    hit_context hc = {s, i, first, t0};
    bool hits = em->spawn_count && pfx_spawn_has(em, PFX_SPAWN_HIT);
    pfx_collide(em->deflectors, em->deflector_count, dt, &view, &st->collide_rng,
                hits ? on_hit : NULL, &hc, &st->collisions);
}

/* Death at age >= lifetime; the last live particle fills the hole. */
void pfx_step_kill_expired(pfx_sim *s, size_t emitter, double t1) {
    pfx_pool *p = &s->pools[emitter];
    const bool deaths = pfx_spawn_has(&s->effect->emitters[emitter], PFX_SPAWN_DEATH);
    const double *birth = p->birth;
    const float *lifetime = p->lifetime;
    /* Most blocks hold no death: a branch-free scan (vectorised) skips them,
     * and only a block with a death runs the swap-remove loop. */
    enum { BLOCK = 64 };
    uint32_t i = 0;
    while (i < p->count) {
        uint32_t end = p->count - i > BLOCK ? i + BLOCK : p->count;
        int dead = 0;
        for (uint32_t j = i; j < end; j++)
            dead |= t1 - birth[j] >= lifetime[j];
        if (!dead) {
            i = end;
            continue;
        }
        while (i < end) {
            if (t1 - birth[i] < lifetime[i]) {
                i++;
                continue;
            }
            if (deaths) {
                /* Died at t1 - (age - lifetime), back along its velocity;
                 * killed ones (PFX_KILLED) at t1, where they are. */
                double over = p->lifetime[i] < 0 ? 0 : (t1 - birth[i]) - p->lifetime[i];
                const double pos[3] = {p->px[i] - p->vx[i] * over, p->py[i] - p->vy[i] * over,
                                       p->pz[i] - p->vz[i] * over},
                             vel[3] = {p->vx[i], p->vy[i], p->vz[i]};
                pfx_spawn_event_of(s, emitter, PFX_SPAWN_DEATH, i, t1 - over, pos, vel, NULL);
            }
            pfx_pool_move(p, i, --p->count);
            if (end > p->count)
                end = p->count;
        }
    }
}
