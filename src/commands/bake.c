/* pfx bake FILE -o OUT: the particle state of the output frames as CSV,
 * PLY or pcache, with its manifest and depfile: one file, or one file a
 * frame when OUT's name holds a run of '#'. */
#include "commands/commands.h"

#include <string.h>

#include "jobs/bake_view.h"
#include "output/bake.h"

/* The bake's format: --format, else the output's extension (.ply, .pcache),
 * else CSV. False (after the usage error) on a word that names none. */
static bool bake_format(const pfx_cli *o, pfx_bake_format *f) {
    *f = PFX_BAKE_CSV;
    if (o->format) {
        if (pfx_bake_format_parse(o->format, f))
            return true;
        pfx_cli_usage_error("bake --format takes 'csv', 'ply' or 'pcache', got '%s'", o->format);
        return false;
    }
    const char *dot = strrchr(o->output, '.');
    if (dot && !strchr(dot, '/'))
        pfx_bake_format_parse(dot + 1, f);
    return true;
}

/* Where the frames go: -o, and in its file name the run of '#' that one
 * file a frame puts the zero-padded frame number in (cache_####.ply:
 * cache_0005.ply), as Blender and Houdini spell a frame sequence; hashes 0:
 * every frame into the one file. */
typedef struct bake_target {
    const char *path;
    size_t hash_at, hashes;
} bake_target;

/* Finds -o's run of '#'. False when there is more than one, or one outside
 * the file name. */
static bool find_hashes(const char *path, bake_target *t) {
    *t = (bake_target){.path = path};
    const char *run = strchr(path, '#');
    if (!run)
        return true;
    t->hash_at = (size_t)(run - path);
    t->hashes = strspn(run, "#");
    return !strchr(run + t->hashes, '#') && !strchr(run, '/');
}

/* Frame f's file of a sequence, into out; false when it does not fit. */
static bool frame_file(const bake_target *t, long f, char *out, size_t size) {
    int n = snprintf(out, size, "%.*s%0*ld%s", (int)t->hash_at, t->path, (int)t->hashes, f,
                     t->path + t->hash_at + t->hashes);
    return n > 0 && (size_t)n < size;
}

/* The usage checks of bake's options, and its format; 0 when they pass,
 * else the exit status (the message printed). */
static int check_bake_options(int count, const pfx_cli *o, pfx_bake_format *format) {
    if (count != 1)
        return pfx_cli_usage_error("%s", "bake takes one FILE and -o OUT");
    if (!o->output)
        return pfx_cli_usage_error("%s",
                                   "bake needs -o OUT (a .csv, .ply or .pcache file, or - for "
                                   "standard output)");
    if (!bake_format(o, format))
        return EXIT_USAGE;
    if (!strcmp(o->output, "-") && o->depfile)
        return pfx_cli_usage_error("%s", "--depfile needs a file to name as its target, not -o -");
    bake_target t;
    if (!find_hashes(o->output, &t))
        return pfx_cli_usage_error("-o takes one run of '#' (the frame number, as in "
                                   "cache_####.ply), in the file name, got '%s'",
                                   o->output);
    return 0;
}

/* One frame of a sequence: its own file, whole or absent, equal to a bake
 * of that frame alone, listed in the manifest once written. */
static bool bake_frame_file(const bake_target *t, const pfx_effect *e, pfx_bake_format format,
                            pfx_bake_view *rows, const pfx_sim *state, long f, pfx_delivery *dl,
                            pfx_diags *run) {
    char path[4600];
    if (!frame_file(t, f, path, sizeof path)) {
        pfx_diag_error(run, PFX_RULE_TOO_LARGE, "output path for frame %ld of '%s' is too long", f,
                       t->path);
        return false;
    }
    pfx_bake *b = pfx_bake_open(path, format, e, run);
    if (!b)
        return false;
    bool ok = pfx_bake_view_write(rows, b, state, f, pfx_sim_frame_time(e, f));
    if (!pfx_bake_close(b, ok, run) || !ok)
        return false;
    const char *slash = strrchr(path, '/');
    return pfx_manifest_add_output(dl->now, dl->dir, slash ? slash + 1 : path, run);
}

/* Simulates frames first..last and writes every --every'th to the bake at
 * -o (whole or not at all), or each to its own file (listed in dl's
 * manifest as it is written; those before a failure stay); notes the
 * particles a full pool dropped and the work done by sub-emitters unless
 * -q. */
static bool bake_frames(const pfx_effect *e, const pfx_cli *o, pfx_bake_format format, long first,
                        long last, pfx_delivery *dl, pfx_diags *run) {
    const bool to_stdout = !strcmp(o->output, "-");
    bake_target t;
    find_hashes(o->output, &t);
    pfx_sim *sim = pfx_sim_create(e, run), *view = pfx_sim_create(e, run);
    pfx_bake *b = NULL;
    pfx_bake_view rows = {0};
    bool ok = false;
    if (!sim || !view) {
        pfx_diag_error(run, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if (!to_stdout && !pfx_cli_make_parent_dirs(o->output, run))
        goto done;
    if (!t.hashes && !(b = pfx_bake_open(o->output, format, e, run)))
        goto done;
    ok = true;
    for (long f = first; f <= last && ok; f++) {
        const pfx_sim *state = pfx_sim_frame(sim, view, f);
        if (sim->failed || view->failed) {
            ok = false;
            break;
        }
        if ((f - first) % o->every)
            continue;
        ok = t.hashes ? bake_frame_file(&t, e, format, &rows, state, f, dl, run)
                      : pfx_bake_view_write(&rows, b, state, f, pfx_sim_frame_time(e, f));
    }
    if ((b && !pfx_bake_close(b, ok, run)) || !ok) {
        if (!run->errors)
            pfx_diag_error(run, PFX_RULE_WRITE_FAILED, "cannot write the bake");
        ok = false;
        goto done;
    }
    if (!o->quiet) {
        pfx_sim_note_dropped(sim, run);
        pfx_sim_note_work(sim, run);
    }
done:
    pfx_bake_view_free(&rows);
    pfx_sim_destroy(view);
    pfx_sim_destroy(sim);
    return ok;
}

int pfx_cmd_bake(const char *const *operands, int count, const pfx_cli *o) {
    pfx_bake_format format;
    int usage = check_bake_options(count, o, &format);
    if (usage)
        return usage;
    bool to_stdout = !strcmp(o->output, "-");
    pfx_loaded l;
    pfx_effect *e = pfx_cli_load(&l, operands[0], o);
    int status = EXIT_INVALID;
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    long first, last;
    /* The manifest: OUT.manifest.json beside OUT (none for standard
     * output; cache_####.ply.manifest.json for a sequence), listing OUT, or
     * each file of the sequence, by its name. A sequence has no one file
     * for a depfile to name: its target is the manifest, as render's is. */
    char dir[4096] = ".", manifest[4200];
    const char *name = o->output, *slash = strrchr(o->output, '/');
    if (slash) {
        snprintf(dir, sizeof dir, "%.*s", slash == o->output ? 1 : (int)(slash - o->output),
                 o->output);
        name = slash + 1;
    }
    snprintf(manifest, sizeof manifest, "%s.manifest.json", o->output);
    const bool sequence = strchr(o->output, '#') != NULL;
    pfx_delivery dl = {.dir = dir,
                       .manifest_path = to_stdout ? NULL : manifest,
                       .depfile = o->depfile,
                       .target = sequence ? manifest : o->output,
                       .force = o->force};
    if (!e)
        goto done;
    if (!pfx_cli_frame_range(e, o, &first, &last)) {
        status = EXIT_USAGE;
        goto done;
    }
    if (!pfx_cli_memory_fits(e, first, last, false, o, &run))
        goto done;
    if (!pfx_delivery_begin(&dl, "bake", &run) ||
        !pfx_cli_describe_run(&dl, &l, first, last, o, &run))
        goto done;
    pfx_manifest_set_string(dl.now, "format", pfx_bake_format_name(format));
    pfx_manifest_set_number(dl.now, "every", (double)o->every);
    /* A sequence is checked file by file: cache_####.obj must not write
     * over the mesh cache_0001.obj it reads. */
    pfx_output_names names = {0};
    bake_target t;
    find_hashes(o->output, &t);
    if (t.hashes) {
        char prefix[4096];
        snprintf(prefix, sizeof prefix, "%.*s", (int)t.hash_at, o->output);
        pfx_output_names_add_numbered(&names, prefix, (int)t.hashes,
                                      o->output + t.hash_at + t.hashes, first, last, o->every);
    } else {
        pfx_output_names_add(&names, to_stdout ? NULL : o->output);
    }
    bool names_ok = pfx_cli_check_outputs(&dl, &names, &run);
    pfx_output_names_free(&names);
    if (!names_ok)
        goto done;
    if (!to_stdout && pfx_delivery_up_to_date(&dl)) {
        if (pfx_delivery_skip(&dl, &run)) {
            pfx_cli_say_up_to_date(o, operands[0], o->output, &dl);
            status = 0;
        }
        goto done;
    }
    if (!bake_frames(e, o, format, first, last, &dl, &run))
        goto done;
    if (!to_stdout && ((!sequence && !pfx_manifest_add_output(dl.now, dir, name, &run)) ||
                       !pfx_delivery_finish(&dl, &run)))
        goto done;
    if (!o->quiet) {
        char every[32] = "";
        if (o->every > 1)
            snprintf(every, sizeof every, ", every %ld", o->every);
        fprintf(stderr, "pfx: baked '%s': frames %ld to %ld%s as %s to '%s'%s", operands[0], first,
                last, every, pfx_bake_format_name(format),
                to_stdout ? "standard output" : o->output, sequence ? ", one file a frame" : "");
        if (dl.stale_removed)
            fprintf(stderr, ", %zu stale removed", dl.stale_removed);
        fputc('\n', stderr);
    }
    status = 0;
done:
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    pfx_delivery_free(&dl);
    pfx_loaded_free(&l);
    return status;
}
