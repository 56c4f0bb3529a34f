/* A JSON document as an output file: indented, keys in the order they
 * were set, a final newline, written through the atomic-file writer (whole
 * or absent). Manifests, atlas and motion-vector sidecars use it. */
#ifndef PFX_OUTPUT_JSON_FILE_H
#define PFX_OUTPUT_JSON_FILE_H

#include <jansson.h>
#include <stdbool.h>

#include "base/diag.h"
#include "output/atomic_file.h"

/* Writes root to path and syncs the directory; root NULL (a failed
 * json_pack) is reported as out of memory. Does not take root. False with
 * "cannot write 'path': ..." in d. */
bool pfx_json_file_write(const char *path, const json_t *root, pfx_diags *d);
/* The same as a file of group g, which renames it into place with the
 * others (output/atomic_file.h). */
bool pfx_json_file_write_in(pfx_atomic_group *g, const char *path, const json_t *root,
                            pfx_diags *d);

#endif
