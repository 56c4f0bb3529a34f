/* Diagnostics: the one error channel below main.c. Collected per file,
 * sorted by position, printed gcc-style (file:line:col: severity: message,
 * the source line, a caret) or as JSON lines. Runtime failures (a file
 * that cannot be written, a simulation that blew up) go into a list with
 * no file and print as "pfx: message". No global state: every stage that
 * can fail takes a pfx_diags (or a pfx_diag_at). */
#ifndef PFX_DIAG_H
#define PFX_DIAG_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "base/diag_rules.h"

typedef enum { PFX_SEV_ERROR, PFX_SEV_WARNING, PFX_SEV_NOTE } pfx_severity;

/* A rule's enumerator is its stable number (PFX_RULE_OUT_OF_RANGE = 3001);
 * 0 is no rule, which only notes have. */
typedef enum {
    PFX_RULE_NONE = 0,
#define PFX_RULE_ENUM(num, id, name, sev, help) PFX_RULE_##id = num,
    PFX_DIAG_RULES(PFX_RULE_ENUM)
#undef PFX_RULE_ENUM
} pfx_rule;

typedef struct pfx_rule_info {
    pfx_rule rule; /* its number */
    const char *name;
    pfx_severity severity; /* the default: a call may report it otherwise */
    const char *help;
} pfx_rule_info;

/* The table's rows in order, and their count. */
extern const pfx_rule_info pfx_rules[];
extern const size_t pfx_rule_count;
/* The row of rule, or NULL for PFX_RULE_NONE and numbers with no row. */
const pfx_rule_info *pfx_rule_find(pfx_rule rule);

typedef struct pfx_diag {
    pfx_severity severity;
    int line, col; /* 1-based; 0 when the problem has no position */
    int span;      /* characters to underline, at least 1 */
    int seq;       /* insertion order, for a stable sort */
    pfx_rule rule; /* PFX_RULE_NONE for a note */
    char *message;
    /* The effect's reason when its `allow:` acknowledges the warning (a
     * note shares its head's): not printed, not counted in warnings, a
     * suppression in SARIF. Borrowed from the list's allow table. */
    const char *allowed;
} pfx_diag;

/* A rule an effect file acknowledges (`allow: {PFX5002: reason}`). */
typedef struct pfx_diag_allow {
    pfx_rule rule;
    char *reason;
} pfx_diag_allow;

typedef struct pfx_diags {
    const char *file;   /* the name printed before each diagnostic; NULL: runtime
                           failures, printed after "pfx: " */
    const char *source; /* the file's text, for the quoted line; may be NULL */
    size_t source_len;
    pfx_diag *items;
    size_t count, cap;
    int errors, warnings;
    int allowed;            /* warnings acknowledged by `allow:`, not in warnings */
    int dropped;            /* diagnostics past the cap, counted not stored */
    pfx_diag_allow *allows; /* the file's `allow:` table */
    size_t allow_count;
} pfx_diags;

/* At most this many diagnostics are kept per file: a hostile file cannot
 * make the report unbounded. */
#define PFX_DIAG_MAX 200

void pfx_diags_init(pfx_diags *d, const char *file, const char *source, size_t source_len);
/* A list for runtime failures: no file, no source. */
void pfx_diags_init_runtime(pfx_diags *d);
void pfx_diags_free(pfx_diags *d);

/* Every error and warning names its rule, just before the format; a note
 * (pfx_diag_note) belongs to the error or warning before it and has none. */
void pfx_diag_add(pfx_diags *d, pfx_severity sev, int line, int col, int span, pfx_rule rule,
                  const char *fmt, ...) __attribute__((format(printf, 7, 8)));
void pfx_diag_vadd(pfx_diags *d, pfx_severity sev, int line, int col, int span, pfx_rule rule,
                   const char *fmt, va_list ap);
void pfx_diag_note(pfx_diags *d, int line, int col, int span, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* An error without a position (a runtime failure), in git's wording:
 * lowercase, no full stop, the subject in single quotes. d may be NULL. */
void pfx_diag_error(pfx_diags *d, pfx_rule rule, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Acknowledges warnings of `rule` in d with `reason` (copied): those
 * already there and those added later are marked allowed, counted in
 * d->allowed instead of d->warnings. Returns false when out of memory. */
bool pfx_diags_allow(pfx_diags *d, pfx_rule rule, const char *reason);

/* Moves every diagnostic of src to the end of dst (src is left empty); an
 * allowed warning (and its notes) is only counted in dst->allowed. */
void pfx_diags_append(pfx_diags *dst, pfx_diags *src);

/* Where a stage that cannot locate a problem itself should blame it: the
 * list and the position of the node that led there (a mesh file's key, a
 * texture's key). */
typedef struct pfx_diag_at {
    pfx_diags *d;
    int line, col, span;
} pfx_diag_at;
void pfx_diag_error_at(const pfx_diag_at *at, pfx_rule rule, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Prints every diagnostic sorted by position (notes stay after the error they
 * follow; allowed warnings and their notes are left out), each error and warning ending in its rule
 * id (" [PFX3001]"). json: one object per line with file, line, column, severity, rule (null for a
 * note) and message. */
void pfx_diags_print(const pfx_diags *d, FILE *out, bool json);

/* The indices of d->items in printed order (each head followed by its
 * notes), in a malloc'd array of d->count the caller frees; NULL when out
 * of memory. */
size_t *pfx_diags_order(const pfx_diags *d);

/* Prints the rule table, a row a line: id, default severity, name and
 * help, separated by runs of spaces (validate --list-rules; the man page's
 * DIAGNOSTICS section lists the same rows). */
void pfx_rules_print(FILE *out);

/* "PFX3001" for rule 3001, into buf (at least 12 bytes); "" for none. */
const char *pfx_rule_id(pfx_rule rule, char *buf, size_t size);

#endif
