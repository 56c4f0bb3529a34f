/* pfx's diagnostics as LSP Diagnostics: each error and warning with its
 * rule id as `code`, its severity, the range of the node it blames, and
 * the notes that follow it as relatedInformation (the key it conflicts
 * with), with, for a misspelt force, deflector or emitter, the definition
 * of the name it suggests. Also the position helpers every
 * feature shares. */
#include "lsp/document.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lsp/tree.h"

json_t *pfx_lsp_pos_json(const pfx_lsp_doc *d, int line, int col) {
    if (line < 1)
        return json_pack("{s:i, s:i}", "line", 0, "character", 0);
    return json_pack("{s:i, s:i}", "line", line - 1, "character",
                     pfx_lsp_char_of_col(&d->lines, line, col));
}

json_t *pfx_lsp_range_json(const pfx_lsp_doc *d, int line, int col, int span) {
    return json_pack("{s:o, s:o}", "start", pfx_lsp_pos_json(d, line, col), "end",
                     pfx_lsp_pos_json(d, line, line < 1 ? col : col + (span > 0 ? span : 1)));
}

json_t *pfx_lsp_range_bytes(const pfx_lsp_doc *d, size_t from, size_t to) {
    int l0, c0, l1, c1;
    pfx_lsp_position(&d->lines, from, &l0, &c0);
    pfx_lsp_position(&d->lines, to, &l1, &c1);
    return json_pack("{s:{s:i, s:i}, s:{s:i, s:i}}", "start", "line", l0, "character", c0, "end",
                     "line", l1, "character", c1);
}

/* The range of a diagnostic: its node's span, or for a flow collection
 * (whose span is its opening bracket) up to its closing bracket when that
 * is on the same line, so `[2.0, 1.2]` is underlined whole. */
static json_t *diag_range(const pfx_lsp_doc *d, const pfx_diag *g) {
    if (g->line < 1 || (size_t)g->line > d->lines.line_count)
        return pfx_lsp_range_json(d, g->line, g->col, g->span);
    size_t at =
        pfx_lsp_offset(&d->lines, g->line - 1, pfx_lsp_char_of_col(&d->lines, g->line, g->col));
    const char *t = d->lines.text;
    if (g->span == 1 && at < d->lines.len && (t[at] == '[' || t[at] == '{')) {
        int depth = 0;
        for (size_t i = at; i < d->lines.len && t[i] != '\n'; i++) {
            depth += (t[i] == '[' || t[i] == '{') - (t[i] == ']' || t[i] == '}');
            if (!depth)
                return pfx_lsp_range_bytes(d, at, i + 1);
        }
    }
    return pfx_lsp_range_json(d, g->line, g->col, g->span);
}

typedef struct definition {
    pfx_lsp_section section;
    const char *name;
    size_t len;
    const pfx_node *found;
} definition;

static void find_definition(const pfx_lsp_name *n, void *ctx) {
    definition *f = ctx;
    if (!f->found && n->definition && n->section == f->section && n->node->len == f->len &&
        !memcmp(n->node->text, f->name, f->len))
        f->found = n->node;
}

/* A reference to an unknown force, deflector or emitter whose message
 * suggests another name: the suggestion's definition as related
 * information, so the editor can show and jump to the name meant. The
 * message is the compiler's (emitter.c, compile_spawn.c). */
static void suggested_definition(const pfx_lsp_doc *d, const pfx_diag *g, json_t *head) {
    static const char *const kinds[PFX_LSP_SECTIONS] = {"unknown force '", "unknown deflector '",
                                                        "names no emitter '"};
    const char *s = g->rule == PFX_RULE_UNKNOWN_NAME ? strstr(g->message, "did you mean '") : NULL;
    if (!s)
        return;
    s += strlen("did you mean '");
    const char *e = strchr(s, '\'');
    definition f = {0, s, e ? (size_t)(e - s) : 0, NULL};
    for (int k = 0; k < PFX_LSP_SECTIONS && e; k++)
        if (strstr(g->message, kinds[k])) {
            f.section = (pfx_lsp_section)k;
            pfx_lsp_names(d->loaded.doc.root, find_definition, &f);
        }
    if (!f.found)
        return;
    char msg[160];
    snprintf(msg, sizeof msg, "'%.*s' is defined here", (int)f.len, f.name);
    json_t *rel = json_array();
    json_array_append_new(
        rel, json_pack("{s:{s:s, s:o}, s:s}", "location", "uri", d->uri, "range",
                       pfx_lsp_range_json(d, f.found->line, f.found->col, f.found->span), "message",
                       msg));
    json_object_set_new(head, "relatedInformation", rel);
}

/* LSP's DiagnosticSeverity: 1 error, 2 warning, 3 information. */
static int severity(pfx_severity s) {
    return s == PFX_SEV_ERROR ? 1 : s == PFX_SEV_WARNING ? 2 : 3;
}

/* Appends the diagnostics of list to out, each head with its notes. */
static void add_list(const pfx_lsp_doc *d, const pfx_diags *list, json_t *out) {
    size_t *order = pfx_diags_order(list);
    if (!order)
        return;
    json_t *head = NULL;
    for (size_t i = 0; i < list->count; i++) {
        const pfx_diag *g = &list->items[order[i]];
        /* A warning the file's `allow:` acknowledges is not shown, as
         * validate does not print it; its notes share its reason. */
        if (g->allowed) {
            head = NULL;
            continue;
        }
        if (g->severity == PFX_SEV_NOTE && head) {
            json_t *rel = json_object_get(head, "relatedInformation");
            if (!rel) {
                rel = json_array();
                json_object_set_new(head, "relatedInformation", rel);
            }
            json_array_append_new(rel, json_pack("{s:{s:s, s:o}, s:s}", "location", "uri", d->uri,
                                                 "range",
                                                 pfx_lsp_range_json(d, g->line, g->col, g->span),
                                                 "message", g->message));
            continue;
        }
        char id[16];
        pfx_rule_id(g->rule, id, sizeof id);
        head = json_pack("{s:o, s:i, s:s, s:s}", "range", diag_range(d, g), "severity",
                         severity(g->severity), "source", "pfx", "message", g->message);
        if (!head)
            continue;
        if (*id)
            json_object_set_new(head, "code", json_string(id));
        suggested_definition(d, g, head);
        json_array_append_new(out, head);
    }
    free(order);
}

json_t *pfx_lsp_diagnostics(const pfx_lsp_doc *d) {
    json_t *out = json_array();
    if (!out || !d->analysed)
        return out;
    add_list(d, &d->loaded.overrides.diags, out);
    add_list(d, &d->loaded.diags, out);
    return out;
}
