/* pfx info FILE: what the compiled model holds and what a render of it
 * will cost, as text or one JSON object. */
#include "commands/commands.h"

#include "base/json_text.h"
#include "jobs/estimate.h"
#include "render/sprites.h"

/* What the estimate counts: a render, and its motion-vector pass when
 * --motion-vectors is given. */
static unsigned estimate_flags(const pfx_cli *o) {
    return PFX_ESTIMATE_RENDER | (o->motion_vectors ? PFX_ESTIMATE_MOTION_VECTORS : 0);
}

/* The estimate of a whole render, every frame, before anything is allocated:
 * work as particle-steps and memory by part (jobs/estimate.c). */
static void print_estimate(const pfx_effect *e, const pfx_cli *o) {
    pfx_estimate est;
    char b[32];
    pfx_estimate_run(e, 0, pfx_effect_frame_count(e) - 1, estimate_flags(o), &est);
    printf("  work to the last frame, at most: %.4g steps, %.4g particle-steps, %.4g sprites "
           "covering %.4g pixels\n",
           est.steps, est.particle_steps, est.sprites, est.sprite_pixels);
    if (est.spawn_events > 0)
        printf("  sub-emitter events to the last frame, at most: %.4g (work %.4g)\n",
               est.spawn_events, est.work);
    printf("  memory of a render, at most %s:\n", pfx_memory_format(est.total_bytes, b, sizeof b));
    for (int p = 0; p < PFX_MEMORY_PART_COUNT; p++)
        if (est.bytes[p] > 0)
            printf("    %s: %s%s\n", pfx_memory_part_names[p],
                   pfx_memory_format(est.bytes[p], b, sizeof b),
                   p == (int)est.biggest ? " (the most)" : "");
    char c[32], f[32];
    printf("  2 x pools + %s fixed + %d threads x %s = %s: %s\n",
           pfx_memory_format(est.fixed_bytes, f, sizeof f), est.threads,
           pfx_memory_format(est.per_thread_bytes, b, sizeof b),
           pfx_memory_format(est.bound_bytes, c, sizeof c),
           est.total_bytes <= est.bound_bytes
               ? "the estimate is within it"
               : "the estimate is over it (parts that grow with the particles beyond the "
                 "pools: depth sort, loop, spawn queues, ribbons)");
}

/* pfx info --format json: the figures of the text form that scripts use
 * (sizes, pools, the estimate) as one JSON object on standard output. */
static int print_info_json(const pfx_effect *e, const pfx_cli *o) {
    json_t *emitters = json_array();
    double bytes = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        const size_t bpp = pfx_sim_bytes_per_particle(e, i);
        bytes += (double)em->capacity * (double)bpp;
        json_array_append_new(emitters, json_pack("{s:s, s:I, s:I}", "name", em->name, "capacity",
                                                  (json_int_t)em->capacity, "bytes_per_particle",
                                                  (json_int_t)bpp));
    }
    pfx_estimate est;
    pfx_estimate_run(e, 0, pfx_effect_frame_count(e) - 1, estimate_flags(o), &est);
    json_t *root = json_pack(
        "{s:o, s:I, s:i, s:i, s:o, s:f, s:b}", "effect", pfx_json_bytes(e->path), "frames",
        (json_int_t)pfx_effect_frame_count(e), "width", e->width, "height", e->height, "emitters",
        emitters, "pool_bytes", bytes, "depth_sort", pfx_sprites_need_sort(e));
    json_t *estimate = pfx_estimate_json(&est);
    if (root && estimate) {
        json_object_update(root, estimate);
        if (o->max_memory)
            json_object_set_new(root, "max_memory_bytes", json_real((double)o->max_memory));
    }
    json_decref(estimate);
    /* A path that is not UTF-8 keeps its bytes in "effect_base64". */
    json_t *escaped = root ? pfx_json_escaped(root) : NULL;
    char *text = escaped ? json_dumps(escaped, JSON_INDENT(2) | JSON_PRESERVE_ORDER) : NULL;
    json_decref(escaped);
    json_decref(root);
    if (!text) {
        fprintf(stderr, "pfx: out of memory\n");
        return EXIT_INVALID;
    }
    printf("%s\n", text);
    free(text);
    return 0;
}

/* One emitter of pfx info's text: shape, rate, pool, integrator,
 * deflectors, sub-emitters and kill rules. */
static void print_emitter(const pfx_effect *e, const pfx_emitter *em, size_t bpp) {
    printf("    %s: %s shape, %s rate up to %g particles/s%s%s, lifetime up to %g s, %s "
           "blend\n",
           em->name, pfx_kind_name(pfx_shape_names, (int)em->shape.type),
           pfx_kind_name(pfx_rate_kind_names, (int)em->rate_kind), pfx_emitter_max_rate(em),
           em->burst_count ? " plus bursts" : "", em->spawned_peak > 0 ? " plus sub-emitters" : "",
           em->max_lifetime, em->blend == PFX_BLEND_ADD ? "additive" : "alpha");
    printf("      pool %u particles x %zu bytes = %zu bytes%s\n", em->capacity, bpp,
           em->capacity * bpp, em->saturates ? " (saturates: cut by the budget)" : "");
    if (em->motion)
        printf("      integrator: %s\n", em->motion->choice.why);
    else if (em->accel[0] == 0 && em->accel[1] == 0 && em->accel[2] == 0)
        printf("      integrator: exact (no force: straight lines)\n");
    else
        printf("      integrator: exact (only gravity, [%g, %g, %g] m/s^2%s: the "
               "constant-acceleration closed form, exact at any step)\n",
               em->accel[0], em->accel[1], em->accel[2],
               em->gravity_scale.dist == PFX_DIST_CONST ? "" : " x gravity_scale");
    if (em->deflector_count) {
        printf("      deflectors:");
        for (size_t d = 0; d < em->deflector_count; d++)
            printf(" %s", em->deflectors[d].name);
        printf(" (swept exact hits; %zu scratch bytes per particle)\n",
               pfx_sim_scratch_bytes_per_particle(e, (size_t)(em - e->emitters)));
    }
    for (size_t k = 0; k < em->spawn_count; k++)
        printf("      %s -> %s\n", pfx_kind_name(pfx_spawn_event_names, (int)em->spawns[k].event),
               e->emitters[em->spawns[k].target].name);
    if (em->kill)
        printf("      kill rules: %zu%s\n", em->kill->count,
               em->kill->bounds == PFX_BOUNDS_WRAP   ? ", wrapping bounds"
               : em->kill->bounds == PFX_BOUNDS_KILL ? ", killing bounds"
                                                     : "");
}

int pfx_cmd_info(const char *const *operands, int count, const pfx_cli *o) {
    if (count != 1)
        return pfx_cli_usage_error("%s", "info takes one FILE");
    pfx_loaded l;
    pfx_effect *e = pfx_cli_load(&l, operands[0], o);
    if (!e) {
        pfx_loaded_free(&l);
        return EXIT_INVALID;
    }
    if (o->json) {
        int status = print_info_json(e, o);
        pfx_loaded_free(&l);
        return status;
    }
    double steps_per_frame = e->sim_rate / e->fps;
    printf("effect %s\n", e->path);
    printf("  frames %ld (%g s at %g fps), image %dx%d\n", pfx_effect_frame_count(e), e->duration,
           e->fps, e->width, e->height);
    printf("  simulation %g steps/s (dt %.6g s), %.4g steps per frame, prewarm %g s, seed %llu\n",
           e->sim_rate, 1.0 / e->sim_rate, steps_per_frame, e->prewarm,
           (unsigned long long)e->seed);
    if (e->loop)
        printf("  loops every %g s (%ld frames), shown from t = %g s when every particle alive "
               "is periodic\n",
               e->duration, e->loop_frames, e->loop_start);
    printf("  forces %zu\n", e->force_count);
    for (size_t i = 0; i < e->force_count; i++)
        printf("    %s: %s%s\n", e->forces[i].name,
               pfx_kind_name(pfx_force_names, (int)e->forces[i].spec.kind),
               e->forces[i].spec.region.kind ? " (in a region)" : "");
    size_t total = 0, bytes = 0;
    printf("  emitters %zu\n", e->emitter_count);
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        size_t bpp = pfx_sim_bytes_per_particle(e, i);
        print_emitter(e, em, bpp);
        total += em->capacity;
        bytes += em->capacity * bpp;
    }
    printf("  particles at most %zu of the %llu budget, %zu bytes\n", total,
           (unsigned long long)e->max_particles, bytes);
    printf("  depth sort: %s\n", pfx_sprites_need_sort(e)
                                     ? "yes (a sprite emitter blends by alpha)"
                                     : "no (no sprite emitter blends by alpha)");
    print_estimate(e, o);
    if (o->max_memory) {
        char b[32];
        printf("  memory bound %s (--max-memory)\n",
               pfx_memory_format((double)o->max_memory, b, sizeof b));
    }
    pfx_loaded_free(&l);
    return 0;
}
