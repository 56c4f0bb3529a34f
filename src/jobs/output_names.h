/* The files a render or bake will create, listed and checked before any
 * work (jobs/output_names.c): a name its directory cannot hold, or an
 * output that is one of the run's own inputs, fails the run before the
 * first frame instead of after the last one. */
#ifndef PFX_JOBS_OUTPUT_NAMES_H
#define PFX_JOBS_OUTPUT_NAMES_H

#include <stdbool.h>

#include "base/diag.h"
#include "jobs/manifest.h"

/* One output, or a numbered run of them: prefix NNNN suffix for every
 * frame first..last (frames are listed as a run so that a long sequence
 * costs one entry). */
typedef struct pfx_output_name {
    char *prefix, *suffix; /* malloc'd; suffix NULL: a single file, prefix is its path */
    long first, last, step;
    int digits; /* the frame number zero-padded to at least this many */
} pfx_output_name;

typedef struct pfx_output_names {
    pfx_output_name *items;
    size_t count, cap;
    bool failed; /* out of memory while listing: the check fails */
} pfx_output_names;

/* Lists the file at path (copied). NULL is ignored (an output not made). */
void pfx_output_names_add(pfx_output_names *o, const char *path);
/* Lists dir/<stem><infix>NNNN.<ext> for the frames first..last. */
void pfx_output_names_add_frames(pfx_output_names *o, const char *dir, const char *stem,
                                 const char *infix, long first, long last, const char *ext);
/* Lists <prefix>N<suffix> for N = first, first + step, ... up to last,
 * with N zero-padded to `digits` (bake's cache_####.ply: prefix "cache_",
 * 4 digits, suffix ".ply"). */
void pfx_output_names_add_numbered(pfx_output_names *o, const char *prefix, int digits,
                                   const char *suffix, long first, long last, long step);

/* True when every listed name fits (its file name within its directory's
 * NAME_MAX, the path within PATH_MAX; the temporary files pfx writes
 * beside it are cut to fit whenever the name does), none is a directory
 * already there, and none is the same file (device and inode) as an
 * input of m. Otherwise false, with one
 * error per problem in d. Creates nothing. */
bool pfx_output_names_check(const pfx_output_names *o, const pfx_manifest *m, pfx_diags *d);

void pfx_output_names_free(pfx_output_names *o);

#endif
