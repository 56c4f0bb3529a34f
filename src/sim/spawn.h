/* Sub-emitter events inside the simulation: a parent particle's birth,
 * death, deflector hit or trail makes particles of a target emitter at the
 * exact place and time. Internal to src/sim (sim.c and spawn.c). */
#ifndef PFX_SPAWN_H
#define PFX_SPAWN_H

#include "sim/appearance.h"
#include "sim/state.h"

/* What a spawned birth takes from its parent. */
typedef struct pfx_parent {
    double pos[3], vel[3], normal[3];
    bool has_normal; /* a hit: `direction: normal` uses the surface normal */
    bool inherit_velocity, inherit_color, inherit_size;
    float color[3], size;
    float generation;
    uint32_t id; /* the parent's id: a ribbon's points are grouped by it */
    /* The event's key: a hash of the parent's emitter, the sub-emitter, the
     * parent's id and the event's number (its hit count, its trail index;
     * 0 for birth and death), all independent of the step. The children's
     * ids and draws come from it and their index in the event. */
    uint64_t key;
} pfx_parent;

/* Ids of sub-emitter children have the top bit set (scheduled births
 * count up from 0 below it); the other 31 bits are a hash of the event's
 * key and the child's index, so the same child has the same id at any
 * sim.rate. Two live children of an emitter share an id with odds of
 * about n^2 / 2^32 for n alive. */
#define PFX_CHILD_ID_BIT 0x80000000u
static inline uint32_t pfx_child_id(uint64_t key, uint32_t child) {
    return PFX_CHILD_ID_BIT | (uint32_t)(pfx_mix64(key + child) >> 33);
}

/* One queued event that fired: what the children take from their parent,
 * when, and how many there are (its count and probability were drawn when
 * it was queued). */
typedef struct spawn_record {
    pfx_parent parent;
    double t;
    uint32_t births;
} spawn_record;

/* A target emitter's events of the step, in the order they were queued.
 * It holds at most as many births as the target's pool: once the births
 * queued since the last pass reach the pool's capacity, the pool will be
 * full before any later event is processed, so later births are only
 * counted (in overflow) and dropped after the queued ones, as a full pool
 * drops them. Its size is thereby bounded by the pool's, whatever the
 * parents' counts. */
typedef struct pfx_spawn_queue {
    spawn_record *items;
    uint32_t count, cap;
    uint64_t queued;   /* births in items, and processed since the step began */
    uint64_t overflow; /* births past the pool's capacity, to drop */
} pfx_spawn_queue;

/* The records target emitter i's queue holds: the events its parents can
 * raise in one step (each parent particle dies, is born, lays its trail
 * births of one step or hits up to PFX_COLLIDE_MAX_HITS deflectors), and
 * never more than the target's pool can take. 0: no sub-emitter feeds it. */
size_t pfx_spawn_queue_capacity(const pfx_effect *e, size_t i);

/* Queues the sub-emitter events of kind `event` of particle j of emitter i,
 * at time t, position pos, velocity vel (and the hit normal, or NULL). */
void pfx_spawn_event_of(pfx_sim *s, size_t i, pfx_spawn_event event, uint32_t j, double t,
                        const double pos[3], const double vel[3], const double normal[3]);

/* What an event takes from its particle at the moment it happens: the two
 * halves of pfx_spawn_event_of, so that a thread can take the particle's
 * part while it owns the particle and the queues (shared) take the events
 * later in a fixed order, with the same result. */
typedef struct pfx_spawn_source {
    double t, pos[3], vel[3], normal[3];
    bool has_normal;
    uint64_t number; /* the event's number (a hit's: the impacts before it) */
    uint32_t id;
    float generation, color[3], size;
} pfx_spawn_source;

/* Reads particle j of emitter i into *src (pure: reads the pool only). */
void pfx_spawn_capture(const pfx_sim *s, size_t i, pfx_spawn_event event, uint32_t j, double t,
                       const double pos[3], const double vel[3], const double normal[3],
                       pfx_spawn_source *src);
/* Queues the events of kind `event` of emitter i that *src describes. */
void pfx_spawn_queue_source(pfx_sim *s, size_t i, pfx_spawn_event event,
                            const pfx_spawn_source *src);

/* Queues the trail births of particles [first, first + n) of emitter i in
 * the step from t0 (or their birth, if later) to t1, whose end state they
 * hold: one per trail time, whatever the step rate. */
void pfx_spawn_trails(pfx_sim *s, size_t i, uint32_t first, uint32_t n, double t0, double t1);

/* Allocates the event queues (at pfx_sim_create); false when out of memory. */
bool pfx_spawn_queues_create(pfx_sim *s);
void pfx_spawn_queues_destroy(pfx_sim *s);

/* Whether emitter em has any sub-emitter of kind `event`. */
bool pfx_spawn_has(const pfx_emitter *em, pfx_spawn_event event);

#endif
