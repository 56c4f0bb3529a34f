/* One open document of the language server (lsp/server.c keeps them): the
 * editor's text, its version, and the last analysis of that text through
 * the same load path as `pfx validate` (jobs/load.c). Kept thin on purpose:
 * the live session (jobs/session.c) is the place such state should move to.
 * The features (hover.c, complete.c, ...) read a document, never write. */
#ifndef PFX_LSP_DOCUMENT_H
#define PFX_LSP_DOCUMENT_H

#include <jansson.h>
#include <stdbool.h>

#include "jobs/load.h"
#include "lsp/position.h"

typedef struct pfx_lsp_doc {
    char *uri;  /* as the client named it */
    char *path; /* the file path it stands for (relative meshes resolve from it) */
    char *text; /* the editor's text, not the file on disk */
    size_t len;
    long version;
    bool pending;  /* text changed since the last analysis */
    double due_ms; /* when the pending analysis runs (the debounce) */
    /* The last analysis, of `text` when !pending. */
    bool analysed;
    pfx_loaded loaded;
    pfx_lsp_text lines; /* line index of loaded.source */
} pfx_lsp_doc;

/* LSP Position {line, character} of pfx's 1-based line and column. */
json_t *pfx_lsp_pos_json(const pfx_lsp_doc *d, int line, int col);
/* A Range from pfx's line and column over span characters of that line. */
json_t *pfx_lsp_range_json(const pfx_lsp_doc *d, int line, int col, int span);
/* A Range from byte offsets of d's analysed text. */
json_t *pfx_lsp_range_bytes(const pfx_lsp_doc *d, size_t from, size_t to);

/* The features, each answering from d's analysis (the server analyses a
 * pending document before it asks). Each returns a new JSON reference (the
 * result of the request), json_null() when there is nothing. */
json_t *pfx_lsp_diagnostics(const pfx_lsp_doc *d);
json_t *pfx_lsp_hover(const pfx_lsp_doc *d, int line, int character);
json_t *pfx_lsp_completion(const pfx_lsp_doc *d, int line, int character);
json_t *pfx_lsp_symbols(const pfx_lsp_doc *d);
json_t *pfx_lsp_definition(const pfx_lsp_doc *d, int line, int character);
json_t *pfx_lsp_references(const pfx_lsp_doc *d, int line, int character, bool declaration);
/* NULL (not json_null()) refuses the rename: new_name is not a plain key
 * or another force, deflector or emitter already has it. */
json_t *pfx_lsp_rename(const pfx_lsp_doc *d, int line, int character, const char *new_name);
json_t *pfx_lsp_code_actions(const pfx_lsp_doc *d, json_t *params);
json_t *pfx_lsp_colors(const pfx_lsp_doc *d);
json_t *pfx_lsp_color_presentations(const pfx_lsp_doc *d, json_t *params);

#endif
