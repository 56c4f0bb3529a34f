/* Colour swatches and the picker: every colour of the file as a
 * documentColor (a "#rgb", "#rgba", "#rrggbb" or "#rrggbbaa" string
 * anywhere; a CSS colour name, transparent, or [r, g, b(, a)] with
 * components in 0..1 under a colour key, gradient stops, {random} and
 * {pick} included), each word read as the compiler reads it
 * (compile/colour_text.h), and a picked colour written back in the form
 * the text had (a name as a quoted hex). HDR colours above 1 have no swatch: a picker cannot show
 * them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/colour_text.h"
#include "lsp/document.h"
#include "lsp/tree.h"

static bool colour_key(const char *k) {
    return strstr(k, "color") || strstr(k, "colour") || !strcmp(k, "background");
}

static void add(const pfx_lsp_doc *d, const pfx_node *n, const double rgba[4], json_t *out) {
    json_array_append_new(out,
                          json_pack("{s:o, s:{s:f, s:f, s:f, s:f}}", "range",
                                    pfx_lsp_range_json(d, n->line, n->col, n->span), "color", "red",
                                    rgba[0], "green", rgba[1], "blue", rgba[2], "alpha", rgba[3]));
}

/* A colour word (compile/colour_text.h) as a swatch's rgba; false when
 * n is not one. */
static bool colour_word(const pfx_node *n, double rgba[4]) {
    float c[4];
    if (n->kind != PFX_NODE_SCALAR || !pfx_colour_parse_word(n->text, c))
        return false;
    for (int i = 0; i < 4; i++)
        rgba[i] = c[i];
    return true;
}

/* The value of a colour key: a colour, a list of colours or stops, or a
 * {random: [c1, c2]} or {pick: gradient}. A quoted hex string is walk's
 * (it has a swatch wherever it is); a stop's own colour key is too. */
static void colour_value(const pfx_lsp_doc *d, const pfx_node *v, int depth, json_t *out) {
    double word[4];
    if (!v || depth > 4)
        return;
    if (v->kind == PFX_NODE_SCALAR && v->text[0] != '#' && colour_word(v, word))
        add(d, v, word, out);
    if (v->kind == PFX_NODE_MAP)
        for (size_t i = 0; i < v->count; i++)
            if (!colour_key(v->pairs[i].key->text))
                colour_value(d, v->pairs[i].value, depth + 1, out);
    if (v->kind != PFX_NODE_SEQ)
        return;
    if (v->count == 3 || v->count == 4) {
        double rgba[4] = {0, 0, 0, 1};
        size_t i = 0;
        for (; i < v->count; i++) {
            const pfx_node *c = v->items[i];
            char *end;
            if (c->kind != PFX_NODE_SCALAR || !c->plain)
                break;
            rgba[i] = strtod(c->text, &end);
            if (*end || !(rgba[i] >= 0 && rgba[i] <= 1))
                break;
        }
        if (i == v->count && v->line == v->items[v->count - 1]->line) {
            add(d, v, rgba, out);
            return;
        }
    }
    for (size_t i = 0; i < v->count; i++)
        colour_value(d, v->items[i], depth + 1, out);
}

static void walk(const pfx_lsp_doc *d, const pfx_node *n, int depth, json_t *out) {
    if (!n || depth > PFX_MAX_DEPTH || json_array_size(out) >= 10000)
        return;
    double rgba[4];
    if (n->kind == PFX_NODE_SCALAR && !n->plain && n->text[0] == '#' && colour_word(n, rgba))
        add(d, n, rgba, out);
    if (n->kind == PFX_NODE_SEQ)
        for (size_t i = 0; i < n->count; i++)
            walk(d, n->items[i], depth + 1, out);
    if (n->kind == PFX_NODE_MAP)
        for (size_t i = 0; i < n->count; i++) {
            if (colour_key(n->pairs[i].key->text))
                colour_value(d, n->pairs[i].value, 0, out);
            walk(d, n->pairs[i].value, depth + 1, out);
        }
}

json_t *pfx_lsp_colors(const pfx_lsp_doc *d) {
    json_t *out = json_array();
    if (out)
        walk(d, d->loaded.doc.root, 0, out);
    return out;
}

static int byte(double v) {
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    return (int)lround(v * 255);
}

json_t *pfx_lsp_color_presentations(const pfx_lsp_doc *d, json_t *params) {
    json_t *c = json_object_get(params, "color"), *range = json_object_get(params, "range");
    double r = json_number_value(json_object_get(c, "red")),
           g = json_number_value(json_object_get(c, "green")),
           b = json_number_value(json_object_get(c, "blue")),
           a = json_number_value(json_object_get(c, "alpha"));
    size_t from = pfx_lsp_offset(
        &d->lines,
        (int)json_integer_value(json_object_get(json_object_get(range, "start"), "line")),
        (int)json_integer_value(json_object_get(json_object_get(range, "start"), "character")));
    bool list = from < d->lines.len && d->lines.text[from] == '[';
    char text[96];
    if (list && byte(a) == 255)
        snprintf(text, sizeof text, "[%.3g, %.3g, %.3g]", r, g, b);
    else if (list)
        snprintf(text, sizeof text, "[%.3g, %.3g, %.3g, %.3g]", r, g, b, a);
    else if (byte(a) == 255)
        snprintf(text, sizeof text, "\"#%02x%02x%02x\"", byte(r), byte(g), byte(b));
    else
        snprintf(text, sizeof text, "\"#%02x%02x%02x%02x\"", byte(r), byte(g), byte(b), byte(a));
    return json_pack("[{s:s, s:{s:O, s:s}}]", "label", text, "textEdit", "range", range, "newText",
                     text);
}
