/* Diagnostics as a SARIF 2.1.0 log (OASIS Static Analysis Results
 * Interchange Format), the form code-scanning services read: one run whose
 * tool lists every rule of base/diag_rules.h, and one result per error or
 * warning, its notes as related locations. It formats what base/diag.h
 * collected; it does not decide what is an error. */
#ifndef PFX_SARIF_H
#define PFX_SARIF_H

#include <stdbool.h>
#include <stdio.h>

#include "base/diag.h"

typedef struct pfx_sarif pfx_sarif;

/* An empty log; NULL when out of memory. Free it with pfx_sarif_destroy. */
pfx_sarif *pfx_sarif_create(void);
void pfx_sarif_destroy(pfx_sarif *s);

/* Appends d's diagnostics as results, in the order pfx_diags_print prints
 * them. d is only read; the log keeps copies. False when out of memory. */
bool pfx_sarif_add(pfx_sarif *s, const pfx_diags *d);

/* Writes the whole log to out as one JSON document and a newline. False
 * when it could not be written. */
bool pfx_sarif_write(const pfx_sarif *s, FILE *out);

#endif
