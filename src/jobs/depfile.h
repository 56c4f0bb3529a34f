/* Depfiles: one Make rule naming every input a run read, for make, ninja
 * and CMake's add_custom_command(DEPFILE ...). */
#ifndef PFX_JOBS_DEPFILE_H
#define PFX_JOBS_DEPFILE_H

#include <stdbool.h>

#include "base/diag.h"
#include "jobs/manifest.h"

/* Writes "target: input input ...\n" to path (whole or not at all), every
 * input of m, with spaces, '#', ':' and '$' escaped as make and ninja read
 * them. False with the reason in d. */
/* True when make and ninja would both read the target and every input of
 * m as the path it is; else false, naming each path and its character in
 * d (a newline, a tab, ';', '|', '=' ... : see depfile.c). Called before
 * the run, so that a depfile that cannot be written costs no work. */
bool pfx_depfile_check(const char *target, const pfx_manifest *m, pfx_diags *d);

bool pfx_depfile_write(const char *path, const char *target, const pfx_manifest *m, pfx_diags *d);

#endif
