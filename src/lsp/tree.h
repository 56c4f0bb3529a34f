/* Finding things in an effect's node tree for the language server
 * (lsp/tree.c): the key under a position with the key table row that
 * describes it, and the names of forces, deflectors and emitters with every
 * place that refers to them. Reads the parser's tree and the compiler's
 * tables; knows nothing of LSP's JSON. */
#ifndef PFX_LSP_TREE_H
#define PFX_LSP_TREE_H

#include <stdbool.h>

#include "compile/schema.h"
#include "parse/node.h"

/* The key table a mapping is read with, and where it sits. */
typedef struct pfx_lsp_place {
    const pfx_key_table *table;      /* NULL: no table (a fragment, a section, an unknown type) */
    const pfx_schema_family *family; /* a kinded mapping's family, or NULL */
    int section;                     /* a named section's mapping (pfx_lsp_section), or -1 */
    const pfx_node *map;             /* the mapping, when walking a tree */
    const char *emitter;             /* the name of the emitter it is in, or NULL */
} pfx_lsp_place;

/* What is at a position: a key of a mapping (key set), or a scalar value
 * (value set, key its pair's key when it has one). */
typedef struct pfx_lsp_hit {
    pfx_lsp_place in;
    const pfx_node *key, *value;
    const pfx_key *row; /* key's row in in.table, or NULL */
} pfx_lsp_hit;

/* The node at pfx's (line, col) in root; false when none. */
bool pfx_lsp_find(const pfx_node *root, int line, int col, pfx_lsp_hit *hit);

/* The place of the mapping under key `name` of the place `in`, whose
 * `type` is `type` (NULL: none or unknown); its map is left NULL. False
 * when that mapping is read without a table. */
bool pfx_lsp_descend(const pfx_lsp_place *in, const char *name, const char *type,
                     pfx_lsp_place *out);

/* The top-level place: the effect's own table. */
pfx_lsp_place pfx_lsp_top_place(const pfx_node *root);

/* Named things: the sections of the top level whose keys are names. */
typedef enum {
    PFX_LSP_FORCE,
    PFX_LSP_DEFLECTOR,
    PFX_LSP_EMITTER,
    PFX_LSP_SECTIONS
} pfx_lsp_section;
extern const char *const pfx_lsp_section_names[PFX_LSP_SECTIONS]; /* "forces", ... */

/* A name's definition (its key under the section) or a reference to it. */
typedef struct pfx_lsp_name {
    pfx_lsp_section section;
    const pfx_node *node;
    bool definition;
} pfx_lsp_name;

/* Calls fn for every definition and reference in root, in file order. */
void pfx_lsp_names(const pfx_node *root, void (*fn)(const pfx_lsp_name *n, void *ctx), void *ctx);
/* The definition or reference at pfx's (line, col), or false. */
bool pfx_lsp_name_at(const pfx_node *root, int line, int col, pfx_lsp_name *out);

/* Whether scalar n covers pfx's (line, col), quotes included. */
bool pfx_lsp_covers(const pfx_node *n, int line, int col);

#endif
