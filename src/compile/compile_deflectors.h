/* Compiling one `deflectors:` entry. */
#ifndef PFX_COMPILE_DEFLECTORS_H
#define PFX_COMPILE_DEFLECTORS_H

#include "compile/keys.h"
#include "compile/read.h"
#include "model/effect.h"

/* Reads deflector `key: n` into out (name copied into the reader's arena);
 * `seed` salts its chance hash. Reports problems; false on any error. */
bool pfx_compile_deflector(pfx_reader *r, const pfx_node *key, const pfx_node *n, uint64_t seed,
                           pfx_deflector *out);

/* The key table of each deflector kind (PFX_DEFLECTOR_KINDS order),
 * NULL-terminated, for the schema. */
extern const pfx_key_table *const pfx_deflector_tables[];

#endif
