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
#include <string.h>

#include "compile/mesh_load.h"

static const char *const shape_types[] = {"point",    "line", "rect",   "disc",
                                          "ellipse",  "box",  "sphere", "hemisphere",
                                          "cylinder", "cone", "mesh",   NULL};
static const pfx_shape_type shape_enum[] = {
    PFX_SHAPE_POINT,    PFX_SHAPE_LINE, PFX_SHAPE_RECT,   PFX_SHAPE_DISC,
    PFX_SHAPE_ELLIPSE,  PFX_SHAPE_BOX,  PFX_SHAPE_SPHERE, PFX_SHAPE_HEMISPHERE,
    PFX_SHAPE_CYLINDER, PFX_SHAPE_CONE, PFX_SHAPE_MESH};

static const char *const emit_modes[] = {"volume", "surface", "edge", NULL};

static const char *const point_keys[] = {"type", "emit_from", NULL};
static const char *const line_keys[] = {"type", "from", "to", "emit_from", NULL};
static const char *const rect_keys[] = {"type", "size", "emit_from", NULL};
static const char *const disc_keys[] = {"type", "radius", "inner", "arc", "emit_from", NULL};
static const char *const ellipse_keys[] = {"type", "radii", "emit_from", NULL};
static const char *const box_keys[] = {"type", "size", "emit_from", NULL};
static const char *const sphere_keys[] = {"type", "radius", "inner", "emit_from", NULL};
static const char *const cylinder_keys[] = {"type", "radius", "height", "emit_from", NULL};
static const char *const cone_keys[] = {"type", "radius", "height", "angle", "emit_from", NULL};
static const char *const mesh_keys[] = {"type", "file", "scale", "emit_from", NULL};

#define VOL (1u << PFX_EMIT_VOLUME)
#define SURF (1u << PFX_EMIT_SURFACE)
#define EDGE (1u << PFX_EMIT_EDGE)

/* Per type, indexed by pfx_shape_type: its keys and its emit_from modes. */
static const struct {
    const char *const *keys;
    unsigned modes;
} kinds[] = {
    [PFX_SHAPE_POINT] = {point_keys, VOL},
    [PFX_SHAPE_SPHERE] = {sphere_keys, VOL | SURF},
    [PFX_SHAPE_BOX] = {box_keys, VOL | SURF},
    [PFX_SHAPE_DISC] = {disc_keys, VOL | EDGE},
    [PFX_SHAPE_LINE] = {line_keys, VOL},
    [PFX_SHAPE_RECT] = {rect_keys, VOL | EDGE},
    [PFX_SHAPE_ELLIPSE] = {ellipse_keys, VOL | EDGE},
    [PFX_SHAPE_HEMISPHERE] = {sphere_keys, VOL | SURF},
    [PFX_SHAPE_CYLINDER] = {cylinder_keys, VOL | SURF},
    [PFX_SHAPE_CONE] = {cone_keys, VOL | SURF},
    [PFX_SHAPE_MESH] = {mesh_keys, SURF},
};

#define ELLIPSE_SEGMENTS 512

const char *pfx_shape_type_name(pfx_shape_type t) {
    for (size_t i = 0; i < sizeof shape_enum / sizeof *shape_enum; i++)
        if (shape_enum[i] == t)
            return shape_types[i];
    return "?";
}

static const char *article(const char *word) { return strchr("aeiou", word[0]) ? "an" : "a"; }

/* A required number key, at least 0: reports its absence at the type node. */
static bool need_length(pfx_reader *r, const pfx_node *n, const pfx_node *type, const char *key,
                        double *out) {
    const pfx_node *v = pfx_node_get(n, key);
    if (!v) {
        pfx_read_error(r, type, "%s %s shape needs a '%s'", article(type->text), type->text, key);
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
        pfx_read_error(r, type, "%s %s shape needs %s", article(type->text), type->text, needed);
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
        pfx_read_error(r, v, "'inner' applies only to emit_from: volume (the %s is at 'radius')",
                       s->from == PFX_EMIT_EDGE ? "edge" : "surface");
        return;
    }
    if (pfx_check_above(r, v, "inner", s->inner, 0, false) && radius_ok && !(s->inner < s->radius))
        pfx_read_error(r, v, "'inner' must be less than 'radius' (%g), got %g", s->radius,
                       s->inner);
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

/* The mesh file, relative to the effect file's directory. */
static void read_mesh(pfx_reader *r, const pfx_node *n, const pfx_node *type, pfx_shape *s,
                      const char *effect_path) {
    const pfx_node *v = pfx_node_get(n, "file");
    const char *file;
    double scale = 1;
    const pfx_node *sc = pfx_node_get(n, "scale");
    bool scale_ok = !sc || (pfx_read_number(r, sc, "scale", &scale) &&
                            pfx_check_above(r, sc, "scale", scale, 0, true));
    if (!v) {
        pfx_read_error(r, type, "a mesh shape needs a 'file' (a Wavefront OBJ path)");
        return;
    }
    if (!pfx_read_string(r, v, "file", &file) || !scale_ok)
        return;
    char path[4096];
    size_t dir = 0;
    if (file[0] != '/' && effect_path) {
        const char *slash = strrchr(effect_path, '/');
        dir = slash ? (size_t)(slash - effect_path) + 1 : 0;
    }
    if (dir + strlen(file) + 1 > sizeof path) {
        pfx_read_error(r, v, "the path of '%s' is too long", file);
        return;
    }
    memcpy(path, effect_path, dir);
    strcpy(path + dir, file);
    pfx_mesh m;
    pfx_diag_at at = pfx_read_at(r, v);
    if (!pfx_mesh_load(path, file, scale, r->arena, &m, &at))
        return;
    s->verts = m.verts;
    s->tris = m.tris;
    s->cum = m.cum;
    s->cum_count = m.tri_count;
}

bool pfx_compile_shape(pfx_reader *r, const pfx_node *n, pfx_shape *s, const char *emitter,
                       const char *effect_path) {
    int errors = r->d->errors;
    char where[160];
    snprintf(where, sizeof where, "the shape of emitter '%s'", emitter);
    if (!pfx_read_map(r, n, "shape"))
        return false;
    const pfx_node *type = pfx_node_get(n, "type");
    if (!type) {
        pfx_read_error(r, n,
                       "a shape needs a 'type' (point, line, rect, disc, ellipse, box, sphere, "
                       "hemisphere, cylinder, cone or mesh)");
        return false;
    }
    int t = pfx_read_enum(r, type, "type", "shape type", shape_types);
    if (t < 0)
        return false;
    memset(s, 0, sizeof *s);
    s->type = shape_enum[t];
    unsigned modes = kinds[s->type].modes;
    pfx_read_check_keys(r, n, kinds[s->type].keys, where);

    s->from = s->type == PFX_SHAPE_MESH ? PFX_EMIT_SURFACE : PFX_EMIT_VOLUME;
    const pfx_node *v;
    if ((v = pfx_node_get(n, "emit_from"))) {
        int m = pfx_read_enum(r, v, "emit_from", "emit_from mode", emit_modes);
        if (m >= 0 && !(modes & (1u << m))) {
            char list[64] = "";
            for (int i = 0; emit_modes[i]; i++)
                if (modes & (1u << i))
                    snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
                             list[0] ? " or " : "", emit_modes[i]);
            pfx_read_error(r, v, "%s %s shape cannot emit from '%s'; 'emit_from' must be %s",
                           article(type->text), type->text, emit_modes[m], list);
        } else if (m >= 0) {
            s->from = (pfx_emit_from)m;
        }
    }

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
            pfx_read_error(r, n, "out of memory");
        break;
    case PFX_SHAPE_DISC:
    case PFX_SHAPE_SPHERE:
    case PFX_SHAPE_HEMISPHERE:
        radius_ok = need_length(r, n, type, "radius", &s->radius);
        read_inner(r, n, s, radius_ok);
        if (s->type == PFX_SHAPE_DISC && (v = pfx_node_get(n, "arc"))) {
            double arc;
            if (pfx_read_number(r, v, "arc", &arc) && pfx_check_above(r, v, "arc", arc, 0, true) &&
                pfx_check_below(r, v, "arc", arc, 360, false))
                s->arc_turns = arc / 360;
        }
        break;
    case PFX_SHAPE_CYLINDER:
    case PFX_SHAPE_CONE:
        need_length(r, n, type, "radius", &s->radius);
        need_length(r, n, type, "height", &s->height);
        if (s->type == PFX_SHAPE_CONE && (v = pfx_node_get(n, "angle")) &&
            pfx_read_number(r, v, "angle", &s->angle_deg) &&
            pfx_check_above(r, v, "angle", s->angle_deg, 0, false))
            pfx_check_below(r, v, "angle", s->angle_deg, 90, false);
        break;
    case PFX_SHAPE_MESH:
        read_mesh(r, n, type, s, effect_path);
        break;
    }
    return r->d->errors == errors;
}
