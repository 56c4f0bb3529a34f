/* Quick fixes for the diagnostics the editor sends back: apply the "did
 * you mean 'x'?" of a message (keeping the quotes of a quoted scalar),
 * apply the integrator a stability warning names ("emitter 'e': ... use
 * integrator 'exact'") to that emitter, and acknowledge a warning in the file with the top-level
 * `allow` key
 * (`allow: {PFXNNNN: "reason"}`): a line added to an existing block, or
 * the block added after the `pfx:` line. */
#include <stdio.h>
#include <string.h>

#include "lsp/document.h"

static json_t *edit_action(const pfx_lsp_doc *d, const char *title, json_t *diag, json_t *range,
                           const char *text, bool preferred) {
    json_t *edit = json_pack("{s:o, s:s}", "range", range, "newText", text);
    return json_pack("{s:s, s:s, s:[O], s:b, s:{s:{s:[o]}}}", "title", title, "kind", "quickfix",
                     "diagnostics", diag, "isPreferred", preferred, "edit", "changes", d->uri,
                     edit);
}

/* The text of an LSP range on one line of d (its first byte, and length). */
static const char *range_text(const pfx_lsp_doc *d, json_t *range, size_t *n) {
    json_t *s = json_object_get(range, "start"), *e = json_object_get(range, "end");
    size_t a = pfx_lsp_offset(&d->lines, (int)json_integer_value(json_object_get(s, "line")),
                              (int)json_integer_value(json_object_get(s, "character")));
    size_t b = pfx_lsp_offset(&d->lines, (int)json_integer_value(json_object_get(e, "line")),
                              (int)json_integer_value(json_object_get(e, "character")));
    *n = b > a ? b - a : 0;
    return d->lines.text + a;
}

static void suggestion(const pfx_lsp_doc *d, json_t *diag, json_t *out) {
    const char *msg = json_string_value(json_object_get(diag, "message"));
    const char *p = msg ? strstr(msg, "did you mean '") : NULL;
    if (!p)
        return;
    p += strlen("did you mean '");
    const char *q = strchr(p, '\'');
    if (!q || q - p > 200)
        return;
    json_t *range = json_object_get(diag, "range");
    size_t n;
    const char *old = range_text(d, range, &n);
    char text[256], title[300];
    char quote = n >= 2 && (old[0] == '"' || old[0] == '\'') ? old[0] : 0;
    if (quote)
        snprintf(text, sizeof text, "%c%.*s%c", quote, (int)(q - p), p, quote);
    else
        snprintf(text, sizeof text, "%.*s", (int)(q - p), p);
    snprintf(title, sizeof title, "Change to '%.*s'", (int)(q - p), p);
    json_array_append_new(out, edit_action(d, title, diag, json_deep_copy(range), text, true));
}

static void allow(const pfx_lsp_doc *d, json_t *diag, json_t *out) {
    const char *code = json_string_value(json_object_get(diag, "code"));
    if (json_integer_value(json_object_get(diag, "severity")) != 2 || !code ||
        strncmp(code, "PFX", 3) || strlen(code) > 12)
        return;
    const pfx_node *root = d->loaded.doc.root, *pfx = NULL, *block = NULL, *key = NULL;
    for (size_t i = 0; root && root->kind == PFX_NODE_MAP && i < root->count; i++) {
        if (!strcmp(root->pairs[i].key->text, "pfx"))
            pfx = root->pairs[i].key;
        if (!strcmp(root->pairs[i].key->text, "allow")) {
            key = root->pairs[i].key;
            block = root->pairs[i].value;
        }
    }
    char text[128], title[64];
    int line; /* 0-based: the new text goes at the start of this line */
    if (block && block->kind == PFX_NODE_MAP && block->count && block->line > key->line) {
        /* A block mapping: one more line at its first child's indentation. */
        line = key->line;
        snprintf(text, sizeof text, "%*s%s: \"why this is intended\"\n",
                 block->pairs[0].key->col - 1, "", code);
    } else if (key) {
        return; /* an `allow` written another way: leave it to the user */
    } else {
        line = pfx ? pfx->line : 0;
        snprintf(text, sizeof text, "allow:\n  %s: \"why this is intended\"\n", code);
    }
    json_t *at = json_pack("{s:i, s:i}", "line", line, "character", 0);
    json_t *range = json_pack("{s:o, s:O}", "start", at, "end", at);
    snprintf(title, sizeof title, "Allow %s in this file", code);
    json_array_append_new(out, edit_action(d, title, diag, range, text, false));
}

/* The block mapping of emitter `name`, or NULL. */
static const pfx_node *emitter_map(const pfx_node *root, const char *name, size_t n) {
    const pfx_node *ems =
        root && root->kind == PFX_NODE_MAP ? pfx_node_get(root, "emitters") : NULL;
    for (size_t i = 0; ems && ems->kind == PFX_NODE_MAP && i < ems->count; i++)
        if (ems->pairs[i].key->len == n && !memcmp(ems->pairs[i].key->text, name, n))
            return ems->pairs[i].value;
    return NULL;
}

/* Whether mapping m is written in flow style ({...}). */
static bool flow(const pfx_lsp_doc *d, const pfx_node *m) {
    size_t at =
        pfx_lsp_offset(&d->lines, m->line - 1, pfx_lsp_char_of_col(&d->lines, m->line, m->col));
    return at < d->lines.len && d->lines.text[at] == '{';
}

static void integrator_fix(const pfx_lsp_doc *d, json_t *diag, json_t *out) {
    const char *msg = json_string_value(json_object_get(diag, "message"));
    const char *code = json_string_value(json_object_get(diag, "code"));
    if (!msg || !code || strcmp(code, "PFX5001") || strncmp(msg, "emitter '", 9))
        return;
    const char *name = msg + 9, *name_end = strchr(name, '\'');
    const char *use = strstr(msg, "use integrator '");
    if (!name_end || !use)
        return;
    use += strlen("use integrator '");
    const char *use_end = strchr(use, '\'');
    const pfx_node *em = emitter_map(d->loaded.doc.root, name, (size_t)(name_end - name));
    if (!use_end || use_end - use > 32 || !em || em->kind != PFX_NODE_MAP || !em->count)
        return;
    char text[96], title[96];
    json_t *range;
    const pfx_node *now = pfx_node_get(em, "integrator");
    if (now && now->kind == PFX_NODE_SCALAR) { /* replace the one chosen */
        snprintf(text, sizeof text, "%.*s", (int)(use_end - use), use);
        range = pfx_lsp_range_json(d, now->line, now->col, now->span);
    } else if (!flow(d, em)) { /* a block: a line before its first key */
        const pfx_node *first = em->pairs[0].key;
        snprintf(text, sizeof text, "%*sintegrator: %.*s\n", first->col - 1, "",
                 (int)(use_end - use), use);
        json_t *at = json_pack("{s:i, s:i}", "line", first->line - 1, "character", 0);
        range = json_pack("{s:o, s:O}", "start", at, "end", at);
    } else {
        return;
    }
    snprintf(title, sizeof title, "Use integrator '%.*s' in emitter '%.*s'", (int)(use_end - use),
             use, (int)(name_end - name), name);
    json_array_append_new(out, edit_action(d, title, diag, range, text, true));
}

json_t *pfx_lsp_code_actions(const pfx_lsp_doc *d, json_t *params) {
    json_t *out = json_array(), *diag;
    json_t *diags = json_object_get(json_object_get(params, "context"), "diagnostics");
    size_t i;
    if (!out)
        return out;
    json_array_foreach(diags, i, diag) {
        if (i >= 64)
            break;
        suggestion(d, diag, out);
        integrator_fix(d, diag, out);
        allow(d, diag, out);
    }
    return out;
}
