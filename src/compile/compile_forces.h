/* Compiling one `forces:` entry. */
#ifndef PFX_COMPILE_FORCES_H
#define PFX_COMPILE_FORCES_H

#include "compile/read.h"
#include "model/effect.h"

/* Reads force `key: f` into out (name copied into the reader's arena).
 * `seed` seeds turbulence. Reports problems; returns false on any error. */
bool pfx_compile_force(pfx_reader *r, const pfx_node *key, const pfx_node *f, uint64_t seed,
                       pfx_force *out);

#endif
