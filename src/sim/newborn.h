/* Births into the pools (sim/newborn.c). Internal to src/sim. */
#ifndef PFX_SIM_NEWBORN_H
#define PFX_SIM_NEWBORN_H

#include "sim/spawn.h"

/* Emits emitter i's scheduled births due up to t1, each stepped from its
 * birth time to t1. Births that cannot be alive at t1 are skipped in closed
 * form, their draws jumped, so a step costs the births due in it. */
void pfx_sim_emit(pfx_sim *s, size_t i, double t1);

/* Makes every queued sub-emitter particle (and those their births queue in
 * turn) for the step ending at t1. */
void pfx_spawn_process(pfx_sim *s, double t1);

#endif
