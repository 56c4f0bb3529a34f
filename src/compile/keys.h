/* The key table: every YAML key of the effect format as a row of the table
 * of the mapping it belongs to (name, type, range, default, where it lands,
 * what it means). One row drives the unknown-key check and its suggestion,
 * the typed reading with its range check, the default, and the JSON Schema
 * (`pfx schema`); the man page test reads the schema. Keys that need code
 * (a colour gradient, keyframes, a cross-key rule) keep a hook that the
 * row names, so even they are found, reported and documented through it. */
#ifndef PFX_COMPILE_KEYS_H
#define PFX_COMPILE_KEYS_H

#include <stddef.h>

#include "compile/read.h"

typedef enum {
    PFX_KEY_NUMBER, /* a double in [lo, hi] */
    PFX_KEY_WHOLE,  /* a whole number in [lo, hi], stored as an int */
    PFX_KEY_BOOL,   /* true or false */
    PFX_KEY_VEC3,   /* [x, y, z]; each within +-hi when hi > 0 */
    PFX_KEY_ENUM,   /* one name of `names`, stored as an int (its index + enum_base) */
    PFX_KEY_VALUE,  /* a random value, every sample within [lo, hi] */
    PFX_KEY_RANGE,  /* a number or [min, max] (or {mean, var}) within [lo, hi], as double[2] */
    PFX_KEY_COLOUR, /* a colour, stored as float[4] */
    PFX_KEY_STRING, /* a string, stored as const char * (the node's text) */
    PFX_KEY_MAP,    /* a mapping with its own table */
    PFX_KEY_CODE    /* read by the hook alone; the schema from `schema` */
} pfx_key_type;

enum {
    PFX_KEY_LO_STRICT = 1u << 0,  /* above lo, not at it */
    PFX_KEY_HI_STRICT = 1u << 1,  /* below hi, not at it */
    PFX_KEY_REQUIRED = 1u << 2,   /* the mapping needs it (its code says so, with
                                     the wording that fits) */
    PFX_KEY_NO_DEFAULT = 1u << 3, /* no default is written or published */
    PFX_KEY_DEGREES = 1u << 4,    /* NUMBER: written in degrees, stored in radians */
    PFX_KEY_NONZERO = 1u << 5     /* VEC3: not [0, 0, 0] (its code says so) */
};

typedef struct pfx_key_table pfx_key_table;

/* Reads the key's value node v of mapping map into dest (the struct the
 * table fills). A hook replaces the typed reading of its row. */
typedef void (*pfx_key_hook)(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest);

typedef struct pfx_key {
    const char *name;
    pfx_key_type type;
    unsigned flags;
    double lo, hi;
    double def[3];              /* NUMBER, WHOLE, BOOL, VALUE: def[0]; VEC3: all three */
    ptrdiff_t offset;           /* where it lands in dest; -1: a hook's own, or read
                                   by the table's code after pfx_keys_read */
    const char *const *names;   /* ENUM: the NULL-terminated names */
    const char *what;           /* ENUM: the word in "unknown <what> 'x'" */
    int enum_base;              /* ENUM: the stored value of names[0] */
    const pfx_key_table *table; /* MAP */
    pfx_key_hook hook;          /* read by code instead of by type */
    const char *schema;         /* CODE, or a hook's richer syntax: a JSON Schema fragment */
    const char *doc;            /* what it means, for the schema's description */
} pfx_key;

struct pfx_key_table {
    const char *name; /* its name in the schema's $defs */
    const char *doc;  /* what the mapping is */
    const char *kind; /* for one kind's table (force_drag): its `type` ("drag") */
    const pfx_key *keys;
    size_t count;
    const char *extra; /* rules across keys, as JSON Schema to merge (or NULL) */
};

#define PFX_KEY_TABLE(var, nm, kd, dc, rows)                                                       \
    const pfx_key_table var = {nm, dc, kd, rows, sizeof rows / sizeof rows[0], NULL}
#define PFX_KEY_TABLE_EXTRA(var, nm, kd, dc, rows, ex)                                             \
    const pfx_key_table var = {nm, dc, kd, rows, sizeof rows / sizeof rows[0], ex}

/* Every key of map is a row of t; reports the others at their key, with
 * the nearest row's name as a suggestion. `where` names the mapping in
 * messages ("emitter 'flame'"). Returns false if any key was unknown. */
bool pfx_keys_check(pfx_reader *r, const pfx_node *map, const pfx_key_table *t, const char *where);

/* Writes every row's default into dest (rows with an offset and a type
 * that has one). */
void pfx_keys_defaults(const pfx_key_table *t, void *dest);

/* Reads every row present in map into dest: by its hook, or by its type
 * with its range checked; absent rows keep what dest holds. */
void pfx_keys_read(pfx_reader *r, const pfx_node *map, const pfx_key_table *t, void *dest);

/* The kind a mapping's `type` names: its index in `kinds`, or -1 after
 * reporting a missing type at `blame` ("<subject> needs a 'type' (a, b or
 * c)") or an unknown one with the nearest kind, else the kinds ("expected
 * one of: a, b, c" when one_of, "expected a, b or c" otherwise). */
int pfx_keys_kind(pfx_reader *r, const pfx_node *map, const pfx_node *blame, const char *subject,
                  const char *what, const char *const *kinds, bool one_of);

/* The row of t named `name`, or NULL. */
const pfx_key *pfx_keys_find(const pfx_key_table *t, const char *name);

#endif
