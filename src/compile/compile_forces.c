/* The `forces:` entries: each type's keys, defaults and ranges, compiled into
 * a pfx_motion_force in SI units (degrees become radians here). It does not
 * decide which emitter feels what or which integrator runs; compile.c does. */
#include "compile/compile_forces.h"

#include "base/hash.h"

#include <math.h>
#include <string.h>

static const char *const force_types[] = {"gravity",     "attractor", "drag",   "vortex",
                                          "magnetic",    "spiral",    "spring", "turbulence",
                                          "speed_limit", NULL};
static const pfx_motion_kind force_kinds[] = {
    PFX_MOTION_GRAVITY, PFX_MOTION_ATTRACTOR,  PFX_MOTION_DRAG,
    PFX_MOTION_VORTEX,  PFX_MOTION_MAGNETIC,   PFX_MOTION_SPIRAL,
    PFX_MOTION_SPRING,  PFX_MOTION_TURBULENCE, PFX_MOTION_SPEED_LIMIT};

/* Keys per type, `type` and `region` included. */
static const char *const *keys_for(pfx_motion_kind k) {
    static const char *const gravity[] = {"type", "accel", "region", NULL};
    static const char *const attractor[] = {"type",    "center", "strength",         "softening",
                                            "falloff", "radius", "reference_radius", "region",
                                            NULL};
    static const char *const drag[] = {"type", "k", "c", "wind", "region", NULL};
    static const char *const vortex[] = {"type", "center", "axis",   "strength", "radius",
                                         "d",    "inflow", "region", NULL};
    static const char *const magnetic[] = {"type", "field", "electric", "region", NULL};
    static const char *const spiral[] = {"type", "center", "axis", "rate", "region", NULL};
    static const char *const spring[] = {"type", "anchor", "k", "zeta", "region", NULL};
    static const char *const turbulence[] = {"type",  "strength", "scale", "octaves",
                                             "speed", "region",   NULL};
    static const char *const speed_limit[] = {"type", "max", "region", NULL};
    switch (k) {
    case PFX_MOTION_GRAVITY:
        return gravity;
    case PFX_MOTION_ATTRACTOR:
        return attractor;
    case PFX_MOTION_DRAG:
        return drag;
    case PFX_MOTION_VORTEX:
        return vortex;
    case PFX_MOTION_MAGNETIC:
        return magnetic;
    case PFX_MOTION_SPIRAL:
        return spiral;
    case PFX_MOTION_SPRING:
        return spring;
    case PFX_MOTION_TURBULENCE:
        return turbulence;
    default:
        return speed_limit;
    }
}

/* An optional number within [lo, hi]; *out keeps its default when absent. */
static bool number_in(pfx_reader *r, const pfx_node *map, const char *key, double *out, double lo,
                      double hi) {
    const pfx_node *n = pfx_node_get(map, key);
    if (!n)
        return true;
    double v;
    if (!pfx_read_number(r, n, key, &v))
        return false;
    if (!pfx_check_above(r, n, key, v, lo, false) || !pfx_check_below(r, n, key, v, hi, false))
        return false;
    *out = v;
    return true;
}

/* A unit axis (default +Y); the zero vector is an error. */
static void axis(pfx_reader *r, const pfx_node *map, double out[3]) {
    out[0] = out[2] = 0;
    out[1] = 1;
    const pfx_node *n = pfx_node_get(map, "axis");
    double v[3];
    if (!n || !pfx_read_numbers(r, n, "axis", v, 3))
        return;
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len == 0) {
        pfx_read_error(r, n, "'axis' must not be the zero vector");
        return;
    }
    for (int i = 0; i < 3; i++)
        out[i] = v[i] / len;
}

static void region(pfx_reader *r, const pfx_node *n, pfx_motion_region *out) {
    static const char *const sphere_keys[] = {"type", "center", "radius", "falloff", NULL};
    static const char *const box_keys[] = {"type", "center", "size", "falloff", NULL};
    static const char *const types[] = {"sphere", "box", NULL};
    if (!pfx_read_map(r, n, "region"))
        return;
    const pfx_node *t = pfx_node_get(n, "type");
    const char *name;
    if (!t) {
        pfx_read_error(r, n, "a region needs a 'type' (sphere or box)");
        return;
    }
    if (!pfx_read_string(r, t, "type", &name))
        return;
    bool sphere = !strcmp(name, "sphere");
    if (!sphere && strcmp(name, "box")) {
        const char *s = pfx_suggest(name, types);
        pfx_read_error(r, t, "unknown region type '%s'; %s%s%s", name,
                       s ? "did you mean '" : "expected sphere or box", s ? s : "", s ? "'?" : "");
        return;
    }
    pfx_read_check_keys(r, n, sphere ? sphere_keys : box_keys, "a region");
    out->kind = sphere ? PFX_REGION_SPHERE : PFX_REGION_BOX;
    pfx_read_vec3_within(r, n, "center", out->center, 1e6);
    number_in(r, n, "falloff", &out->falloff, 0, 1e6);
    if (sphere) {
        out->radius = 1;
        number_in(r, n, "radius", &out->radius, 0, 1e6);
    } else {
        double size[3] = {1, 1, 1};
        const pfx_node *sz = pfx_node_get(n, "size");
        if (sz && pfx_read_numbers(r, sz, "size", size, 3))
            for (int i = 0; i < 3; i++)
                if (size[i] < 0)
                    pfx_read_error(r, sz->items[i], "region 'size' must be at least 0, got %g",
                                   size[i]);
        for (int i = 0; i < 3; i++)
            out->half[i] = size[i] / 2;
    }
}

bool pfx_compile_force(pfx_reader *r, const pfx_node *key, const pfx_node *f, uint64_t seed,
                       pfx_force *out) {
    const double deg = M_PI / 180;
    int errors = r->d->errors;
    out->name = pfx_arena_strndup(r->arena, key->text, key->len);
    pfx_motion_force *m = &out->spec;
    m->name = out->name;
    if (!pfx_read_map(r, f, key->text))
        return false;
    const pfx_node *type = pfx_node_get(f, "type");
    if (!type) {
        pfx_read_error(r, key,
                       "force '%s' needs a 'type' (gravity, attractor, drag, vortex, "
                       "magnetic, spiral, spring, turbulence or speed_limit)",
                       key->text);
        return false;
    }
    const char *name;
    if (!pfx_read_string(r, type, "type", &name))
        return false;
    int t = -1;
    for (int i = 0; force_types[i]; i++)
        if (!strcmp(force_types[i], name))
            t = i;
    if (t < 0) {
        const char *s = pfx_suggest(name, force_types);
        if (s)
            pfx_read_error(r, type, "unknown force type '%s'; did you mean '%s'?", name, s);
        else
            pfx_read_error(r, type,
                           "unknown force type '%s'; expected gravity, attractor, drag, vortex, "
                           "magnetic, spiral, spring, turbulence or speed_limit",
                           name);
        return false;
    }
    m->kind = force_kinds[t];
    char where[160];
    snprintf(where, sizeof where, "force '%s'", key->text);
    pfx_read_check_keys(r, f, keys_for(m->kind), where);
    const pfx_node *n;
    if ((n = pfx_node_get(f, "region")))
        region(r, n, &m->region);
    switch (m->kind) {
    case PFX_MOTION_GRAVITY:
        m->accel[1] = -9.81;
        pfx_read_vec3_within(r, f, "accel", m->accel, 1e6);
        break;
    case PFX_MOTION_ATTRACTOR: {
        static const char *const falloffs[] = {"inverse_square", "linear", "constant", NULL};
        pfx_read_vec3_within(r, f, "center", m->center, 1e6);
        m->strength = 1;
        number_in(r, f, "strength", &m->strength, -1e9, 1e9);
        number_in(r, f, "softening", &m->softening, 0, 1e6);
        number_in(r, f, "radius", &m->radius, 0, 1e6);
        m->ref_radius = 1;
        number_in(r, f, "reference_radius", &m->ref_radius, 1e-6, 1e6);
        if ((n = pfx_node_get(f, "falloff")) && pfx_read_string(r, n, "falloff", &name)) {
            int k = -1;
            for (int i = 0; falloffs[i]; i++)
                if (!strcmp(falloffs[i], name))
                    k = i;
            if (k < 0)
                pfx_read_error(r, n,
                               "unknown falloff '%s'; expected inverse_square, linear or constant",
                               name);
            else
                m->falloff = (pfx_falloff)k;
        }
        break;
    }
    case PFX_MOTION_DRAG:
        m->k = 1;
        if (pfx_node_get(f, "c") && !pfx_node_get(f, "k"))
            m->k = 0; /* quadratic only */
        number_in(r, f, "k", &m->k, 0, 1e6);
        number_in(r, f, "c", &m->c, 0, 1e6);
        pfx_read_vec3_within(r, f, "wind", m->wind, 1e6);
        break;
    case PFX_MOTION_VORTEX:
        pfx_read_vec3_within(r, f, "center", m->center, 1e6);
        axis(r, f, m->axis);
        m->strength = 90;
        number_in(r, f, "strength", &m->strength, -1e6, 1e6);
        m->strength *= deg;
        m->radius = 1;
        number_in(r, f, "radius", &m->radius, 1e-6, 1e6);
        number_in(r, f, "d", &m->sims_d, 0, 1e6);
        number_in(r, f, "inflow", &m->inflow, -1e6, 1e6);
        break;
    case PFX_MOTION_MAGNETIC:
        m->field[1] = 1;
        pfx_read_vec3_within(r, f, "field", m->field, 1e6);
        pfx_read_vec3_within(r, f, "electric", m->electric, 1e9);
        break;
    case PFX_MOTION_SPIRAL:
        pfx_read_vec3_within(r, f, "center", m->center, 1e6);
        axis(r, f, m->axis);
        m->rate = 90;
        number_in(r, f, "rate", &m->rate, -1e6, 1e6);
        m->rate *= deg;
        break;
    case PFX_MOTION_SPRING:
        m->k = 10;
        number_in(r, f, "k", &m->k, 0, 1e8);
        number_in(r, f, "zeta", &m->zeta, 0, 1e3);
        if ((n = pfx_node_get(f, "anchor"))) {
            if (n->kind == PFX_NODE_SCALAR && !strcmp(n->text, "birth"))
                m->use_birth = true;
            else if (n->kind != PFX_NODE_SEQ)
                pfx_read_error(r, n, "'anchor' must be a point [x, y, z] or 'birth'");
            else
                pfx_read_vec3_within(r, f, "anchor", m->center, 1e6);
        } else {
            m->use_birth = true;
        }
        break;
    case PFX_MOTION_TURBULENCE: {
        m->strength = 1;
        number_in(r, f, "strength", &m->strength, 0, 1e6);
        m->scale = 1;
        number_in(r, f, "scale", &m->scale, 1e-6, 1e6);
        double oct = 1;
        number_in(r, f, "octaves", &oct, 1, 8);
        if (oct != floor(oct) && (n = pfx_node_get(f, "octaves")))
            pfx_read_error(r, n, "'octaves' must be a whole number from 1 to 8, got %g", oct);
        m->octaves = (int)oct;
        number_in(r, f, "speed", &m->speed, -1e6, 1e6);
        /* The noise is seeded by the effect's seed and the force's name, so
         * --seed changes it and renaming another force does not. */
        m->seed = pfx_fnv1a_str(seed ^ 0x9e3779b97f4a7c15ULL, out->name);
        break;
    }
    case PFX_MOTION_SPEED_LIMIT:
        m->max_speed = 10;
        number_in(r, f, "max", &m->max_speed, 0, 1e6);
        break;
    default:
        break;
    }
    return r->d->errors == errors;
}
