/* The depfile of jobs/depfile.h: GCC's -MD form (one target, its inputs on
 * continuation lines), which make includes, and ninja and CMake read with
 * `deps = gcc`. Written whole or not at all (output/atomic_file.h). What
 * the two readers take as the same path is escaped; a path that either of
 * them would read as another one is refused before the run. */
#include "jobs/depfile.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "output/atomic_file.h"

/* A path as Make and ninja read it: '\ ' for a space, '\#' for '#', '\:'
 * for ':', '$$' for '$'. pfx_depfile_check has refused what this cannot
 * carry. */
static void put_path(FILE *f, const char *p) {
    for (; *p; p++) {
        if (*p == ' ' || *p == '#' || *p == ':')
            fputc('\\', f);
        else if (*p == '$')
            fputc('$', f);
        fputc(*p, f);
    }
}

/* The character of p that GNU Make (4.3) or ninja (1.11) would read as
 * something else than itself however it is written, or 0. Found by
 * feeding each byte to both: a control character (a newline or a tab ends
 * the path), ';' (starts a recipe), '|' (order-only), '=' (a variable),
 * '*', '?', '[', ']' (make globs them: a[1].png reads as a1.png where that
 * exists; ninja keeps a backslash before them), a leading '~' (make
 * expands ~user), and quotes, '&', '<', '>', '^' and '`',
 * where ninja ends the path; a path ending in ':' or ')' (ninja keeps the
 * backslash; make reads an archive member); a backslash before a space,
 * '#', ':' or the end (the escapes above would change meaning). */
static char unreadable(const char *p) {
    size_t n = strlen(p);
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)p[i];
        if (c < 0x20 || c == 0x7f || strchr(";|=*?[]\"'&<>^`", c) || (i == 0 && c == '~'))
            return (char)c;
        if (c == '\\' && (i + 1 == n || strchr(" #:", p[i + 1])))
            return '\\';
    }
    if (n && (p[n - 1] == ':' || p[n - 1] == ')'))
        return p[n - 1];
    return 0;
}

/* One refusal: the character shown as C would show it. */
static bool refuse(const char *what, const char *path, char c, pfx_diags *d) {
    char shown[8];
    if (c == '\n')
        snprintf(shown, sizeof shown, "\\n");
    else if (c == '\t')
        snprintf(shown, sizeof shown, "\\t");
    else if ((unsigned char)c < 0x20 || c == 0x7f)
        snprintf(shown, sizeof shown, "\\x%02x", (unsigned char)c);
    else
        snprintf(shown, sizeof shown, "%c", c);
    pfx_diag_error(d, PFX_RULE_WRITE_FAILED,
                   "cannot name %s '%s' in a depfile: make or ninja would misread its '%s'; "
                   "rename it or leave out --depfile",
                   what, path, shown);
    return false;
}

bool pfx_depfile_check(const char *target, const pfx_manifest *m, pfx_diags *d) {
    bool ok = true;
    char c = unreadable(target);
    if (c || strchr(target, '%'))
        ok = refuse("the target", target, c ? c : '%', d);
    for (size_t i = 0; i < pfx_manifest_input_count(m); i++) {
        const char *p = pfx_manifest_input(m, i);
        if (p && (c = unreadable(p)) != 0)
            ok = refuse("the input", p, c, d);
    }
    return ok;
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
