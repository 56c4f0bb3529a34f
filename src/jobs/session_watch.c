/* The live session's watcher: a thread waiting on a file watch
 * (jobs/file_watch.c) over the effect file and what it reads, which
 * recompiles the session on each change. */
#include "jobs/file_watch.h"
#include "jobs/session_internal.h"

static void *watch_main(void *arg) {
    pfx_session *s = arg;
    while (pfx_file_watch_wait(s->watch))
        pfx_session_reload(s);
    return NULL;
}

void pfx_session_watch_inputs(pfx_session *s, const pfx_effect *e) {
    if (!s->watch)
        return;
    pfx_file_watch_reset(s->watch);
    pfx_file_watch_add(s->watch, s->o.path);
    if (e)
        pfx_file_watch_add_effect(s->watch, e);
}

bool pfx_session_watch_start(pfx_session *s, pfx_diags *d) {
    s->watch = pfx_file_watch_create(d);
    if (!s->watch)
        return false;
    /* The file alone until a good compile names what it reads. */
    pfx_session_watch_inputs(s, NULL);
    if (pthread_create(&s->watcher, NULL, watch_main, s)) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "cannot start the file watcher");
        return false;
    }
    s->has_watcher = true;
    return true;
}

void pfx_session_watch_stop(pfx_session *s) {
    if (s->has_watcher) {
        pfx_file_watch_stop(s->watch);
        pthread_join(s->watcher, NULL);
        s->has_watcher = false;
    }
    pfx_file_watch_destroy(s->watch);
    s->watch = NULL;
}
