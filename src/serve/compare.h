/* The preview's comparison (A/B against another file or another seed): a
 * second live session beside the edited file's, replaced or dropped while
 * requests may still be reading the one before, so each request holds
 * the one it uses until it is done. */
#ifndef PFX_SERVE_COMPARE_H
#define PFX_SERVE_COMPARE_H

#include <stdbool.h>
#include <stdint.h>

#include "base/diag.h"
#include "jobs/session.h"

typedef struct pfx_compare pfx_compare;
typedef struct pfx_compare_ref pfx_compare_ref; /* one comparison, held */

/* No comparison yet; later ones are made from base (the edited file's
 * options; its path is kept, not copied). NULL when out of memory. */
pfx_compare *pfx_compare_create(const pfx_session_options *base);
/* Stops and frees the comparison; call it after the server stopped. */
void pfx_compare_destroy(pfx_compare *c);

/* Compares with file `path` (NULL: the edited file) at seed `seed` (when
 * has_seed; else the file's or --seed's), replacing what was compared
 * before. False, with the reason in d, when the file cannot be read or
 * the session not started; the comparison before is dropped either way. */
bool pfx_compare_set(pfx_compare *c, const char *path, bool has_seed, uint64_t seed, pfx_diags *d);
/* Compares with nothing. */
void pfx_compare_clear(pfx_compare *c);

/* The comparison now, held until pfx_compare_release; NULL when there is
 * none. */
pfx_compare_ref *pfx_compare_hold(pfx_compare *c);
void pfx_compare_release(pfx_compare *c, pfx_compare_ref *r);
pfx_session *pfx_compare_session(const pfx_compare_ref *r);

/* What is compared as JSON text (malloc'd): null, or {file, seed} (seed
 * null when it is the file's own). NULL when out of memory. */
char *pfx_compare_json(pfx_compare *c);

#endif
