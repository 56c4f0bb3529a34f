/* Compiling when an emitter emits: `rate` (number, {mean, var}, a curve
 * [{t, value}], or {initial, delta}), `interval`, `bursts`, `start`,
 * `duration` and `loop`. */
#ifndef PFX_COMPILE_EMISSION_H
#define PFX_COMPILE_EMISSION_H

#include "compile/read.h"
#include "model/effect.h"

/* Reads the emission keys of emitter mapping n into em (defaults: 10 per
 * second from time 0 for ever). Reports problems; false on any error. */
bool pfx_compile_emission(pfx_reader *r, const pfx_node *n, pfx_emitter *em);

/* Reads keyframes `[{t: s, value: [x, y, z]}, ...]` (t increasing) into keys,
 * or a plain [x, y, z] into fixed (keys->count stays 0). */
bool pfx_read_keys3(pfx_reader *r, const pfx_node *n, const char *what, double fixed[3],
                    pfx_keys3 *keys);

#endif
