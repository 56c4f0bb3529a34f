/* The particle cache as CSV: one row per live particle per baked frame, the
 * ground truth users and tests check physics against. Written whole or not
 * at all (a temporary file renamed into place). */
#ifndef PFX_BAKE_CSV_H
#define PFX_BAKE_CSV_H

#include <stdbool.h>
#include <stdio.h>

#include "sim/sim.h"

#define PFX_BAKE_HEADER "frame,time,emitter,id,x,y,z,vx,vy,vz,age,lifetime,size,r,g,b,a"

typedef struct pfx_bake pfx_bake;

/* Opens a temporary file beside `path` (output/atomic_file.h) and writes
 * the header. Returns NULL with the reason in d. */
pfx_bake *pfx_bake_open(const char *path, pfx_diags *d);
/* Appends frame `frame` at time `time`: every live particle of `s`, by
 * emitter in file order, then by id. Floats are printed with 9 significant
 * digits, enough to round-trip. */
bool pfx_bake_frame(pfx_bake *b, const pfx_sim *s, long frame, double time);
/* commit: flush, sync and rename into place; otherwise remove the
 * temporary file. A write that failed (a full disk, EFBIG past ulimit -f)
 * is reported with the path and errno either way. Returns false with the
 * reason in d on failure (and nothing left at path). Frees b. */
bool pfx_bake_close(pfx_bake *b, bool commit, pfx_diags *d);

#endif
