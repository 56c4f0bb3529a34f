/* OpenEXR frames through the OpenEXR Core C library (the only part of pfx
 * that includes <openexr.h>): a float frame as half-float RGBA, whole or
 * absent (output/atomic_file.h). */
#ifndef PFX_EXR_WRITE_H
#define PFX_EXR_WRITE_H

#include <stdbool.h>

#include "base/diag.h"
#include "render/image.h"

/* Writes img to `path` as a single-part scanline EXR with channels R, G, B,
 * A of type half, ZIP compressed: colour as rendered (linear,
 * premultiplied) times 2^exposure, alpha as rendered, no tone curve and no
 * dither; its header says Rec. 709 chromaticities and, when fps > 0, the
 * framesPerSecond. sync_dir: fsync the directory after the rename (a caller writing
 * many frames syncs it once instead). On failure returns false with the
 * reason in d and leaves no file at `path` or at the temporary name. */
bool pfx_exr_write(const char *path, const pfx_float_image *img, double exposure, double fps,
                   bool sync_dir, pfx_diags *d);

#endif
