/* Compiling sub-emitters: `on_birth`, `on_death`, `on_hit` and `trail`. */
#ifndef PFX_COMPILE_SPAWN_H
#define PFX_COMPILE_SPAWN_H

#include "compile/read.h"
#include "model/effect.h"

/* Reads the sub-emitter keys of emitter mapping n into em->spawns; targets
 * are looked up by name in the `emitters:` mapping. */
bool pfx_compile_spawns(pfx_reader *r, const pfx_node *n, const pfx_node *emitters,
                        pfx_emitter *em);

/* After every emitter is compiled: rejects cycles of sub-emitters without a
 * `depth`, marks the columns targets need (generation, parent colour, size
 * scale), and computes each emitter's worst-case spawned birth rate for
 * pool sizing. `emitters` is the `emitters:` mapping, for locations. */
bool pfx_resolve_spawns(pfx_reader *r, pfx_effect *e, const pfx_node *emitters);

/* Every `draw: ribbon` emitter is fed by the trail of exactly one other
 * emitter and by nothing else (no sub-emitter event, no births of its
 * own); reports each breach at its key, and notes the feeder in
 * ribbon_parent. */
bool pfx_check_ribbons(pfx_reader *r, pfx_effect *e, const pfx_node *emitters);

#endif
