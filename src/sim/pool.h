/* Pool storage, expanded from the column list (sim/columns.h): how many
 * bytes an emitter's particles take, where each column lies, and the
 * column-wise operations the simulation needs. Internal to src/sim. */
#ifndef PFX_SIM_POOL_H
#define PFX_SIM_POOL_H

#include "sim/state.h"

/* Bytes one particle of em takes: the columns it keeps, state and scratch. */
size_t pfx_pool_bytes_per_particle(const pfx_emitter *em);
/* Of those, the step's own scratch (the SCRATCH columns). */
size_t pfx_pool_scratch_bytes_per_particle(const pfx_emitter *em);
/* Bytes of a pool of n particles, a multiple of 8. */
size_t pfx_pool_bytes(const pfx_emitter *em, uint32_t n);
/* Points p's columns into block (8-byte aligned, pfx_pool_bytes long) for
 * n particles; columns em does not keep are NULL. Empties the pool: no
 * particle, at time 0, nothing that may run away, no death ahead. */
void pfx_pool_layout(pfx_pool *p, const pfx_emitter *em, void *block, uint32_t n);
/* Particle `from`'s state and carried columns copied over particle `to`
 * (swap-remove). */
void pfx_pool_move(pfx_pool *p, uint32_t to, uint32_t from);
/* src's live particles, state and carried columns, into dst (same
 * emitter). */
void pfx_pool_copy(pfx_pool *dst, const pfx_pool *src);
/* A view of p from index `from` on: the same columns, shifted. */
pfx_pool pfx_pool_from(const pfx_pool *p, uint32_t from);
/* h folded with every state column of the live particles, then the count. */
uint64_t pfx_pool_hash(const pfx_pool *p, uint64_t h);

#endif
