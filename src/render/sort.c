/* The depth sort of alpha-blended sprites: back to front by view depth,
 * stable and exactly reproducible, spread over the renderer's threads in
 * fixed blocks (base/radix.h), so the order is the same for any count. */
#include "render/render_internal.h"

#include <stdlib.h>
#include <string.h>

#include "base/radix.h"

static bool grow_scratch(pfx_renderer *r, size_t count, pfx_diags *d) {
    if (count <= r->scratch_cap)
        return true;
    size_t cap = r->scratch_cap ? r->scratch_cap : 1024;
    while (cap < count)
        cap *= 2;
    uint32_t *keys = realloc(r->keys, 2 * cap * sizeof *keys);
    if (keys)
        r->keys = keys;
    uint32_t *index = realloc(r->index, 2 * cap * sizeof *index);
    if (index)
        r->index = index;
    pfx_sprite *sorted = realloc(r->sorted, cap * sizeof *sorted);
    if (sorted)
        r->sorted = sorted;
    uint32_t *hist = realloc(r->hist, pfx_radix_hist_words(cap) * sizeof *hist);
    if (hist)
        r->hist = hist;
    if (!keys || !index || !sorted || !hist) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory sorting %zu sprites", count);
        return false;
    }
    r->scratch_cap = cap;
    return true;
}

size_t pfx_renderer_sort_bytes(size_t count) {
    size_t cap = 1024;
    while (cap < count)
        cap *= 2;
    return cap * (4 * sizeof(uint32_t) + sizeof(pfx_sprite)) +
           pfx_radix_hist_words(cap) * sizeof(uint32_t);
}

/* Maps a float to a uint32 whose unsigned order is the float's order
 * (negative floats have all bits flipped, positive ones only the sign). */
static uint32_t float_order_key(float x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}

/* The block jobs around the radix sort: make the keys, gather the sprites
 * in sorted order, copy them back. Each writes only its block's range. */
typedef struct sort_job {
    pfx_renderer *r;
    pfx_sprite *sprites;
    const uint32_t *order;
    size_t count;
    double f[3], e[3];
} sort_job;

static void block_range(const sort_job *j, size_t b, size_t *lo, size_t *hi) {
    *lo = b * PFX_RADIX_BLOCK;
    *hi = *lo + PFX_RADIX_BLOCK < j->count ? *lo + PFX_RADIX_BLOCK : j->count;
}

/* Keys are inverted so that ascending key = descending depth. */
static void make_keys(void *ctx, size_t b) {
    const sort_job *j = ctx;
    size_t lo, hi;
    block_range(j, b, &lo, &hi);
    const pfx_sprite *s = j->sprites;
    uint32_t *key = j->r->keys, *idx = j->r->index;
    for (size_t i = lo; i < hi; i++) {
        double depth = (s[i].x - j->e[0]) * j->f[0] + (s[i].y - j->e[1]) * j->f[1] +
                       (s[i].z - j->e[2]) * j->f[2];
        key[i] = ~float_order_key((float)depth);
        idx[i] = (uint32_t)i;
    }
}

static void gather(void *ctx, size_t b) {
    const sort_job *j = ctx;
    size_t lo, hi;
    block_range(j, b, &lo, &hi);
    for (size_t i = lo; i < hi; i++)
        j->r->sorted[i] = j->sprites[j->order[i]];
}

static void copy_back(void *ctx, size_t b) {
    const sort_job *j = ctx;
    size_t lo, hi;
    block_range(j, b, &lo, &hi);
    memcpy(j->sprites + lo, j->r->sorted + lo, (hi - lo) * sizeof *j->sprites);
}

/* Back-to-front sort by view depth (distance along the camera's forward
 * axis), farthest first: LSD radix on the depths' order-preserving bits,
 * O(n), stable by construction (equal depths keep input order). */
bool pfx_sort_back_to_front(pfx_renderer *r, const pfx_view *v, pfx_sprite *sprites, size_t count,
                            pfx_diags *d) {
    if (count < 2)
        return true;
    if (count > UINT32_MAX) {
        pfx_diag_error(d, PFX_RULE_TOO_MANY, "too many sprites to sort: %zu", count);
        return false;
    }
    if (!grow_scratch(r, count, d))
        return false;
    sort_job j = {r, sprites, NULL, count, {0}, {0}};
    memcpy(j.f, v->forward, sizeof j.f);
    memcpy(j.e, v->eye, sizeof j.e);
    /* The same small-count rule as the radix passes: one thread below it. */
    pfx_workers *w = count >= PFX_RADIX_PARALLEL_MIN ? r->workers : NULL;
    const size_t blocks = (count + PFX_RADIX_BLOCK - 1) / PFX_RADIX_BLOCK;
    pfx_workers_run(w, blocks, make_keys, &j);
    j.order = pfx_radix_sort(w, r->keys, r->index, r->keys + r->scratch_cap,
                             r->index + r->scratch_cap, r->hist, count);
    pfx_workers_run(w, blocks, gather, &j);
    pfx_workers_run(w, blocks, copy_back, &j);
    return true;
}
