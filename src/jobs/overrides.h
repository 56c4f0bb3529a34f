/* --set PATH=VALUE: overrides applied to an effect's parsed node tree before
 * it compiles (jobs/overrides.c). Every command that loads an effect gets
 * them through pfx_load, so a front end (render, bake, info, validate, the
 * preview's session) needs nothing of its own. */
#ifndef PFX_JOBS_OVERRIDES_H
#define PFX_JOBS_OVERRIDES_H

#include <stdbool.h>
#include <stddef.h>

#include "parse/node.h"

/* The most --set arguments one command line may give. */
#define PFX_MAX_SETS 256

/* The overrides of one load. Their diagnostics are located in a "file"
 * named --set whose line N is the Nth argument as given (PATH=VALUE), so
 * `--set:2:21:` points into the second --set. */
typedef struct pfx_overrides {
    char *source;    /* the arguments, one a line (malloc'd) */
    pfx_diags diags; /* file "--set", source `source` */
    pfx_doc *values; /* each VALUE parsed (malloc'd, count of them) */
    size_t count;
    const pfx_node **replaced; /* per override: the value it replaced; NULL: none, added */
} pfx_overrides;

/* Applies sets[0..n) ("PATH=VALUE", PATH dot-separated keys and list
 * indices) to doc in order. `file` names the effect in messages. A key
 * absent from the file is inserted when the effect format has it (missing
 * mappings above it too, unless they are names of the author's, such as an
 * emitter's); a path through nothing is an error in ov->diags with the
 * nearest path as a suggestion. Containers on a path are copied before
 * they change, so a YAML alias elsewhere keeps the file's value. Returns
 * false on any error. ov is zeroed first; free it with
 * pfx_overrides_free, whatever this returned. */
bool pfx_overrides_apply(pfx_overrides *ov, pfx_doc *doc, const char *file, const char *const *sets,
                         size_t n);

/* After compile: moves from the file's list to ov->diags every diagnostic
 * compile located in an override's value, each error with a note naming
 * the key of the file it overrides. */
void pfx_overrides_claim(pfx_overrides *ov, pfx_diags *file_diags);

void pfx_overrides_free(pfx_overrides *ov);

#endif
