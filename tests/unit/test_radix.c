/* The threaded radix sort (base/radix.h) gives the stable order for any
 * thread count: 2e6 keys with many ties sorted on 1, 2, 3 and 7 threads
 * equal the one-thread result and a reference stable sort (qsort on
 * (key, index), which no two elements share). Also the edges: no keys,
 * one, every key equal (every pass skipped), counts that do not fill the
 * last block. */
#include "base/radix.h"
#include "base/rng.h"
#include "test.h"

#include <stdbool.h>
#include <stdint.h>

typedef struct pair {
    uint32_t key, index;
} pair;

static int by_key_then_index(const void *a, const void *b) {
    const pair *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

/* Sorts a copy of keys on `threads` threads (0: no worker set at all) and
 * returns the index order (malloc'd), or NULL when memory runs out. */
static uint32_t *radix_order(const uint32_t *keys, size_t n, int threads) {
    uint32_t *k = malloc(2 * (n + 1) * sizeof *k), *i = malloc(2 * (n + 1) * sizeof *i);
    uint32_t *h = malloc(pfx_radix_hist_words(n) * sizeof *h), *out = malloc((n + 1) * sizeof *out);
    pfx_workers *w = threads > 0 ? pfx_workers_create(threads) : NULL;
    CHECK(k && i && h && out && (threads == 0 || w));
    if (!k || !i || !h || !out || (threads > 0 && !w)) {
        free(k), free(i), free(h), free(out), pfx_workers_destroy(w);
        return NULL;
    }
    memcpy(k, keys, n * sizeof *k);
    for (size_t j = 0; j < n; j++)
        i[j] = (uint32_t)j;
    const uint32_t *order = pfx_radix_sort(w, k, i, k + n + 1, i + n + 1, h, n);
    memcpy(out, order, n * sizeof *out);
    /* The keys beside the returned indices are sorted too. */
    const uint32_t *sorted = order == i ? k : k + n + 1;
    size_t wrong = 0;
    for (size_t j = 0; j < n; j++)
        wrong += sorted[j] != keys[out[j]];
    CHECK(wrong == 0);
    free(k), free(i), free(h), pfx_workers_destroy(w);
    return out;
}

static uint32_t *reference_order(const uint32_t *keys, size_t n) {
    pair *p = malloc((n + 1) * sizeof *p);
    uint32_t *out = malloc((n + 1) * sizeof *out);
    CHECK(p && out);
    if (!p || !out) {
        free(p), free(out);
        return NULL;
    }
    for (size_t j = 0; j < n; j++)
        p[j] = (pair){keys[j], (uint32_t)j};
    qsort(p, n, sizeof *p, by_key_then_index);
    for (size_t j = 0; j < n; j++)
        out[j] = p[j].index;
    free(p);
    return out;
}

static bool same(const uint32_t *a, const uint32_t *b, size_t n) {
    return a && b && (n == 0 || memcmp(a, b, n * sizeof *a) == 0);
}

/* Every key against the reference and the one-thread order, at threads 1,
 * 2, 3, 7. */
static void check_all(const uint32_t *keys, size_t n, const char *what) {
    uint32_t *ref = reference_order(keys, n), *serial = radix_order(keys, n, 0);
    CHECK(same(serial, ref, n));
    const int counts[] = {1, 2, 3, 7};
    for (int t = 0; t < 4; t++) {
        uint32_t *o = radix_order(keys, n, counts[t]);
        if (!same(o, ref, n))
            fprintf(stderr, "  %s, %zu keys: %d threads differ from the stable order\n", what, n,
                    counts[t]);
        CHECK(same(o, ref, n));
        free(o);
    }
    free(ref), free(serial);
}

/* 2e6 keys from 5000 values: about 400 ties each, spread over all four
 * bytes so that no pass is skipped. */
static void test_many_ties(void) {
    const size_t n = 2000000;
    uint32_t *keys = malloc(n * sizeof *keys);
    CHECK(keys != NULL);
    if (!keys)
        return;
    pfx_rng r;
    pfx_rng_seed(&r, 11, 0);
    for (size_t j = 0; j < n; j++)
        keys[j] = (uint32_t)(pfx_rng_next(&r) % 5000) * 858993u; /* 858993 x 4999 < 2^32 */
    check_all(keys, n, "ties");
    /* Only the top byte differs: three passes skipped, one moves. */
    for (size_t j = 0; j < n; j++)
        keys[j] = (uint32_t)(pfx_rng_next(&r) % 7) << 24 | 0x00abcdefu;
    check_all(keys, n, "top byte");
    free(keys);
}

static void test_edges(void) {
    const size_t sizes[] = {
        0, 1, 2, 3, PFX_RADIX_BLOCK - 1, PFX_RADIX_BLOCK + 1, PFX_RADIX_PARALLEL_MIN + 12345};
    const size_t most = PFX_RADIX_PARALLEL_MIN + 12345;
    uint32_t *keys = malloc(most * sizeof *keys);
    CHECK(keys != NULL);
    if (!keys)
        return;
    pfx_rng r;
    pfx_rng_seed(&r, 12, 0);
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        for (size_t j = 0; j < sizes[s]; j++)
            keys[j] = (uint32_t)pfx_rng_next(&r);
        check_all(keys, sizes[s], "random");
        for (size_t j = 0; j < sizes[s]; j++)
            keys[j] = 42; /* every pass skipped: the input order */
        check_all(keys, sizes[s], "equal");
    }
    free(keys);
}

int main(void) {
    RUN(test_edges);
    RUN(test_many_ties);
    return TEST_EXIT();
}
