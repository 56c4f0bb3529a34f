/* The colour words of compile/colour_text.h: hex digits and the CSS
 * names' table. Lists of components ([r, g, b]) are the reader's
 * (compile/read.c), as they need a node per component to blame. */
#include "compile/colour_text.h"

#include <stddef.h>
#include <string.h>

#include "compile/css_colours.h"

static int hex_digit(char c) {
    return c >= '0' && c <= '9'   ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : -1;
}

bool pfx_colour_parse_hex(const char *s, float out[4]) {
    if (s[0] != '#')
        return false;
    size_t n = strlen(s + 1);
    if (n != 3 && n != 4 && n != 6 && n != 8)
        return false;
    for (size_t i = 0; i < n; i++)
        if (hex_digit(s[1 + i]) < 0)
            return false;
    out[3] = 1.0f;
    if (n <= 4) {
        for (size_t i = 0; i < n; i++)
            out[i] = (float)(hex_digit(s[1 + i]) * 17) / 255.0f;
    } else {
        for (size_t i = 0; i < n / 2; i++)
            out[i] = (float)(hex_digit(s[1 + 2 * i]) * 16 + hex_digit(s[2 + 2 * i])) / 255.0f;
    }
    return true;
}

#define CSS_NAME(name, rgb) name,
#define CSS_VALUE(name, rgb) rgb,
const char *const pfx_css_colour_names[] = {PFX_CSS_COLOURS(CSS_NAME) NULL};
static const unsigned css_values[] = {PFX_CSS_COLOURS(CSS_VALUE)};
#undef CSS_NAME
#undef CSS_VALUE

bool pfx_colour_parse_name(const char *s, float out[4]) {
    for (size_t i = 0; pfx_css_colour_names[i]; i++)
        if (!strcmp(s, pfx_css_colour_names[i])) {
            for (int c = 0; c < 3; c++)
                out[c] = (float)((css_values[i] >> (16 - 8 * c)) & 0xff) / 255.0f;
            out[3] = 1.0f;
            return true;
        }
    return false;
}

bool pfx_colour_parse_word(const char *s, float out[4]) {
    if (!strcmp(s, "transparent")) {
        out[0] = out[1] = out[2] = out[3] = 0.0f;
        return true;
    }
    return pfx_colour_parse_hex(s, out) || pfx_colour_parse_name(s, out);
}
