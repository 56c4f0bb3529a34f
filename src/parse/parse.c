/* YAML text -> pfx_node tree through libyaml's event parser (the only file
 * that includes <yaml.h>). It enforces the structural limits (depth, alias
 * expansion, duplicate keys, scalar keys) and maps libyaml's own errors onto
 * located diagnostics; it knows nothing of the effect format. */
#include "parse/node.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "base/strmap.h"

/* A container being built: its children are gathered in a growable vector
 * and copied into the arena when it closes. */
typedef struct open_node {
    pfx_node *node;
    pfx_node **kids;
    size_t count, cap;
    uint64_t weight; /* expanded size of the subtree so far */
} open_node;

typedef struct anchor {
    char *name;
    pfx_node *node;
    uint64_t weight;
} anchor;

typedef struct parser_state {
    pfx_doc *doc;
    pfx_diags *d;
    const char *text; /* the source, for looking at the byte an error points at */
    size_t text_len;
    open_node stack[PFX_MAX_DEPTH + 1];
    int depth;
    anchor *anchors;
    size_t anchor_count, anchor_cap;
    pfx_strmap anchor_index; /* name -> its latest definition in anchors */
    uint64_t total_weight;
    bool failed;
} parser_state;

static pfx_node *new_node(parser_state *s, pfx_node_kind kind, yaml_mark_t start, yaml_mark_t end) {
    pfx_node *n = pfx_arena_alloc(&s->doc->arena, sizeof *n);
    if (!n)
        return NULL;
    n->kind = kind;
    n->line = (int)start.line + 1; /* libyaml marks are 0-based */
    n->col = (int)start.column + 1;
    n->span =
        end.line == start.line && end.column > start.column ? (int)(end.column - start.column) : 1;
    return n;
}

static bool push_child(parser_state *s, pfx_node *n, uint64_t weight) {
    s->total_weight += weight;
    if (s->depth == 0) {
        s->doc->root = n;
        return true;
    }
    open_node *o = &s->stack[s->depth - 1];
    if (o->count == o->cap) {
        size_t cap = o->cap ? o->cap * 2 : 8;
        pfx_node **kids = realloc(o->kids, cap * sizeof *kids);
        if (!kids)
            return false;
        o->kids = kids;
        o->cap = cap;
    }
    o->kids[o->count++] = n;
    o->weight += weight;
    return true;
}

static void remember_anchor(parser_state *s, const yaml_char_t *name, pfx_node *n,
                            uint64_t weight) {
    if (!name)
        return;
    if (s->anchor_count == s->anchor_cap) {
        size_t cap = s->anchor_cap ? s->anchor_cap * 2 : 8;
        anchor *a = realloc(s->anchors, cap * sizeof *a);
        if (!a)
            return;
        s->anchors = a;
        s->anchor_cap = cap;
    }
    char *copy = strdup((const char *)name);
    if (!copy)
        return;
    /* The latest definition wins, as YAML says an anchor may be redefined. */
    bool found;
    size_t *at = pfx_strmap_add(&s->anchor_index, copy, strlen(copy), s->anchor_count, &found);
    if (!at) {
        free(copy);
        return;
    }
    *at = s->anchor_count;
    s->anchors[s->anchor_count++] = (anchor){copy, n, weight};
}

static const anchor *find_anchor(const parser_state *s, const char *name) {
    const size_t *i = pfx_strmap_get(&s->anchor_index, name, strlen(name));
    return i ? &s->anchors[*i] : NULL;
}

/* Closes the container on top of the stack: copies its children into the
 * arena, checks mapping keys, and hands it to its parent. */
static bool close_container(parser_state *s, const yaml_char_t *anchor_name) {
    open_node *o = &s->stack[--s->depth];
    pfx_node *n = o->node;
    bool ok = true;
    if (n->kind == PFX_NODE_SEQ) {
        n->count = o->count;
        n->items = pfx_arena_alloc(&s->doc->arena, (o->count + 1) * sizeof *n->items);
        if (n->items && o->count) /* memcpy from NULL is undefined even for 0 bytes */
            memcpy(n->items, o->kids, o->count * sizeof *n->items);
    } else {
        size_t pairs = o->count / 2;
        n->pairs = pfx_arena_alloc(&s->doc->arena, (pairs + 1) * sizeof *n->pairs);
        n->count = 0;
        /* Duplicates by a hashed set of the keys kept so far: linear in the
         * mapping's size, however many keys a file gives it. */
        pfx_strmap seen = {.k0 = s->anchor_index.k0, .k1 = s->anchor_index.k1};
        for (size_t i = 0; n->pairs && i < pairs; i++) {
            pfx_node *k = o->kids[2 * i], *v = o->kids[2 * i + 1];
            if (k->kind != PFX_NODE_SCALAR) {
                pfx_diag_add(s->d, PFX_SEV_ERROR, k->line, k->col, 1, PFX_RULE_COMPLEX_KEY,
                             "mapping keys must be plain names, not %s", pfx_node_kind_name(k));
                ok = false;
                continue;
            }
            bool dup;
            size_t *first = pfx_strmap_add(&seen, k->text, k->len, n->count, &dup);
            if (!first) {
                ok = false;
                s->failed = true;
                break;
            }
            if (dup) {
                const pfx_node *prev = n->pairs[*first].key;
                pfx_diag_add(s->d, PFX_SEV_ERROR, k->line, k->col, (int)k->len,
                             PFX_RULE_DUPLICATE_KEY, "duplicate key '%s'", k->text);
                pfx_diag_note(s->d, prev->line, prev->col, (int)prev->len,
                              "'%s' first defined here", prev->text);
                ok = false;
                continue;
            }
            n->pairs[n->count++] = (pfx_pair){k, v};
        }
        pfx_strmap_free(&seen);
    }
    uint64_t weight = o->weight + 1;
    free(o->kids);
    o->kids = NULL;
    remember_anchor(s, anchor_name, n, weight);
    /* The subtree's own nodes were counted as they were pushed; only the
     * container itself is new. */
    s->total_weight -= o->weight;
    return push_child(s, n, weight) && ok;
}

/* libyaml's parser errors carry a problem with its position and, often, a
 * context ("while parsing a block mapping") with the position it started at:
 * the first becomes the error, the second a note. */
static void report_yaml_error(parser_state *s, const yaml_parser_t *p) {
    const char *problem = p->problem ? p->problem : "malformed YAML";
    yaml_mark_t mark = p->problem_mark;
    /* libyaml's message for a tab in indentation does not name the tab. */
    if (s->text && mark.index < s->text_len && s->text[mark.index] == '\t') {
        pfx_diag_add(s->d, PFX_SEV_ERROR, (int)mark.line + 1, (int)mark.column + 1, 1,
                     PFX_RULE_YAML_SYNTAX,
                     "found a tab where indentation is expected; YAML indents with spaces");
        return;
    }
    pfx_diag_add(s->d, PFX_SEV_ERROR, (int)mark.line + 1, (int)mark.column + 1, 1,
                 PFX_RULE_YAML_SYNTAX, "%s", problem);
    if (p->context)
        pfx_diag_note(s->d, (int)p->context_mark.line + 1, (int)p->context_mark.column + 1, 1,
                      "%s that started here", p->context);
}

/* Byte offset -> 1-based line and column, for reader errors that carry only
 * an offset. */
static void offset_to_position(const char *text, size_t len, size_t off, int *line, int *col) {
    int l = 1, c = 1;
    for (size_t i = 0; i < off && i < len; i++) {
        if (text[i] == '\n') {
            l++;
            c = 1;
        } else {
            c++;
        }
    }
    *line = l;
    *col = c;
}

static bool handle_event(parser_state *s, const yaml_event_t *ev) {
    switch (ev->type) {
    case YAML_SCALAR_EVENT: {
        pfx_node *n = new_node(s, PFX_NODE_SCALAR, ev->start_mark, ev->end_mark);
        if (!n)
            return false;
        n->text = pfx_arena_strndup(&s->doc->arena, (const char *)ev->data.scalar.value,
                                    ev->data.scalar.length);
        n->len = ev->data.scalar.length;
        n->plain = ev->data.scalar.style == YAML_PLAIN_SCALAR_STYLE;
        if (!n->text)
            return false;
        remember_anchor(s, ev->data.scalar.anchor, n, 1);
        return push_child(s, n, 1);
    }
    case YAML_SEQUENCE_START_EVENT:
    case YAML_MAPPING_START_EVENT: {
        pfx_node_kind kind = ev->type == YAML_SEQUENCE_START_EVENT ? PFX_NODE_SEQ : PFX_NODE_MAP;
        pfx_node *n = new_node(s, kind, ev->start_mark, ev->start_mark);
        if (!n)
            return false;
        if (s->depth >= PFX_MAX_DEPTH) {
            pfx_diag_add(s->d, PFX_SEV_ERROR, n->line, n->col, 1, PFX_RULE_TOO_LARGE,
                         "nesting deeper than %d levels", PFX_MAX_DEPTH);
            s->failed = true;
            return false;
        }
        s->stack[s->depth++] = (open_node){.node = n};
        return true;
    }
    case YAML_SEQUENCE_END_EVENT:
    case YAML_MAPPING_END_EVENT: {
        /* The anchor belongs to the start event; libyaml does not repeat it
         * on the end event, so it was stashed in the node's text field. */
        open_node *o = &s->stack[s->depth - 1];
        const yaml_char_t *anchor_name = (const yaml_char_t *)o->node->text;
        o->node->text = NULL;
        if (!close_container(s, anchor_name))
            s->failed = true;
        return true;
    }
    case YAML_ALIAS_EVENT: {
        const char *name = (const char *)ev->data.alias.anchor;
        const anchor *a = find_anchor(s, name);
        if (!a) {
            pfx_diag_add(s->d, PFX_SEV_ERROR, (int)ev->start_mark.line + 1,
                         (int)ev->start_mark.column + 1, (int)strlen(name) + 1,
                         PFX_RULE_UNKNOWN_ANCHOR, "unknown anchor '%s'", name);
            s->failed = true;
            return true;
        }
        if (s->total_weight + a->weight > PFX_MAX_EXPANDED_NODES) {
            pfx_diag_add(s->d, PFX_SEV_ERROR, (int)ev->start_mark.line + 1,
                         (int)ev->start_mark.column + 1, (int)strlen(name) + 1, PFX_RULE_TOO_LARGE,
                         "aliases expand to more than %d nodes", PFX_MAX_EXPANDED_NODES);
            s->failed = true;
            return false;
        }
        return push_child(s, a->node, a->weight);
    }
    default:
        return true;
    }
}

bool pfx_parse(const char *text, size_t len, pfx_doc *doc, pfx_diags *d) {
    memset(doc, 0, sizeof *doc);
    parser_state s = {.doc = doc, .d = d, .text = text, .text_len = len};
    pfx_strmap_init(&s.anchor_index);
    yaml_parser_t p;
    if (!yaml_parser_initialize(&p))
        return false;
    yaml_parser_set_input_string(&p, (const unsigned char *)text, len);
    int documents = 0;
    bool done = false, ok = true;
    while (!done) {
        yaml_event_t ev;
        if (!yaml_parser_parse(&p, &ev)) {
            if (p.error == YAML_READER_ERROR) {
                int line, col;
                offset_to_position(text, len, p.problem_offset, &line, &col);
                pfx_diag_add(d, PFX_SEV_ERROR, line, col, 1, PFX_RULE_NOT_UTF8,
                             "%s (the file must be UTF-8 text)",
                             p.problem ? p.problem : "unreadable input");
            } else {
                report_yaml_error(&s, &p);
            }
            ok = false;
            break;
        }
        if (ev.type == YAML_DOCUMENT_START_EVENT && ++documents > 1) {
            pfx_diag_add(d, PFX_SEV_ERROR, (int)ev.start_mark.line + 1,
                         (int)ev.start_mark.column + 1, 3, PFX_RULE_MULTIPLE_DOCUMENTS,
                         "an effect file holds one YAML document, found a second");
            ok = false;
            yaml_event_delete(&ev);
            break;
        }
        bool is_start = ev.type == YAML_SEQUENCE_START_EVENT || ev.type == YAML_MAPPING_START_EVENT;
        const yaml_char_t *anchor_name =
            ev.type == YAML_SEQUENCE_START_EVENT  ? ev.data.sequence_start.anchor
            : ev.type == YAML_MAPPING_START_EVENT ? ev.data.mapping_start.anchor
                                                  : NULL;
        bool go = handle_event(&s, &ev);
        if (go && is_start && anchor_name)
            s.stack[s.depth - 1].node->text = pfx_arena_strndup(
                &doc->arena, (const char *)anchor_name, strlen((const char *)anchor_name));
        done = ev.type == YAML_STREAM_END_EVENT;
        yaml_event_delete(&ev);
        if (!go) {
            ok = false;
            break;
        }
    }
    while (s.depth > 0)
        free(s.stack[--s.depth].kids);
    for (size_t i = 0; i < s.anchor_count; i++)
        free(s.anchors[i].name);
    free(s.anchors);
    pfx_strmap_free(&s.anchor_index);
    yaml_parser_delete(&p);
    if (s.failed)
        ok = false;
    if (!ok)
        doc->root = NULL;
    return ok;
}

void pfx_doc_free(pfx_doc *doc) {
    pfx_arena_free(&doc->arena);
    doc->root = NULL;
}

const pfx_node *pfx_node_get(const pfx_node *map, const char *key) {
    if (!map || map->kind != PFX_NODE_MAP)
        return NULL;
    size_t n = strlen(key);
    for (size_t i = 0; i < map->count; i++) {
        const pfx_node *k = map->pairs[i].key;
        if (k->len == n && memcmp(k->text, key, n) == 0)
            return map->pairs[i].value;
    }
    return NULL;
}

const char *pfx_node_kind_name(const pfx_node *n) {
    switch (n->kind) {
    case PFX_NODE_SEQ:
        return "a list";
    case PFX_NODE_MAP:
        return "a mapping";
    default:
        /* `key:` with nothing after it is a plain empty scalar in YAML. */
        return n->plain && n->len == 0 ? "an empty value" : "a scalar";
    }
}
