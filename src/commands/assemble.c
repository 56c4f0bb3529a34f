/* pfx assemble DIR... -o OUT: the slices of renders into one directory. */
#include "commands/commands.h"

#include "jobs/assemble.h"

/* pfx assemble DIR... -o OUT: the slices of renders into one directory. */
int pfx_cmd_assemble(const char *const *operands, int count, const pfx_cli *o) {
    if (count < 1)
        return pfx_cli_usage_error("%s",
                                   "assemble needs at least one DIR (with the slices' frames)");
    if (!o->output)
        return pfx_cli_usage_error("%s", "assemble needs -o OUT");
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    pfx_assemble_report r;
    pfx_assemble_options opt = {.atlas = o->atlas ? &o->atlas_layout : NULL,
                                .preview = o->preview,
                                .preview_quality = o->preview_quality};
    bool ok = pfx_cli_make_dirs(o->output, &run) &&
              pfx_assemble(operands, (size_t)count, o->output, &opt, &r, &run);
    if (ok && !o->quiet)
        fprintf(stderr,
                "pfx: assembled %zu frames of %zu render%s in '%s' (%zu linked, %zu copied, %zu "
                "already there)\n",
                r.frames, r.effects, r.effects == 1 ? "" : "s", o->output, r.linked, r.copied,
                r.kept);
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    return ok ? 0 : EXIT_INVALID;
}
