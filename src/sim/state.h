/* The simulation's state: the particle pools, each emitter's streams and
 * schedule, and the simulation that holds them. Plain data; sim.c drives
 * it, the passes (step.c, newborn.c, spawn.c) work on it. */
#ifndef PFX_SIM_STATE_H
#define PFX_SIM_STATE_H

#include <stdbool.h>
#include <stdint.h>

#include "base/diag.h"
#include "base/rng.h"
#include "model/effect.h"
#include "sim/collide.h"
#include "sim/columns.h"
#include "sim/motion.h"
#include "sim/schedule.h"

/* Live particles of one emitter, dense: indices [0, count), one array per
 * column of sim/columns.h. Columns the emitter does not keep are NULL
 * (gravity_scale when constant, size0/size1 when the size is constant...),
 * so an emitter pays only for its attributes and forces: 40 bytes per
 * particle for the fixed columns (birth time 8, position, velocity,
 * lifetime, id) plus each optional column. */
typedef struct pfx_pool {
    uint32_t count, capacity;
    uint32_t newborn;  /* first index born in the step being taken */
    double time;       /* the time the state is at: a particle's age is time - birth */
    bool may_run_away; /* gravity-only: some particle's bound at birth reaches the
                          state check's limits, so the kernel checks each step */
    /* The least birth + lifetime of those born (INFINITY while none was):
     * no particle dies of age before it, where nothing shortens a life
     * (pfx_emitter_state.lives_fixed). It lets the move pass skip its scan
     * for deaths (pfx_step_move). */
    double death_floor;
#define PFX_POOL_FIELD(name, type, role, needed, what) type *name;
    PFX_POOL_COLUMNS(PFX_POOL_FIELD)
#undef PFX_POOL_FIELD
} pfx_pool;

typedef struct pfx_emitter_state {
    pfx_rng rng;              /* the particles' attributes */
    pfx_rng rng_base;         /* rng at time 0: a looping effect restarts it every period */
    uint64_t rng_period;      /* the schedule period rng was last restarted for */
    pfx_schedule sched;       /* when they are born */
    uint64_t born;            /* births so far (each drawn, alive or not) */
    uint64_t scheduled;       /* scheduled births so far: the next one's id */
    uint64_t dropped;         /* births lost to a full pool */
    uint64_t draws_per_birth; /* generator outputs one birth takes (fixed) */
    uint64_t hit_key;         /* salt of random resilience and friction (collide.h key) */
    uint64_t spawn_key;       /* salt of its particles' sub-emitter events (spawn.c) */
    bool lives_fixed;         /* a life ends only at birth + lifetime: no kill rule, no deflector
                                 that kills or takes life (so pfx_pool.death_floor holds) */
    pfx_collide_stats collisions;
    float rest_dt; /* the step the resting flags were made with (pfx_collide_pool.rest) */
    /* The work done, for comparing with jobs/estimate.c's bound: particles
     * stepped (each counted once per substep of its integrator), and the
     * sub-emitter events raised into this emitter (each a count and a
     * chance drawn, whether or not it fires or its pool can take it). */
    uint64_t particle_steps;
    uint64_t spawn_events;
} pfx_emitter_state;

/* Particles per block of the threaded passes (pfx_sim.block): a power of
 * two between these, a multiple of the motion kernels' PFX_MOTION_BLOCK
 * and of the resting chunks (256). 8192 particles of gravity are about
 * 30 us of work, well above the cost of waking a thread; a pool too small
 * for 4 blocks a thread at that size takes smaller ones (pfx_sim_block),
 * so that two threads share 10^4 particles at all. No result depends on
 * where the blocks fall: each particle's step is its own, and the events
 * and deaths a block holds are taken in pool order. */
#define PFX_SIM_BLOCK_MAX 8192u
#define PFX_SIM_BLOCK_MIN 1024u

typedef struct pfx_birth_batch pfx_birth_batch;

typedef struct pfx_sim {
    const pfx_effect *effect;
    double dt;
    uint64_t step; /* steps taken; the simulation time is step * dt */
    double time;   /* time of the state (after a partial step on a snapshot) */
    pfx_pool *pools;
    pfx_emitter_state *emitters;
    void *storage; /* one allocation behind every pool */
    size_t bytes;
    struct pfx_spawn_queue *queues; /* per emitter: sub-emitter events of the step */
    pfx_motion_plan *plans;         /* per emitter with a motion model: what its kernels run */
    struct pfx_sim *loop_start;     /* a looping effect's state at frame 0, to wrap to */
    struct pfx_workers *workers;    /* the threads the passes use (owned; NULL: one) */
    uint32_t block;                 /* particles a block (pfx_sim_block) */
    uint8_t *block_flags;           /* per block of the largest pool: sim/step.h's flags */
    pfx_collide_stats *block_stats; /* per block: a parallel collide pass's counters */
    struct pfx_birth_block *births; /* the columns of a block of births (sim/birth.h) */
    struct pfx_birth_batch *batch;  /* scheduled births on the threads (sim/newborn.c) */
    bool failed;                    /* a state went non-finite or exploded: stop */
    pfx_diags *diags;               /* where a failure says what, where, when and the likely
                                       cause (not owned; may be NULL) */
    /* per block: its on_hit events (sim/step.h); NULL where no emitter has on_hit */
    struct pfx_hit_buffer *hit_buffers;
} pfx_sim;

/* Particle i's age at the pool's time, seconds. */
static inline double pfx_particle_age(const pfx_pool *p, uint32_t i) {
    return p->time - p->birth[i];
}

#endif
