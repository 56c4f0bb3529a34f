/* PNG output through libpng (the only part of pfx that includes <png.h>).
 * Files appear whole or not at all: each is written to a temporary name in
 * the same directory and renamed into place. */
#ifndef PFX_PNG_WRITE_H
#define PFX_PNG_WRITE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/diag.h"
#include "output/atomic_file.h"

/* Writes width*height 8-bit straight-alpha RGBA pixels (top row first) to
 * `path` atomically (output/atomic_file.h: synced to the disk before its
 * rename, the directory after). On failure returns false with the reason
 * in d and leaves no file at `path` or at the temporary name. */
bool pfx_png_write(const char *path, const uint8_t *rgba, int width, int height, pfx_diags *d);
/* pfx_png_write without syncing the directory after the rename: a caller
 * writing many files there syncs it once (pfx_atomic_sync_dir). */
bool pfx_png_write_nosync(const char *path, const uint8_t *rgba, int width, int height,
                          pfx_diags *d);
/* pfx_png_write as a file of group g, which renames it into place with the
 * others (output/atomic_file.h). */
bool pfx_png_write_in(pfx_atomic_group *g, const char *path, const uint8_t *rgba, int width,
                      int height, pfx_diags *d);

/* Writes width*height 16-bit RGBA samples (host byte order, top row
 * first) as a 16-bit RGBA PNG, atomically as pfx_png_write does; sync_dir:
 * also fsync the directory (false when the caller syncs it once after a
 * batch). Motion-vector frames and sheets (output/motion_vectors.h). */
bool pfx_png_write16(const char *path, const uint16_t *rgba, int width, int height, bool sync_dir,
                     pfx_diags *d);
/* pfx_png_write16 as a file of group g. */
bool pfx_png_write16_in(pfx_atomic_group *g, const char *path, const uint16_t *rgba, int width,
                        int height, pfx_diags *d);
/* Reads any PNG as 16-bit RGBA samples in host byte order (8-bit images
 * widened by x 257). Returns a malloc'd buffer the caller frees, or NULL. */
uint16_t *pfx_png_read16(const char *path, int *width, int *height);
/* Bytes each encoding thread keeps for frames of width x height (the
 * filtered rows, room for their deflated stream, the compressor), from its
 * first frame until it ends: for the memory estimate. */
size_t pfx_png_encoder_scratch_bytes(int width, int height);

/* Reads an 8-bit RGBA PNG (for tests). Returns a malloc'd buffer the caller
 * frees, or NULL. */
uint8_t *pfx_png_read(const char *path, int *width, int *height);

/* Reads the PNG at path as 8-bit RGBA only when it is a regular file whose
 * header says width x height: a frame claiming another size (a crafted
 * 20000x20000 of a few bytes) costs no allocation and no decoding. NULL
 * otherwise, with the header's size in *got_w, *got_h (0 when no header
 * was read). The buffer is malloc'd; the caller frees it. */
uint8_t *pfx_png_read_sized(const char *path, int width, int height, int *got_w, int *got_h);

#endif
