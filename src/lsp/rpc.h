/* JSON-RPC framing of the Language Server Protocol (lsp/rpc.c): messages
 * cut from a byte stream by their Content-Length header, bounded in size,
 * and messages written with one. It knows nothing of methods; the server
 * (lsp/server.c) gives meaning to the bodies. */
#ifndef PFX_LSP_RPC_H
#define PFX_LSP_RPC_H

#include <stdbool.h>
#include <stddef.h>

#include "base/diag.h"

/* A message body is at most this many bytes (an effect file is at most
 * 16 MiB, and its text travels inside JSON, escaped). */
#define PFX_LSP_MAX_BODY (32u << 20)
/* The header part is at most this many bytes. */
#define PFX_LSP_MAX_HEADER 8192u

/* Bytes received and not yet cut into messages. */
typedef struct pfx_lsp_reader {
    char *buf;
    size_t len, cap;
    size_t done; /* bytes of the last message returned, dropped at the next call */
} pfx_lsp_reader;

typedef enum {
    PFX_LSP_FRAME_MORE, /* no whole message yet: feed more bytes */
    PFX_LSP_FRAME_OK,   /* *body (in the reader, not NUL-terminated) holds one */
    PFX_LSP_FRAME_BAD   /* a header that cannot be read, reported in d: the
                           stream cannot be resynchronised */
} pfx_lsp_frame;

/* Appends n bytes to r. False (reported in d) when out of memory. */
bool pfx_lsp_reader_feed(pfx_lsp_reader *r, const void *data, size_t n, pfx_diags *d);
/* Cuts the next message. The body stays valid until the next call. */
pfx_lsp_frame pfx_lsp_reader_next(pfx_lsp_reader *r, char **body, size_t *len, pfx_diags *d);
void pfx_lsp_reader_free(pfx_lsp_reader *r);

/* The framed form of body: "Content-Length: N\r\n\r\n" then the body, in a
 * malloc'd buffer of *out_len bytes (NULL when out of memory). */
char *pfx_lsp_frame_text(const char *body, size_t len, size_t *out_len);

#endif
