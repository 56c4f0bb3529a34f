/* Death conditions besides old age, and wrapping bounds (REFERENCE.md §1
 * step 1, §10 snow). The compiler fills a pfx_kill_rules per emitter
 * (src/compile/compile_kill.c); after each integration the simulation calls
 * pfx_kill_apply, which wraps positions into a wrapping box and marks the
 * particles a rule kills by setting lifetime = PFX_KILLED, so the existing
 * age >= lifetime swap-remove pass removes them: no second compaction. */
#ifndef PFX_KILL_H
#define PFX_KILL_H

#include <stdbool.h>
#include <stddef.h>

/* Declared in sim/sim.h; repeated here so that effect.h can include this
 * header without a cycle (a repeated typedef is valid C11). */
typedef struct pfx_pool pfx_pool;

/* A `kill:` list longer than this is a compile error. */
#define PFX_KILL_MAX_RULES 16
/* Entries of the alpha-at-age table pfx_kill_apply reads (PFX_GRADIENT_LUT). */
#define PFX_KILL_ALPHA_LUT 256

typedef enum {
    PFX_KILL_INSIDE = 0,  /* dies inside the region (boundary included) */
    PFX_KILL_OUTSIDE,     /* dies outside the region (boundary survives) */
    PFX_KILL_ALPHA_BELOW, /* dies when its over-life alpha < threshold */
    PFX_KILL_DISTANCE     /* dies farther than threshold metres from the emitter */
} pfx_kill_kind;

typedef enum {
    PFX_KILL_BOX = 0,   /* axis-aligned: |x - center| <= half per axis */
    PFX_KILL_SPHERE,    /* |x - center| <= radius */
    PFX_KILL_HALF_SPACE /* (x - center) . normal >= 0: the side the normal points to */
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
typedef enum { PFX_BOUNDS_NONE = 0, PFX_BOUNDS_KILL, PFX_BOUNDS_WRAP } pfx_bounds_mode;

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

/* Wraps (bounds WRAP) then marks (bounds KILL and each rule, in list order;
 * regions test the wrapped positions) the live particles of p, one pass per
 * rule, never allocating: a particle to die gets lifetime = PFX_KILLED and stays in
 * place for the age >= lifetime pass to remove. `emitter_pos` is the
 * emitter's world position at the time of the check (read by
 * distance_from_emitter only; may be NULL otherwise). `alpha_at_age[k]` is
 * the particle's alpha at normalised age k / (PFX_KILL_ALPHA_LUT - 1), looked
 * up at the nearest entry as pfx_particle_color does (read by alpha_below
 * only; may be NULL otherwise). Positions and lifetimes are written in place;
 * nothing else is touched. */
void pfx_kill_apply(const pfx_kill_rules *k, pfx_pool *p, const double emitter_pos[3],
                    const float alpha_at_age[PFX_KILL_ALPHA_LUT]);

/* One coordinate x mapped into the half-open float interval [lo, hi)
 * (lo < hi): lo + (x - lo) mod (hi - lo), the remainder taken exactly, the
 * result the nearest float to it, and hi itself (reached by round-off or
 * exactly) identified with lo. Always lo <= result < hi. */
float pfx_kill_wrap(float x, float lo, float hi);

#endif
