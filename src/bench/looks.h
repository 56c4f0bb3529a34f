/* `pfx bench`: the cost of each way a sprite can look (built-in kinds,
 * textures, flipbooks, stretch, light, motion blur) next to the plain
 * round sprite, in the same run. */
#ifndef PFX_BENCH_LOOKS_H
#define PFX_BENCH_LOOKS_H

#include <stdbool.h>
#include <stdio.h>

#include "base/diag.h"
#include "render/render.h"

/* Draws a fixed field of 5000 sprites through r (width x height) with one
 * material at a time and prints milliseconds per frame, nanoseconds per
 * sprite, and the ratio to the round sprite. Leaves
 * r's materials set to its own; draw with r only after setting yours.
 * Returns false with the failure in d. */
bool pfx_bench_looks(FILE *out, pfx_renderer *r, int width, int height, pfx_diags *d);

#endif
