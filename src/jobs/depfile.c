/* The depfile of jobs/depfile.h: GCC's -MD form (one target, its inputs on
 * continuation lines), which make includes, and ninja and CMake read with
 * `deps = gcc`. Written to a temporary file and renamed into place. */
#include "jobs/depfile.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

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
    char tmp[4200];
    const char *slash = strrchr(path, '/');
    int dir = slash ? (int)(slash - path + 1) : 0;
    snprintf(tmp, sizeof tmp, "%.*s.%s.tmp-%ld", dir, path, path + dir, (long)getpid());
    FILE *f = fopen(tmp, "wx");
    if (!f) {
        pfx_diag_error(d, "cannot write depfile '%s': %s", path, strerror(errno));
        return false;
    }
    put_path(f, target);
    fputc(':', f);
    for (size_t i = 0; i < pfx_manifest_input_count(m); i++) {
        fputs(" \\\n  ", f);
        put_path(f, pfx_manifest_input(m, i));
    }
    fputc('\n', f);
    bool ok = !ferror(f);
    int err = errno;
    if (fclose(f) != 0 && ok)
        ok = false, err = errno;
    if (ok && rename(tmp, path) != 0)
        ok = false, err = errno;
    if (!ok) {
        unlink(tmp);
        pfx_diag_error(d, "cannot write depfile '%s': %s", path, strerror(err ? err : EIO));
    }
    return ok;
}
