/* Depfiles: one Make rule naming every input a run read, for make, ninja
 * and CMake's add_custom_command(DEPFILE ...). */
#ifndef PFX_JOBS_DEPFILE_H
#define PFX_JOBS_DEPFILE_H

#include <stdbool.h>

#include "base/diag.h"
#include "jobs/manifest.h"

/* Writes "target: input input ...\n" to path (whole or not at all), every
 * input of m, with spaces, '#' and '$' escaped as Make reads them. False
 * with the reason in d. */
bool pfx_depfile_write(const char *path, const char *target, const pfx_manifest *m, pfx_diags *d);

#endif
