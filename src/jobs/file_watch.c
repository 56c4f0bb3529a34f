/* Waiting for files to change: one inotify descriptor watching the
 * directories of the files, a list of the names that count, and a pipe
 * that ends the wait. It reads no file and knows no effect beyond its
 * list of inputs. */
#include "jobs/file_watch.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <unistd.h>

#include "jobs/manifest.h"

/* After an event, the wait goes on this long for more, so that a save
 * written in several steps (truncate, write, rename) counts once. */
#define SETTLE_MS 15
#define MAX_WATCHED 256
#define WATCH_EVENTS (IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE | IN_MOVED_FROM)

typedef struct watched {
    int wd; /* the directory's watch */
    char name[256];
} watched;

struct pfx_file_watch {
    int fd, stop[2];
    pthread_mutex_t mu; /* guards the list */
    watched list[MAX_WATCHED];
    size_t count;
};

pfx_file_watch *pfx_file_watch_create(pfx_diags *d) {
    pfx_file_watch *w = calloc(1, sizeof *w);
    if (!w) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for a file watch");
        return NULL;
    }
    pthread_mutex_init(&w->mu, NULL);
    w->fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    w->stop[0] = w->stop[1] = -1;
    if (w->fd < 0 || pipe(w->stop)) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot watch files: %s", strerror(errno));
        pfx_file_watch_destroy(w);
        return NULL;
    }
    for (int i = 0; i < 2; i++)
        fcntl(w->stop[i], F_SETFD, FD_CLOEXEC);
    return w;
}

void pfx_file_watch_destroy(pfx_file_watch *w) {
    if (!w)
        return;
    if (w->fd >= 0)
        close(w->fd);
    for (int i = 0; i < 2; i++)
        if (w->stop[i] >= 0)
            close(w->stop[i]);
    pthread_mutex_destroy(&w->mu);
    free(w);
}

void pfx_file_watch_reset(pfx_file_watch *w) {
    /* Directory watches stay (inotify gives the same one for the same
     * directory again); the names are remade. */
    pthread_mutex_lock(&w->mu);
    w->count = 0;
    pthread_mutex_unlock(&w->mu);
}

void pfx_file_watch_add(pfx_file_watch *w, const char *path) {
    char dir[PATH_MAX];
    const char *slash = strrchr(path, '/');
    const char *name = slash ? slash + 1 : path;
    if (!slash)
        strcpy(dir, ".");
    else if (slash == path)
        strcpy(dir, "/");
    else if ((size_t)(slash - path) < sizeof dir)
        memcpy(dir, path, (size_t)(slash - path)), dir[slash - path] = 0;
    else
        return;
    if (strlen(name) >= sizeof w->list[0].name)
        return;
    int wd = inotify_add_watch(w->fd, dir, WATCH_EVENTS);
    if (wd < 0)
        return;
    pthread_mutex_lock(&w->mu);
    bool known = false;
    for (size_t i = 0; i < w->count && !known; i++)
        known = w->list[i].wd == wd && !strcmp(w->list[i].name, name);
    if (!known && w->count < MAX_WATCHED) {
        w->list[w->count].wd = wd;
        strcpy(w->list[w->count++].name, name);
    }
    pthread_mutex_unlock(&w->mu);
}

static void add_input(void *ctx, const char *path) { pfx_file_watch_add(ctx, path); }

void pfx_file_watch_add_effect(pfx_file_watch *w, const pfx_effect *e) {
    pfx_effect_each_input(e, add_input, w);
}

/* True when the event names a watched file. */
static bool is_watched(pfx_file_watch *w, const struct inotify_event *ev) {
    bool hit = false;
    pthread_mutex_lock(&w->mu);
    for (size_t i = 0; i < w->count && !hit; i++)
        hit = w->list[i].wd == ev->wd && ev->len && !strcmp(w->list[i].name, ev->name);
    pthread_mutex_unlock(&w->mu);
    return hit;
}

/* Reads the events waiting; true when one names a watched file. */
static bool drain(pfx_file_watch *w) {
    char buf[16384] __attribute__((aligned(__alignof__(struct inotify_event))));
    bool changed = false;
    for (;;) {
        ssize_t n = read(w->fd, buf, sizeof buf);
        if (n <= 0)
            return changed;
        for (char *p = buf; p < buf + n;) {
            const struct inotify_event *ev = (const struct inotify_event *)p;
            changed = is_watched(w, ev) || changed;
            p += sizeof *ev + ev->len;
        }
    }
}

bool pfx_file_watch_wait(pfx_file_watch *w) {
    struct pollfd fds[2] = {{w->fd, POLLIN, 0}, {w->stop[0], POLLIN, 0}};
    for (;;) {
        if (poll(fds, 2, -1) < 0 && errno != EINTR)
            return false;
        if (fds[1].revents)
            return false;
        if (!(fds[0].revents & POLLIN) || !drain(w))
            continue;
        while (poll(fds, 1, SETTLE_MS) > 0 && (fds[0].revents & POLLIN))
            drain(w);
        return true;
    }
}

void pfx_file_watch_stop(pfx_file_watch *w) {
    ssize_t n = write(w->stop[1], "x", 1);
    (void)n;
}
