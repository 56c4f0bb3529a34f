/* --preview out.webp|out.mp4: an animated WebP or an MP4 made from a
 * render's frames as written (render and assemble make it the same way). */
#ifndef PFX_JOBS_PREVIEW_H
#define PFX_JOBS_PREVIEW_H

#include <stdbool.h>

#include "base/diag.h"

/* What to make: the file (its extension chooses the writer), its quality
 * (--preview-quality 0..100; -1: the default, WebP lossless and MP4 at
 * CRF 18) and whether the frames' colour is premultiplied by alpha. */
typedef struct pfx_preview {
    const char *path;
    int quality;
    bool premultiplied;
} pfx_preview;

/* Checks, before anything is rendered, that frames of width x height can
 * go into p->path (WebP: at most 16383 pixels a side). False with the
 * reason in d. */
bool pfx_preview_check(const pfx_preview *p, int width, int height, pfx_diags *d);

/* Reads dir/stem_NNNN.png for first, first + step, ... up to last, one at
 * a time, and writes them to p->path at fps / step, looping. Every frame
 * must be width x height (the render's size, from its manifest for
 * assemble), checked on its header before it is decoded, so a frame that
 * claims to be huge costs nothing. False with the reason in d, and no file
 * at the path. */
bool pfx_preview_run(const char *dir, const char *stem, long first, long last, long step,
                     double fps, int width, int height, const pfx_preview *p, pfx_diags *d);

#endif
