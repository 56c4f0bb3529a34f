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
 * fifth pool is small (its blocks shrink to share it among threads). The
 * last three have scheduled births made in batches on the threads
 * (sim/newborn.c): bursts swept against a plane with random responses in
 * their first part-step; a looping effect (each period's first birth
 * restarts the stream) whose shortest lives leave some blocks of births
 * dead at the step's end (those are made alone), with a lifetime loss on
 * impact; and a pool that fills (max_particles), so that batches close
 * short of it and the rest is dropped. */
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
    "pfx: 1\nseed: 8\nforces:\n  g: { type: gravity }\n"
    "deflectors:\n  floor: { type: plane, resilience: [0.2, 0.7], friction: [0, 0.4] }\n"
    "emitters:\n  e:\n    shape: { type: sphere, radius: 0.3 }\n    position: [0, 0.05, 0]\n"
    "    bursts: [{ time: 0, count: 30000 }, { time: 0.31, count: 9000, cycles: 3, "
    "interval: 0.2 }]\n    speed: [1, 3]\n    spread: 120\n    direction: [0, -1, 0]\n"
    "    lifetime: [0.5, 2]\n",
    "pfx: 1\nseed: 9\nduration: 0.4\nloop: true\nforces:\n  g: { type: gravity }\n"
    "deflectors:\n  floor: { type: plane, resilience: 0.5, lifetime_loss: 0.3 }\n"
    "emitters:\n  e:\n    position: [0, 0.2, 0]\n    rate: 90000\n    speed: [0, 2]\n"
    "    spread: 90\n    lifetime: [0.002, 0.3]\n",
    "pfx: 1\nseed: 10\nforces:\n  g: { type: gravity }\n"
    "emitters:\n  e:\n    shape: { type: box, size: [1, 1, 1] }\n    rate: 60000\n"
    "    bursts: [{ time: 0.2, count: 3000 }]\n    speed: [1, 3]\n    lifetime: 1\n",
};
/* --max-particles of each effect (0: the default) */
static const uint64_t max_particles[] = {0, 0, 0, 0, 0, 0, 0, 7000};

static uint64_t run_hash(const char *text, uint64_t max, int threads, int steps, uint32_t *most,
                         uint32_t *block) {
    compiled c;
    pfx_compile_options opt = {.threads = threads, .max_particles = max};
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
    /* the collision counters too, summed over blocks and batches */
    for (size_t i = 0; i < c.e->emitter_count; i++) {
        const pfx_collide_stats *st = &s->emitters[i].collisions;
        const uint64_t counts[] = {st->impacts, st->contacts, st->kills,
                                   st->sticks,  st->capped,   st->fallbacks};
        for (int k = 0; k < 6; k++)
            h = (h ^ counts[k]) * 0x100000001b3ULL;
    }
    pfx_sim_destroy(v);
    pfx_sim_destroy(s);
    compiled_free(&c);
    return h;
}

static void test_thread_counts(void) {
    for (size_t k = 0; k < sizeof effects / sizeof *effects; k++) {
        uint32_t most = 0, block = 0;
        uint64_t one = run_hash(effects[k], max_particles[k], 1, 60, &most, &block);
        CHECK(block == PFX_SIM_BLOCK_MAX);
        const int counts[] = {2, 3, 7};
        for (int t = 0; t < 3; t++) {
            uint32_t m = 0;
            uint64_t h = run_hash(effects[k], max_particles[k], counts[t], 60, &m, &block);
            /* Several blocks, or the threads have nothing to share. */
            CHECK(m > 3 * block);
            if (h != one)
                fprintf(stderr, "  effect %zu: %d threads give %016llx, 1 gives %016llx\n", k,
                        counts[t], (unsigned long long)h, (unsigned long long)one);
            CHECK(h == one);
        }
    }
}

/* A particle that leaves the simulated space stops the simulation at the
 * same step on any thread count: a burst of 6000 at 4e5 m/s (their bound
 * at birth reaches the state check's 1e7 m, so each step checks them, a
 * flag the births made on the threads must raise) passes 1e7 m after 25 s.
 * (The second burst, never reached, leaves the pool room for a block more,
 * so that every block of the first is made on the threads.) */
static int runaway_step(int threads) {
    compiled c;
    pfx_compile_options opt = {.threads = threads};
    if (!compile_opt(
            &c,
            "pfx: 1\nsim: { rate: 25 }\nforces:\n  g: { type: gravity }\n"
            "emitters:\n  e:\n    bursts: [{ time: 0, count: 6000 }, { time: 900, count: 100 }]\n"
            "    direction: [1, 0, 0]\n    speed: 400000\n    lifetime: 1000\n",
            &opt))
        return -1;
    pfx_sim *s = pfx_sim_create(c.e, NULL);
    int step = 0;
    while (!s->failed && step < 1000)
        pfx_sim_step(s), step++;
    pfx_sim_destroy(s);
    compiled_free(&c);
    return step;
}

static void test_runaway_caught(void) {
    const int one = runaway_step(1), two = runaway_step(2);
    /* 1e7 m / 4e5 m/s = 25 s, step 625 at 25 steps a second */
    CHECK(one == 626);
    CHECK(two == one);
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
    RUN(test_runaway_caught);
    return TEST_EXIT();
}
