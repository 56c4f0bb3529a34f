/* What the commands share: usage errors, loading an effect with its
 * diagnostics (and --werror), mkdir -p, the frame range and the memory
 * check before a run, and the manifest settings of a run. */
#include "commands/commands.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

#include "base/sha256.h"
#include "jobs/depfile.h"
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
    int warnings = pfx_loaded_warnings(l);
    if (!o->werror || warnings == 0)
        return false;
    fprintf(stderr, "pfx: '%s': %d warning%s treated as error%s (--werror)\n", path, warnings,
            warnings == 1 ? "" : "s", warnings == 1 ? "" : "s");
    return true;
}

/* Loads and compiles one file, printing its diagnostics. With --werror a
 * warning fails it: the effect stays in l (freed with it), unused. */
pfx_effect *pfx_cli_load(pfx_loaded *l, const char *path, const pfx_cli *o) {
    pfx_effect *e = pfx_load(l, path, &o->compile);
    pfx_loaded_print(l, stderr, o->json);
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
        char step[32] = "";
        if (o->frames_step)
            snprintf(step, sizeof step, ":%ld", o->frames_step);
        if (o->last < 0)
            fprintf(stderr, "pfx: --frames %ld:%s is outside the effect's frames 0:%ld\n", o->first,
                    step, n - 1);
        else
            fprintf(stderr, "pfx: --frames %ld:%ld%s is outside the effect's frames 0:%ld\n",
                    o->first, o->last, step, n - 1);
        return false;
    }
    /* 0:20:5 and 0:22:5 are the same five frames: the range ends where the
     * step lands, so manifests and messages name what is written. */
    *last -= (*last - *first) % o->every;
    return true;
}

long pfx_cli_frame_count(const pfx_cli *o, long first, long last) {
    return last < first ? 0 : (last - first) / o->every + 1;
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
 * after --fps, --size, --seed and --max-particles; --set as given, in
 * order, only when there is one, so that other keys stay as they were),
 * and its inputs. The
 * effect is hashed as the bytes that were parsed, never by opening it
 * again: a pipe (/dev/stdin, <(...)) is drained by then and a named FIFO
 * would wait for a second writer. */
bool pfx_cli_describe_run(pfx_delivery *dl, const pfx_loaded *l, long first, long last,
                          const pfx_cli *o, pfx_diags *d) {
    const pfx_effect *e = l->effect;
    char hex[PFX_SHA256_HEX];
    pfx_sha256_bytes(l->source, l->source_len, hex);
    pfx_manifest_add_input_sha256(dl->now, e->path, hex);
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)e->seed);
    pfx_manifest_set_range(dl->now, "frames", first, last);
    pfx_manifest_set_number(dl->now, "fps", e->fps);
    pfx_manifest_set_number(dl->now, "width", e->width);
    pfx_manifest_set_number(dl->now, "height", e->height);
    pfx_manifest_set_string(dl->now, "seed", seed);
    pfx_manifest_set_number(dl->now, "max_particles", (double)e->max_particles);
    pfx_manifest_set_number(dl->now, "loop", e->loop);
    if (o->compile.set_count)
        pfx_manifest_set_strings(dl->now, "set", o->compile.sets, o->compile.set_count);
    return pfx_manifest_add_effect(dl->now, e, d);
}

/* Lists the manifest and the depfile with the command's other outputs,
 * then checks them all before any work: names that fit, no output that is
 * an input, a depfile that make and ninja read right. */
bool pfx_cli_check_outputs(const pfx_delivery *dl, pfx_output_names *names, pfx_diags *d) {
    pfx_output_names_add(names, dl->manifest_path);
    pfx_output_names_add(names, dl->depfile);
    bool ok = pfx_output_names_check(names, dl->now, d);
    if (dl->depfile && !pfx_depfile_check(dl->target, dl->now, d))
        ok = false;
    return ok;
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
