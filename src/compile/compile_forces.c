/* The `forces:` entries: one key table per force kind (its keys, defaults,
 * ranges and units, degrees becoming radians), compiled into a
 * pfx_motion_force in SI units. It does not decide which emitter feels
 * what or which integrator runs; compile.c does. */
#include "compile/compile_forces.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "base/hash.h"
#include "compile/keys.h"

#define F(field) offsetof(pfx_motion_force, field)
#define R(field) offsetof(pfx_motion_region, field)

/* ---- Hooks: keys that need code ---- */

/* A unit axis; the zero vector is an error. */
static void read_axis(pfx_reader *r, const pfx_node *map, const pfx_node *n, void *dest) {
    (void)map;
    pfx_motion_force *m = dest;
    double v[3];
    if (!pfx_read_numbers(r, n, "axis", v, 3))
        return;
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len == 0) {
        pfx_read_error(r, n, PFX_RULE_ZERO_VECTOR, "'axis' must not be the zero vector");
        return;
    }
    for (int i = 0; i < 3; i++)
        m->axis[i] = v[i] / len;
}

/* A spring's anchor: a point, or `birth` (each particle's birth place). */
static void read_anchor(pfx_reader *r, const pfx_node *map, const pfx_node *n, void *dest) {
    pfx_motion_force *m = dest;
    if (n->kind == PFX_NODE_SCALAR && !strcmp(n->text, "birth"))
        m->use_birth = true;
    else if (n->kind != PFX_NODE_SEQ)
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE, "'anchor' must be a point [x, y, z] or 'birth'");
    else if (pfx_read_vec3_within(r, map, "anchor", m->center, 1e6))
        m->use_birth = false;
}

/* force_over_life's `accel`: a vector (constant over life) or keys
 * [{at: u, value: [x, y, z]}, ...] over normalised age. */
static void read_life_accel(pfx_reader *r, const pfx_node *map, const pfx_node *n, void *dest) {
    (void)map;
    pfx_motion_force *m = dest;
    pfx_life_curve *c = pfx_arena_alloc(r->arena, sizeof *c);
    if (!c)
        return;
    memset(c, 0, sizeof *c);
    if (n->kind == PFX_NODE_SEQ && n->count > 0 && n->items[0]->kind == PFX_NODE_MAP) {
        pfx_key_list_spec spec = {"accel", "at", PFX_LIFE_CURVE_MAX_KEYS, 3, false, 0, 1,
                                  -1e6,    1e6};
        if (!pfx_read_key_list(r, n, &spec, c->at, &c->accel[0][0]))
            return;
        c->count = n->count;
    } else {
        if (!pfx_read_numbers(r, n, "accel", c->accel[0], 3))
            return;
        for (int a = 0; a < 3; a++)
            if (!pfx_check_above(r, n, "accel", c->accel[0][a], -1e6, false) ||
                !pfx_check_below(r, n, "accel", c->accel[0][a], 1e6, false))
                return;
        c->count = 1;
    }
    m->life = c;
}

static const pfx_key sphere_region_keys[] = {
    {"type", PFX_KEY_CODE, .offset = -1, .doc = "sphere"},
    {"center", PFX_KEY_VEC3, .hi = 1e6, .offset = R(center), .doc = "Its centre (m)."},
    {"radius", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .def = {1}, .offset = R(radius),
     .doc = "Its radius (m), 0 to 1e6."},
    {"falloff", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = R(falloff),
     .doc = "Metres over which the force fades to zero outside it (0: a hard edge)."},
};
static PFX_KEY_TABLE(sphere_region, "region_sphere", "sphere",
                     "A sphere where the force acts at full strength.", sphere_region_keys);

/* A box region's size is its full edges, kept as half edges. */
static void read_region_size(pfx_reader *r, const pfx_node *map, const pfx_node *sz, void *dest) {
    (void)map;
    pfx_motion_region *g = dest;
    double size[3];
    if (!pfx_read_numbers(r, sz, "size", size, 3))
        return;
    for (int i = 0; i < 3; i++) {
        if (size[i] < 0)
            pfx_read_error(r, sz->items[i], PFX_RULE_OUT_OF_RANGE,
                           "region 'size' must be at least 0, got %g", size[i]);
        g->half[i] = size[i] / 2;
    }
}

static const pfx_key box_region_keys[] = {
    {"type", PFX_KEY_CODE, .offset = -1, .doc = "box"},
    {"center", PFX_KEY_VEC3, .hi = 1e6, .offset = R(center), .doc = "Its centre (m)."},
    {"size", PFX_KEY_CODE, .offset = -1, .hook = read_region_size,
     .schema = "{\"$ref\": \"#/$defs/vec3\", \"default\": [1, 1, 1]}",
     .doc = "Its edge lengths along x, y, z (m), each at least 0."},
    {"falloff", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = R(falloff),
     .doc = "Metres over which the force fades to zero outside it (0: a hard edge)."},
};
static PFX_KEY_TABLE(box_region, "region_box", "box",
                     "An axis-aligned box where the force acts at full strength.", box_region_keys);

/* In the order of PFX_REGION_KINDS. */
static const pfx_key_table *const region_tables[] = {&sphere_region, &box_region};

static void read_region(pfx_reader *r, const pfx_node *map, const pfx_node *n, void *dest) {
    (void)map;
    pfx_motion_region *out = &((pfx_motion_force *)dest)->region;
    if (!pfx_read_map(r, n, "region"))
        return;
    int k = pfx_keys_kind(r, n, n, "a region", "region type", pfx_region_names, false);
    if (k < 0)
        return;
    const pfx_key_table *t = region_tables[k];
    out->kind = (pfx_region_kind)(PFX_REGION_SPHERE + k);
    pfx_keys_check(r, n, t, "a region");
    out->half[0] = out->half[1] = out->half[2] = 0.5;
    pfx_keys_defaults(t, out);
    pfx_keys_read(r, n, t, out);
}

/* ---- The tables, one per force kind ---- */

#define TYPE_ROW                                                                                   \
    { "type", PFX_KEY_CODE, .offset = -1, .doc = "The force type." }
#define REGION_ROW                                                                                 \
    {                                                                                              \
        "region", PFX_KEY_CODE, .offset = -1, .hook = read_region,                                 \
                                .schema = "{\"$ref\": \"#/$defs/region\"}",                        \
                                .doc = "Restrict the force to a sphere or box, with a falloff."    \
    }

static const pfx_key gravity_keys[] = {
    TYPE_ROW,
    {"accel", PFX_KEY_VEC3, .hi = 1e6, .def = {0, -9.81, 0}, .offset = F(accel),
     .doc = "Acceleration in m/s^2, each component within +-1e6."},
    REGION_ROW,
};
static const pfx_key attractor_keys[] = {
    TYPE_ROW,
    {"center", PFX_KEY_VEC3, .hi = 1e6, .offset = F(center),
     .doc = "A point in metres, each component within +-1e6."},
    {"strength", PFX_KEY_NUMBER, .lo = -1e9, .hi = 1e9, .def = {1}, .offset = F(strength),
     .doc = "m^3/s^2 (GM) for inverse_square; -1e9 to 1e9; negative repels."},
    {"softening", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = F(softening),
     .doc = "Plummer softening radius in metres, 0 to 1e6."},
    {"falloff", PFX_KEY_ENUM, .offset = F(falloff), .names = pfx_falloff_names, .what = "falloff",
     .doc = "inverse_square (s/r^2), linear (s/(L r)) or constant (s/L^2), L = reference_radius."},
    {"radius", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = F(radius),
     .doc = "Cut-off in metres: no force beyond it; 0: none."},
    {"reference_radius", PFX_KEY_NUMBER, .lo = 1e-6, .hi = 1e6, .def = {1}, .offset = F(ref_radius),
     .doc = "L in metres of the linear and constant falloffs (all three agree at r = L), 1e-6 to "
            "1e6."},
    REGION_ROW,
};
static const pfx_key drag_keys[] = {
    TYPE_ROW,
    {"k", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .def = {1}, .offset = F(k),
     .doc = "Linear drag in 1/s, 0 to 1e6 (default 1, or 0 when only c is given)."},
    {"c", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = F(c),
     .doc = "Quadratic drag in 1/m, 0 to 1e6."},
    {"wind", PFX_KEY_VEC3, .hi = 1e6, .offset = F(wind),
     .doc = "The fluid's velocity in m/s, each within +-1e6."},
    REGION_ROW,
};
static const pfx_key vortex_keys[] = {
    TYPE_ROW,
    {"center", PFX_KEY_VEC3, .hi = 1e6, .offset = F(center),
     .doc = "A point in metres, each component within +-1e6."},
    {"axis", PFX_KEY_VEC3, PFX_KEY_NONZERO, .def = {0, 1, 0}, .offset = F(axis), .hook = read_axis,
     .doc = "The axis direction (any length, not [0, 0, 0])."},
    {"strength", PFX_KEY_NUMBER, PFX_KEY_DEGREES, .lo = -1e6, .hi = 1e6, .def = {90},
     .offset = F(strength), .doc = "Degrees per second of rotation at the axis, -1e6 to 1e6."},
    {"radius", PFX_KEY_NUMBER, .lo = 1e-6, .hi = 1e6, .def = {1}, .offset = F(radius),
     .doc = "Radius in metres where the falloff reaches 0, 1e-6 to 1e6."},
    {"d", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = F(sims_d),
     .doc = "The falloff's d, 0 to 1e6."},
    {"inflow", PFX_KEY_NUMBER, .lo = -1e6, .hi = 1e6, .offset = F(inflow),
     .doc = "m/s towards the axis, times f(r); -1e6 to 1e6."},
    REGION_ROW,
};
static const pfx_key magnetic_keys[] = {
    TYPE_ROW,
    {"field", PFX_KEY_VEC3, .hi = 1e6, .def = {0, 1, 0}, .offset = F(field),
     .doc = "Magnetic field B in tesla, each within +-1e6."},
    {"electric", PFX_KEY_VEC3, .hi = 1e9, .offset = F(electric),
     .doc = "Electric field E in V/m, each within +-1e9."},
    REGION_ROW,
};
static const pfx_key spiral_keys[] = {
    TYPE_ROW,
    {"center", PFX_KEY_VEC3, .hi = 1e6, .offset = F(center),
     .doc = "A point in metres, each component within +-1e6."},
    {"axis", PFX_KEY_VEC3, PFX_KEY_NONZERO, .def = {0, 1, 0}, .offset = F(axis), .hook = read_axis,
     .doc = "The axis direction (any length, not [0, 0, 0])."},
    {"rate", PFX_KEY_NUMBER, PFX_KEY_DEGREES, .lo = -1e6, .hi = 1e6, .def = {90}, .offset = F(rate),
     .doc = "Degrees per second, -1e6 to 1e6."},
    REGION_ROW,
};
static const pfx_key spring_keys[] = {
    TYPE_ROW,
    {"anchor", PFX_KEY_CODE, .offset = -1, .hook = read_anchor,
     .schema = "{\"default\": \"birth\", \"oneOf\": [{\"description\": \"A point in metres.\", "
               "\"type\": \"array\", \"items\": {\"type\": \"number\", \"minimum\": -1000000, "
               "\"maximum\": 1000000}, \"minItems\": 3, \"maxItems\": 3}, {\"const\": \"birth\"}]}",
     .doc = "The anchor: a point [x, y, z] (each within +-1e6) or 'birth' (each particle's birth "
            "position)."},
    {"k", PFX_KEY_NUMBER, .lo = 0, .hi = 1e8, .def = {10}, .offset = F(k),
     .doc = "Stiffness per unit mass in 1/s^2 (omega = sqrt(k)), 0 to 1e8."},
    {"zeta", PFX_KEY_NUMBER, .lo = 0, .hi = 1e3, .offset = F(zeta),
     .doc = "Damping ratio (1: critical), 0 to 1000."},
    REGION_ROW,
};
static const pfx_key turbulence_keys[] = {
    TYPE_ROW,
    {"strength", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .def = {1}, .offset = F(strength),
     .doc = "Acceleration scale in m/s^2, 0 to 1e6."},
    {"scale", PFX_KEY_NUMBER, .lo = 1e-6, .hi = 1e6, .def = {1}, .offset = F(scale),
     .doc = "Feature size in metres, 1e-6 to 1e6."},
    {"octaves", PFX_KEY_WHOLE, .lo = 1, .hi = 8, .def = {1}, .offset = F(octaves),
     .doc = "Octaves of noise, each half the amplitude of the last, 1 to 8."},
    {"speed", PFX_KEY_NUMBER, .lo = -1e6, .hi = 1e6, .offset = F(speed),
     .doc = "Drift of the pattern in m/s (time evolution), -1e6 to 1e6."},
    REGION_ROW,
};
static const pfx_key speed_limit_keys[] = {
    TYPE_ROW,
    {"max", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .def = {10}, .offset = F(max_speed),
     .doc = "Largest speed in m/s, 0 to 1e6."},
    REGION_ROW,
};

static const pfx_key force_over_life_keys[] = {
    TYPE_ROW,
    {"accel", PFX_KEY_CODE, PFX_KEY_REQUIRED, .offset = -1, .hook = read_life_accel,
     .schema = "{\"oneOf\": [{\"$ref\": \"#/$defs/vec3\"}, "
               "{\"type\": \"array\", \"minItems\": 1, \"maxItems\": 64, \"items\": "
               "{\"type\": \"object\", \"additionalProperties\": false, \"required\": "
               "[\"at\", \"value\"], \"properties\": {\"at\": {\"type\": \"number\", "
               "\"minimum\": 0, \"maximum\": 1}, \"value\": {\"$ref\": \"#/$defs/vec3\"}}}}]}",
     .doc = "m/s^2: a vector [x, y, z], or 1 to 64 keys [{at: u, value: [x, y, z]}, ...] over "
            "the normalised age u (0 at birth, 1 at death), at increasing, linear between keys "
            "and held beyond them; each component within +-1e6."},
    {"space", PFX_KEY_ENUM, .offset = F(space), .names = pfx_force_space_names, .what = "space",
     .doc = "world (default): the vectors are world axes; emitter: they turn with the emitter's "
            "rotation (keyframed rotation included)."},
    REGION_ROW,
};

static PFX_KEY_TABLE(
    force_gravity, "force_gravity", "gravity",
    "Uniform gravity: a constant acceleration, times each particle's gravity_scale.", gravity_keys);
static PFX_KEY_TABLE(force_attractor, "force_attractor", "attractor",
                     "Radial gravity towards a centre: a = strength d / (r^2 + softening^2)^(3/2) "
                     "(inverse_square); strength < 0 repels.",
                     attractor_keys);
static PFX_KEY_TABLE(force_drag, "force_drag", "drag",
                     "Drag relative to a wind: a = -(k + c |u|) u, u = v - wind.", drag_keys);
static PFX_KEY_TABLE(force_vortex, "force_vortex", "vortex",
                     "Sims vortex: turns positions about an axis at strength f(r) degrees per "
                     "second, f(r) = (r^4 - 2r^2 + 1)/(1 + d r^2), r = distance / radius <= 1.",
                     vortex_keys);
static PFX_KEY_TABLE(
    force_magnetic, "force_magnetic", "magnetic",
    "Lorentz force: a = (q/m)(E + v x B), q = the emitter's charge (C), m = its mass (kg).",
    magnetic_keys);
static PFX_KEY_TABLE(
    force_spiral, "force_spiral", "spiral",
    "Turns each particle's velocity about the axis direction at 'rate' degrees per second.",
    spiral_keys);
static PFX_KEY_TABLE(force_spring, "force_spring", "spring",
                     "Damped spring per unit mass: a = -k (x - anchor) - 2 zeta sqrt(k) v.",
                     spring_keys);
static PFX_KEY_TABLE(force_turbulence, "force_turbulence", "turbulence",
                     "Divergence-free curl noise: a = strength x curl of a noise potential at "
                     "position / scale; seeded by the effect's seed and the force's name.",
                     turbulence_keys);
static PFX_KEY_TABLE(force_speed_limit, "force_speed_limit", "speed_limit",
                     "Scales |v| down to 'max' after each step.", speed_limit_keys);
static PFX_KEY_TABLE(force_over_life, "force_over_life", "force_over_life",
                     "Unity's Force over Lifetime: an acceleration that is a function of the "
                     "particle's normalised age, u = age / lifetime.",
                     force_over_life_keys);

/* One table per force kind, in the order of PFX_FORCE_KINDS. */
const pfx_key_table *const pfx_force_tables[] = {
    &force_gravity,     &force_attractor, &force_drag,   &force_vortex,
    &force_magnetic,    &force_spiral,    &force_spring, &force_turbulence,
    &force_speed_limit, &force_over_life, NULL};
_Static_assert(sizeof pfx_force_tables / sizeof *pfx_force_tables == PFX_MOTION_KIND_COUNT + 1,
               "a force kind without its key table");
const pfx_key_table *const pfx_region_tables[] = {&sphere_region, &box_region, NULL};

bool pfx_compile_force(pfx_reader *r, const pfx_node *key, const pfx_node *f, uint64_t seed,
                       pfx_force *out) {
    int errors = r->d->errors;
    out->name = pfx_arena_strndup(r->arena, key->text, key->len);
    pfx_motion_force *m = &out->spec;
    m->name = out->name;
    if (!pfx_read_map(r, f, key->text))
        return false;
    char subject[160];
    snprintf(subject, sizeof subject, "force '%s'", key->text);
    int k = pfx_keys_kind(r, f, key, subject, "force type", pfx_force_names, false);
    if (k < 0)
        return false;
    const pfx_key_table *t = pfx_force_tables[k];
    m->kind = (pfx_motion_kind)k;
    pfx_keys_check(r, f, t, subject);
    pfx_keys_defaults(t, m);
    if (m->kind == PFX_MOTION_DRAG && pfx_node_get(f, "c") && !pfx_node_get(f, "k"))
        m->k = 0; /* quadratic only */
    if (m->kind == PFX_MOTION_SPRING)
        m->use_birth = true; /* the default anchor */
    pfx_keys_read(r, f, t, m);
    if (m->kind == PFX_MOTION_FORCE_OVER_LIFE && !pfx_node_get(f, "accel"))
        pfx_read_error(r, f, PFX_RULE_MISSING_KEY,
                       "force '%s' needs 'accel' (a vector or keys over life)", key->text);
    if (m->kind == PFX_MOTION_TURBULENCE)
        /* The noise is seeded by the effect's seed and the force's name, so
         * --seed changes it and renaming another force does not. */
        m->seed = pfx_fnv1a_str(seed ^ 0x9e3779b97f4a7c15ULL, out->name);
    return r->d->errors == errors;
}
