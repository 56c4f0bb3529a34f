/* Work and memory of a run from the compiled effect, before any allocation:
 * the same sizes the stages will ask for (pools and queues from sim/, sprites
 * and sort scratch from render/, the frame queue from output/), added up as if
 * all were held at once. Upper bounds, not a profile: nothing is simulated
 * here, and the time is stated as particle-steps. */
#include "jobs/estimate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "jobs/motion_next.h"
#include "output/frame_queue.h"
#include "output/png_write.h"
#include "render/render.h"
#include "render/sprites.h"
#include "sim/pool.h"
#include "sim/sim.h"
#include "sim/spawn.h"

const char *const pfx_memory_part_names[PFX_MEMORY_PART_COUNT] = {
#define PFX_PART_NAME(id, key, name) name,
    PFX_MEMORY_PARTS(PFX_PART_NAME)
#undef PFX_PART_NAME
};

const char *const pfx_memory_part_keys[PFX_MEMORY_PART_COUNT] = {
#define PFX_PART_KEY(id, key, name) key,
    PFX_MEMORY_PARTS(PFX_PART_KEY)
#undef PFX_PART_KEY
};

/* The largest side of emitter em's sprites in pixels, at the emitter's own
 * distance from the camera (particles that come closer are larger; one that
 * covers the image is counted as the image). */
static double sprite_side_px(const pfx_effect *e, const pfx_emitter *em) {
    double size = fmax(pfx_value_max(&em->size_start), pfx_value_max(&em->size_end));
    if (em->size_curve)
        for (int k = 0; k < PFX_GRADIENT_LUT; k++)
            size = fmax(size, em->size_lut[k]);
    /* 0: the emitter is at or behind the camera. */
    double px_per_m = pfx_camera_pixels_per_metre(&e->camera, e->height, em->position);
    return px_per_m > 0 ? size * px_per_m : INFINITY;
}

/* Whether map k of emitter i is the first use of those pixels. */
static bool first_use(const pfx_effect *e, size_t i, int k, const void *pixels) {
    for (size_t j = 0; j <= i; j++) {
        const pfx_image *maps[2] = {e->emitters[j].look.texture, e->emitters[j].look.normal_map};
        for (int m = 0; m < (j < i ? 2 : k); m++)
            if (maps[m] && maps[m]->pixels == pixels)
                return false;
    }
    return true;
}

/* The memory parts of drawing and writing frames: the sprite chunk, the
 * sort, ribbons, the driver, the framebuffers, motion vectors, the frame
 * encoders and the textures; `fixed` gains what does not grow with the
 * particles. */
static void estimate_drawing(const pfx_effect *e, unsigned what, double image, pfx_estimate *out,
                             double *fixed) {
    const double sprites = (double)pfx_sprites_capacity(e) + 1;
    /* render.c makes sprites a chunk at a time into one buffer and
     * uploads each to a GL store of its own: the one being drawn and
     * two in flight. */
    out->bytes[PFX_MEMORY_SPRITES] =
        (PFX_RENDER_CHUNK + fmin(sprites, 3.0 * PFX_RENDER_CHUNK)) * sizeof(pfx_sprite);
    /* render/sort.c: keys and indices (double buffered) and the radix
     * blocks' histograms, grown by doubling; the sprites are made in
     * sorted order, never copied. It stops growing at PFX_SORT_BATCH
     * sprites (more are sorted in batches), so it is a fixed amount. */
    if (pfx_sprites_need_sort(e))
        out->bytes[PFX_MEMORY_SORT] = (double)pfx_renderer_sort_bytes((size_t)sprites);
    *fixed += out->bytes[PFX_MEMORY_SORT];
    out->bytes[PFX_MEMORY_RIBBONS] = (double)pfx_ribbons_bytes(e);
    /* What Mesa keeps of the chunks in flight, and of the ribbons'
     * single draw: see PFX_RENDER_DRIVER_BYTES_PER_SPRITE. */
    const double in_flight = fmin(sprites, PFX_RENDER_DRIVER_CHUNKS * PFX_RENDER_CHUNK);
    const double triangles = (double)pfx_ribbons_triangles(e);
    const double driver_sprites = in_flight * PFX_RENDER_DRIVER_BYTES_PER_SPRITE;
    out->bytes[PFX_MEMORY_DRIVER] =
        driver_sprites +
        fmin(triangles * PFX_RENDER_DRIVER_FIRST_BYTES_PER_TRIANGLE, PFX_RENDER_DRIVER_FIRST_CAP) +
        triangles * PFX_RENDER_DRIVER_BYTES_PER_TRIANGLE;
    *fixed += out->bytes[PFX_MEMORY_SPRITES] + driver_sprites;
    /* RGBA32F in GL and its float read-back, and motion blur's float
     * sum. The frame queue: per encoder thread two float frames (the
     * encoders convert them, so each costs 16 bytes a pixel, four times
     * the RGBA8 frame it becomes), its own buffer (the format is not
     * known here, so the larger, EXR's) and the deflate scratch it keeps
     * (output/png_write.c); and the drawing thread's buffer and scratch,
     * for the frames it encodes itself. */
    out->bytes[PFX_MEMORY_FRAMEBUFFER] = (e->blur_samples > 1 ? 3 : 2) * image * 16;
    /* --motion-vectors: the pass's own RGBA32F target and its float
     * read-back (render/motion_vectors.c, 16 bytes a pixel each), the
     * (dx, dy, coverage) floats (12) and the RGBA16 samples (8) of
     * jobs/motion_job.c; the sprites' ends, a chunk of (x, y, z, weight)
     * and its GL buffer; the simulation one frame ahead and its index
     * (jobs/motion_next.c). Its scale pass simulates before the render
     * and frees as much first, so it adds nothing to the peak. */
    if (what & PFX_ESTIMATE_MOTION_VECTORS)
        out->bytes[PFX_MEMORY_MOTION_VECTORS] =
            image * (16 + 16 + 12 + 8) + 2.0 * PFX_RENDER_CHUNK * 16 + pfx_mv_next_bytes(e);
    out->threads = pfx_frame_encoder_count(e->threads);
    const double scratch = (double)pfx_png_encoder_scratch_bytes(e->width, e->height);
    out->per_thread_bytes = pfx_frame_queue_bytes(e->width, e->height, 1, PFX_FRAME_EXR) + scratch;
    /* The drawing thread encodes too while every frame is queued, with a
     * buffer and a deflate scratch of its own. */
    const double caller =
        pfx_frame_queue_caller_bytes(e->width, e->height, PFX_FRAME_EXR) + scratch;
    out->bytes[PFX_MEMORY_ENCODER] = out->threads * out->per_thread_bytes + caller;
    *fixed += caller;
    /* light: { shadows: true } over a lit sprite: the sprite feed's volume
     * (render/shadow.h) and its 3D texture, with the driver's copy of the
     * upload. */
    if (pfx_sprites_shadowed(e)) {
        const double shadow = 3.0 * sizeof(pfx_shadow_volume);
        out->bytes[PFX_MEMORY_DRIVER] += shadow;
        *fixed += shadow;
    }
    for (size_t i = 0; i < e->emitter_count; i++)
        if (e->emitters[i].look.texture || e->emitters[i].look.normal_map) {
            out->bytes[PFX_MEMORY_DRIVER] += PFX_RENDER_DRIVER_BYTES_PER_TEXTURED;
            *fixed += PFX_RENDER_DRIVER_BYTES_PER_TEXTURED;
        }
    /* Textures: the decoded pixels and their copy in GL with mipmaps (4/3
     * of the base level, held as half floats or floats: twice the decoded
     * bytes, render/mipmap.h), once per file however many emitters name it (the
     * compiler reads a file once, the renderer uploads its pixels once),
     * and while they are uploaded the two levels render/mipmap.c holds at
     * a time (1/4 + 1/16 of the base level at most). */
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_image *maps[2] = {e->emitters[i].look.texture, e->emitters[i].look.normal_map};
        for (int k = 0; k < 2; k++) {
            if (!maps[k])
                continue;
            const double bytes = (double)maps[k]->width * maps[k]->height * 4 * (maps[k]->bits / 8);
            if (first_use(e, i, k, maps[k]->pixels))
                out->bytes[PFX_MEMORY_TEXTURES] += (1 + 2 * 4.0 / 3 + 5.0 / 16) * bytes;
        }
    }
    *fixed += out->bytes[PFX_MEMORY_FRAMEBUFFER] + out->bytes[PFX_MEMORY_TEXTURES];
}

/* Sub-emitter events a step raises at most: for each spawn of a parent,
 * with its pool full (capacity c) all the time, as for particle-steps.
 * A trail raises up to ceil(rate x dt) events a particle a step
 * (sim/spawn.c); births and deaths turn the pool over at most once per
 * shortest lifetime (c x dt / lifetime), or every step (c) where kill
 * rules or deflectors can end a life sooner; a particle on a
 * deflector hits at most once a step in the usual case (resting on a
 * floor), which is what is counted. A cycle of sub-emitters is counted
 * through the pools it fills: each emitter's capacity already holds the
 * children its parents send, within the budget. */
static double spawn_events_per_step(const pfx_effect *e, const pfx_emitter *em) {
    const double dt = 1.0 / e->sim_rate, c = em->capacity;
    const double shortest =
        em->kill || em->deflector_count ? dt : fmax(pfx_value_min(&em->lifetime), dt);
    double events = 0;
    for (size_t k = 0; k < em->spawn_count; k++) {
        const pfx_spawn *sp = &em->spawns[k];
        switch (sp->event) {
        case PFX_SPAWN_TRAIL:
            events += c * ceil(sp->rate * dt);
            break;
        case PFX_SPAWN_HIT:
            events += em->deflector_count ? c : 0;
            break;
        default:
            events += c * dt / shortest;
            break;
        }
    }
    return events;
}

void pfx_estimate_run(const pfx_effect *e, long first, long last, unsigned what,
                      pfx_estimate *out) {
    const bool render = what & PFX_ESTIMATE_RENDER;
    memset(out, 0, sizeof *out);
    if (last < first)
        last = first;
    /* The steps to the last frame: pfx_sim_frame runs from time 0 (prewarm
     * included) to the frame's time; a loop wraps back, so its last frame
     * is within one period after loop_start. */
    const double t_last =
        e->loop ? e->loop_start + (double)(last < e->loop_frames ? last : e->loop_frames) / e->fps
                : pfx_sim_frame_time(e, last);
    out->steps = ceil(t_last * e->sim_rate);
    const double frames = (double)(last - first + 1);
    const double image = (double)e->width * (double)e->height;
    double particles = 0, events = 0, pool_bytes = 0, queue_bytes = 0, fixed = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        /* A particle costs a step per substep its emitter's integrator
         * takes (a stiff field can ask for hundreds). */
        particles += (double)em->capacity * (em->motion ? em->motion->choice.steps : 1);
        events += spawn_events_per_step(e, em);
        pool_bytes += (double)pfx_pool_bytes(em, em->capacity); /* as sim.c allocates */
        queue_bytes += (double)pfx_spawn_queue_capacity(e, i) * sizeof(spawn_record);
        if (render) {
            const double side = sprite_side_px(e, em);
            out->sprites += frames * em->capacity;
            out->sprite_pixels += frames * em->capacity * fmin(image, fmax(1, side * side));
        }
    }
    queue_bytes += (double)pfx_sim_hit_buffer_bytes(e); /* the blocks' on_hit events */
    out->particle_steps = out->steps * particles;
    out->spawn_events = out->steps * events;
    out->work = out->particle_steps + out->spawn_events;
    /* Render and bake hold the stepping state and a view of it (sim.c);
     * a loop keeps frame 0's state too. Each has its spawn queues. */
    const double copies = e->loop ? 3 : 2;
    out->bytes[PFX_MEMORY_POOLS] = pool_bytes;
    out->bytes[PFX_MEMORY_VIEW] = pool_bytes;
    out->bytes[PFX_MEMORY_LOOP] = e->loop ? pool_bytes : 0;
    out->bytes[PFX_MEMORY_QUEUES] = copies * queue_bytes;
    if (render)
        estimate_drawing(e, what, image, out, &fixed);
    out->fixed_bytes = fixed;
    out->bound_bytes = 2 * pool_bytes + fixed + out->threads * out->per_thread_bytes;
    out->biggest = PFX_MEMORY_POOLS;
    for (int p = 0; p < PFX_MEMORY_PART_COUNT; p++) {
        out->total_bytes += out->bytes[p];
        if (out->bytes[p] > out->bytes[out->biggest])
            out->biggest = (pfx_memory_part)p;
    }
}

json_t *pfx_estimate_json(const pfx_estimate *est) {
    json_t *parts = json_object();
    for (int p = 0; p < PFX_MEMORY_PART_COUNT; p++)
        json_object_set_new(parts, pfx_memory_part_keys[p], json_real(est->bytes[p]));
    json_t *memory =
        json_pack("{s:f, s:o, s:i, s:f, s:f, s:f}", "total_bytes", est->total_bytes, "parts", parts,
                  "threads", est->threads, "per_thread_bytes", est->per_thread_bytes, "fixed_bytes",
                  est->fixed_bytes, "bound_bytes", est->bound_bytes);
    return json_pack("{s:{s:f, s:f, s:f, s:f, s:f}, s:o}", "work", "steps", est->steps,
                     "particle_steps", est->particle_steps, "spawn_events", est->spawn_events,
                     "sprites", est->sprites, "sprite_pixels", est->sprite_pixels, "memory",
                     memory);
}

double pfx_estimate_png_bytes(const pfx_effect *e, long frames) {
    const double rows = (4.0 * e->width + 1) * e->height;
    return (double)frames * (rows + floor(rows / 64) + 1024);
}

uint64_t pfx_memory_default_bound(void) {
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0)
        return 0;
    return (uint64_t)pages * (uint64_t)page / 2;
}

bool pfx_memory_parse(const char *text, uint64_t *bytes) {
    char *end;
    if (!text || !(*text >= '0' && *text <= '9'))
        return false;
    double v = strtod(text, &end);
    double unit = 1;
    switch (*end) {
    case 'k':
    case 'K':
        unit = 1024.0;
        break;
    case 'm':
    case 'M':
        unit = 1024.0 * 1024;
        break;
    case 'g':
    case 'G':
        unit = 1024.0 * 1024 * 1024;
        break;
    case 't':
    case 'T':
        unit = 1024.0 * 1024 * 1024 * 1024;
        break;
    }
    if (unit > 1) {
        end++;
        if (!strcmp(end, "iB") || !strcmp(end, "B"))
            end += strlen(end);
    } else if (!strcmp(end, "B")) {
        end++;
    }
    double n = v * unit;
    if (*end || !(n >= 1) || !(n < 1.8e19))
        return false;
    *bytes = (uint64_t)n;
    return true;
}

const char *pfx_memory_format(double n, char *buf, size_t size) {
    static const char *const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
    int u = 0;
    while (n >= 1024 && u < 5) {
        n /= 1024;
        u++;
    }
    if (u == 0)
        snprintf(buf, size, "%.0f bytes", n);
    else
        snprintf(buf, size, "%.3g %s", n, units[u]);
    return buf;
}

/* The key that sets the run's length, for a located warning: prewarm when
 * it is most of it, else duration, else the top of the file. */
static const pfx_node *work_node(const pfx_loaded *l) {
    const pfx_node *root = l->doc.root, *sim = pfx_node_get(root, "sim"), *n = NULL;
    if (l->effect->prewarm > l->effect->duration)
        n = pfx_node_get(sim, "prewarm");
    if (!n)
        n = pfx_node_get(root, "duration");
    if (!n)
        n = pfx_node_get(sim, "rate");
    return n ? n : root;
}

void pfx_estimate_warn(pfx_loaded *l, const pfx_estimate *est, uint64_t bound) {
    if (est->work > PFX_WORK_WARN_PARTICLE_STEPS && est->spawn_events > 0) {
        const pfx_node *n = work_node(l);
        pfx_diag_add(&l->diags, PFX_SEV_WARNING, n ? n->line : 0, n ? n->col : 0, n ? n->span : 0,
                     PFX_RULE_HEAVY_SIMULATION,
                     "the effect needs up to %.3g particle-steps and %.3g sub-emitter events to "
                     "its last frame (%.3g steps), over %.0e: hours or more of simulation (lower "
                     "'duration', 'prewarm', 'sim.rate', the sub-emitters' counts and trail rates, "
                     "or the particle budget)",
                     est->particle_steps, est->spawn_events, est->steps,
                     PFX_WORK_WARN_PARTICLE_STEPS);
    } else if (est->particle_steps > PFX_WORK_WARN_PARTICLE_STEPS) {
        const pfx_node *n = work_node(l);
        pfx_diag_add(&l->diags, PFX_SEV_WARNING, n ? n->line : 0, n ? n->col : 0, n ? n->span : 0,
                     PFX_RULE_HEAVY_SIMULATION,
                     "the effect needs up to %.3g particle-steps to its last frame (%.3g steps of "
                     "up to %.3g particles), over %.0e: hours or more of simulation (lower "
                     "'duration', 'prewarm', 'sim.rate' or the particle budget)",
                     est->particle_steps, est->steps,
                     est->steps > 0 ? est->particle_steps / est->steps : 0,
                     PFX_WORK_WARN_PARTICLE_STEPS);
    }
    if (bound && est->total_bytes > (double)bound) {
        char need[32], have[32], part[32];
        pfx_diag_add(&l->diags, PFX_SEV_WARNING, 0, 0, 0, PFX_RULE_MEMORY_BOUND,
                     "rendering needs up to %s of memory, over the bound of %s (--max-memory); "
                     "the most goes to the %s: %s",
                     pfx_memory_format(est->total_bytes, need, sizeof need),
                     pfx_memory_format((double)bound, have, sizeof have),
                     pfx_memory_part_names[est->biggest],
                     pfx_memory_format(est->bytes[est->biggest], part, sizeof part));
    }
}

bool pfx_estimate_fits(const pfx_effect *e, long first, long last, unsigned what,
                       uint64_t max_memory, pfx_diags *d) {
    pfx_estimate est;
    pfx_estimate_run(e, first, last, what, &est);
    if (!max_memory || est.total_bytes <= (double)max_memory)
        return true;
    char need[32], bound[32], part[32];
    pfx_diag_error(d, PFX_RULE_MEMORY_BOUND,
                   "this %s needs up to %s of memory, over the bound of %s (--max-memory, "
                   "default half of physical memory); the most goes to the %s: %s",
                   what & PFX_ESTIMATE_RENDER ? "render" : "bake",
                   pfx_memory_format(est.total_bytes, need, sizeof need),
                   pfx_memory_format((double)max_memory, bound, sizeof bound),
                   pfx_memory_part_names[est.biggest],
                   pfx_memory_format(est.bytes[est.biggest], part, sizeof part));
    return false;
}

void pfx_estimate_check(pfx_loaded *l, uint64_t bound) {
    if (!l->effect)
        return;
    pfx_estimate est;
    pfx_estimate_run(l->effect, 0, pfx_effect_frame_count(l->effect) - 1, PFX_ESTIMATE_RENDER,
                     &est);
    pfx_estimate_warn(l, &est, bound);
    pfx_overrides_claim(&l->overrides, &l->diags); /* a warning at a --set value */
}
