/* Particle caches: the state of every live particle at each baked frame,
 * as CSV (the ground truth users and tests check physics against), binary
 * PLY (position, velocity, colour, size, age, id: for DCC tools) or Unity
 * VFX Graph's point cache (.pcache). A file is written whole or not at all
 * (a temporary file renamed into place); "-" writes to standard output. */
#ifndef PFX_OUTPUT_BAKE_H
#define PFX_OUTPUT_BAKE_H

#include <stdbool.h>
#include <stdio.h>

#include "base/diag.h"
#include "sim/sim.h"

#define PFX_BAKE_HEADER "frame,time,emitter,id,x,y,z,vx,vy,vz,age,lifetime,size,r,g,b,a"

/* The formats, one row each: enum name, the --format word, the extension. */
#define PFX_BAKE_FORMATS(X)                                                                        \
    X(CSV, "csv")                                                                                  \
    X(PLY, "ply")                                                                                  \
    X(PCACHE, "pcache")

typedef enum {
#define PFX_BAKE_ENUM(e, name) PFX_BAKE_##e,
    PFX_BAKE_FORMATS(PFX_BAKE_ENUM)
#undef PFX_BAKE_ENUM
        PFX_BAKE_FORMAT_COUNT
} pfx_bake_format;

/* The format's word ("csv"), or NULL. */
const char *pfx_bake_format_name(pfx_bake_format f);
/* Looks up a word; false when it names no format. */
bool pfx_bake_format_parse(const char *name, pfx_bake_format *out);

typedef struct pfx_bake pfx_bake;

/* Opens the cache at `path` ("-": standard output) for the effect's
 * emitters. Returns NULL with the reason in d. */
pfx_bake *pfx_bake_open(const char *path, pfx_bake_format format, const pfx_effect *e,
                        pfx_diags *d);
/* Appends frame `frame` at time `time`: every live particle of `s`, by
 * emitter in file order, then by id. */
bool pfx_bake_frame(pfx_bake *b, const pfx_sim *s, long frame, double time);
/* commit: complete the file (PLY and pcache write their header now that the
 * count is known) and rename it into place; otherwise remove the temporary
 * file. Returns false with the reason in d on failure (and nothing left at
 * path). Frees b. */
bool pfx_bake_close(pfx_bake *b, bool commit, pfx_diags *d);

#endif
