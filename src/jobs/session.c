/* The live session: the last good model of one effect file, the
 * diagnostics of the latest compile, and its frames, rendered by one
 * worker thread through jobs/render_job.c (so a frame is the file `pfx
 * render --frames K` writes, byte for byte) into a private scratch
 * directory and kept in memory under a cap. The watcher (session_watch.c)
 * calls pfx_session_reload on every change. No protocol lives here. */
#include "jobs/session.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <jansson.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "base/json_text.h"
#include "jobs/estimate.h"
#include "jobs/load.h"
#include "jobs/pick.h"
#include "jobs/render_job.h"
#include "jobs/session_internal.h"
#include "parse/node.h"

/* A prefetch job runs on to the next cached frame (or the end), and its
 * frames are taken in as their files appear, so that one simulation serves
 * them all; a change cancels it at once, within a simulation step or a
 * motion-blur sample of the frame being drawn. */

/* A rendered frame: the PNG's bytes and what the page shows beside it. */
typedef struct frame_slot {
    void *png; /* NULL: not rendered (or evicted) */
    size_t len;
    bool rendered;  /* stats below are valid (kept after eviction) */
    double ms;      /* simulating and drawing it, in its job */
    size_t sprites; /* drawn */
} frame_slot;

/* One good compile: shared by the session and the work running from it,
 * freed when the last holder lets go. */
typedef struct session_model {
    int refs;
    unsigned version;
    pfx_loaded l;
    const pfx_effect *e;
    long frames;
    int *lines; /* the line of each emitter's key, in emitter order */
    frame_slot *slots;
    uint32_t *alive;  /* frames x emitters: live particles, when rendered */
    uint64_t *raised; /* frames x emitters: sub-emitter events raised into it so far */
    size_t bytes;     /* PNG bytes held in slots */
    size_t cap;       /* at most this many (cache_cap) */
    char *error;      /* a render failure (malloc'd), or NULL */
} session_model;

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static void model_release(session_model *m) {
    if (!m || --m->refs > 0)
        return;
    for (long f = 0; f < m->frames; f++)
        free(m->slots[f].png);
    free(m->slots);
    free(m->alive);
    free(m->raised);
    free(m->lines);
    free(m->error);
    pfx_loaded_free(&m->l);
    free(m);
}

/* The line of each emitter's key under `emitters:` (0 when not found). */
static void find_emitter_lines(session_model *m) {
    const pfx_node *list = m->l.doc.root ? pfx_node_get(m->l.doc.root, "emitters") : NULL;
    for (size_t i = 0; i < m->e->emitter_count; i++) {
        const char *name = m->e->emitters[i].name;
        for (size_t j = 0; list && list->kind == PFX_NODE_MAP && j < list->count; j++) {
            const pfx_node *key = list->pairs[j].key;
            if (key->len == strlen(name) && !memcmp(key->text, name, key->len))
                m->lines[i] = key->line;
        }
    }
}

/* The diagnostics of l as `pfx validate` prints them, and as the JSON
 * objects of `--format json`, parsed back: one printer for both. */
static void describe_diags(pfx_session *s, const pfx_loaded *l) {
    char *text = NULL, *lines = NULL;
    size_t tn = 0, ln = 0;
    FILE *f = open_memstream(&text, &tn);
    if (f) {
        pfx_diags_print(&l->diags, f, false);
        fclose(f);
    }
    json_t *list = json_array();
    f = open_memstream(&lines, &ln);
    if (f) {
        pfx_diags_print(&l->diags, f, true);
        fclose(f);
    }
    for (char *p = lines, *nl; p && *p; p = nl + 1) {
        nl = strchr(p, '\n');
        if (!nl)
            break;
        *nl = 0;
        json_t *o = json_loads(p, 0, NULL);
        if (o) {
            json_object_del(o, "file");
            json_array_append_new(list, o);
        }
    }
    free(lines);
    free(s->diag_text);
    json_decref(s->diag_json);
    s->diag_text = text;
    s->diag_json = list;
}

/* The frame cache's cap for a version: every frame's PNG at most, as
 * estimated (pfx_estimate_png_bytes), but no more than half of what
 * --max-memory leaves beside the estimate of the render itself (256 MiB
 * where no bound is known); the options' cache_bytes instead when set. */
static size_t cache_cap(const pfx_session *s, const pfx_effect *e, long frames) {
    if (s->o.cache_bytes)
        return s->o.cache_bytes;
    double room = 256.0 * 1024 * 1024;
    if (s->o.max_memory) {
        pfx_estimate est;
        pfx_estimate_run(e, 0, frames - 1, PFX_ESTIMATE_RENDER, &est);
        room = fmax(0, floor(((double)s->o.max_memory - est.total_bytes) / 2));
    }
    const double cap = fmin(pfx_estimate_png_bytes(e, frames), room);
    return cap >= (double)SIZE_MAX ? SIZE_MAX : (size_t)cap;
}

bool pfx_session_reload(pfx_session *s) {
    session_model *m = calloc(1, sizeof *m);
    if (!m)
        return false;
    pfx_effect *e = pfx_load(&m->l, s->o.path, &s->o.compile);
    bool good = e != NULL;
    if (good) {
        m->e = e;
        m->refs = 1;
        m->frames = pfx_effect_frame_count(e);
        m->cap = cache_cap(s, e, m->frames);
        m->lines = calloc(e->emitter_count + 1, sizeof *m->lines);
        m->slots = calloc((size_t)m->frames, sizeof *m->slots);
        m->alive = calloc((size_t)m->frames * (e->emitter_count + 1), sizeof *m->alive);
        m->raised = calloc((size_t)m->frames * (e->emitter_count + 1), sizeof *m->raised);
        good = m->lines && m->slots && m->alive && m->raised;
        if (good)
            find_emitter_lines(m);
        else
            pfx_diag_error(&m->l.diags, PFX_RULE_OUT_OF_MEMORY, "out of memory for %ld frames",
                           m->frames);
        /* The bound pfx render keeps, for a render of every frame. */
        good = good && pfx_estimate_fits(e, 0, m->frames - 1, PFX_ESTIMATE_RENDER, s->o.max_memory,
                                         &m->l.diags);
    }
    pthread_mutex_lock(&s->mu);
    describe_diags(s, &m->l);
    s->news++;
    session_model *old = NULL;
    if (good) {
        m->version = ++s->version;
        old = s->good;
        s->good = m;
        /* Stale work stops at once: within a simulation step or a motion-blur
         * sample (jobs/render_job.c). */
        atomic_store(&s->cancel, true);
        pthread_cond_broadcast(&s->work_cv);
        /* Under the lock: another reload cannot free e meanwhile. */
        pfx_session_watch_inputs(s, e);
    }
    pthread_cond_broadcast(&s->news_cv);
    pthread_cond_broadcast(&s->frame_cv);
    model_release(old);
    pthread_mutex_unlock(&s->mu);
    if (!good) {
        m->refs = 1;
        model_release(m);
    }
    return good;
}

/* The next frames the worker should render, nearest the playhead first:
 * the playhead's frame alone, then the frames after it, then those before,
 * each run up to the next cached frame, while the cache has room. False
 * when there is nothing to do. Called with the lock held. */
static bool next_work(const pfx_session *s, const session_model *m, long *first, long *last) {
    long k = s->playhead < 0 ? 0 : s->playhead >= m->frames ? m->frames - 1 : s->playhead;
    if (m->error)
        return false;
    if (!m->slots[k].png) {
        *first = *last = k;
        return true;
    }
    if (m->bytes >= m->cap / 10 * 9)
        return false;
    for (long f = k + 1; f < m->frames; f++)
        if (!m->slots[f].png) {
            *first = *last = f;
            while (*last + 1 < m->frames && !m->slots[*last + 1].png)
                ++*last;
            return true;
        }
    for (long f = k - 1; f >= 0; f--)
        if (!m->slots[f].png) {
            *first = *last = f;
            while (*first > 0 && !m->slots[*first - 1].png)
                --*first;
            return true;
        }
    return false;
}

/* Drops the cached frames farthest from the playhead until `more` bytes
 * fit under the cap (never frame keep). Called with the lock held. */
static void make_room(pfx_session *s, session_model *m, size_t more, long keep) {
    while (m->bytes + more > m->cap) {
        long far = -1, best = -1;
        for (long f = 0; f < m->frames; f++) {
            long dist = labs(f - s->playhead);
            if (m->slots[f].png && f != keep && dist > best)
                far = f, best = dist;
        }
        if (far < 0)
            return;
        m->bytes -= m->slots[far].len;
        free(m->slots[far].png);
        m->slots[far].png = NULL;
    }
}

static void *read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    void *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    *len = (size_t)n;
    return buf;
}

/* A job of the worker: where its frames are written, the next one to take
 * in, and the clock of its last frame. */
typedef struct job_watch {
    pfx_session *s;
    pfx_render_job *job;
    session_model *m;
    char stem[32];
    long next; /* the first frame not yet taken in */
    double t;
} job_watch;

/* Takes frames next..upto into m's slots, in order, while their files are
 * there: the frame queue renames a file into place only once it is whole.
 * With end (the job is over), a missing file is a frame never drawn. */
static void take_frames(job_watch *w, long upto, bool end) {
    pfx_session *s = w->s;
    session_model *m = w->m;
    char path[4200];
    for (; w->next <= upto; w->next++) {
        snprintf(path, sizeof path, "%s/%s_%04ld.png", s->scratch, w->stem, w->next);
        size_t len = 0;
        void *png = read_file(path, &len);
        if (!png && !end)
            return;
        unlink(path);
        if (!png)
            continue;
        pthread_mutex_lock(&s->mu);
        make_room(s, m, len, w->next);
        free(m->slots[w->next].png);
        m->slots[w->next].png = png;
        m->slots[w->next].len = len;
        m->slots[w->next].rendered = true;
        m->bytes += len;
        /* A full cache stops prefetching past the playhead. */
        if (w->next > s->playhead && m->bytes >= m->cap / 10 * 9)
            atomic_store(&s->cancel, true);
        pthread_cond_broadcast(&s->frame_cv);
        pthread_mutex_unlock(&s->mu);
    }
}

/* Per frame, as the job draws it: the time since the last and the live
 * particles of each emitter in the state drawn; then the frames before it
 * that are written by now. */
static void on_frame(void *ctx, long f, size_t sprites) {
    job_watch *w = ctx;
    double t = now_ms();
    frame_slot *slot = &w->m->slots[f];
    const pfx_sim *state = w->job->feed.sim;
    size_t n = w->m->e->emitter_count;
    /* The state's JSON reads these under the lock. */
    pthread_mutex_lock(&w->s->mu);
    slot->ms = t - w->t;
    slot->sprites = sprites;
    for (size_t i = 0; state && i < n; i++) {
        w->m->alive[(size_t)f * (n + 1) + i] = state->pools[i].count;
        w->m->raised[(size_t)f * (n + 1) + i] = state->emitters[i].spawn_events;
    }
    pthread_mutex_unlock(&w->s->mu);
    take_frames(w, f - 1, false);
    w->t = now_ms();
}

/* Renders frames first..last of m into the scratch directory with the
 * render job, then moves them into m's slots. Runs without the lock; the
 * renderer is the worker's alone. */
static void render_range(pfx_session *s, session_model *m, long first, long last) {
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    const pfx_effect *e = m->e;
    if (s->renderer && (s->renderer_w != e->width || s->renderer_h != e->height)) {
        pfx_renderer_destroy(s->renderer);
        s->renderer = NULL;
    }
    if (!s->renderer) {
        s->renderer = pfx_renderer_create(s->o.renderer, e->width, e->height, &run);
        s->renderer_w = e->width;
        s->renderer_h = e->height;
    }
    job_watch watch = {.s = s, .m = m, .next = first};
    snprintf(watch.stem, sizeof watch.stem, "v%u", m->version);
    pfx_render_job job = {.effect = e,
                          .renderer = s->renderer,
                          .dir = s->scratch,
                          .stem = watch.stem,
                          .first = first,
                          .last = last,
                          .format = PFX_FRAME_PNG,
                          .cancel = &s->cancel,
                          .on_frame = on_frame,
                          .on_frame_ctx = &watch};
    watch.job = &job;
    watch.t = now_ms();
    bool ok = s->renderer && pfx_render_job_run(&job, &run);
    pfx_render_job_free(&job);
    take_frames(&watch, last, true);
    pthread_mutex_lock(&s->mu);
    if (!ok && !m->error) {
        char *text = NULL;
        size_t n = 0;
        FILE *f = open_memstream(&text, &n);
        if (f) {
            pfx_diags_print(&run, f, false);
            fclose(f);
        }
        m->error = text ? text : strdup("pfx: the render failed\n");
        s->news++;
        pthread_cond_broadcast(&s->news_cv);
    }
    pthread_cond_broadcast(&s->frame_cv);
    pthread_mutex_unlock(&s->mu);
    pfx_diags_free(&run);
}

static void *worker_main(void *arg) {
    pfx_session *s = arg;
    pthread_mutex_lock(&s->mu);
    while (!s->stopping) {
        session_model *m = s->good;
        long first, last;
        if (!m || !next_work(s, m, &first, &last)) {
            pthread_cond_wait(&s->work_cv, &s->mu);
            continue;
        }
        m->refs++;
        s->busy = m;
        s->busy_first = first;
        s->busy_last = last;
        atomic_store(&s->cancel, false);
        pthread_mutex_unlock(&s->mu);
        render_range(s, m, first, last);
        pthread_mutex_lock(&s->mu);
        s->busy = NULL;
        model_release(m);
    }
    pthread_mutex_unlock(&s->mu);
    pfx_renderer_destroy(s->renderer);
    s->renderer = NULL;
    return NULL;
}

#define SCRATCH_PREFIX "pfx-preview-"

/* Removes dir/pfx-preview-PID-XXXXXX of every PID that is no longer
 * running (kill(pid, 0) says ESRCH), with the frames in it: what a
 * session killed by SIGKILL left behind. A live pid's, another user's
 * (EPERM) and any other name are left alone; the directory holds only
 * plain files (frames and their temporaries), removed without following
 * links. */
static void sweep_stale_scratch(const char *tmp) {
    DIR *dir = opendir(tmp);
    if (!dir)
        return;
    for (struct dirent *de; (de = readdir(dir));) {
        if (strncmp(de->d_name, SCRATCH_PREFIX, strlen(SCRATCH_PREFIX)))
            continue;
        char *end;
        const char *digits = de->d_name + strlen(SCRATCH_PREFIX);
        long pid = strtol(digits, &end, 10);
        if (end == digits || *end != '-' || strlen(end) != 7 || pid <= 0 || pid == (long)getpid() ||
            kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue;
        int fd = openat(dirfd(dir), de->d_name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW);
        DIR *stale = fd >= 0 ? fdopendir(fd) : NULL;
        if (!stale) {
            if (fd >= 0)
                close(fd);
            continue;
        }
        for (struct dirent *f; (f = readdir(stale));)
            if (strcmp(f->d_name, ".") && strcmp(f->d_name, ".."))
                unlinkat(fd, f->d_name, 0);
        closedir(stale);
        unlinkat(dirfd(dir), de->d_name, AT_REMOVEDIR);
    }
    closedir(dir);
}

pfx_session *pfx_session_create(const pfx_session_options *o, pfx_diags *d) {
    pfx_session *s = calloc(1, sizeof *s);
    if (!s) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for the session");
        return NULL;
    }
    s->o = *o;
    pthread_mutex_init(&s->mu, NULL);
    pthread_cond_init(&s->work_cv, NULL);
    pthread_cond_init(&s->news_cv, NULL);
    pthread_cond_init(&s->frame_cv, NULL);
    /* Frames go through files as `pfx render` writes them; a RAM-backed
     * directory where there is one keeps that off the disk. Its name holds
     * the pid, so that a later session can sweep the scratch of one that
     * was killed (SIGKILL runs no cleanup). */
    const char *tmp = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : getenv("TMPDIR");
    tmp = tmp && *tmp ? tmp : "/tmp";
    sweep_stale_scratch(tmp);
    snprintf(s->scratch, sizeof s->scratch, "%s/" SCRATCH_PREFIX "%ld-XXXXXX", tmp, (long)getpid());
    if (!mkdtemp(s->scratch)) {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create a scratch directory '%s': %s",
                       s->scratch, strerror(errno));
        s->scratch[0] = 0;
        pfx_session_destroy(s);
        return NULL;
    }
    if (!pfx_session_watch_start(s, d)) {
        pfx_session_destroy(s);
        return NULL;
    }
    pfx_session_reload(s);
    if (pthread_create(&s->worker, NULL, worker_main, s)) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "cannot start the render thread");
        pfx_session_destroy(s);
        return NULL;
    }
    s->has_worker = true;
    return s;
}

void pfx_session_stop(pfx_session *s) {
    pthread_mutex_lock(&s->mu);
    s->stopping = true;
    atomic_store(&s->cancel, true);
    pthread_cond_broadcast(&s->work_cv);
    pthread_cond_broadcast(&s->news_cv);
    pthread_cond_broadcast(&s->frame_cv);
    pthread_mutex_unlock(&s->mu);
}

void pfx_session_destroy(pfx_session *s) {
    if (!s)
        return;
    pfx_session_stop(s);
    pfx_session_watch_stop(s);
    if (s->has_worker)
        pthread_join(s->worker, NULL);
    model_release(s->good);
    free(s->diag_text);
    json_decref(s->diag_json);
    if (s->scratch[0])
        rmdir(s->scratch);
    pthread_cond_destroy(&s->frame_cv);
    pthread_cond_destroy(&s->news_cv);
    pthread_cond_destroy(&s->work_cv);
    pthread_mutex_destroy(&s->mu);
    free(s);
}

/* A deadline timeout_ms from now for pthread_cond_timedwait. */
static struct timespec deadline_in(int timeout_ms) {
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    t.tv_sec += timeout_ms / 1000;
    t.tv_nsec += (long)(timeout_ms % 1000) * 1000000L;
    if (t.tv_nsec >= 1000000000L)
        t.tv_sec++, t.tv_nsec -= 1000000000L;
    return t;
}

unsigned pfx_session_wait(pfx_session *s, unsigned seen, int timeout_ms) {
    struct timespec until = deadline_in(timeout_ms);
    pthread_mutex_lock(&s->mu);
    while (s->news == seen && !s->stopping)
        if (pthread_cond_timedwait(&s->news_cv, &s->mu, &until) == ETIMEDOUT)
            break;
    unsigned news = s->news;
    pthread_mutex_unlock(&s->mu);
    return news;
}

int pfx_session_frame(pfx_session *s, long k, bool ahead, int timeout_ms, void **png, size_t *len,
                      unsigned *version) {
    struct timespec until = deadline_in(timeout_ms);
    int result = -1;
    pthread_mutex_lock(&s->mu);
    for (;;) {
        session_model *m = s->good;
        if (!m || k < 0 || k >= m->frames || s->stopping) {
            result = 0;
            break;
        }
        if (m->slots[k].png) {
            *png = malloc(m->slots[k].len);
            if (*png) {
                memcpy(*png, m->slots[k].png, m->slots[k].len);
                *len = m->slots[k].len;
                *version = m->version;
                result = 1;
            }
            break;
        }
        if (m->error)
            break;
        /* A look-ahead waits while the worker renders this version (it
         * goes on past the playhead by itself); it takes the playhead only
         * from an idle worker, which a full cache leaves idle. */
        const bool wait_behind = ahead && s->busy == m;
        if (!wait_behind && s->playhead != k) {
            s->playhead = k;
            /* Work that does not hold the new playhead gives way to it. */
            if (s->busy && (s->busy != m || k < s->busy_first || k > s->busy_last))
                atomic_store(&s->cancel, true);
            pthread_cond_broadcast(&s->work_cv);
        }
        struct timespec soon = deadline_in(50);
        const bool sooner =
            wait_behind && (soon.tv_sec < until.tv_sec ||
                            (soon.tv_sec == until.tv_sec && soon.tv_nsec < until.tv_nsec));
        if (pthread_cond_timedwait(&s->frame_cv, &s->mu, sooner ? &soon : &until) == ETIMEDOUT &&
            !sooner)
            break;
    }
    pthread_mutex_unlock(&s->mu);
    return result;
}

/* An emitter's row of the state: its name and line, when it runs (in
 * seconds of the preview's timeline, whose 0 is frame 0) and its bursts as
 * ticks on that timeline, looping as the emitter loops (at most 256). */
static json_t *emitter_json(const session_model *m, size_t i) {
    const pfx_effect *e = m->e;
    const pfx_emitter *em = &e->emitters[i];
    const double t0 = pfx_sim_frame_time(e, 0), end = m->frames / e->fps;
    json_t *bursts = json_array();
    const double period =
        em->loop && isfinite(em->duration) && em->duration > 0 ? em->duration : INFINITY;
    for (double base = em->start - t0; base < end && json_array_size(bursts) < 256;
         base += period) {
        for (size_t b = 0; b < em->burst_count; b++)
            for (uint32_t c = 0; c < em->bursts[b].cycles && json_array_size(bursts) < 256; c++) {
                double t = base + em->bursts[b].time + c * em->bursts[b].interval;
                if (t >= 0 && t <= end)
                    json_array_append_new(bursts, json_real(t));
            }
        if (!isfinite(period))
            break;
    }
    /* Its sub-emitters: which event of its particles feeds which emitter. */
    json_t *spawns = json_array();
    for (size_t j = 0; j < em->spawn_count; j++)
        json_array_append_new(spawns, json_pack("{s:s, s:s}", "event",
                                                pfx_spawn_event_names[em->spawns[j].event],
                                                "emitter", e->emitters[em->spawns[j].target].name));
    double stop = isfinite(em->duration) && !em->loop ? em->start + em->duration - t0 : end;
    return json_pack("{s:s, s:i, s:f, s:f, s:b, s:o, s:o}", "name", em->name, "line",
                     (json_int_t)m->lines[i], "start", em->start - t0 > 0 ? em->start - t0 : 0.0,
                     "end", stop < end ? stop : end, "loop", em->loop, "bursts", bursts, "spawns",
                     spawns);
}

/* The sub-emitter events raised into each emitter between frame f - 1
 * and frame f (from time 0 for frame 0), from the counts the render
 * recorded; null until both frames are rendered. A looping effect's
 * wrap (the count restarts) counts from the period's start. */
static json_t *events_json(const session_model *m, long f) {
    const size_t n = m->e->emitter_count;
    if (f > 0 && !m->slots[f - 1].rendered)
        return json_null();
    json_t *list = json_array();
    for (size_t i = 0; i < n; i++) {
        const uint64_t now = m->raised[(size_t)f * (n + 1) + i];
        const uint64_t before = f > 0 ? m->raised[(size_t)(f - 1) * (n + 1) + i] : 0;
        json_array_append_new(list, json_integer((json_int_t)(now >= before ? now - before : now)));
    }
    return list;
}

char *pfx_session_state_json(pfx_session *s) {
    pthread_mutex_lock(&s->mu);
    const session_model *m = s->good;
    /* The file's name, and the messages quoting it, are bytes: escaped
     * below as every JSON pfx writes escapes them (base/json_text.h). */
    json_t *o = json_pack("{s:o, s:i, s:i, s:O, s:o}", "file", pfx_json_bytes(s->o.path), "version",
                          (json_int_t)s->version, "news", (json_int_t)s->news, "diagnostics",
                          s->diag_json ? s->diag_json : json_array(), "diagnostics_text",
                          pfx_json_bytes(s->diag_text ? s->diag_text : ""));
    if (m) {
        const pfx_effect *e = m->e;
        json_t *emitters = json_array(), *stats = json_array();
        for (size_t i = 0; i < e->emitter_count; i++)
            json_array_append_new(emitters, emitter_json(m, i));
        for (long f = 0; f < m->frames; f++) {
            const frame_slot *slot = &m->slots[f];
            if (!slot->rendered) {
                json_array_append_new(stats, json_null());
                continue;
            }
            json_t *alive = json_array();
            for (size_t i = 0; i < e->emitter_count; i++)
                json_array_append_new(
                    alive, json_integer(m->alive[(size_t)f * (e->emitter_count + 1) + i]));
            json_t *row = json_pack("{s:f, s:i, s:o}", "ms", slot->ms, "sprites",
                                    (json_int_t)slot->sprites, "alive", alive);
            json_object_set_new(row, "events", events_json(m, f));
            json_array_append_new(stats, row);
        }
        json_object_set_new(o, "frames", json_integer(m->frames));
        json_object_set_new(o, "fps", json_real(e->fps));
        json_object_set_new(o, "size", json_pack("[i, i]", e->width, e->height));
        json_object_set_new(o, "emitters", emitters);
        json_object_set_new(o, "stats", stats);
        long held = 0;
        for (long f = 0; f < m->frames; f++)
            held += m->slots[f].png != NULL;
        json_object_set_new(o, "cache",
                            json_pack("{s:i, s:I, s:I}", "frames", (json_int_t)held, "bytes",
                                      (json_int_t)m->bytes, "cap", (json_int_t)m->cap));
        json_object_set_new(o, "render_error", m->error ? pfx_json_bytes(m->error) : json_null());
        json_object_set_new(o, "alpha", json_string(pfx_alpha_mode_names[e->alpha_mode]));
    } else {
        json_object_set_new(o, "frames", json_integer(0));
        json_object_set_new(o, "emitters", json_array());
    }
    pthread_mutex_unlock(&s->mu);
    json_t *escaped = o ? pfx_json_escaped(o) : NULL;
    char *text = escaped ? json_dumps(escaped, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(escaped);
    json_decref(o);
    return text;
}

char *pfx_session_pick_json(pfx_session *s, long k, int x, int y) {
    pthread_mutex_lock(&s->mu);
    session_model *m = s->good;
    if (m)
        m->refs++;
    pthread_mutex_unlock(&s->mu);
    if (!m)
        return NULL;
    char *text = NULL;
    const pfx_effect *e = m->e;
    bool *hit = calloc(e->emitter_count + 1, sizeof *hit);
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    if (hit && k >= 0 && k < m->frames && x >= 0 && y >= 0 && x < e->width && y < e->height &&
        pfx_pick(e, k, x, y, hit, &run)) {
        json_t *list = json_array();
        for (size_t i = 0; i < e->emitter_count; i++)
            if (hit[i])
                json_array_append_new(list, json_pack("{s:s, s:i}", "emitter", e->emitters[i].name,
                                                      "line", (json_int_t)m->lines[i]));
        text = json_dumps(list, JSON_COMPACT);
        json_decref(list);
    }
    pfx_diags_free(&run);
    free(hit);
    pthread_mutex_lock(&s->mu);
    model_release(m);
    pthread_mutex_unlock(&s->mu);
    return text;
}
