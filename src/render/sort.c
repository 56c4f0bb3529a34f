/* The depth sort of alpha-blended sprites: back to front by view depth,
 * stable and exactly reproducible, spread over the renderer's threads in
 * fixed blocks (base/radix.h), so the order is the same for any count. It
 * sorts keys and positions only (16 bytes a sprite with the radix
 * ping-pong); the sprites themselves are made in that order a chunk at a
 * time when they are drawn (pfx_sort_make), never copied whole.
 *
 * Its memory is bounded whatever the count: at most r->sort_batch sprites
 * (PFX_SORT_BATCH) are sorted at once. A source with more is given out in
 * batches, each the next sort_batch sprites of the stable order: a radix
 * select (three histogram passes over the keys, 11, 11 and 10 bits) finds
 * the key k at which the remaining sprites reach the batch size, and a
 * gathering pass takes every remaining sprite with a smaller key and, of
 * those with key k, the first ones in source order. Sorting that batch
 * stably gives exactly the next stretch of the whole order, so batches
 * draw the same frame as one sort would. Keys are computed again on each
 * pass, from the sprites' centres, rather than kept. */
#include "render/render_internal.h"

#include <stdlib.h>
#include <string.h>

#include "base/radix.h"

/* Sprites a block of pfx_sort_make makes: enough to pay for waking a
 * thread (a sprite from the pools costs tens of ns), few enough that a
 * chunk is shared out. */
#define MAKE_BLOCK 2048u

/* The batches' passes split the source into at most this many blocks, each
 * with a histogram of SELECT_BINS words: 2 MiB, whatever the count. */
#define SELECT_BLOCKS 256u
#define SELECT_BINS 2048u

/* Scratch for n sprites, grown by doubling, never past the batch size. */
static size_t scratch_for(size_t n, size_t batch) {
    size_t cap = 1024;
    while (cap < n && cap < batch)
        cap *= 2;
    return cap < batch ? cap : batch;
}

static bool grow_scratch(pfx_renderer *r, size_t count, pfx_diags *d) {
    const size_t cap = scratch_for(count, r->sort_batch);
    bool ok = true;
    if (cap > r->scratch_cap) {
        uint32_t *keys = realloc(r->keys, 2 * cap * sizeof *keys);
        if (keys)
            r->keys = keys;
        uint32_t *index = realloc(r->index, 2 * cap * sizeof *index);
        if (index)
            r->index = index;
        uint32_t *hist = realloc(r->hist, pfx_radix_hist_words(cap) * sizeof *hist);
        if (hist)
            r->hist = hist;
        ok = keys && index && hist;
        if (ok)
            r->scratch_cap = cap;
    }
    if (ok && count > r->sort_batch && !r->select_hist)
        ok = (r->select_hist = malloc(SELECT_BLOCKS * SELECT_BINS * sizeof *r->select_hist));
    if (!ok)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory sorting %zu sprites", count);
    return ok;
}

size_t pfx_renderer_sort_bytes(size_t count) {
    const size_t cap = scratch_for(count, PFX_SORT_BATCH);
    size_t bytes = cap * 4 * sizeof(uint32_t) + pfx_radix_hist_words(cap) * sizeof(uint32_t);
    if (count > PFX_SORT_BATCH)
        bytes += SELECT_BLOCKS * SELECT_BINS * sizeof(uint32_t);
    return bytes;
}

/* Maps a float to a uint32 whose unsigned order is the float's order
 * (negative floats have all bits flipped, positive ones only the sign). */
static uint32_t float_order_key(float x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}

/* The keys of sprites [at, at + n), n <= 512: inverted, so that ascending
 * key = descending depth. The centres come from the source into the
 * stack. */
static void keys_of(const pfx_sort_cursor *c, size_t at, size_t n, uint32_t *key) {
    float p[3 * 512];
    c->src->centres(c->src->ctx, at, n, p);
    for (size_t k = 0; k < n; k++) {
        const float *q = p + 3 * k;
        double depth =
            (q[0] - c->e[0]) * c->f[0] + (q[1] - c->e[1]) * c->f[1] + (q[2] - c->e[2]) * c->f[2];
        key[k] = ~float_order_key((float)depth);
    }
}

/* ---- One sort of everything (at most a batch) ---- */

typedef struct key_job {
    const pfx_sort_cursor *c;
    uint32_t *key, *idx;
    size_t count;
} key_job;

static void make_keys(void *ctx, size_t b) {
    const key_job *j = ctx;
    const size_t lo = b * PFX_RADIX_BLOCK,
                 hi = lo + PFX_RADIX_BLOCK < j->count ? lo + PFX_RADIX_BLOCK : j->count;
    for (size_t at = lo; at < hi; at += 512) {
        const size_t n = hi - at < 512 ? hi - at : 512;
        keys_of(j->c, at, n, j->key + at);
        for (size_t k = 0; k < n; k++)
            j->idx[at + k] = (uint32_t)(at + k);
    }
}

/* Sorts (key, idx)[0, n) stably over r's threads (one below the parallel
 * minimum); the sorted positions. */
static const uint32_t *radix(pfx_renderer *r, size_t n) {
    pfx_workers *w = n >= PFX_RADIX_PARALLEL_MIN ? r->workers : NULL;
    if (n < 2)
        return r->index;
    return pfx_radix_sort(w, r->keys, r->index, r->keys + r->scratch_cap, r->index + r->scratch_cap,
                          r->hist, n);
}

/* ---- Batches ---- */

/* A pass over the source's blocks: a histogram of one digit of the keys
 * of the remaining sprites under a prefix, a count of those below a key
 * and equal to it, or their gathering into the batch. */
typedef enum { PASS_HISTOGRAM, PASS_COUNT, PASS_GATHER } pass_kind;

typedef struct select_job {
    pfx_renderer *r;
    const pfx_sort_cursor *c;
    pass_kind kind;
    size_t blocks;
    unsigned shift, bins;  /* histogram: the digit (key >> shift) & (bins - 1) */
    uint32_t prefix, mask; /* histogram: only keys with (key & mask) == prefix */
    uint32_t pivot;        /* count, gather: the batch's last key */
    size_t below[SELECT_BLOCKS], equal[SELECT_BLOCKS];  /* count: per block */
    size_t offset[SELECT_BLOCKS], quota[SELECT_BLOCKS]; /* gather: per block */
    size_t end[SELECT_BLOCKS]; /* gather: where the block's share ends (a guard: the keys are
                                  the same on every pass, so it is never reached early) */
} select_job;

/* Whether sprite i, of key k, is still to be given out: after the last
 * one given, (k_last, i_last), in the stable order. */
static inline bool remaining(const pfx_sort_cursor *c, uint32_t k, size_t i) {
    return !c->started || k > c->k_last || (k == c->k_last && i > c->i_last);
}

static void select_block(void *ctx, size_t b) {
    select_job *j = ctx;
    const pfx_sort_cursor *c = j->c;
    const size_t count = c->src->count;
    const size_t lo = count * b / j->blocks, hi = count * (b + 1) / j->blocks;
    uint32_t *hist = NULL;
    if (j->kind == PASS_HISTOGRAM) {
        hist = j->r->select_hist + b * SELECT_BINS;
        memset(hist, 0, j->bins * sizeof *hist);
    }
    size_t below = 0, equal = 0, out = j->offset[b], quota = j->quota[b];
    uint32_t key[512];
    for (size_t at = lo; at < hi; at += 512) {
        const size_t n = hi - at < 512 ? hi - at : 512;
        keys_of(c, at, n, key);
        for (size_t k = 0; k < n; k++) {
            if (!remaining(c, key[k], at + k))
                continue;
            if (j->kind == PASS_HISTOGRAM) {
                if ((key[k] & j->mask) == j->prefix)
                    hist[(key[k] >> j->shift) & (j->bins - 1)]++;
            } else if (j->kind == PASS_COUNT) {
                below += key[k] < j->pivot;
                equal += key[k] == j->pivot;
            } else if ((key[k] < j->pivot || (key[k] == j->pivot && quota > 0)) &&
                       out < j->end[b]) {
                quota -= key[k] == j->pivot;
                j->r->keys[out] = key[k];
                j->r->index[out++] = (uint32_t)(at + k);
            }
        }
    }
    j->below[b] = below;
    j->equal[b] = equal;
}

static void run_pass(select_job *j, pass_kind kind) {
    j->kind = kind;
    pfx_workers_run(j->r->workers, j->blocks, select_block, j);
}

/* Gathers the next `want` sprites of the stable order into r->keys and
 * r->index, in source order: with `all`, every remaining one (want is the
 * number remaining). */
static void gather_batch(pfx_renderer *r, const pfx_sort_cursor *c, size_t want, bool all) {
    select_job job = {.r = r, .c = c}, *j = &job;
    const size_t blocks = (c->src->count + PFX_RADIX_BLOCK - 1) / PFX_RADIX_BLOCK;
    j->blocks = blocks < SELECT_BLOCKS ? blocks : SELECT_BLOCKS;
    /* The radix select: the key at which the remaining sprites, counted in
     * key order, reach `want`, a digit at a time from the top. */
    static const unsigned shifts[3] = {21, 10, 0}, widths[3] = {11, 11, 10};
    size_t before = 0; /* remaining sprites with keys below the prefix's range */
    for (int level = 0; level < 3 && !all; level++) {
        j->shift = shifts[level];
        j->bins = 1u << widths[level];
        run_pass(j, PASS_HISTOGRAM);
        unsigned digit = 0;
        for (;; digit++) {
            size_t in = 0;
            for (size_t b = 0; b < j->blocks; b++)
                in += r->select_hist[b * SELECT_BINS + digit];
            if (before + in >= want || digit + 1 == j->bins)
                break;
            before += in;
        }
        j->prefix |= (uint32_t)digit << j->shift;
        j->mask |= (j->bins - 1) << j->shift;
    }
    /* Everything below the pivot key, then the first of its ties in source
     * order: each block's place and share, in block order. */
    j->pivot = all ? UINT32_MAX : j->prefix;
    run_pass(j, PASS_COUNT);
    before = 0;
    for (size_t b = 0; b < j->blocks; b++)
        before += j->below[b];
    size_t at = 0, ties = want - before;
    for (size_t b = 0; b < j->blocks; b++) {
        j->offset[b] = at;
        j->quota[b] = j->equal[b] < ties ? j->equal[b] : ties;
        ties -= j->quota[b];
        at += j->below[b] + j->quota[b];
        j->end[b] = at;
    }
    run_pass(j, PASS_GATHER);
}

void pfx_sort_begin(pfx_sort_cursor *c, const pfx_view *v, const pfx_sprite_source *src) {
    memset(c, 0, sizeof *c);
    c->src = src;
    memcpy(c->f, v->forward, sizeof c->f);
    memcpy(c->e, v->eye, sizeof c->e);
}

bool pfx_sort_next(pfx_renderer *r, pfx_sort_cursor *c, const uint32_t **order, size_t *n,
                   pfx_diags *d) {
    const size_t count = c->src->count;
    *order = NULL;
    *n = 0;
    if (count > UINT32_MAX) {
        pfx_diag_error(d, PFX_RULE_TOO_MANY, "too many sprites to sort: %zu", count);
        return false;
    }
    if (c->done >= count)
        return true;
    if (!grow_scratch(r, count, d))
        return false;
    const size_t left = count - c->done;
    if (!c->started && left <= r->sort_batch) { /* all at once, as one sort */
        key_job j = {c, r->keys, r->index, count};
        pfx_workers *w = count >= PFX_RADIX_PARALLEL_MIN ? r->workers : NULL;
        pfx_workers_run(w, (count + PFX_RADIX_BLOCK - 1) / PFX_RADIX_BLOCK, make_keys, &j);
        *n = count;
    } else {
        *n = left < r->sort_batch ? left : r->sort_batch;
        gather_batch(r, c, *n, *n == left);
    }
    *order = radix(r, *n);
    /* The batch's last sprite: where the next one starts. */
    const uint32_t *keys = *order == r->index ? r->keys : r->keys + r->scratch_cap;
    c->k_last = keys[*n - 1];
    c->i_last = (*order)[*n - 1];
    c->started = true;
    c->done += *n;
    return true;
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

/* pfx_renderer_sort: the order, batch by batch, then the sprites permuted
 * through a copy. */
bool pfx_sort_back_to_front(pfx_renderer *r, const pfx_view *v, pfx_sprite *sprites, size_t count,
                            pfx_diags *d) {
    if (count < 2)
        return true;
    if (count > r->sorted_cap) {
        pfx_sprite *sorted = realloc(r->sorted, count * sizeof *sorted);
        if (!sorted) {
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory sorting %zu sprites", count);
            return false;
        }
        r->sorted = sorted;
        r->sorted_cap = count;
    }
    const pfx_sprite_source src = pfx_sprite_source_array(sprites, count);
    pfx_sort_cursor c;
    pfx_sort_begin(&c, v, &src);
    for (size_t at = 0; at < count;) {
        const uint32_t *order;
        size_t n;
        if (!pfx_sort_next(r, &c, &order, &n, d))
            return false;
        pfx_sort_make(r, &src, order, 0, n, r->sorted + at);
        at += n;
    }
    memcpy(sprites, r->sorted, count * sizeof *sprites);
    return true;
}
