/* The estimate of a run (jobs/estimate.c) against what the simulation
 * really allocates, the step count from its definition, and --max-memory's
 * size parser; and the spawn queues' bound by their target pools. */

#include "jobs/estimate.h"
#include "output/frame_queue.h"
#include "render/render.h"
#include "sim/sim.h"
#include "sim/spawn.h"
#include "test.h"
#include "test_compile.h"

/* Sub-emitters in a cycle with trails, a deflector, alpha and additive
 * emitters: every pool and queue kind the estimate adds up. */
static const char *const cycle =
    "pfx: 1\nduration: 2\nfps: 30\nsim: { rate: 90 }\n"
    "deflectors:\n  floor: { type: plane }\n"
    "emitters:\n"
    "  a:\n    rate: 1000\n    lifetime: 0.5\n    blend: alpha\n"
    "    trail: { emit: b, rate: 200 }\n    on_death: { emit: b, count: 50, depth: 4 }\n"
    "  b:\n    lifetime: 0.25\n    on_death: { emit: a, count: 3, depth: 4 }\n"
    "  c:\n    rate: 10\n    lifetime: 1\n";

static void test_pools_and_queues_as_allocated(void) {
    compiled c;
    const pfx_effect *e = compile_text(&c, cycle);
    if (!e)
        return;
    pfx_estimate est;
    pfx_estimate_run(e, 0, 59, false, &est);
    pfx_sim *s = pfx_sim_create(e, NULL);
    CHECK(s != NULL);
    if (s) {
        CHECK_NEAR(est.bytes[PFX_MEMORY_POOLS], (double)s->bytes, 0);
        CHECK_NEAR(est.bytes[PFX_MEMORY_VIEW], (double)s->bytes, 0);
        double queues = 0;
        for (size_t i = 0; i < e->emitter_count; i++) {
            queues += (double)s->queues[i].cap * sizeof(spawn_record);
            /* A queue never holds more records than its target's pool. */
            CHECK(s->queues[i].cap <= e->emitters[i].capacity);
        }
        CHECK(queues > 0);
        CHECK_NEAR(est.bytes[PFX_MEMORY_QUEUES], 2 * queues, 0);
        pfx_sim_destroy(s);
    }
    /* Baking draws nothing: no sprite, framebuffer or encoder. */
    CHECK(est.bytes[PFX_MEMORY_SPRITES] == 0 && est.bytes[PFX_MEMORY_FRAMEBUFFER] == 0);
    /* Frame 59 is at 59/30 s: ceil(59/30 * 90) = 177 steps, each with at
     * most every pool full. */
    CHECK_NEAR(est.steps, 177, 0);
    double particles = 0;
    for (size_t i = 0; i < e->emitter_count; i++)
        particles += e->emitters[i].capacity;
    CHECK_NEAR(est.particle_steps, 177 * particles, 0);
    compiled_free(&c);
}

static void test_render_parts(void) {
    compiled c;
    const pfx_effect *e = compile_text(&c, cycle);
    if (!e)
        return;
    pfx_estimate est;
    pfx_estimate_run(e, 10, 12, true, &est);
    double particles = 0;
    for (size_t i = 0; i < e->emitter_count; i++)
        particles += e->emitters[i].capacity;
    /* 512 x 512: RGBA32F twice; per encoder (one per core) two float
     * frames of 16 bytes a pixel and an EXR file of at most 8, the
     * filtered rows (512 x 4 + 1 bytes each), libdeflate's bound for their
     * stream (the rows, + 1/1000, + 1 KiB) and its 700 KiB compressor; and
     * for the drawing thread, which encodes when every frame is queued, an
     * EXR file and the same scratch (counted in the fixed amount). */
    const double encoders = pfx_frame_encoder_count(e->threads);
    const double rows = (512 * 4 + 1) * 512;
    const double scratch = 2 * rows + 1049 + 1024 + 700 * 1024;
    const double per_thread = 512.0 * 512 * (2 * 16 + 8) + scratch;
    const double caller = 512.0 * 512 * 8 + scratch;
    CHECK_NEAR(est.bytes[PFX_MEMORY_FRAMEBUFFER], 2.0 * 512 * 512 * 16, 0);
    CHECK_NEAR(est.bytes[PFX_MEMORY_ENCODER], encoders * per_thread + caller, 0);
    CHECK_NEAR(est.per_thread_bytes, per_thread, 0);
    /* Sprites go to GL in chunks of 4096 (render.h), at most two in flight:
     * one chunk buffer, up to three GL stores of 64-byte sprites, and the
     * driver's 2 KiB a sprite over four chunks; none of it grows with the
     * particles (this effect has more than four chunks' worth). */
    CHECK(PFX_RENDER_CHUNK == 4096 && particles > 4 * 4096);
    CHECK_NEAR(est.bytes[PFX_MEMORY_SPRITES], 4 * 4096 * 64, 0);
    CHECK_NEAR(est.bytes[PFX_MEMORY_DRIVER], 4 * 4096 * 2048.0, 0);
    /* The sort: two key and two index arrays of 4 bytes, by doubling from
     * 1024, and 256 histogram words a 65536-key block and one more. */
    size_t cap = 1024;
    while (cap < particles + 1)
        cap *= 2;
    CHECK_NEAR(est.bytes[PFX_MEMORY_SORT], cap * 16.0 + ((cap + 65535) / 65536 + 1) * 256 * 4, 0);
    CHECK(est.bytes[PFX_MEMORY_SORT] < (particles + 1) * 33);
    /* Past PFX_SORT_BATCH sprites the sort works in batches: its scratch
     * stops at 2^22 sprites' keys and positions (64 MiB), their
     * histograms, and the batches' 256 x 2048 selection histograms. */
    CHECK(PFX_SORT_BATCH == (size_t)1 << 22);
    const double top = (double)(1 << 22) * 16 + (64 + 1) * 256 * 4 + 256 * 2048 * 4;
    CHECK_NEAR((double)pfx_renderer_sort_bytes(PFX_SORT_BATCH + 1), top, 0);
    CHECK_NEAR((double)pfx_renderer_sort_bytes((size_t)1 << 30), top, 0);
    /* What does not grow with the particles past a point: the sprite
     * chunk, the driver's chunks, the framebuffers, the sort and the
     * drawing thread's encoding; the bound adds it to 2 x pools and the
     * encoders. */
    CHECK_NEAR(est.fixed_bytes,
               4 * 4096 * 64 + 4 * 4096 * 2048.0 + 2.0 * 512 * 512 * 16 +
                   est.bytes[PFX_MEMORY_SORT] + caller,
               0);
    CHECK_NEAR(est.bound_bytes,
               2 * est.bytes[PFX_MEMORY_POOLS] + est.fixed_bytes + encoders * per_thread, 0);
    CHECK_NEAR(est.sprites, 3 * particles, 0);
    double total = 0, most = 0;
    for (int p = 0; p < PFX_MEMORY_PART_COUNT; p++) {
        total += est.bytes[p];
        most = fmax(most, est.bytes[p]);
    }
    CHECK_NEAR(est.total_bytes, total, 0);
    CHECK_NEAR(est.bytes[est.biggest], most, 0);
    compiled_free(&c);
}

/* --motion-vectors adds its pass, 52 bytes a pixel (a second RGBA32F
 * target and its read-back, 3 floats and 4 16-bit samples a pixel), a
 * chunk of the sprites' ends (16 bytes a sprite) and its GL buffer, and
 * the simulation one frame ahead: the pools and queues once more (the
 * state and its view, as the render's own) and an id index, 8 bytes a
 * particle (plus one) and 16 a particle of the largest pool with the
 * radix sort's 256 words a block (plus one); to a render and to nothing
 * else; without it the part is 0. */
static void test_motion_vectors_part(void) {
    compiled c;
    const pfx_effect *e = compile_text(&c, cycle);
    if (!e)
        return;
    pfx_estimate plain, mv, bake;
    pfx_estimate_run(e, 10, 12, PFX_ESTIMATE_RENDER, &plain);
    pfx_estimate_run(e, 10, 12, PFX_ESTIMATE_RENDER | PFX_ESTIMATE_MOTION_VECTORS, &mv);
    pfx_estimate_run(e, 10, 12, PFX_ESTIMATE_MOTION_VECTORS, &bake);
    double particles = 1, most = 1;
    for (size_t i = 0; i < e->emitter_count; i++) {
        particles += e->emitters[i].capacity;
        most = e->emitters[i].capacity > most ? e->emitters[i].capacity : most;
    }
    CHECK(!e->loop); /* its queues are the state's and the view's */
    const double want = 512.0 * 512 * (16 + 16 + 12 + 8) + 2.0 * 4096 * 16 +
                        plain.bytes[PFX_MEMORY_POOLS] + plain.bytes[PFX_MEMORY_VIEW] +
                        plain.bytes[PFX_MEMORY_QUEUES] + 8 * particles + 16 * most +
                        4 * 256 * (ceil(most / 65536) + 1);
    CHECK_NEAR(plain.bytes[PFX_MEMORY_MOTION_VECTORS], 0, 0);
    CHECK_NEAR(mv.bytes[PFX_MEMORY_MOTION_VECTORS], want, 0);
    CHECK_NEAR(mv.total_bytes, plain.total_bytes + want, 0);
    CHECK_NEAR(bake.bytes[PFX_MEMORY_MOTION_VECTORS], 0, 0);
    CHECK_NEAR(bake.bytes[PFX_MEMORY_FRAMEBUFFER], 0, 0);
    CHECK(!strcmp(pfx_memory_part_keys[PFX_MEMORY_MOTION_VECTORS], "motion_vectors"));
    /* The other parts do not move. */
    for (int p = 0; p < PFX_MEMORY_PART_COUNT; p++)
        if (p != PFX_MEMORY_MOTION_VECTORS)
            CHECK_NEAR(mv.bytes[p], plain.bytes[p], 0);
    compiled_free(&c);
}

static void test_memory_parse(void) {
    uint64_t b = 0;
    CHECK(pfx_memory_parse("4096", &b) && b == 4096);
    CHECK(pfx_memory_parse("100B", &b) && b == 100);
    CHECK(pfx_memory_parse("512K", &b) && b == 512 * 1024);
    CHECK(pfx_memory_parse("3M", &b) && b == 3 * 1024 * 1024);
    CHECK(pfx_memory_parse("1.5G", &b) && b == 1536ULL * 1024 * 1024);
    CHECK(pfx_memory_parse("2GiB", &b) && b == 2ULL << 30);
    CHECK(pfx_memory_parse("1TB", &b) && b == 1ULL << 40);
    const char *bad[] = {"", "0", "-1", "G", "4X", "1.5Gx", "1e30", "nan", " 4", NULL};
    for (int i = 0; bad[i]; i++)
        CHECK(!pfx_memory_parse(bad[i], &b));
    char buf[32];
    CHECK(!strcmp(pfx_memory_format(1536.0 * 1024 * 1024, buf, sizeof buf), "1.5 GiB"));
    CHECK(!strcmp(pfx_memory_format(100, buf, sizeof buf), "100 bytes"));
}

int main(void) {
    RUN(test_pools_and_queues_as_allocated);
    RUN(test_render_parts);
    RUN(test_motion_vectors_part);
    RUN(test_memory_parse);
    return TEST_EXIT();
}
