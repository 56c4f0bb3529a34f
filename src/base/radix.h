/* A stable LSD radix sort of 32-bit keys that carry 32-bit indices, spread
 * over a worker set (base/workers.h) in fixed blocks: the order it gives is
 * that of a stable sort, whatever the thread count. It knows nothing of
 * sprites; render/sort.c makes the keys. */
#ifndef PFX_BASE_RADIX_H
#define PFX_BASE_RADIX_H

#include <stddef.h>
#include <stdint.h>

#include "base/workers.h"

/* Keys per block: the unit of the threaded passes. Boundaries depend on
 * the count alone. 2^16 keys and their indices (512 KiB in and out) stay
 * in a core's L2 cache while the block is counted and scattered. */
#define PFX_RADIX_BLOCK 65536u

/* Below this many keys one thread sorts them (a single block). Measured on
 * 2 busy cores (median of 21 runs, random keys, 1 vs 2 threads): 2^16 keys
 * 1.4 ms either way; 2^17 5.2 vs 4.4 ms; 2^18 15 vs 9 ms; 2^19 32 vs 21 ms.
 * With 16384-key blocks two threads lost or tied up to 2^18 keys (the helpers'
 * wake-ups, 11 jobs a sort), hence large blocks and this bound. */
#define PFX_RADIX_PARALLEL_MIN (2 * PFX_RADIX_BLOCK)

/* Histogram words the sort of `count` keys needs: 256 per block. */
size_t pfx_radix_hist_words(size_t count);

/* Sorts key[0 .. count) ascending, stably (equal keys keep their order),
 * moving idx[] with them. key_tmp and idx_tmp are scratch of count words
 * each and hist of pfx_radix_hist_words(count); the caller owns them all.
 * 8 bits a pass; a pass where every key has the same digit is skipped, so
 * the result lands in (key, idx) or in (key_tmp, idx_tmp): the return
 * value is the sorted index array (idx or idx_tmp), whose keys are in the
 * matching key array. w may be NULL (one thread). count < 2^32. Never
 * allocates. */
uint32_t *pfx_radix_sort(pfx_workers *w, uint32_t *key, uint32_t *idx, uint32_t *key_tmp,
                         uint32_t *idx_tmp, uint32_t *hist, size_t count);

#endif
