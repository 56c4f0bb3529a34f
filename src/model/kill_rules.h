/* Death conditions besides old age, and wrapping bounds, as the compiled
 * effect holds them (an emitter's `kill:` and `bounds:`); the simulation
 * applies them (sim/kill.h). */
#ifndef PFX_MODEL_KILL_RULES_H
#define PFX_MODEL_KILL_RULES_H

#include <stdbool.h>
#include <stddef.h>

#include "model/kinds.h"

/* A `kill:` list longer than this is a compile error. */
#define PFX_KILL_MAX_RULES 16
/* Entries of the alpha-at-age table pfx_kill_apply reads (PFX_GRADIENT_LUT). */
#define PFX_KILL_ALPHA_LUT 256

/* Rules (model/kinds.h): inside (dies inside the region, boundary
 * included), outside (dies outside it, boundary survives), alpha_below
 * (dies when its over-life alpha < threshold), distance_from_emitter (dies
 * farther than threshold metres from the emitter). */
typedef enum {
#define PFX_KILL_ENUM(e, name) PFX_KILL_##e,
    PFX_KILL_KINDS(PFX_KILL_ENUM)
#undef PFX_KILL_ENUM
} pfx_kill_kind;

/* Regions: box (axis-aligned, |x - center| <= half per axis), sphere
 * (|x - center| <= radius), half_space ((x - center) . normal >= 0). */
typedef enum {
#define PFX_KILL_SHAPE_ENUM(e, name) PFX_KILL_##e,
    PFX_KILL_SHAPES(PFX_KILL_SHAPE_ENUM)
#undef PFX_KILL_SHAPE_ENUM
} pfx_kill_shape;

/* One rule, flat: the compiler fills only what its kind and shape read.
 * World space, metres. */
typedef struct pfx_kill_rule {
    pfx_kill_kind kind;
    pfx_kill_shape shape; /* INSIDE, OUTSIDE */
    double center[3];     /* box, sphere: centre; half-space: a point on the plane */
    double half[3];       /* box: half edge lengths, >= 0 */
    double radius;        /* sphere: > 0 */
    double normal[3];     /* half-space: unit */
    double threshold;     /* ALPHA_BELOW: alpha in [0, 1]; DISTANCE: metres > 0 */
} pfx_kill_rule;

/* Zero means default: no bounds. */
typedef enum {
#define PFX_BOUNDS_ENUM(e, name) PFX_BOUNDS_##e,
    PFX_BOUNDS_MODES(PFX_BOUNDS_ENUM)
#undef PFX_BOUNDS_ENUM
} pfx_bounds_mode;

/* An emitter's `bounds:` and `kill:` together (about 1.6 KB; one per emitter
 * that has either, in the effect's arena). The bounds box is the float box
 * [(float)(center - half), (float)(center + half)] per axis: KILL removes a
 * particle outside the closed box; WRAP maps each coordinate into the
 * half-open box [lo, hi) (a particle leaving through one face re-enters at the
 * opposite one, velocity unchanged). */
typedef struct pfx_kill_rules {
    pfx_bounds_mode bounds;
    double bounds_center[3];
    double bounds_half[3]; /* > 0 on every axis under WRAP */
    size_t count;
    pfx_kill_rule rules[PFX_KILL_MAX_RULES];
} pfx_kill_rules;

/* True when k has no bounds and no rule: the caller keeps no rules (NULL) and
 * never calls pfx_kill_apply. */
bool pfx_kill_rules_empty(const pfx_kill_rules *k);
/* True when some rule reads the alpha-at-age table (alpha_below). */
bool pfx_kill_needs_alpha(const pfx_kill_rules *k);

#endif
