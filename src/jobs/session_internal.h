/* The live session's state, shared by session.c (models, frames, the
 * render worker) and session_watch.c (the inotify watcher); no other file
 * includes it. */
#ifndef PFX_JOBS_SESSION_INTERNAL_H
#define PFX_JOBS_SESSION_INTERNAL_H

#include <jansson.h>
#include <pthread.h>
#include <stdatomic.h>

#include "jobs/session.h"
#include "model/effect.h"

struct session_model;

struct pfx_session {
    pfx_session_options o;
    pthread_mutex_t mu; /* guards everything below but the worker's renderer */
    pthread_cond_t work_cv, news_cv, frame_cv;
    struct session_model *good; /* the last good compile; NULL before one */
    json_t *diag_json;          /* the latest compile's diagnostics */
    char *diag_text;            /* the same as `pfx validate` prints them */
    unsigned version;           /* raised by each good compile */
    unsigned news;              /* raised by each compile, good or not, and a render failure */
    long playhead;
    atomic_bool cancel;         /* the worker's job stops after its frame */
    struct session_model *busy; /* what the worker renders now, or NULL */
    long busy_first, busy_last;
    bool stopping;
    pthread_t worker;
    bool has_worker;
    pfx_renderer *renderer; /* the worker's alone */
    int renderer_w, renderer_h;
    char scratch[4096]; /* where the render job writes frames before they are read in */
    /* The watcher (session_watch.c). */
    pthread_t watcher;
    bool has_watcher;
    struct pfx_file_watch *watch;
};

/* Starts the watcher thread on the file (and, after each good compile,
 * what it reads). False with the reason in d. */
bool pfx_session_watch_start(pfx_session *s, pfx_diags *d);
/* Watches the effect file and every input of e from now on. */
void pfx_session_watch_inputs(pfx_session *s, const pfx_effect *e);
/* Stops and joins the watcher; safe when it never started. */
void pfx_session_watch_stop(pfx_session *s);

#endif
