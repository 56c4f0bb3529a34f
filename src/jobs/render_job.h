/* Rendering a frame range to a PNG or EXR sequence: the one frame loop that
 * `pfx render` runs and `pfx bench` times. */
#ifndef PFX_JOBS_RENDER_JOB_H
#define PFX_JOBS_RENDER_JOB_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "base/diag.h"
#include "model/effect.h"
#include "output/frame_queue.h"
#include "render/render.h"
#include "render/sprites.h"
#include "sim/sim.h"

typedef struct pfx_render_job {
    /* In: what to draw and where. Frames first..last (inclusive) go to
     * dir/stem_NNNN.png (or .exr, as format says; zero is PNG); dir must
     * exist. */
    const pfx_effect *effect;
    pfx_renderer *renderer; /* the caller's; a renderer that started */
    const char *dir, *stem;
    long first, last;
    long step; /* every step-th frame from first (last - first a multiple); 0 or 1: all */
    pfx_frame_format format;
    bool progress; /* a "\rpfx: frame ..." line on stderr as frames go */
    /* Called after each frame is drawn and handed to the frame writer, from
     * the thread running the job (see jobs/progress.h), or NULL. */
    void (*on_frame)(void *ctx, long frame, size_t particles);
    void *on_frame_ctx;
    /* --motion-vectors: also dir/stem_mv_NNNN.png, encoded by this (NULL:
     * none, and no motion pass is drawn). */
    const struct pfx_mv_meta *motion;
    int threads; /* encoder threads; 0: the effect's threads (--threads), else one
                    per online core */
    /* When set (by another thread), the job stops with no error, within a
     * simulation step or a motion-blur sample, the frame being drawn left
     * unwritten: frames_done says how far it got. NULL: never.
     * The live session (jobs/session.c) cancels stale work with it. */
    const atomic_bool *cancel;

    /* Out, valid after pfx_render_job_run until pfx_render_job_free. */
    long frames_done;     /* frames drawn and handed to the writer */
    size_t sprites_drawn; /* summed over those frames */
    size_t sprite_count;  /* the last frame's */
    pfx_sprite_feed feed; /* the frame's sprites, made as the renderer reads them */
    pfx_sim *sim;         /* the simulation at the last frame (per-emitter drop counts) */
    pfx_sim *view;
    struct pfx_ribbon_buffer *ribbons; /* the frame's ribbon triangles */
} pfx_render_job;

/* Simulates, draws and writes every frame of the job, a pool of
 * encoders overlapping the next frames' work. Each file is whole or absent. Returns
 * false with the failure in d (which emitter, particle and time when the
 * simulation blew up; the path and errno when a file cannot be written);
 * frames written before a failure stay. */
bool pfx_render_job_run(pfx_render_job *job, pfx_diags *d);

/* Frees what run allocated (the sims and the sprite feed), not the
 * renderer. */
void pfx_render_job_free(pfx_render_job *job);

#endif
