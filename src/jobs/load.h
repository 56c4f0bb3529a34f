/* Loading an effect file into a compiled effect (jobs/load.c). */
#ifndef PFX_JOBS_LOAD_H
#define PFX_JOBS_LOAD_H

#include "compile/compile.h"
#include "jobs/overrides.h"

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
    pfx_overrides overrides; /* the options' --set, with their own diagnostics */
} pfx_loaded;

/* Loads path into l, applying opt's --set to the parsed tree before it
 * compiles. Returns the effect or NULL (errors in l->diags, those of --set
 * in l->overrides.diags: pfx_loaded_print prints both; an I/O failure is
 * an error without position). Free with pfx_loaded_free. */
pfx_effect *pfx_load(pfx_loaded *l, const char *path, const pfx_compile_options *opt);
/* The same from bytes in memory (a fuzzer's input, a test's text): path
 * only names them in messages and anchors relative mesh paths. The bytes
 * are copied; the caller keeps its own. */
pfx_effect *pfx_load_bytes(pfx_loaded *l, const char *path, const void *bytes, size_t len,
                           const pfx_compile_options *opt);
void pfx_loaded_free(pfx_loaded *l);
/* Prints l's diagnostics: those of --set, then the file's. */
void pfx_loaded_print(const pfx_loaded *l, FILE *out, bool json);
/* The warnings of l, the file's and --set's together (--werror). */
int pfx_loaded_warnings(const pfx_loaded *l);

#endif
