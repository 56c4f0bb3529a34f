/* `pfx bench`'s depth-sort figures: the renderer's threaded radix sort of
 * alpha-blended sprites at 10^6 and 4 x 10^6 sprites, next to qsort. */
#ifndef PFX_BENCH_SORT_SPEED_H
#define PFX_BENCH_SORT_SPEED_H

#include <jansson.h>
#include <stdio.h>

#include "base/diag.h"
#include "render/render.h"

/* Times pfx_renderer_sort on r at 1, 2 and `cores` threads (those up to
 * cores), the median of several runs each, and the reference: qsort on
 * (depth key, index), which gives the same stable order, and a gather of
 * the sprites. Appends {sprites, threads, ms, qsort_ms} to `rows` and
 * prints a table to out (NULL: none). Sets r's threads back to `cores`.
 * False with the failure in d when memory runs out or the orders differ. */
bool pfx_bench_sort(FILE *out, pfx_renderer *r, int cores, json_t *rows, pfx_diags *d);

#endif
