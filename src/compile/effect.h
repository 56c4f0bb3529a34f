/* The compiled effect: an immutable, validated description of a particle
 * effect, produced by pfx_compile from a parsed file. Everything downstream
 * (simulation, rendering, output) reads only this; after compile, bad input
 * is impossible, so later stages assert instead of reporting. */
#ifndef PFX_EFFECT_H
#define PFX_EFFECT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sim/motion.h"

#define PFX_FORMAT_VERSION 1
#define PFX_MAX_FORCES 32 /* an emitter's force set is a 32-bit mask */
#define PFX_GRADIENT_LUT 256
#define PFX_DEFAULT_MAX_PARTICLES 1000000

/* A random quantity. Constant: a. Uniform: [a, b]. Normal: mean a, standard
 * deviation b, clamped to [lo, hi]. `{mean, var}` compiles to uniform. */
typedef enum { PFX_DIST_CONST, PFX_DIST_UNIFORM, PFX_DIST_NORMAL } pfx_dist;
typedef struct pfx_value {
    pfx_dist dist;
    double a, b;
    double lo, hi; /* normal only */
} pfx_value;

/* Colours are linear 0..1 RGBA, straight alpha. A gradient is sampled once
 * into a lookup table over normalised age [0, 1]. */
typedef struct pfx_gradient {
    float lut[PFX_GRADIENT_LUT][4];
    bool constant; /* every entry equal: no per-particle lookup needed */
} pfx_gradient;

typedef enum { PFX_SHAPE_POINT, PFX_SHAPE_SPHERE, PFX_SHAPE_BOX, PFX_SHAPE_DISC } pfx_shape_type;
typedef struct pfx_shape {
    pfx_shape_type type;
    double radius;  /* sphere, disc */
    double size[3]; /* box: full edge lengths */
} pfx_shape;

/* A named force: its motion-model entry in SI units (radians, m, s). */
typedef struct pfx_force {
    const char *name;
    pfx_motion_force spec;
} pfx_force;

typedef enum { PFX_BLEND_ADD, PFX_BLEND_ALPHA } pfx_blend;

typedef struct pfx_emitter {
    const char *name;
    pfx_shape shape;
    double position[3];
    double rotation[9];  /* row-major, from rotation degrees X then Y then Z */
    double rate;         /* particles per second */
    double direction[3]; /* unit, already rotated into world space */
    double spread_deg;   /* cone half-angle */
    pfx_value speed;
    pfx_value lifetime;
    double max_lifetime; /* upper bound of `lifetime` */
    pfx_value size_start;
    pfx_value size_end;
    bool size_same;   /* `size` given as one value: end equals start */
    bool size_varies; /* start or end random: per-particle columns */
    pfx_gradient color;
    uint32_t force_mask; /* bit i: feels effect->forces[i] */
    pfx_value gravity_scale;
    pfx_value charge; /* coulomb, for magnetic forces */
    pfx_value mass;   /* kg, for magnetic forces (others are per unit mass) */
    double accel[3];  /* sum of the gravities it feels (before gravity_scale) */
    /* NULL when the emitter feels only gravity under the `auto` integrator:
     * then the exact constant-acceleration kernel runs. Otherwise the forces
     * it feels and the integrator, prepared for dt = 1 / sim.rate. */
    pfx_motion *motion;
    pfx_blend blend;
    uint32_t capacity; /* pool size: floor(rate * max_lifetime) + 1, budget-capped */
    bool saturates;    /* capacity was cut by the particle budget */
} pfx_emitter;

typedef struct pfx_camera {
    double position[3];
    double target[3];
    double up[3];
    bool ortho;
    double fov_deg;      /* perspective: vertical field of view */
    double ortho_height; /* ortho: view height in metres */
} pfx_camera;

typedef struct pfx_effect {
    const char *path; /* the file it came from */
    double duration;
    double fps;
    uint64_t seed;
    double sim_rate; /* steps per second */
    double prewarm;
    pfx_integrator integrator; /* sim.integrator; emitters may override */
    double tolerance;          /* sim.tolerance, m per simulated second */
    int substeps;              /* sim.substeps; 0: auto */
    pfx_camera camera;
    int width, height;
    float background[4]; /* straight RGBA 0..1 */
    size_t force_count;
    pfx_force *forces;
    size_t emitter_count;
    pfx_emitter *emitters;
    uint64_t max_particles;
} pfx_effect;

/* Upper bound of a value's samples. */
double pfx_value_max(const pfx_value *v);
/* Lower bound of a value's samples. */
double pfx_value_min(const pfx_value *v);

/* Frames in the whole effect: round(duration * fps), at least 1. */
long pfx_effect_frame_count(const pfx_effect *e);

#endif
