/* Positions between pfx and LSP (lsp/position.c), converted here and
 * nowhere else: pfx counts 1-based lines and 1-based columns of Unicode
 * characters (libyaml's marks), LSP 0-based lines and 0-based UTF-16 code
 * units. Both directions read the document's text. */
#ifndef PFX_LSP_POSITION_H
#define PFX_LSP_POSITION_H

#include <stddef.h>

/* A document's text and the byte offset where each line starts. */
typedef struct pfx_lsp_text {
    const char *text;
    size_t len;
    size_t *line_starts; /* malloc'd, line_count of them */
    size_t line_count;
} pfx_lsp_text;

/* Indexes text (kept by reference). False when out of memory. */
int pfx_lsp_text_init(pfx_lsp_text *t, const char *text, size_t len);
void pfx_lsp_text_free(pfx_lsp_text *t);

/* The UTF-16 character of pfx's 1-based (line, col); past the line's end
 * clamps to it. */
int pfx_lsp_char_of_col(const pfx_lsp_text *t, int line, int col);
/* The byte offset of LSP's (line, character), clamped to the text. */
size_t pfx_lsp_offset(const pfx_lsp_text *t, int line, int character);
/* pfx's 1-based column of LSP's (line, character) on that line. */
int pfx_lsp_col_of_char(const pfx_lsp_text *t, int line, int character);
/* The LSP (line, character) of byte offset off. */
void pfx_lsp_position(const pfx_lsp_text *t, size_t off, int *line, int *character);

#endif
