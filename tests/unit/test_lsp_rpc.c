/* The language server's two exact conversions: LSP framing (a message cut
 * at its Content-Length however the bytes arrive, bad headers refused) and
 * positions (pfx's character columns to LSP's UTF-16 units and back, with
 * known answers for ASCII, two-byte, three-byte and four-byte UTF-8). */
#include <string.h>

#include "lsp/position.h"
#include "lsp/rpc.h"
#include "test.h"

static void framing_whole_and_split(void) {
    const char *stream = "Content-Length: 2\r\n\r\n{}content-length:3\r\nX: y\r\n\r\n[1]";
    size_t n = strlen(stream);
    for (size_t cut = 0; cut <= n; cut++) { /* every split into two reads */
        pfx_lsp_reader r = {0};
        pfx_diags d;
        pfx_diags_init_runtime(&d);
        char *body;
        size_t len;
        int got = 0;
        CHECK(pfx_lsp_reader_feed(&r, stream, cut, &d));
        while (pfx_lsp_reader_next(&r, &body, &len, &d) == PFX_LSP_FRAME_OK)
            got++;
        CHECK(pfx_lsp_reader_feed(&r, stream + cut, n - cut, &d));
        pfx_lsp_frame f;
        while ((f = pfx_lsp_reader_next(&r, &body, &len, &d)) == PFX_LSP_FRAME_OK) {
            got++;
            if (got == 2)
                CHECK(len == 3 && !memcmp(body, "[1]", 3));
        }
        CHECK(got == 2 && f == PFX_LSP_FRAME_MORE && d.errors == 0);
        pfx_lsp_reader_free(&r);
        pfx_diags_free(&d);
    }
}

static void framing_bad_headers(void) {
    const char *bad[] = {"Content-Length: x\r\n\r\n", "Content-Type: a\r\n\r\n",
                         "Content-Length: 33554433\r\n\r\n", "Content-Length: -1\r\n\r\n"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        pfx_lsp_reader r = {0};
        pfx_diags d;
        pfx_diags_init_runtime(&d);
        char *body;
        size_t len;
        CHECK(pfx_lsp_reader_feed(&r, bad[i], strlen(bad[i]), &d));
        CHECK(pfx_lsp_reader_next(&r, &body, &len, &d) == PFX_LSP_FRAME_BAD);
        CHECK(d.errors == 1);
        pfx_lsp_reader_free(&r);
        pfx_diags_free(&d);
    }
}

static void positions_utf16(void) {
    /* "é" is 2 bytes and 1 unit, "€" 3 bytes and 1 unit, "😀" 4 bytes and 2 units. */
    const char *text = "ab\n\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80x: 1\r\nlast";
    pfx_lsp_text t;
    CHECK(pfx_lsp_text_init(&t, text, strlen(text)));
    CHECK(t.line_count == 3);
    CHECK(pfx_lsp_char_of_col(&t, 2, 1) == 0);
    CHECK(pfx_lsp_char_of_col(&t, 2, 3) == 2);  /* after é and € */
    CHECK(pfx_lsp_char_of_col(&t, 2, 4) == 4);  /* after the emoji: two units */
    CHECK(pfx_lsp_char_of_col(&t, 2, 99) == 8); /* clamped to the line, \r excluded */
    CHECK(pfx_lsp_offset(&t, 1, 4) == 3 + 9);   /* the 'x' */
    CHECK(pfx_lsp_col_of_char(&t, 1, 4) == 4);
    int line, ch;
    pfx_lsp_position(&t, 3 + 9, &line, &ch);
    CHECK(line == 1 && ch == 4);
    pfx_lsp_position(&t, strlen(text), &line, &ch);
    CHECK(line == 2 && ch == 4);
    CHECK(pfx_lsp_offset(&t, 7, 0) == strlen(text));
    pfx_lsp_text_free(&t);
}

int main(void) {
    RUN(framing_whole_and_split);
    RUN(framing_bad_headers);
    RUN(positions_utf16);
    return TEST_EXIT();
}
