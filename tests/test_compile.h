/* Compiling an effect written inline in a test: parse + compile with the
 * diagnostics printed on failure (so a broken test effect says why). */
#ifndef PFX_TEST_COMPILE_H
#define PFX_TEST_COMPILE_H

#include <string.h>

#include "compile/compile.h"
#include "test.h"

typedef struct compiled {
    pfx_doc doc;
    pfx_arena arena;
    pfx_diags diags;
    pfx_effect *e;
} compiled;

/* Compiles text as if read from `path` (files it names, such as textures
 * and meshes, are found beside that path). */
static pfx_effect *compile_as(compiled *c, const char *text, const char *path,
                              const pfx_compile_options *opt) {
    memset(c, 0, sizeof *c);
    size_t len = strlen(text);
    pfx_diags_init(&c->diags, path, text, len);
    if (pfx_parse(text, len, &c->doc, &c->diags))
        c->e = pfx_compile(c->doc.root, path, opt, &c->arena, &c->diags);
    if (!c->e)
        pfx_diags_print(&c->diags, stderr, false);
    CHECK(c->e != NULL);
    return c->e;
}

static inline pfx_effect *compile_opt(compiled *c, const char *text,
                                      const pfx_compile_options *opt) {
    return compile_as(c, text, "inline.yaml", opt);
}

static inline pfx_effect *compile_text(compiled *c, const char *text) {
    return compile_opt(c, text, NULL);
}

static inline void compiled_free(compiled *c) {
    pfx_doc_free(&c->doc);
    pfx_arena_free(&c->arena);
    pfx_diags_free(&c->diags);
}

#endif
