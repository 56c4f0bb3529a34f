/* Cutting LSP messages out of a byte stream: a header part of
 * "Name: value\r\n" lines ending in an empty line, of which only
 * Content-Length matters, then that many bytes of JSON. Sizes are bounded
 * before anything is allocated for them; a header that cannot be read is
 * an error, since nothing says where the next message starts. */
#include "lsp/rpc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

bool pfx_lsp_reader_feed(pfx_lsp_reader *r, const void *data, size_t n, pfx_diags *d) {
    if (r->done) { /* drop the message handed out last time */
        memmove(r->buf, r->buf + r->done, r->len - r->done);
        r->len -= r->done;
        r->done = 0;
    }
    if (r->len + n + 1 > r->cap) {
        size_t cap = r->cap ? r->cap : 65536;
        while (cap < r->len + n + 1)
            cap *= 2;
        char *nb = realloc(r->buf, cap);
        if (!nb) {
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for an LSP message");
            return false;
        }
        r->buf = nb;
        r->cap = cap;
    }
    memcpy(r->buf + r->len, data, n);
    r->len += n;
    return true;
}

/* The end of the header part (the index after its empty line), or 0. */
static size_t header_end(const char *buf, size_t len) {
    for (size_t i = 0; i + 3 < len; i++)
        if (buf[i] == '\r' && buf[i + 1] == '\n' && buf[i + 2] == '\r' && buf[i + 3] == '\n')
            return i + 4;
    return 0;
}

/* Content-Length from the header lines in h (n bytes); -1 when missing or
 * not a number, -2 when above the bound. */
static long long content_length(const char *h, size_t n) {
    long long found = -1;
    for (size_t i = 0; i < n;) {
        size_t e = i;
        while (e < n && h[e] != '\r')
            e++;
        static const char name[] = "content-length:";
        size_t nl = sizeof name - 1;
        if (e - i > nl && !strncasecmp(h + i, name, nl)) {
            size_t p = i + nl;
            while (p < e && h[p] == ' ')
                p++;
            if (p == e)
                return -1;
            unsigned long long v = 0;
            for (; p < e; p++) {
                if (h[p] < '0' || h[p] > '9')
                    return -1;
                v = v * 10 + (unsigned)(h[p] - '0');
                if (v > PFX_LSP_MAX_BODY)
                    return -2;
            }
            found = (long long)v;
        }
        i = e + 2;
    }
    return found;
}

pfx_lsp_frame pfx_lsp_reader_next(pfx_lsp_reader *r, char **body, size_t *len, pfx_diags *d) {
    if (r->done) {
        memmove(r->buf, r->buf + r->done, r->len - r->done);
        r->len -= r->done;
        r->done = 0;
    }
    size_t scan = r->len < PFX_LSP_MAX_HEADER ? r->len : PFX_LSP_MAX_HEADER;
    size_t h = header_end(r->buf, scan);
    if (!h) {
        if (r->len >= PFX_LSP_MAX_HEADER) {
            pfx_diag_error(d, PFX_RULE_READ_FAILED,
                           "cannot read an LSP message: no end of its header in %u bytes",
                           PFX_LSP_MAX_HEADER);
            return PFX_LSP_FRAME_BAD;
        }
        return PFX_LSP_FRAME_MORE;
    }
    long long n = content_length(r->buf, h - 4);
    if (n == -2) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED,
                       "cannot read an LSP message: its Content-Length is above %u MiB",
                       PFX_LSP_MAX_BODY >> 20);
        return PFX_LSP_FRAME_BAD;
    }
    if (n < 0) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED,
                       "cannot read an LSP message: its header has no valid Content-Length");
        return PFX_LSP_FRAME_BAD;
    }
    if (r->len - h < (size_t)n)
        return PFX_LSP_FRAME_MORE;
    *body = r->buf + h;
    *len = (size_t)n;
    r->done = h + (size_t)n;
    return PFX_LSP_FRAME_OK;
}

void pfx_lsp_reader_free(pfx_lsp_reader *r) {
    free(r->buf);
    memset(r, 0, sizeof *r);
}

char *pfx_lsp_frame_text(const char *body, size_t len, size_t *out_len) {
    char head[48];
    int hn = snprintf(head, sizeof head, "Content-Length: %zu\r\n\r\n", len);
    char *out = malloc((size_t)hn + len);
    if (!out)
        return NULL;
    memcpy(out, head, (size_t)hn);
    memcpy(out + hn, body, len);
    *out_len = (size_t)hn + len;
    return out;
}
