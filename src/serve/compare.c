/* The preview's comparison: at most one second session, swapped under a
 * lock and freed by whoever lets go of it last (a frame request may wait
 * on it for a minute). */
#include "serve/compare.h"

#include <errno.h>
#include <jansson.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/json_text.h"

struct pfx_compare_ref {
    pfx_session *session;
    char *path; /* the session's options point here */
    bool has_seed;
    uint64_t seed;
    int refs; /* holders, plus one while it is the comparison */
};

struct pfx_compare {
    pfx_session_options base;
    pthread_mutex_t mu;
    pfx_compare_ref *now;
};

pfx_compare *pfx_compare_create(const pfx_session_options *base) {
    pfx_compare *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->base = *base;
    pthread_mutex_init(&c->mu, NULL);
    return c;
}

static void ref_free(pfx_compare_ref *r) {
    pfx_session_destroy(r->session);
    free(r->path);
    free(r);
}

/* Drops one hold of r (under c->mu); frees it, outside the lock, when it
 * was the last. */
static void drop(pfx_compare *c, pfx_compare_ref *r) {
    if (!r)
        return;
    pthread_mutex_lock(&c->mu);
    bool last = --r->refs == 0;
    pthread_mutex_unlock(&c->mu);
    if (last)
        ref_free(r);
}

/* Makes r the comparison; the one before is stopped (its waits return)
 * and let go. */
static void replace(pfx_compare *c, pfx_compare_ref *r) {
    pthread_mutex_lock(&c->mu);
    pfx_compare_ref *old = c->now;
    c->now = r;
    pthread_mutex_unlock(&c->mu);
    if (old)
        pfx_session_stop(old->session);
    drop(c, old);
}

bool pfx_compare_set(pfx_compare *c, const char *path, bool has_seed, uint64_t seed, pfx_diags *d) {
    replace(c, NULL);
    const char *file = path && *path ? path : c->base.path;
    if (access(file, R_OK) != 0) {
        pfx_diag_error(d, PFX_RULE_MISSING_FILE, "cannot open '%s': %s", file, strerror(errno));
        return false;
    }
    pfx_compare_ref *r = calloc(1, sizeof *r);
    if (!r || !(r->path = strdup(file))) {
        free(r);
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for a comparison");
        return false;
    }
    r->has_seed = has_seed;
    r->seed = seed;
    r->refs = 1;
    pfx_session_options o = c->base;
    o.path = r->path;
    if (has_seed) {
        o.compile.has_seed = true;
        o.compile.seed = seed;
    }
    r->session = pfx_session_create(&o, d);
    if (!r->session) {
        ref_free(r);
        return false;
    }
    replace(c, r);
    return true;
}

void pfx_compare_clear(pfx_compare *c) { replace(c, NULL); }

pfx_compare_ref *pfx_compare_hold(pfx_compare *c) {
    pthread_mutex_lock(&c->mu);
    pfx_compare_ref *r = c->now;
    if (r)
        r->refs++;
    pthread_mutex_unlock(&c->mu);
    return r;
}

void pfx_compare_release(pfx_compare *c, pfx_compare_ref *r) { drop(c, r); }

pfx_session *pfx_compare_session(const pfx_compare_ref *r) { return r->session; }

char *pfx_compare_json(pfx_compare *c) {
    pfx_compare_ref *r = pfx_compare_hold(c);
    json_t *o = r ? json_pack("{s:o, s:o}", "file", pfx_json_bytes(r->path), "seed",
                              r->has_seed ? json_integer((json_int_t)r->seed) : json_null())
                  : json_null();
    pfx_compare_release(c, r);
    /* A file name that is not UTF-8 keeps its bytes (base/json_text.h). */
    json_t *escaped = o ? pfx_json_escaped(o) : NULL;
    char *text = escaped ? json_dumps(escaped, JSON_COMPACT | JSON_ENCODE_ANY) : NULL;
    json_decref(escaped);
    json_decref(o);
    return text;
}

void pfx_compare_destroy(pfx_compare *c) {
    if (!c)
        return;
    replace(c, NULL);
    pthread_mutex_destroy(&c->mu);
    free(c);
}
