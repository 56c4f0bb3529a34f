/* A colour written as one word: "#rgb", "#rgba", "#rrggbb", "#rrggbbaa",
 * a CSS colour name (compile/css_colours.h) or transparent. The one
 * reading of those words, shared by the colour reader (compile/read.c)
 * and the editor's swatches (lsp/colours.c). It reports nothing. */
#ifndef PFX_COMPILE_COLOUR_TEXT_H
#define PFX_COMPILE_COLOUR_TEXT_H

#include <stdbool.h>

/* The CSS colour names, in the table's order, NULL-terminated. */
extern const char *const pfx_css_colour_names[];

/* "#rgb", "#rgba", "#rrggbb" or "#rrggbbaa" into rgba in 0..1 (each byte
 * / 255; without alpha, opaque). False, out untouched, for anything else. */
bool pfx_colour_parse_hex(const char *s, float out[4]);
/* A CSS colour name, converted as its "#rrggbb" is, opaque. False, out
 * untouched, when s is not one. */
bool pfx_colour_parse_name(const char *s, float out[4]);
/* Any of the words above, or transparent (0, 0, 0, 0). */
bool pfx_colour_parse_word(const char *s, float out[4]);

#endif
