/* Deflectors: planes (infinite or bounded), discs, spheres and boxes that
 * particles bounce off, die on or stick to. The simulation integrates a step
 * first, then pfx_collide resolves the step's path of every particle against
 * the deflectors it hits: exact time of impact on the step's parabola, the
 * response at that time, the rest of the step after it (docs/physics.md,
 * Deflectors). */
#ifndef PFX_COLLIDE_H
#define PFX_COLLIDE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/rng.h"
#include "model/deflector.h"

#define PFX_COLLIDE_MAX_DEFLECTORS PFX_MAX_DEFLECTORS
/* Hits resolved per particle per step; then it waits at the last hit point. */
#define PFX_COLLIDE_MAX_HITS 8

/* The lifetime a kill rule or a deflector writes: the particle dies at the
 * end of the step, where it is. */
#define PFX_KILLED (-1.0f)

/* The columns pfx_collide reads and writes; all arrays hold `count` floats.
 * The start-of-step state (x0, v0) is scratch the simulation saved before
 * integrating; (px.., vx..) hold the integrator's end state and are resolved
 * in place. */
typedef struct pfx_collide_pool {
    uint32_t count;
    const float *px0, *py0, *pz0, *vx0, *vy0, *vz0;
    float *px, *py, *pz, *vx, *vy, *vz;
    float *lifetime;    /* kill writes PFX_KILLED; lifetime_loss lowers it */
    const uint32_t *id; /* key of the chance hash and of random responses; NULL: the pool
                           index (not stable) */
    uint32_t *hits;     /* optional: impacts so far, the other key of a random response
                           (without it every impact draws as the first) */
    uint64_t key;       /* salt of the random responses: the emitter's */
    uint8_t *stuck;     /* optional: 1 once stuck (see pfx_collide) */
    float *ax;          /* optional: the carried acceleration (sim/columns.h), set to NaN
                           where a position changes: it is no longer the one there */
    /* Optional: the resting state (see pfx_collide). rest[i] != 0 says the
     * particle's state is a fixed point of this pass: resolving it with the
     * integrator's end state (rest_px.. rest_vz)[i] over a step of the
     * rest_valid dt left it exactly where it was, counting rest[i] & 0x7f
     * minus 1 contacts and no other event, storing it when rest[i] & 0x80. */
    uint8_t *rest;
    float *rest_px, *rest_py, *rest_pz, *rest_vx, *rest_vy, *rest_vz;
    bool rest_valid; /* the flags were made with this call's dt */
} pfx_collide_pool;

/* Whether the collide pass may resolve particles near one plane in vector
 * lanes (collide_slide.c); true, and the same bits either way: the tests
 * turn it off to compare the two. */
extern bool pfx_collide_lanes;

/* Called for every impact and every kill or stick touch (not for resting
 * contact; a pfx_collide run from inside it takes no vector lanes): particle index, deflector index
 * into the array passed, hit point, unit surface normal on the particle's side, and the time of the
 * hit in seconds after the start of the step. */
typedef void (*pfx_hit_fn)(void *user, uint32_t index, size_t deflector, const double pos[3],
                           const double normal[3], double t_hit);

typedef struct pfx_collide_stats {
    uint64_t impacts;  /* bounces with an incoming normal speed above |a_N| dt */
    uint64_t contacts; /* resting touches (sliding particles, once per step each) */
    uint64_t kills, sticks;
    uint64_t capped;    /* particles that reached PFX_COLLIDE_MAX_HITS in a step */
    uint64_t fallbacks; /* end state behind a surface the parabola missed: re-solved */
} pfx_collide_stats;

/* dst += src, field by field. */
static inline void pfx_collide_stats_add(pfx_collide_stats *dst, const pfx_collide_stats *src) {
    dst->impacts += src->impacts, dst->contacts += src->contacts, dst->kills += src->kills;
    dst->sticks += src->sticks, dst->capped += src->capped, dst->fallbacks += src->fallbacks;
}

/* Resolves one step of length dt (> 0) of every particle in `pool` against
 * `defl[0..n_defl)` (n_defl <= PFX_COLLIDE_MAX_DEFLECTORS). The path of a
 * step is the parabola x0 + v0 t + a t^2 / 2, a = (v1 - v0) / dt; the
 * earliest hit wins, the response applies at its time and the rest of the
 * step follows the new parabola, up to PFX_COLLIDE_MAX_HITS times. Particles
 * that touch nothing keep the integrator's state bit for bit. `near`: the
 * marks of pfx_collide_near for this pool and dt, or NULL to find them
 * here. Random resilience and friction are drawn per particle and hit
 * (a hash of the pool's key, the deflector, the id and the hit number,
 * which each impact raises), so the particles are independent of each
 * other; on_hit and stats may be NULL; stats are added to. Never
 * allocates.
 * The caller must: run its kill pass afterwards (a killed particle has
 * lifetime == PFX_KILLED); keep `stuck` (when given) as a pool column, 0 at birth and
 * moved by swap-remove — a stuck particle is put back at x0 with v = 0 each
 * step, whatever the integrator did; without the column a stuck particle
 * stops at the hit point and afterwards rests there like any other. Resting
 * particles need nothing: each step they are found in contact again and held
 * exactly on the surface.
 * Resting as a state: the pass is a pure function of a particle's start
 * state, the integrator's end state, dt and its own columns, so where it
 * left a particle exactly as it found it (at rest on a surface, its forces
 * pressing it there) the same inputs again give the same bits. With `rest`
 * given, such a particle is flagged with its inputs, and the next step
 * whose integrator end state is bit for bit the flagged one (velocity and
 * forces unchanged) restores it without the sweep; any change wakes it.
 * The caller must clear the flag where anything else moves a particle (a
 * wrap, a birth), and give rest_valid only when dt is the flags' dt. */
void pfx_collide(const pfx_deflector *defl, size_t n_defl, double dt, const pfx_collide_pool *pool,
                 const uint8_t *near, pfx_hit_fn on_hit, void *user, pfx_collide_stats *stats);

/* The broad phase of pfx_collide on its own: near[i] (pool->count bytes)
 * becomes non-zero where particle i may touch one of defl this step (is
 * within its sweep bound of a surface, with a margin) or is stuck, zero
 * elsewhere; whether any is. A conservative float test whose marks give
 * pfx_collide exactly the result of its own broad phase. It reads the pool
 * only, so threads may run it on disjoint ranges while the particles are
 * still in their caches, and pass the marks (the same pool and dt) to
 * pfx_collide, which then visits the marked particles only. */
bool pfx_collide_near(const pfx_deflector *defl, size_t n_defl, double dt,
                      const pfx_collide_pool *pool, uint8_t *near);

/* The resting particles of the pool (see pfx_collide), after
 * pfx_collide_near and before pfx_collide with the same marks: each one
 * flagged at rest whose integrator end state is bit for bit its flagged
 * one is put back where the step found it, exactly as pfx_collide would,
 * and its mark cleared, so that pfx_collide does not visit it. Does
 * nothing without pool->rest or pool->rest_valid. Returns the contacts
 * pfx_collide would have counted for them; *any_near: whether a mark is
 * left. Reads and writes the pool's particles only: threads may run it on
 * disjoint ranges. */
uint64_t pfx_collide_rest(const pfx_collide_pool *pool, uint8_t *near, bool *any_near);

/* Whether deflector d affects the particle with this id: a fixed hash of
 * (id, d->seed) to [0, 1) compared with d->chance, so a particle always hits,
 * or always passes, the same deflector. */
bool pfx_deflector_affects(const pfx_deflector *d, uint32_t id);

#endif
