/* What the commands share: usage errors, loading an effect with its
 * diagnostics (and --werror), mkdir -p, the frame range and the memory
 * check before a run, and the manifest settings of a run. */
#include "commands/commands.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

#include "jobs/estimate.h"

int pfx_cli_usage_error(const char *fmt, const char *arg) {
    fputs("pfx: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\nTry 'pfx --help' for more information.\n", stderr);
    return EXIT_USAGE;
}

/* Looks up a renderer name; on a bad one prints the usage error, naming
 * `what` (the option or variable) and every kind, and returns false. */
bool pfx_cli_parse_renderer(const char *what, const char *name, pfx_renderer_kind *kind) {
    if (pfx_renderer_kind_parse(name, kind))
        return true;
    char kinds[128] = "";
    for (int k = 0; k < PFX_RENDERER_KIND_COUNT; k++)
        snprintf(kinds + strlen(kinds), sizeof kinds - strlen(kinds), "%s'%s'",
                 k == 0                             ? ""
                 : k == PFX_RENDERER_KIND_COUNT - 1 ? " or "
                                                    : ", ",
                 pfx_renderer_kind_name((pfx_renderer_kind)k));
    fprintf(stderr, "pfx: %s takes %s, got '%s'\n", what, kinds, name);
    fputs("Try 'pfx --help' for more information.\n", stderr);
    return false;
}

/* The renderer for render and bench: --renderer, else PFX_RENDERER, else
 * auto. Returns false (after the usage error) on a bad PFX_RENDERER. */
bool pfx_cli_renderer_kind(const pfx_cli *o, pfx_renderer_kind *kind) {
    const char *env = getenv("PFX_RENDERER");
    *kind = PFX_RENDERER_AUTO;
    if (o->has_renderer)
        *kind = o->renderer;
    else if (env && *env)
        return pfx_cli_parse_renderer("PFX_RENDERER", env, kind);
    return true;
}

/* --werror: true (with a line saying so) when l has warnings to fail on. */
bool pfx_cli_fails_on_warnings(const pfx_loaded *l, const char *path, const pfx_cli *o) {
    if (!o->werror || l->diags.warnings == 0)
        return false;
    fprintf(stderr, "pfx: '%s': %d warning%s treated as error%s (--werror)\n", path,
            l->diags.warnings, l->diags.warnings == 1 ? "" : "s",
            l->diags.warnings == 1 ? "" : "s");
    return true;
}

/* Loads and compiles one file, printing its diagnostics. With --werror a
 * warning fails it: the effect stays in l (freed with it), unused. */
pfx_effect *pfx_cli_load(pfx_loaded *l, const char *path, const pfx_cli *o) {
    pfx_effect *e = pfx_load(l, path, &o->compile);
    pfx_diags_print(&l->diags, stderr, o->json);
    return e && !pfx_cli_fails_on_warnings(l, path, o) ? e : NULL;
}

/* mkdir -p */
bool pfx_cli_make_dirs(const char *path, pfx_diags *d) {
    char buf[4096];
    if (strlen(path) >= sizeof buf) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE, "output path is too long");
        return false;
    }
    strcpy(buf, path);
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == 0) {
            char saved = *p;
            *p = 0;
            struct stat st;
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
                pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create '%s': %s", buf,
                               strerror(errno));
                return false;
            }
            if (stat(buf, &st) != 0) { /* a symlink loop, a dangling link */
                pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create '%s': %s", buf,
                               strerror(errno));
                return false;
            }
            if (!S_ISDIR(st.st_mode)) {
                pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create '%s': %s", buf,
                               strerror(ENOTDIR));
                return false;
            }
            *p = saved;
            if (!saved)
                return true;
        }
    }
}

/* mkdir -p of the directory part of a file path. */
bool pfx_cli_make_parent_dirs(const char *path, pfx_diags *d) {
    const char *slash = strrchr(path, '/');
    if (!slash || slash == path)
        return true;
    char dir[4096];
    if ((size_t)(slash - path) >= sizeof dir) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE, "output path is too long");
        return false;
    }
    memcpy(dir, path, (size_t)(slash - path));
    dir[slash - path] = 0;
    return pfx_cli_make_dirs(dir, d);
}

/* The file's name without directory and extension: out/fire_0000.png. */
void pfx_cli_file_stem(const char *path, char *out, size_t size) {
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    snprintf(out, size, "%s", base);
    char *dot = strrchr(out, '.');
    if (dot && dot != out)
        *dot = 0;
}

/* Resolves --frames against the effect's frame count; false if outside. */
bool pfx_cli_frame_range(const pfx_effect *e, const pfx_cli *o, long *first, long *last) {
    long n = pfx_effect_frame_count(e);
    *first = o->has_frames ? o->first : 0;
    *last = o->has_frames && o->last >= 0 ? o->last : n - 1;
    /* A looping effect's frames go on for ever: frame f is frame f mod n. */
    if ((*last >= n && !(e->loop && *last < 1000000)) || *first > *last) {
        if (o->last < 0)
            fprintf(stderr, "pfx: --frames %ld: is outside the effect's frames 0:%ld\n", o->first,
                    n - 1);
        else
            fprintf(stderr, "pfx: --frames %ld:%ld is outside the effect's frames 0:%ld\n",
                    o->first, o->last, n - 1);
        return false;
    }
    return true;
}

/* Refuses, before anything is allocated, a run estimated to need more than
 * --max-memory (default half of physical memory), naming the biggest part. */
bool pfx_cli_memory_fits(const pfx_effect *e, long first, long last, bool render, const pfx_cli *o,
                         pfx_diags *run) {
    return pfx_estimate_fits(e, first, last,
                             render | (o->motion_vectors ? PFX_ESTIMATE_MOTION_VECTORS : 0),
                             o->max_memory, run);
}

/* The manifest's settings common to render and bake (the effect's values
 * after --fps, --size, --seed and --max-particles), and its inputs. */
bool pfx_cli_describe_run(pfx_delivery *dl, const pfx_effect *e, long first, long last,
                          pfx_diags *d) {
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)e->seed);
    pfx_manifest_set_range(dl->now, "frames", first, last);
    pfx_manifest_set_number(dl->now, "fps", e->fps);
    pfx_manifest_set_number(dl->now, "width", e->width);
    pfx_manifest_set_number(dl->now, "height", e->height);
    pfx_manifest_set_string(dl->now, "seed", seed);
    pfx_manifest_set_number(dl->now, "max_particles", (double)e->max_particles);
    pfx_manifest_set_number(dl->now, "loop", e->loop);
    return pfx_manifest_add_effect(dl->now, e, d);
}

/* Says that there was nothing to do, with the key that proved it. */
void pfx_cli_say_up_to_date(const pfx_cli *o, const char *path, const char *where,
                            pfx_delivery *dl) {
    if (!o->quiet)
        fprintf(stderr,
                "pfx: '%s' is up to date in '%s' (bake key %.12s); nothing to do, --force "
                "redoes it\n",
                path, where, pfx_manifest_key(dl->now));
}
