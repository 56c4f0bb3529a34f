/* Collects and prints diagnostics. The text form follows gcc and clang: the
 * position, the severity, the message, then the source line and a caret with
 * tildes under the offending span. It does not decide what is an error. */
#include "base/diag.h"

#include <jansson.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/json_text.h"

const pfx_rule_info pfx_rules[] = {
#define PFX_RULE_ROW(num, id, name, sev, help) {PFX_RULE_##id, name, PFX_SEV_##sev, help},
    PFX_DIAG_RULES(PFX_RULE_ROW)
#undef PFX_RULE_ROW
};
const size_t pfx_rule_count = sizeof pfx_rules / sizeof pfx_rules[0];

const pfx_rule_info *pfx_rule_find(pfx_rule rule) {
    for (size_t i = 0; i < pfx_rule_count && rule != PFX_RULE_NONE; i++)
        if (pfx_rules[i].rule == rule)
            return &pfx_rules[i];
    return NULL;
}

void pfx_rules_print(FILE *out) {
    static const char *const sev[] = {"error", "warning", "note"};
    for (size_t i = 0; i < pfx_rule_count; i++)
        fprintf(out, "PFX%04d  %-7s  %-20s  %s\n", (int)pfx_rules[i].rule,
                sev[pfx_rules[i].severity], pfx_rules[i].name, pfx_rules[i].help);
}

const char *pfx_rule_id(pfx_rule rule, char *buf, size_t size) {
    if (rule == PFX_RULE_NONE)
        snprintf(buf, size, "%s", "");
    else
        snprintf(buf, size, "PFX%04d", (int)rule);
    return buf;
}

void pfx_diags_init(pfx_diags *d, const char *file, const char *source, size_t source_len) {
    memset(d, 0, sizeof *d);
    d->file = file;
    d->source = source;
    d->source_len = source_len;
}

void pfx_diags_init_runtime(pfx_diags *d) { pfx_diags_init(d, NULL, NULL, 0); }

void pfx_diag_error(pfx_diags *d, pfx_rule rule, const char *fmt, ...) {
    if (!d)
        return;
    va_list ap;
    va_start(ap, fmt);
    pfx_diag_vadd(d, PFX_SEV_ERROR, 0, 0, 0, rule, fmt, ap);
    va_end(ap);
}

void pfx_diag_error_at(const pfx_diag_at *at, pfx_rule rule, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    pfx_diag_vadd(at->d, PFX_SEV_ERROR, at->line, at->col, at->span > 0 ? at->span : 1, rule, fmt,
                  ap);
    va_end(ap);
}

void pfx_diag_note(pfx_diags *d, int line, int col, int span, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    pfx_diag_vadd(d, PFX_SEV_NOTE, line, col, span, PFX_RULE_NONE, fmt, ap);
    va_end(ap);
}

void pfx_diags_append(pfx_diags *dst, pfx_diags *src) {
    for (size_t i = 0; i < src->count; i++) {
        const pfx_diag *g = &src->items[i];
        /* Acknowledged in src's file: counted, not shown again (its reason
         * goes with src). */
        if (g->allowed) {
            dst->allowed += g->severity == PFX_SEV_WARNING;
            continue;
        }
        pfx_diag_add(dst, g->severity, g->line, g->col, g->span, g->rule, "%s", g->message);
    }
    pfx_diags_free(src);
}

void pfx_diags_free(pfx_diags *d) {
    for (size_t i = 0; i < d->count; i++)
        free(d->items[i].message);
    free(d->items);
    d->items = NULL;
    d->count = d->cap = 0;
    for (size_t i = 0; i < d->allow_count; i++)
        free(d->allows[i].reason);
    free(d->allows);
    d->allows = NULL;
    d->allow_count = 0;
}

/* The reason the file gives for allowing warnings of rule, or NULL. */
static const char *allow_reason(const pfx_diags *d, pfx_rule rule) {
    for (size_t i = 0; i < d->allow_count; i++)
        if (d->allows[i].rule == rule)
            return d->allows[i].reason;
    return NULL;
}

bool pfx_diags_allow(pfx_diags *d, pfx_rule rule, const char *reason) {
    pfx_diag_allow *a = realloc(d->allows, (d->allow_count + 1) * sizeof *a);
    if (!a)
        return false;
    d->allows = a;
    char *copy = strdup(reason);
    if (!copy)
        return false;
    a[d->allow_count++] = (pfx_diag_allow){rule, copy};
    /* Warnings reported before the table was read: a warning and its
     * notes. */
    const char *head = NULL;
    for (size_t i = 0; i < d->count; i++) {
        pfx_diag *g = &d->items[i];
        if (g->severity != PFX_SEV_NOTE)
            head = g->severity == PFX_SEV_WARNING && g->rule == rule && !g->allowed ? copy : NULL;
        if (head && !g->allowed) {
            g->allowed = head;
            if (g->severity == PFX_SEV_WARNING) {
                d->warnings--;
                d->allowed++;
            }
        }
    }
    return true;
}

void pfx_diag_vadd(pfx_diags *d, pfx_severity sev, int line, int col, int span, pfx_rule rule,
                   const char *fmt, va_list ap) {
    if (!d)
        return;
    /* An allowed warning, or a note of one. */
    const char *allowed = sev == PFX_SEV_WARNING            ? allow_reason(d, rule)
                          : sev == PFX_SEV_NOTE && d->count ? d->items[d->count - 1].allowed
                                                            : NULL;
    int *counter = sev == PFX_SEV_ERROR     ? &d->errors
                   : sev != PFX_SEV_WARNING ? NULL
                   : allowed                ? &d->allowed
                                            : &d->warnings;
    if (counter)
        ++*counter;
    if (d->count >= PFX_DIAG_MAX) {
        d->dropped++;
        return;
    }
    if (d->count == d->cap) {
        size_t cap = d->cap ? d->cap * 2 : 16;
        pfx_diag *items = realloc(d->items, cap * sizeof *items);
        if (!items) {
            d->dropped++;
            return;
        }
        d->items = items;
        d->cap = cap;
    }
    char buf[1024];
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    if (n >= (int)sizeof buf) {
        /* Cut on a UTF-8 character boundary, so JSON output stays UTF-8. */
        size_t end = sizeof buf - 1, lead = end;
        while (lead > 0 && ((unsigned char)buf[lead - 1] & 0xc0) == 0x80)
            lead--;
        if (lead > 0) {
            unsigned char c = (unsigned char)buf[lead - 1];
            size_t need = c >= 0xf0 ? 4 : c >= 0xe0 ? 3 : c >= 0xc0 ? 2 : 1;
            if (lead - 1 + need > end)
                buf[lead - 1] = 0; /* the last character was cut: drop it */
        }
    }
    /* Control characters from the file (an escape in a key) never reach the
     * terminal raw. */
    for (char *p = buf; *p; p++)
        if ((unsigned char)*p < 0x20 || *p == 0x7f)
            *p = '?';
    /* A node shared through YAML aliases reports once. */
    for (size_t i = 0; i < d->count; i++) {
        const pfx_diag *o = &d->items[i];
        if (o->line == line && o->col == col && o->severity == sev && !strcmp(o->message, buf)) {
            if (counter)
                --*counter;
            return;
        }
    }
    pfx_diag *g = &d->items[d->count];
    g->severity = sev;
    g->line = line;
    g->col = col;
    g->span = span > 0 ? span : 1;
    g->seq = (int)d->count;
    g->rule = sev == PFX_SEV_NOTE ? PFX_RULE_NONE : rule;
    g->allowed = allowed;
    g->message = strdup(buf);
    if (g->message)
        d->count++;
}

void pfx_diag_add(pfx_diags *d, pfx_severity sev, int line, int col, int span, pfx_rule rule,
                  const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    pfx_diag_vadd(d, sev, line, col, span, rule, fmt, ap);
    va_end(ap);
}

static const char *severity_name(pfx_severity s) {
    return s == PFX_SEV_ERROR ? "error" : s == PFX_SEV_WARNING ? "warning" : "note";
}

/* Notes belong to the diagnostic before them, so a group (one error or
 * warning and its notes) sorts by the position of its head. */
typedef struct {
    int line, col, seq;
    size_t first, count;
} diag_group;

static int group_cmp(const void *pa, const void *pb) {
    const diag_group *a = pa, *b = pb;
    if (a->line != b->line)
        return a->line < b->line ? -1 : 1;
    if (a->col != b->col)
        return a->col < b->col ? -1 : 1;
    return a->seq < b->seq ? -1 : a->seq > b->seq;
}

/* Finds line `line` (1-based) of the source; returns its start and length. */
static const char *source_line(const pfx_diags *d, int line, size_t *len) {
    if (!d->source || line < 1)
        return NULL;
    const char *p = d->source, *end = d->source + d->source_len;
    for (int l = 1; l < line; l++) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        if (!nl)
            return NULL;
        p = nl + 1;
    }
    const char *nl = memchr(p, '\n', (size_t)(end - p));
    size_t n = nl ? (size_t)(nl - p) : (size_t)(end - p);
    if (n && p[n - 1] == '\r')
        n--;
    *len = n;
    return p;
}

/* The length of the well-formed UTF-8 character at s (at most n bytes), or
 * 0 when the bytes there are not one (RFC 3629: no overlong forms, no
 * surrogates, nothing above U+10FFFF). */
static size_t utf8_length(const char *s, size_t n, unsigned *code) {
    const unsigned char *u = (const unsigned char *)s;
    *code = u[0];
    if (u[0] < 0x80)
        return 1;
    size_t len = u[0] >= 0xc2 && u[0] <= 0xdf   ? 2
                 : u[0] >= 0xe0 && u[0] <= 0xef ? 3
                 : u[0] >= 0xf0 && u[0] <= 0xf4 ? 4
                                                : 0;
    if (len == 0 || len > n)
        return 0;
    for (size_t i = 1; i < len; i++)
        if ((u[i] & 0xc0) != 0x80)
            return 0;
    unsigned cp = len == 2   ? (u[0] & 0x1fu) << 6 | (u[1] & 0x3fu)
                  : len == 3 ? (u[0] & 0x0fu) << 12 | (u[1] & 0x3fu) << 6 | (u[2] & 0x3fu)
                             : (u[0] & 0x07u) << 18 | (u[1] & 0x3fu) << 12 | (u[2] & 0x3fu) << 6 |
                                   (u[3] & 0x3fu);
    if ((len == 3 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) ||
        (len == 4 && (cp < 0x10000 || cp > 0x10ffff)))
        return 0;
    *code = cp;
    return len;
}

/* Terminal columns of a printed character: 2 for the East Asian wide and
 * fullwidth blocks (CJK, Hangul, fullwidth forms, emoji), else 1. */
static int display_width(unsigned c) {
    return (c >= 0x1100 && c <= 0x115f) || (c >= 0x2e80 && c <= 0xa4cf && c != 0x303f) ||
                   (c >= 0xac00 && c <= 0xd7a3) || (c >= 0xf900 && c <= 0xfaff) ||
                   (c >= 0xfe30 && c <= 0xfe4f) || (c >= 0xff00 && c <= 0xff60) ||
                   (c >= 0xffe0 && c <= 0xffe6) || (c >= 0x1f300 && c <= 0x1f64f) ||
                   (c >= 0x1f900 && c <= 0x1f9ff) || (c >= 0x20000 && c <= 0x3fffd)
               ? 2
               : 1;
}

static void print_text(const pfx_diags *d, const pfx_diag *g, FILE *out) {
    /* The rule id ends the line, as gcc and clang-tidy print their option
     * or check name: " [PFX3001]". */
    char id[16], tail[20] = "";
    if (g->rule != PFX_RULE_NONE)
        snprintf(tail, sizeof tail, " [%s]", pfx_rule_id(g->rule, id, sizeof id));
    if (!d->file) { /* a runtime failure: "pfx: message", git's form */
        if (g->severity == PFX_SEV_ERROR)
            fprintf(out, "pfx: %s%s\n", g->message, tail);
        else
            fprintf(out, "pfx: %s: %s%s\n", severity_name(g->severity), g->message, tail);
        return;
    }
    if (g->line > 0)
        fprintf(out, "%s:%d:%d: %s: %s%s\n", d->file, g->line, g->col, severity_name(g->severity),
                g->message, tail);
    else
        fprintf(out, "%s: %s: %s%s\n", d->file, severity_name(g->severity), g->message, tail);
    size_t len = 0;
    const char *text = source_line(d, g->line, &len);
    if (!text)
        return;
    /* Long lines are cut so a minified file cannot flood the terminal. */
    const size_t max_shown = 200;
    size_t shown = len < max_shown ? len : max_shown;
    fprintf(out, "%5d | ", g->line);
    /* libyaml counts columns in characters: a well-formed UTF-8 character
     * is printed as it is and counts one column; the caret line pads each
     * by its width on a terminal (two for CJK), so the caret stays under
     * it. Control characters and malformed bytes are shown as '?'. */
    unsigned char width[200];
    size_t cols = 0;
    for (size_t i = 0; i < shown;) {
        unsigned code;
        size_t n = utf8_length(text + i, shown - i, &code);
        if (n > 1)
            fwrite(text + i, 1, n, out);
        else
            fputc(code == '\t' ? ' ' : (code >= 0x20 && code < 0x7f) ? (int)code : '?', out);
        width[cols++] = (unsigned char)(n > 1 ? display_width(code) : 1);
        i += n ? n : 1;
    }
    fputs(shown < len ? " ...\n" : "\n", out);
    fputs("      | ", out);
    int col = g->col > 0 ? g->col : 1;
    if ((size_t)col > cols + 1)
        col = (int)cols + 1;
    for (int i = 1; i < col; i++)
        fprintf(out, "%*s", width[i - 1], "");
    fputc('^', out);
    int span = g->span;
    if ((size_t)(col - 1 + span) > cols)
        span = (int)cols - (col - 1);
    for (int i = 1; i < span; i++)
        fprintf(out, "%.*s", width[col - 1 + i], "~~");
    if (span >= 1 && col <= (int)cols && width[col - 1] == 2)
        fputc('~', out);
    fputc('\n', out);
}

size_t *pfx_diags_order(const pfx_diags *d) {
    diag_group *groups = malloc((d->count + 1) * sizeof *groups);
    size_t *order = malloc((d->count + 1) * sizeof *order);
    if (!groups || !order) {
        free(groups);
        free(order);
        return NULL;
    }
    size_t n = 0;
    for (size_t i = 0; i < d->count; i++) {
        const pfx_diag *g = &d->items[i];
        if (g->severity == PFX_SEV_NOTE && n > 0) {
            groups[n - 1].count++;
            continue;
        }
        groups[n++] = (diag_group){g->line, g->col, g->seq, i, 1};
    }
    qsort(groups, n, sizeof *groups, group_cmp);
    size_t k = 0;
    for (size_t j = 0; j < n; j++)
        for (size_t i = groups[j].first; i < groups[j].first + groups[j].count; i++)
            order[k++] = i;
    free(groups);
    return order;
}

/* One JSON line through jansson, keys in this order. Strings are taken
 * as they are (json_string_nocheck) and escaped for the dump: a file name
 * that is not UTF-8 keeps its exact bytes in "file_base64" (and the
 * message quoting it in "message_base64"; base/json_text.h). */
static void print_json(const pfx_diags *d, const pfx_diag *g, FILE *out) {
    char id[16];
    json_t *o = json_object();
    json_object_set_new(o, "file", d->file ? pfx_json_bytes(d->file) : json_null());
    json_object_set_new(o, "line", json_integer(g->line));
    json_object_set_new(o, "column", json_integer(g->col));
    json_object_set_new(o, "severity", json_string(severity_name(g->severity)));
    json_object_set_new(o, "rule",
                        g->rule != PFX_RULE_NONE ? json_string(pfx_rule_id(g->rule, id, sizeof id))
                                                 : json_null());
    json_object_set_new(o, "message", pfx_json_bytes(g->message));
    json_t *escaped = pfx_json_escaped(o);
    if (escaped && json_dumpf(escaped, out, JSON_COMPACT | JSON_PRESERVE_ORDER) == 0)
        fputc('\n', out);
    json_decref(escaped);
    json_decref(o);
}

void pfx_diags_print(const pfx_diags *d, FILE *out, bool json) {
    size_t *order = pfx_diags_order(d);
    for (size_t k = 0; k < d->count && order; k++) {
        const pfx_diag *g = &d->items[order[k]];
        if (g->allowed)
            continue;
        if (json)
            print_json(d, g, out);
        else
            print_text(d, g, out);
    }
    free(order);
    if (d->dropped && !json)
        fprintf(out, "%s: note: %d more diagnostics not shown\n", d->file ? d->file : "pfx",
                d->dropped);
}
