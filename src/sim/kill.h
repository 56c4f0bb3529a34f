/* Applying death conditions besides old age, and wrapping bounds (the
 * particle loop's first step; snow that leaves its box re-enters at the top:
 * docs/physics.md). The compiler fills a pfx_kill_rules per emitter
 * (src/compile/compile_kill.c); after each integration the simulation calls
 * pfx_kill_apply, which wraps positions into a wrapping box and marks the
 * particles a rule kills by setting lifetime = PFX_KILLED, so the existing
 * age >= lifetime swap-remove pass removes them: no second compaction. */
#ifndef PFX_KILL_H
#define PFX_KILL_H

#include <stdbool.h>
#include <stddef.h>

#include "model/kill_rules.h"

typedef struct pfx_pool pfx_pool;

/* Wraps (bounds WRAP) then marks (bounds KILL and each rule, in list order;
 * regions test the wrapped positions) the live particles of p, one pass per
 * rule, never allocating: a particle to die gets lifetime = PFX_KILLED and stays in
 * place for the age >= lifetime pass to remove. `emitter_pos` is the
 * emitter's world position at the time of the check (read by
 * distance_from_emitter only; may be NULL otherwise). `alpha_at_age[k]` is
 * the particle's alpha at normalised age k / (PFX_KILL_ALPHA_LUT - 1), looked
 * up at the nearest entry as pfx_particle_color does (read by alpha_below
 * only; may be NULL otherwise). Positions and lifetimes are written in place;
 * nothing else is touched. */
void pfx_kill_apply(const pfx_kill_rules *k, pfx_pool *p, const double emitter_pos[3],
                    const float alpha_at_age[PFX_KILL_ALPHA_LUT]);

/* One coordinate x mapped into the half-open float interval [lo, hi)
 * (lo < hi): lo + (x - lo) mod (hi - lo), the remainder taken exactly, the
 * result the nearest float to it, and hi itself (reached by round-off or
 * exactly) identified with lo. Always lo <= result < hi. */
float pfx_kill_wrap(float x, float lo, float hi);

#endif
