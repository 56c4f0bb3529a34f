/* Quick fixes for the diagnostics the editor sends back: apply the "did
 * you mean 'x'?" of a message (keeping the quotes of a quoted scalar),
 * and acknowledge a warning in the file with the top-level `allow` key
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
        allow(d, diag, out);
    }
    return out;
}
