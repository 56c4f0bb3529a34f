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
    bool has_alpha;
    pfx_alpha_mode alpha; /* --alpha: overrides image.alpha */
    int threads;          /* simulation threads; 0: the machine's cores */
    /* --set PATH=VALUE, in order: applied to the node tree by jobs/load.c
     * before compile (which never reads them) */
    const char *const *sets;
    size_t set_count;
} pfx_compile_options;

/* Compiles a parsed document. Reports every problem into d; returns NULL if
 * there was any error. The effect and everything it points to live in
 * `arena`, freed by the caller with pfx_arena_free. */
pfx_effect *pfx_compile(const pfx_node *root, const char *path, const pfx_compile_options *opt,
                        pfx_arena *arena, pfx_diags *d);

#endif
