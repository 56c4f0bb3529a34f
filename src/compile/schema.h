/* The JSON Schema of the effect format, generated from the key tables
 * (compile/schema.c), and the registry of the format's tables it walks
 * (compile/format.c). */
#ifndef PFX_COMPILE_SCHEMA_H
#define PFX_COMPILE_SCHEMA_H

#include "compile/keys.h"

/* A kinded family: a mapping whose `type` picks one of `kinds`, each with
 * its own table (in the same order). */
typedef struct pfx_schema_family {
    const char *name; /* its $defs name: "force" */
    const char *doc;
    const char *type_doc;
    const char *const *kinds;           /* NULL-terminated */
    const pfx_key_table *const *tables; /* NULL-terminated, one per kind */
} pfx_schema_family;

/* A syntax that code reads (a random value, a colour...): a $defs entry
 * written as JSON. */
typedef struct pfx_schema_fragment {
    const char *name;
    const char *json;
} pfx_schema_fragment;

extern const char *const pfx_schema_title;
extern const pfx_key_table pfx_schema_top;
extern const pfx_key_table *const pfx_schema_tables[];   /* NULL-terminated */
extern const pfx_schema_family pfx_schema_families[];    /* ends with a NULL name */
extern const pfx_schema_fragment pfx_schema_fragments[]; /* ends with a NULL name */

/* The whole schema as JSON text (malloc'd; the caller frees it). */
char *pfx_schema_text(void);

#endif
