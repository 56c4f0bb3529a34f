/* The threads of jobs/parallel.h: one pthread per chunk, each running the
 * ordinary frame loop (render_job.c) on its own renderer. Diagnostics are
 * collected per chunk and appended in chunk order, so the report does not
 * depend on which thread finished first. */
#include "jobs/parallel.h"

#include <pthread.h>
#include <stdlib.h>
#include <unistd.h>

#include "jobs/slice.h"

typedef struct chunk {
    pfx_render_job job;
    pfx_renderer_kind kind;
    pfx_diags d;
    bool ok;
} chunk;

static void *run_chunk(void *arg) {
    chunk *c = arg;
    c->job.renderer =
        pfx_renderer_create(c->kind, c->job.effect->width, c->job.effect->height, &c->d);
    c->ok = c->job.renderer && pfx_render_job_run(&c->job, &c->d);
    pfx_renderer_destroy(c->job.renderer);
    c->job.renderer = NULL;
    return NULL;
}

bool pfx_render_job_run_parallel(pfx_render_job *job, pfx_renderer_kind kind, int threads,
                                 pfx_diags *d) {
    const long step = job->step > 1 ? job->step : 1;
    long frames = (job->last - job->first) / step + 1;
    if (threads > frames)
        threads = (int)frames;
    if (threads < 1)
        threads = 1;
    chunk *cs = calloc((size_t)threads, sizeof *cs);
    pthread_t *ts = calloc((size_t)threads, sizeof *ts);
    bool *started = calloc((size_t)threads, sizeof *started);
    if (!cs || !ts || !started) {
        free(cs);
        free(ts);
        free(started);
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return false;
    }
    /* The frame encoders (render_job.h's threads): the cores shared among the
     * chunks, rather than every chunk starting one per core. */
    int encoders = job->threads;
    if (encoders <= 0) {
        long cores = sysconf(_SC_NPROCESSORS_ONLN);
        encoders = cores > threads ? (int)(cores / threads) : 1;
    }
    for (int i = 0; i < threads; i++) {
        chunk *c = &cs[i];
        c->job = *job;
        c->job.threads = encoders;
        c->job.progress = false;
        c->job.renderer = NULL;
        c->kind = kind;
        pfx_diags_init_runtime(&c->d);
        pfx_slice_range_step(job->first, job->last, step, i, threads, &c->job.first, &c->job.last);
        started[i] = pthread_create(&ts[i], NULL, run_chunk, c) == 0;
        if (!started[i])
            run_chunk(c); /* no thread to be had: this one does the work */
    }
    bool ok = true;
    job->frames_done = 0;
    job->sprites_drawn = 0;
    for (int i = 0; i < threads; i++) {
        chunk *c = &cs[i];
        if (started[i])
            pthread_join(ts[i], NULL);
        ok = ok && c->ok;
        job->frames_done += c->job.frames_done;
        job->sprites_drawn += c->job.sprites_drawn;
        pfx_diags_append(d, &c->d); /* frees c->d */
        if (i == threads - 1) {
            /* The last chunk's state is the job's: its sims end at the last frame. */
            job->sim = c->job.sim;
            job->view = c->job.view;
            job->feed = c->job.feed;
            job->ribbons = c->job.ribbons;
            job->sprite_count = c->job.sprite_count;
        } else {
            pfx_render_job_free(&c->job);
        }
    }
    free(cs);
    free(ts);
    free(started);
    return ok;
}
