/* An emitter's `kill:` list and `bounds:` box: each rule's keys, defaults and
 * ranges, compiled into a pfx_kill_rules (world space, metres, unit normals).
 * Applying the rules is the simulation's job (src/sim/kill.c); this file only
 * validates and fills. */
#include "compile/compile_kill.h"

#include <math.h>
#include <string.h>

/* Every coordinate and length: positions are floats, and beyond this their
 * resolution is coarser than a tenth of a metre. */
#define LIMIT 1e6

static const char *const rule_names[] = {"inside", "outside", "alpha_below",
                                         "distance_from_emitter", NULL};
static const char *const region_names[] = {"box", "sphere", "half_space", NULL};
static const char *const mode_names[] = {"kill", "wrap", NULL};

static bool vec3(pfx_reader *r, const pfx_node *map, const char *key, double out[3]) {
    return pfx_read_vec3_within(r, map, key, out, LIMIT);
}

/* A length in (0, LIMIT] (strict) or [0, LIMIT]. */
static bool length(pfx_reader *r, const pfx_node *n, const char *what, bool strict, double *out) {
    return pfx_read_number(r, n, what, out) && pfx_check_above(r, n, what, *out, 0, strict) &&
           pfx_check_below(r, n, what, *out, LIMIT, false);
}

/* `{center, size}` under key `key` (for the missing-size message). A
 * wrapping box needs every edge long enough to hold a float interval. */
static void box(pfx_reader *r, const pfx_node *key, const pfx_node *n, const char *where, bool wrap,
                double center[3], double half[3]) {
    static const char *const keys[] = {"center", "size", NULL};
    if (!pfx_read_map(r, n, "box"))
        return;
    pfx_read_check_keys(r, n, keys, where);
    vec3(r, n, "center", center);
    const pfx_node *sz = pfx_node_get(n, "size");
    double size[3];
    if (!sz) {
        pfx_read_error(r, key, PFX_RULE_MISSING_KEY, "a box needs a 'size' [x, y, z]");
        return;
    }
    if (!pfx_read_numbers(r, sz, "size", size, 3))
        return;
    for (int i = 0; i < 3; i++) {
        const pfx_node *item = sz->items[i];
        if (wrap && !(size[i] > 0)) {
            pfx_read_error(r, item, PFX_RULE_OUT_OF_RANGE,
                           "a wrapping box's 'size' must be greater than 0, got %g", size[i]);
            continue;
        }
        if (!pfx_check_above(r, item, "size", size[i], 0, false) ||
            !pfx_check_below(r, item, "size", size[i], LIMIT, false))
            continue;
        half[i] = size[i] / 2;
        if (wrap && !((float)(center[i] - half[i]) < (float)(center[i] + half[i])))
            pfx_read_error(r, item, PFX_RULE_OUT_OF_RANGE,
                           "a wrapping box's 'size' %g is below the float resolution at its "
                           "centre %g",
                           size[i], center[i]);
    }
}

/* The value of `inside:` or `outside:`: a mapping with one region. */
static void region(pfx_reader *r, const pfx_node *rule_key, const pfx_node *n, pfx_kill_rule *out) {
    const char *what = rule_key->text;
    if (!pfx_read_map(r, n, what))
        return;
    if (n->count == 0) {
        pfx_read_error(r, n, PFX_RULE_MISSING_KEY, "'%s' needs a region: box, sphere or half_space",
                       what);
        return;
    }
    for (size_t i = 1; i < n->count; i++)
        pfx_read_error(r, n->pairs[i].key, PFX_RULE_CONFLICTING_KEYS,
                       "'%s' takes one region; put '%s' in a kill rule of its own", what,
                       n->pairs[i].key->text);
    const pfx_node *key = n->pairs[0].key, *v = n->pairs[0].value;
    int t = pfx_read_enum(r, key, "region", "region type", region_names);
    if (t < 0)
        return;
    out->shape = (pfx_kill_shape)t;
    if (out->shape == PFX_KILL_BOX) {
        box(r, key, v, "a kill box", false, out->center, out->half);
        return;
    }
    if (!pfx_read_map(r, v, key->text))
        return;
    if (out->shape == PFX_KILL_SPHERE) {
        static const char *const keys[] = {"center", "radius", NULL};
        pfx_read_check_keys(r, v, keys, "a kill sphere");
        vec3(r, v, "center", out->center);
        const pfx_node *rad = pfx_node_get(v, "radius");
        if (!rad)
            pfx_read_error(r, key, PFX_RULE_MISSING_KEY, "a sphere needs a 'radius'");
        else
            length(r, rad, "radius", true, &out->radius);
        return;
    }
    static const char *const keys[] = {"point", "normal", NULL};
    pfx_read_check_keys(r, v, keys, "a kill half_space");
    vec3(r, v, "point", out->center);
    const pfx_node *nn = pfx_node_get(v, "normal");
    double nv[3];
    if (!nn) {
        pfx_read_error(r, key, PFX_RULE_MISSING_KEY, "a half_space needs a 'normal' [x, y, z]");
        return;
    }
    if (!pfx_read_numbers(r, nn, "normal", nv, 3))
        return;
    double len = sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
    if (len == 0) {
        pfx_read_error(r, nn, PFX_RULE_ZERO_VECTOR, "'normal' must not be the zero vector");
        return;
    }
    for (int i = 0; i < 3; i++)
        out->normal[i] = nv[i] / len;
}

/* One list item: a mapping with exactly one key, the rule. */
static void rule(pfx_reader *r, const pfx_node *item, pfx_kill_rule *out) {
    if (item->kind != PFX_NODE_MAP || item->count == 0) {
        pfx_read_error(r, item, PFX_RULE_WRONG_TYPE,
                       "a kill rule must be a mapping with one key: inside, outside, "
                       "alpha_below or distance_from_emitter");
        return;
    }
    for (size_t i = 1; i < item->count; i++)
        pfx_read_error(r, item->pairs[i].key, PFX_RULE_CONFLICTING_KEYS,
                       "a kill rule has one key; put '%s' in a list item of its own",
                       item->pairs[i].key->text);
    const pfx_node *key = item->pairs[0].key, *v = item->pairs[0].value;
    int k = pfx_read_enum(r, key, "kill", "kill rule", rule_names);
    if (k < 0)
        return;
    out->kind = (pfx_kill_kind)k;
    switch (out->kind) {
    case PFX_KILL_INSIDE:
    case PFX_KILL_OUTSIDE:
        region(r, key, v, out);
        break;
    case PFX_KILL_ALPHA_BELOW:
        if (pfx_read_number(r, v, "alpha_below", &out->threshold) &&
            (out->threshold < 0 || out->threshold > 1))
            pfx_read_error(r, v, PFX_RULE_OUT_OF_RANGE, "'alpha_below' must be in 0..1, got %g",
                           out->threshold);
        break;
    case PFX_KILL_DISTANCE:
        length(r, v, "distance_from_emitter", true, &out->threshold);
        break;
    }
}

static void bounds(pfx_reader *r, const pfx_node *n, pfx_kill_rules *out) {
    static const char *const keys[] = {"box", "mode", NULL};
    if (!pfx_read_map(r, n, "bounds"))
        return;
    pfx_read_check_keys(r, n, keys, "'bounds'");
    /* `mode` first: it decides whether a zero edge is allowed. */
    out->bounds = PFX_BOUNDS_KILL;
    const pfx_node *m = pfx_node_get(n, "mode");
    if (m) {
        int i = pfx_read_enum(r, m, "mode", "bounds mode", mode_names);
        if (i == 1)
            out->bounds = PFX_BOUNDS_WRAP;
    }
    const pfx_node *b = pfx_node_get(n, "box");
    if (!b) {
        pfx_read_error(r, n, PFX_RULE_MISSING_KEY,
                       "'bounds' needs a 'box' {center: [x, y, z], size: [x, y, z]}");
        return;
    }
    const pfx_node *key = NULL;
    for (size_t i = 0; i < n->count; i++)
        if (n->pairs[i].value == b)
            key = n->pairs[i].key;
    box(r, key, b, "the bounds box", out->bounds == PFX_BOUNDS_WRAP, out->bounds_center,
        out->bounds_half);
}

bool pfx_compile_kill(pfx_reader *r, const pfx_node *kill_node, const pfx_node *bounds_node,
                      pfx_kill_rules *out) {
    int errors = r->d->errors;
    memset(out, 0, sizeof *out);
    if (bounds_node)
        bounds(r, bounds_node, out);
    if (kill_node) {
        if (kill_node->kind != PFX_NODE_SEQ) {
            pfx_read_error(r, kill_node, PFX_RULE_WRONG_TYPE,
                           "'kill' must be a list of rules, got %s", pfx_node_kind_name(kill_node));
        } else if (kill_node->count > PFX_KILL_MAX_RULES) {
            pfx_read_error(r, kill_node->items[PFX_KILL_MAX_RULES], PFX_RULE_TOO_MANY,
                           "an emitter has at most %d kill rules, got %zu", PFX_KILL_MAX_RULES,
                           kill_node->count);
        } else {
            out->count = kill_node->count;
            for (size_t i = 0; i < kill_node->count; i++)
                rule(r, kill_node->items[i], &out->rules[i]);
        }
    }
    return r->d->errors == errors;
}
