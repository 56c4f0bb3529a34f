/* The frame loop of `pfx render` and `pfx bench`: sim -> sprites -> draw ->
 * frame queue (whose encoders convert and write PNG or EXR), one frame at a
 * time. */
#include "jobs/render_job.h"

#include <stdio.h>
#include <stdlib.h>

#include "jobs/motion_job.h"
#include "output/frame_queue.h"
#include "render/sprites.h"

/* Frame NNNN of the job, or false when the name does not fit. */
static bool frame_path(const pfx_render_job *job, long frame, char *out, size_t size) {
    int n = snprintf(out, size, "%s/%s_%04ld.%s", job->dir, job->stem, frame,
                     pfx_frame_format_name(job->format));
    return n > 0 && (size_t)n < size;
}

/* draw_frame's answer when the job was cancelled part way: no error. */
#define CANCELLED (-2)

static bool cancelled(const pfx_render_job *job) { return job->cancel && atomic_load(job->cancel); }

/* Steps the simulation towards frame f one step at a time, a cancel
 * checked before each, up to a step short of the frame (pfx_sim_frame
 * takes the rest, so the steps are the same ones, and so are the bytes).
 * A new version in the live session so stops a stale simulation within a
 * step rather than at the end of a long run-up to the playhead. False
 * when cancelled. */
static bool run_towards(pfx_render_job *job, long f) {
    if (!job->cancel)
        return true;
    const double t = pfx_sim_frame_time(job->effect, f), rate = job->effect->sim_rate;
    while (!job->sim->failed && (double)(job->sim->step + 2) < t * rate) {
        if (cancelled(job))
            return false;
        pfx_sim_step(job->sim);
    }
    return !cancelled(job);
}

/* One frame's float image, into img (a frame of the queue). Without motion blur: the state at the
 * frame's time, drawn. With it: `samples` states at fixed times t_k = t + k / (samples - 1) x
 * shutter / fps (k = 0 .. samples - 1; the shutter opens at the frame's time), each drawn with
 * weight 1 / samples and summed in that order, so a moving particle leaves a streak |v| shutter /
 * fps long and its summed brightness is kept. The times depend only on the frame, so slices and
 * reruns give the same bytes. Returns the sprites drawn at the frame's own time, -1 on failure
 * (reported into d), or CANCELLED when job->cancel was set before the simulation reached the frame
 * or between two samples of its motion blur. */
static long draw_frame(pfx_render_job *job, long f, const pfx_render_settings *s, bool sort,
                       pfx_float_image *img, pfx_mv_frame *mv, pfx_diags *d) {
    const pfx_effect *e = job->effect;
    if (!run_towards(job, f))
        return CANCELLED;
    const pfx_sim *state = pfx_sim_frame(job->sim, job->view, f);
    if (job->sim->failed || job->view->failed)
        return -1; /* the sims reported into d */
    const pfx_sprite_source src = pfx_sprite_feed_source(&job->feed, state);
    const size_t n = src.count;
    if (!pfx_renderer_set_shadow(job->renderer, pfx_sprite_feed_shadow(&job->feed, state), d))
        return -1;
    pfx_ribbons ribbons = pfx_ribbons_build(job->ribbons, state);
    /* Motion vectors first: the frame's own sprites, before motion blur
     * moves the view on to later times. */
    char path[4600];
    if (job->motion && !pfx_mv_frame_path(job->dir, job->stem, f, path, sizeof path)) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE, "output path '%s/%s_mv_%04ld.png' is too long",
                       job->dir, job->stem, f);
        return -1;
    }
    if (job->motion &&
        !pfx_mv_frame_write(mv, job->renderer, e, s, &src, &job->feed, f, job->motion, path, d))
        return -1;
    if (e->blur_samples <= 1)
        return pfx_renderer_draw_float(job->renderer, &e->camera, s, &src, sort, ribbons, img, d)
                   ? (long)n
                   : -1;
    const int samples = e->blur_samples;
    const float weight = 1.0f / (float)samples;
    const double t0 = pfx_sim_frame_time(e, f), open = e->shutter / e->fps;
    if (!pfx_renderer_blur_begin(job->renderer, d))
        return -1;
    for (int k = 0; k < samples; k++) {
        if (k > 0 && cancelled(job))
            return CANCELLED;
        if (k > 0) {
            double t = t0 + open * k / (samples - 1);
            pfx_sim_run_to(job->sim, t);
            pfx_sim_view_at(job->sim, job->view, t);
            if (job->sim->failed || job->view->failed)
                return -1;
            const pfx_sprite_source at = pfx_sprite_feed_source(&job->feed, job->view);
            pfx_ribbons sub = pfx_ribbons_build(job->ribbons, job->view);
            if (!pfx_renderer_set_shadow(job->renderer,
                                         pfx_sprite_feed_shadow(&job->feed, job->view), d))
                return -1;
            if (!pfx_renderer_blur_add(job->renderer, &e->camera, s, &at, sort, sub, weight, d))
                return -1;
        } else if (!pfx_renderer_blur_add(job->renderer, &e->camera, s, &src, sort, ribbons, weight,
                                          d)) {
            return -1;
        }
    }
    pfx_renderer_blur_resolve_float(job->renderer, s, img);
    return (long)n;
}

bool pfx_render_job_run(pfx_render_job *job, pfx_diags *d) {
    const pfx_effect *e = job->effect;
    job->frames_done = 0;
    job->sprites_drawn = 0;
    job->sprite_count = 0;
    job->sim = pfx_sim_create(e, d);
    job->view = pfx_sim_create(e, d);
    job->ribbons = pfx_ribbons_create(e);
    if (!job->sim || !job->view || !pfx_sprite_feed_init(&job->feed, e) || !job->ribbons) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for %zu particles",
                       pfx_sprites_capacity(e));
        return false;
    }
    const int encoders = pfx_frame_encoder_count(job->threads > 0 ? job->threads : e->threads);
    const pfx_render_settings settings = pfx_sprites_settings(e);
    const pfx_tone tone = pfx_render_tone(&settings);
    pfx_frame_queue *q = pfx_frame_queue_create(e->width, e->height, encoders, job->format, &tone);
    if (!q) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot start the %s writer for %dx%d frames",
                       pfx_frame_format_name(job->format), e->width, e->height);
        return false;
    }
    pfx_frame_queue_set_fps(q, e->fps);
    pfx_material *materials = malloc((e->emitter_count + 1) * sizeof *materials);
    if (!materials) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for %zu materials",
                       e->emitter_count);
        pfx_frame_queue_finish(q, NULL);
        return false;
    }
    pfx_sprites_materials(e, materials);
    bool failed = !pfx_renderer_set_materials(job->renderer, materials, e->emitter_count, d);
    free(materials);
    const bool sort = pfx_sprites_need_sort(e);
    pfx_mv_frame mv = {NULL, NULL, NULL};
    if (!failed && job->motion)
        failed = !pfx_mv_frame_init(&mv, e, d);
    /* Making each chunk's sprites from the pools, and the depth sort, run
     * on the effect's threads (--threads); neither result depends on how
     * many, so where they cannot start this thread does the work and the
     * frames are the same. */
    pfx_renderer_set_threads(job->renderer, e->threads, NULL);
    char name[4600];
    const long step = job->step > 1 ? job->step : 1;
    for (long f = job->first; !failed && f <= job->last && !pfx_frame_queue_failed(q); f += step) {
        if (cancelled(job))
            break;
        long drawn = draw_frame(job, f, &settings, sort, pfx_frame_queue_buffer(q), &mv, d);
        if (drawn == CANCELLED)
            break;
        failed = drawn < 0;
        size_t n = failed ? 0 : (size_t)drawn;
        if (!failed && !frame_path(job, f, name, sizeof name)) {
            pfx_diag_error(d, PFX_RULE_TOO_LARGE, "output path '%s/%s_%04ld.%s' is too long",
                           job->dir, job->stem, f, pfx_frame_format_name(job->format));
            failed = true;
        }
        if (failed)
            break;
        pfx_frame_queue_submit(q, name);
        job->frames_done++;
        job->sprites_drawn += n;
        job->sprite_count = n;
        if (job->on_frame)
            job->on_frame(job->on_frame_ctx, f, n);
        if (job->progress)
            fprintf(stderr, "\rpfx: frame %ld of %ld-%ld (%zu particles)   ", f, job->first,
                    job->last, n);
    }
    if (job->progress)
        fputc('\n', stderr);
    /* The writer's own failure (a full disk, a vanished directory) is
     * reported when it is what stopped the loop. */
    bool written = pfx_frame_queue_finish(q, failed ? NULL : d);
    pfx_mv_frame_free(&mv);
    return !failed && written;
}

void pfx_render_job_free(pfx_render_job *job) {
    pfx_sprite_feed_free(&job->feed);
    pfx_ribbons_destroy(job->ribbons);
    job->ribbons = NULL;
    pfx_sim_destroy(job->view);
    pfx_sim_destroy(job->sim);
    job->sim = job->view = NULL;
}
