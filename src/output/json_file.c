#include "output/json_file.h"

#include <errno.h>
#include <stdio.h>

#include "base/json_text.h"
#include "output/atomic_file.h"

bool pfx_json_file_write(const char *path, const json_t *root, pfx_diags *d) {
    return pfx_json_file_write_in(NULL, path, root, d);
}

bool pfx_json_file_write_in(pfx_atomic_group *g, const char *path, const json_t *root,
                            pfx_diags *d) {
    if (!root) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "cannot write '%s': out of memory", path);
        return false;
    }
    /* Names that are not UTF-8 keep their bytes (base/json_text.h). */
    json_t *escaped = pfx_json_escaped(root);
    if (!escaped) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "cannot write '%s': out of memory", path);
        return false;
    }
    pfx_atomic_file *a = pfx_atomic_open_in(g, path, d);
    if (!a) {
        json_decref(escaped);
        return false;
    }
    FILE *f = pfx_atomic_stream(a);
    if (json_dumpf(escaped, f, JSON_INDENT(2) | JSON_PRESERVE_ORDER) != 0 || fputc('\n', f) == EOF)
        pfx_atomic_failed(a, errno);
    json_decref(escaped);
    return pfx_atomic_commit(a, true, d);
}
