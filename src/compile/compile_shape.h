/* Compiling an emitter's shape. */
#ifndef PFX_COMPILE_SHAPE_H
#define PFX_COMPILE_SHAPE_H

#include "compile/effect.h"
#include "compile/read.h"

/* Reads `shape:` node n into s. `emitter` names the emitter in messages;
 * `effect_path` is the effect file's path (files a shape names are relative
 * to its directory). Reports problems; returns false on any error. */
bool pfx_compile_shape(pfx_reader *r, const pfx_node *n, pfx_shape *s, const char *emitter,
                       const char *effect_path);

#endif
