/* The JSON lines of jobs/progress.h. Each line is built whole and written
 * with one fputs under the lock, then flushed, so that a reader never sees
 * half a line however many threads report. */
#include "jobs/progress.h"

#include <jansson.h>
#include <stdlib.h>
#include <time.h>

#include "base/json_text.h"

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void pfx_progress_init(pfx_progress *p, FILE *out, const char *effect, long total) {
    pthread_mutex_init(&p->lock, NULL);
    p->out = out;
    p->effect = effect;
    p->total = total;
    p->done = 0;
    p->start = now_s();
}

/* The effect's name is taken as it is and escaped for the dump: one that
 * is not UTF-8 keeps its bytes in "effect_base64" (base/json_text.h). */
static void put(pfx_progress *p, json_t *line) {
    json_t *escaped = line ? pfx_json_escaped(line) : NULL;
    char *text =
        escaped ? json_dumps(escaped, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(6))
                : NULL;
    json_decref(escaped);
    if (text) {
        fputs(text, p->out);
        fputc('\n', p->out);
        fflush(p->out);
    }
    free(text);
    json_decref(line);
}

void pfx_progress_frame(void *ctx, long frame, size_t particles) {
    pfx_progress *p = ctx;
    pthread_mutex_lock(&p->lock);
    p->done++;
    put(p, json_pack("{s:s, s:o, s:I, s:I, s:I, s:I, s:f}", "event", "frame", "effect",
                     pfx_json_bytes(p->effect), "frame", (json_int_t)frame, "done",
                     (json_int_t)p->done, "total", (json_int_t)p->total, "particles",
                     (json_int_t)particles, "elapsed_s", now_s() - p->start));
    pthread_mutex_unlock(&p->lock);
}

void pfx_progress_finish(pfx_progress *p, int status) {
    pthread_mutex_lock(&p->lock);
    put(p, json_pack("{s:s, s:o, s:I, s:I, s:i, s:f}", "event", "done", "effect",
                     pfx_json_bytes(p->effect), "done", (json_int_t)p->done, "total",
                     (json_int_t)p->total, "status", status, "elapsed_s", now_s() - p->start));
    pthread_mutex_unlock(&p->lock);
    pthread_mutex_destroy(&p->lock);
}
