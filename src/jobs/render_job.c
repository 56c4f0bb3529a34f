/* The frame loop of `pfx render` and `pfx bench`: sim -> sprites -> draw ->
 * PNG queue, one frame at a time. */
#include "jobs/render_job.h"

#include <stdio.h>
#include <stdlib.h>

#include "output/png_write.h"
#include "render/sprites.h"

/* Frame NNNN of the job, or false when the name does not fit. */
static bool frame_path(const pfx_render_job *job, long frame, char *out, size_t size) {
    int n = snprintf(out, size, "%s/%s_%04ld.png", job->dir, job->stem, frame);
    return n > 0 && (size_t)n < size;
}

bool pfx_render_job_run(pfx_render_job *job, pfx_diags *d) {
    const pfx_effect *e = job->effect;
    job->frames_done = 0;
    job->sprites_drawn = 0;
    job->sprite_count = 0;
    job->sim = pfx_sim_create(e, d);
    job->view = pfx_sim_create(e, d);
    job->sprites = malloc((pfx_sprites_capacity(e) + 1) * sizeof *job->sprites);
    if (!job->sim || !job->view || !job->sprites) {
        pfx_diag_error(d, "out of memory for %zu particles", pfx_sprites_capacity(e));
        return false;
    }
    pfx_png_queue *q = pfx_png_queue_create(e->width, e->height);
    if (!q) {
        pfx_diag_error(d, "cannot start the PNG writer");
        return false;
    }
    const bool sort = pfx_sprites_need_sort(e);
    bool failed = false; /* here, not in the writer */
    char name[4600];
    for (long f = job->first; f <= job->last && !pfx_png_queue_failed(q); f++) {
        const pfx_sim *state = pfx_sim_frame(job->sim, job->view, f);
        failed = job->sim->failed || job->view->failed; /* the sims reported into d */
        size_t n = failed ? 0 : pfx_sprites_build(state, job->sprites);
        uint8_t *pixels = pfx_png_queue_buffer(q);
        failed = failed || !pfx_renderer_draw(job->renderer, &e->camera, e->background,
                                              job->sprites, n, sort, pixels, d);
        if (!failed && !frame_path(job, f, name, sizeof name)) {
            pfx_diag_error(d, "output path '%s/%s_%04ld.png' is too long", job->dir, job->stem, f);
            failed = true;
        }
        if (failed)
            break;
        pfx_png_queue_submit(q, name);
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
    bool written = pfx_png_queue_finish(q, failed ? NULL : d);
    return !failed && written;
}

void pfx_render_job_free(pfx_render_job *job) {
    free(job->sprites);
    pfx_sim_destroy(job->view);
    pfx_sim_destroy(job->sim);
    job->sprites = NULL;
    job->sim = job->view = NULL;
}
