/* --atlas: the sprite sheet built from a render's frames as written (so
 * that render and assemble build it the same way), listed in the manifest. */
#ifndef PFX_JOBS_ATLAS_JOB_H
#define PFX_JOBS_ATLAS_JOB_H

#include <stdbool.h>

#include "base/diag.h"
#include "jobs/manifest.h"
#include "output/atlas.h"

/* The frames should not take more memory than this while the sheet is
 * built (every frame is held at once, for the crop box). */
#define PFX_ATLAS_MAX_BYTES (1024LL * 1024 * 1024)

/* Reads dir/stem_NNNN.png for first, first + step, ... up to last, and
 * writes dir/stem_atlas.png and dir/stem_atlas.json laid out by l (columns,
 * rows, padding, extrude, crop set by the caller; the rest is filled in),
 * the JSON's fps being fps / step. A frame size in l (frame_w > 0) is the
 * one every frame must have, checked on each PNG's header before it is
 * decoded (assemble gives the manifest's); 0 takes the first frame's. Adds
 * both to m (may be NULL). False with the reason in d, and neither file
 * written. */
bool pfx_atlas_job_run(const char *dir, const char *stem, long first, long last, long step,
                       double fps, bool loop, pfx_atlas_layout *l, pfx_manifest *m, pfx_diags *d);

/* The atlas settings of l into m's settings (part of the bake key). */
void pfx_atlas_job_describe(const pfx_atlas_layout *l, pfx_manifest *m);

#endif
