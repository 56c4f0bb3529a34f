/* pfx bench [accuracy]: speed against references measured in the same
 * run, or integrator accuracy against exact solutions. */
#include "commands/commands.h"

#include <jansson.h>
#include <stdio.h>
#include <string.h>

#include "bench/accuracy.h"
#include "bench/speed.h"
#include "compile/read.h"

int pfx_cmd_bench(const char *const *operands, int count, const pfx_cli *o) {
    if (count > 0 && !strcmp(operands[0], "accuracy")) {
        if (!o->output)
            return pfx_cli_usage_error("%s", "bench accuracy needs -o DIR");
        return pfx_bench_accuracy(o->output, stdout) == 0 ? 0 : EXIT_INVALID;
    }
    /* The sections named, each once; none: all of them. */
    unsigned sections = 0;
    for (int i = 0; i < count; i++) {
        unsigned bit = pfx_bench_section(operands[i]);
        if (!bit) {
            const char *sug = pfx_suggest(operands[i], pfx_bench_section_names);
            char msg[320];
            snprintf(msg, sizeof msg,
                     "unknown benchmark '%.100s'%s%s%s; try accuracy, sim, forces, emission, sort, "
                     "render or looks",
                     operands[i], sug ? "; did you mean '" : "", sug ? sug : "", sug ? "'?" : "");
            return pfx_cli_usage_error("%s", msg);
        }
        sections |= bit;
    }
    pfx_renderer_kind kind;
    if (!pfx_cli_renderer_kind(o, &kind))
        return EXIT_USAGE;
    /* The rendering half draws the fire example: from the source tree, or
     * PFX_FIRE_EFFECT. */
    const char *fire = getenv("PFX_FIRE_EFFECT");
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    bool ok = pfx_bench_speed(stdout, fire ? fire : "effects/fire.yaml", kind, o->bench_json,
                              sections ? sections : PFX_BENCH_ALL, &run);
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    return ok ? 0 : EXIT_INVALID;
}
