/* Node tree -> pfx_effect: validation, defaults and units. The only stage
 * that reports problems with the effect's content. */
#ifndef PFX_COMPILE_H
#define PFX_COMPILE_H

#include "base/arena.h"
#include "base/diag.h"
#include "model/effect.h"
#include "parse/node.h"

typedef struct pfx_compile_options {
    uint64_t max_particles; /* 0: PFX_DEFAULT_MAX_PARTICLES */
    bool has_seed;
    uint64_t seed;     /* --seed: overrides the file's */
    double fps;        /* > 0: overrides the file's */
    int width, height; /* > 0: override image.size */
} pfx_compile_options;

/* Compiles a parsed document. Reports every problem into d; returns NULL if
 * there was any error. The effect and everything it points to live in
 * `arena`, freed by the caller with pfx_arena_free. */
pfx_effect *pfx_compile(const pfx_node *root, const char *path, const pfx_compile_options *opt,
                        pfx_arena *arena, pfx_diags *d);

/* Reads, parses and compiles the file at path in one call, printing nothing:
 * diagnostics go to d, which the caller initialises with pfx_load's source
 * buffer; see main.c for the usual use. */
typedef struct pfx_loaded {
    char *source; /* the file's bytes (malloc'd), NUL-terminated */
    size_t source_len;
    pfx_doc doc;
    pfx_arena arena; /* the effect's */
    pfx_effect *effect;
    pfx_diags diags;
} pfx_loaded;

/* Loads path into l. Returns the effect or NULL (errors in l->diags; an I/O
 * failure is an error without position). Free with pfx_loaded_free. */
pfx_effect *pfx_load(pfx_loaded *l, const char *path, const pfx_compile_options *opt);
void pfx_loaded_free(pfx_loaded *l);

#endif
