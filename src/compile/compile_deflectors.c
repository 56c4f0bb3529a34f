/* The `deflectors:` entries: shape (plane, disc, sphere, box), placement and
 * response (bounce with resilience and friction, kill, stick, lifetime
 * loss, chance), compiled into a pfx_deflector (src/sim/collide.h). */
#include "compile/compile_deflectors.h"

#include <math.h>
#include <string.h>

#include "base/rng.h"

static const char *const types[] = {"plane", "disc", "sphere", "box", NULL};
static const char *const responses[] = {"bounce", "kill", "stick", NULL};

static const char *const *keys_for(pfx_deflector_shape s) {
    static const char *const plane[] = {"type",     "point",      "normal",   "size",
                                        "response", "resilience", "friction", "lifetime_loss",
                                        "chance",   NULL};
    static const char *const disc[] = {"type",     "point",      "normal",   "radius",
                                       "response", "resilience", "friction", "lifetime_loss",
                                       "chance",   NULL};
    static const char *const sphere[] = {"type",     "center",     "radius",   "inside",
                                         "response", "resilience", "friction", "lifetime_loss",
                                         "chance",   NULL};
    static const char *const box[] = {"type",     "center",     "size",     "inside",
                                      "response", "resilience", "friction", "lifetime_loss",
                                      "chance",   NULL};
    return s == PFX_DEFLECTOR_PLANE    ? plane
           : s == PFX_DEFLECTOR_DISC   ? disc
           : s == PFX_DEFLECTOR_SPHERE ? sphere
                                       : box;
}

/* A number in [lo, hi] or a range [a, b] inside it, into out[2]. */
static bool read_range(pfx_reader *r, const pfx_node *map, const char *key, double lo, double hi,
                       double out[2]) {
    const pfx_node *n = pfx_node_get(map, key);
    if (!n)
        return true;
    pfx_value v;
    if (!pfx_read_value(r, n, key, &v))
        return false;
    if (v.dist == PFX_DIST_NORMAL) {
        pfx_read_error(r, n, "'%s' takes a number or a range [min, max]", key);
        return false;
    }
    out[0] = pfx_value_min(&v);
    out[1] = pfx_value_max(&v);
    return pfx_check_above(r, n, key, out[0], lo, false) &&
           pfx_check_below(r, n, key, out[1], hi, false);
}

static bool read_flag(pfx_reader *r, const pfx_node *map, const char *key, bool *out) {
    const pfx_node *n = pfx_node_get(map, key);
    if (!n)
        return true;
    if (n->kind != PFX_NODE_SCALAR || (strcmp(n->text, "true") && strcmp(n->text, "false"))) {
        pfx_read_error(r, n, "'%s' must be true or false", key);
        return false;
    }
    *out = !strcmp(n->text, "true");
    return true;
}

bool pfx_compile_deflector(pfx_reader *r, const pfx_node *key, const pfx_node *n, uint64_t seed,
                           pfx_deflector *out) {
    int errors = r->d->errors;
    out->name = pfx_arena_strndup(r->arena, key->text, key->len);
    if (!pfx_read_map(r, n, key->text))
        return false;
    const pfx_node *t = pfx_node_get(n, "type");
    if (!t) {
        pfx_read_error(r, key, "deflector '%s' needs a 'type' (plane, disc, sphere or box)",
                       key->text);
        return false;
    }
    int type = pfx_read_enum(r, t, "type", "deflector type", types);
    if (type < 0)
        return false;
    out->shape = (pfx_deflector_shape)type;
    char where[160];
    snprintf(where, sizeof where, "deflector '%s'", key->text);
    pfx_read_check_keys(r, n, keys_for(out->shape), where);
    /* Defaults: a ground plane y = 0 facing up; a unit sphere or box at the
     * origin; a perfect bounce without friction affecting every particle. */
    out->normal[1] = 1;
    out->radius = 1;
    out->resilience[0] = out->resilience[1] = 1;
    out->chance = 1;
    out->seed = pfx_rng_stream_for(out->name) ^ seed;
    const pfx_node *v;
    if (out->shape == PFX_DEFLECTOR_PLANE || out->shape == PFX_DEFLECTOR_DISC) {
        pfx_read_vec3_within(r, n, "point", out->point, 1e6);
        if (pfx_read_vec3_within(r, n, "normal", out->normal, 1e6) && out->normal[0] == 0 &&
            out->normal[1] == 0 && out->normal[2] == 0)
            pfx_read_error(r, pfx_node_get(n, "normal"), "'normal' must not be the zero vector");
    } else {
        pfx_read_vec3_within(r, n, "center", out->point, 1e6);
        read_flag(r, n, "inside", &out->inside);
    }
    if ((v = pfx_node_get(n, "radius")) && pfx_read_number(r, v, "radius", &out->radius))
        (void)(pfx_check_above(r, v, "radius", out->radius, 0, true) &&
               pfx_check_below(r, v, "radius", out->radius, 1e6, false));
    if ((v = pfx_node_get(n, "size"))) {
        int count = out->shape == PFX_DEFLECTOR_PLANE ? 2 : 3;
        if (pfx_read_numbers(r, v, "size", out->size, count))
            for (int i = 0; i < count; i++)
                if (!(out->size[i] > 0 && out->size[i] <= 1e6))
                    pfx_read_error(r, v->items[i], "'size' must be above 0 and at most 1e6, got %g",
                                   out->size[i]);
    } else if (out->shape == PFX_DEFLECTOR_BOX) {
        out->size[0] = out->size[1] = out->size[2] = 1;
    }
    if ((v = pfx_node_get(n, "response"))) {
        int resp = pfx_read_enum(r, v, "response", "response", responses);
        if (resp >= 0)
            out->response = (pfx_deflect_response)resp;
    }
    read_range(r, n, "resilience", 0, 1, out->resilience);
    read_range(r, n, "friction", 0, 1, out->friction);
    if ((v = pfx_node_get(n, "lifetime_loss")) &&
        pfx_read_number(r, v, "lifetime_loss", &out->lifetime_loss))
        (void)(pfx_check_above(r, v, "lifetime_loss", out->lifetime_loss, 0, false) &&
               pfx_check_below(r, v, "lifetime_loss", out->lifetime_loss, 1, false));
    if ((v = pfx_node_get(n, "chance")) && pfx_read_number(r, v, "chance", &out->chance))
        (void)(pfx_check_above(r, v, "chance", out->chance, 0, false) &&
               pfx_check_below(r, v, "chance", out->chance, 1, false));
    return r->d->errors == errors;
}
