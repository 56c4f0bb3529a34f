/* Atomic output files (atomic_file.h). Open temporaries are listed in a
 * registry under a mutex. Signals that end the process are blocked
 * in every thread and taken by one thread in sigwait(), which removes the
 * listed temporaries while holding the mutex (so no writer creates or
 * renames one meanwhile) and then dies of the signal it got: the usual
 * way for a program to clean up and still tell its caller it was
 * interrupted (Cracauer, "Proper handling of SIGINT/SIGQUIT",
 * https://www.cons.org/cracauer/sigint.html). A temporary is created with
 * O_EXCL under the same mutex, so every one on the disk is in the list. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "output/atomic_file.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Temporaries open at once: one per frame encoder thread (up to one per
 * core, times -j), plus the sidecars a job writes. The list grows as
 * needed, under the lock, so a machine of many cores never runs out: a
 * fixed 16 failed with EMFILE once more than 16 encoders wrote at once. */

struct pfx_atomic_file {
    FILE *f;
    char *path, *temp;
    int error; /* the first errno of a failed write, 0 if none */
    int slot;
    pfx_atomic_group *group; /* commit hands the closed temporary to it */
};

/* Files written to their temporaries, to be renamed together. */
#define GROUP_MAX 8
struct pfx_atomic_group {
    pfx_atomic_file *done[GROUP_MAX]; /* committed: closed, synced, not renamed */
    int opened, count;
};

static pthread_mutex_t registry_lock = PTHREAD_MUTEX_INITIALIZER;
static char **registry;     /* registry_cap entries, NULL where free */
static size_t registry_cap; /* under registry_lock */
static bool dying;          /* a signal is being handled: no new temporaries */

/* Thread-safe strerror. */
static const char *errno_text(int errnum, char *buf, size_t size) {
    if (strerror_r(errnum, buf, size) != 0)
        snprintf(buf, size, "error %d", errnum);
    return buf;
}

static void report(pfx_diags *d, const char *path, int errnum) {
    char why[128];
    pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write '%s': %s", path,
                   errno_text(errnum, why, sizeof why));
}

/* The longest file name the directory of path allows (its NAME_MAX). */
static long name_max(const char *path, size_t dir_len) {
    char dir[PATH_MAX];
    if (dir_len == 0)
        snprintf(dir, sizeof dir, ".");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(dir_len < sizeof dir ? dir_len : sizeof dir - 1),
                 path);
    errno = 0;
    long n = pathconf(dir, _PC_NAME_MAX);
    return n > 0 ? n : NAME_MAX;
}

/* "<dir>/.<name>.tmp-<pid>-<n>": the same directory, so rename() is atomic;
 * the process id and a counter keep writers apart. When that is longer
 * than the directory allows, the name is cut (at a UTF-8 character
 * boundary) so that the temporary fits whenever the final name does. NULL
 * with errno set when the final name is itself too long, or out of
 * memory. */
static char *temp_name(const char *path) {
    static unsigned counter; /* under registry_lock */
    const char *slash = strrchr(path, '/');
    size_t dir_len = slash ? (size_t)(slash - path + 1) : 0;
    const char *name = path + dir_len;
    size_t len = strlen(name);
    long max = name_max(path, dir_len);
    if ((long)len > max) {
        errno = ENAMETOOLONG;
        return NULL;
    }
    char suffix[48];
    snprintf(suffix, sizeof suffix, ".tmp-%ld-%u", (long)getpid(), counter++);
    size_t keep = len;
    if ((long)(1 + keep + strlen(suffix)) > max) {
        keep = max > (long)(1 + strlen(suffix)) ? (size_t)max - 1 - strlen(suffix) : 0;
        while (keep > 0 && ((unsigned char)name[keep] & 0xc0) == 0x80)
            keep--;
    }
    size_t size = dir_len + 1 + keep + strlen(suffix) + 1;
    char *temp = malloc(size);
    if (!temp)
        return NULL;
    snprintf(temp, size, "%.*s.%.*s%s", (int)dir_len, path, (int)keep, name, suffix);
    return temp;
}

/* A registered temporary for path: a new empty file open for writing, or
 * (link_from not NULL) a hard link to link_from. NULL with the errno in
 * *errnum. */
static pfx_atomic_file *start(const char *path, const char *link_from, int *errnum) {
    pfx_atomic_file *a = calloc(1, sizeof *a);
    char *copy = strdup(path);
    if (!a || !copy) {
        free(a);
        free(copy);
        *errnum = ENOMEM;
        return NULL;
    }
    a->path = copy;
    a->slot = -1;
    *errnum = 0;
    pthread_mutex_lock(&registry_lock);
    for (size_t i = 0; i < registry_cap && a->slot < 0; i++)
        if (!registry[i])
            a->slot = (int)i;
    if (a->slot < 0 && registry_cap < INT_MAX / 2) {
        size_t cap = registry_cap ? 2 * registry_cap : 16;
        char **grown = realloc(registry, cap * sizeof *grown);
        if (grown) {
            for (size_t i = registry_cap; i < cap; i++)
                grown[i] = NULL;
            a->slot = (int)registry_cap;
            registry = grown;
            registry_cap = cap;
        }
    }
    if (dying)
        *errnum = EINTR;
    else if (a->slot < 0)
        *errnum = EMFILE;
    else if (!(a->temp = temp_name(path)))
        *errnum = errno ? errno : ENOMEM;
    if (!*errnum && link_from) {
        if (link(link_from, a->temp) != 0)
            *errnum = errno;
        else
            registry[a->slot] = a->temp;
    } else if (!*errnum) {
        /* O_EXCL: fail rather than follow or truncate something there. */
        int fd = open(a->temp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 || !(a->f = fdopen(fd, "wb"))) {
            *errnum = errno;
            if (fd >= 0) {
                close(fd);
                unlink(a->temp);
            }
        } else {
            registry[a->slot] = a->temp;
        }
    }
    pthread_mutex_unlock(&registry_lock);
    if (*errnum) {
        free(a->temp);
        free(a->path);
        free(a);
        return NULL;
    }
    return a;
}

pfx_atomic_file *pfx_atomic_open(const char *path, pfx_diags *d) {
    int errnum;
    pfx_atomic_file *a = start(path, NULL, &errnum);
    if (!a)
        report(d, path, errnum);
    return a;
}

pfx_atomic_file *pfx_atomic_open_in(pfx_atomic_group *g, const char *path, pfx_diags *d) {
    if (!g)
        return pfx_atomic_open(path, d);
    if (g->opened == GROUP_MAX) {
        report(d, path, EMFILE);
        return NULL;
    }
    pfx_atomic_file *a = pfx_atomic_open(path, d);
    if (a) {
        a->group = g;
        g->opened++;
    }
    return a;
}

FILE *pfx_atomic_stream(pfx_atomic_file *a) { return a->f; }

void pfx_atomic_failed(pfx_atomic_file *a, int errnum) {
    if (!a->error)
        a->error = errnum ? errnum : EIO;
}

/* Closes the stream (if open), optionally renames, and takes the temporary
 * off the list, all under the lock a signal's cleanup takes. */
static int finish(pfx_atomic_file *a, bool rename_it) {
    int errnum = 0;
    pthread_mutex_lock(&registry_lock);
    if (rename_it && rename(a->temp, a->path) != 0)
        errnum = errno;
    if (!rename_it || errnum)
        unlink(a->temp);
    registry[a->slot] = NULL;
    pthread_mutex_unlock(&registry_lock);
    return errnum;
}

static void destroy(pfx_atomic_file *a) {
    free(a->temp);
    free(a->path);
    free(a);
}

bool pfx_atomic_commit(pfx_atomic_file *a, bool sync_dir, pfx_diags *d) {
    int errnum = a->error;
    /* Buffered data can fail to land at fflush, at fsync (delayed
     * allocation) or at fclose. */
    if (!errnum && (fflush(a->f) != 0 || ferror(a->f)))
        errnum = errno ? errno : EIO;
    if (!errnum && fsync(fileno(a->f)) != 0)
        errnum = errno;
    if (fclose(a->f) != 0 && !errnum)
        errnum = errno ? errno : EIO;
    a->f = NULL;
    if (!errnum && a->group) {
        /* Still listed: a signal removes it until the group renames it. */
        a->group->done[a->group->count++] = a;
        return true;
    }
    if (!errnum)
        errnum = finish(a, true);
    else
        finish(a, false);
    bool ok = errnum == 0;
    if (!ok)
        report(d, a->path, errnum);
    else if (sync_dir)
        ok = pfx_atomic_sync_dir(a->path, d);
    destroy(a);
    return ok;
}

void pfx_atomic_abort(pfx_atomic_file *a) {
    if (!a)
        return;
    if (a->f)
        fclose(a->f);
    finish(a, false);
    destroy(a);
}

pfx_atomic_group *pfx_atomic_group_create(pfx_diags *d) {
    pfx_atomic_group *g = calloc(1, sizeof *g);
    if (!g)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
    return g;
}

bool pfx_atomic_group_commit(pfx_atomic_group *g, pfx_diags *d) {
    int errnum = 0, failed = 0;
    /* Under the lock: a signal's cleanup comes before or after every
     * rename, never between two. */
    pthread_mutex_lock(&registry_lock);
    for (int i = 0; i < g->count; i++) {
        pfx_atomic_file *a = g->done[i];
        if (!errnum && rename(a->temp, a->path) != 0) {
            errnum = errno;
            failed = i;
        }
        if (errnum)
            unlink(a->temp);
        registry[a->slot] = NULL;
    }
    pthread_mutex_unlock(&registry_lock);
    bool ok = errnum == 0;
    if (!ok)
        report(d, g->done[failed]->path, errnum);
    else if (g->count)
        ok = pfx_atomic_sync_dir(g->done[0]->path, d);
    for (int i = 0; i < g->count; i++)
        destroy(g->done[i]);
    free(g);
    return ok;
}

void pfx_atomic_group_abort(pfx_atomic_group *g) {
    if (!g)
        return;
    for (int i = 0; i < g->count; i++) {
        finish(g->done[i], false);
        destroy(g->done[i]);
    }
    free(g);
}

int pfx_atomic_link(const char *from, const char *path, pfx_diags *d) {
    int errnum;
    pfx_atomic_file *a = start(path, from, &errnum);
    if (!a)
        return 0;
    errnum = finish(a, true);
    if (errnum)
        report(d, path, errnum);
    destroy(a);
    return errnum ? -1 : 1;
}

bool pfx_atomic_sync_dir(const char *path, pfx_diags *d) {
    const char *slash = strrchr(path, '/');
    char dir[PATH_MAX];
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    int errnum = fd < 0 ? errno : fsync(fd) != 0 ? errno : 0;
    if (fd >= 0)
        close(fd);
    /* Some file systems cannot sync a directory; the files are synced. */
    if (errnum == EINVAL || errnum == EROFS)
        errnum = 0;
    if (errnum) {
        char why[128];
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot sync the directory '%s': %s", dir,
                       errno_text(errnum, why, sizeof why));
    }
    return errnum == 0;
}

/* ---- signals */

static sigset_t fatal_signals;
static void (*_Atomic stop_hook)(int sig);

static void *signal_thread(void *arg) {
    (void)arg;
    int sig;
    while (sigwait(&fatal_signals, &sig) != 0)
        ;
    /* A server asks first, once: it stops cleanly; a second signal ends
     * the process as below, in case stopping hangs. */
    void (*hook)(int) = atomic_exchange(&stop_hook, NULL);
    if (hook) {
        hook(sig);
        while (sigwait(&fatal_signals, &sig) != 0)
            ;
    }
    /* Keep the lock: no writer creates or renames a temporary from now on,
     * whatever it is doing when the process ends. */
    pthread_mutex_lock(&registry_lock);
    dying = true;
    for (size_t i = 0; i < registry_cap; i++)
        if (registry[i])
            unlink(registry[i]);
    signal(sig, SIG_DFL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, sig);
    pthread_sigmask(SIG_UNBLOCK, &one, NULL);
    raise(sig);
    _exit(128 + sig); /* not reached: the default action ends the process */
}

void pfx_atomic_set_stop_hook(void (*hook)(int sig)) { atomic_store(&stop_hook, hook); }

bool pfx_atomic_guard_signals(void) {
    signal(SIGXFSZ, SIG_IGN);
    sigemptyset(&fatal_signals);
    sigaddset(&fatal_signals, SIGINT);
    sigaddset(&fatal_signals, SIGTERM);
    sigaddset(&fatal_signals, SIGHUP);
    /* A signal ignored when pfx started (nohup, a background job's SIGINT)
     * stays ignored. */
    int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    for (int i = 0; i < 3; i++) {
        struct sigaction old;
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
            sigdelset(&fatal_signals, sigs[i]);
    }
    sigset_t old_mask;
    if (pthread_sigmask(SIG_BLOCK, &fatal_signals, &old_mask) != 0)
        return false;
    pthread_t t;
    pthread_attr_t attr;
    bool ok = pthread_attr_init(&attr) == 0 &&
              pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED) == 0 &&
              pthread_create(&t, &attr, signal_thread, NULL) == 0;
    pthread_attr_destroy(&attr);
    if (!ok)
        pthread_sigmask(SIG_SETMASK, &old_mask, NULL);
    return ok;
}
