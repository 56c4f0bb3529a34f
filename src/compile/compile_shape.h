/* Compiling an emitter's shape. */
#ifndef PFX_COMPILE_SHAPE_H
#define PFX_COMPILE_SHAPE_H

#include "compile/read.h"
#include "model/effect.h"

/* Reads `shape:` node n into s. `emitter` names the emitter in messages;
 * `effect_path` is the effect file's path (a mesh `file` is relative to its
 * directory; NULL: to the working directory). Tables (an ellipse rim's, a
 * mesh's) live in r->arena. Reports problems; returns false on any error. */
bool pfx_compile_shape(pfx_reader *r, const pfx_node *n, pfx_shape *s, const char *emitter,
                       const char *effect_path);

/* The shape type's name as written in effect files ("cylinder"). */
const char *pfx_shape_type_name(pfx_shape_type t);

#endif
