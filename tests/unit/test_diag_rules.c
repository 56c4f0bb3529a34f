/* The rule table of base/diag_rules.h and how diagnostics carry it: ids
 * unique, in their category's range and in order, names unique; lookups;
 * the " [PFXnnnn]" suffix of the text form and the "rule" field of the
 * JSON form, none on notes; a few rules pinned to their published ids;
 * allowed warnings. */
#include "test.h"

#include <ctype.h>

#include "base/diag.h"

static void table_is_sound(void) {
    CHECK(pfx_rule_count >= 30);
    for (size_t i = 0; i < pfx_rule_count; i++) {
        const pfx_rule_info *r = &pfx_rules[i];
        int n = (int)r->rule, range = n / 1000;
        CHECK(n >= 1000 && n <= 9999);
        CHECK(range == 1 || range == 2 || range == 3 || range == 4 || range == 5 || range == 6 ||
              range == 9);
        CHECK(r->severity == PFX_SEV_ERROR || r->severity == PFX_SEV_WARNING);
        CHECK(range != 5 || r->severity == PFX_SEV_WARNING); /* stability: warnings */
        if (i > 0)
            CHECK(pfx_rules[i - 1].rule < r->rule); /* sorted, so unique */
        for (size_t j = 0; j < i; j++)
            CHECK(strcmp(pfx_rules[j].name, r->name) != 0);
        CHECK(r->name[0] && islower((unsigned char)r->name[0]));
        for (const char *p = r->name; *p; p++)
            CHECK(islower((unsigned char)*p) || isdigit((unsigned char)*p) ||
                  (*p == '-' && p[1] && p[1] != '-'));
        CHECK(r->help[0] && !strchr(r->help, '\n') && r->help[strlen(r->help) - 1] == '.');
        CHECK(pfx_rule_find(r->rule) == r);
    }
    CHECK(pfx_rule_find(PFX_RULE_NONE) == NULL);
    CHECK(pfx_rule_find((pfx_rule)1999) == NULL);
}

/* Published ids: these must never change (the table's comment says so). */
static void ids_are_stable(void) {
    char id[16];
    CHECK(PFX_RULE_YAML_SYNTAX == 1001);
    CHECK(PFX_RULE_UNKNOWN_KEY == 2001);
    CHECK(PFX_RULE_DUPLICATE_KEY == 2002);
    CHECK(PFX_RULE_WRONG_TYPE == 2003);
    CHECK(PFX_RULE_OUT_OF_RANGE == 3001);
    CHECK(PFX_RULE_UNKNOWN_NAME == 4001);
    CHECK(PFX_RULE_MISSING_FILE == 4002);
    CHECK(PFX_RULE_UNSTABLE_INTEGRATOR == 5001);
    CHECK(PFX_RULE_POOL_SATURATED == 6004);
    CHECK(PFX_RULE_OUT_OF_MEMORY == 9001);
    CHECK(!strcmp(pfx_rule_id(PFX_RULE_OUT_OF_RANGE, id, sizeof id), "PFX3001"));
    CHECK(!strcmp(pfx_rule_id(PFX_RULE_NONE, id, sizeof id), ""));
    CHECK(!strcmp(pfx_rule_find(PFX_RULE_OUT_OF_RANGE)->name, "out-of-range"));
    CHECK(!strcmp(pfx_rule_find(PFX_RULE_UNSTABLE_INTEGRATOR)->name, "unstable-integrator"));
    CHECK(pfx_rule_find(PFX_RULE_UNSTABLE_INTEGRATOR)->severity == PFX_SEV_WARNING);
}

/* Prints d into a string (static, overwritten by the next call). */
static const char *printed(const pfx_diags *d, bool json) {
    static char buf[4096];
    FILE *f = tmpfile();
    if (!f)
        return "";
    pfx_diags_print(d, f, json);
    rewind(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = 0;
    fclose(f);
    return buf;
}

static void forms_carry_the_rule(void) {
    static const char src[] = "pfx: 1\nrate: -3\n";
    pfx_diags d;
    pfx_diags_init(&d, "f.yaml", src, sizeof src - 1);
    pfx_diag_add(&d, PFX_SEV_ERROR, 2, 7, 2, PFX_RULE_OUT_OF_RANGE,
                 "'rate' must be greater than 0, got %d", -3);
    pfx_diag_note(&d, 1, 1, 3, "in the effect");
    CHECK(d.count == 2 && d.items[0].rule == PFX_RULE_OUT_OF_RANGE &&
          d.items[1].rule == PFX_RULE_NONE);
    CHECK(!strcmp(printed(&d, false),
                  "f.yaml:2:7: error: 'rate' must be greater than 0, got -3 [PFX3001]\n"
                  "    2 | rate: -3\n"
                  "      |       ^~\n"
                  "f.yaml:1:1: note: in the effect\n"
                  "    1 | pfx: 1\n"
                  "      | ^~~\n"));
    CHECK(!strcmp(printed(&d, true),
                  "{\"file\":\"f.yaml\",\"line\":2,\"column\":7,\"severity\":\"error\","
                  "\"rule\":\"PFX3001\",\"message\":\"'rate' must be greater than 0, got -3\"}\n"
                  "{\"file\":\"f.yaml\",\"line\":1,\"column\":1,\"severity\":\"note\","
                  "\"rule\":null,\"message\":\"in the effect\"}\n"));
    /* Appending keeps the rule. */
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    pfx_diag_error(&run, PFX_RULE_WRITE_FAILED, "cannot write '%s': %s", "x.png", "No space");
    CHECK(!strcmp(printed(&run, false), "pfx: cannot write 'x.png': No space [PFX9003]\n"));
    pfx_diags_append(&d, &run);
    CHECK(d.count == 3 && d.items[2].rule == PFX_RULE_WRITE_FAILED);
    pfx_diags_free(&run);
    pfx_diags_free(&d);
}

/* Order: groups sorted by position, each head followed by its notes. */
static void order_keeps_notes_with_their_head(void) {
    pfx_diags d;
    pfx_diags_init(&d, "f.yaml", NULL, 0);
    pfx_diag_add(&d, PFX_SEV_ERROR, 5, 1, 1, PFX_RULE_DUPLICATE_KEY, "second");
    pfx_diag_note(&d, 1, 1, 1, "first here");
    pfx_diag_add(&d, PFX_SEV_WARNING, 3, 1, 1, PFX_RULE_LOOP_SEAM, "seam");
    size_t *o = pfx_diags_order(&d);
    CHECK(o && o[0] == 2 && o[1] == 0 && o[2] == 1);
    free(o);
    pfx_diags_free(&d);
}

/* allow: a warning of an allowed rule, reported before the table is read
 * or after, is marked with the reason, counted in allowed not warnings,
 * and so are its notes; other rules and errors are untouched; appended
 * to another list it is counted there, not shown. */
static void allow_marks_and_counts(void) {
    pfx_diags d;
    pfx_diags_init(&d, "f.yaml", NULL, 0);
    pfx_diag_add(&d, PFX_SEV_WARNING, 3, 1, 1, PFX_RULE_LOOP_SEAM, "before");
    pfx_diag_note(&d, 3, 1, 1, "its note");
    pfx_diag_add(&d, PFX_SEV_WARNING, 4, 1, 1, PFX_RULE_EMPTY_EFFECT, "other rule");
    CHECK(pfx_diags_allow(&d, PFX_RULE_LOOP_SEAM, "accepted"));
    pfx_diag_add(&d, PFX_SEV_WARNING, 5, 1, 1, PFX_RULE_LOOP_SEAM, "after");
    pfx_diag_add(&d, PFX_SEV_ERROR, 6, 1, 1, PFX_RULE_LOOP_SEAM, "an error of that rule");
    CHECK(d.count == 5 && d.warnings == 1 && d.allowed == 2 && d.errors == 1);
    CHECK(d.items[0].allowed && !strcmp(d.items[0].allowed, "accepted"));
    CHECK(d.items[1].allowed == d.items[0].allowed);
    CHECK(!d.items[2].allowed && d.items[3].allowed && !d.items[4].allowed);
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    pfx_diags_append(&run, &d);
    CHECK(run.count == 2 && run.warnings == 1 && run.allowed == 2 && run.errors == 1);
    pfx_diags_free(&run);
    pfx_diags_free(&d);
}

int main(void) {
    RUN(table_is_sound);
    RUN(allow_marks_and_counts);
    RUN(ids_are_stable);
    RUN(forms_carry_the_rule);
    RUN(order_keeps_notes_with_their_head);
    return TEST_EXIT();
}
