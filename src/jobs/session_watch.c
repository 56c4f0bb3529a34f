/* The live session's watcher: one thread reading inotify events for the
 * effect file and what it reads (textures, meshes), which recompiles the
 * session on a change. It reads nothing else and renders nothing. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <unistd.h>

#include "jobs/manifest.h"
#include "jobs/session_internal.h"

/* After an event, the watcher waits this long for more before it
 * recompiles, so that a save written in several steps (truncate, write,
 * rename) compiles once. */
#define SETTLE_MS 15

#define WATCH_EVENTS (IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE | IN_MOVED_FROM)

/* Adds path's directory to the watch and path's name to the list. */
static void watch_path(void *ctx, const char *path) {
    pfx_session *s = ctx;
    char dir[PATH_MAX];
    const char *slash = strrchr(path, '/');
    const char *name = slash ? slash + 1 : path;
    if (slash) {
        size_t n = (size_t)(slash - path);
        if (n >= sizeof dir)
            return;
        memcpy(dir, path, n);
        dir[n ? n : 1] = 0;
        if (!n)
            dir[0] = '/';
    } else {
        strcpy(dir, ".");
    }
    if (s->watched_count >= PFX_SESSION_MAX_WATCHED || strlen(name) >= sizeof s->watched[0].name)
        return;
    int wd = inotify_add_watch(s->inotify_fd, dir, WATCH_EVENTS);
    if (wd < 0)
        return;
    for (size_t i = 0; i < s->watched_count; i++)
        if (s->watched[i].wd == wd && !strcmp(s->watched[i].name, name))
            return;
    session_watched *w = &s->watched[s->watched_count++];
    w->wd = wd;
    strcpy(w->name, name);
}

void pfx_session_watch_inputs(pfx_session *s, const pfx_effect *e) {
    if (s->inotify_fd < 0)
        return;
    pthread_mutex_lock(&s->watch_mu);
    /* Directory watches stay (inotify gives the same one for the same
     * directory); the list of names is remade. */
    s->watched_count = 0;
    watch_path(s, s->o.path);
    if (e)
        pfx_effect_each_input(e, watch_path, s);
    pthread_mutex_unlock(&s->watch_mu);
}

/* True when the event names a watched file. */
static bool is_watched(pfx_session *s, const struct inotify_event *ev) {
    bool hit = false;
    pthread_mutex_lock(&s->watch_mu);
    for (size_t i = 0; i < s->watched_count && !hit; i++)
        hit = s->watched[i].wd == ev->wd && ev->len && !strcmp(s->watched[i].name, ev->name);
    pthread_mutex_unlock(&s->watch_mu);
    return hit;
}

/* Reads the events waiting; true when one names a watched file. */
static bool drain(pfx_session *s) {
    char buf[16384] __attribute__((aligned(__alignof__(struct inotify_event))));
    bool changed = false;
    for (;;) {
        ssize_t n = read(s->inotify_fd, buf, sizeof buf);
        if (n <= 0)
            return changed;
        for (char *p = buf; p < buf + n;) {
            const struct inotify_event *ev = (const struct inotify_event *)p;
            changed = changed || is_watched(s, ev);
            p += sizeof *ev + ev->len;
        }
    }
}

static void *watch_main(void *arg) {
    pfx_session *s = arg;
    struct pollfd fds[2] = {{s->inotify_fd, POLLIN, 0}, {s->stop_pipe[0], POLLIN, 0}};
    for (;;) {
        if (poll(fds, 2, -1) < 0 && errno != EINTR)
            break;
        if (fds[1].revents)
            break;
        if (!(fds[0].revents & POLLIN) || !drain(s))
            continue;
        /* Let the rest of a multi-step save arrive, then compile once. */
        while (poll(fds, 1, SETTLE_MS) > 0 && (fds[0].revents & POLLIN))
            drain(s);
        pfx_session_reload(s);
    }
    return NULL;
}

bool pfx_session_watch_start(pfx_session *s, pfx_diags *d) {
    s->inotify_fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (s->inotify_fd < 0 || pipe(s->stop_pipe)) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot watch '%s': %s", s->o.path,
                       strerror(errno));
        return false;
    }
    fcntl(s->stop_pipe[0], F_SETFD, FD_CLOEXEC);
    fcntl(s->stop_pipe[1], F_SETFD, FD_CLOEXEC);
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
        ssize_t w = write(s->stop_pipe[1], "x", 1);
        (void)w;
        pthread_join(s->watcher, NULL);
        s->has_watcher = false;
    }
    if (s->inotify_fd >= 0)
        close(s->inotify_fd);
    for (int i = 0; i < 2; i++)
        if (s->stop_pipe[i] >= 0)
            close(s->stop_pipe[i]);
    s->inotify_fd = s->stop_pipe[0] = s->stop_pipe[1] = -1;
}
