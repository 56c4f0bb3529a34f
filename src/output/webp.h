/* Animated WebP previews through libwebp's WebPAnimEncoder (the only part
 * of pfx that includes <webp/...>). Frames are added one at a time, so a
 * long render needs no more memory than the encoder's own. */
#ifndef PFX_OUTPUT_WEBP_H
#define PFX_OUTPUT_WEBP_H

#include <stdbool.h>
#include <stdint.h>

#include "base/diag.h"

/* libwebp's WEBP_MAX_DIMENSION, for checks made before any frame. */
#define PFX_WEBP_MAX_SIDE 16383

typedef struct pfx_webp pfx_webp;

/* Starts an animation of width x height frames shown for 1/fps s each,
 * looping for ever, lossless (quality < 0) or lossy with alpha (quality
 * 0..100, libwebp's own scale). NULL with the reason in d. */
pfx_webp *pfx_webp_create(int width, int height, double fps, int quality, pfx_diags *d);
/* Adds frame number k (from 0) of 8-bit straight RGBA, top row first. */
bool pfx_webp_add(pfx_webp *w, const uint8_t *rgba, long k, pfx_diags *d);
/* commit: assembles the file and writes it to path whole or not at all;
 * otherwise drops it. Frees w. */
bool pfx_webp_finish(pfx_webp *w, const char *path, long frames, bool commit, pfx_diags *d);

#endif
