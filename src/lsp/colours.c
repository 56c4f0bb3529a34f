/* Colour swatches and the picker: every colour of the file (a "#rgb",
 * "#rgba", "#rrggbb" or "#rrggbbaa" string anywhere, and [r, g, b(, a)]
 * with components in 0..1 under a colour key, gradient stops included)
 * as a documentColor, and a picked colour written back in the form the
 * text had. HDR colours above 1 have no swatch: a picker cannot show them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lsp/document.h"
#include "lsp/tree.h"

static int hex(char c) {
    return c >= '0' && c <= '9'   ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : -1;
}

/* "#rgb", "#rgba", "#rrggbb" or "#rrggbbaa" into rgba in 0..1. */
static bool parse_hex(const char *s, size_t n, double rgba[4]) {
    if (n < 4 || s[0] != '#' || (n != 4 && n != 5 && n != 7 && n != 9))
        return false;
    int digits = n - 1 <= 4 ? 1 : 2, count = (int)(n - 1) / digits;
    rgba[3] = 1;
    for (int i = 0; i < count; i++) {
        int hi = hex(s[1 + i * digits]), lo = digits == 2 ? hex(s[2 + i * digits]) : hi;
        if (hi < 0 || lo < 0)
            return false;
        rgba[i] = (hi * 16 + lo) / 255.0;
    }
    return true;
}

static bool colour_key(const char *k) {
    return strstr(k, "color") || strstr(k, "colour") || !strcmp(k, "background");
}

static void add(const pfx_lsp_doc *d, const pfx_node *n, const double rgba[4], json_t *out) {
    json_array_append_new(out,
                          json_pack("{s:o, s:{s:f, s:f, s:f, s:f}}", "range",
                                    pfx_lsp_range_json(d, n->line, n->col, n->span), "color", "red",
                                    rgba[0], "green", rgba[1], "blue", rgba[2], "alpha", rgba[3]));
}

/* The value of a colour key: a colour, or a list of colours or stops. */
static void colour_value(const pfx_lsp_doc *d, const pfx_node *v, int depth, json_t *out) {
    if (!v || depth > 4 || v->kind != PFX_NODE_SEQ)
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
    if (n->kind == PFX_NODE_SCALAR && !n->plain && parse_hex(n->text, n->len, rgba))
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
