/* pfx tune FILE -o DIR: the effect under a ladder of simulation settings
 * (jobs/tune.c), reported as DIR/tune.{csv,json,svg,png} and a summary on
 * stdout (jobs/tune_report.c). This file only checks the options. */
#include "commands/commands.h"

#include "jobs/tune.h"

int pfx_cmd_tune(const char *const *operands, int count, const pfx_cli *o) {
    if (count != 1)
        return pfx_cli_usage_error("%s", "tune takes one FILE and -o DIR");
    if (!o->output)
        return pfx_cli_usage_error("%s", "tune needs -o DIR (for tune.csv, tune.json, tune.svg "
                                         "and tune.png)");
    if (o->every > 1)
        return pfx_cli_usage_error("%s", "tune chooses the frames it compares within --frames A:B; "
                                         "it takes no step");
    pfx_tune_request q = {
        .path = operands[0], .compile = &o->compile, .tolerance = 0.5, .tolerance_px = true};
    if (o->tolerance && !pfx_tune_parse_tolerance(o->tolerance, &q.tolerance, &q.tolerance_px))
        return pfx_cli_usage_error("--tolerance takes a number above 0 and a unit: px, m, cm or "
                                   "mm (0.5px, 1mm), got '%s'",
                                   o->tolerance);
    /* Read once: every run of the ladder compiles these bytes. */
    pfx_loaded l;
    pfx_effect *e = pfx_cli_load(&l, operands[0], o);
    q.loaded = &l;
    int status = EXIT_INVALID;
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    pfx_tune_result res = {0};
    if (!e)
        goto done;
    if (!pfx_cli_frame_range(e, o, &q.first, &q.last)) {
        status = EXIT_USAGE;
        goto done;
    }
    if (!pfx_cli_make_dirs(o->output, &run))
        goto done;
    if (!pfx_tune_run_ladder(&q, &res, o->quiet ? NULL : stderr, &run) ||
        !pfx_tune_scene_costs(&q, &res, &run) ||
        !pfx_tune_report(&q, &res, o->output, stdout, &run))
        goto done;
    status = 0;
done:
    pfx_tune_result_free(&res);
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    pfx_loaded_free(&l);
    return status;
}
