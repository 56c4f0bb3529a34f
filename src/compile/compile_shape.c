/* The emitter `shape:` mapping: each shape type's keys, defaults and ranges,
 * compiled into a pfx_shape, with the tables some samplers search (an
 * ellipse rim's arc length, a mesh's triangle areas). Sampling the shape is
 * the simulation's job (src/sim/sample.c); this file only validates and
 * fills.
 *
 * Conventions, in the emitter's local frame (its rotation, then position,
 * are applied after sampling). Flat shapes lie in the XZ plane, normal +Y.
 *   point       the origin.
 *   line        from -> to, uniform by length.
 *   rect        size [w, h]: x in [-w/2, w/2], z in [-h/2, h/2]; volume =
 *               the area; edge = the perimeter by length.
 *   disc        radius R, inner k R (a ring), arc degrees from +X towards
 *               +Z; volume = the area, edge = the outer rim (the arc).
 *   ellipse     radii [a, b] along X and Z; volume = the area (a stretched
 *               uniform disc point), edge = the rim by arc length (a
 *               512-segment table, see sample.c).
 *   box         size [x, y, z] centred; surface = the six faces by area.
 *   sphere      radius, inner (a thick shell); surface = the sphere r = R.
 *   hemisphere  the y >= 0 half of the sphere; surface = the dome only.
 *   cylinder    radius, height: axis +Y, base at y = 0, top at y = height;
 *               surface = the side only (no caps).
 *   cone        radius at the base y = 0, narrowing to the apex at y =
 *               height; surface = the lateral surface only (no base).
 *               `angle` tilts the volume normal (see sample.h).
 *   mesh        file: an OBJ surface, by triangle area; surface only.
 * `emit_from` defaults to volume (surface for a mesh). */
#include "compile/compile_shape.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "compile/keys.h"
#include "compile/mesh_load.h"

#define VOL (1u << PFX_EMIT_VOLUME)
#define SURF (1u << PFX_EMIT_SURFACE)
#define EDGE (1u << PFX_EMIT_EDGE)

/* The emit_from modes each kind allows, in the order of PFX_SHAPE_KINDS. */
static const unsigned kind_modes[] = {VOL,        VOL,        VOL | EDGE, VOL | EDGE,
                                      VOL | EDGE, VOL | SURF, VOL | SURF, VOL | SURF,
                                      VOL | SURF, VOL | SURF, SURF};

#define S(field) offsetof(pfx_shape, field)
#define TYPE(text)                                                                                 \
    { "type", PFX_KEY_CODE, .offset = -1, .doc = text }
#define EMIT_FROM(modes, words, def)                                                               \
    {                                                                                              \
        "emit_from", PFX_KEY_CODE, .offset = -1,                                                   \
                                   .schema = "{\"enum\": [" modes "], \"default\": \"" def "\"}",  \
                                   .doc = "Where births are: " words " (default " def ")."         \
    }
#define VOLUME_ONLY EMIT_FROM("\"volume\"", "volume", "volume")
#define VOLUME_EDGE EMIT_FROM("\"volume\", \"edge\"", "volume, edge", "volume")
#define VOLUME_SURFACE EMIT_FROM("\"volume\", \"surface\"", "volume, surface", "volume")
/* Required keys: read by the code of pfx_compile_shape, which names the
 * missing one in the shape's own words ("a box shape needs a 'size'"). */
#define LENGTHS(n)                                                                                 \
    "{\"type\": \"array\", \"items\": {\"type\": \"number\", \"minimum\": 0}, \"minItems\": " #n   \
    ", \"maxItems\": " #n "}"
#define RADIUS_ROW                                                                                 \
    {                                                                                              \
        "radius", PFX_KEY_NUMBER, PFX_KEY_REQUIRED | PFX_KEY_NO_DEFAULT,                           \
            .lo = 0, .hi = INFINITY, .offset = -1, .doc = "Radius in metres, at least 0."          \
    }
#define INNER_ROW                                                                                  \
    {                                                                                              \
        "inner", PFX_KEY_NUMBER,                                                                   \
            .lo = 0, .hi = INFINITY, .offset = -1,                                                 \
            .doc =                                                                                 \
                "Inner radius in metres (0 <= inner < radius): births between inner and radius; "  \
                "emit_from: volume only."                                                          \
    }
#define HEIGHT_ROW                                                                                 \
    {                                                                                              \
        "height", PFX_KEY_NUMBER, PFX_KEY_REQUIRED | PFX_KEY_NO_DEFAULT,                           \
            .lo = 0, .hi = INFINITY, .offset = -1,                                                 \
            .doc = "Height in metres along local +Y from the base at y = 0, at least 0."           \
    }

static const pfx_key point_keys[] = {
    TYPE("A point: every particle is born at the emitter's position."), VOLUME_ONLY};
static const pfx_key line_keys[] = {TYPE("A segment from 'from' to 'to', uniform by length."),
                                    {"from", PFX_KEY_VEC3, PFX_KEY_REQUIRED | PFX_KEY_NO_DEFAULT,
                                     .offset = -1,
                                     .doc = "One end [x, y, z] in the emitter's frame, metres."},
                                    {"to", PFX_KEY_VEC3, PFX_KEY_REQUIRED | PFX_KEY_NO_DEFAULT,
                                     .offset = -1, .doc = "The other end [x, y, z], metres."},
                                    VOLUME_ONLY};
static const pfx_key rect_keys[] = {
    TYPE("A rectangle in the local XZ plane (normal +Y), centred: volume = its area, edge = its "
         "perimeter."),
    {"size", PFX_KEY_CODE, PFX_KEY_REQUIRED, .offset = -1, .schema = LENGTHS(2),
     .doc = "[w, h]: edge lengths along X and Z in metres, each at least 0."},
    VOLUME_EDGE};
static void read_arc(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest);
static const pfx_key disc_keys[] = {
    TYPE("A disc in the local XZ plane (normal +Y): volume = the area (a ring with inner, a sector "
         "with arc), edge = the rim."),
    RADIUS_ROW,
    INNER_ROW,
    {"arc", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT, .lo = 0, .hi = 360, .def = {360}, .offset = -1,
     .hook = read_arc,
     .doc = "The sector in degrees, from +X towards +Z, greater than 0, at most 360."},
    VOLUME_EDGE};
static const pfx_key ellipse_keys[] = {
    TYPE("An ellipse in the local XZ plane: volume = the area, edge = the rim by arc length."),
    {"radii", PFX_KEY_CODE, PFX_KEY_REQUIRED, .offset = -1, .schema = LENGTHS(2),
     .doc = "[a, b]: semi-axes along X and Z in metres, each at least 0."},
    VOLUME_EDGE};
static const pfx_key box_keys[] = {
    TYPE("A box centred on the emitter: volume, or surface (the six faces by area)."),
    {"size", PFX_KEY_CODE, PFX_KEY_REQUIRED, .offset = -1, .schema = LENGTHS(3),
     .doc = "Full edge lengths [x, y, z] in metres, each at least 0."},
    VOLUME_SURFACE};
static const pfx_key sphere_keys[] = {
    TYPE("A ball: volume (a thick shell with inner), or surface (the sphere r = radius)."),
    RADIUS_ROW, INNER_ROW, VOLUME_SURFACE};
static const pfx_key hemisphere_keys[] = {
    TYPE("The y >= 0 half of a ball: volume, or surface (the dome only)."), RADIUS_ROW, INNER_ROW,
    VOLUME_SURFACE};
static const pfx_key cylinder_keys[] = {
    TYPE("A cylinder on local +Y from y = 0 to y = height: volume, or surface (the side only, no "
         "caps)."),
    RADIUS_ROW, HEIGHT_ROW, VOLUME_SURFACE};
static const pfx_key cone_keys[] = {
    TYPE("A cone with its base (radius) at y = 0 and apex at y = height: volume, or surface (the "
         "lateral surface only)."),
    RADIUS_ROW,
    HEIGHT_ROW,
    {"angle", PFX_KEY_NUMBER, PFX_KEY_DEGREES, .lo = 0, .hi = 90, .offset = S(angle),
     .doc = "Degrees, 0 to 90: the volume normal (direction: normal) tilts outward from +Y by "
            "angle x rho / radius."},
    VOLUME_SURFACE};
static const pfx_key mesh_keys[] = {
    TYPE("A Wavefront OBJ surface, uniform by triangle area."),
    {"file", PFX_KEY_STRING, PFX_KEY_REQUIRED, .offset = -1,
     .doc = "Path of the OBJ file, relative to the effect file's directory."},
    {"scale", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT, .lo = 0, .hi = INFINITY, .def = {1}, .offset = -1,
     .doc = "Scale of the mesh's coordinates, greater than 0."},
    EMIT_FROM("\"surface\"", "surface", "surface")};

#define INNER_VOLUME_ONLY                                                                          \
    "{\"if\": {\"required\": [\"inner\"]}, \"then\": {\"properties\": {\"emit_from\": "            \
    "{\"const\": \"volume\"}}}}"
static PFX_KEY_TABLE(shape_point, "shape_point", "point", NULL, point_keys);
static PFX_KEY_TABLE(shape_line, "shape_line", "line", NULL, line_keys);
static PFX_KEY_TABLE(shape_rect, "shape_rect", "rect", NULL, rect_keys);
/* inner is for volume samples only */
static PFX_KEY_TABLE_EXTRA(shape_disc, "shape_disc", "disc", NULL, disc_keys, INNER_VOLUME_ONLY);
static PFX_KEY_TABLE(shape_ellipse, "shape_ellipse", "ellipse", NULL, ellipse_keys);
static PFX_KEY_TABLE(shape_box, "shape_box", "box", NULL, box_keys);
/* inner is for volume samples only */
static PFX_KEY_TABLE_EXTRA(shape_sphere, "shape_sphere", "sphere", NULL, sphere_keys,
                           INNER_VOLUME_ONLY);
/* inner is for volume samples only */
static PFX_KEY_TABLE_EXTRA(shape_hemisphere, "shape_hemisphere", "hemisphere", NULL,
                           hemisphere_keys, INNER_VOLUME_ONLY);
static PFX_KEY_TABLE(shape_cylinder, "shape_cylinder", "cylinder", NULL, cylinder_keys);
static PFX_KEY_TABLE(shape_cone, "shape_cone", "cone", NULL, cone_keys);
static PFX_KEY_TABLE(shape_mesh, "shape_mesh", "mesh", NULL, mesh_keys);

/* One table per shape kind, in the order of PFX_SHAPE_KINDS. */
const pfx_key_table *const pfx_shape_tables[] = {
    &shape_point,  &shape_line,       &shape_rect,     &shape_disc, &shape_ellipse, &shape_box,
    &shape_sphere, &shape_hemisphere, &shape_cylinder, &shape_cone, &shape_mesh,    NULL};
_Static_assert(sizeof pfx_shape_tables / sizeof *pfx_shape_tables ==
                   sizeof kind_modes / sizeof *kind_modes + 1,
               "a shape kind without its key table or modes");

/* `arc` in degrees, kept as a fraction of a turn. */
static void read_arc(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    pfx_shape *s = dest;
    double arc;
    if (pfx_read_number(r, v, "arc", &arc) && pfx_check_above(r, v, "arc", arc, 0, true) &&
        pfx_check_below(r, v, "arc", arc, 360, false))
        s->arc_turns = arc / 360;
}

#define ELLIPSE_SEGMENTS 512

static const char *article(const char *word) { return strchr("aeiou", word[0]) ? "an" : "a"; }

/* A required number key, at least 0: reports its absence at the type node. */
static bool need_length(pfx_reader *r, const pfx_node *n, const pfx_node *type, const char *key,
                        double *out) {
    const pfx_node *v = pfx_node_get(n, key);
    if (!v) {
        pfx_read_error(r, type, PFX_RULE_MISSING_KEY, "%s %s shape needs a '%s'",
                       article(type->text), type->text, key);
        return false;
    }
    return pfx_read_number(r, v, key, out) && pfx_check_above(r, v, key, *out, 0, false);
}

/* A required list of `count` numbers, each at least 0 unless `any_sign`;
 * `needed` says what is missing ("a 'size' [x, y, z]"). */
static bool need_numbers(pfx_reader *r, const pfx_node *n, const pfx_node *type, const char *key,
                         const char *needed, double *out, int count, bool any_sign) {
    const pfx_node *v = pfx_node_get(n, key);
    if (!v) {
        pfx_read_error(r, type, PFX_RULE_MISSING_KEY, "%s %s shape needs %s", article(type->text),
                       type->text, needed);
        return false;
    }
    if (!pfx_read_numbers(r, v, key, out, count))
        return false;
    bool ok = true;
    for (int i = 0; i < count && !any_sign; i++)
        ok &= pfx_check_above(r, v->items[i], key, out[i], 0, false);
    return ok;
}

/* `inner`: 0 <= inner < radius, and only for volume samples (a surface or
 * rim is at `radius`). */
static void read_inner(pfx_reader *r, const pfx_node *n, pfx_shape *s, bool radius_ok) {
    const pfx_node *v = pfx_node_get(n, "inner");
    if (!v || !pfx_read_number(r, v, "inner", &s->inner))
        return;
    if (s->from != PFX_EMIT_VOLUME) {
        pfx_read_error(r, v, PFX_RULE_INAPPLICABLE_KEY,
                       "'inner' applies only to emit_from: volume (the %s is at 'radius')",
                       s->from == PFX_EMIT_EDGE ? "edge" : "surface");
        return;
    }
    if (pfx_check_above(r, v, "inner", s->inner, 0, false) && radius_ok && !(s->inner < s->radius))
        pfx_read_error(r, v, PFX_RULE_INCONSISTENT_VALUES,
                       "'inner' must be less than 'radius' (%g), got %g", s->radius, s->inner);
}

/* The rim's cumulative arc length by the trapezoid rule, which the sampler
 * inverts exactly (sample.c, ellipse_edge). */
static bool ellipse_table(pfx_reader *r, pfx_shape *s) {
    double *cum = pfx_arena_alloc(r->arena, (ELLIPSE_SEGMENTS + 1) * sizeof *cum);
    if (!cum)
        return false;
    double a = s->radii[0], b = s->radii[1], h = 2 * M_PI / ELLIPSE_SEGMENTS;
    double prev = hypot(0.0, b);
    cum[0] = 0;
    for (int i = 1; i <= ELLIPSE_SEGMENTS; i++) {
        double t = h * i, v = hypot(a * sin(t), b * cos(t));
        cum[i] = cum[i - 1] + h * (prev + v) / 2;
        prev = v;
    }
    s->cum = cum;
    s->cum_count = ELLIPSE_SEGMENTS + 1;
    return true;
}

/* The mesh file, relative to the effect file's directory, read once however
 * many emitters name it. */
static void read_mesh(pfx_reader *r, const pfx_node *n, const pfx_node *type, pfx_shape *s,
                      const char *effect_path) {
    const pfx_node *v = pfx_node_get(n, "file");
    const char *file;
    double scale = 1;
    const pfx_node *sc = pfx_node_get(n, "scale");
    bool scale_ok = !sc || (pfx_read_number(r, sc, "scale", &scale) &&
                            pfx_check_above(r, sc, "scale", scale, 0, true));
    if (!v) {
        pfx_read_error(r, type, PFX_RULE_MISSING_KEY,
                       "a mesh shape needs a 'file' (a Wavefront OBJ path)");
        return;
    }
    char path[4096];
    if (!pfx_read_path(r, v, "file", effect_path, &file, path, sizeof path) || !scale_ok)
        return;
    /* A file named before at the same scale shares its triangles. */
    const pfx_mesh *seen = pfx_file_cache_find(r, path, PFX_FILE_MESH, scale);
    pfx_mesh m, *kept;
    if (seen) {
        m = *seen;
    } else {
        pfx_diag_at at = pfx_read_at(r, v);
        if (!pfx_mesh_load(path, file, scale, r->arena, &m, &at))
            return;
        if ((kept = pfx_arena_alloc(r->arena, sizeof *kept))) {
            *kept = m;
            pfx_file_cache_add(r, path, PFX_FILE_MESH, scale, kept);
        }
    }
    s->verts = m.verts;
    s->tris = m.tris;
    s->cum = m.cum;
    s->cum_count = m.tri_count;
    s->file = pfx_arena_strndup(r->arena, path, strlen(path));
}

bool pfx_compile_shape(pfx_reader *r, const pfx_node *n, pfx_shape *s, const char *emitter,
                       const char *effect_path) {
    int errors = r->d->errors;
    char where[160];
    snprintf(where, sizeof where, "the shape of emitter '%s'", emitter);
    if (!pfx_read_map(r, n, "shape"))
        return false;
    int t = pfx_keys_kind(r, n, n, "a shape", "shape type", pfx_shape_names, true);
    if (t < 0)
        return false;
    const pfx_node *type = pfx_node_get(n, "type");
    memset(s, 0, sizeof *s);
    s->type = (pfx_shape_type)t;
    unsigned modes = kind_modes[t];
    const pfx_key_table *table = pfx_shape_tables[t];
    pfx_keys_check(r, n, table, where);

    s->from = s->type == PFX_SHAPE_MESH ? PFX_EMIT_SURFACE : PFX_EMIT_VOLUME;
    const pfx_node *v;
    if ((v = pfx_node_get(n, "emit_from"))) {
        int m = pfx_read_enum(r, v, "emit_from", "emit_from mode", pfx_emit_from_names);
        if (m >= 0 && !(modes & (1u << m))) {
            char list[64] = "";
            for (int i = 0; pfx_emit_from_names[i]; i++)
                if (modes & (1u << i))
                    snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
                             list[0] ? " or " : "", pfx_emit_from_names[i]);
            pfx_read_error(r, v, PFX_RULE_UNKNOWN_CHOICE,
                           "%s %s shape cannot emit from '%s'; 'emit_from' must be %s",
                           article(type->text), type->text, pfx_emit_from_names[m], list);
        } else if (m >= 0) {
            s->from = (pfx_emit_from)m;
        }
    }
    /* The typed rows (arc, angle); the rest need the checks below. */
    pfx_keys_read(r, n, table, s);

    bool radius_ok = false;
    switch (s->type) {
    case PFX_SHAPE_POINT:
        break;
    case PFX_SHAPE_LINE:
        need_numbers(r, n, type, "from", "a 'from' point [x, y, z]", s->line_from, 3, true);
        need_numbers(r, n, type, "to", "a 'to' point [x, y, z]", s->line_to, 3, true);
        break;
    case PFX_SHAPE_RECT:
        need_numbers(r, n, type, "size", "a 'size' [w, h]", s->size, 2, false);
        break;
    case PFX_SHAPE_BOX:
        need_numbers(r, n, type, "size", "a 'size' [x, y, z]", s->size, 3, false);
        break;
    case PFX_SHAPE_ELLIPSE:
        if (need_numbers(r, n, type, "radii", "'radii' [a, b]", s->radii, 2, false) &&
            s->from == PFX_EMIT_EDGE && !ellipse_table(r, s))
            pfx_read_error(r, n, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        break;
    case PFX_SHAPE_DISC:
    case PFX_SHAPE_SPHERE:
    case PFX_SHAPE_HEMISPHERE:
        radius_ok = need_length(r, n, type, "radius", &s->radius);
        read_inner(r, n, s, radius_ok);
        break;
    case PFX_SHAPE_CYLINDER:
    case PFX_SHAPE_CONE:
        need_length(r, n, type, "radius", &s->radius);
        need_length(r, n, type, "height", &s->height);
        break;
    case PFX_SHAPE_MESH:
        read_mesh(r, n, type, s, effect_path);
        break;
    }
    return r->d->errors == errors;
}
