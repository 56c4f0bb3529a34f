/* Births into the pools (sim/newborn.c). Internal to src/sim. */
#ifndef PFX_SIM_NEWBORN_H
#define PFX_SIM_NEWBORN_H

#include "sim/spawn.h"

/* Emits emitter i's scheduled births due up to t1, each stepped from its
 * birth time to t1. Births that cannot be alive at t1 are skipped in closed
 * form, their draws jumped, so a step costs the births due in it. */
void pfx_sim_emit(pfx_sim *s, size_t i, double t1);

/* The batches in which scheduled births are made on `threads` threads,
 * one of them working in `own`, the sim's block (NULL for one thread, and
 * when out of memory): at most 16 tasks, 15 blocks of working columns
 * (about 52 KB each) beside the sim's own. */
pfx_birth_batch *pfx_birth_batch_create(int threads, struct pfx_birth_block *own);
void pfx_birth_batch_destroy(pfx_birth_batch *batch);

/* Makes every queued sub-emitter particle (and those their births queue in
 * turn) for the step ending at t1. */
void pfx_spawn_process(pfx_sim *s, double t1);

#endif
