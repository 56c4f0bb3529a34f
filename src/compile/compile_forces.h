/* Compiling one `forces:` entry. */
#ifndef PFX_COMPILE_FORCES_H
#define PFX_COMPILE_FORCES_H

#include "compile/keys.h"
#include "compile/read.h"
#include "model/effect.h"

/* Reads force `key: f` into out (name copied into the reader's arena).
 * `seed` seeds turbulence. Reports problems; returns false on any error. */
bool pfx_compile_force(pfx_reader *r, const pfx_node *key, const pfx_node *f, uint64_t seed,
                       pfx_force *out);

/* The key table of each force kind (PFX_FORCE_KINDS order) and of each
 * region kind, NULL-terminated, for the schema. */
extern const pfx_key_table *const pfx_force_tables[];
extern const pfx_key_table *const pfx_region_tables[];

#endif
