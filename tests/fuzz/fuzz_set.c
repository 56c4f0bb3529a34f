/* libFuzzer target: --set PATH=VALUE. Each line of the input (at most 16)
 * is one --set word, applied in order to a fixed effect that has what a
 * path walks through (named emitters and forces, a nested mapping, lists,
 * a YAML alias), then compiled, its diagnostics printed both ways into
 * /dev/null. A crash, a sanitizer report, a leak or a slow input is a
 * finding; a refused override is not. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jobs/load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char effect[] = "pfx: 1\n"
                             "duration: 0.5\n"
                             "sim: { rate: 60 }\n"
                             "image: { size: [32, 32] }\n"
                             "forces:\n"
                             "  gravity: { type: gravity, accel: [0, -9.81, 0] }\n"
                             "emitters:\n"
                             "  flame: &body\n"
                             "    shape: { type: sphere, radius: 0.2 }\n"
                             "    rate: 20\n"
                             "    lifetime: { mean: 0.5, var: 0.1 }\n"
                             "    size: { start: 0.2, end: 0 }\n"
                             "    color: [\"#ffd890\", \"#40000000\"]\n"
                             "    bursts: [{ time: 0, count: 3 }]\n"
                             "    forces: [gravity]\n"
                             "  copy: *body\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static FILE *devnull;
    if (!devnull)
        devnull = fopen("/dev/null", "w");
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = 0;
    const char *sets[16];
    size_t n = 0;
    for (char *line = text; line && n < 16;) {
        char *nl = strchr(line, '\n');
        if (nl)
            *nl = 0;
        sets[n++] = line;
        line = nl ? nl + 1 : NULL;
    }
    pfx_loaded l;
    pfx_compile_options opt = {.max_particles = 500, .sets = sets, .set_count = n};
    pfx_load_bytes(&l, "/nonexistent/fuzz.yaml", effect, sizeof effect - 1, &opt);
    if (devnull) {
        pfx_loaded_print(&l, devnull, false);
        pfx_loaded_print(&l, devnull, true);
    }
    pfx_loaded_free(&l);
    free(text);
    return 0;
}
