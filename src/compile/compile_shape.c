/* The emitter `shape:` mapping: each shape type's keys, defaults and ranges,
 * compiled into a pfx_shape. Sampling the shape is the simulation's job
 * (src/sim/sample.c); this file only validates and fills. */
#include "compile/compile_shape.h"

#include <string.h>

static const char *const shape_types[] = {"point", "sphere", "box", "disc", NULL};

bool pfx_compile_shape(pfx_reader *r, const pfx_node *n, pfx_shape *s, const char *emitter,
                       const char *effect_path) {
    (void)effect_path; /* mesh paths are relative to the effect file */
    int errors = r->d->errors;
    char where[160];
    snprintf(where, sizeof where, "the shape of emitter '%s'", emitter);
    if (!pfx_read_map(r, n, "shape"))
        return false;
    const pfx_node *type = pfx_node_get(n, "type");
    if (!type) {
        pfx_read_error(r, n, "a shape needs a 'type' (point, sphere, box or disc)");
        return false;
    }
    int t = pfx_read_enum(r, type, "shape type", shape_types);
    if (t < 0)
        return false;
    s->type = (pfx_shape_type)t;
    static const char *const point_keys[] = {"type", NULL};
    static const char *const radius_keys[] = {"type", "radius", NULL};
    static const char *const box_keys[] = {"type", "size", NULL};
    const char *const *keys = s->type == PFX_SHAPE_POINT ? point_keys
                              : s->type == PFX_SHAPE_BOX ? box_keys
                                                         : radius_keys;
    pfx_read_check_keys(r, n, keys, where);
    if (s->type == PFX_SHAPE_SPHERE || s->type == PFX_SHAPE_DISC) {
        const pfx_node *rad = pfx_node_get(n, "radius");
        if (!rad)
            pfx_read_error(r, type, "a %s shape needs a 'radius'", type->text);
        else if (pfx_read_number(r, rad, "radius", &s->radius))
            pfx_check_above(r, rad, "radius", s->radius, 0, false);
    } else if (s->type == PFX_SHAPE_BOX) {
        const pfx_node *sz = pfx_node_get(n, "size");
        if (!sz)
            pfx_read_error(r, type, "a box shape needs a 'size' [x, y, z]");
        else if (pfx_read_numbers(r, sz, "size", s->size, 3))
            for (int i = 0; i < 3; i++)
                pfx_check_above(r, sz->items[i], "size", s->size[i], 0, false);
    }
    return r->d->errors == errors;
}
