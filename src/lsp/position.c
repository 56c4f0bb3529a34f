/* Line starts, and the one conversion between pfx's columns (Unicode
 * characters, 1-based) or byte offsets and LSP's UTF-16 code units. A
 * character above U+FFFF is two UTF-16 units; a malformed byte counts as
 * one character, as libyaml would have refused the file anyway. */
#include "lsp/position.h"

#include <stdlib.h>

int pfx_lsp_text_init(pfx_lsp_text *t, const char *text, size_t len) {
    t->text = text;
    t->len = len;
    size_t n = 1;
    for (size_t i = 0; i < len; i++)
        n += text[i] == '\n';
    t->line_starts = malloc(n * sizeof *t->line_starts);
    t->line_count = 0;
    if (!t->line_starts)
        return 0;
    t->line_starts[t->line_count++] = 0;
    for (size_t i = 0; i < len; i++)
        if (text[i] == '\n')
            t->line_starts[t->line_count++] = i + 1;
    return 1;
}

void pfx_lsp_text_free(pfx_lsp_text *t) {
    free(t->line_starts);
    t->line_starts = NULL;
    t->line_count = 0;
}

/* Bytes of the UTF-8 sequence that starts with byte c (1 for a stray one). */
static size_t seq_len(unsigned char c) { return c >= 0xf0 ? 4 : c >= 0xe0 ? 3 : c >= 0xc0 ? 2 : 1; }

static size_t line_end(const pfx_lsp_text *t, size_t line) {
    size_t e = line + 1 < t->line_count ? t->line_starts[line + 1] - 1 : t->len;
    if (e > t->line_starts[line] && t->text[e - 1] == '\r')
        e--;
    return e;
}

int pfx_lsp_char_of_col(const pfx_lsp_text *t, int line, int col) {
    if (line < 1 || (size_t)line > t->line_count)
        return 0;
    size_t p = t->line_starts[line - 1], e = line_end(t, (size_t)line - 1);
    int units = 0;
    for (int c = 1; c < col && p < e; c++) {
        size_t n = seq_len((unsigned char)t->text[p]);
        units += n == 4 ? 2 : 1;
        p += n;
    }
    return units;
}

size_t pfx_lsp_offset(const pfx_lsp_text *t, int line, int character) {
    if (line < 0)
        return 0;
    if ((size_t)line >= t->line_count)
        return t->len;
    size_t p = t->line_starts[line], e = line_end(t, (size_t)line);
    for (int u = 0; u < character && p < e;) {
        size_t n = seq_len((unsigned char)t->text[p]);
        u += n == 4 ? 2 : 1;
        p += n;
    }
    return p < e ? p : e;
}

void pfx_lsp_position(const pfx_lsp_text *t, size_t off, int *line, int *character) {
    *line = *character = 0;
    if (!t->line_count) /* not indexed (out of memory) */
        return;
    if (off > t->len)
        off = t->len;
    size_t lo = 0, hi = t->line_count; /* the last line start <= off */
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (t->line_starts[mid] <= off)
            lo = mid;
        else
            hi = mid;
    }
    int units = 0;
    for (size_t p = t->line_starts[lo]; p < off;) {
        size_t n = seq_len((unsigned char)t->text[p]);
        units += n == 4 ? 2 : 1;
        p += n;
    }
    *line = (int)lo;
    *character = units;
}

int pfx_lsp_col_of_char(const pfx_lsp_text *t, int line, int character) {
    if (line < 0 || (size_t)line >= t->line_count)
        return 1;
    size_t p = t->line_starts[line], e = pfx_lsp_offset(t, line, character);
    int col = 1;
    for (; p < e; p += seq_len((unsigned char)t->text[p]))
        col++;
    return col;
}
