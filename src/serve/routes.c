/* The preview's routes, one row each: the page's three files, the state,
 * a frame, the event stream and pick. Every path not in the table is a
 * 404; files come from the binary (page_assets.c), never the disk. */
#include "serve/routes.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "serve/page_assets.h"

/* Every answer: its type, never cached, never sniffed as another type;
 * queued, and the reference dropped (libmicrohttpd keeps its own). */
static enum MHD_Result queue(struct MHD_Connection *conn, unsigned status, struct MHD_Response *r,
                             const char *type) {
    MHD_add_response_header(r, "Content-Type", type);
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    enum MHD_Result ret = MHD_queue_response(conn, status, r);
    MHD_destroy_response(r);
    return ret;
}

enum MHD_Result pfx_route_text(struct MHD_Connection *conn, unsigned status, const char *type,
                               const char *text) {
    struct MHD_Response *r =
        MHD_create_response_from_buffer(strlen(text), (void *)text, MHD_RESPMEM_MUST_COPY);
    return r ? queue(conn, status, r, type) : MHD_NO;
}

/* A response owning a malloc'd body (libmicrohttpd frees it); the body
 * freed here when there is none. */
static struct MHD_Response *owned(void *body, size_t len) {
    struct MHD_Response *r = MHD_create_response_from_buffer(len, body, MHD_RESPMEM_MUST_FREE);
    if (!r)
        free(body);
    return r;
}

static enum MHD_Result send_owned(struct MHD_Connection *conn, const char *type, void *body,
                                  size_t len) {
    struct MHD_Response *r = owned(body, len);
    return r ? queue(conn, MHD_HTTP_OK, r, type) : MHD_NO;
}

static enum MHD_Result send_asset(struct MHD_Connection *conn, const pfx_page_asset *a,
                                  const char *set_cookie) {
    struct MHD_Response *r =
        MHD_create_response_from_buffer(a->len, (void *)a->bytes, MHD_RESPMEM_PERSISTENT);
    if (!r)
        return MHD_NO;
    if (set_cookie)
        MHD_add_response_header(r, "Set-Cookie", set_cookie);
    /* The page loads nothing from elsewhere: no CDN, no inline script. */
    MHD_add_response_header(r, "Content-Security-Policy",
                            "default-src 'self'; img-src 'self' blob: data:; "
                            "connect-src 'self'; frame-ancestors 'none'");
    return queue(conn, MHD_HTTP_OK, r, a->type);
}

static enum MHD_Result route_index(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                   const char *url) {
    (void)url;
    return send_asset(conn, &pfx_page_index_html, c->set_cookie);
}

static enum MHD_Result route_js(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                const char *url) {
    (void)c;
    (void)url;
    return send_asset(conn, &pfx_page_app_js, NULL);
}

static enum MHD_Result route_css(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                 const char *url) {
    (void)c;
    (void)url;
    return send_asset(conn, &pfx_page_style_css, NULL);
}

/* True when the request names the comparison: ?variant=compare. */
static bool wants_compare(struct MHD_Connection *conn) {
    const char *v = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "variant");
    return v && !strcmp(v, "compare");
}

static enum MHD_Result no_compare(struct MHD_Connection *conn) {
    return pfx_route_text(conn, MHD_HTTP_NOT_FOUND, "text/plain", "pfx: nothing is compared\n");
}

/* The session a request names: the edited file's, or with
 * ?variant=compare the comparison's, held in *held until release() (a new
 * comparison may replace it meanwhile). NULL when the comparison is asked
 * for and there is none. */
static pfx_session *session_of(const pfx_route_ctx *c, struct MHD_Connection *conn,
                               pfx_compare_ref **held) {
    *held = NULL;
    if (!wants_compare(conn))
        return c->session;
    *held = c->compare ? pfx_compare_hold(c->compare) : NULL;
    return *held ? pfx_compare_session(*held) : NULL;
}

static void release(const pfx_route_ctx *c, pfx_compare_ref *held) {
    if (held)
        pfx_compare_release(c->compare, held);
}

/* The edited file's state with what it is compared with ("compare": null
 * or {file, seed}) as its last key; with ?variant=compare, the
 * comparison's own state. */
static enum MHD_Result route_state(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                   const char *url) {
    (void)url;
    char *json = NULL;
    if (wants_compare(conn)) {
        pfx_compare_ref *held;
        pfx_session *session = session_of(c, conn, &held);
        if (!session)
            return no_compare(conn);
        json = pfx_session_state_json(session);
        release(c, held);
    } else {
        char *state = pfx_session_state_json(c->session);
        char *with = c->compare ? pfx_compare_json(c->compare) : strdup("null");
        size_t n = state ? strlen(state) : 0;
        /* state is one compact object: its closing brace gives way. */
        if (state && with && n > 2 && (json = malloc(n + strlen(with) + 16)))
            sprintf(json, "%.*s,\"compare\":%s}", (int)(n - 1), state, with);
        free(state);
        free(with);
    }
    if (!json)
        return pfx_route_text(conn, MHD_HTTP_INTERNAL_SERVER_ERROR, "text/plain",
                              "out of memory\n");
    return send_owned(conn, "application/json", json, strlen(json));
}

/* POST /api/compare?file=PATH&seed=N: compare with another file (relative
 * to pfx's directory; none: the edited one) and/or another seed; neither:
 * compare with nothing. The comparison's state, or 400 with the reason. */
static enum MHD_Result route_compare(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                     const char *url) {
    (void)url;
    const char *file = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "file");
    const char *seed = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "seed");
    if (!c->compare)
        return no_compare(conn);
    if (!(file && *file) && !(seed && *seed)) {
        pfx_compare_clear(c->compare);
        return pfx_route_text(conn, MHD_HTTP_OK, "application/json", "null");
    }
    char *end = NULL;
    errno = 0;
    unsigned long long n = seed && *seed ? strtoull(seed, &end, 10) : 0;
    if (seed && *seed && (*end || errno || *seed == '-'))
        return pfx_route_text(conn, MHD_HTTP_BAD_REQUEST, "text/plain",
                              "pfx: seed takes a whole number from 0 to 2^64 - 1\n");
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    bool ok = pfx_compare_set(c->compare, file, seed && *seed, n, &d);
    char *text = NULL;
    size_t len = 0;
    FILE *f = ok ? NULL : open_memstream(&text, &len);
    if (f) {
        pfx_diags_print(&d, f, false);
        fclose(f);
    }
    pfx_diags_free(&d);
    if (!ok) {
        enum MHD_Result ret = pfx_route_text(conn, MHD_HTTP_BAD_REQUEST, "text/plain",
                                             text ? text : "pfx: cannot compare\n");
        free(text);
        return ret;
    }
    char *json = pfx_compare_json(c->compare);
    if (!json)
        return pfx_route_text(conn, MHD_HTTP_INTERNAL_SERVER_ERROR, "text/plain",
                              "out of memory\n");
    return send_owned(conn, "application/json", json, strlen(json));
}

/* A whole number from 0 to 10^8 filling s, or -1. */
static long parse_index(const char *s, size_t n) {
    long v = 0;
    if (!s || n == 0 || n > 9)
        return -1;
    for (size_t i = 0; i < n; i++) {
        if (s[i] < '0' || s[i] > '9')
            return -1;
        v = v * 10 + (s[i] - '0');
    }
    return v;
}

static long arg_index(struct MHD_Connection *conn, const char *name) {
    const char *v = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, name);
    return v ? parse_index(v, strlen(v)) : -1;
}

/* How long a frame request waits for its frame to be rendered. */
#define FRAME_WAIT_MS 60000

static enum MHD_Result route_frame(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                   const char *url) {
    const char *digits = url + strlen("/frame/");
    long k = parse_index(digits, strlen(digits) - strlen(".png"));
    void *png = NULL;
    size_t len = 0;
    unsigned version = 0;
    const char *ahead = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "ahead");
    pfx_compare_ref *held;
    pfx_session *session = session_of(c, conn, &held);
    if (!session)
        return no_compare(conn);
    int got = k < 0 ? 0
                    : pfx_session_frame(session, k, ahead && !strcmp(ahead, "1"), FRAME_WAIT_MS,
                                        &png, &len, &version);
    release(c, held);
    if (got == 0)
        return pfx_route_text(conn, MHD_HTTP_NOT_FOUND, "text/plain", "pfx: no such frame\n");
    if (got < 0)
        return pfx_route_text(conn, MHD_HTTP_SERVICE_UNAVAILABLE, "text/plain",
                              "pfx: the frame could not be rendered\n");
    struct MHD_Response *r = owned(png, len);
    if (!r)
        return MHD_NO;
    char v[16];
    snprintf(v, sizeof v, "%u", version);
    MHD_add_response_header(r, "X-Pfx-Version", v);
    return queue(conn, MHD_HTTP_OK, r, "image/png");
}

/* The emitters under a pixel; with ?variant=compare, the comparison's
 * (its lines are in its own file), held meanwhile as route_frame does. */
static enum MHD_Result route_pick(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                  const char *url) {
    (void)url;
    long k = arg_index(conn, "frame"), x = arg_index(conn, "x"), y = arg_index(conn, "y");
    pfx_compare_ref *held;
    pfx_session *session = session_of(c, conn, &held);
    if (!session)
        return no_compare(conn);
    char *json = k < 0 || x < 0 || y < 0 ? NULL : pfx_session_pick_json(session, k, (int)x, (int)y);
    release(c, held);
    if (!json)
        return pfx_route_text(conn, MHD_HTTP_BAD_REQUEST, "text/plain",
                              "pfx: pick takes frame, x and y inside the frame\n");
    return send_owned(conn, "application/json", json, strlen(json));
}

/* Server-sent events: one `news` event (the version and the news count)
 * each time the session has news, a comment every 15 s to keep the
 * connection open, the end when the server stops. */
typedef struct event_stream {
    const pfx_route_ctx *c;
    unsigned seen;
    bool greeted;
} event_stream;

static ssize_t read_events(void *cls, uint64_t pos, char *buf, size_t max) {
    (void)pos;
    event_stream *es = cls;
    if (atomic_load(es->c->stopping))
        return MHD_CONTENT_READER_END_OF_STREAM;
    if (!es->greeted) {
        es->greeted = true;
        return snprintf(buf, max, "retry: 500\n\n");
    }
    unsigned news = pfx_session_wait(es->c->session, es->seen, 15000);
    if (atomic_load(es->c->stopping))
        return MHD_CONTENT_READER_END_OF_STREAM;
    if (news == es->seen)
        return snprintf(buf, max, ": still here\n\n");
    es->seen = news;
    return snprintf(buf, max, "event: news\ndata: {\"news\": %u}\n\n", news);
}

static enum MHD_Result route_events(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                    const char *url) {
    (void)url;
    event_stream *es = calloc(1, sizeof *es);
    if (!es)
        return MHD_NO;
    es->c = c;
    /* News from now on; the page reads the state when the stream opens. */
    es->seen = pfx_session_wait(c->session, ~0u, 0);
    struct MHD_Response *r =
        MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 1024, read_events, es, free);
    if (!r) {
        free(es);
        return MHD_NO;
    }
    return queue(conn, MHD_HTTP_OK, r, "text/event-stream");
}

/* A path pattern: exact, or a prefix and a suffix around digits. */
static const struct {
    const char *method, *path, *suffix; /* suffix NULL: path is exact */
    pfx_route_fn fn;
} routes[] = {
    {"GET", "/", NULL, route_index},         {"GET", "/app.js", NULL, route_js},
    {"GET", "/style.css", NULL, route_css},  {"GET", "/api/state", NULL, route_state},
    {"GET", "/events", NULL, route_events},  {"GET", "/pick", NULL, route_pick},
    {"GET", "/frame/", ".png", route_frame}, {"POST", "/api/compare", NULL, route_compare},
};

pfx_route_fn pfx_route_find(const char *method, const char *url) {
    size_t n = strlen(url);
    for (size_t i = 0; i < sizeof routes / sizeof routes[0]; i++) {
        if (strcmp(method, routes[i].method))
            continue;
        if (!routes[i].suffix) {
            if (!strcmp(url, routes[i].path))
                return routes[i].fn;
            continue;
        }
        size_t p = strlen(routes[i].path), s = strlen(routes[i].suffix);
        if (n > p + s && !strncmp(url, routes[i].path, p) &&
            !strcmp(url + n - s, routes[i].suffix) && parse_index(url + p, n - p - s) >= 0)
            return routes[i].fn;
    }
    return NULL;
}
