/* --progress json: one JSON object per line on a stream (stderr) for farm
 * managers and build tools, written through jansson. Safe to call from
 * several render threads at once. */
#ifndef PFX_JOBS_PROGRESS_H
#define PFX_JOBS_PROGRESS_H

#include <pthread.h>
#include <stddef.h>
#include <stdio.h>

typedef struct pfx_progress {
    pthread_mutex_t lock;
    FILE *out;
    const char *effect; /* the file's path as given */
    long total, done;
    double start; /* monotonic seconds */
} pfx_progress;

/* Starts the report of `effect`, `total` frames, on out. */
void pfx_progress_init(pfx_progress *p, FILE *out, const char *effect, long total);
/* A render_job on_frame callback (ctx: the pfx_progress): writes
 * {"event":"frame","effect":...,"frame":F,"done":D,"total":T,
 *  "particles":N,"elapsed_s":S}. */
void pfx_progress_frame(void *ctx, long frame, size_t particles);
/* The last line: {"event":"done","effect":...,"done":D,"total":T,
 * "status":S,"elapsed_s":S}. Frees nothing the caller owns. */
void pfx_progress_finish(pfx_progress *p, int status);

#endif
