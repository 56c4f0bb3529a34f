/* --preview out.webp: an animated WebP made from a render's frames as
 * written (render and assemble make it the same way). */
#ifndef PFX_JOBS_PREVIEW_H
#define PFX_JOBS_PREVIEW_H

#include <stdbool.h>

#include "base/diag.h"

/* Reads dir/stem_NNNN.png for first..last one at a time and writes them to
 * path as a lossless animated WebP at fps, looping. Every frame must be
 * width x height (the render's size, from its manifest for assemble),
 * checked on its header before it is decoded, so a frame that claims to be
 * huge costs nothing. False with the reason in d, and no file at path. */
bool pfx_preview_run(const char *dir, const char *stem, long first, long last, double fps,
                     int width, int height, const char *path, pfx_diags *d);

#endif
