/* The particle simulation: one Struct-of-Arrays pool per emitter, stepped at
 * the effect's fixed rate. Births happen at their exact times inside a step;
 * a frame's state is the fixed-step state advanced by the remainder on a
 * scratch copy, so the stepping never depends on the output frame rate. */
#ifndef PFX_SIM_H
#define PFX_SIM_H

#include <stdbool.h>
#include <stdint.h>

#include "model/effect.h"
#include "sim/appearance.h"
#include "sim/state.h"

/* Allocates every pool once (sized by the compiler) and seeds every emitter.
 * A failure of the simulation is reported into d (may be NULL; not owned).
 * Returns NULL when out of memory. Free with pfx_sim_destroy. */
pfx_sim *pfx_sim_create(const pfx_effect *e, pfx_diags *d);
void pfx_sim_destroy(pfx_sim *s);

/* Bytes each particle of emitter i occupies (the columns it keeps). */
size_t pfx_sim_bytes_per_particle(const pfx_effect *e, size_t i);
/* Of those, the step's own scratch (the deflectors' start state and
 * marks). */
size_t pfx_sim_scratch_bytes_per_particle(const pfx_effect *e, size_t i);

/* Bytes of the on_hit event buffers of the collide pass's blocks
 * (sim/step.h), 0 where no emitter's hits start particles. */
size_t pfx_sim_hit_buffer_bytes(const pfx_effect *e);
/* Particles a block of e's threaded passes (sim/state.h): PFX_SIM_BLOCK_MAX,
 * halved down to PFX_SIM_BLOCK_MIN while its largest pool would hold fewer
 * than 4 blocks a thread (at 10^5 particles, 8192 a block: two threads
 * on 4096 were 5 % slower in `pfx bench sim`). */
uint32_t pfx_sim_block(const pfx_effect *e);

/* Advances by one fixed step. Never allocates. After a step that left a
 * non-finite or exploding state, s->failed is set, the failure is in the
 * diagnostics given at create, and further steps do nothing. */
void pfx_sim_step(pfx_sim *s);

/* Steps until the next step would pass simulation time t. */
void pfx_sim_run_to(pfx_sim *s, double t);

/* Back to the state at time 0 (no allocation). */
void pfx_sim_reset(pfx_sim *s);

/* Copies s into view (created from the same effect) and advances the copy
 * from s's time to t (t >= s->time, less than one step later) by a partial
 * step: the state at exact time t, without disturbing the fixed stepping. */
void pfx_sim_view_at(const pfx_sim *s, pfx_sim *view, double t);

/* Runs s up to output frame `frame` (frames must come in increasing order)
 * and returns the state at the frame's exact time: s itself when the frame
 * falls on a step, otherwise `view` advanced by the remainder. */
const pfx_sim *pfx_sim_frame(pfx_sim *s, pfx_sim *view, long frame);

/* The simulation time of output frame f: prewarm + f / fps. */
double pfx_sim_frame_time(const pfx_effect *e, long frame);

/* FNV-1a over every live particle's columns, in pool order: the state hash
 * the determinism test pins. */
uint64_t pfx_sim_hash(const pfx_sim *s);

/* A note per emitter whose full pool dropped births, saying how many; d
 * may be NULL. */
void pfx_sim_note_dropped(const pfx_sim *s, pfx_diags *d);
/* A note of the work done so far when sub-emitters raised events (what
 * jobs/estimate.c bounds beforehand): the particle-steps and the events,
 * summed over the emitters. Nothing for an effect without sub-emitters. */
void pfx_sim_note_work(const pfx_sim *s, pfx_diags *d);

#endif
