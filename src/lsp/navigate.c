/* The outline (documentSymbol) and the names of forces, deflectors and
 * emitters: go to definition, find references, rename. A name's places
 * come from lsp/tree.c's one walk, so the three always agree. */
#include <string.h>

#include "lsp/document.h"
#include "lsp/tree.h"

/* The end (line, col just past it) of everything n holds. */
static void node_end(const pfx_node *n, int depth, int *line, int *col) {
    if (!n || depth > PFX_MAX_DEPTH)
        return;
    int l = n->line, c = n->col + (n->span > 0 ? n->span : 1);
    if (l > *line || (l == *line && c > *col))
        *line = l, *col = c;
    if (n->kind == PFX_NODE_SEQ)
        for (size_t i = 0; i < n->count; i++)
            node_end(n->items[i], depth + 1, line, col);
    if (n->kind == PFX_NODE_MAP)
        for (size_t i = 0; i < n->count; i++) {
            node_end(n->pairs[i].key, depth + 1, line, col);
            node_end(n->pairs[i].value, depth + 1, line, col);
        }
}

/* LSP's SymbolKind. */
enum { SYM_MODULE = 2, SYM_CLASS = 5, SYM_FUNCTION = 12, SYM_OBJECT = 19 };

static json_t *symbol(const pfx_lsp_doc *d, const pfx_node *k, const pfx_node *v, int kind,
                      const char *detail) {
    int el = k->line, ec = k->col + k->span;
    node_end(v, 0, &el, &ec);
    json_t *range = json_pack("{s:o, s:o}", "start", pfx_lsp_pos_json(d, k->line, k->col), "end",
                              pfx_lsp_pos_json(d, el, ec));
    json_t *s = json_pack("{s:s, s:i, s:o, s:o}", "name", k->len ? k->text : "(empty)", "kind",
                          kind, "range", range, "selectionRange",
                          pfx_lsp_range_json(d, k->line, k->col, k->span));
    if (s && detail)
        json_object_set_new(s, "detail", json_string(detail));
    return s;
}

json_t *pfx_lsp_symbols(const pfx_lsp_doc *d) {
    static const int entry_kinds[PFX_LSP_SECTIONS] = {SYM_FUNCTION, SYM_OBJECT, SYM_CLASS};
    json_t *out = json_array();
    const pfx_node *root = d->loaded.doc.root;
    if (!out || !root || root->kind != PFX_NODE_MAP)
        return out;
    for (size_t i = 0; i < root->count; i++) {
        const pfx_node *k = root->pairs[i].key, *v = root->pairs[i].value;
        int sec = -1;
        for (int s = 0; s < PFX_LSP_SECTIONS; s++)
            if (!strcmp(k->text, pfx_lsp_section_names[s]))
                sec = s;
        bool block = v && v->kind == PFX_NODE_MAP;
        if (!block)
            continue; /* the outline: the sections and the mappings (camera, image, sim) */
        json_t *s = symbol(d, k, v, sec >= 0 ? SYM_MODULE : SYM_OBJECT, NULL);
        if (!s)
            continue;
        if (sec >= 0) {
            json_t *kids = json_array();
            for (size_t e = 0; e < v->count; e++) {
                const pfx_node *t = NULL, *ev = v->pairs[e].value;
                if (ev && ev->kind == PFX_NODE_MAP)
                    t = pfx_node_get(ev, "type");
                json_array_append_new(kids,
                                      symbol(d, v->pairs[e].key, ev, entry_kinds[sec],
                                             t && t->kind == PFX_NODE_SCALAR ? t->text : NULL));
            }
            json_object_set_new(s, "children", kids);
        }
        json_array_append_new(out, s);
    }
    return out;
}

/* The range of a name's text: inside the quotes of a quoted scalar. */
static json_t *name_range(const pfx_lsp_doc *d, const pfx_node *n) {
    bool quoted = !n->plain && n->span >= 2;
    return pfx_lsp_range_json(d, n->line, n->col + quoted, quoted ? n->span - 2 : n->span);
}

typedef struct gather {
    const pfx_lsp_doc *d;
    pfx_lsp_section section;
    const char *name;
    bool declaration; /* include the definition */
    json_t *out;      /* Locations, or TextEdits when new_name is set */
    const char *new_name;
    const pfx_node *definition;
} gather;

static void gather_one(const pfx_lsp_name *n, void *ctx) {
    gather *g = ctx;
    if (n->section != g->section || strcmp(n->node->text, g->name))
        return;
    if (n->definition && !g->definition)
        g->definition = n->node;
    if (n->definition && !g->declaration)
        return;
    json_t *range = name_range(g->d, n->node);
    if (g->new_name)
        json_array_append_new(g->out,
                              json_pack("{s:o, s:s}", "range", range, "newText", g->new_name));
    else
        json_array_append_new(g->out, json_pack("{s:s, s:o}", "uri", g->d->uri, "range", range));
}

/* Gathers the places of the name at (line, character); false if none. */
static bool gather_at(const pfx_lsp_doc *d, int line, int character, gather *g) {
    int col = pfx_lsp_col_of_char(&d->lines, line, character);
    pfx_lsp_name at;
    if (!pfx_lsp_name_at(d->loaded.doc.root, line + 1, col, &at))
        return false;
    g->d = d;
    g->section = at.section;
    g->name = at.node->text;
    g->out = json_array();
    pfx_lsp_names(d->loaded.doc.root, gather_one, g);
    return g->out != NULL;
}

json_t *pfx_lsp_definition(const pfx_lsp_doc *d, int line, int character) {
    gather g = {0};
    if (!gather_at(d, line, character, &g))
        return json_null();
    json_decref(g.out);
    if (!g.definition)
        return json_null();
    return json_pack("{s:s, s:o}", "uri", d->uri, "range", name_range(d, g.definition));
}

json_t *pfx_lsp_references(const pfx_lsp_doc *d, int line, int character, bool declaration) {
    gather g = {0};
    g.declaration = declaration;
    if (!gather_at(d, line, character, &g))
        return json_null();
    return g.out;
}

/* A new name must be a plain YAML key: letters, digits, '_' and '-'. */
static bool plain_name(const char *s) {
    if (!s || !*s || strlen(s) > 128)
        return false;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') ||
              *s == '_' || *s == '-'))
            return false;
    return true;
}

typedef struct taken {
    pfx_lsp_section section;
    const char *name;
    bool found;
} taken;

static void find_taken(const pfx_lsp_name *n, void *ctx) {
    taken *t = ctx;
    t->found |= n->definition && n->section == t->section && !strcmp(n->node->text, t->name);
}

json_t *pfx_lsp_rename(const pfx_lsp_doc *d, int line, int character, const char *new_name) {
    gather g = {0};
    g.declaration = true;
    g.new_name = new_name;
    if (!gather_at(d, line, character, &g))
        return json_null(); /* nothing to rename there */
    taken t = {g.section, new_name, false};
    if (plain_name(new_name))
        pfx_lsp_names(d->loaded.doc.root, find_taken, &t);
    if (!plain_name(new_name) || t.found) {
        json_decref(g.out);
        return NULL; /* refused: two things would share a name */
    }
    return json_pack("{s:{s:o}}", "changes", d->uri, g.out);
}
