/* The depth sort's benchmark: random sprites in a cube in front of a
 * camera, sorted back to front by the renderer (render/sort.c) on 1, 2 and
 * every core, and by qsort on (depth key, index) as the reference; the
 * reference's order is also the check that the radix order is right. */
#include "bench/sort_speed.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/rng.h"

#define SORT_RUNS 5 /* timed runs per row; the median is reported */
#define QSORT_RUNS 3

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int by_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *t, int n) {
    qsort(t, (size_t)n, sizeof *t, by_double);
    return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

/* The camera looks down -z from z = 10 at a cube of side 10 around the
 * origin; depth is 10 - z. */
static const pfx_camera camera = {
    .position = {0, 0, 10}, .target = {0, 0, 0}, .up = {0, 1, 0}, .fov = 0.8};

typedef struct keyed {
    float depth;
    uint32_t index;
} keyed;

/* Farthest first; equal depths in input order (the radix sort's order). */
static int by_depth_then_index(const void *a, const void *b) {
    const keyed *x = a, *y = b;
    if (x->depth != y->depth)
        return x->depth > y->depth ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

/* qsort's time for the same job: depths, the sort, the gather; `out`
 * receives the sorted sprites. */
static double qsort_ms(const pfx_sprite *in, size_t n, keyed *k, pfx_sprite *out) {
    double t0 = now();
    for (size_t i = 0; i < n; i++)
        k[i] = (keyed){(float)(10.0 - in[i].z), (uint32_t)i};
    qsort(k, n, sizeof *k, by_depth_then_index);
    for (size_t i = 0; i < n; i++)
        out[i] = in[k[i].index];
    return 1e3 * (now() - t0);
}

static bool bench_size(FILE *out, pfx_renderer *r, int cores, size_t n, pfx_sprite *in,
                       pfx_sprite *work, pfx_sprite *ref, keyed *k, json_t *rows, pfx_diags *d) {
    pfx_rng rng;
    pfx_rng_seed(&rng, 7, n);
    memset(in, 0, n * sizeof *in);
    for (size_t i = 0; i < n; i++) {
        in[i].x = (float)pfx_rng_range(&rng, -5, 5);
        in[i].y = (float)pfx_rng_range(&rng, -5, 5);
        /* 2^16 distinct depths: ties, as sprites born together have. */
        in[i].z = (float)((double)(pfx_rng_next(&rng) >> 16) / 65536.0 * 10.0 - 5.0);
        in[i].size = 0.1f;
    }
    double t[SORT_RUNS > QSORT_RUNS ? SORT_RUNS : QSORT_RUNS];
    for (int j = 0; j < QSORT_RUNS; j++)
        t[j] = qsort_ms(in, n, k, ref);
    const double reference = median(t, QSORT_RUNS);
    const int wanted[3] = {1, 2, cores};
    for (int c = 0; c < 3; c++) {
        const int threads = wanted[c];
        if (threads > cores || (c > 0 && threads <= wanted[c - 1]))
            continue;
        if (!pfx_renderer_set_threads(r, threads, d))
            return false;
        for (int j = -1; j < SORT_RUNS; j++) { /* run -1 grows the scratch */
            memcpy(work, in, n * sizeof *in);
            double t0 = now();
            if (!pfx_renderer_sort(r, &camera, work, n, d))
                return false;
            if (j >= 0)
                t[j] = 1e3 * (now() - t0);
        }
        if (memcmp(work, ref, n * sizeof *work) != 0) {
            pfx_diag_error(d, PFX_RULE_IMPOSSIBLE_REQUEST,
                           "the depth sort of %zu sprites on %d threads differs from qsort's", n,
                           threads);
            return false;
        }
        const double ms = median(t, SORT_RUNS);
        json_array_append_new(rows, json_pack("{s:I, s:i, s:f, s:f}", "sprites", (json_int_t)n,
                                              "threads", threads, "ms", ms, "qsort_ms", reference));
        if (out)
            fprintf(out, "  %10zu %7d %10.1f %10.1f %8.1fx\n", n, threads, ms, reference,
                    reference / ms);
    }
    return true;
}

bool pfx_bench_sort(FILE *out, pfx_renderer *r, int cores, json_t *rows, pfx_diags *d) {
    const size_t sizes[2] = {1000000, 4000000}, most = 4000000;
    pfx_sprite *in = malloc(most * sizeof *in), *work = malloc(most * sizeof *work),
               *ref = malloc(most * sizeof *ref);
    keyed *k = malloc(most * sizeof *k);
    bool ok = in && work && ref && k;
    if (!ok)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for %zu sprites", most);
    if (ok && out) {
        fprintf(out,
                "depth sort: random sprites back to front (keys, radix passes, gather), "
                "median of %d runs; reference qsort on (depth, index), median of %d\n",
                SORT_RUNS, QSORT_RUNS);
        fprintf(out, "  %10s %7s %10s %10s %9s\n", "sprites", "threads", "ms", "qsort ms",
                "speed-up");
    }
    for (int s = 0; ok && s < 2; s++)
        ok = bench_size(out, r, cores, sizes[s], in, work, ref, k, rows, d);
    ok = pfx_renderer_set_threads(r, cores, d) && ok;
    free(in), free(work), free(ref), free(k);
    return ok;
}
