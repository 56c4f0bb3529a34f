/* What a key means, in words: the one text of a key-table row that both
 * `pfx lsp`'s hover and the JSON Schema's descriptions show (its meaning
 * with the unit, the form its value takes, its range and its default). */
#ifndef PFX_COMPILE_KEY_DOC_H
#define PFX_COMPILE_KEY_DOC_H

#include <stdbool.h>
#include <stddef.h>

#include "compile/keys.h"

/* What every colour key accepts: the schema's error message for a bad
 * colour and the form hover shows. */
extern const char *const pfx_colour_forms;

/* Writes k's text into buf (size bytes, always terminated): its doc, then
 * "Form: ...", "Range: ..." and "Default: ..." paragraphs. With markdown,
 * names and values are `code`; without, the text is plain. Returns the
 * length written (truncated to fit). */
size_t pfx_key_doc(const pfx_key *k, bool markdown, char *buf, size_t size);

#endif
