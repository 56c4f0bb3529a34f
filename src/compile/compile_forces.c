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
        pfx_read_error(r, n, "'axis' must not be the zero vector");
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
        pfx_read_error(r, n, "'anchor' must be a point [x, y, z] or 'birth'");
    else if (pfx_read_vec3_within(r, map, "anchor", m->center, 1e6))
        m->use_birth = false;
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
            pfx_read_error(r, sz->items[i], "region 'size' must be at least 0, got %g", size[i]);
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
        "region", PFX_KEY_CODE,                                                                    \
            .offset = -1, .hook = read_region, .schema = "{\"$ref\": \"#/$defs/region\"}",         \
            .doc =                                                                                 \
                "Where it acts: a sphere or box, fading out over `falloff` (default everywhere)."  \
    }

static const pfx_key gravity_keys[] = {
    TYPE_ROW,
    {"accel", PFX_KEY_VEC3, .hi = 1e6, .def = {0, -9.81, 0}, .offset = F(accel),
     .doc = "The acceleration in m/s^2, each component within +-1e6."},
    REGION_ROW,
};
static const pfx_key attractor_keys[] = {
    TYPE_ROW,
    {"center", PFX_KEY_VEC3, .hi = 1e6, .offset = F(center), .doc = "The point it pulls to (m)."},
    {"strength", PFX_KEY_NUMBER, .lo = -1e9, .hi = 1e9, .def = {1}, .offset = F(strength),
     .doc = "mu in m^3/s^2 (a = mu / r^2 at distance r); negative repels."},
    {"softening", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = F(softening),
     .doc = "Plummer softening radius in m: a = mu r / (r^2 + e^2)^(3/2)."},
    {"falloff", PFX_KEY_ENUM, .offset = F(falloff), .names = pfx_falloff_names, .what = "falloff",
     .doc = "How the pull falls with distance."},
    {"radius", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = F(radius),
     .doc = "No pull beyond this distance (0: everywhere)."},
    {"reference_radius", PFX_KEY_NUMBER, .lo = 1e-6, .hi = 1e6, .def = {1}, .offset = F(ref_radius),
     .doc = "L of the linear and constant falloffs, and where stability is judged."},
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
    {"center", PFX_KEY_VEC3, .hi = 1e6, .offset = F(center), .doc = "A point on its axis (m)."},
    {"axis", PFX_KEY_VEC3, .def = {0, 1, 0}, .offset = F(axis), .hook = read_axis,
     .doc = "Its axis direction (any length but zero)."},
    {"strength", PFX_KEY_NUMBER, PFX_KEY_DEGREES, .lo = -1e6, .hi = 1e6, .def = {90},
     .offset = F(strength), .doc = "Degrees per second at the axis, times Sims' falloff."},
    {"radius", PFX_KEY_NUMBER, .lo = 1e-6, .hi = 1e6, .def = {1}, .offset = F(radius),
     .doc = "Its radius in m: no turn beyond it."},
    {"d", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .offset = F(sims_d),
     .doc = "d of the falloff (r^4 - 2r^2 + 1) / (1 + d r^2)."},
    {"inflow", PFX_KEY_NUMBER, .lo = -1e6, .hi = 1e6, .offset = F(inflow),
     .doc = "m/s towards the axis, times the falloff."},
    REGION_ROW,
};
static const pfx_key magnetic_keys[] = {
    TYPE_ROW,
    {"field", PFX_KEY_VEC3, .hi = 1e6, .def = {0, 1, 0}, .offset = F(field),
     .doc = "B in tesla, each component within +-1e6."},
    {"electric", PFX_KEY_VEC3, .hi = 1e9, .offset = F(electric),
     .doc = "E in V/m, each component within +-1e9."},
    REGION_ROW,
};
static const pfx_key spiral_keys[] = {
    TYPE_ROW,
    {"center", PFX_KEY_VEC3, .hi = 1e6, .offset = F(center), .doc = "A point on its axis (m)."},
    {"axis", PFX_KEY_VEC3, .def = {0, 1, 0}, .offset = F(axis), .hook = read_axis,
     .doc = "The axis velocities turn about."},
    {"rate", PFX_KEY_NUMBER, PFX_KEY_DEGREES, .lo = -1e6, .hi = 1e6, .def = {90}, .offset = F(rate),
     .doc = "Degrees per second the velocity turns."},
    REGION_ROW,
};
static const pfx_key spring_keys[] = {
    TYPE_ROW,
    {"anchor", PFX_KEY_CODE, .offset = -1, .hook = read_anchor,
     .schema = "{\"oneOf\": [{\"$ref\": \"#/$defs/vec3\"}, {\"const\": \"birth\"}], "
               "\"default\": \"birth\"}",
     .doc = "The point it pulls to, or 'birth': each particle's own birth place."},
    {"k", PFX_KEY_NUMBER, .lo = 0, .hi = 1e8, .def = {10}, .offset = F(k),
     .doc = "Stiffness per mass in 1/s^2 (omega = sqrt(k))."},
    {"zeta", PFX_KEY_NUMBER, .lo = 0, .hi = 1e3, .offset = F(zeta),
     .doc = "Damping ratio (1: critical)."},
    REGION_ROW,
};
static const pfx_key turbulence_keys[] = {
    TYPE_ROW,
    {"strength", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .def = {1}, .offset = F(strength),
     .doc = "Typical acceleration in m/s^2."},
    {"scale", PFX_KEY_NUMBER, .lo = 1e-6, .hi = 1e6, .def = {1}, .offset = F(scale),
     .doc = "Feature size in m."},
    {"octaves", PFX_KEY_WHOLE, .lo = 1, .hi = 8, .def = {1}, .offset = F(octaves),
     .doc = "Octaves of noise, 1 to 8, each half the amplitude of the last."},
    {"speed", PFX_KEY_NUMBER, .lo = -1e6, .hi = 1e6, .offset = F(speed),
     .doc = "How fast the pattern drifts, m/s."},
    REGION_ROW,
};
static const pfx_key speed_limit_keys[] = {
    TYPE_ROW,
    {"max", PFX_KEY_NUMBER, .lo = 0, .hi = 1e6, .def = {10}, .offset = F(max_speed),
     .doc = "The largest speed in m/s."},
    REGION_ROW,
};

static PFX_KEY_TABLE(force_gravity, "force_gravity", "gravity", "Uniform acceleration.",
                     gravity_keys);
static PFX_KEY_TABLE(force_attractor, "force_attractor", "attractor",
                     "A point that pulls (or pushes).", attractor_keys);
static PFX_KEY_TABLE(force_drag, "force_drag", "drag",
                     "Drag relative to a wind: a = -(k + c |u|) u, u = v - wind.", drag_keys);
static PFX_KEY_TABLE(force_vortex, "force_vortex", "vortex",
                     "Turns positions about an axis (Sims 1990).", vortex_keys);
static PFX_KEY_TABLE(force_magnetic, "force_magnetic", "magnetic",
                     "The Lorentz force (q/m)(E + v x B).", magnetic_keys);
static PFX_KEY_TABLE(force_spiral, "force_spiral", "spiral", "Turns velocities about an axis.",
                     spiral_keys);
static PFX_KEY_TABLE(force_spring, "force_spring", "spring",
                     "A damped spring: a = -k (x - anchor) - 2 zeta sqrt(k) v.", spring_keys);
static PFX_KEY_TABLE(force_turbulence, "force_turbulence", "turbulence",
                     "Divergence-free curl noise.", turbulence_keys);
static PFX_KEY_TABLE(force_speed_limit, "force_speed_limit", "speed_limit", "Clamps the speed.",
                     speed_limit_keys);

/* One table per force kind, in the order of PFX_FORCE_KINDS. */
const pfx_key_table *const pfx_force_tables[] = {
    &force_gravity, &force_attractor, &force_drag,       &force_vortex,      &force_magnetic,
    &force_spiral,  &force_spring,    &force_turbulence, &force_speed_limit, NULL};
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
    if (m->kind == PFX_MOTION_TURBULENCE)
        /* The noise is seeded by the effect's seed and the force's name, so
         * --seed changes it and renaming another force does not. */
        m->seed = pfx_fnv1a_str(seed ^ 0x9e3779b97f4a7c15ULL, out->name);
    return r->d->errors == errors;
}
