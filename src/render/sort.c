/* The depth sort of alpha-blended sprites: back to front by view depth,
 * stable and exactly reproducible, spread over the renderer's threads in
 * fixed blocks (base/radix.h), so the order is the same for any count. It
 * sorts keys and positions only (16 bytes a sprite with the radix
 * ping-pong); the sprites themselves are made in that order a chunk at a
 * time when they are drawn (pfx_sort_make), never copied whole. */
#include "render/render_internal.h"

#include <stdlib.h>
#include <string.h>

#include "base/radix.h"

/* Sprites a block of pfx_sort_make makes: enough to pay for waking a
 * thread (a sprite from the pools costs tens of ns), few enough that a
 * chunk is shared out. */
#define MAKE_BLOCK 2048u

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
    uint32_t *hist = realloc(r->hist, pfx_radix_hist_words(cap) * sizeof *hist);
    if (hist)
        r->hist = hist;
    if (!keys || !index || !hist) {
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
    return cap * 4 * sizeof(uint32_t) + pfx_radix_hist_words(cap) * sizeof(uint32_t);
}

/* Maps a float to a uint32 whose unsigned order is the float's order
 * (negative floats have all bits flipped, positive ones only the sign). */
static uint32_t float_order_key(float x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}

/* The keys of the radix sort, block by block: each writes only its block's
 * range. */
typedef struct key_job {
    pfx_renderer *r;
    const pfx_sprite_source *src;
    size_t count;
    double f[3], e[3];
} key_job;

/* Keys are inverted so that ascending key = descending depth. The centres
 * come from the source a few hundred at a time, into the stack. */
static void make_keys(void *ctx, size_t b) {
    const key_job *j = ctx;
    const size_t lo = b * PFX_RADIX_BLOCK,
                 hi = lo + PFX_RADIX_BLOCK < j->count ? lo + PFX_RADIX_BLOCK : j->count;
    uint32_t *key = j->r->keys, *idx = j->r->index;
    float c[3 * 512];
    for (size_t at = lo; at < hi; at += 512) {
        const size_t n = hi - at < 512 ? hi - at : 512;
        j->src->centres(j->src->ctx, at, n, c);
        for (size_t k = 0; k < n; k++) {
            const float *p = c + 3 * k;
            double depth = (p[0] - j->e[0]) * j->f[0] + (p[1] - j->e[1]) * j->f[1] +
                           (p[2] - j->e[2]) * j->f[2];
            key[at + k] = ~float_order_key((float)depth);
            idx[at + k] = (uint32_t)(at + k);
        }
    }
}

/* Back-to-front order by view depth (distance along the camera's forward
 * axis), farthest first: LSD radix on the depths' order-preserving bits,
 * O(n), stable by construction (equal depths keep input order). */
const uint32_t *pfx_sort_order(pfx_renderer *r, const pfx_view *v, const pfx_sprite_source *src,
                               pfx_diags *d) {
    const size_t count = src->count;
    if (count > UINT32_MAX) {
        pfx_diag_error(d, PFX_RULE_TOO_MANY, "too many sprites to sort: %zu", count);
        return NULL;
    }
    if (!grow_scratch(r, count ? count : 1, d))
        return NULL;
    key_job j = {r, src, count, {0}, {0}};
    memcpy(j.f, v->forward, sizeof j.f);
    memcpy(j.e, v->eye, sizeof j.e);
    /* The same small-count rule as the radix passes: one thread below it. */
    pfx_workers *w = count >= PFX_RADIX_PARALLEL_MIN ? r->workers : NULL;
    pfx_workers_run(w, (count + PFX_RADIX_BLOCK - 1) / PFX_RADIX_BLOCK, make_keys, &j);
    if (count < 2)
        return r->index;
    return pfx_radix_sort(w, r->keys, r->index, r->keys + r->scratch_cap, r->index + r->scratch_cap,
                          r->hist, count);
}

/* Sprites [lo, hi) of a source (through index when not NULL), block by
 * block into out. */
typedef struct make_job {
    const pfx_sprite_source *src;
    const uint32_t *index;
    size_t lo, hi;
    pfx_sprite *out;
} make_job;

static void make_block(void *ctx, size_t b) {
    const make_job *j = ctx;
    const size_t lo = j->lo + b * MAKE_BLOCK,
                 hi = lo + MAKE_BLOCK < j->hi ? lo + MAKE_BLOCK : j->hi;
    j->src->make(j->src->ctx, lo, hi - lo, j->index ? j->index + lo : NULL, j->out + (lo - j->lo));
}

void pfx_sort_make(pfx_renderer *r, const pfx_sprite_source *src, const uint32_t *index, size_t lo,
                   size_t hi, pfx_sprite *out) {
    make_job j = {src, index, lo, hi, out};
    const size_t blocks = (hi - lo + MAKE_BLOCK - 1) / MAKE_BLOCK;
    pfx_workers_run(blocks > 1 ? r->workers : NULL, blocks, make_block, &j);
}

/* pfx_renderer_sort: the order, then the sprites permuted through a copy. */
bool pfx_sort_back_to_front(pfx_renderer *r, const pfx_view *v, pfx_sprite *sprites, size_t count,
                            pfx_diags *d) {
    if (count < 2)
        return true;
    const pfx_sprite_source src = pfx_sprite_source_array(sprites, count);
    const uint32_t *order = pfx_sort_order(r, v, &src, d);
    if (!order)
        return false;
    if (count > r->sorted_cap) {
        pfx_sprite *sorted = realloc(r->sorted, r->scratch_cap * sizeof *sorted);
        if (!sorted) {
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory sorting %zu sprites", count);
            return false;
        }
        r->sorted = sorted;
        r->sorted_cap = r->scratch_cap;
    }
    pfx_sort_make(r, &src, order, 0, count, r->sorted);
    memcpy(sprites, r->sorted, count * sizeof *sprites);
    return true;
}
