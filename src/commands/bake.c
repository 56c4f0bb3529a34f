/* pfx bake FILE -o OUT: the particle state of the output frames as CSV,
 * PLY or pcache, with its manifest and depfile. */
#include "commands/commands.h"

#include <string.h>

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
    return 0;
}

/* Simulates frames first..last and writes every --every'th to the bake at
 * -o (whole or not at all); notes the particles a full pool dropped and the
 * work done by sub-emitters unless -q. */
static bool bake_frames(const pfx_effect *e, const pfx_cli *o, pfx_bake_format format, long first,
                        long last, pfx_diags *run) {
    const bool to_stdout = !strcmp(o->output, "-");
    pfx_sim *sim = pfx_sim_create(e, run), *view = pfx_sim_create(e, run);
    pfx_bake *b = NULL;
    bool ok = false;
    if (!sim || !view) {
        pfx_diag_error(run, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if (!to_stdout && !pfx_cli_make_parent_dirs(o->output, run))
        goto done;
    b = pfx_bake_open(o->output, format, e, run);
    if (!b)
        goto done;
    ok = true;
    for (long f = first; f <= last && ok; f++) {
        const pfx_sim *state = pfx_sim_frame(sim, view, f);
        if (sim->failed || view->failed) {
            ok = false;
            break;
        }
        if ((f - first) % o->every == 0)
            ok = pfx_bake_frame(b, state, f, pfx_sim_frame_time(e, f));
    }
    if (!pfx_bake_close(b, ok, run) || !ok) {
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
     * output), listing OUT by its name. */
    char dir[4096] = ".", manifest[4200];
    const char *name = o->output, *slash = strrchr(o->output, '/');
    if (slash) {
        snprintf(dir, sizeof dir, "%.*s", slash == o->output ? 1 : (int)(slash - o->output),
                 o->output);
        name = slash + 1;
    }
    snprintf(manifest, sizeof manifest, "%s.manifest.json", o->output);
    pfx_delivery dl = {.dir = dir,
                       .manifest_path = to_stdout ? NULL : manifest,
                       .depfile = o->depfile,
                       .target = o->output,
                       .force = o->force};
    if (!e)
        goto done;
    if (!pfx_cli_frame_range(e, o, &first, &last)) {
        status = EXIT_USAGE;
        goto done;
    }
    if (!pfx_cli_memory_fits(e, first, last, false, o, &run))
        goto done;
    if (!pfx_delivery_begin(&dl, "bake", &run) || !pfx_cli_describe_run(&dl, e, first, last, &run))
        goto done;
    pfx_manifest_set_string(dl.now, "format", pfx_bake_format_name(format));
    pfx_manifest_set_number(dl.now, "every", (double)o->every);
    if (!to_stdout && pfx_delivery_up_to_date(&dl)) {
        if (pfx_delivery_skip(&dl, &run)) {
            pfx_cli_say_up_to_date(o, operands[0], o->output, &dl);
            status = 0;
        }
        goto done;
    }
    if (!bake_frames(e, o, format, first, last, &run))
        goto done;
    if (!to_stdout &&
        (!pfx_manifest_add_output(dl.now, dir, name, &run) || !pfx_delivery_finish(&dl, &run)))
        goto done;
    if (!o->quiet) {
        fprintf(stderr, "pfx: baked '%s': frames %ld to %ld as %s to '%s'\n", operands[0], first,
                last, pfx_bake_format_name(format), to_stdout ? "standard output" : o->output);
    }
    status = 0;
done:
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    pfx_delivery_free(&dl);
    pfx_loaded_free(&l);
    return status;
}
