/* Work and memory of a run, estimated from the compiled effect before
 * anything is allocated (jobs/estimate.c): what `pfx info` shows, what
 * `validate` warns about, and what --max-memory refuses. */
#ifndef PFX_JOBS_ESTIMATE_H
#define PFX_JOBS_ESTIMATE_H

#include <stdbool.h>
#include <stdint.h>

#include <jansson.h>

#include "jobs/load.h"

/* Where a run's memory goes, one row each: the enum, the key of `pfx info
 * --format json` and the name that `pfx info` and the --max-memory error
 * print. */
#define PFX_MEMORY_PARTS(X)                                                                        \
    X(POOLS, "pools", "particle pools")                                                            \
    X(VIEW, "view", "frame view (a second copy of the pools)")                                     \
    X(LOOP, "loop", "loop start (a third copy of the pools)")                                      \
    X(QUEUES, "queues", "spawn queues")                                                            \
    X(SPRITES, "sprites", "sprites (a chunk and its GL vertex buffers)")                           \
    X(SORT, "sort", "depth-sort scratch")                                                          \
    X(RIBBONS, "ribbons", "ribbon triangles (array, scratch and GL vertex buffer)")                \
    X(DRIVER, "driver", "GL driver's binned triangles (llvmpipe, chunks in flight)")               \
    X(FRAMEBUFFER, "framebuffer", "float framebuffer, read-back, blur sum")                        \
    X(MOTION_VECTORS, "motion_vectors", "motion-vector pass (float target, read-back, encoding)")  \
    X(ENCODER, "encoders", "frame encoder buffers and deflate scratch")                            \
    X(TEXTURES, "textures", "textures")

typedef enum {
#define PFX_PART_ENUM(id, key, name) PFX_MEMORY_##id,
    PFX_MEMORY_PARTS(PFX_PART_ENUM)
#undef PFX_PART_ENUM
        PFX_MEMORY_PART_COUNT
} pfx_memory_part;

extern const char *const pfx_memory_part_names[PFX_MEMORY_PART_COUNT];
extern const char *const pfx_memory_part_keys[PFX_MEMORY_PART_COUNT];

/* Above this much work (particle-steps and sub-emitter events) `validate` warns: hours at the
 * speeds `pfx bench` measures (about 1e7 to 1e8 particle-steps a second). */
#define PFX_WORK_WARN_PARTICLE_STEPS 1e11

/* Upper bounds, each for the run to the last frame asked for: every pool
 * full from the first step on, every sprite as large as it can be. */
typedef struct pfx_estimate {
    double steps;          /* fixed simulation steps, prewarm included */
    double particle_steps; /* steps x the particles alive in each x their
                              emitter's substeps, at most */
    double spawn_events;   /* sub-emitter events raised (trail births, births,
                              deaths, hits of parents with spawns), at most:
                              each costs about what a particle-step does */
    double work;           /* particle_steps + spawn_events */
    double sprites;        /* sprites drawn over the frames rendered */
    double sprite_pixels;  /* their pixels, each sprite at most the image */
    double bytes[PFX_MEMORY_PART_COUNT];
    double total_bytes; /* peak: every part at once */
    pfx_memory_part biggest;
    /* The bound on a render: 2 x the pools plus a fixed amount for the
     * drawing thread and one per encoder thread. fixed_bytes is what does
     * not grow with the particles: the sprite chunk and its GL stores, the
     * driver's chunks in flight and its shaders for textures, the float
     * framebuffers, the textures and the drawing thread's own encoding
     * buffer and deflate scratch (it grows with the image, as the
     * encoders' frames do). per_thread_bytes is what each encoder thread
     * holds (its two frames and its deflate scratch). bound_bytes = 2 x
     * pools + fixed_bytes + threads x per_thread_bytes. What falls outside
     * it grows with the particles: the depth sort's keys (16 bytes a
     * sprite, when an emitter blends by alpha), a loop's third copy of the
     * pools, the spawn queues and the ribbons. */
    int threads;
    double per_thread_bytes;
    double fixed_bytes;
    double bound_bytes;
} pfx_estimate;

/* What a run does, for pfx_estimate_run, or'ed: a bake (0) or a render,
 * with --motion-vectors or not. RENDER is 1 so that a bool `render`
 * (true, false) still says render or bake. */
enum {
    PFX_ESTIMATE_RENDER = 1,
    PFX_ESTIMATE_MOTION_VECTORS = 2, /* with RENDER: the motion-vector pass too */
};

/* Estimates a run of e to output frame `last` (frames from `first`):
 * drawing them when `what` has PFX_ESTIMATE_RENDER, baking them otherwise.
 * Pure: reads the effect only. */
void pfx_estimate_run(const pfx_effect *e, long first, long last, unsigned what, pfx_estimate *out);
/* True when that run's estimate fits in max_memory bytes (0: no bound);
 * else false with an error in d naming the need, the bound and the
 * biggest part (render and bake refuse such a run, preview such a
 * version). */
bool pfx_estimate_fits(const pfx_effect *e, long first, long last, unsigned what,
                       uint64_t max_memory, pfx_diags *d);

/* The estimate as JSON (jansson; the caller owns the reference): work
 * {steps, particle_steps, sprites, sprite_pixels} and memory {total_bytes,
 * one key per part (pfx_memory_part_keys), threads, per_thread_bytes,
 * fixed_bytes, bound_bytes}. NULL when out of memory. */
json_t *pfx_estimate_json(const pfx_estimate *est);

/* The bytes of `frames` frames of e as the PNG files a render writes, at
 * most: per frame the filtered rows, n = (4 x width + 1) x height, plus
 * n / 64 + 1024 for deflate's and PNG's framing (stored blocks, chunk
 * headers). The live session's frame cache is capped by it. */
double pfx_estimate_png_bytes(const pfx_effect *e, long frames);

/* Half of physical memory: --max-memory's default (0 where unknown). */
uint64_t pfx_memory_default_bound(void);

/* Parses SIZE: bytes, or a number with K, M, G or T (powers of 1024, an
 * optional "iB" or "B" after it). False when it is not one, or zero. */
bool pfx_memory_parse(const char *text, uint64_t *bytes);

/* Writes n bytes as "12.3 GiB" into buf. */
const char *pfx_memory_format(double n, char *buf, size_t size);

/* Warnings for `validate` into l->diags, located at the key that sets
 * the work: work past PFX_WORK_WARN_PARTICLE_STEPS, or past bound bytes of
 * memory (0: no bound), naming the biggest consumer. */
void pfx_estimate_warn(pfx_loaded *l, const pfx_estimate *est, uint64_t bound);
/* `validate`'s checks of a file that compiled (l->effect): the warnings of
 * a render of every frame, against bound bytes (0: none). The one path of
 * `validate` and the language server, so both report the same. */
void pfx_estimate_check(pfx_loaded *l, uint64_t bound);

#endif
