/* Every vocabulary of the effect format, declared once. Each table is an
 * X-macro: X(ENUM_SUFFIX, "name", ...) per kind, in enum order. The enum, the
 * NULL-terminated name list that the reader matches (and suggests from and
 * lists in "expected one of"), `pfx info` and the JSON Schema all expand
 * from the one row, so a new kind is a new row here plus its code. */
#ifndef PFX_MODEL_KINDS_H
#define PFX_MODEL_KINDS_H

#include <stdbool.h>
#include <stddef.h>

/* Forces: X(ENUM, name, word in messages, what it is) */
#define PFX_FORCE_KINDS(X)                                                                         \
    X(GRAVITY, "gravity", "gravity", "uniform acceleration")                                       \
    X(ATTRACTOR, "attractor", "attractor", "a point that pulls (or pushes)")                       \
    X(DRAG, "drag", "drag", "linear and quadratic drag towards a wind")                            \
    X(VORTEX, "vortex", "vortex", "turns positions about an axis (Sims)")                          \
    X(MAGNETIC, "magnetic", "magnetic force", "Lorentz force q (E + v x B)")                       \
    X(SPIRAL, "spiral", "spiral", "turns velocities about an axis")                                \
    X(SPRING, "spring", "spring", "pulls towards an anchor")                                       \
    X(TURBULENCE, "turbulence", "turbulence", "divergence-free curl noise")                        \
    X(SPEED_LIMIT, "speed_limit", "speed limit", "clamps the speed")                               \
    X(FORCE_OVER_LIFE, "force_over_life", "force over life",                                       \
      "an acceleration over the particle's normalised age")

/* Integrators: X(ENUM, name, order or "exact", use) */
#define PFX_INTEGRATOR_KINDS(X)                                                                    \
    X(AUTO, "auto", "-", "chosen per emitter from the forces it feels")                            \
    X(EULER, "euler", "1", "explicit Euler, for comparisons")                                      \
    X(SYMPLECTIC, "symplectic", "1", "semi-implicit Euler")                                        \
    X(MIDPOINT, "midpoint", "2", "explicit midpoint (RK2)")                                        \
    X(RK4, "rk4", "4", "classical Runge-Kutta")                                                    \
    X(VERLET, "verlet", "2", "velocity Verlet")                                                    \
    X(EXACT, "exact", "exact", "closed form for gravity and linear drag")                          \
    X(BORIS, "boris", "2", "split step with the Boris rotation")

/* Emitter shapes: X(ENUM, name), in the order messages list them. */
#define PFX_SHAPE_KINDS(X)                                                                         \
    X(POINT, "point")                                                                              \
    X(LINE, "line")                                                                                \
    X(RECT, "rect")                                                                                \
    X(DISC, "disc")                                                                                \
    X(ELLIPSE, "ellipse")                                                                          \
    X(BOX, "box")                                                                                  \
    X(SPHERE, "sphere")                                                                            \
    X(HEMISPHERE, "hemisphere")                                                                    \
    X(CYLINDER, "cylinder")                                                                        \
    X(CONE, "cone")                                                                                \
    X(MESH, "mesh")

/* Where on a shape births are. */
#define PFX_EMIT_FROM_KINDS(X)                                                                     \
    X(VOLUME, "volume")                                                                            \
    X(SURFACE, "surface")                                                                          \
    X(EDGE, "edge")

/* Deflector shapes and responses. */
#define PFX_DEFLECTOR_KINDS(X)                                                                     \
    X(PLANE, "plane")                                                                              \
    X(DISC, "disc")                                                                                \
    X(SPHERE, "sphere")                                                                            \
    X(BOX, "box")
#define PFX_DEFLECT_RESPONSES(X)                                                                   \
    X(BOUNCE, "bounce")                                                                            \
    X(KILL, "kill")                                                                                \
    X(STICK, "stick")

/* Kill rules (the key of a `kill:` entry) and their regions. */
#define PFX_KILL_KINDS(X)                                                                          \
    X(INSIDE, "inside")                                                                            \
    X(OUTSIDE, "outside")                                                                          \
    X(ALPHA_BELOW, "alpha_below")                                                                  \
    X(DISTANCE, "distance_from_emitter")
#define PFX_KILL_SHAPES(X)                                                                         \
    X(BOX, "box")                                                                                  \
    X(SPHERE, "sphere")                                                                            \
    X(HALF_SPACE, "half_space")
#define PFX_BOUNDS_MODES(X)                                                                        \
    X(NONE, "none")                                                                                \
    X(KILL, "kill")                                                                                \
    X(WRAP, "wrap")

/* Sub-emitter events: X(ENUM, key) */
#define PFX_SPAWN_EVENTS(X)                                                                        \
    X(BIRTH, "on_birth")                                                                           \
    X(DEATH, "on_death")                                                                           \
    X(HIT, "on_hit")                                                                               \
    X(TRAIL, "trail")

/* Blend modes and sprite kinds. */
#define PFX_BLEND_KINDS(X)                                                                         \
    X(ADD, "add")                                                                                  \
    X(ALPHA, "alpha")
#define PFX_SPRITE_KINDS(X)                                                                        \
    X(ROUND, "round")                                                                              \
    X(SQUARE, "square")                                                                            \
    X(SPARK, "spark")                                                                              \
    X(SMOKE, "smoke")                                                                              \
    X(FLARE, "flare")                                                                              \
    X(RING, "ring")

/* What an emitter draws: a sprite per particle, or (for an emitter fed by a
 * `trail`) one connected strip per parent through its trail particles. */
#define PFX_DRAW_KINDS(X)                                                                          \
    X(SPRITE, "sprite")                                                                            \
    X(RIBBON, "ribbon")

/* How a sprite faces: the camera, its screen-space velocity (stretched), a
 * fixed world axis it turns about (axial billboard), or a fixed plane. */
#define PFX_ALIGN_KINDS(X)                                                                         \
    X(CAMERA, "camera")                                                                            \
    X(VELOCITY, "velocity")                                                                        \
    X(AXIS, "axis")                                                                                \
    X(WORLD, "world")

/* The output image: tone curves and alpha conventions. */
#define PFX_TONEMAP_KINDS(X)                                                                       \
    X(NONE, "none")                                                                                \
    X(REINHARD, "reinhard")                                                                        \
    X(ACES, "aces")
#define PFX_ALPHA_MODES(X)                                                                         \
    X(STRAIGHT, "straight")                                                                        \
    X(PREMULTIPLIED, "premultiplied")

/* Attractor falloffs, direction modes (beside a vector), the frames a
 * force's vectors may be given in, region shapes. */
#define PFX_FALLOFF_KINDS(X)                                                                       \
    X(INVERSE_SQUARE, "inverse_square")                                                            \
    X(LINEAR, "linear")                                                                            \
    X(CONSTANT, "constant")
#define PFX_DIRECTION_MODES(X)                                                                     \
    X(NORMAL, "normal")                                                                            \
    X(RADIAL, "radial")                                                                            \
    X(INWARD, "inward")                                                                            \
    X(TANGENT, "tangent")
#define PFX_FORCE_SPACES(X)                                                                        \
    X(WORLD, "world")                                                                              \
    X(EMITTER, "emitter")
#define PFX_REGION_KINDS(X)                                                                        \
    X(SPHERE, "sphere")                                                                            \
    X(BOX, "box")

/* Rate forms, for `pfx info`. */
#define PFX_RATE_KINDS(X)                                                                          \
    X(CONSTANT, "constant")                                                                        \
    X(CURVE, "curve")                                                                              \
    X(RAMP, "ramp")                                                                                \
    X(RANDOM, "mean +- var")                                                                       \
    X(INTERVAL, "interval")

/* The NULL-terminated name list of each table (model/kinds.c), for the
 * readers, suggestions, messages, `pfx info` and the schema. */
extern const char *const pfx_force_names[];
extern const char *const pfx_force_words[];
extern const char *const pfx_force_docs[];
extern const char *const pfx_integrator_names[];
extern const char *const pfx_integrator_orders[];
extern const char *const pfx_shape_names[];
extern const char *const pfx_emit_from_names[];
extern const char *const pfx_deflector_names[];
extern const char *const pfx_deflect_response_names[];
extern const char *const pfx_kill_names[];
extern const char *const pfx_kill_shape_names[];
extern const char *const pfx_bounds_mode_names[];
extern const char *const pfx_spawn_event_names[];
extern const char *const pfx_blend_names[];
extern const char *const pfx_sprite_names[];
extern const char *const pfx_draw_names[];
extern const char *const pfx_align_names[];
extern const char *const pfx_tonemap_names[];
extern const char *const pfx_alpha_mode_names[];
extern const char *const pfx_falloff_names[];
extern const char *const pfx_direction_mode_names[];
extern const char *const pfx_force_space_names[];
extern const char *const pfx_region_names[];
extern const char *const pfx_rate_kind_names[];

/* The names as a list for a message: "a, b, c" (or_style false) or
 * "a, b or c" (true), cut to fit buf. */
void pfx_kind_list(const char *const *names, bool or_style, char *buf, size_t size);

/* names[i] if i is within the NULL-terminated list, else "?". */
const char *pfx_kind_name(const char *const *names, int i);
/* The index of s in the NULL-terminated list, or -1. */
int pfx_kind_find(const char *const *names, const char *s);
/* How many names the list holds. */
size_t pfx_kind_count(const char *const *names);

#endif
