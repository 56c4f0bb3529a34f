/* Deflectors: planes (infinite or bounded), discs, spheres and boxes that
 * particles bounce off, die on or stick to. The simulation integrates a step
 * first, then pfx_collide resolves the step's path of every particle against
 * the deflectors it hits: exact time of impact on the step's parabola, the
 * response at that time, the rest of the step after it (REFERENCE.md §5). */
#ifndef PFX_COLLIDE_H
#define PFX_COLLIDE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sim/rng.h"

/* A deflector list longer than this is a compile error upstream. */
#define PFX_COLLIDE_MAX_DEFLECTORS 64
/* Hits resolved per particle per step; then it waits at the last hit point. */
#define PFX_COLLIDE_MAX_HITS 8

typedef enum {
    PFX_DEFLECTOR_PLANE = 0, /* infinite (one-sided) or bounded by size[0..1] (two-sided) */
    PFX_DEFLECTOR_DISC,      /* two-sided, radius about point */
    PFX_DEFLECTOR_SPHERE,    /* one-sided: particles outside, or inside */
    PFX_DEFLECTOR_BOX        /* axis-aligned, one-sided: outside, or inside */
} pfx_deflector_shape;

typedef enum {
    PFX_DEFLECT_BOUNCE = 0, /* v' = (1 - mu) v_T - eps v_N */
    PFX_DEFLECT_KILL,       /* lifetime := PFX_KILLED; the simulation's kill pass removes it */
    PFX_DEFLECT_STICK       /* v := 0 at the hit point, for the rest of its life */
} pfx_deflect_response;

/* One deflector, in world space and SI units, as the compiler leaves it.
 * Sides: an infinite plane is the surface of a solid behind its normal, so
 * particles live in front (n.(x - point) >= 0); a sphere or box keeps its
 * particles outside, or inside when `inside`. Particles that start a step on
 * the solid side of one of those (emitted inside it) pass through it until
 * they come out. A disc and a bounded plane are thin: particles bounce off
 * either face. */
typedef struct pfx_deflector {
    const char *name; /* for messages only */
    pfx_deflector_shape shape;
    bool inside;     /* sphere, box: the particles' side is the inside */
    double point[3]; /* plane, disc: a point on it (the centre when bounded); sphere, box: centre */
    double normal[3]; /* plane, disc: normal, any length > 0 */
    double axis_u[3]; /* bounded plane: direction of size[0] in the plane; zero: world x
                         projected into the plane (z when the normal is within 25 deg of x) */
    double radius;    /* disc, sphere */
    double size[3];   /* plane: [w, h], bounded when both > 0; box: full edge lengths */
    pfx_deflect_response response;
    double resilience[2]; /* eps in [lo, hi], drawn uniformly per impact; lo == hi: constant */
    double friction[2];   /* mu in [lo, hi], likewise; sliding uses the midpoint */
    double lifetime_loss; /* fraction of the lifetime removed per impact, in [0, 1] */
    double chance;        /* fraction of particles it affects, in [0, 1] */
    uint64_t seed;        /* salt of the chance hash, e.g. pfx_rng_stream_for(name) ^ effect seed */
} pfx_deflector;

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
    const uint32_t *id; /* key of the chance hash; NULL: the pool index (not stable) */
    uint8_t *stuck;     /* optional: 1 once stuck (see pfx_collide) */
} pfx_collide_pool;

/* Called for every impact and every kill or stick touch (not for resting
 * contact): particle index, deflector index into the array passed, hit point,
 * unit surface normal on the particle's side, and the time of the hit in
 * seconds after the start of the step. */
typedef void (*pfx_hit_fn)(void *user, uint32_t index, size_t deflector, const double pos[3],
                           const double normal[3], double t_hit);

typedef struct pfx_collide_stats {
    uint64_t impacts;  /* bounces with an incoming normal speed above |a_N| dt */
    uint64_t contacts; /* resting touches (sliding particles, once per step each) */
    uint64_t kills, sticks;
    uint64_t capped;    /* particles that reached PFX_COLLIDE_MAX_HITS in a step */
    uint64_t fallbacks; /* end state behind a surface the parabola missed: re-solved */
} pfx_collide_stats;

/* Resolves one step of length dt (> 0) of every particle in `pool` against
 * `defl[0..n_defl)` (n_defl <= PFX_COLLIDE_MAX_DEFLECTORS). The path of a
 * step is the parabola x0 + v0 t + a t^2 / 2, a = (v1 - v0) / dt; the
 * earliest hit wins, the response applies at its time and the rest of the
 * step follows the new parabola, up to PFX_COLLIDE_MAX_HITS times. Particles
 * that touch nothing keep the integrator's state bit for bit. Random
 * resilience and friction draw from `rng` (in particle order); on_hit and
 * stats may be NULL; stats are added to. Never allocates.
 * The caller must: run its kill pass afterwards (a killed particle has
 * lifetime == PFX_KILLED); keep `stuck` (when given) as a pool column, 0 at birth and
 * moved by swap-remove — a stuck particle is put back at x0 with v = 0 each
 * step, whatever the integrator did; without the column a stuck particle
 * stops at the hit point and afterwards rests there like any other. Resting
 * particles need nothing: each step they are found in contact again and held
 * exactly on the surface. */
void pfx_collide(const pfx_deflector *defl, size_t n_defl, double dt, const pfx_collide_pool *pool,
                 pfx_rng *rng, pfx_hit_fn on_hit, void *user, pfx_collide_stats *stats);

/* Whether deflector d affects the particle with this id: a fixed hash of
 * (id, d->seed) to [0, 1) compared with d->chance, so a particle always hits,
 * or always passes, the same deflector. */
bool pfx_deflector_affects(const pfx_deflector *d, uint32_t id);

/* Signed distance from x to the deflector's surface, positive on the
 * particles' side (for thin shapes: distance to the plane, positive in front
 * of the normal). For tests and diagnostics. */
double pfx_deflector_distance(const pfx_deflector *d, const double x[3]);

#endif
