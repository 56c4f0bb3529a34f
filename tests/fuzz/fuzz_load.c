/* libFuzzer target: the path of `pfx validate`. Any bytes are read as an
 * effect file, parsed, compiled, and their diagnostics printed both ways
 * (text and JSON lines) into /dev/null. A crash, a sanitizer report, a leak
 * or a slow input is a finding; a rejected file is not. Mesh paths resolve
 * against a directory that does not exist, so only absolute ones reach the
 * disk. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "jobs/load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static FILE *devnull;
    if (!devnull)
        devnull = fopen("/dev/null", "w");
    pfx_loaded l;
    pfx_compile_options opt = {0};
    pfx_load_bytes(&l, "/nonexistent/fuzz.yaml", data, size, &opt);
    if (devnull) {
        pfx_diags_print(&l.diags, devnull, false);
        pfx_diags_print(&l.diags, devnull, true);
    }
    pfx_loaded_free(&l);
    return 0;
}
