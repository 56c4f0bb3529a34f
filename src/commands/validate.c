/* pfx validate FILE... (text, JSON lines or one SARIF log) and pfx schema
 * (the JSON Schema generated from the key tables). */
#include "commands/commands.h"

#include "compile/schema.h"
#include "jobs/estimate.h"
#include "output/sarif.h"

/* The one summary line of a validation that passed (text form only: the
 * JSON lines and the SARIF log carry their own counts). */
static void say_validated(const char *const *operands, int count, int warnings, int allowed) {
    if (count == 1)
        fprintf(stderr, "pfx: validated '%s': ", operands[0]);
    else
        fprintf(stderr, "pfx: validated %d files: ", count);
    if (warnings)
        fprintf(stderr, "%d warning%s", warnings, warnings == 1 ? "" : "s");
    else
        fputs("no warnings", stderr);
    if (allowed)
        fprintf(stderr, ", %d allowed", allowed);
    fputc('\n', stderr);
}

int pfx_cmd_validate(const char *const *operands, int count, const pfx_cli *o) {
    if (o->list_rules) {
        pfx_rules_print(stdout);
        return 0;
    }
    if (count < 1)
        return pfx_cli_usage_error("%s", "validate needs at least one FILE");
    int status = 0;
    int warnings = 0, allowed = 0;
    /* --format sarif: every file's diagnostics gather into one log, written
     * to stdout at the end (stderr keeps the --werror lines and failures
     * to build or write the log). */
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    pfx_sarif *sarif = o->sarif ? pfx_sarif_create() : NULL;
    if (o->sarif && !sarif)
        pfx_diag_error(&run, PFX_RULE_OUT_OF_MEMORY, "out of memory for the SARIF log");
    for (int i = 0; i < count && !run.errors; i++) {
        pfx_loaded l;
        pfx_effect *e = pfx_load(&l, operands[i], &o->compile);
        pfx_estimate_check(&l, o->max_memory); /* the whole render: what it would cost */
        if (sarif && !(pfx_sarif_add(sarif, &l.overrides.diags) && pfx_sarif_add(sarif, &l.diags)))
            pfx_diag_error(&run, PFX_RULE_OUT_OF_MEMORY, "out of memory for the SARIF log");
        if (!sarif)
            pfx_loaded_print(&l, stderr, o->json);
        if (!e || pfx_cli_fails_on_warnings(&l, operands[i], o))
            status = EXIT_INVALID;
        warnings += l.diags.warnings;
        allowed += l.diags.allowed;
        pfx_loaded_free(&l);
    }
    if (sarif && !run.errors && !pfx_sarif_write(sarif, stdout))
        pfx_diag_error(&run, PFX_RULE_WRITE_FAILED,
                       "cannot write the SARIF log to standard output");
    pfx_sarif_destroy(sarif);
    pfx_diags_print(&run, stderr, false);
    if (run.errors)
        status = EXIT_INVALID;
    pfx_diags_free(&run);
    if (status == 0 && !o->quiet && !o->json && !o->sarif)
        say_validated(operands, count, warnings, allowed);
    return status;
}

/* The JSON Schema of the effect format, from the key tables. */
int pfx_cmd_schema(const char *const *operands, int count, const pfx_cli *o) {
    if (count != 0)
        return pfx_cli_usage_error("%s", "schema takes no FILE");
    (void)operands;
    (void)o;
    char *text = pfx_schema_text();
    if (!text) {
        fputs("pfx: out of memory\n", stderr);
        return EXIT_INVALID;
    }
    puts(text);
    free(text);
    return ferror(stdout) ? EXIT_INVALID : 0;
}
