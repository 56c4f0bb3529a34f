/* The `deflectors:` entries: shape (plane, disc, sphere, box), placement and
 * response (bounce with resilience and friction, kill, stick, lifetime
 * loss, chance), compiled into a pfx_deflector (src/sim/collide.h). */
#include "compile/compile_deflectors.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "base/rng.h"
#include "compile/keys.h"

#define D(field) offsetof(pfx_deflector, field)

/* A plane's or disc's normal: any length but zero. */
static void read_normal(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    pfx_deflector *d = dest;
    if (pfx_read_vec3_within(r, map, "normal", d->normal, 1e6) && d->normal[0] == 0 &&
        d->normal[1] == 0 && d->normal[2] == 0)
        pfx_read_error(r, v, PFX_RULE_ZERO_VECTOR, "'normal' must not be the zero vector");
}

/* A bounded plane's [w, h] or a box's [x, y, z]: each above 0, at most 1e6. */
static void read_size(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    pfx_deflector *d = dest;
    int count = d->shape == PFX_DEFLECTOR_PLANE ? 2 : 3;
    if (pfx_read_numbers(r, v, "size", d->size, count))
        for (int i = 0; i < count; i++)
            if (!(d->size[i] > 0 && d->size[i] <= 1e6))
                pfx_read_error(r, v->items[i], PFX_RULE_OUT_OF_RANGE,
                               "'size' must be above 0 and at most 1e6, got %g", d->size[i]);
}

#define POINT_ROWS                                                                                 \
    {"point", PFX_KEY_VEC3, .hi = 1e6, .offset = D(point),                                         \
     .doc = "A point on it in metres (the centre when bounded), each within +-1e6."},              \
    {                                                                                              \
        "normal", PFX_KEY_VEC3, PFX_KEY_NONZERO,                                                   \
            .hi = 1e6, .def = {0, 1, 0}, .offset = D(normal), .hook = read_normal,                 \
            .doc = "Its normal (any length, not [0, 0, 0]), each within +-1e6."                    \
    }
#define CENTER_ROW                                                                                 \
    {                                                                                              \
        "center", PFX_KEY_VEC3, .hi = 1e6, .offset = D(point),                                     \
                                .doc = "Centre in metres, each within +-1e6."                      \
    }
#define RADIUS_ROW                                                                                 \
    {                                                                                              \
        "radius", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT,                                               \
            .lo = 0, .hi = 1e6, .def = {1}, .offset = D(radius),                                   \
            .doc = "Radius in metres, above 0, at most 1e6."                                       \
    }
#define INSIDE_ROW                                                                                 \
    { "inside", PFX_KEY_BOOL, .offset = D(inside), .doc = "true: particles are kept inside." }
#define RESPONSE_ROWS                                                                              \
    {"response",                                                                                   \
     PFX_KEY_ENUM,                                                                                 \
     .offset = D(response),                                                                        \
     .names = pfx_deflect_response_names,                                                          \
     .what = "response",                                                                           \
     .doc = "bounce (default), kill (the particle dies at the hit) or stick (it stays at the hit " \
            "point)."},                                                                            \
        {"resilience",                                                                             \
         PFX_KEY_RANGE,                                                                            \
         .lo = 0,                                                                                  \
         .hi = 1,                                                                                  \
         .def = {1},                                                                               \
         .offset = D(resilience),                                                                  \
         .doc = "Restitution eps, 0 to 1: a number, or a range [min, max] drawn per impact; the "  \
                "normal speed after a bounce is eps times the speed before."},                     \
        {"friction",                                                                               \
         PFX_KEY_RANGE,                                                                            \
         .lo = 0,                                                                                  \
         .hi = 1,                                                                                  \
         .offset = D(friction),                                                                    \
         .doc = "Friction mu, 0 to 1 (or a range drawn per impact): the tangential velocity is "   \
                "multiplied by 1 - mu at an impact; sliding decelerates by mu |a_N|."},            \
        {"lifetime_loss",                                                                          \
         PFX_KEY_NUMBER,                                                                           \
         .lo = 0,                                                                                  \
         .hi = 1,                                                                                  \
         .offset = D(lifetime_loss),                                                               \
         .doc = "Fraction of the particle's lifetime removed at each impact, 0 to 1."},            \
    {                                                                                              \
        "chance", PFX_KEY_NUMBER, .lo = 0, .hi = 1, .def = {1}, .offset = D(chance),               \
                                  .doc = "Fraction of the particles (by id) the deflector "        \
                                         "affects, 0 to 1; the others pass "                       \
                                         "through."                                                \
    }
#define TYPE_ROW                                                                                   \
    { "type", PFX_KEY_CODE, .offset = -1, .doc = "The deflector type." }

static const pfx_key plane_keys[] = {
    TYPE_ROW,
    POINT_ROWS,
    {"size", PFX_KEY_CODE, .offset = -1, .hook = read_size,
     .schema = "{\"type\": \"array\", \"items\": {\"type\": \"number\", \"exclusiveMinimum\": 0, "
               "\"maximum\": 1000000}, \"minItems\": 2, \"maxItems\": 2}",
     .doc = "[w, h]: a bounded rectangle of this size (metres, each above 0, at most 1e6), "
            "two-sided."},
    RESPONSE_ROWS,
};
static const pfx_key disc_keys[] = {TYPE_ROW, POINT_ROWS, RADIUS_ROW, RESPONSE_ROWS};
static const pfx_key sphere_keys[] = {TYPE_ROW, CENTER_ROW, RADIUS_ROW, INSIDE_ROW, RESPONSE_ROWS};
static const pfx_key box_keys[] = {
    TYPE_ROW,
    CENTER_ROW,
    {"size", PFX_KEY_VEC3, .def = {1, 1, 1}, .offset = D(size), .hook = read_size,
     .schema = "{\"type\": \"array\", \"items\": {\"type\": \"number\", \"exclusiveMinimum\": 0, "
               "\"maximum\": 1000000}, \"minItems\": 3, \"maxItems\": 3, \"default\": [1, 1, 1]}",
     .doc = "Full edge lengths [x, y, z] in metres, each above 0, at most 1e6."},
    INSIDE_ROW,
    RESPONSE_ROWS,
};

static PFX_KEY_TABLE(deflector_plane, "deflector_plane", "plane",
                     "A plane: infinite and one-sided (particles live in front of the normal), or "
                     "bounded by size and two-sided.",
                     plane_keys);
static PFX_KEY_TABLE(deflector_disc, "deflector_disc", "disc", "A two-sided disc.", disc_keys);
static PFX_KEY_TABLE(deflector_sphere, "deflector_sphere", "sphere",
                     "A sphere keeping particles outside (or inside).", sphere_keys);
static PFX_KEY_TABLE(deflector_box, "deflector_box", "box",
                     "An axis-aligned box keeping particles outside (or inside).", box_keys);

/* One table per deflector kind, in the order of PFX_DEFLECTOR_KINDS. */
const pfx_key_table *const pfx_deflector_tables[] = {&deflector_plane, &deflector_disc,
                                                     &deflector_sphere, &deflector_box, NULL};

bool pfx_compile_deflector(pfx_reader *r, const pfx_node *key, const pfx_node *n, uint64_t seed,
                           pfx_deflector *out) {
    int errors = r->d->errors;
    out->name = pfx_arena_strndup(r->arena, key->text, key->len);
    if (!pfx_read_map(r, n, key->text))
        return false;
    char subject[160];
    snprintf(subject, sizeof subject, "deflector '%s'", key->text);
    int k = pfx_keys_kind(r, n, key, subject, "deflector type", pfx_deflector_names, true);
    if (k < 0)
        return false;
    out->shape = (pfx_deflector_shape)k;
    const pfx_key_table *t = pfx_deflector_tables[k];
    pfx_keys_check(r, n, t, subject);
    /* Defaults: a ground plane y = 0 facing up; a unit sphere or box at the
     * origin; a perfect bounce without friction affecting every particle. */
    pfx_keys_defaults(t, out);
    out->seed = pfx_rng_stream_for(out->name) ^ seed;
    pfx_keys_read(r, n, t, out);
    return r->d->errors == errors;
}
