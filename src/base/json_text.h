/* Text pfx did not write itself (file names, messages quoting them) in the
 * JSON it writes: diagnostics, --progress json, manifests, atlas and
 * motion-vector sidecars. A file name is bytes, not always UTF-8, and
 * jansson refuses what is not UTF-8: these helpers keep such a name
 * whole. Text that is UTF-8 is written as it is. A string member that is
 * not gets each byte outside a UTF-8 character replaced by U+FFFD (for
 * reading), and a member "<key>_base64" beside it with the exact bytes
 * (RFC 4648 base64): the way ripgrep's --json carries bytes. */
#ifndef PFX_BASE_JSON_TEXT_H
#define PFX_BASE_JSON_TEXT_H

#include <jansson.h>
#include <stdbool.h>

/* A jansson string of s's bytes as they are, UTF-8 or not, for building a
 * document in memory (comparisons see the real bytes). Dump only what
 * pfx_json_escaped made of it. NULL when out of memory. */
json_t *pfx_json_bytes(const char *s);

/* A deep copy of v that jansson can dump: each string member that is not
 * UTF-8 as the header says (U+FFFD, and its bytes in "<key>_base64");
 * strings in arrays and object keys get U+FFFD only. NULL when out of
 * memory. The caller owns the result. */
json_t *pfx_json_escaped(const json_t *v);

/* The inverse, in place, for a document pfx reads back: each member
 * "<key>_base64" beside a string member "<key>" is decoded into <key>
 * (as pfx_json_bytes) and removed. */
void pfx_json_unescape(json_t *v);

#endif
