/* Compiling an emitter's `kill:` rules and `bounds:` box. */
#ifndef PFX_COMPILE_KILL_H
#define PFX_COMPILE_KILL_H

#include "compile/read.h"
#include "model/kill_rules.h"

/* Reads `kill:` node kill_node and `bounds:` node bounds_node (either may be
 * NULL: absent) into out, which it overwrites. Reports every problem at its
 * node; returns false on any error. Nothing is allocated: the caller keeps a
 * copy only when !pfx_kill_rules_empty(out). */
bool pfx_compile_kill(pfx_reader *r, const pfx_node *kill_node, const pfx_node *bounds_node,
                      pfx_kill_rules *out);

#endif
