/* Each particle-cache format's writer of bake.h's rows (output/bake_*.c).
 * Internal to src/output/. */
#ifndef PFX_OUTPUT_BAKE_ROWS_H
#define PFX_OUTPUT_BAKE_ROWS_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "output/bake.h"

/* CSV: the header at once, then one text line per row into `out`. */
bool pfx_bake_csv_header(FILE *out);
bool pfx_bake_csv_row(FILE *out, const pfx_bake_row *row);

/* PLY and pcache: fixed-size little-endian records into a scratch file, and
 * the header (which needs the count) written at the end. */
enum { PFX_BAKE_RECORD_BYTES = 64 };
void pfx_bake_record(const pfx_bake_row *row, unsigned char rec[PFX_BAKE_RECORD_BYTES]);
bool pfx_bake_ply_header(FILE *out, const pfx_effect *e, uint64_t count);
bool pfx_bake_pcache_header(FILE *out, const pfx_effect *e, uint64_t count);

#endif
