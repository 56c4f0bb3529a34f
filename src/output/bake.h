/* Particle caches: the state of every live particle at each baked frame,
 * as CSV (the ground truth users and tests check physics against), binary
 * PLY (position, velocity, colour, size, age, id: for DCC tools) or Unity
 * VFX Graph's point cache (.pcache). A file is written whole or not at all
 * (a temporary file renamed into place); "-" writes to standard output. */
#ifndef PFX_OUTPUT_BAKE_H
#define PFX_OUTPUT_BAKE_H

#include <stdbool.h>
#include <stdio.h>

#include <stddef.h>
#include <stdint.h>

#include "base/diag.h"
#include "model/effect.h"

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

/* One particle at one frame, as every format writes it: plain values, so
 * that writers never read the simulation's pools (jobs/bake_view.h makes
 * the rows from them). */
typedef struct pfx_bake_row {
    long frame;
    double time, age;
    uint32_t emitter, id;
    const char *emitter_name;
    float pos[3], vel[3];
    float lifetime, size;
    float color[4]; /* straight, 0..1 */
} pfx_bake_row;

typedef struct pfx_bake pfx_bake;

/* Opens the cache at `path` ("-": standard output) for the effect's
 * emitters. Returns NULL with the reason in d. */
pfx_bake *pfx_bake_open(const char *path, pfx_bake_format format, const pfx_effect *e,
                        pfx_diags *d);
/* Appends `count` rows in the order given (the caller's: by frame, then
 * emitter in file order, then id). False once a write has failed; the
 * reason is reported by pfx_bake_close. */
bool pfx_bake_rows(pfx_bake *b, const pfx_bake_row *rows, size_t count);
/* Marks the bake failed for errno `errnum` (such as ENOMEM while making its
 * rows): pfx_bake_close then reports it and leaves nothing at the path.
 * Returns false. */
bool pfx_bake_fail(pfx_bake *b, int errnum);
/* commit: complete the file (PLY and pcache write their header now that the
 * count is known) and rename it into place; otherwise remove the temporary
 * file. Returns false with the reason in d on failure (and nothing left at
 * path). Frees b. */
bool pfx_bake_close(pfx_bake *b, bool commit, pfx_diags *d);

#endif
