/* Completion from the text as typed, which is often not valid YAML yet:
 * the cursor's context (the keys of the enclosing block mappings, from
 * indentation, and of the flow collections opened on its line) picks a
 * key table. A key position offers the table's keys with their meaning; a
 * value position the key's vocabulary (an enum, a family's `type`, true or
 * false), this file's force, deflector or emitter names where a
 * reference goes (`forces: [`, `deflectors: [`, `emit:`), or the PNG and
 * OBJ files beside the effect for `texture`, `normal_map` and a mesh's
 * `file`. */
#include <ctype.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "compile/compiler.h"
#include "lsp/document.h"
#include "lsp/tree.h"

#define MAX_PATH 16
#define NAME_MAX_LEN 64

/* A key of the path to the cursor: its name, and where its own mapping's
 * lines are (for its `type`). */
typedef struct seg {
    char name[NAME_MAX_LEN];
    size_t line;      /* the line of the key */
    int indent;       /* the key's column (0-based bytes) */
    const char *flow; /* on the key's line, where its flow mapping starts, or NULL */
} seg;

typedef struct line_view {
    const char *s;
    size_t n;
} line_view;

static line_view line_at(const pfx_lsp_doc *d, size_t i) {
    const pfx_lsp_text *t = &d->lines;
    size_t a = t->line_starts[i], b = i + 1 < t->line_count ? t->line_starts[i + 1] - 1 : t->len;
    if (b > a && t->text[b - 1] == '\r')
        b--;
    return (line_view){t->text + a, b - a};
}

static bool is_key_char(char c) {
    return isalnum((unsigned char)c) || c == '_' || c == '-' || c == '.';
}

/* Reads `key:` at s (n bytes left): the key's length, 0 when none. The
 * colon must end the text or come before a space. */
static size_t key_at(const char *s, size_t n) {
    size_t k = 0;
    while (k < n && is_key_char(s[k]))
        k++;
    if (!k || k >= n || s[k] != ':' || (k + 1 < n && s[k + 1] != ' '))
        return 0;
    return k;
}

/* A line's indentation, past a list's "- ", and whether it holds anything. */
static int indent_of(line_view l, bool *blank) {
    size_t i = 0;
    while (i < l.n && (l.s[i] == ' ' || (l.s[i] == '-' && i + 1 < l.n && l.s[i + 1] == ' ')))
        i++;
    *blank = i == l.n || l.s[i] == '#';
    return (int)i;
}

static void seg_set(seg *g, const char *s, size_t n, size_t line, int indent) {
    if (n >= NAME_MAX_LEN)
        n = NAME_MAX_LEN - 1;
    memcpy(g->name, s, n);
    g->name[n] = 0;
    g->line = line;
    g->indent = indent;
    g->flow = NULL;
}

/* The word after a key's colon, from t up to end, spaces skipped: into
 * out (at most size - 1 characters). */
static void copy_value_word(const char *t, const char *end, char *out, size_t size) {
    while (t < end && *t == ' ')
        t++;
    size_t n = 0;
    while (t + n < end && n + 1 < size && is_key_char(t[n]))
        n++;
    memcpy(out, t, n);
    out[n] = 0;
}

/* The `type` of the mapping under path key g: in its flow on its line, or
 * as a key of its block's first level. Written into out (or ""). */
static void type_of(const pfx_lsp_doc *d, const seg *g, char *out, size_t size) {
    *out = 0;
    line_view l = line_at(d, g->line);
    const char *p = g->flow ? g->flow : NULL;
    if (p) {
        const char *t = NULL;
        for (const char *q = p; q + 5 <= l.s + l.n; q++)
            if (!strncmp(q, "type:", 5) && (q == p || !is_key_char(q[-1])))
                t = q + 5;
        if (t)
            copy_value_word(t, l.s + l.n, out, size);
        return;
    }
    for (size_t i = g->line + 1; i < d->lines.line_count; i++) {
        bool blank;
        line_view c = line_at(d, i);
        int ind = indent_of(c, &blank);
        if (blank)
            continue;
        if (ind <= g->indent)
            return;
        size_t k = key_at(c.s + ind, c.n - (size_t)ind);
        if (k == 4 && !strncmp(c.s + ind, "type", 4)) {
            copy_value_word(c.s + ind + 5, c.s + c.n, out, size);
            return;
        }
    }
}

/* The cursor's context. */
typedef struct context {
    seg path[MAX_PATH];
    int depth;
    bool value;             /* a value position: of key path[depth - 1]... */
    char key[NAME_MAX_LEN]; /* ...named key */
    bool in_list;           /* inside `key: [` */
    size_t value_at;        /* where the value's text starts on the cursor's line */
} context;

/* The flow part of the cursor's line (cur, n bytes before the cursor):
 * pushes a segment per `{` opened after a key, and says whether the cursor
 * is at a value (and of which key). */
static void flow_context(const pfx_lsp_doc *d, context *c, size_t line, const char *cur, size_t n,
                         int base) {
    const char *last_key = NULL;
    size_t last_len = 0;
    int last_col = base;
    bool quoted = false;
    c->value = false;
    for (size_t i = 0; i < n; i++) {
        char ch = cur[i];
        if (ch == '"' || ch == '\'') {
            quoted = !quoted;
            continue;
        }
        if (quoted)
            continue;
        if (ch == '#' && (i == 0 || cur[i - 1] == ' '))
            break; /* a comment: nothing to complete */
        size_t k = (i == 0 || !is_key_char(cur[i - 1])) ? key_at(cur + i, n - i) : 0;
        if (k) {
            last_key = cur + i;
            last_len = k;
            last_col = (int)i;
            c->value = true;
            c->in_list = false;
            i += k;
            c->value_at = i + 1;
            while (c->value_at < n && cur[c->value_at] == ' ')
                c->value_at++;
            continue;
        }
        if (ch == '{' && last_key && c->depth < MAX_PATH) {
            seg *g = &c->path[c->depth++];
            seg_set(g, last_key, last_len, line, last_col);
            g->flow = cur + i;
            last_key = NULL;
            c->value = false;
        } else if (ch == '[') {
            c->in_list = c->value;
        } else if (ch == ',') {
            if (!c->in_list)
                c->value = false;
        } else if (ch == '}' && c->depth > 0) {
            c->depth--;
            c->value = false;
        } else if (ch == ']') {
            c->in_list = false;
        }
    }
    (void)d;
    if (c->value && last_key) {
        size_t m = last_len < NAME_MAX_LEN - 1 ? last_len : NAME_MAX_LEN - 1;
        memcpy(c->key, last_key, m);
        c->key[m] = 0;
    } else
        c->value = false;
}

static void find_context(const pfx_lsp_doc *d, size_t line, size_t col_bytes, context *c) {
    memset(c, 0, sizeof *c);
    line_view l = line_at(d, line);
    if (col_bytes > l.n)
        col_bytes = l.n;
    bool blank;
    int want = indent_of(l, &blank);
    if ((size_t)want > col_bytes)
        want = (int)col_bytes;
    /* The block parents: each line above with less indentation and a key
     * whose value is on the lines below. */
    seg up[MAX_PATH];
    int nup = 0;
    for (size_t i = line; i-- > 0 && want > 0 && nup < MAX_PATH;) {
        line_view p = line_at(d, i);
        int ind = indent_of(p, &blank);
        if (blank || ind >= want)
            continue;
        size_t k = key_at(p.s + ind, p.n - (size_t)ind);
        want = ind;
        if (!k)
            continue;
        seg_set(&up[nup++], p.s + ind, k, i, ind);
    }
    for (int i = nup; i-- > 0;)
        c->path[c->depth++] = up[i];
    flow_context(d, c, line, l.s, col_bytes, indent_of(l, &blank));
}

/* The place the path leads to. A key read by code (on_death, a list of
 * stops) leads to a place without a table that still knows its emitter,
 * where `emit:` takes an emitter's name. */
static void resolve(const pfx_lsp_doc *d, const context *c, pfx_lsp_place *p) {
    *p = pfx_lsp_top_place(NULL);
    for (int i = 0; i < c->depth; i++) {
        char type[NAME_MAX_LEN];
        type_of(d, &c->path[i], type, sizeof type);
        pfx_lsp_place next;
        if (!pfx_lsp_descend(p, c->path[i].name, *type ? type : NULL, &next))
            next = (pfx_lsp_place){NULL, NULL, -1, NULL, p->emitter};
        *p = next;
    }
}

static void add_item(json_t *items, const char *label, int kind, const char *detail,
                     const char *doc, const char *insert) {
    json_t *it = json_pack("{s:s, s:i}", "label", label, "kind", kind);
    if (!it)
        return;
    if (detail)
        json_object_set_new(it, "detail", json_string(detail));
    if (doc)
        json_object_set_new(it, "documentation",
                            json_pack("{s:s, s:s}", "kind", "markdown", "value", doc));
    if (insert)
        json_object_set_new(it, "insertText", json_string(insert));
    json_array_append_new(items, it);
}

/* LSP's CompletionItemKind. */
enum {
    ITEM_PROPERTY = 10,
    ITEM_VALUE = 12,
    ITEM_FILE = 17,
    ITEM_REFERENCE = 18,
    ITEM_FOLDER = 19,
    ITEM_ENUM_MEMBER = 20
};

typedef struct names_ctx {
    pfx_lsp_section section;
    json_t *items;
} names_ctx;

/* The names a section defines, from its block's first level of keys. */
static void section_names(const pfx_lsp_doc *d, pfx_lsp_section sec, json_t *items) {
    const char *want = pfx_lsp_section_names[sec];
    static const char *const words[] = {"force", "deflector", "emitter"};
    int child = -1;
    bool inside = false;
    for (size_t i = 0; i < d->lines.line_count; i++) {
        bool blank;
        line_view l = line_at(d, i);
        int ind = indent_of(l, &blank);
        if (blank)
            continue;
        if (ind == 0) {
            size_t k = key_at(l.s, l.n);
            inside = k == strlen(want) && !strncmp(l.s, want, k);
            child = -1;
            continue;
        }
        if (!inside)
            continue;
        if (child < 0)
            child = ind;
        size_t k = ind == child ? key_at(l.s + ind, l.n - (size_t)ind) : 0;
        if (k) {
            char name[NAME_MAX_LEN];
            size_t m = k < sizeof name - 1 ? k : sizeof name - 1;
            memcpy(name, l.s + ind, m);
            name[m] = 0;
            add_item(items, name, ITEM_REFERENCE, words[sec], NULL, NULL);
        }
    }
}

/* The keys already written in the block mapping the cursor's line belongs
 * to (not the cursor's own line), up to 64; none in a flow mapping. */
typedef struct present {
    char names[64][NAME_MAX_LEN];
    size_t count;
} present;

static void present_keys(const pfx_lsp_doc *d, const context *c, size_t line, present *out) {
    out->count = 0;
    if (c->depth > 0 && c->path[c->depth - 1].flow)
        return;
    bool blank;
    int own = indent_of(line_at(d, line), &blank);
    const seg *parent = c->depth > 0 ? &c->path[c->depth - 1] : NULL;
    for (size_t i = parent ? parent->line + 1 : 0; i < d->lines.line_count && out->count < 64;
         i++) {
        line_view l = line_at(d, i);
        int ind = indent_of(l, &blank);
        if (blank)
            continue;
        if (parent && ind <= parent->indent)
            break;
        size_t k = ind == own && i != line ? key_at(l.s + ind, l.n - (size_t)ind) : 0;
        if (k) {
            seg g;
            seg_set(&g, l.s + ind, k, i, ind);
            memcpy(out->names[out->count++], g.name, NAME_MAX_LEN);
        }
    }
}

static void table_keys(const pfx_key_table *t, const present *have, json_t *items) {
    for (size_t i = 0; i < t->count; i++) {
        bool written = false;
        for (size_t h = 0; h < have->count && !written; h++)
            written = !strcmp(have->names[h], t->keys[i].name);
        if (written)
            continue; /* a key once: a second would be a duplicate-key error */
        char insert[NAME_MAX_LEN + 4];
        snprintf(insert, sizeof insert, "%s: ", t->keys[i].name);
        add_item(items, t->keys[i].name, ITEM_PROPERTY, t->doc, t->keys[i].doc, insert);
    }
}

static int by_name(const void *a, const void *b) {
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Files for a path key, relative to the effect's directory: the
 * directories and the files ending in ext under what is typed so far
 * (typed, n bytes, quotes dropped), sorted, at most 500. Each replaces the
 * typed text from `from` (byte offset in the document) to the cursor. */
static void paths(const pfx_lsp_doc *d, const char *typed, size_t n, size_t from, size_t to,
                  const char *ext, json_t *items) {
    if (n && (*typed == '"' || *typed == '\'')) {
        typed++, n--, from++;
    }
    const char *slash = NULL;
    for (size_t i = 0; i < n; i++)
        if (typed[i] == '/')
            slash = typed + i;
    size_t dir_len = slash ? (size_t)(slash - typed) + 1 : 0;
    const char *base_end = strrchr(d->path, '/');
    char dir[4096];
    int w = snprintf(dir, sizeof dir, "%.*s%.*s", base_end ? (int)(base_end - d->path + 1) : 0,
                     d->path, (int)dir_len, typed);
    if (w < 0 || (size_t)w >= sizeof dir || (n && *typed == '/'))
        return; /* relative paths only: the effect's own files */
    DIR *dp = opendir(*dir ? dir : ".");
    if (!dp)
        return;
    char *names[500];
    size_t count = 0;
    struct dirent *e;
    while (count < 500 && (e = readdir(dp))) {
        if (e->d_name[0] == '.')
            continue;
        char full[4352];
        struct stat st;
        snprintf(full, sizeof full, "%s%s", dir, e->d_name);
        bool is_dir = !stat(full, &st) && S_ISDIR(st.st_mode);
        size_t ln = strlen(e->d_name), le = strlen(ext);
        if (!is_dir && (ln < le || strcasecmp(e->d_name + ln - le, ext)))
            continue;
        char *name = malloc(dir_len + ln + 2);
        if (!name)
            break;
        snprintf(name, dir_len + ln + 2, "%.*s%s%s", (int)dir_len, typed, e->d_name,
                 is_dir ? "/" : "");
        names[count++] = name;
    }
    closedir(dp);
    qsort(names, count, sizeof names[0], by_name);
    for (size_t i = 0; i < count; i++) {
        json_t *it =
            json_pack("{s:s, s:i, s:{s:o, s:s}}", "label", names[i], "kind",
                      names[i][strlen(names[i]) - 1] == '/' ? ITEM_FOLDER : ITEM_FILE, "textEdit",
                      "range", pfx_lsp_range_bytes(d, from, to), "newText", names[i]);
        if (it)
            json_array_append_new(items, it);
        free(names[i]);
    }
}

json_t *pfx_lsp_completion(const pfx_lsp_doc *d, int line, int character) {
    json_t *items = json_array();
    if (!items || line < 0 || (size_t)line >= d->lines.line_count)
        return items;
    size_t off = pfx_lsp_offset(&d->lines, line, character);
    context c;
    find_context(d, (size_t)line, off - d->lines.line_starts[line], &c);
    pfx_lsp_place p;
    resolve(d, &c, &p);
    if (!c.value) {   /* a key */
        present have; /* 4 KiB */
        present_keys(d, &c, (size_t)line, &have);
        if (p.table)
            table_keys(p.table, &have, items);
        else if (p.family)
            add_item(items, "type", ITEM_PROPERTY, p.family->name, p.family->type_doc, "type: ");
        return items;
    }
    if (!strcmp(c.key, "type") && p.family) {
        for (size_t i = 0; p.family->kinds[i]; i++)
            add_item(items, p.family->kinds[i], ITEM_ENUM_MEMBER, p.family->name,
                     p.family->tables[i]->doc, NULL);
        return items;
    }
    const char *ext =
        p.table == &pfx_emitter_table && (!strcmp(c.key, "texture") || !strcmp(c.key, "normal_map"))
            ? ".png"
        : p.family && p.table && !strcmp(p.family->name, "shape") &&
                !strcmp(p.table->kind, "mesh") && !strcmp(c.key, "file")
            ? ".obj"
            : NULL;
    if (ext) {
        size_t line_start = d->lines.line_starts[line];
        size_t at = c.value_at < off - line_start ? c.value_at : off - line_start;
        paths(d, d->lines.text + line_start + at, off - line_start - at, line_start + at, off, ext,
              items);
        return items;
    }
    if (p.emitter && !strcmp(c.key, "emit")) {
        section_names(d, PFX_LSP_EMITTER, items);
        return items;
    }
    if (p.table == &pfx_emitter_table && !strcmp(c.key, "forces")) {
        section_names(d, PFX_LSP_FORCE, items);
        return items;
    }
    if (p.table == &pfx_emitter_table && !strcmp(c.key, "deflectors")) {
        section_names(d, PFX_LSP_DEFLECTOR, items);
        return items;
    }
    const pfx_key *row = p.table ? pfx_keys_find(p.table, c.key) : NULL;
    if (row && row->type == PFX_KEY_ENUM)
        for (size_t i = 0; row->names[i]; i++)
            add_item(items, row->names[i], ITEM_ENUM_MEMBER, row->name, NULL, NULL);
    if (row && row->type == PFX_KEY_BOOL) {
        add_item(items, "true", ITEM_VALUE, row->name, NULL, NULL);
        add_item(items, "false", ITEM_VALUE, row->name, NULL, NULL);
    }
    return items;
}
