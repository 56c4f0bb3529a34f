/* libFuzzer target: pfx lsp's message streams. An input that starts with
 * "Content-Length" is fed as it is, in two reads (the framing's own
 * corners); any other is a list of JSON bodies separated by 0x1e bytes,
 * each framed and fed in turn (what a client sends: tests/fuzz/
 * lsp_seeds.py writes whole sessions like that). Then every pending
 * analysis runs. Responses go nowhere. A crash, a sanitizer report, a leak
 * or a slow input is a finding; an error response is not. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lsp/rpc.h"
#include "lsp/server.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static bool discard(void *ctx, const char *bytes, size_t n) {
    (void)ctx, (void)bytes, (void)n;
    return true;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    pfx_lsp_server *s = pfx_lsp_server_create(discard, NULL);
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    bool alive = s != NULL;
    double now = 0;
    if (alive && size >= 14 && !memcmp(data, "Content-Length", 14)) {
        size_t half = size / 2;
        alive = pfx_lsp_server_feed(s, data, half, now, &run) &&
                pfx_lsp_server_feed(s, data + half, size - half, now, &run);
    } else {
        for (size_t at = 0; alive && at < size;) {
            const uint8_t *end = memchr(data + at, 0x1e, size - at);
            size_t n = end ? (size_t)(end - (data + at)) : size - at, framed_len;
            char *framed = pfx_lsp_frame_text((const char *)data + at, n, &framed_len);
            if (!framed)
                break;
            alive = pfx_lsp_server_feed(s, framed, framed_len, now, &run);
            free(framed);
            at += n + 1;
            now += 40; /* some edits fall inside the debounce, some after */
            if (alive && pfx_lsp_server_wait_ms(s, now) == 0)
                pfx_lsp_server_tick(s, now, false);
        }
    }
    if (s)
        pfx_lsp_server_tick(s, now, true);
    pfx_lsp_server_destroy(s);
    pfx_diags_free(&run);
    return 0;
}
