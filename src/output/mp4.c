/* output/mp4.h: an ffmpeg child fed raw RGB through a pipe. ffmpeg writes
 * into pfx's own atomic temporary through /dev/fd/3 (it never learns a
 * name, so a signal that removes the temporary leaves nothing behind), and
 * pfx renames it into place only after ffmpeg exited 0. SIGPIPE is blocked
 * in the writing thread while ffmpeg lives, so an ffmpeg that dies early
 * turns into EPIPE and a report, not the death of pfx. An exit status of 0
 * is not trusted alone: ffmpeg 5.1 exits 0 after "Error writing trailer"
 * (a full disk, `ulimit -f`), so the file's top-level boxes are walked and
 * must tile it exactly, with its index (moov) and media (mdat) present. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "output/mp4.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "output/atomic_file.h"

extern char **environ;

struct pfx_mp4 {
    pfx_atomic_file *file; /* the temporary ffmpeg writes through /dev/fd/3 */
    FILE *log;             /* ffmpeg's stderr: an unlinked temporary file */
    pid_t pid;
    int in;                   /* the write end of ffmpeg's standard input */
    int width, height;        /* of the frames given */
    int out_w, out_h;         /* rounded up to even */
    uint8_t *rgb;             /* one padded, composited frame */
    int write_errno;          /* the first failed write's errno, or 0 */
    bool reaped, failed;      /* ffmpeg has been waited for; it failed */
    sigset_t old_mask;        /* the thread's mask before SIGPIPE was blocked */
    char path[PATH_MAX + 16]; /* for messages */
};

bool pfx_mp4_path(const char *path) {
    size_t n = strlen(path);
    return n > 4 && strcmp(path + n - 4, ".mp4") == 0;
}

bool pfx_mp4_find_ffmpeg(const char *path, char *exe, size_t exe_size, pfx_diags *d) {
    /* execvp's search: an empty entry is the current directory, and an
     * unset PATH is the system's default. */
    const char *dirs = getenv("PATH");
    char fallback[256];
    if (!dirs) {
        size_t n = confstr(_CS_PATH, fallback, sizeof fallback);
        dirs = n > 0 && n <= sizeof fallback ? fallback : "/usr/bin:/bin";
    }
    for (const char *p = dirs;;) {
        const char *colon = strchr(p, ':');
        int len = colon ? (int)(colon - p) : (int)strlen(p);
        struct stat st;
        int n = snprintf(exe, exe_size, "%.*s%sffmpeg", len, p, len ? "/" : "");
        if (n > 0 && (size_t)n < exe_size && stat(exe, &st) == 0 && S_ISREG(st.st_mode) &&
            access(exe, X_OK) == 0)
            return true;
        if (!colon)
            break;
        p = colon + 1;
    }
    size_t n = strlen(path);
    pfx_diag_error(d, PFX_RULE_MISSING_TOOL,
                   "cannot write '%s': ffmpeg not found on PATH (install ffmpeg or use "
                   "--preview %.*s.webp)",
                   path, (int)(pfx_mp4_path(path) ? n - 4 : n), path);
    return false;
}

/* Starts exe with the pipe's read end as stdin, /dev/null as stdout, the
 * log as stderr and the temporary as fd 3. Each goes through a copy above
 * 9 first: a source that is itself 0 to 3 (pfx started with a standard
 * stream closed) would be overwritten by an earlier dup2, or keep
 * close-on-exec when dup2'd onto itself. Returns 0 or an errno. */
static int spawn(pfx_mp4 *m, const char *exe, int pipe_read, int file_fd, char *const argv[]) {
    int high[3] = {fcntl(pipe_read, F_DUPFD_CLOEXEC, 10),
                   fcntl(fileno(m->log), F_DUPFD_CLOEXEC, 10), fcntl(file_fd, F_DUPFD_CLOEXEC, 10)};
    int err = high[0] < 0 || high[1] < 0 || high[2] < 0 ? errno : 0;
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t attr;
    if (!err && !(err = posix_spawn_file_actions_init(&fa)) && (err = posix_spawnattr_init(&attr)))
        posix_spawn_file_actions_destroy(&fa);
    if (err) {
        for (int i = 0; i < 3; i++)
            if (high[i] >= 0)
                close(high[i]);
        return err;
    }
    /* ffmpeg takes Ctrl-C with pfx: no signal blocked (pfx blocks the fatal
     * ones for its signal thread), SIGPIPE back to its default. */
    sigset_t none, pipe_only;
    sigemptyset(&none);
    sigemptyset(&pipe_only);
    sigaddset(&pipe_only, SIGPIPE);
    if (!(err = posix_spawn_file_actions_adddup2(&fa, high[0], 0)) &&
        !(err = posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0)) &&
        !(err = posix_spawn_file_actions_adddup2(&fa, high[1], 2)) &&
        !(err = posix_spawn_file_actions_adddup2(&fa, high[2], 3)) &&
        !(err = posix_spawnattr_setsigmask(&attr, &none)) &&
        !(err = posix_spawnattr_setsigdefault(&attr, &pipe_only)) &&
        !(err = posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF)))
        err = posix_spawn(&m->pid, exe, &fa, &attr, argv, environ);
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&fa);
    for (int i = 0; i < 3; i++)
        close(high[i]);
    return err;
}

/* The argv: raw rgb24 in at fps, H.264 yuv420p out, the index (moov) at
 * the front so that a browser plays it while it loads. */
static int start_ffmpeg(pfx_mp4 *m, const char *exe, double fps, int crf, int pipe_read,
                        int file_fd) {
    char size[32], rate[40], quality[16];
    snprintf(size, sizeof size, "%dx%d", m->out_w, m->out_h);
    snprintf(quality, sizeof quality, "%d", crf);
    snprintf(rate, sizeof rate, "%.17g", fps);
    char *const argv[] = {"ffmpeg",    "-hide_banner", "-nostdin", "-nostats", "-loglevel", "error",
                          "-y",        "-f",           "rawvideo", "-pix_fmt", "rgb24",     "-s",
                          size,        "-r",           rate,       "-i",       "pipe:0",    "-an",
                          "-c:v",      "libx264",      "-pix_fmt", "yuv420p",  "-crf",      quality,
                          "-movflags", "+faststart",   "-f",       "mp4",      "/dev/fd/3", NULL};
    return spawn(m, exe, pipe_read, file_fd, argv);
}

static void release(pfx_mp4 *m) {
    if (m->log)
        fclose(m->log);
    pthread_sigmask(SIG_SETMASK, &m->old_mask, NULL);
    free(m->rgb);
    free(m);
}

pfx_mp4 *pfx_mp4_create(int width, int height, double fps, int crf, const char *path,
                        pfx_diags *d) {
    char exe[PATH_MAX];
    if (!pfx_mp4_find_ffmpeg(path, exe, sizeof exe, d))
        return NULL;
    pfx_mp4 *m = calloc(1, sizeof *m);
    if (!m) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "cannot write '%s': out of memory", path);
        return NULL;
    }
    snprintf(m->path, sizeof m->path, "%s", path);
    m->width = width, m->height = height;
    m->out_w = width + (width & 1), m->out_h = height + (height & 1);
    m->rgb = calloc((size_t)m->out_w * (size_t)m->out_h, 3); /* padding stays black */
    sigset_t pipe_only;
    sigemptyset(&pipe_only);
    sigaddset(&pipe_only, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_only, &m->old_mask);
    m->log = tmpfile();
    if (!m->rgb || !m->log) {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write '%s': %s", path,
                       strerror(m->rgb ? errno : ENOMEM));
        release(m);
        return NULL;
    }
    fcntl(fileno(m->log), F_SETFD, FD_CLOEXEC);
    if (!(m->file = pfx_atomic_open(path, d))) {
        release(m);
        return NULL;
    }
    /* Both ends close on exec: the child gets its copy of the read end as
     * fd 0 only, so it sees end-of-file when pfx closes the write end. */
    int fds[2];
    int err = pipe(fds) != 0 ? errno : 0;
    if (!err) {
        fcntl(fds[0], F_SETFD, FD_CLOEXEC);
        fcntl(fds[1], F_SETFD, FD_CLOEXEC);
        err = start_ffmpeg(m, exe, fps, crf, fds[0], fileno(pfx_atomic_stream(m->file)));
        close(fds[0]);
        if (err)
            close(fds[1]);
        else
            m->in = fds[1];
    }
    if (err) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot write '%s': cannot run '%s': %s", path,
                       exe, strerror(err));
        pfx_atomic_abort(m->file);
        release(m);
        return NULL;
    }
    return m;
}

static bool write_all(int fd, const uint8_t *p, size_t n) {
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return false;
        p += w, n -= (size_t)w;
    }
    return true;
}

/* Closes ffmpeg's input, waits for it and takes the SIGPIPE a failed
 * write left pending; with d, reports a failure (ffmpeg's exit status and
 * its last words, or the failed write). Sets m->failed. */
static void reap(pfx_mp4 *m, pfx_diags *d);

bool pfx_mp4_add(pfx_mp4 *m, const uint8_t *rgba, pfx_diags *d) {
    if (m->reaped)
        return false;
    /* Straight alpha over black: c * a / 255, rounded. */
    for (int y = 0; y < m->height; y++) {
        const uint8_t *s = rgba + (size_t)y * m->width * 4;
        uint8_t *o = m->rgb + (size_t)y * m->out_w * 3;
        for (int x = 0; x < m->width; x++, s += 4, o += 3)
            for (int c = 0; c < 3; c++)
                o[c] = (uint8_t)((s[c] * s[3] + 127) / 255);
    }
    if (write_all(m->in, m->rgb, (size_t)m->out_w * m->out_h * 3))
        return true;
    m->write_errno = errno ? errno : EIO;
    reap(m, d);
    return false;
}

/* The last few non-empty lines of ffmpeg's stderr, joined by "; ". */
static void log_tail(FILE *log, char *out, size_t size) {
    char buf[2048];
    out[0] = '\0';
    long end = fseek(log, 0, SEEK_END) == 0 ? ftell(log) : -1;
    if (end <= 0 ||
        fseek(log, end > (long)sizeof buf - 1 ? end - (long)sizeof buf + 1 : 0, SEEK_SET) != 0)
        return;
    size_t n = fread(buf, 1, sizeof buf - 1, log);
    buf[n] = '\0';
    const char *lines[3]; /* a ring of the last three */
    int count = 0;
    for (char *save = NULL, *l = strtok_r(buf, "\r\n", &save); l; l = strtok_r(NULL, "\r\n", &save))
        if (*l)
            lines[count++ % 3] = l;
    size_t used = 0;
    for (int i = count > 3 ? count - 3 : 0; i < count && used < size; i++)
        used += (size_t)snprintf(out + used, size - used, "%s%s", used ? "; " : "", lines[i % 3]);
}

static uint64_t be(const uint8_t *p, int bytes) {
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++)
        v = v << 8 | p[i];
    return v;
}

/* The box walk of mp4_whole over the `end` bytes of fd. */
static bool boxes_whole(int fd, uint64_t end, char *why, size_t size) {
    bool moov = false, mdat = false;
    for (uint64_t at = 0; at < end;) {
        uint8_t h[16];
        ssize_t got = pread(fd, h, sizeof h, (off_t)at);
        uint64_t box = got >= 8 ? be(h, 4) : 0, head = 8;
        if (got >= 8 && box == 1) {
            box = got >= 16 ? be(h + 8, 8) : 0;
            head = 16;
        } else if (got >= 8 && box == 0) {
            box = end - at;
        }
        if (got < (ssize_t)head || box < head || box > end - at) {
            snprintf(why, size, "a box at byte %llu runs past its end at %llu bytes",
                     (unsigned long long)at, (unsigned long long)end);
            return false;
        }
        if (at == 0 && memcmp(h + 4, "ftyp", 4) != 0) {
            snprintf(why, size, "it does not start with an 'ftyp' box");
            return false;
        }
        moov = moov || !memcmp(h + 4, "moov", 4);
        mdat = mdat || !memcmp(h + 4, "mdat", 4);
        at += box;
    }
    if (!moov || !mdat)
        snprintf(why, size, "it has no '%s' box", moov ? "mdat" : "moov");
    return moov && mdat;
}

/* Whether the MP4 behind `written` is whole: ISO BMFF top-level boxes
 * (32-bit size and type; size 1: a 64-bit size follows; size 0: to the end
 * of the file) from 'ftyp' to the last byte, 'moov' and 'mdat' among them.
 * When not, says why in `why`. The temporary is open for writing only: it
 * is read through a second, read-only descriptor of the same file, the way
 * ffmpeg reached it. */
static bool mp4_whole(int written, char *why, size_t size) {
    char self[64];
    snprintf(self, sizeof self, "/dev/fd/%d", written);
    int fd = open(self, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        snprintf(why, size, "cannot read it back: %s", strerror(errno));
        if (fd >= 0)
            close(fd);
        return false;
    }
    bool whole = boxes_whole(fd, (uint64_t)st.st_size, why, size);
    close(fd);
    return whole;
}

static void reap(pfx_mp4 *m, pfx_diags *d) {
    close(m->in);
    m->reaped = true;
    int status = 0;
    while (waitpid(m->pid, &status, 0) < 0 && errno == EINTR)
        ;
    if (m->write_errno == EPIPE) {
        sigset_t pipe_only;
        sigemptyset(&pipe_only);
        sigaddset(&pipe_only, SIGPIPE);
        struct timespec now = {0, 0};
        while (sigtimedwait(&pipe_only, NULL, &now) == SIGPIPE)
            ;
    }
    m->failed = true;
    char tail[600], why[128];
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        char how[64];
        log_tail(m->log, tail, sizeof tail);
        if (WIFSIGNALED(status))
            snprintf(how, sizeof how, "was killed by signal %d", WTERMSIG(status));
        else
            snprintf(how, sizeof how, "exited with status %d", WEXITSTATUS(status));
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot write '%s': ffmpeg %s%s%s", m->path, how,
                       *tail ? ": " : "", tail);
    } else if (m->write_errno) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED,
                       "cannot write '%s': ffmpeg stopped reading its frames: %s", m->path,
                       strerror(m->write_errno));
    } else if (!mp4_whole(fileno(pfx_atomic_stream(m->file)), why, sizeof why)) {
        log_tail(m->log, tail, sizeof tail);
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED,
                       "cannot write '%s': ffmpeg exited 0 but its MP4 is incomplete (%s)%s%s",
                       m->path, why, *tail ? ": " : "", tail);
    } else {
        m->failed = false;
    }
}

bool pfx_mp4_finish(pfx_mp4 *m, bool commit, pfx_diags *d) {
    bool ok = !m->failed;
    if (!m->reaped) {
        if (!commit)
            kill(m->pid, SIGKILL); /* the caller failed: no need to wait for a file */
        reap(m, commit ? d : NULL);
        ok = commit ? !m->failed : true;
    }
    if (ok && commit) {
        ok = pfx_atomic_commit(m->file, true, d);
        m->file = NULL;
    }
    pfx_atomic_abort(m->file);
    release(m);
    return ok;
}
