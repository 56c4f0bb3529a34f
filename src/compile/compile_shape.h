/* Compiling an emitter's shape. */
#ifndef PFX_COMPILE_SHAPE_H
#define PFX_COMPILE_SHAPE_H

#include "compile/keys.h"
#include "compile/read.h"
#include "model/effect.h"

/* Reads `shape:` node n into s. `emitter` names the emitter in messages;
 * `effect_path` is the effect file's path (a mesh `file` is relative to its
 * directory; NULL: to the working directory). Tables (an ellipse rim's, a
 * mesh's) live in r->arena. Reports problems; returns false on any error. */
bool pfx_compile_shape(pfx_reader *r, const pfx_node *n, pfx_shape *s, const char *emitter,
                       const char *effect_path);

/* The key table of each shape kind (PFX_SHAPE_KINDS order), NULL-terminated,
 * for the schema. */
extern const pfx_key_table *const pfx_shape_tables[];

#endif
