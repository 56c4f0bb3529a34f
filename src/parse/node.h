/* The parsed document: a tree of scalars, sequences and mappings, each with
 * its 1-based line and column. YAML aliases share the anchored node, so the
 * tree is a DAG whose expanded size the parser has bounded. */
#ifndef PFX_NODE_H
#define PFX_NODE_H

#include <stdbool.h>
#include <stddef.h>

#include "base/arena.h"
#include "base/diag.h"

typedef enum { PFX_NODE_SCALAR, PFX_NODE_SEQ, PFX_NODE_MAP } pfx_node_kind;

typedef struct pfx_node pfx_node;
typedef struct pfx_pair {
    pfx_node *key; /* always a scalar */
    pfx_node *value;
} pfx_pair;

struct pfx_node {
    pfx_node_kind kind;
    int line, col; /* 1-based */
    int span;      /* source columns the node's first line covers, for the caret */
    /* scalar */
    const char *text;
    size_t len;
    bool plain; /* unquoted: may be a number, boolean or null */
    /* sequence: items; mapping: pairs in file order */
    size_t count;
    pfx_node **items;
    pfx_pair *pairs;
};

typedef struct pfx_doc {
    pfx_arena arena;
    pfx_node *root; /* NULL when the file is empty or did not parse */
} pfx_doc;

/* Limits that keep a hostile file bounded in time and memory. */
#define PFX_MAX_FILE_BYTES (16u << 20)
#define PFX_MAX_DEPTH 64
#define PFX_MAX_EXPANDED_NODES 1000000

/* Parses YAML text (one document) into doc. Reports every syntax problem into
 * d at its position; returns false if the document cannot be used. The
 * caller frees doc with pfx_doc_free even on failure. */
bool pfx_parse(const char *text, size_t len, pfx_doc *doc, pfx_diags *d);
void pfx_doc_free(pfx_doc *doc);

/* The value of `key` in mapping `map`, or NULL. */
const pfx_node *pfx_node_get(const pfx_node *map, const char *key);
/* Kind name for messages: "a number", "a list", "a mapping", "a string". */
const char *pfx_node_kind_name(const pfx_node *n);

#endif
