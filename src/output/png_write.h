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

/* Writes width*height 16-bit RGBA samples (host byte order, top row
 * first) as a 16-bit RGBA PNG, atomically as pfx_png_write does; sync_dir:
 * also fsync the directory (false when the caller syncs it once after a
 * batch). Motion-vector frames and sheets (output/motion_vectors.h). */
bool pfx_png_write16(const char *path, const uint16_t *rgba, int width, int height, bool sync_dir,
                     pfx_diags *d);
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

/* Background encoders so PNG encoding overlaps rendering and uses several
 * cores: the renderer fills one buffer while a pool of encoder threads
 * encodes and writes the frames before it. */
typedef struct pfx_png_queue pfx_png_queue;

/* The most encoder threads a queue starts. */
#define PFX_PNG_MAX_ENCODERS 64

/* How many encoders a queue for `wanted` threads starts: wanted, or one per
 * online core when it is 0, within 1 .. PFX_PNG_MAX_ENCODERS. The memory
 * estimate and the render both ask here. */
int pfx_png_encoder_count(int wanted);

/* Creates a queue for frames of width x height with `threads` encoders
 * (1 to PFX_PNG_MAX_ENCODERS; 2 x threads frame buffers) and starts them;
 * the caller owns it and ends it with pfx_png_queue_finish. NULL if the
 * size is invalid or memory or a thread is unavailable. */
pfx_png_queue *pfx_png_queue_create(int width, int height, int threads);
/* A buffer to render the next frame into; blocks while every buffer is
 * queued or being encoded. */
uint8_t *pfx_png_queue_buffer(pfx_png_queue *q);
/* Hands the buffer last returned by pfx_png_queue_buffer to the encoders
 * to be written to `path` (copied). Encoders take frames in submission
 * order; each file's bytes do not depend on the number of encoders. After
 * the first failure later frames are not written. */
void pfx_png_queue_submit(pfx_png_queue *q, const char *path);
/* True once a frame has failed; later frames are dropped, so the caller
 * may stop rendering early. The error itself comes from finish. */
bool pfx_png_queue_failed(pfx_png_queue *q);
/* Waits for every submitted frame, syncs their directory (each frame was
 * synced before its rename), stops the thread and frees the queue.
 * Returns false with the first write error added to d (may be NULL). */
bool pfx_png_queue_finish(pfx_png_queue *q, pfx_diags *d);

#endif
