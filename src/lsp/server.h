/* The language server (lsp/server.c): LSP 3.17 over a byte stream. One
 * loop reads messages, answers each request from the current state, and
 * analyses a changed document after a short debounce, so that a newer
 * edit supersedes an older one before any work is spent on it. */
#ifndef PFX_LSP_SERVER_H
#define PFX_LSP_SERVER_H

#include <stdbool.h>
#include <stddef.h>

#include "base/diag.h"

/* Milliseconds between the last change of a document and its analysis. */
#define PFX_LSP_DEBOUNCE_MS 100
/* Documents open at once; more are refused (with a message to the user). */
#define PFX_LSP_MAX_DOCS 64
/* Ranged changes applied from one didChange (a client asked for full text
 * sends one). */
#define PFX_LSP_MAX_CHANGES 256

/* Where the server's framed messages go; false when they cannot. */
typedef bool (*pfx_lsp_write_fn)(void *ctx, const char *data, size_t n);

typedef struct pfx_lsp_server pfx_lsp_server;

/* A server writing through write(ctx, ...). NULL when out of memory. */
pfx_lsp_server *pfx_lsp_server_create(pfx_lsp_write_fn write, void *ctx);
void pfx_lsp_server_destroy(pfx_lsp_server *s);

/* Takes n bytes of the client's stream at time now_ms and handles every
 * whole message in it. False when the stream is unusable (a header that
 * cannot be read, reported in `run`) or the client sent `exit`. */
bool pfx_lsp_server_feed(pfx_lsp_server *s, const void *data, size_t n, double now_ms,
                         pfx_diags *run);
/* Milliseconds until the next debounced analysis is due (0: now), or -1
 * when none is pending. */
int pfx_lsp_server_wait_ms(const pfx_lsp_server *s, double now_ms);
/* Analyses every document whose debounce has passed at now_ms (every
 * pending one when `all`), publishing their diagnostics. */
void pfx_lsp_server_tick(pfx_lsp_server *s, double now_ms, bool all);
/* The exit status `exit` asks for: 0 after a shutdown request, 1 otherwise
 * (also when the stream ends without `exit`). */
int pfx_lsp_server_exit_code(const pfx_lsp_server *s);

/* Serves the client on file descriptors in and out until `exit` or the end
 * of in. Returns the exit status; stream failures are reported in run. */
int pfx_lsp_serve(int in, int out, pfx_diags *run);

#endif
