/* The stable radix sort of radix.h. Each 8-bit pass counts the digits of
 * every block (in parallel), turns the counts into offsets in (digit,
 * block) order on one thread, and scatters every block to its offsets (in
 * parallel). Block b's keys with digit d land after every key of a smaller
 * digit and after block b - 1's keys of digit d, in their order within the
 * block: exactly where one thread walking the keys in order puts them. So
 * the result is the stable order for any thread count, and the one-thread
 * path is the same code run on the caller's thread. */
#include "base/radix.h"

#include <stdbool.h>
#include <string.h>

typedef struct radix_pass {
    const uint32_t *key, *idx;
    uint32_t *key_out, *idx_out;
    uint32_t *hist; /* 256 words per block: counts, then offsets */
    size_t count;
    unsigned shift;
} radix_pass;

size_t pfx_radix_hist_words(size_t count) {
    return 256 * ((count + PFX_RADIX_BLOCK - 1) / PFX_RADIX_BLOCK + 1);
}

static void block_range(const radix_pass *p, size_t b, size_t *lo, size_t *hi) {
    *lo = b * PFX_RADIX_BLOCK;
    *hi = *lo + PFX_RADIX_BLOCK < p->count ? *lo + PFX_RADIX_BLOCK : p->count;
}

static void count_block(void *ctx, size_t b) {
    const radix_pass *p = ctx;
    uint32_t *h = p->hist + 256 * b;
    memset(h, 0, 256 * sizeof *h);
    size_t lo, hi;
    block_range(p, b, &lo, &hi);
    const uint32_t *key = p->key;
    const unsigned shift = p->shift;
    for (size_t i = lo; i < hi; i++)
        h[(key[i] >> shift) & 0xff]++;
}

static void scatter_block(void *ctx, size_t b) {
    const radix_pass *p = ctx;
    uint32_t *h = p->hist + 256 * b;
    size_t lo, hi;
    block_range(p, b, &lo, &hi);
    const uint32_t *key = p->key, *idx = p->idx;
    uint32_t *key_out = p->key_out, *idx_out = p->idx_out;
    const unsigned shift = p->shift;
    for (size_t i = lo; i < hi; i++) {
        uint32_t dst = h[(key[i] >> shift) & 0xff]++;
        key_out[dst] = key[i];
        idx_out[dst] = idx[i];
    }
}

/* Counts to offsets, digit by digit and within a digit block by block.
 * False when every key has the same digit (the pass would move nothing). */
static bool offsets(radix_pass *p, size_t blocks) {
    const uint32_t first = (p->key[0] >> p->shift) & 0xff;
    size_t same = 0;
    for (size_t b = 0; b < blocks; b++)
        same += p->hist[256 * b + first];
    if (same == p->count)
        return false;
    uint32_t sum = 0;
    for (unsigned d = 0; d < 256; d++)
        for (size_t b = 0; b < blocks; b++) {
            uint32_t c = p->hist[256 * b + d];
            p->hist[256 * b + d] = sum;
            sum += c;
        }
    return true;
}

uint32_t *pfx_radix_sort(pfx_workers *w, uint32_t *key, uint32_t *idx, uint32_t *key_tmp,
                         uint32_t *idx_tmp, uint32_t *hist, size_t count) {
    if (count < 2)
        return idx;
    /* Small sorts stay on the caller's thread (radix.h: measured). */
    pfx_workers *use = count >= PFX_RADIX_PARALLEL_MIN ? w : NULL;
    const size_t blocks = (count + PFX_RADIX_BLOCK - 1) / PFX_RADIX_BLOCK;
    for (unsigned shift = 0; shift < 32; shift += 8) {
        radix_pass p = {key, idx, key_tmp, idx_tmp, hist, count, shift};
        pfx_workers_run(use, blocks, count_block, &p);
        if (!offsets(&p, blocks))
            continue;
        pfx_workers_run(use, blocks, scatter_block, &p);
        uint32_t *t = key;
        key = key_tmp, key_tmp = t;
        t = idx;
        idx = idx_tmp, idx_tmp = t;
    }
    return idx;
}
