/* A fixed set of threads that share out the blocks of one job at a time:
 * the caller runs blocks too, and returns when every block is done. Which
 * thread runs which block is not fixed, so a job must make each block's
 * result depend on the block alone (and write only the block's own
 * memory); then the result is the same for any thread count. pthreads. */
#ifndef PFX_BASE_WORKERS_H
#define PFX_BASE_WORKERS_H

#include <stddef.h>

typedef struct pfx_workers pfx_workers;

/* The processors this process may run on (at least 1). */
int pfx_workers_cores(void);

/* A set of `threads` threads in all, the caller's included (threads - 1
 * are started; threads <= 1 starts none). Returns NULL when out of memory
 * or when a thread cannot start. Free with pfx_workers_destroy. */
pfx_workers *pfx_workers_create(int threads);
/* Stops and joins the threads; w may be NULL. */
void pfx_workers_destroy(pfx_workers *w);
/* Threads in the set, the caller's included; 1 for NULL. */
int pfx_workers_count(const pfx_workers *w);

/* Runs fn(ctx, b) for every b in [0, blocks) (blocks < 2^32), each once, spread over the
 * set's threads, and returns when all have returned. w may be NULL (all on
 * the caller's thread). Never allocates. Not reentrant: one job at a time
 * per set. */
typedef void (*pfx_block_fn)(void *ctx, size_t block);
void pfx_workers_run(pfx_workers *w, size_t blocks, pfx_block_fn fn, void *ctx);

#endif
