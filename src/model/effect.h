/* The compiled effect: an immutable, validated description of a particle
 * effect in SI units and radians, produced by pfx_compile from a parsed
 * file. Everything downstream (simulation, rendering, output) reads only
 * this; after compile, bad input is impossible, so later stages assert
 * instead of reporting. The model includes no stage: compile writes it,
 * sim and render read it. */
#ifndef PFX_MODEL_EFFECT_H
#define PFX_MODEL_EFFECT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "model/deflector.h"
#include "model/kill_rules.h"
#include "model/kinds.h"
#include "model/motion.h"

/* Radians per degree: files are written in degrees, the model holds
 * radians (M_PI / 180 as the compiler computes it). */
#define PFX_DEGREE (3.14159265358979323846 / 180)

#define PFX_FORMAT_VERSION 1
#define PFX_MAX_FORCES 32     /* an emitter's force set is a 32-bit mask */
#define PFX_MAX_EMITTERS 1024 /* checked before any is compiled */
#define PFX_GRADIENT_LUT 256
#define PFX_DEFAULT_MAX_PARTICLES 1000000
/* The most pixels an image can have: the renderer draws into one RGBA32F
 * framebuffer, which Mesa cannot allocate past 2^31 bytes (16 per pixel). */
#define PFX_MAX_IMAGE_PIXELS (1ULL << 27)
/* The most pixels on an image's side and the most frames a second: bounds
 * of the effect file (man/pfx-effect.5) that assemble checks slices'
 * manifests against too. */
#define PFX_MAX_IMAGE_SIDE 16384
#define PFX_MAX_FPS 1000.0

/* A random quantity. Constant: a. Uniform: [a, b]. Normal: mean a, standard
 * deviation b, clamped to [lo, hi]. `{mean, var}` compiles to uniform. */
typedef enum { PFX_DIST_CONST, PFX_DIST_UNIFORM, PFX_DIST_NORMAL } pfx_dist;
typedef enum {
    PFX_FORM_NUMBER,     /* 3 */
    PFX_FORM_RANGE,      /* [min, max] */
    PFX_FORM_MEAN_VAR,   /* {mean, var} */
    PFX_FORM_NORMAL,     /* {normal, clamp} */
    PFX_FORM_NORMAL_CUT3 /* {normal} without clamp: cut at 3 sd */
} pfx_value_form;
typedef struct pfx_value {
    pfx_dist dist;
    double a, b;
    double lo, hi;       /* normal only */
    pfx_value_form form; /* how it was written, for messages about its bounds */
} pfx_value;

/* v with every sample multiplied by k > 0 (degrees to radians). */
pfx_value pfx_value_scaled(pfx_value v, double k);

/* A constant value. */
static inline pfx_value pfx_value_const(double a) {
    return (pfx_value){.dist = PFX_DIST_CONST, .a = a};
}

/* Colours are linear 0..1 RGBA, straight alpha. A gradient is sampled once
 * into a lookup table over normalised age [0, 1]. */
typedef struct pfx_gradient {
    float lut[PFX_GRADIENT_LUT][4];
    bool constant; /* every entry equal: no per-particle lookup needed */
} pfx_gradient;

/* Emitter shapes, in the emitter's local frame (src/compile/compile_shape.c
 * states each one's placement; src/sim/sample.c samples them). The first
 * four keep their values; new types are appended. */
typedef enum {
#define PFX_SHAPE_ENUM(e, name) PFX_SHAPE_##e,
    PFX_SHAPE_KINDS(PFX_SHAPE_ENUM)
#undef PFX_SHAPE_ENUM
} pfx_shape_type;
/* Where on the shape births are: the solid (area for flat shapes), its
 * surface, or its rim. Zero, volume, is the default. */
typedef enum {
#define PFX_EMIT_ENUM(e, name) PFX_EMIT_##e,
    PFX_EMIT_FROM_KINDS(PFX_EMIT_ENUM)
#undef PFX_EMIT_ENUM
} pfx_emit_from;
/* Zero in a field means its default (full turn, solid, no table), so a
 * shape built as {type, radius, size} is still a whole solid shape. */
typedef struct pfx_shape {
    pfx_shape_type type;
    double radius;  /* sphere, disc, hemisphere, cylinder, cone: outer radius */
    double size[3]; /* box: full edge lengths; rect: [w (X), h (Z), 0] */
    pfx_emit_from from;
    double inner;     /* disc, sphere, hemisphere: inner radius, 0 <= inner < radius */
    double arc_turns; /* disc: the arc as a fraction of a turn, in (0, 1]; 0: full */
    double radii[2];  /* ellipse: semi-axes a (X), b (Z) */
    double line_from[3], line_to[3];
    double height; /* cylinder, cone: along +Y from the base at y = 0 */
    double angle;  /* cone: tilt of the volume normal at the rim, radians */
    /* Ellipse edge: cum[i] = arc length from t = 0 to t = 2 pi i / (count - 1).
     * Mesh: cum[i] = total area of triangles 0..i. In the compile arena. */
    const double *cum;
    uint32_t cum_count;
    /* Mesh: vertices (x, y, z) and three vertex indices per triangle. */
    const double *verts;
    const uint32_t *tris;
    /* Mesh: the OBJ's path as it was opened (relative to the working
     * directory), so that manifests and depfiles can name the input. */
    const char *file;
} pfx_shape;

/* A named force: its motion-model entry in SI units (radians, m, s). */
typedef struct pfx_force {
    const char *name;
    pfx_motion_force spec;
} pfx_force;

typedef enum {
#define PFX_BLEND_ENUM(e, name) PFX_BLEND_##e,
    PFX_BLEND_KINDS(PFX_BLEND_ENUM)
#undef PFX_BLEND_ENUM
} pfx_blend;

/* The sprite drawn for each particle (model/kinds.h). */
typedef enum {
#define PFX_SPRITE_ENUM(e, name) PFX_SPRITE_##e,
    PFX_SPRITE_KINDS(PFX_SPRITE_ENUM)
#undef PFX_SPRITE_ENUM
} pfx_sprite_kind;

typedef enum {
#define PFX_DRAW_ENUM(e, name) PFX_DRAW_##e,
    PFX_DRAW_KINDS(PFX_DRAW_ENUM)
#undef PFX_DRAW_ENUM
} pfx_draw;

typedef enum {
#define PFX_ALIGN_ENUM(e, name) PFX_ALIGN_##e,
    PFX_ALIGN_KINDS(PFX_ALIGN_ENUM)
#undef PFX_ALIGN_ENUM
} pfx_align;

typedef enum {
#define PFX_TONEMAP_ENUM(e, name) PFX_TONEMAP_##e,
    PFX_TONEMAP_KINDS(PFX_TONEMAP_ENUM)
#undef PFX_TONEMAP_ENUM
} pfx_tonemap;

typedef enum {
#define PFX_ALPHA_ENUM(e, name) PFX_ALPHA_##e,
    PFX_ALPHA_MODES(PFX_ALPHA_ENUM)
#undef PFX_ALPHA_ENUM
} pfx_alpha_mode;

/* A texture read when the effect is compiled: premultiplied RGBA, rows top
 * first, 8 or 16 bits a channel as the file had them. */
typedef struct pfx_image {
    const char *path; /* as written, relative to the effect file */
    const char *file; /* where it was read from: an input of the run's manifest */
    int width, height;
    int bits;     /* 8 or 16 */
    void *pixels; /* width * height * 4 uint8_t or uint16_t */
} pfx_image;

/* A texture sheet played over time: cells of a cols x rows grid read row
 * by row from the top left. frames 0: no flipbook. */
typedef struct pfx_flipbook {
    int cols, rows, frames;
    double fps;        /* cells per second of age; 0: the sheet plays once over life */
    bool random_start; /* each particle starts at its own cell */
    bool blend;        /* cross-fade between consecutive cells */
} pfx_flipbook;

/* How an emitter's particles are drawn beyond size and colour: the sprite
 * (built-in, or a texture), flipbook, orientation, lighting, intensity. The
 * simulation never reads it. */
typedef struct pfx_look {
    /* RIBBON: the emitter's particles are the points of strips, one per
     * parent whose trail made them, in birth order; sprite is the strip's
     * cross-section (round: soft, square: flat). */
    pfx_draw draw;
    pfx_sprite_kind sprite;
    const pfx_image *texture;    /* NULL: the built-in sprite */
    const pfx_image *normal_map; /* NULL: a spherical normal per sprite */
    pfx_flipbook flipbook;
    pfx_align align;
    double axis[3];        /* AXIS: the world axis; WORLD: the plane's normal (unit) */
    double stretch_length; /* VELOCITY: length = size * stretch_length + |v| * stretch_speed */
    double stretch_speed;  /* seconds */
    /* RIBBON: the fractions of a strip's length (from its head, the newest
     * end, and from its tail) over which width and alpha rise linearly from
     * 0; [0, 0]: none. */
    double ribbon_taper[2];
    bool lit;
    /* A turn uniform over a full turn per particle on top of `angle`, from
     * the particle's own hash: the default for sheets with no up (compile
     * decides; man pfx-effect(5), angle). */
    bool random_angle;
    bool intensity_curve;                  /* intensity over life from intensity_lut */
    float intensity;                       /* else this constant */
    float intensity_lut[PFX_GRADIENT_LUT]; /* multiplies the colour, not alpha */
} pfx_look;

/* Sub-emitters: an event of a parent particle that makes particles of
 * another (or the same) emitter at the particle's place and time. */
typedef enum {
#define PFX_SPAWN_ENUM(e, name) PFX_SPAWN_##e,
    PFX_SPAWN_EVENTS(PFX_SPAWN_ENUM)
#undef PFX_SPAWN_ENUM
} pfx_spawn_event;
typedef struct pfx_spawn {
    pfx_spawn_event event;
    uint32_t target; /* emitter index */
    pfx_value count; /* particles per event (trail: 1 per birth) */
    double rate;     /* trail: births per second of the particle's life */
    double probability;
    bool inherit_velocity, inherit_color, inherit_size;
    uint32_t depth; /* generations allowed through it (0: no limit; required in cycles) */
} pfx_spawn;

/* How a particle's colour is chosen: from the gradient by its age, or once
 * at birth (a random mix of two colours, or a random point of a gradient). */
typedef enum { PFX_COLOR_OVER_LIFE, PFX_COLOR_RANDOM, PFX_COLOR_PICK } pfx_color_mode;

/* A piecewise-linear function through (t[i], v[i]), t increasing; held
 * constant before the first key and after the last. */
typedef struct pfx_curve {
    size_t count;
    double *t, *v;
    double *integral; /* integral from t[0] to t[i] (rate curves only) */
} pfx_curve;

/* How an emitter spaces its births in its own time tau (seconds since its
 * start, within the period when it loops). */
/* Constant: births at k / rate. Curve: rate(tau) piecewise linear, births
 * where its integral crosses k. Ramp (Reeves): rate = initial + delta * tau,
 * stopping at 0. Random (Reeves mean +- var): each whole second has its own
 * rate. Interval: the time to the next birth is a random value. */
typedef enum {
#define PFX_RATE_ENUM(e, name) PFX_RATE_##e,
    PFX_RATE_KINDS(PFX_RATE_ENUM)
#undef PFX_RATE_ENUM
} pfx_rate_kind;

typedef struct pfx_burst {
    double time;        /* emitter time of the first burst */
    pfx_value count;    /* particles per burst */
    uint32_t cycles;    /* bursts, >= 1 */
    double interval;    /* seconds between cycles */
    double probability; /* each cycle fires with this probability */
} pfx_burst;

/* Keyframed vectors (position metres, rotation radians), linear between keys. */
typedef struct pfx_keys3 {
    size_t count; /* 0: not animated */
    double *t;
    double (*v)[3];
} pfx_keys3;

/* `direction: [x, y, z]`, or by name: the shape's outward surface normal at
 * the birth point, away from the shape's centre, or towards it. */
typedef enum {
    PFX_DIRECTION_VECTOR,
#define PFX_DIRECTION_ENUM(e, name) PFX_DIRECTION_##e,
    PFX_DIRECTION_MODES(PFX_DIRECTION_ENUM)
#undef PFX_DIRECTION_ENUM
} pfx_direction_mode;

typedef struct pfx_emitter {
    const char *name;
    pfx_shape shape;
    double position[3];
    double rotation[9]; /* row-major, from rotation angles X then Y then Z */
    pfx_rate_kind rate_kind;
    double rate;                     /* CONSTANT: per second; RANDOM: the mean */
    double rate_var;                 /* RANDOM: rates are uniform in rate +- rate_var */
    double ramp_initial, ramp_delta; /* RAMP: per second, per second^2 */
    pfx_curve rate_curve;            /* CURVE: per second over emitter time */
    pfx_value interval;              /* INTERVAL: seconds */
    size_t burst_count;
    pfx_burst *bursts;
    double start;        /* effect time the emitter starts */
    double duration;     /* seconds it emits (INFINITY: to the end); the period when looping */
    bool loop;           /* repeat the emission pattern every `duration` */
    double horizon;      /* emitter time past which nothing is ever shown (the effect's end) */
    double direction[3]; /* unit, in the emitter's frame (rotated at birth) */
    pfx_direction_mode direction_mode;
    double spread;                    /* cone half-angle, radians */
    bool spread_two_angle;            /* `spread: [alpha, beta]`: the thesis's two angles */
    double spread_alpha, spread_beta; /* radians */
    pfx_value distance;               /* birth offset along the direction, metres */
    double inherit_velocity;          /* fraction of the emitter's velocity added */
    pfx_keys3 position_keys;          /* animated `position` (else `position` holds) */
    pfx_keys3 rotation_keys;          /* animated `rotation`, radians */
    double lod_area;   /* `lod`: the emitter's area on screen in pixels (0: no lod) */
    double key_period; /* > 0: keyframes repeat with this period (a looping effect) */
    pfx_value speed;
    pfx_value lifetime;
    double max_lifetime; /* upper bound of `lifetime` */
    pfx_value size_start;
    pfx_value size_end;
    bool size_same;     /* `size` given as one value: end equals start */
    bool size_varies;   /* start or end random: per-particle columns */
    pfx_gradient color; /* over life (OVER_LIFE), or the gradient PICK draws from */
    pfx_color_mode color_mode;
    float color_a[4], color_b[4]; /* RANDOM: each particle is a fixed mix of the two */
    bool size_curve;              /* size over life from size_lut, not start/end */
    float size_lut[PFX_GRADIENT_LUT];
    pfx_value angle; /* sprite angle at birth, radians */
    pfx_value spin;  /* radians per second (constant over life unless spin_curve) */
    bool spin_curve; /* spin over life: angle = angle0 + lifetime * spin_turn_lut[u] */
    float spin_turn_lut[PFX_GRADIENT_LUT]; /* integral of spin over normalised age */
    pfx_look look;
    bool alpha_curve; /* alpha_lut multiplies the colour's alpha */
    float alpha_lut[PFX_GRADIENT_LUT];
    uint32_t force_mask; /* bit i: feels effect->forces[i] */
    pfx_value gravity_scale;
    pfx_value charge; /* coulomb, for magnetic forces */
    pfx_value mass;   /* kg, for magnetic forces (others are per unit mass) */
    double accel[3];  /* sum of the gravities it feels (before gravity_scale) */
    /* NULL when the emitter feels only gravity under the `auto` integrator:
     * then the exact constant-acceleration kernel runs. Otherwise the forces
     * it feels and the integrator, prepared for dt = 1 / sim.rate. */
    pfx_motion *motion;
    size_t deflector_count; /* the deflectors it hits (`deflectors:`, default all) */
    pfx_deflector *deflectors;
    bool sticks;        /* some deflector of it sticks: a per-particle stuck flag */
    size_t spawn_count; /* its sub-emitters (on_birth, on_death, on_hit, trail) */
    pfx_spawn *spawns;
    double spawned_rate;   /* worst-case births per second it receives from parents */
    double spawned_peak;   /* worst-case of those alive at once (pool sizing) */
    bool keeps_generation; /* in a cycle of sub-emitters: a generation column */
    bool keeps_parent_color, keeps_size_scale; /* some parent passes colour / size */
    uint32_t ribbon_parent; /* draw: ribbon: the emitter whose trail lays its points */
    pfx_blend blend;
    pfx_kill_rules *kill;                 /* kill rules and bounds; NULL: age alone kills */
    float alpha_at_age[PFX_GRADIENT_LUT]; /* alpha over life, for alpha_below */
    uint32_t capacity;   /* pool size: floor(rate * max_lifetime) + 1, budget-capped */
    bool saturates;      /* capacity was cut by the particle budget */
    bool motion_vectors; /* drawn into --motion-vectors' pass and its scale (the default) */
} pfx_emitter;

typedef struct pfx_camera {
    double position[3];
    double target[3];
    double up[3];
    bool ortho;
    double fov;          /* perspective: vertical field of view, radians */
    double ortho_height; /* ortho: view height in metres */
} pfx_camera;

/* What makes a camera unusable: its view has no direction, or its up vector
 * gives no sideways axis. */
typedef enum pfx_camera_fault {
    PFX_CAMERA_OK,
    PFX_CAMERA_SAME_POINT,  /* |target - position| <= 1e-12 m */
    PFX_CAMERA_UP_PARALLEL, /* |forward x up| <= 1e-12 */
} pfx_camera_fault;

/* The camera's orthonormal frame, right-handed as OpenGL's lookAt builds
 * it: forward from position to target, side = forward x up, up = side x
 * forward (each written only when the result is PFX_CAMERA_OK). */
pfx_camera_fault pfx_camera_frame(const pfx_camera *cam, double side[3], double up[3],
                                  double forward[3]);

/* Where world point p lands in a width x height image seen through cam, as
 * the renderer projects it: px[0] from the left edge, px[1] up from the
 * bottom edge, in pixels; *depth is the distance along the view direction
 * (perspective) or 1 (ortho). False, with px unset, for a degenerate
 * camera or a point not in front of it (depth <= 1e-6). */
bool pfx_camera_project(const pfx_camera *cam, int width, int height, const double p[3],
                        double px[2], double *depth);

/* Pixels one metre spans on screen at world point p, seen through cam in
 * an image `height` pixels tall: height / (2 tan(fov / 2) depth) for a
 * perspective camera (depth along the view direction), height /
 * ortho_height for an orthographic one. 0 for a point at or behind the
 * camera. */
double pfx_camera_pixels_per_metre(const pfx_camera *cam, int height, const double p[3]);

typedef struct pfx_effect {
    const char *path; /* the file it came from */
    double duration;
    double fps;
    uint64_t seed;
    double sim_rate; /* steps per second */
    double prewarm;
    bool loop;                 /* seamless: every emitter repeats with period `duration` */
    long loop_frames;          /* frames in one period (duration x fps, whole) */
    double loop_start;         /* simulation time of frame 0 when looping */
    pfx_integrator integrator; /* sim.integrator; emitters may override */
    double tolerance;          /* sim.tolerance, m per simulated second */
    double tolerance_px;       /* sim.tolerance given in pixels (> 0), else 0 */
    int substeps;              /* sim.substeps; 0: auto */
    pfx_camera camera;
    int width, height;
    float background[4]; /* straight RGBA 0..1 */
    double exposure;     /* EV: colours times 2^exposure before the tone curve */
    pfx_tonemap tonemap;
    double preserve_hue; /* 0..1: per-channel curve (0) to hue-keeping (1) */
    pfx_alpha_mode alpha_mode;
    bool dither;          /* before 8-bit quantisation */
    double shutter;       /* motion blur: open fraction of the frame interval (0: none) */
    int blur_samples;     /* sub-frame times per frame, >= 1 */
    bool has_light;       /* `light:` given (lit emitters need it) */
    double light_dir[3];  /* unit: the direction the light travels */
    float light_color[3]; /* linear, may exceed 1 */
    float light_ambient[3];
    bool light_shadows;    /* lit sprites darkened by the particles towards the light */
    double shadow_density; /* multiplies the casters' optical depth */
    size_t force_count;
    pfx_force *forces;
    size_t deflector_count;
    pfx_deflector *deflectors;
    size_t emitter_count;
    pfx_emitter *emitters;
    uint64_t max_particles;
    int threads; /* simulation threads (--threads, PFX_THREADS); 0: the machine's cores.
                    A run setting, not the effect's: the output is the same for any */
} pfx_effect;

/* Upper bound of a value's samples. */
double pfx_value_max(const pfx_value *v);
/* Lower bound of a value's samples. */
double pfx_value_min(const pfx_value *v);

/* Frames in the whole effect: round(duration * fps), at least 1. */
long pfx_effect_frame_count(const pfx_effect *e);

/* ---- Emission bounds (model/emission.c) ---- */

/* Births per second the emitter can reach at most (for pool sizing). */
double pfx_emitter_max_rate(const pfx_emitter *em);

/* The most particles the emitter can have alive at once (pool size before
 * the budget): continuous births within one maximum lifetime plus every
 * burst that can overlap them. */
double pfx_emitter_peak(const pfx_emitter *em);

/* The expected number of continuous births in emitter time [0, tau] of one
 * period: the integral of the rate (not for INTERVAL or RANDOM). */
double pfx_emitter_births_by(const pfx_emitter *em, double tau);

/* ---- Emitter placement (model/pose.c) ---- */

/* The emitter's placement at effect time t: position, rotation matrix and
 * the velocity of its keyframed motion. */
typedef struct emitter_pose {
    double position[3], rotation[9], velocity[3];
} emitter_pose;

/* Rotation angles (x, y, z) in radians -> row-major R = Rz * Ry * Rx: a
 * point is turned about X first, then Y, then Z, all about the fixed world
 * axes. */
void pfx_rotation_from_angles(const double rad[3], double m[9]);

void pfx_emitter_pose_at(const pfx_emitter *em, double t, emitter_pose *p);

#endif
