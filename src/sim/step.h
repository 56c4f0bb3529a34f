/* The passes of one step (sim/step.c), shared by the stepping of live
 * particles (sim.c) and of newborns (newborn.c). Internal to src/sim. */
#ifndef PFX_SIM_STEP_H
#define PFX_SIM_STEP_H

#include <math.h>

#include "sim/spawn.h"
#include "sim/state.h"

/* What the passes of a step know of a block (pfx_sim.block_flags), set by
 * the move pass: a state that may be bad, a death, a particle a deflector
 * may touch (or a stuck one); the collide pass adds a death to the blocks
 * it visits. */
enum { PFX_BLOCK_BAD = 1, PFX_BLOCK_DEATH = 2, PFX_BLOCK_NEAR = 4 };

/* Emitter i's live particles moved from t0 to t1 (the gravity kernel or
 * the emitter's motion plan), in blocks of pfx_sim.block spread over the
 * simulation's threads, each block saving the start state its deflectors
 * sweep from, checking its own state and marking the particles a deflector
 * may touch (the broad phase, for pfx_step_collide_moved). With
 * scan_deaths each block also notes whether it holds a particle dead at t1
 * (for pfx_step_kill_flagged), so that the serial death pass reads only
 * those blocks; without it every block is noted. Returns the first index
 * of the first block that may hold a non-finite or runaway particle (for
 * pfx_step_check_state to confirm and name), or the count when none. */
uint32_t pfx_step_move(pfx_sim *s, size_t i, double t0, double t1, bool scan_deaths);
/* Whether a newborn of a gravity-only emitter at (x, v) under acceleration
 * a, living `life` more seconds, could ever trip the state check. */
bool pfx_step_may_run_away(const float x[3], const float v[3], const double a[3], double life);
/* Its shortcut: true when the newborn is far inside both bounds, shown
 * without square roots (they were 12 % of a birth's time): the 1-norm
 * bounds the 2-norm, and the factor 2 to the bounds is far more than the
 * rounding of either sum, so pfx_step_may_run_away never answers
 * differently for it. NaN and inf give false. Branch-free (`&`), so a
 * loop of it over a block of newborns vectorises. */
static inline bool pfx_step_far_inside(const float x[3], const float v[3], const double a[3],
                                       double life) {
    const double v1 = fabs((double)v[0]) + fabs((double)v[1]) + fabs((double)v[2]),
                 a1 = fabs(a[0]) + fabs(a[1]) + fabs(a[2]),
                 x1 = fabs((double)x[0]) + fabs((double)x[1]) + fabs((double)x[2]);
    const double speed1 = v1 + a1 * life;
    return (speed1 < 2.85e5) & (x1 + speed1 * life < 0.25 * PFX_MOTION_MAX_POSITION);
}
/* The motion kernels' view of particles [first, first + n) of p. */
pfx_motion_pool_f pfx_step_motion_view(const pfx_pool *p, uint32_t first, uint32_t n);

/* The position and velocity of particle j of emitter i `back` seconds
 * (0 <= back <= the step) before t1, its state in the pool being that at
 * t1: where a death or a trail birth inside the step happened. Under the
 * emitter's gravity alone, the closed form; with a motion plan, the
 * particle stepped on twice by `back` with its own scheme and the
 * quadratic through t1, t1 + b and t1 + 2b extrapolated back to t1 - b
 * (x(t1 - b) = 3 x(t1) - 3 x(t1 + b) + x(t1 + 2b), v likewise): exact to
 * b^3, operators included (a vortex carries x without changing v), so
 * children converge at second order or better (a straight line back along
 * v was first order in velocity, and missed a vortex's carry). */
void pfx_step_state_before(const pfx_sim *s, size_t i, uint32_t j, double t1, double back,
                           double pos[3], double vel[3]);
/* The state check of particles [first, count) of emitter i at time t: the
 * first non-finite or runaway one stops the simulation with its emitter,
 * id, time and the likely cause. */
void pfx_step_check_state(pfx_sim *s, size_t i, uint32_t first, double t);
/* Deflectors for particles [first, first + n) of emitter i over the step of
 * length dt from t0 just integrated (on_hit events queued), counted in
 * *stats. */
void pfx_step_collide(pfx_sim *s, size_t i, uint32_t first, uint32_t n, double t0, double dt,
                      pfx_collide_stats *stats);
/* Deflectors for every particle of emitter i after pfx_step_move(s, i, t0,
 * t1), dt the step's length as a float, from the marks it left: only the
 * blocks it noted near a surface, which are noted as holding a death too
 * (a deflector may kill or shorten a life), so pfx_step_kill_flagged stays
 * exact. Spread over the threads: each particle's result is its own, and
 * on_hit events are held per block (pfx_hit_buffer) and queued in block
 * order, the order of a pass over the pool. */
void pfx_step_collide_moved(pfx_sim *s, size_t i, double t0, double dt);

/* The on_hit events a block of the parallel collide pass holds. A block
 * takes its particles in runs whose events surely fit (each particle hits
 * at most PFX_COLLIDE_MAX_HITS times a step) and stops where the next
 * would not; the serial merge queues what it holds, then runs the block's
 * rest from `resume` with its events queued at once: the same events in
 * the same order, whatever the threads, with a fixed buffer. */
#define PFX_BLOCK_HIT_EVENTS 512
typedef struct pfx_hit_buffer {
    uint32_t count;  /* events held */
    uint32_t resume; /* the first particle (from the block's start) left to the merge */
    pfx_spawn_source items[PFX_BLOCK_HIT_EVENTS];
} pfx_hit_buffer;
/* Deaths at age >= lifetime at t1 (on_death events queued); the last live
 * particle fills each hole. */
void pfx_step_kill_expired(pfx_sim *s, size_t i, double t1);
/* pfx_step_kill_expired over the blocks the last pfx_step_move noted, with
 * the same result: valid while no lifetime changed since that pass outside
 * the blocks pfx_step_collide_moved noted. */
void pfx_step_kill_flagged(pfx_sim *s, size_t i, double t1);

#endif
