/* The thread set of workers.h: helpers sleep on a condition variable until
 * a job is posted, then take blocks with the caller from one atomic ticket
 * (the job's number in the high half, the next block in the low half, so a
 * helper that wakes late never takes a block of a later job); the caller
 * returns once every block is done, without waiting for helpers that have
 * not woken. It knows nothing of particles; the simulation decides what a
 * block is.
 *
 * Waking a sleeping thread is slow where the processors are virtual: on
 * the 2-core reference machine (a virtual machine) a helper began its
 * first block 170-320 us after the job was posted on average, and up to
 * 5 ms, against a whole step of 10^6 particles on two threads of about
 * 1 ms; the caller, asleep while a helper finished its last block (some
 * 8 us), paid the same again. So each side first polls for up to
 * PFX_WORKERS_SPIN_NS: a helper for the next job (a simulation posts one
 * a step, after a short serial part), the caller for the blocks still
 * running, and only then sleeps. A busy-wait is bounded by it, so an idle
 * set costs nothing, and one posted less often than that (a render's
 * depth sort, once a frame) wastes at most that much of a core a job.
 * A set of more threads than the machine has cores does not poll: there a
 * polling thread takes the core a working one needs (--threads 6 on the
 * 2 cores: 10-15 % slower with the poll). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "base/workers.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#define PFX_WORKERS_SPIN_NS 50000

struct pfx_workers {
    pthread_mutex_t lock;
    pthread_cond_t posted;   /* helpers wait here for a new generation or stop */
    pthread_cond_t finished; /* the caller waits here for busy == 0 */
    pthread_t *threads;
    int helpers;         /* threads started */
    uint64_t generation; /* jobs posted so far */
    bool stop;
    pfx_block_fn fn; /* the current job */
    void *ctx;
    size_t blocks;
    atomic_uint_fast64_t ticket; /* generation << 32 | the next block to take */
    atomic_size_t done;          /* blocks of the current job finished */
    int64_t poll_ns;             /* PFX_WORKERS_SPIN_NS, or 0 when oversubscribed */
};

/* The ticket's halves: the job it belongs to (the low 32 bits of the
 * generation) and the next block to take. */
static uint_fast64_t ticket_job(uint64_t gen) { return gen & 0xffffffffu; }
static uint_fast64_t ticket_block(uint_fast64_t t) { return t & 0xffffffffu; }

int pfx_workers_cores(void) {
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)(n < 1024 ? n : 1024) : 1;
}

/* Takes blocks of job `gen` until none is left; the thread that finishes
 * the last block wakes the caller. */
static void drain(pfx_workers *w, uint64_t gen, pfx_block_fn fn, void *ctx, size_t blocks) {
    uint_fast64_t t = atomic_load_explicit(&w->ticket, memory_order_acquire);
    for (;;) {
        if (t >> 32 != ticket_job(gen) || ticket_block(t) >= blocks)
            return;
        if (!atomic_compare_exchange_weak_explicit(&w->ticket, &t, t + 1, memory_order_acq_rel,
                                                   memory_order_acquire))
            continue;
        fn(ctx, (size_t)ticket_block(t));
        if (atomic_fetch_add_explicit(&w->done, 1, memory_order_acq_rel) + 1 == blocks) {
            pthread_mutex_lock(&w->lock);
            pthread_cond_signal(&w->finished);
            pthread_mutex_unlock(&w->lock);
        }
        t = atomic_load_explicit(&w->ticket, memory_order_acquire);
    }
}

static int64_t monotonic_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* A hint to the processor that this is a busy-wait (x86 PAUSE, Arm
 * YIELD): it saves power and leaves a sibling hyperthread the core. */
static inline void spin_pause(void) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__) || defined(__arm__)
    __asm__ volatile("yield");
#endif
}

/* Polls until done(w, arg) holds or w->poll_ns have passed (once when it
 * is 0); whether it holds. The clock is read every 64 polls. */
static bool spin_until(const pfx_workers *w, bool (*done)(const pfx_workers *, uint64_t),
                       uint64_t arg) {
    if (w->poll_ns == 0)
        return done(w, arg);
    const int64_t end = monotonic_ns() + w->poll_ns;
    for (unsigned i = 1;; i++) {
        if (done(w, arg))
            return true;
        spin_pause();
        if (i % 64 == 0 && monotonic_ns() > end)
            return false;
    }
}

/* Whether a job after `seen` was posted: the ticket's high half. */
static bool job_posted(const pfx_workers *w, uint64_t seen) {
    const uint_fast64_t t = atomic_load_explicit(&w->ticket, memory_order_acquire);
    return t >> 32 != ticket_job(seen);
}

/* Whether every one of the current job's `blocks` is done. */
static bool blocks_done(const pfx_workers *w, uint64_t blocks) {
    return atomic_load_explicit(&w->done, memory_order_acquire) >= blocks;
}

static void *helper_main(void *arg) {
    pfx_workers *w = arg;
    uint64_t seen = 0;
    pthread_mutex_lock(&w->lock);
    for (;;) {
        if (w->poll_ns > 0 && !w->stop && w->generation == seen) {
            /* The job itself is read under the lock, below. */
            pthread_mutex_unlock(&w->lock);
            spin_until(w, job_posted, seen);
            pthread_mutex_lock(&w->lock);
        }
        while (!w->stop && w->generation == seen)
            pthread_cond_wait(&w->posted, &w->lock);
        if (w->stop)
            break;
        seen = w->generation;
        pfx_block_fn fn = w->fn;
        void *ctx = w->ctx;
        size_t blocks = w->blocks;
        pthread_mutex_unlock(&w->lock);
        drain(w, seen, fn, ctx, blocks);
        pthread_mutex_lock(&w->lock);
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

pfx_workers *pfx_workers_create(int threads) {
    pfx_workers *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    atomic_init(&w->ticket, 0);
    atomic_init(&w->done, 0);
    if (threads <= 1)
        return w;
    w->poll_ns = threads <= pfx_workers_cores() ? PFX_WORKERS_SPIN_NS : 0;
    w->threads = calloc((size_t)threads - 1, sizeof *w->threads);
    if (!w->threads || pthread_mutex_init(&w->lock, NULL) != 0) {
        free(w->threads);
        free(w);
        return NULL;
    }
    pthread_cond_init(&w->posted, NULL);
    pthread_cond_init(&w->finished, NULL);
    for (int i = 0; i < threads - 1; i++) {
        if (pthread_create(&w->threads[i], NULL, helper_main, w) != 0) {
            pfx_workers_destroy(w);
            return NULL;
        }
        w->helpers++;
    }
    return w;
}

void pfx_workers_destroy(pfx_workers *w) {
    if (!w)
        return;
    if (w->threads) {
        pthread_mutex_lock(&w->lock);
        w->stop = true;
        pthread_cond_broadcast(&w->posted);
        pthread_mutex_unlock(&w->lock);
        for (int i = 0; i < w->helpers; i++)
            pthread_join(w->threads[i], NULL);
        pthread_cond_destroy(&w->posted);
        pthread_cond_destroy(&w->finished);
        pthread_mutex_destroy(&w->lock);
        free(w->threads);
    }
    free(w);
}

int pfx_workers_count(const pfx_workers *w) { return w ? w->helpers + 1 : 1; }

void pfx_workers_run(pfx_workers *w, size_t blocks, pfx_block_fn fn, void *ctx) {
    if (!w || w->helpers == 0 || blocks <= 1) {
        for (size_t b = 0; b < blocks; b++)
            fn(ctx, b);
        return;
    }
    pthread_mutex_lock(&w->lock);
    w->fn = fn;
    w->ctx = ctx;
    w->blocks = blocks;
    w->generation++;
    const uint64_t gen = w->generation;
    atomic_store_explicit(&w->done, 0, memory_order_relaxed);
    atomic_store_explicit(&w->ticket, ticket_job(gen) << 32, memory_order_release);
    pthread_cond_broadcast(&w->posted);
    pthread_mutex_unlock(&w->lock);
    drain(w, gen, fn, ctx, blocks);
    if (spin_until(w, blocks_done, blocks))
        return;
    pthread_mutex_lock(&w->lock);
    while (atomic_load_explicit(&w->done, memory_order_acquire) < blocks)
        pthread_cond_wait(&w->finished, &w->lock);
    pthread_mutex_unlock(&w->lock);
}
