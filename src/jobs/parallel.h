/* A render job's frames on several threads: the range cut into contiguous
 * chunks (jobs/slice.h), each with its own renderer, simulation and PNG
 * writer. Every frame depends only on its time, so the files are byte for
 * byte those of one thread. */
#ifndef PFX_JOBS_PARALLEL_H
#define PFX_JOBS_PARALLEL_H

#include <stdbool.h>

#include "base/diag.h"
#include "jobs/render_job.h"
#include "render/render.h"

/* Runs job (effect, dir, stem, first, last; its renderer is not used) as
 * `threads` chunks, each on a thread with a renderer of `kind` made there.
 * Each chunk simulates from the start: the simulation up to a chunk's
 * first frame is repeated, the price of the parallel drawing. On return
 * job->frames_done counts every frame written and job->sim is the last
 * chunk's (for the dropped-births note). False with the failures in d, in
 * frame order; frames written before a failure stay. */
bool pfx_render_job_run_parallel(pfx_render_job *job, pfx_renderer_kind kind, int threads,
                                 pfx_diags *d);

#endif
