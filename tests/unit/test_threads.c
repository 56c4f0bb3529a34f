/* The simulation's thread count does not change its state, pool order
 * included: the state hash after many steps (and after views between
 * steps) is the same for 1, 2, 3 and 7 threads, on effects whose pools
 * span many blocks of the threaded passes. The bake and render comparison
 * of the same property is tests/threads/run_threads.sh. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "base/workers.h"
#include "sim/sim.h"
#include "test_compile.h"

#include <time.h>

/* Gravity only (the exact kernel), a split-step force set with operators,
 * and a deflector with random response, on_hit and on_death births; the
 * last pool is small (its blocks shrink to share it among threads). */
static const char *const effects[] = {
    "pfx: 1\nseed: 3\nforces:\n  g: { type: gravity }\n"
    "emitters:\n  e:\n    shape: { type: sphere, radius: 0.3 }\n    rate: 60000\n"
    "    speed: [1, 3]\n    spread: 40\n    lifetime: [0.5, 1]\n"
    "    gravity_scale: [0.5, 1.5]\n",
    "pfx: 1\nseed: 4\nforces:\n  g: { type: gravity }\n"
    "  a: { type: attractor, center: [0, 1, 0], strength: 2, softening: 0.2 }\n"
    "  v: { type: vortex, axis: [0, 1, 0], strength: 3, radius: 2 }\n"
    "  s: { type: spiral, axis: [0, 1, 0], rate: 2 }\n"
    "emitters:\n  e:\n    shape: { type: sphere, radius: 0.3 }\n    rate: 80000\n"
    "    speed: [1, 3]\n    spread: 40\n    lifetime: [0.4, 0.8]\n",
    "pfx: 1\nseed: 5\nforces:\n  g: { type: gravity }\n  d: { type: drag, c: 0.1 }\n"
    "deflectors:\n  floor: { type: plane, resilience: [0.2, 0.7], friction: [0, 0.4] }\n"
    "emitters:\n  e:\n    shape: { type: sphere, radius: 0.3 }\n    position: [0, 0.4, 0]\n"
    "    rate: 80000\n    speed: [1, 3]\n    spread: 60\n    lifetime: [0.4, 0.8]\n"
    "    on_hit: { emit: c, count: 1, probability: 0.2 }\n"
    "    on_death: { emit: c, count: 1, probability: 0.2 }\n"
    "  c:\n    speed: [0, 1]\n    lifetime: 0.1\n    deflectors: []\n",
    /* an attractor whose substeps auto takes per particle (by distance) */
    "pfx: 1\nseed: 6\nforces:\n  g: { type: gravity }\n"
    "  a: { type: attractor, center: [0, 0.6, 0], strength: 2, softening: 0.2 }\n"
    "  s: { type: spiral, axis: [0, 1, 0], rate: 2 }\n"
    "emitters:\n  e:\n    shape: { type: sphere, radius: 0.3 }\n    rate: 80000\n"
    "    speed: [1, 3]\n    spread: 40\n    lifetime: [0.4, 0.8]\n"
    "    gravity_scale: [0.5, 1.5]\n",
    "pfx: 1\nseed: 7\nforces:\n  g: { type: gravity }\n"
    "deflectors:\n  floor: { type: plane, resilience: [0.2, 0.7], friction: 0.3 }\n"
    "emitters:\n  e:\n    shape: { type: sphere, radius: 0.3 }\n    position: [0, 0.4, 0]\n"
    "    rate: 12000\n    speed: [1, 3]\n    spread: 60\n    lifetime: 0.8\n"
    "    on_hit: { emit: c, count: 1, probability: 0.3 }\n"
    "  c:\n    speed: [0, 1]\n    lifetime: 0.1\n    deflectors: []\n",
};

static uint64_t run_hash(const char *text, int threads, int steps, uint32_t *most,
                         uint32_t *block) {
    compiled c;
    pfx_compile_options opt = {.threads = threads};
    if (!compile_opt(&c, text, &opt))
        return 0;
    pfx_sim *s = pfx_sim_create(c.e, NULL), *v = pfx_sim_create(c.e, NULL);
    CHECK(s && v);
    if (!s || !v)
        return 0;
    /* (fewer where the pool has fewer blocks than threads) */
    CHECK((pfx_workers_count(s->workers) > 1) == (threads > 1));
    *block = s->block;
    for (int k = 0; k < steps; k++) {
        pfx_sim_step(s);
        if (k % 5 == 0)
            pfx_sim_view_at(s, v, s->time + 0.375 * s->dt);
        if (s->pools[0].count > *most)
            *most = s->pools[0].count;
    }
    CHECK(!s->failed && !v->failed);
    uint64_t h = pfx_sim_hash(s) ^ 31 * pfx_sim_hash(v);
    pfx_sim_destroy(v);
    pfx_sim_destroy(s);
    compiled_free(&c);
    return h;
}

static void test_thread_counts(void) {
    for (size_t k = 0; k < sizeof effects / sizeof *effects; k++) {
        uint32_t most = 0, block = 0;
        uint64_t one = run_hash(effects[k], 1, 60, &most, &block);
        CHECK(block == PFX_SIM_BLOCK_MAX);
        const int counts[] = {2, 3, 7};
        for (int t = 0; t < 3; t++) {
            uint32_t m = 0;
            uint64_t h = run_hash(effects[k], counts[t], 60, &m, &block);
            /* Several blocks, or the threads have nothing to share. */
            CHECK(m > 3 * block);
            if (h != one)
                fprintf(stderr, "  effect %zu: %d threads give %016llx, 1 gives %016llx\n", k,
                        counts[t], (unsigned long long)h, (unsigned long long)one);
            CHECK(h == one);
        }
    }
}

/* The thread set itself: every block runs exactly once, for any count of
 * blocks and threads, job after job. Every other job is posted after a
 * pause longer than the set's poll (50 us), so that the helpers have gone
 * to sleep and must be woken, and the others back to back, taken by
 * helpers still polling; a block's result must be seen by the caller
 * either way. */
typedef struct tally {
    int *runs;
} tally;

static void count_block(void *ctx, size_t b) { ((tally *)ctx)->runs[b]++; }

static void test_workers(void) {
    int runs[1000];
    for (int threads = 1; threads <= 5; threads++) {
        pfx_workers *w = pfx_workers_create(threads);
        CHECK(w && pfx_workers_count(w) == threads);
        for (size_t blocks = 0; blocks < 1000; blocks += 37) {
            memset(runs, 0, sizeof runs);
            tally t = {runs};
            if (blocks % 2) {
                const struct timespec pause = {0, 300000};
                nanosleep(&pause, NULL);
            }
            pfx_workers_run(w, blocks, count_block, &t);
            int wrong = 0;
            for (size_t b = 0; b < 1000; b++)
                wrong += runs[b] != (b < blocks);
            CHECK(wrong == 0);
        }
        pfx_workers_destroy(w);
    }
}

int main(void) {
    RUN(test_workers);
    RUN(test_thread_counts);
    return TEST_EXIT();
}
