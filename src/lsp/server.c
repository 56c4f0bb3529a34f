/* The language server's state and loop: the lifecycle of LSP 3.17
 * (initialize, initialized, shutdown, exit), the open documents with full
 * text sync, the debounce, and one handler per method in a table. The
 * features themselves live beside it (diagnostics.c, hover.c, ...); this
 * file only routes to them and never reads an effect's tree. */
#include "lsp/server.h"

#include <errno.h>
#include <jansson.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "jobs/estimate.h"
#include "lsp/document.h"
#include "lsp/rpc.h"
#include "parse/node.h"

/* JSON-RPC and LSP error codes. */
enum {
    RPC_PARSE_ERROR = -32700,
    RPC_INVALID_REQUEST = -32600,
    RPC_METHOD_NOT_FOUND = -32601,
    RPC_INVALID_PARAMS = -32602,
    LSP_SERVER_NOT_INITIALIZED = -32002
};

struct pfx_lsp_server {
    pfx_lsp_write_fn write;
    void *ctx;
    pfx_lsp_reader reader;
    bool write_failed; /* the client stopped reading: nothing more can be said */
    int write_errno;
    enum {
        BEFORE_INIT,
        RUNNING,
        SHUT_DOWN,
        EXITED,
        EXITED_EARLY
    } state; /* EXITED_EARLY: exit without shutdown */
    pfx_lsp_doc docs[PFX_LSP_MAX_DOCS];
    size_t doc_count;
};

/* What a handler gives back: a result (requests), or an error. */
typedef struct reply {
    json_t *result;
    int code;
    const char *message;
} reply;

typedef void (*handler_fn)(pfx_lsp_server *s, json_t *params, double now, reply *out);

static void send(pfx_lsp_server *s, json_t *msg) {
    char *body = json_dumps(msg, JSON_COMPACT);
    json_decref(msg);
    if (!body)
        return;
    size_t n;
    char *framed = pfx_lsp_frame_text(body, strlen(body), &n);
    free(body);
    if (framed && !s->write_failed && !s->write(s->ctx, framed, n)) {
        s->write_failed = true;
        s->write_errno = errno;
    }
    free(framed);
}

static void notify(pfx_lsp_server *s, const char *method, json_t *params) {
    send(s, json_pack("{s:s, s:s, s:o}", "jsonrpc", "2.0", "method", method, "params", params));
}

/* ---- documents ---------------------------------------------------------- */

static pfx_lsp_doc *find_doc(pfx_lsp_server *s, json_t *params) {
    const char *uri =
        json_string_value(json_object_get(json_object_get(params, "textDocument"), "uri"));
    for (size_t i = 0; uri && i < s->doc_count; i++)
        if (!strcmp(s->docs[i].uri, uri))
            return &s->docs[i];
    return NULL;
}

/* The file path a file: URI names (percent-decoded), else the URI itself. */
static char *uri_path(const char *uri) {
    const char *p = strncmp(uri, "file://", 7) ? uri : uri + 7;
    char *out = malloc(strlen(p) + 1), *o = out;
    if (!out)
        return NULL;
    for (; *p; p++) {
        unsigned v;
        if (*p == '%' && sscanf(p + 1, "%2x", &v) == 1 && v) {
            *o++ = (char)v;
            p += 2;
        } else
            *o++ = *p;
    }
    *o = 0;
    return out;
}

static void drop_analysis(pfx_lsp_doc *d) {
    if (!d->analysed)
        return;
    pfx_loaded_free(&d->loaded);
    pfx_lsp_text_free(&d->lines);
    d->analysed = false;
}

static void free_doc(pfx_lsp_doc *d) {
    drop_analysis(d);
    free(d->uri);
    free(d->path);
    free(d->text);
    memset(d, 0, sizeof *d);
}

/* Loads and compiles the document's text exactly as `pfx validate` would
 * the file (jobs/load.c, then validate's estimate warnings against its
 * default memory bound, half of this machine's memory), then publishes
 * the diagnostics. */
static void analyse(pfx_lsp_server *s, pfx_lsp_doc *d) {
    drop_analysis(d);
    pfx_compile_options opt = {0};
    pfx_load_bytes(&d->loaded, d->path, d->text, d->len, &opt);
    pfx_estimate_check(&d->loaded, pfx_memory_default_bound());
    d->analysed = true;
    d->pending = false;
    if (!pfx_lsp_text_init(&d->lines, d->loaded.source ? d->loaded.source : "",
                           d->loaded.source ? d->loaded.source_len : 0))
        d->lines.line_count = 0;
    json_t *params = json_pack("{s:s, s:I, s:o}", "uri", d->uri, "version", (json_int_t)d->version,
                               "diagnostics", pfx_lsp_diagnostics(d));
    if (params)
        notify(s, "textDocument/publishDiagnostics", params);
}

/* Replaces d's text with the n bytes at text (copied). Past the largest
 * effect file only one more byte is kept: the load reports the file as too
 * large, and 64 hostile documents cost at most 64 times 16 MiB. */
static bool set_text(pfx_lsp_doc *d, const char *text, size_t n) {
    if (n > PFX_MAX_FILE_BYTES)
        n = PFX_MAX_FILE_BYTES + 1;
    char *copy = malloc(n + 1);
    if (!copy)
        return false;
    memcpy(copy, text, n);
    copy[n] = 0;
    free(d->text);
    d->text = copy;
    d->len = n;
    return true;
}

/* ---- handlers ----------------------------------------------------------- */

static void on_initialize(pfx_lsp_server *s, json_t *params, double now, reply *out) {
    (void)params, (void)now;
    if (s->state != BEFORE_INIT) {
        out->code = RPC_INVALID_REQUEST;
        out->message = "initialize was already sent";
        return;
    }
    s->state = RUNNING;
    out->result =
        json_pack("{s:{s:{s:b, s:i}, s:b, s:{s:[s,s,s,s]}, s:b, s:b, s:b, s:b, s:{s:[s]}, s:b}, "
                  "s:{s:s, s:s}}",
                  "capabilities", "textDocumentSync", "openClose", 1, "change", 1, "hoverProvider",
                  1, "completionProvider", "triggerCharacters", ":", " ", "[", ",",
                  "documentSymbolProvider", 1, "definitionProvider", 1, "referencesProvider", 1,
                  "renameProvider", 1, "codeActionProvider", "codeActionKinds", "quickfix",
                  "colorProvider", 1, "serverInfo", "name", "pfx", "version", PFX_VERSION);
}

static void on_nothing(pfx_lsp_server *s, json_t *params, double now, reply *out) {
    (void)s, (void)params, (void)now, (void)out;
}

static void on_shutdown(pfx_lsp_server *s, json_t *params, double now, reply *out) {
    (void)params, (void)now;
    s->state = SHUT_DOWN;
    out->result = json_null();
}

static void on_exit_message(pfx_lsp_server *s, json_t *params, double now, reply *out) {
    (void)params, (void)now, (void)out;
    s->state = s->state == SHUT_DOWN ? EXITED : EXITED_EARLY;
}

static void on_did_open(pfx_lsp_server *s, json_t *params, double now, reply *out) {
    (void)out;
    json_t *td = json_object_get(params, "textDocument");
    const char *uri = json_string_value(json_object_get(td, "uri"));
    json_t *text = json_object_get(td, "text");
    if (!uri || !json_is_string(text))
        return;
    pfx_lsp_doc *d = find_doc(s, params);
    if (!d) {
        if (s->doc_count == PFX_LSP_MAX_DOCS) {
            notify(s, "window/showMessage",
                   json_pack("{s:i, s:s}", "type", 2, "message",
                             "pfx: too many open effect files; close some to check this one"));
            return;
        }
        d = &s->docs[s->doc_count];
        d->uri = strdup(uri);
        d->path = uri_path(uri);
        if (!d->uri || !d->path) {
            free_doc(d);
            return;
        }
        s->doc_count++;
    }
    if (!set_text(d, json_string_value(text), json_string_length(text)))
        return;
    d->version = (long)json_integer_value(json_object_get(td, "version"));
    d->pending = true;
    d->due_ms = now; /* a file just opened is checked at once */
}

static void on_did_change(pfx_lsp_server *s, json_t *params, double now, reply *out) {
    (void)out;
    pfx_lsp_doc *d = find_doc(s, params);
    json_t *changes = json_object_get(params, "contentChanges");
    size_t i;
    json_t *c;
    if (!d)
        return;
    json_array_foreach(changes, i, c) {
        if (i == PFX_LSP_MAX_CHANGES)
            break; /* each ranged change costs a pass over the text */
        json_t *text = json_object_get(c, "text");
        json_t *range = json_object_get(c, "range");
        if (!json_is_string(text))
            continue;
        if (!range) {
            set_text(d, json_string_value(text), json_string_length(text));
            continue;
        }
        /* An incremental change, though the server asks for full text. */
        pfx_lsp_text t;
        if (!pfx_lsp_text_init(&t, d->text, d->len))
            continue;
        json_t *st = json_object_get(range, "start"), *en = json_object_get(range, "end");
        size_t a = pfx_lsp_offset(&t, (int)json_integer_value(json_object_get(st, "line")),
                                  (int)json_integer_value(json_object_get(st, "character")));
        size_t b = pfx_lsp_offset(&t, (int)json_integer_value(json_object_get(en, "line")),
                                  (int)json_integer_value(json_object_get(en, "character")));
        pfx_lsp_text_free(&t);
        if (b < a)
            b = a;
        size_t tn = json_string_length(text), n = d->len - (b - a) + tn;
        if (n > PFX_MAX_FILE_BYTES + 1) { /* too large: keep it so, as set_text would */
            tn = tn > n - (PFX_MAX_FILE_BYTES + 1) ? tn - (n - (PFX_MAX_FILE_BYTES + 1)) : 0;
            n = d->len - (b - a) + tn;
        }
        char *nt = malloc(n + 1);
        if (!nt)
            continue;
        memcpy(nt, d->text, a);
        memcpy(nt + a, json_string_value(text), tn);
        memcpy(nt + a + tn, d->text + b, d->len - b);
        nt[n] = 0;
        free(d->text);
        d->text = nt;
        d->len = n;
    }
    d->version = (long)json_integer_value(
        json_object_get(json_object_get(params, "textDocument"), "version"));
    d->pending = true;
    d->due_ms = now + PFX_LSP_DEBOUNCE_MS; /* a newer change moves it on */
}

static void on_did_close(pfx_lsp_server *s, json_t *params, double now, reply *out) {
    (void)now, (void)out;
    pfx_lsp_doc *d = find_doc(s, params);
    if (!d)
        return;
    /* Clear its diagnostics: the editor no longer shows the file. */
    notify(s, "textDocument/publishDiagnostics",
           json_pack("{s:s, s:[]}", "uri", d->uri, "diagnostics"));
    free_doc(d);
    *d = s->docs[--s->doc_count];
    memset(&s->docs[s->doc_count], 0, sizeof s->docs[0]);
}

/* The document a request names, analysed if an edit is pending (so that
 * the answer is about the text the user sees); NULL with an error. */
static pfx_lsp_doc *request_doc(pfx_lsp_server *s, json_t *params, reply *out) {
    pfx_lsp_doc *d = find_doc(s, params);
    if (!d) {
        out->code = RPC_INVALID_PARAMS;
        out->message = "the document is not open";
        return NULL;
    }
    if (d->pending || !d->analysed)
        analyse(s, d);
    return d;
}

static void position(json_t *params, int *line, int *character) {
    json_t *p = json_object_get(params, "position");
    *line = (int)json_integer_value(json_object_get(p, "line"));
    *character = (int)json_integer_value(json_object_get(p, "character"));
}

#define DOC_REQUEST(fn, body)                                                                      \
    static void fn(pfx_lsp_server *s, json_t *params, double now, reply *out) {                    \
        (void)now;                                                                                 \
        pfx_lsp_doc *d = request_doc(s, params, out);                                              \
        int line, character;                                                                       \
        position(params, &line, &character);                                                       \
        (void)line, (void)character;                                                               \
        if (d && !(out->result = body)) {                                                          \
            out->code = RPC_INVALID_PARAMS;                                                        \
            out->message = "the new name must be a plain key (letters, digits, '_', '-') that "    \
                           "no other of its kind has";                                             \
        }                                                                                          \
    }
DOC_REQUEST(on_hover, pfx_lsp_hover(d, line, character))
DOC_REQUEST(on_completion, pfx_lsp_completion(d, line, character))
DOC_REQUEST(on_symbols, pfx_lsp_symbols(d))
DOC_REQUEST(on_definition, pfx_lsp_definition(d, line, character))
DOC_REQUEST(on_references,
            pfx_lsp_references(d, line, character,
                               json_is_true(json_object_get(json_object_get(params, "context"),
                                                            "includeDeclaration"))))
DOC_REQUEST(on_rename, pfx_lsp_rename(d, line, character,
                                      json_string_value(json_object_get(params, "newName"))))
DOC_REQUEST(on_code_action, pfx_lsp_code_actions(d, params))
DOC_REQUEST(on_colors, pfx_lsp_colors(d))
DOC_REQUEST(on_color_presentation, pfx_lsp_color_presentations(d, params))

/* The methods, one row each: a request gets a response, a notification
 * none. `any_time`: allowed before initialize and after shutdown. */
typedef struct method_row {
    const char *name;
    handler_fn fn;
    bool any_time;
} method_row;

static const method_row methods[] = {
    {"initialize", on_initialize, true},
    {"initialized", on_nothing, false},
    {"shutdown", on_shutdown, false},
    {"exit", on_exit_message, true},
    {"textDocument/didOpen", on_did_open, false},
    {"textDocument/didChange", on_did_change, false},
    {"textDocument/didClose", on_did_close, false},
    {"textDocument/didSave", on_nothing, false},
    {"textDocument/hover", on_hover, false},
    {"textDocument/completion", on_completion, false},
    {"textDocument/documentSymbol", on_symbols, false},
    {"textDocument/definition", on_definition, false},
    {"textDocument/references", on_references, false},
    {"textDocument/rename", on_rename, false},
    {"textDocument/codeAction", on_code_action, false},
    {"textDocument/documentColor", on_colors, false},
    {"textDocument/colorPresentation", on_color_presentation, false},
};

static void respond(pfx_lsp_server *s, json_t *id, reply *r) {
    json_t *msg = json_pack("{s:s, s:O}", "jsonrpc", "2.0", "id", id ? id : json_null());
    if (!msg)
        return;
    if (r->code)
        json_object_set_new(msg, "error",
                            json_pack("{s:i, s:s}", "code", r->code, "message", r->message));
    else
        json_object_set_new(msg, "result", r->result ? r->result : json_null());
    send(s, msg);
}

static void handle(pfx_lsp_server *s, const char *body, size_t len, double now) {
    json_error_t err;
    json_t *msg = json_loadb(body, len, 0, &err);
    reply r = {0};
    if (!msg) {
        r.code = RPC_PARSE_ERROR;
        r.message = "the message is not JSON";
        respond(s, NULL, &r);
        return;
    }
    json_t *id = json_object_get(msg, "id");
    const char *method = json_string_value(json_object_get(msg, "method"));
    bool request = id && (json_is_integer(id) || json_is_string(id));
    if (!method) {
        if (json_is_object(msg) && id &&
            (json_object_get(msg, "result") || json_object_get(msg, "error"))) {
            json_decref(msg); /* a response to a request of ours: none is sent */
            return;
        }
        r.code = RPC_INVALID_REQUEST;
        r.message = "the message has no method";
        respond(s, request ? id : NULL, &r);
        json_decref(msg);
        return;
    }
    const method_row *row = NULL;
    for (size_t i = 0; i < sizeof methods / sizeof methods[0]; i++)
        if (!strcmp(methods[i].name, method))
            row = &methods[i];
    json_t *params = json_object_get(msg, "params");
    if (!row) {
        r.code = RPC_METHOD_NOT_FOUND;
        r.message = "pfx does not handle this method";
    } else if (!row->any_time && s->state == BEFORE_INIT) {
        r.code = LSP_SERVER_NOT_INITIALIZED;
        r.message = "the server is not initialized";
    } else if (!row->any_time && s->state == SHUT_DOWN) {
        r.code = RPC_INVALID_REQUEST;
        r.message = "the server is shut down";
    } else {
        row->fn(s, params, now, &r);
    }
    if (request)
        respond(s, id, &r);
    else if (r.result)
        json_decref(r.result);
    json_decref(msg);
}

/* ---- the server --------------------------------------------------------- */

pfx_lsp_server *pfx_lsp_server_create(pfx_lsp_write_fn write, void *ctx) {
    pfx_lsp_server *s = calloc(1, sizeof *s);
    if (s) {
        s->write = write;
        s->ctx = ctx;
    }
    return s;
}

void pfx_lsp_server_destroy(pfx_lsp_server *s) {
    if (!s)
        return;
    for (size_t i = 0; i < s->doc_count; i++)
        free_doc(&s->docs[i]);
    pfx_lsp_reader_free(&s->reader);
    free(s);
}

bool pfx_lsp_server_feed(pfx_lsp_server *s, const void *data, size_t n, double now_ms,
                         pfx_diags *run) {
    if (s->state >= EXITED || !pfx_lsp_reader_feed(&s->reader, data, n, run))
        return false;
    for (;;) {
        char *body;
        size_t len;
        pfx_lsp_frame f = pfx_lsp_reader_next(&s->reader, &body, &len, run);
        if (f == PFX_LSP_FRAME_BAD)
            return false;
        if (f == PFX_LSP_FRAME_MORE)
            return true;
        handle(s, body, len, now_ms);
        if (s->state >= EXITED || s->write_failed)
            return false;
    }
}

int pfx_lsp_server_wait_ms(const pfx_lsp_server *s, double now_ms) {
    double due = -1;
    for (size_t i = 0; i < s->doc_count; i++)
        if (s->docs[i].pending && (due < 0 || s->docs[i].due_ms < due))
            due = s->docs[i].due_ms;
    if (due < 0)
        return -1;
    return due <= now_ms ? 0 : (int)(due - now_ms) + 1;
}

void pfx_lsp_server_tick(pfx_lsp_server *s, double now_ms, bool all) {
    for (size_t i = 0; i < s->doc_count; i++)
        if (s->docs[i].pending && (all || s->docs[i].due_ms <= now_ms))
            analyse(s, &s->docs[i]);
}

int pfx_lsp_server_exit_code(const pfx_lsp_server *s) { return s->state == EXITED ? 0 : 1; }

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static bool write_fd(void *ctx, const char *data, size_t n) {
    int fd = *(int *)ctx;
    while (n) {
        ssize_t w = write(fd, data, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return false;
        data += w;
        n -= (size_t)w;
    }
    return true;
}

/* Whether fd has bytes to read within wait milliseconds (-1: for ever). */
static int readable(int fd, int wait) {
    struct pollfd p = {.fd = fd, .events = POLLIN};
    int r;
    while ((r = poll(&p, 1, wait)) < 0 && errno == EINTR)
        ;
    return r;
}

int pfx_lsp_serve(int in, int out, pfx_diags *run) {
    pfx_lsp_server *s = pfx_lsp_server_create(write_fd, &out);
    if (!s) {
        pfx_diag_error(run, PFX_RULE_OUT_OF_MEMORY, "out of memory for the language server");
        return 1;
    }
    /* A client that goes away mid-answer is a failed write (EPIPE), not a
     * signal that kills the server before it can say so. */
    signal(SIGPIPE, SIG_IGN);
    static char buf[65536];
    for (;;) {
        /* Input first: every message waiting is handled before an analysis
         * runs, so a burst of edits costs one compile, of the newest text. */
        int r = readable(in, pfx_lsp_server_wait_ms(s, now_ms()));
        if (r < 0)
            break;
        if (r == 0) {
            pfx_lsp_server_tick(s, now_ms(), false);
            if (s->write_failed)
                break;
            continue;
        }
        ssize_t n = read(in, buf, sizeof buf);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0 || !pfx_lsp_server_feed(s, buf, (size_t)n, now_ms(), run))
            break;
    }
    int status = pfx_lsp_server_exit_code(s);
    if (s->write_failed)
        pfx_diag_error(run, PFX_RULE_WRITE_FAILED, "cannot write to the editor: %s",
                       strerror(s->write_errno));
    pfx_lsp_server_destroy(s);
    return status;
}
