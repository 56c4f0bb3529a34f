/* A deflector as the compiled effect holds it: a plane, disc, sphere or box
 * in world space and SI units, and how particles respond to it. The
 * simulation resolves hits against it (sim/collide.h). */
#ifndef PFX_MODEL_DEFLECTOR_H
#define PFX_MODEL_DEFLECTOR_H

#include <stdbool.h>
#include <stdint.h>

#include "model/kinds.h"

/* A deflector list longer than this is a compile error. */
#define PFX_MAX_DEFLECTORS 64

/* Shapes (model/kinds.h): a plane, infinite (one-sided) or bounded by
 * size[0..1] (two-sided); a disc (two-sided, radius about point); a sphere
 * and an axis-aligned box (one-sided: particles outside, or inside). */
typedef enum {
#define PFX_DEFLECTOR_ENUM(e, name) PFX_DEFLECTOR_##e,
    PFX_DEFLECTOR_KINDS(PFX_DEFLECTOR_ENUM)
#undef PFX_DEFLECTOR_ENUM
} pfx_deflector_shape;

/* Responses: bounce, v' = (1 - mu) v_T - eps v_N; kill (it dies at the end
 * of the step); stick (v := 0 at the hit point, for the rest of its life). */
typedef enum {
#define PFX_DEFLECT_ENUM(e, name) PFX_DEFLECT_##e,
    PFX_DEFLECT_RESPONSES(PFX_DEFLECT_ENUM)
#undef PFX_DEFLECT_ENUM
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

#endif
