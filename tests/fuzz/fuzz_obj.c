/* libFuzzer target: the Wavefront OBJ reader of the mesh shape. The input
 * is copied into a buffer of exactly its size, so a read past the end is
 * an AddressSanitizer report, and parsed as a mesh file would be. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "compile/mesh_load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *text = malloc(size ? size : 1);
    if (!text)
        return 0;
    if (size)
        memcpy(text, data, size);
    pfx_arena arena = {0};
    pfx_diags d;
    pfx_diags_init(&d, "fuzz.yaml", NULL, 0);
    pfx_diag_at at = {&d, 1, 1, 1};
    pfx_mesh m;
    pfx_mesh_parse(text, size, "fuzz.obj", 1.0, &arena, &m, &at);
    pfx_diags_free(&d);
    pfx_arena_free(&arena);
    free(text);
    return 0;
}
