/* `allow:` at the top of an effect: warnings its author has read and
 * accepts, each rule id with the reason (`allow: {PFX5002: "..."}`). The
 * table goes into the file's diagnostics list, which marks the warnings
 * of those rules as allowed wherever they come from (the compiler, the
 * estimate); it does not decide what is printed. */
#include <stdlib.h>
#include <string.h>

#include "compile/compiler.h"

/* The rule named by id "PFXnnnn", or NULL. */
static const pfx_rule_info *rule_of_id(const char *id) {
    if (strncmp(id, "PFX", 3) != 0 || strlen(id) != 7 || strspn(id + 3, "0123456789") != 4)
        return NULL;
    return pfx_rule_find((pfx_rule)atoi(id + 3));
}

/* Reports an unknown rule id at key k: the id of a rule written by its
 * name ("loop-seam"), else the nearest warning id. */
static void unknown_rule(pfx_reader *r, const pfx_node *k) {
    enum { MAX_IDS = 64 };
    const char *ids[MAX_IDS + 1];
    char buf[MAX_IDS][12];
    size_t n = 0;
    for (size_t i = 0; i < pfx_rule_count && n < MAX_IDS; i++) {
        if (!strcmp(pfx_rules[i].name, k->text)) {
            pfx_read_error(r, k, PFX_RULE_UNKNOWN_CHOICE,
                           "'allow' takes rule ids, not names: write %s for '%s'",
                           pfx_rule_id(pfx_rules[i].rule, buf[0], sizeof buf[0]), k->text);
            return;
        }
        if (pfx_rules[i].severity == PFX_SEV_WARNING)
            ids[n] = pfx_rule_id(pfx_rules[i].rule, buf[n], sizeof buf[n]), n++;
    }
    ids[n] = NULL;
    const char *near = pfx_suggest(k->text, ids);
    if (near)
        pfx_read_error(r, k, PFX_RULE_UNKNOWN_CHOICE,
                       "unknown rule '%s' in 'allow'; did you mean %s?", k->text, near);
    else
        pfx_read_error(r, k, PFX_RULE_UNKNOWN_CHOICE,
                       "unknown rule '%s' in 'allow' (pfx validate --list-rules lists them)",
                       k->text);
}

void pfx_compile_allow(compiler *c, const pfx_node *allow) {
    pfx_reader *r = &c->r;
    if (!pfx_read_map(r, allow, "allow"))
        return;
    for (size_t i = 0; i < allow->count; i++) {
        const pfx_node *k = allow->pairs[i].key, *v = allow->pairs[i].value;
        const pfx_rule_info *rule = rule_of_id(k->text);
        if (!rule) {
            unknown_rule(r, k);
            continue;
        }
        if (rule->severity != PFX_SEV_WARNING) {
            pfx_read_error(r, k, PFX_RULE_INAPPLICABLE_KEY,
                           "%s (%s) is an error, which 'allow' cannot acknowledge; only warnings "
                           "can be allowed",
                           k->text, rule->name);
            continue;
        }
        if (v->kind != PFX_NODE_SCALAR) {
            pfx_read_error(r, v, PFX_RULE_WRONG_TYPE,
                           "the reason for allowing %s must be text, got %s", k->text,
                           pfx_node_kind_name(v));
            continue;
        }
        if (v->len == 0 || strspn(v->text, " \t") == v->len) {
            pfx_read_error(r, v, PFX_RULE_MALFORMED_VALUE,
                           "the reason for allowing %s is empty; say why the warning is acceptable",
                           k->text);
            continue;
        }
        if (!pfx_diags_allow(r->d, rule->rule, v->text))
            pfx_read_error(r, v, PFX_RULE_OUT_OF_MEMORY, "out of memory for 'allow'");
    }
}
