/* Reading a mapping by its key table: the unknown-key check, the defaults,
 * and every row's typed reading with its range, or its hook. The messages
 * are the readers' of read.c, so a key read here reports exactly as one
 * read by hand would. */
#include "compile/keys.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define MAX_ROWS 64

const pfx_key *pfx_keys_find(const pfx_key_table *t, const char *name) {
    for (size_t i = 0; i < t->count; i++)
        if (!strcmp(t->keys[i].name, name))
            return &t->keys[i];
    return NULL;
}

bool pfx_keys_check(pfx_reader *r, const pfx_node *map, const pfx_key_table *t, const char *where) {
    const char *names[MAX_ROWS + 1];
    size_t n = t->count < MAX_ROWS ? t->count : MAX_ROWS;
    for (size_t i = 0; i < n; i++)
        names[i] = t->keys[i].name;
    names[n] = NULL;
    return pfx_read_check_keys(r, map, names, where);
}

void pfx_keys_defaults(const pfx_key_table *t, void *dest) {
    for (size_t i = 0; i < t->count; i++) {
        const pfx_key *k = &t->keys[i];
        if (k->offset < 0 || (k->flags & PFX_KEY_NO_DEFAULT))
            continue;
        char *at = (char *)dest + k->offset;
        switch (k->type) {
        case PFX_KEY_NUMBER: {
            double v = k->def[0];
            if (k->flags & PFX_KEY_DEGREES)
                v *= PFX_DEGREE;
            memcpy(at, &v, sizeof v);
            break;
        }
        case PFX_KEY_WHOLE:
        case PFX_KEY_ENUM: {
            int v = (int)k->def[0] + (k->type == PFX_KEY_ENUM ? k->enum_base : 0);
            memcpy(at, &v, sizeof v);
            break;
        }
        case PFX_KEY_BOOL: {
            bool v = k->def[0] != 0;
            memcpy(at, &v, sizeof v);
            break;
        }
        case PFX_KEY_VEC3:
            memcpy(at, k->def, 3 * sizeof(double));
            break;
        case PFX_KEY_VALUE: {
            pfx_value v = pfx_value_const(k->def[0]);
            memcpy(at, &v, sizeof v);
            break;
        }
        case PFX_KEY_RANGE:
            memcpy(at, (double[2]){k->def[0], k->def[0]}, 2 * sizeof(double));
            break;
        case PFX_KEY_MAP: /* the mapping's own defaults, where it lands */
            pfx_keys_defaults(k->table, at);
            break;
        default:
            break;
        }
    }
}

/* A number within the row's range; false (reported) otherwise. */
static bool read_ranged(pfx_reader *r, const pfx_node *v, const pfx_key *k, double *out) {
    double x;
    if (!pfx_read_number(r, v, k->name, &x) ||
        !pfx_check_above(r, v, k->name, x, k->lo, k->flags & PFX_KEY_LO_STRICT) ||
        !pfx_check_below(r, v, k->name, x, k->hi, k->flags & PFX_KEY_HI_STRICT))
        return false;
    *out = x;
    return true;
}

/* `true` or `false`. */
static bool read_bool(pfx_reader *r, const pfx_node *v, const char *key, bool *out) {
    if (v->kind != PFX_NODE_SCALAR || (strcmp(v->text, "true") && strcmp(v->text, "false"))) {
        pfx_read_error(r, v, PFX_RULE_WRONG_TYPE, "'%s' must be true or false", key);
        return false;
    }
    *out = !strcmp(v->text, "true");
    return true;
}

static void read_row(pfx_reader *r, const pfx_node *map, const pfx_node *v, const pfx_key *k,
                     void *dest) {
    char *at = (char *)dest + k->offset;
    double x;
    switch (k->type) {
    case PFX_KEY_NUMBER:
        if (read_ranged(r, v, k, &x)) {
            if (k->flags & PFX_KEY_DEGREES)
                x *= PFX_DEGREE;
            memcpy(at, &x, sizeof x);
        }
        break;
    case PFX_KEY_WHOLE:
        if (read_ranged(r, v, k, &x)) {
            if (x != floor(x))
                pfx_read_error(r, v, PFX_RULE_NOT_INTEGER, "'%s' must be a whole number, got %g",
                               k->name, x);
            int i = (int)x;
            memcpy(at, &i, sizeof i);
        }
        break;
    case PFX_KEY_BOOL: {
        bool b;
        if (read_bool(r, v, k->name, &b))
            memcpy(at, &b, sizeof b);
        break;
    }
    case PFX_KEY_VEC3:
        if (k->hi > 0)
            pfx_read_vec3_within(r, map, k->name, (double *)(void *)at, k->hi);
        else
            pfx_read_numbers(r, v, k->name, (double *)(void *)at, 3);
        break;
    case PFX_KEY_ENUM: {
        int i = pfx_read_enum(r, v, k->name, k->what ? k->what : k->name, k->names);
        if (i >= 0) {
            i += k->enum_base;
            memcpy(at, &i, sizeof i);
        }
        break;
    }
    case PFX_KEY_VALUE:
        pfx_read_value_in(r, v, k->name, (pfx_value *)(void *)at, k->lo,
                          k->flags & PFX_KEY_LO_STRICT, k->hi);
        break;
    case PFX_KEY_RANGE: {
        pfx_value val;
        double *out = (double *)(void *)at;
        if (!pfx_read_value(r, v, k->name, &val))
            break;
        if (val.dist == PFX_DIST_NORMAL) {
            pfx_read_error(r, v, PFX_RULE_WRONG_TYPE, "'%s' takes a number or a range [min, max]",
                           k->name);
            break;
        }
        out[0] = pfx_value_min(&val);
        out[1] = pfx_value_max(&val);
        (void)(pfx_check_above(r, v, k->name, out[0], k->lo, false) &&
               pfx_check_below(r, v, k->name, out[1], k->hi, false));
        break;
    }
    case PFX_KEY_COLOUR:
        pfx_read_color(r, v, k->name, 1, (float *)(void *)at);
        break;
    case PFX_KEY_STRING:
        pfx_read_string(r, v, k->name, (const char **)(void *)at);
        break;
    case PFX_KEY_MAP:
        if (pfx_read_map(r, v, k->name)) {
            char where[96];
            snprintf(where, sizeof where, "'%s'", k->name);
            pfx_keys_check(r, v, k->table, where);
            pfx_keys_read(r, v, k->table, at);
        }
        break;
    case PFX_KEY_CODE:
        break;
    }
}

void pfx_keys_read(pfx_reader *r, const pfx_node *map, const pfx_key_table *t, void *dest) {
    for (size_t i = 0; i < t->count; i++) {
        const pfx_key *k = &t->keys[i];
        const pfx_node *v = pfx_node_get(map, k->name);
        if (!v)
            continue;
        if (k->hook)
            k->hook(r, map, v, dest);
        else if (k->offset >= 0)
            read_row(r, map, v, k, dest);
        /* else: read by the table's own code, after this */
    }
}

int pfx_keys_kind(pfx_reader *r, const pfx_node *map, const pfx_node *blame, const char *subject,
                  const char *what, const char *const *kinds, bool one_of) {
    char list[256];
    const pfx_node *t = pfx_node_get(map, "type");
    if (!t) {
        pfx_kind_list(kinds, true, list, sizeof list);
        pfx_read_error(r, blame, PFX_RULE_MISSING_KEY, "%s needs a 'type' (%s)", subject, list);
        return -1;
    }
    const char *name;
    if (!pfx_read_string(r, t, "type", &name))
        return -1;
    int k = pfx_kind_find(kinds, name);
    if (k >= 0)
        return k;
    const char *s = pfx_suggest(name, kinds);
    pfx_kind_list(kinds, !one_of, list, sizeof list);
    if (s)
        pfx_read_error(r, t, PFX_RULE_UNKNOWN_CHOICE, "unknown %s '%s'; did you mean '%s'?", what,
                       name, s);
    else
        pfx_read_error(r, t, PFX_RULE_UNKNOWN_CHOICE, "unknown %s '%s'; expected %s%s", what, name,
                       one_of ? "one of: " : "", list);
    return -1;
}
