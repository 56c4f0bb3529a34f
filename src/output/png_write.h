/* PNG output through libpng (the only part of pfx that includes <png.h>).
 * Files appear whole or not at all: each is written to a temporary name in
 * the same directory and renamed into place. */
#ifndef PFX_PNG_WRITE_H
#define PFX_PNG_WRITE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/diag.h"

/* Writes width*height 8-bit straight-alpha RGBA pixels (top row first) to
 * `path` atomically (output/atomic_file.h: synced to the disk before its
 * rename, the directory after). On failure returns false with the reason
 * in d and leaves no file at `path` or at the temporary name. */
bool pfx_png_write(const char *path, const uint8_t *rgba, int width, int height, pfx_diags *d);
/* pfx_png_write without syncing the directory after the rename: a caller
 * writing many files there syncs it once (pfx_atomic_sync_dir). */
bool pfx_png_write_nosync(const char *path, const uint8_t *rgba, int width, int height,
                          pfx_diags *d);

/* Reads an 8-bit RGBA PNG (for tests). Returns a malloc'd buffer the caller
 * frees, or NULL. */
uint8_t *pfx_png_read(const char *path, int *width, int *height);

#endif
