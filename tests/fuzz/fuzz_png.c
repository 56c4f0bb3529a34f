/* libFuzzer target: the PNG texture reader of `texture` and `normal_map`
 * (output/png_read.c). The reader takes a path (it checks that the file is
 * a regular file of bounded size before opening it), so each input is
 * written to a file of this process's own and read as a colour texture and
 * as a normal map. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "output/png_read.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static char path[64];
    if (!path[0])
        snprintf(path, sizeof path, "/tmp/pfx-fuzz-png-%ld.png", (long)getpid());
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    bool written = fwrite(data, 1, size, f) == size;
    if (fclose(f) != 0 || !written)
        return 0;
    for (int premultiply = 0; premultiply < 2; premultiply++) {
        pfx_arena arena = {0};
        pfx_diags d;
        pfx_diags_init(&d, "fuzz.yaml", NULL, 0);
        pfx_diag_at at = {&d, 1, 1, 1};
        pfx_image img;
        pfx_png_read_texture(path, "fuzz.png", premultiply, &arena, &img, &at);
        pfx_diags_free(&d);
        pfx_arena_free(&arena);
    }
    return 0;
}
