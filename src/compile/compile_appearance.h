/* Compiling how a particle looks over its life: `size`, `color`, `alpha`. */
#ifndef PFX_COMPILE_APPEARANCE_H
#define PFX_COMPILE_APPEARANCE_H

#include "compile/read.h"
#include "model/effect.h"

/* Reads the appearance keys of emitter mapping n into em (keeping em's
 * defaults for absent keys). Reports problems; false on any error. */
bool pfx_compile_appearance(pfx_reader *r, const pfx_node *n, pfx_emitter *em);

/* A curve [{at, value}] over normalised age (values in [lo, hi]) sampled
 * linearly into lut; false (reported) when it is malformed. */
bool pfx_read_life_curve(pfx_reader *r, const pfx_node *n, const char *what, double lo, double hi,
                         float lut[PFX_GRADIENT_LUT]);

#endif
