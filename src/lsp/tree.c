/* The key at a position and the names of an effect, from the parsed tree.
 * The table of a mapping follows the compiler's own: a MAP row's table,
 * the named sections (forces, deflectors, emitters), and the kinded
 * families whose `type` picks the table (shape, region, force, deflector).
 * Walks are bounded by the parser's limits on depth and expanded size. */
#include "lsp/tree.h"

#include <string.h>

#include "compile/compiler.h"

const char *const pfx_lsp_section_names[PFX_LSP_SECTIONS] = {"forces", "deflectors", "emitters"};

bool pfx_lsp_covers(const pfx_node *n, int line, int col) {
    return n && n->kind == PFX_NODE_SCALAR && n->line == line && col >= n->col &&
           col < n->col + (n->span > 0 ? n->span : 1) + 1; /* the cursor just after it counts */
}

pfx_lsp_place pfx_lsp_top_place(const pfx_node *root) {
    pfx_lsp_place p = {&pfx_schema_top, NULL, -1, root, NULL};
    return p;
}

/* A kinded mapping of family fam: the table its `type` names. */
static bool kinded(const char *fam, const char *type, const char *emitter, pfx_lsp_place *out) {
    const pfx_schema_family *f = NULL;
    for (const pfx_schema_family *g = pfx_schema_families; g->name; g++)
        if (!strcmp(g->name, fam))
            f = g;
    if (!f)
        return false;
    *out = (pfx_lsp_place){NULL, f, -1, NULL, emitter};
    for (size_t i = 0; type && f->kinds[i]; i++)
        if (!strcmp(f->kinds[i], type))
            out->table = f->tables[i];
    return true;
}

bool pfx_lsp_descend(const pfx_lsp_place *in, const char *name, const char *type,
                     pfx_lsp_place *out) {
    if (in->section == PFX_LSP_EMITTER) {
        *out = (pfx_lsp_place){&pfx_emitter_table, NULL, -1, NULL, name};
        return true;
    }
    if (in->section >= 0)
        return kinded(in->section == PFX_LSP_FORCE ? "force" : "deflector", type, NULL, out);
    if (in->table == &pfx_schema_top)
        for (int s = 0; s < PFX_LSP_SECTIONS; s++)
            if (!strcmp(name, pfx_lsp_section_names[s])) {
                *out = (pfx_lsp_place){NULL, NULL, s, NULL, NULL};
                return true;
            }
    if (in->table == &pfx_emitter_table && !strcmp(name, "shape"))
        return kinded("shape", type, in->emitter, out);
    if (in->family && !strcmp(in->family->name, "force") && !strcmp(name, "region"))
        return kinded("region", type, in->emitter, out);
    const pfx_key *row = in->table ? pfx_keys_find(in->table, name) : NULL;
    if (row && row->type == PFX_KEY_MAP && row->table) {
        *out = (pfx_lsp_place){row->table, NULL, -1, NULL, in->emitter};
        return true;
    }
    return false;
}

/* The place of mapping v under key k of in, with its map set. */
static bool child_place(const pfx_lsp_place *in, const pfx_node *k, const pfx_node *v,
                        pfx_lsp_place *out) {
    if (!v || v->kind != PFX_NODE_MAP)
        return false;
    const pfx_node *t = pfx_node_get(v, "type");
    if (!pfx_lsp_descend(in, k->text, t && t->kind == PFX_NODE_SCALAR ? t->text : NULL, out))
        return false;
    out->map = v;
    return true;
}

/* Searches the mapping of place p, then what it holds, for (line, col). */
static bool find_in(const pfx_lsp_place *p, int line, int col, int depth, pfx_lsp_hit *hit);

/* Searches any node without a table: a scalar value, a list, a mapping. */
static bool find_value(const pfx_lsp_place *p, const pfx_node *key, const pfx_node *v, int line,
                       int col, int depth, pfx_lsp_hit *hit) {
    if (!v || depth > PFX_MAX_DEPTH)
        return false;
    if (v->kind == PFX_NODE_SCALAR) {
        if (!pfx_lsp_covers(v, line, col))
            return false;
        *hit = (pfx_lsp_hit){*p, key, v, NULL};
        if (key && p->table)
            hit->row = pfx_keys_find(p->table, key->text);
        return true;
    }
    if (v->line > line)
        return false; /* a node starts before everything it holds */
    if (v->kind == PFX_NODE_SEQ) {
        for (size_t i = 0; i < v->count; i++)
            if (find_value(p, key, v->items[i], line, col, depth + 1, hit))
                return true;
        return false;
    }
    pfx_lsp_place none = {NULL, NULL, -1, v, p->emitter};
    return find_in(&none, line, col, depth + 1, hit);
}

static bool find_in(const pfx_lsp_place *p, int line, int col, int depth, pfx_lsp_hit *hit) {
    const pfx_node *m = p->map;
    if (!m || m->kind != PFX_NODE_MAP || depth > PFX_MAX_DEPTH)
        return false;
    for (size_t i = 0; i < m->count; i++) {
        const pfx_node *k = m->pairs[i].key, *v = m->pairs[i].value;
        if (pfx_lsp_covers(k, line, col)) {
            *hit = (pfx_lsp_hit){*p, k, NULL, p->table ? pfx_keys_find(p->table, k->text) : NULL};
            return true;
        }
        if (!v || v->line > line)
            continue;
        pfx_lsp_place child;
        if (child_place(p, k, v, &child)) {
            if (find_in(&child, line, col, depth + 1, hit))
                return true;
            continue;
        }
        if (find_value(p, k, v, line, col, depth + 1, hit))
            return true;
    }
    return false;
}

bool pfx_lsp_find(const pfx_node *root, int line, int col, pfx_lsp_hit *hit) {
    pfx_lsp_place top = pfx_lsp_top_place(root);
    return root && find_in(&top, line, col, 0, hit);
}

/* Every `emit:` below n (sub-emitters and trails name emitters). */
static void emits(const pfx_node *n, int depth, void (*fn)(const pfx_lsp_name *, void *),
                  void *ctx) {
    if (!n || depth > PFX_MAX_DEPTH)
        return;
    if (n->kind == PFX_NODE_SEQ)
        for (size_t i = 0; i < n->count; i++)
            emits(n->items[i], depth + 1, fn, ctx);
    if (n->kind != PFX_NODE_MAP)
        return;
    for (size_t i = 0; i < n->count; i++) {
        const pfx_node *k = n->pairs[i].key, *v = n->pairs[i].value;
        if (!strcmp(k->text, "emit") && v && v->kind == PFX_NODE_SCALAR) {
            pfx_lsp_name r = {PFX_LSP_EMITTER, v, false};
            fn(&r, ctx);
        } else
            emits(v, depth + 1, fn, ctx);
    }
}

void pfx_lsp_names(const pfx_node *root, void (*fn)(const pfx_lsp_name *n, void *ctx), void *ctx) {
    if (!root || root->kind != PFX_NODE_MAP)
        return;
    for (size_t i = 0; i < root->count; i++) {
        const pfx_node *k = root->pairs[i].key, *v = root->pairs[i].value;
        int sec = -1;
        for (int x = 0; x < PFX_LSP_SECTIONS; x++)
            if (!strcmp(k->text, pfx_lsp_section_names[x]))
                sec = x;
        if (sec < 0 || !v || v->kind != PFX_NODE_MAP)
            continue;
        for (size_t e = 0; e < v->count; e++) {
            pfx_lsp_name d = {(pfx_lsp_section)sec, v->pairs[e].key, true};
            fn(&d, ctx);
            const pfx_node *ev = v->pairs[e].value;
            if (sec != PFX_LSP_EMITTER || !ev || ev->kind != PFX_NODE_MAP)
                continue;
            for (size_t j = 0; j < ev->count; j++) {
                const pfx_node *ek = ev->pairs[j].key, *lv = ev->pairs[j].value;
                int ref = !strcmp(ek->text, "forces")       ? PFX_LSP_FORCE
                          : !strcmp(ek->text, "deflectors") ? PFX_LSP_DEFLECTOR
                                                            : -1;
                if (ref >= 0 && lv && lv->kind == PFX_NODE_SEQ) {
                    for (size_t x = 0; x < lv->count; x++)
                        if (lv->items[x]->kind == PFX_NODE_SCALAR) {
                            pfx_lsp_name r = {(pfx_lsp_section)ref, lv->items[x], false};
                            fn(&r, ctx);
                        }
                } else if (ref < 0)
                    emits(lv, 0, fn, ctx);
            }
        }
    }
}

typedef struct name_search {
    int line, col;
    pfx_lsp_name found;
    bool ok;
} name_search;

static void match_name(const pfx_lsp_name *n, void *ctx) {
    name_search *s = ctx;
    if (!s->ok && pfx_lsp_covers(n->node, s->line, s->col)) {
        s->found = *n;
        s->ok = true;
    }
}

bool pfx_lsp_name_at(const pfx_node *root, int line, int col, pfx_lsp_name *out) {
    name_search s = {line, col, {0}, false};
    pfx_lsp_names(root, match_name, &s);
    *out = s.found;
    return s.ok;
}
