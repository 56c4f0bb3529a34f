/* --set PATH=VALUE on the parsed node tree: walks PATH (keys and list
 * indices), parses VALUE as YAML and puts it there, asking the effect
 * format's JSON Schema (compile/schema.c) whether an absent key exists. It
 * does not check the value: compile does, and its diagnostics located in a
 * value are moved back here so they point at the --set argument. */
#include "jobs/overrides.h"

#include <jansson.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "compile/read.h"
#include "compile/schema.h"

/* Nodes made from --set k carry line PFX_SET_LINE + k: past any line of
 * an effect file (at most 16 MiB), so compile's diagnostics in them can be
 * told from the file's and moved to the --set list. */
#define PFX_SET_LINE (1 << 30)

/* The schemas a position of the tree may follow: every branch of a oneOf,
 * anyOf or allOf and every $ref, expanded. Empty: the format says nothing
 * here (then nothing is refused and nothing is made up). */
typedef struct schema_set {
    const json_t *s[64];
    size_t n;
} schema_set;

typedef struct walk {
    pfx_overrides *ov;
    pfx_doc *doc;
    const char *file;
    json_t *schema; /* made on first use: replacing a value needs none */
    bool schema_made;
    const json_t *defs;
    int line;          /* this override's line in ov->diags */
    const char *arg;   /* PATH=VALUE */
    uint64_t in_lists; /* bit i: component i of PATH indexed a list */
} walk;

static void schema_add(schema_set *set, const json_t *defs, const json_t *s, int depth) {
    if (!json_is_object(s) || depth > 16 || set->n == sizeof set->s / sizeof set->s[0])
        return;
    set->s[set->n++] = s;
    const char *ref = json_string_value(json_object_get(s, "$ref"));
    if (ref && !strncmp(ref, "#/$defs/", 8))
        schema_add(set, defs, json_object_get(defs, ref + 8), depth + 1);
    static const char *const branches[] = {"oneOf", "anyOf", "allOf"};
    for (size_t b = 0; b < 3; b++) {
        size_t i;
        const json_t *alt;
        json_array_foreach(json_object_get(s, branches[b]), i, alt) {
            schema_add(set, defs, alt, depth + 1);
        }
    }
}

/* Whether `name` is a key the format lists here, and whether the mapping
 * here takes names of the author's (emitters, forces). */
static bool schema_has_key(const schema_set *set, const char *name) {
    for (size_t i = 0; i < set->n; i++)
        if (json_object_get(json_object_get(set->s[i], "properties"), name))
            return true;
    return false;
}

static bool schema_takes_names(const schema_set *set) {
    for (size_t i = 0; i < set->n; i++)
        if (json_is_object(json_object_get(set->s[i], "additionalProperties")))
            return true;
    return false;
}

/* The schemas of key `name` (or of any name, where the mapping takes
 * names), or of list item `index` when name is NULL. */
static void schema_child(const schema_set *set, const json_t *defs, const char *name, size_t index,
                         schema_set *out) {
    out->n = 0;
    for (size_t i = 0; i < set->n; i++) {
        const json_t *s = set->s[i];
        if (name) {
            schema_add(out, defs, json_object_get(json_object_get(s, "properties"), name), 0);
        } else {
            const json_t *prefix = json_array_get(json_object_get(s, "prefixItems"), index);
            schema_add(out, defs, prefix ? prefix : json_object_get(s, "items"), 0);
        }
    }
    if (name && !out->n)
        for (size_t i = 0; i < set->n; i++)
            schema_add(out, defs, json_object_get(set->s[i], "additionalProperties"), 0);
}

/* The name nearest to word (pfx_suggest) among the file's keys in map
 * and, unless set is NULL, the format's keys here; NULL if none is close. */
static const char *nearest_key(const pfx_node *map, const schema_set *set, const char *word) {
    size_t cap = map->count + 1;
    for (size_t i = 0; set && i < set->n; i++)
        cap += json_object_size(json_object_get(set->s[i], "properties"));
    const char **names = malloc(cap * sizeof *names);
    if (!names)
        return NULL;
    size_t n = 0;
    for (size_t i = 0; i < map->count; i++)
        names[n++] = map->pairs[i].key->text;
    for (size_t i = 0; set && i < set->n; i++) {
        const char *k;
        const json_t *v;
        json_object_foreach(json_object_get(set->s[i], "properties"), k, v) {
            (void)v;
            names[n++] = k;
        }
    }
    names[n] = NULL;
    const char *s = pfx_suggest(word, names);
    free(names);
    return s;
}

static pfx_node *new_node(walk *w, pfx_node_kind kind, int col, int span) {
    pfx_node *n = pfx_arena_alloc(&w->doc->arena, sizeof *n);
    if (n) {
        memset(n, 0, sizeof *n);
        n->kind = kind;
        n->line = PFX_SET_LINE + w->line - 1;
        n->col = col;
        n->span = span;
    }
    return n;
}

/* A copy of container n whose pairs or items may change (one spare slot
 * for a key inserted), so that an alias of n elsewhere keeps the file's. */
static pfx_node *copy_container(walk *w, const pfx_node *n) {
    pfx_node *c = pfx_arena_alloc(&w->doc->arena, sizeof *c);
    if (!c)
        return NULL;
    *c = *n;
    if (n->kind == PFX_NODE_MAP) {
        c->pairs = pfx_arena_alloc(&w->doc->arena, (n->count + 1) * sizeof *c->pairs);
        if (c->pairs && n->count)
            memcpy(c->pairs, n->pairs, n->count * sizeof *c->pairs);
        return c->pairs ? c : NULL;
    }
    c->items = pfx_arena_alloc(&w->doc->arena, (n->count + 1) * sizeof *c->items);
    if (c->items && n->count)
        memcpy(c->items, n->items, n->count * sizeof *c->items);
    return c->items ? c : NULL;
}

/* Puts every node of the parsed VALUE on the override's line, its columns
 * counted from the start of the argument. Aliases are visited once per
 * use, which the parser's expansion bound keeps finite. */
static void relocate(pfx_node *n, int line, int col0) {
    if (n->line >= PFX_SET_LINE)
        return; /* an alias already moved */
    n->line = line;
    n->col += col0;
    for (size_t i = 0; i < n->count; i++) {
        if (n->kind == PFX_NODE_SEQ)
            relocate(n->items[i], line, col0);
        else if (n->kind == PFX_NODE_MAP) {
            relocate(n->pairs[i].key, line, col0);
            relocate(n->pairs[i].value, line, col0);
        }
    }
}

/* VALUE parsed as a YAML document into ov->values[k]; its syntax errors
 * go to the --set list at their column. NULL on an error. */
static pfx_node *parse_value(walk *w, size_t k, const char *value, int col0) {
    if (value[0] == '#') {
        /* YAML would read a comment, an empty value: a colour is meant. */
        pfx_node *v = pfx_arena_alloc(&w->doc->arena, sizeof *v);
        if (v)
            *v = (pfx_node){.kind = PFX_NODE_SCALAR,
                            .line = PFX_SET_LINE + w->line - 1,
                            .col = col0 + 1,
                            .span = (int)strlen(value),
                            .text = value,
                            .len = strlen(value)};
        return v;
    }
    pfx_diags d;
    pfx_diags_init(&d, "--set", value, strlen(value));
    bool ok = pfx_parse(value, strlen(value), &w->ov->values[k], &d);
    for (size_t i = 0; i < d.count; i++) {
        const pfx_diag *g = &d.items[i];
        pfx_diag_add(&w->ov->diags, g->severity, w->line, g->line == 1 ? col0 + g->col : col0 + 1,
                     g->span, g->rule, "%s", g->message);
    }
    pfx_diags_free(&d);
    if (!ok)
        return NULL;
    pfx_node *v = w->ov->values[k].root;
    if (!v) { /* `key=`: YAML's empty plain scalar, which compile names */
        v = pfx_arena_alloc(&w->ov->values[k].arena, sizeof *v);
        if (!v)
            return NULL;
        *v = (pfx_node){.kind = PFX_NODE_SCALAR, .col = 1, .span = 1, .text = "", .plain = true};
    }
    relocate(v, PFX_SET_LINE + w->line - 1, col0);
    return v;
}

/* Reports that the path up to `end` (the component at col, len bytes)
 * names nothing; `suggest` (may be NULL) replaces that component. */
static void no_path(walk *w, pfx_rule rule, size_t end, int col, size_t len, const char *suggest,
                    const char *why) {
    const char *arg = w->arg;
    if (suggest)
        pfx_diag_add(&w->ov->diags, PFX_SEV_ERROR, w->line, col, (int)len, rule,
                     "'%.*s' %s; did you mean '%.*s%s'?", (int)end, arg, why, col - 1, arg,
                     suggest);
    else
        pfx_diag_add(&w->ov->diags, PFX_SEV_ERROR, w->line, col, (int)len, rule, "'%.*s' %s",
                     (int)end, arg, why);
}

/* The schemas at the path arg[0..end), each component a key or, where
 * w->in_lists says, a list index. The schema is generated and parsed the
 * first time (about 15 ms); past 64 components the format says nothing. */
static void schema_at(walk *w, const char *end, schema_set *set) {
    if (!w->schema_made) {
        char *text = pfx_schema_text();
        w->schema = text ? json_loads(text, 0, NULL) : NULL;
        w->defs = json_object_get(w->schema, "$defs");
        w->schema_made = true;
        free(text);
    }
    set->n = 0;
    schema_add(set, w->defs, w->schema, 0);
    int i = 0;
    for (const char *p = w->arg; p < end && set->n; i++) {
        const char *dot = memchr(p, '.', (size_t)(end - p)), *e = dot ? dot : end;
        char name[256];
        snprintf(name, sizeof name, "%.*s", (int)(e - p), p);
        bool index = i < 64 && (w->in_lists >> i & 1);
        schema_set child;
        schema_child(set, w->defs, index ? NULL : name, index ? strtoul(name, NULL, 10) : 0,
                     &child);
        *set = i < 64 ? child : (schema_set){.n = 0};
        p = e + 1;
    }
}

/* One step into list c by the component at p (name): the slot of the
 * item, or NULL after the error. */
static pfx_node **list_step(walk *w, size_t k, pfx_node *c, const char *name, const char *p,
                            const char *end, bool last) {
    const char *arg = w->arg;
    int col = (int)(p - arg) + 1;
    char *stop;
    unsigned long i = strtoul(name, &stop, 10);
    if (*stop || name[0] < '0' || name[0] > '9' || i >= c->count) {
        char why[160];
        snprintf(why, sizeof why, "names nothing in '%s': '%.*s' is a list of %zu, indexed from 0",
                 w->file, col - 2, arg, c->count);
        no_path(w, PFX_RULE_UNKNOWN_NAME, (size_t)(end - arg), col, (size_t)(end - p), NULL, why);
        return NULL;
    }
    int depth = 0;
    for (const char *q = arg; q < p; q++)
        depth += *q == '.';
    if (depth < 64)
        w->in_lists |= (uint64_t)1 << depth;
    if (last)
        w->ov->replaced[k] = c->items[i];
    return &c->items[i];
}

/* One step into mapping c by key `name` (the component at p): the slot of
 * its value, the key added when absent and the format has it (or, last,
 * where the mapping takes any name: a new emitter, whole; never an
 * author's name on the way). NULL after the error. */
static pfx_node **map_step(walk *w, size_t k, pfx_node *c, const char *name, const char *p,
                           const char *end, bool last) {
    const char *arg = w->arg;
    int col = (int)(p - arg) + 1;
    size_t len = (size_t)(end - p), i = 0;
    while (i < c->count && strcmp(c->pairs[i].key->text, name))
        i++;
    if (i < c->count && !last)
        return &c->pairs[i].value;
    if (i < c->count) {
        /* The key moves to the --set too, so that compile's words about
         * the pair point there. */
        w->ov->replaced[k] = c->pairs[i].value;
        pfx_node *key = new_node(w, PFX_NODE_SCALAR, col, (int)len);
        if (!key)
            return NULL;
        key->text = c->pairs[i].key->text;
        key->len = c->pairs[i].key->len;
        key->plain = true;
        c->pairs[i].key = key;
        return &c->pairs[i].value;
    }
    schema_set set;
    schema_at(w, p > arg ? p - 1 : arg, &set);
    bool known = schema_has_key(&set, name), names = schema_takes_names(&set);
    if (!(known || (last && (names || !set.n)))) {
        char why[160];
        snprintf(why, sizeof why, "names nothing in '%s'", w->file);
        no_path(w, names || !set.n ? PFX_RULE_UNKNOWN_NAME : PFX_RULE_UNKNOWN_KEY,
                (size_t)(end - arg), col, len, nearest_key(c, names ? NULL : &set, name),
                names || !set.n ? why : "names no key of the effect format");
        return NULL;
    }
    pfx_node *key = new_node(w, PFX_NODE_SCALAR, col, (int)len);
    pfx_node *empty = last ? NULL : new_node(w, PFX_NODE_MAP, col, (int)len);
    if (!key || (!last && !empty))
        return NULL;
    key->text = pfx_arena_strndup(&w->doc->arena, name, len);
    key->len = len;
    key->plain = true;
    c->pairs[c->count++] = (pfx_pair){key, empty};
    return &c->pairs[i].value;
}

/* Walks the path of override k and puts its value at the end. */
static bool apply_one(walk *w, size_t k) {
    const char *arg = w->arg, *eq = strchr(arg, '=');
    if (!eq || eq == arg) {
        pfx_diag_add(&w->ov->diags, PFX_SEV_ERROR, w->line, 1, (int)strlen(arg) + 1,
                     PFX_RULE_MALFORMED_VALUE,
                     "--set takes PATH=VALUE, such as emitters.flame.rate=300");
        return false;
    }
    pfx_node *value = parse_value(w, k, eq + 1, (int)(eq + 1 - arg));
    if (!value)
        return false;
    if (!w->doc->root) /* an empty file: compile says so */
        return true;
    w->in_lists = 0;
    pfx_node **slot = &w->doc->root;
    char name[256];
    for (const char *p = arg; p < eq;) {
        const char *dot = memchr(p, '.', (size_t)(eq - p));
        const char *end = dot ? dot : eq;
        size_t len = (size_t)(end - p);
        int col = (int)(p - arg) + 1;
        if (len == 0 || len >= sizeof name) {
            no_path(w, PFX_RULE_UNKNOWN_KEY, (size_t)(end - arg), col, len ? len : 1, NULL,
                    len ? "has a key too long to be one" : "has an empty key between dots");
            return false;
        }
        memcpy(name, p, len);
        name[len] = 0;
        pfx_node *n = *slot;
        if (n->kind == PFX_NODE_SCALAR) {
            char why[160], at[48];
            if (n->line >= PFX_SET_LINE)
                snprintf(at, sizeof at, "--set %d", n->line - PFX_SET_LINE + 1);
            else
                snprintf(at, sizeof at, "line %d", n->line);
            snprintf(why, sizeof why, "names nothing in '%s': '%.*s' is a scalar (%s)", w->file,
                     col - 2, arg, at);
            no_path(w, PFX_RULE_UNKNOWN_NAME, (size_t)(end - arg), col, len, NULL, why);
            return false;
        }
        pfx_node *c = copy_container(w, n);
        if (!c)
            return false;
        *slot = c;
        slot = c->kind == PFX_NODE_SEQ ? list_step(w, k, c, name, p, end, end == eq)
                                       : map_step(w, k, c, name, p, end, end == eq);
        if (!slot)
            return false;
        p = end + 1;
    }
    *slot = value;
    return true;
}

bool pfx_overrides_apply(pfx_overrides *ov, pfx_doc *doc, const char *file, const char *const *sets,
                         size_t n) {
    memset(ov, 0, sizeof *ov);
    size_t total = 1;
    for (size_t k = 0; k < n; k++)
        total += strlen(sets[k]) + 1;
    ov->source = malloc(total);
    ov->values = calloc(n + 1, sizeof *ov->values);
    ov->replaced = calloc(n + 1, sizeof *ov->replaced);
    pfx_diags_init(&ov->diags, "--set", NULL, 0);
    if (!ov->source || !ov->values || !ov->replaced) {
        pfx_diag_error(&ov->diags, PFX_RULE_OUT_OF_MEMORY, "out of memory for --set");
        return false;
    }
    /* The "file" the diagnostics quote: one argument a line (a newline in
     * a VALUE shows as a space, so that the lines stay one per --set). */
    char *o = ov->source;
    for (size_t k = 0; k < n; k++) {
        for (const char *s = sets[k]; *s; s++)
            *o++ = *s == '\n' || *s == '\r' ? ' ' : *s;
        *o++ = '\n';
    }
    *o = 0;
    ov->diags.source = ov->source;
    ov->diags.source_len = (size_t)(o - ov->source);
    ov->count = n;
    walk w = {.ov = ov, .doc = doc, .file = file};
    bool ok = true;
    /* Every override is tried, so that each bad one is reported. */
    for (size_t k = 0; k < n; k++) {
        w.line = (int)k + 1;
        w.arg = sets[k];
        int errors = ov->diags.errors;
        if (!apply_one(&w, k)) {
            ok = false;
            if (ov->diags.errors == errors)
                pfx_diag_error(&ov->diags, PFX_RULE_OUT_OF_MEMORY, "out of memory for --set");
        }
    }
    json_decref(w.schema);
    return ok;
}

/* The note after an error in override `line`'s value: the key of the file
 * it stands for, and the line of the value it replaced. */
static void note_key(pfx_overrides *ov, int line, const char *file) {
    const char *arg = ov->source;
    for (int l = 1; l < line; l++)
        arg = strchr(arg, '\n') + 1;
    int len = (int)strcspn(arg, "=");
    const pfx_node *was = ov->replaced[line - 1];
    if (!was)
        pfx_diag_note(&ov->diags, line, 1, len, "'%.*s' is not in %s: --set adds it", len, arg,
                      file);
    else if (was->line >= PFX_SET_LINE)
        pfx_diag_note(&ov->diags, line, 1, len, "'%.*s' replaces the value --set %d gave it", len,
                      arg, was->line - PFX_SET_LINE + 1);
    else
        pfx_diag_note(&ov->diags, line, 1, len, "'%.*s' replaces the value at %s:%d:%d", len, arg,
                      file, was->line, was->col);
}

void pfx_overrides_claim(pfx_overrides *ov, pfx_diags *file_diags) {
    if (!ov->count)
        return;
    pfx_diags kept;
    pfx_diags_init(&kept, file_diags->file, file_diags->source, file_diags->source_len);
    kept.dropped = file_diags->dropped;
    bool moving = false;
    int error_line = 0; /* the override of the group being moved, when an error */
    for (size_t i = 0; i <= file_diags->count; i++) {
        const pfx_diag *g = i < file_diags->count ? &file_diags->items[i] : NULL;
        bool in_set = g && g->line >= PFX_SET_LINE;
        if (!g || g->severity != PFX_SEV_NOTE) {
            if (error_line) /* closes the group before */
                note_key(ov, error_line, file_diags->file);
            if (!g)
                break;
            moving = in_set;
            error_line = moving && g->severity == PFX_SEV_ERROR ? g->line - PFX_SET_LINE + 1 : 0;
        }
        if (!moving)
            pfx_diag_add(&kept, g->severity, g->line, g->col, g->span, g->rule, "%s", g->message);
        else if (in_set)
            pfx_diag_add(&ov->diags, g->severity, g->line - PFX_SET_LINE + 1, g->col, g->span,
                         g->rule, "%s", g->message);
        else /* a note into the file, which this list cannot quote: it says where */
            pfx_diag_add(&ov->diags, g->severity, 0, 0, 1, g->rule, "%s (%s:%d:%d)", g->message,
                         file_diags->file, g->line, g->col);
    }
    pfx_diags_free(file_diags);
    *file_diags = kept;
}

void pfx_overrides_free(pfx_overrides *ov) {
    for (size_t k = 0; k < ov->count && ov->values; k++)
        pfx_doc_free(&ov->values[k]);
    free(ov->values);
    free(ov->replaced);
    free(ov->source);
    pfx_diags_free(&ov->diags);
    memset(ov, 0, sizeof *ov);
}
