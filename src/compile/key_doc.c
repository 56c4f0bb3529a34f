/* A key-table row in words, for hover and the schema: its meaning first
 * (the row's doc, which names the unit), then its form, range and default
 * from the row's type, bounds and flags. It neither reads YAML nor knows
 * where the key sits (hover and the schema say that themselves). */
#include "compile/key_doc.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

const char *const pfx_colour_forms =
    "a colour: #rrggbb, #rrggbbaa, [r, g, b(, a)] in 0..1, or a CSS name such as 'orange'";

/* Text appended to a fixed buffer, truncated at its end. */
typedef struct text {
    char *buf;
    size_t size, n;
} text;

static void put(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(text *t, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    int w = vsnprintf(t->buf + t->n, t->size - t->n, fmt, ap);
    va_end(ap);
    if (w > 0)
        t->n = t->n + (size_t)w < t->size ? t->n + (size_t)w : t->size - 1;
}

static void put_names(text *t, const char *const *names, const char *q) {
    for (size_t i = 0; names[i]; i++)
        put(t, "%s%s%s%s", i ? ", " : "", q, names[i], q);
}

/* The form a row's value takes, in words. */
static void put_form(text *t, const pfx_key *k, const char *q) {
    switch (k->type) {
    case PFX_KEY_NUMBER:
        put(t, "a number%s", k->flags & PFX_KEY_DEGREES ? " (degrees)" : "");
        break;
    case PFX_KEY_WHOLE:
        put(t, "a whole number");
        break;
    case PFX_KEY_BOOL:
        put(t, "%strue%s or %sfalse%s", q, q, q, q);
        break;
    case PFX_KEY_VEC3:
        put(t, "[x, y, z]");
        break;
    case PFX_KEY_ENUM:
        put(t, "one of ");
        put_names(t, k->names, q);
        break;
    case PFX_KEY_VALUE:
        put(t, "a value: a number, [min, max], {mean, var} or {normal: [mean, sd], clamp}");
        break;
    case PFX_KEY_RANGE:
        put(t, "a number or [min, max]");
        break;
    case PFX_KEY_COLOUR:
        put(t, "%s", pfx_colour_forms);
        break;
    case PFX_KEY_STRING:
        put(t, "a string");
        break;
    case PFX_KEY_MAP:
        put(t, "a mapping");
        break;
    case PFX_KEY_CODE: /* no form of its own: its doc says it (pfx_key_doc skips it) */
        break;
    }
}

static bool has_range(const pfx_key *k) {
    return (k->type == PFX_KEY_NUMBER || k->type == PFX_KEY_WHOLE || k->type == PFX_KEY_VALUE ||
            k->type == PFX_KEY_RANGE) &&
           (isfinite(k->lo) || isfinite(k->hi));
}

static void put_range(text *t, const pfx_key *k) {
    put(t, "\n\nRange: ");
    if (isfinite(k->lo))
        put(t, "%s %g", k->flags & PFX_KEY_LO_STRICT ? "above" : "from", k->lo);
    if (isfinite(k->lo) && isfinite(k->hi))
        put(t, ", ");
    if (isfinite(k->hi))
        put(t, "%s %g", k->flags & PFX_KEY_HI_STRICT ? "below" : "at most", k->hi);
}

static void put_default(text *t, const pfx_key *k, const char *q) {
    if (k->flags & PFX_KEY_NO_DEFAULT)
        return;
    if (k->type == PFX_KEY_ENUM && k->names)
        put(t, "\n\nDefault: %s%s%s", q, k->names[(int)k->def[0]], q);
    else if (k->type == PFX_KEY_BOOL)
        put(t, "\n\nDefault: %s%s%s", q, k->def[0] ? "true" : "false", q);
    else if (k->type == PFX_KEY_VEC3)
        put(t, "\n\nDefault: [%g, %g, %g]", k->def[0], k->def[1], k->def[2]);
    else if (k->type == PFX_KEY_NUMBER || k->type == PFX_KEY_WHOLE || k->type == PFX_KEY_VALUE ||
             k->type == PFX_KEY_RANGE)
        put(t, "\n\nDefault: %g", k->def[0]);
}

size_t pfx_key_doc(const pfx_key *k, bool markdown, char *buf, size_t size) {
    const char *q = markdown ? "`" : "";
    text t = {buf, size, 0};
    if (!size)
        return 0;
    buf[0] = '\0';
    if (k->doc && k->doc[0])
        put(&t, "%s", k->doc);
    if (k->type != PFX_KEY_CODE) { /* a hook's row: its doc names its forms */
        put(&t, "%sForm: ", t.n ? "\n\n" : "");
        put_form(&t, k, q);
    }
    if (has_range(k))
        put_range(&t, k);
    put_default(&t, k, q);
    return t.n;
}
