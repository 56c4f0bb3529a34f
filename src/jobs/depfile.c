/* The depfile of jobs/depfile.h: GCC's -MD form (one target, its inputs on
 * continuation lines), which make includes, and ninja and CMake read with
 * `deps = gcc`. Written whole or not at all (output/atomic_file.h). */
#include "jobs/depfile.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "output/atomic_file.h"

/* A path as Make reads it: '\ ' for a space, '\#' for '#', '$$' for '$'. */
static void put_path(FILE *f, const char *p) {
    for (; *p; p++) {
        if (*p == ' ' || *p == '#')
            fputc('\\', f);
        else if (*p == '$')
            fputc('$', f);
        fputc(*p, f);
    }
}

bool pfx_depfile_write(const char *path, const char *target, const pfx_manifest *m, pfx_diags *d) {
    pfx_atomic_file *a = pfx_atomic_open(path, d);
    if (!a)
        return false;
    FILE *f = pfx_atomic_stream(a);
    put_path(f, target);
    fputc(':', f);
    for (size_t i = 0; i < pfx_manifest_input_count(m); i++) {
        fputs(" \\\n  ", f);
        put_path(f, pfx_manifest_input(m, i));
    }
    fputc('\n', f);
    if (ferror(f))
        pfx_atomic_failed(a, errno);
    return pfx_atomic_commit(a, true, d);
}
