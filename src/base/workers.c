/* The thread set of workers.h: helpers sleep on a condition variable until
 * a job is posted, then take blocks with the caller. Each thread of the set
 * has its own share of a job's blocks, the same run of them for every job
 * of that many blocks, and takes from it first, then from the others' (a
 * thread that wakes late leaves its share to the rest): a simulation posts
 * the same pool's blocks step after step, so each thread finds its share
 * in its own caches. (With one shared ticket the blocks went to whichever
 * thread came first, and 10^4 particles, 400 KB, moved between the two
 * cores' caches every step: on the 2-core reference machine 2 threads
 * took 2.7-2.8 us a step of gravity where one took 2.3; with shares,
 * 1.7-1.8.) A share's ticket holds the job's number in the high half
 * and its next block in the low half, so a helper that wakes late never
 * takes a block of a later job; the caller returns once every block is
 * done, without waiting for helpers that have not woken. It knows nothing
 * of particles; the simulation decides what a block is.
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

/* A thread's share of the current job: generation << 32 | the next block
 * to take of it; a cache line of its own, since it is written at every
 * block taken. */
typedef struct share {
    _Alignas(64) atomic_uint_fast64_t ticket;
} share;

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
    share *shares;           /* one per thread, the caller's first */
    struct helper_arg *args; /* each helper's set and share number */
    atomic_size_t done;      /* blocks of the current job finished, each thread's added
                                when it runs out */
    int64_t poll_ns;         /* PFX_WORKERS_SPIN_NS, or 0 when oversubscribed */
};

/* A helper's own argument: the set and its share's number. */
typedef struct helper_arg {
    pfx_workers *w;
    int index;
} helper_arg;

/* The ticket's halves: the job it belongs to (the low 32 bits of the
 * generation) and the next block to take. */
static uint_fast64_t ticket_job(uint64_t gen) { return gen & 0xffffffffu; }
static uint_fast64_t ticket_block(uint_fast64_t t) { return t & 0xffffffffu; }

int pfx_workers_cores(void) {
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)(n < 1024 ? n : 1024) : 1;
}

/* Threads in the set: the caller and its helpers. */
static int members(const pfx_workers *w) { return w->helpers + 1; }

/* The first block of share k of a job of `blocks` blocks (k == members:
 * the end of the last share). */
static size_t share_start(const pfx_workers *w, size_t blocks, int k) {
    return blocks * (size_t)k / (size_t)members(w);
}

/* Takes blocks of job `gen` until none is left, from share `me` first,
 * then from the others in turn, and counts them done once at the end (a
 * count shared by every thread, written at every block, was a cache line
 * passed between the cores at every block); the thread whose count
 * completes the job wakes the caller. */
static void drain(pfx_workers *w, uint64_t gen, pfx_block_fn fn, void *ctx, size_t blocks, int me) {
    const int n = members(w);
    size_t ran = 0;
    for (int step = 0; step < n; step++) {
        const int k = (me + step) % n;
        atomic_uint_fast64_t *ticket = &w->shares[k].ticket;
        const size_t end = share_start(w, blocks, k + 1);
        uint_fast64_t t = atomic_load_explicit(ticket, memory_order_acquire);
        for (;;) {
            if (t >> 32 != ticket_job(gen) || ticket_block(t) >= end)
                break;
            if (!atomic_compare_exchange_weak_explicit(ticket, &t, t + 1, memory_order_acq_rel,
                                                       memory_order_acquire))
                continue;
            fn(ctx, (size_t)ticket_block(t));
            ran++;
            t = atomic_load_explicit(ticket, memory_order_acquire);
        }
    }
    if (ran && atomic_fetch_add_explicit(&w->done, ran, memory_order_acq_rel) + ran == blocks) {
        pthread_mutex_lock(&w->lock);
        pthread_cond_signal(&w->finished);
        pthread_mutex_unlock(&w->lock);
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

/* Whether a job after `seen` was posted: the high half of the caller's
 * share's ticket. */
static bool job_posted(const pfx_workers *w, uint64_t seen) {
    const uint_fast64_t t = atomic_load_explicit(&w->shares[0].ticket, memory_order_acquire);
    return t >> 32 != ticket_job(seen);
}

/* Whether every one of the current job's `blocks` is done. */
static bool blocks_done(const pfx_workers *w, uint64_t blocks) {
    return atomic_load_explicit(&w->done, memory_order_acquire) >= blocks;
}

static void *helper_main(void *arg) {
    pfx_workers *w = ((helper_arg *)arg)->w;
    const int me = ((helper_arg *)arg)->index;
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
        drain(w, seen, fn, ctx, blocks, me);
        pthread_mutex_lock(&w->lock);
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

pfx_workers *pfx_workers_create(int threads) {
    pfx_workers *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    atomic_init(&w->done, 0);
    if (threads <= 1)
        return w;
    w->poll_ns = threads <= pfx_workers_cores() ? PFX_WORKERS_SPIN_NS : 0;
    w->threads = calloc((size_t)threads - 1, sizeof *w->threads);
    w->args = calloc((size_t)threads - 1, sizeof *w->args);
    w->shares = aligned_alloc(_Alignof(share), (size_t)threads * sizeof *w->shares);
    if (!w->threads || !w->args || !w->shares || pthread_mutex_init(&w->lock, NULL) != 0) {
        free(w->threads);
        free(w->args);
        free(w->shares);
        free(w);
        return NULL;
    }
    for (int k = 0; k < threads; k++)
        atomic_init(&w->shares[k].ticket, 0);
    pthread_cond_init(&w->posted, NULL);
    pthread_cond_init(&w->finished, NULL);
    for (int i = 0; i < threads - 1; i++) {
        w->args[i] = (helper_arg){w, i + 1};
        if (pthread_create(&w->threads[i], NULL, helper_main, &w->args[i]) != 0) {
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
        free(w->args);
        free(w->shares);
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
    for (int k = members(w) - 1; k >= 0; k--) /* the caller's last: job_posted reads it */
        atomic_store_explicit(&w->shares[k].ticket,
                              ticket_job(gen) << 32 | share_start(w, blocks, k),
                              memory_order_release);
    pthread_cond_broadcast(&w->posted);
    pthread_mutex_unlock(&w->lock);
    drain(w, gen, fn, ctx, blocks, 0);
    if (spin_until(w, blocks_done, blocks))
        return;
    pthread_mutex_lock(&w->lock);
    while (atomic_load_explicit(&w->done, memory_order_acquire) < blocks)
        pthread_cond_wait(&w->finished, &w->lock);
    pthread_mutex_unlock(&w->lock);
}
