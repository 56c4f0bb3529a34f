/* What every render and bake does around its work: decide from the
 * previous manifest whether there is anything to do, and afterwards list
 * the outputs, remove the stale ones, write the manifest and the depfile.
 * The command fills the manifest's settings and inputs; this file owns the
 * order of the steps. */
#ifndef PFX_JOBS_DELIVERY_H
#define PFX_JOBS_DELIVERY_H

#include <stdbool.h>

#include "base/diag.h"
#include "jobs/manifest.h"

typedef struct pfx_delivery {
    /* In. */
    const char *dir;           /* the outputs' directory */
    const char *manifest_path; /* dir/<name>.manifest.json; NULL: no manifest (-o -) */
    const char *depfile;       /* --depfile, or NULL */
    const char *target;        /* the depfile's target: the file a build rule names */
    bool force;                /* --force: run even when up to date */
    /* State: the manifest being built, and the previous one (or NULL). */
    pfx_manifest *now, *prev;
    size_t stale_removed; /* after finish */
} pfx_delivery;

/* Creates the manifest for `command` and reads the previous one. False
 * when out of memory. */
bool pfx_delivery_begin(pfx_delivery *dl, const char *command, pfx_diags *d);

/* True when the previous manifest has the same bake key and every output
 * it lists is intact, and --force was not given: then the command skips
 * its work and calls pfx_delivery_skip. */
bool pfx_delivery_up_to_date(pfx_delivery *dl);

/* Nothing to do: refresh the time of the manifest and the depfile's target
 * (so that make and ninja see them newer than touched but unchanged inputs)
 * and write the depfile. */
bool pfx_delivery_skip(pfx_delivery *dl, pfx_diags *d);

/* After the outputs are listed (pfx_manifest_add_output on dl->now):
 * removes stale outputs, writes the manifest, then the depfile. */
bool pfx_delivery_finish(pfx_delivery *dl, pfx_diags *d);

void pfx_delivery_free(pfx_delivery *dl);

#endif
