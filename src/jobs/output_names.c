/* The checks of jobs/output_names.h, made before a run does any work.
 * Inputs and outputs are compared as files (device and inode), not as
 * strings: "a.yaml", "./a.yaml" and a link to it are the same file. An
 * output that does not exist yet cannot be an input. */
#include "jobs/output_names.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "jobs/input_files.h"

static char *copy_of(const char *s) {
    size_t n = strlen(s) + 1;
    char *c = malloc(n);
    return c ? memcpy(c, s, n) : NULL;
}

static void push(pfx_output_names *o, char *prefix, char *suffix, long first, long last, long step,
                 int digits) {
    if (o->count == o->cap) {
        size_t cap = o->cap ? 2 * o->cap : 16;
        pfx_output_name *grown = realloc(o->items, cap * sizeof *grown);
        if (!grown) {
            o->failed = true;
            free(prefix);
            free(suffix);
            return;
        }
        o->items = grown;
        o->cap = cap;
    }
    if (!prefix) {
        o->failed = true;
        free(suffix);
        return;
    }
    o->items[o->count++] = (pfx_output_name){prefix, suffix, first, last, step, digits};
}

void pfx_output_names_add(pfx_output_names *o, const char *path) {
    if (path)
        push(o, copy_of(path), NULL, 0, 0, 1, 0);
}

void pfx_output_names_add_frames(pfx_output_names *o, const char *dir, const char *stem,
                                 const char *infix, long first, long last, const char *ext) {
    if (first > last)
        return;
    size_t n = strlen(dir) + strlen(stem) + strlen(infix) + 2;
    char *prefix = malloc(n), *suffix = malloc(strlen(ext) + 2);
    if (prefix)
        snprintf(prefix, n, "%s/%s%s", dir, stem, infix);
    if (suffix)
        snprintf(suffix, strlen(ext) + 2, ".%s", ext);
    if (!suffix) {
        free(prefix);
        prefix = NULL;
    }
    push(o, prefix, suffix, first, last, 1, 4);
}

void pfx_output_names_add_numbered(pfx_output_names *o, const char *prefix, int digits,
                                   const char *suffix, long first, long last, long step) {
    if (first > last || step < 1)
        return;
    char *p = copy_of(prefix), *s = copy_of(suffix);
    if (!s) {
        free(p);
        p = NULL;
    }
    /* The last frame listed is the last one written. */
    push(o, p, s, first, first + (last - first) / step * step, step, digits);
}

/* The k'th path of item it (k = 0 for a single file) into buf; false
 * when it does not fit PATH_MAX. */
static bool path_of(const pfx_output_name *it, long frame, char *buf, size_t size) {
    int n = it->suffix ? snprintf(buf, size, "%s%0*ld%s", it->prefix, it->digits, frame, it->suffix)
                       : snprintf(buf, size, "%s", it->prefix);
    return n >= 0 && (size_t)n < size;
}

/* The longest file name the directory of path takes; the usual NAME_MAX
 * where the directory does not exist yet (pfx makes it). */
static long name_max_of(const char *path) {
    const char *slash = strrchr(path, '/');
    char dir[PATH_MAX];
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else
        snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    long n = pathconf(dir, _PC_NAME_MAX);
    return n > 0 ? n : NAME_MAX;
}

static bool fits(const char *path, pfx_diags *d) {
    const char *slash = strrchr(path, '/');
    const char *name = slash ? slash + 1 : path;
    if ((long)strlen(name) <= name_max_of(path))
        return true;
    pfx_diag_error(d, PFX_RULE_TOO_LARGE, "cannot write '%s': %s (at most %ld bytes)", path,
                   strerror(ENAMETOOLONG), name_max_of(path));
    return false;
}

/* Whether pfx can put a file at path: not a directory there (a file
 * cannot be renamed over one, and finding it after the last frame is too
 * late) and not one of the inputs. */
static bool writable(const char *path, const pfx_input_files *inputs, pfx_diags *d) {
    struct stat st;
    if (stat(path, &st) != 0)
        return true; /* not there yet: neither */
    if (S_ISDIR(st.st_mode)) {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write '%s': %s", path, strerror(EISDIR));
        return false;
    }
    const char *in = pfx_input_files_match(inputs, st.st_dev, st.st_ino);
    if (!in)
        return true;
    pfx_diag_error(d, PFX_RULE_WRITE_FAILED,
                   "cannot write '%s': it is the input '%s' of this run; choose another output",
                   path, in);
    return false;
}

bool pfx_output_names_check(const pfx_output_names *o, const pfx_manifest *m, pfx_diags *d) {
    if (o->failed) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return false;
    }
    pfx_input_files inputs;
    if (!pfx_input_files_of(m, &inputs)) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return false;
    }
    bool ok = true;
    char path[PATH_MAX];
    for (size_t i = 0; i < o->count; i++) {
        const pfx_output_name *it = &o->items[i];
        /* A frame number's name is longest at the last frame. */
        if (!path_of(it, it->last, path, sizeof path)) {
            pfx_diag_error(d, PFX_RULE_TOO_LARGE, "cannot write '%s...': %s", it->prefix,
                           strerror(ENAMETOOLONG));
            ok = false;
            continue;
        }
        if (!fits(path, d)) {
            ok = false;
            continue;
        }
        for (long f = it->first; f <= it->last; f += it->step)
            if (path_of(it, f, path, sizeof path) && !writable(path, &inputs, d)) {
                ok = false;
                break;
            }
    }
    pfx_input_files_free(&inputs);
    return ok;
}

void pfx_output_names_free(pfx_output_names *o) {
    for (size_t i = 0; i < o->count; i++) {
        free(o->items[i].prefix);
        free(o->items[i].suffix);
    }
    free(o->items);
    *o = (pfx_output_names){0};
}
