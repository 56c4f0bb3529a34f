/* The row view of a simulation for particle caches: the live particles of
 * a frame as output/bake.h's plain rows, so that the cache writers never
 * read sim pools nor call sim's colour and size functions. */
#ifndef PFX_JOBS_BAKE_VIEW_H
#define PFX_JOBS_BAKE_VIEW_H

#include <stdbool.h>
#include <stddef.h>

#include "output/bake.h"
#include "sim/sim.h"

/* Rows are made a block at a time, so a frame of a million particles
 * needs no million-row buffer: a row is 88 bytes, the block 22 KiB. */
enum { PFX_BAKE_VIEW_BLOCK = 256 };

typedef struct pfx_bake_view {
    struct pfx_bake_order *order; /* a pool's (id, index) pairs, sorted by id */
    size_t order_cap;
    pfx_bake_row rows[PFX_BAKE_VIEW_BLOCK];
} pfx_bake_view;

/* Zero a pfx_bake_view before its first use ({0} will do). Hands b every
 * live particle of `s` at frame `frame` (time `time`): by emitter in file
 * order, then by birth id (the pool's own order is an artefact of
 * swap-remove). False when b failed or memory ran out (then b is marked
 * failed with ENOMEM, reported when it is closed). */
bool pfx_bake_view_write(pfx_bake_view *v, pfx_bake *b, const pfx_sim *s, long frame, double time);

/* Frees what the view allocated; it may be used again after. */
void pfx_bake_view_free(pfx_bake_view *v);

#endif
