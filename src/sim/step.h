/* The passes of one step (sim/step.c), shared by the stepping of live
 * particles (sim.c) and of newborns (newborn.c). Internal to src/sim. */
#ifndef PFX_SIM_STEP_H
#define PFX_SIM_STEP_H

#include "sim/state.h"

/* Exact constant-acceleration motion over dt for every live particle of a
 * gravity-only emitter; returns whether the fused state check saw
 * something (only when p->may_run_away). */
bool pfx_step_gravity(const pfx_emitter *em, pfx_pool *p, float dt);
/* Whether a newborn of a gravity-only emitter at (x, v) under acceleration
 * a, living `life` more seconds, could ever trip the state check. */
bool pfx_step_may_run_away(const float x[3], const float v[3], const double a[3], double life);
/* Emitter i's live particles advanced by its motion plan over `span`. */
void pfx_step_motion(pfx_sim *s, size_t i, double span);
/* The motion kernels' view of particles [first, first + n) of p. */
pfx_motion_pool_f pfx_step_motion_view(const pfx_pool *p, uint32_t first, uint32_t n);
/* The state check of particles [first, count) of emitter i at time t: the
 * first non-finite or runaway one stops the simulation with its emitter,
 * id, time and the likely cause. */
void pfx_step_check_state(pfx_sim *s, size_t i, uint32_t first, double t);
/* Saves the start-of-step state the collision pass sweeps from. */
void pfx_step_save_start(pfx_pool *p);
/* Deflectors for particles [first, first + n) of emitter i over the step of
 * length dt from t0 just integrated (on_hit events queued). */
void pfx_step_collide(pfx_sim *s, size_t i, uint32_t first, uint32_t n, double t0, double dt);
/* Deaths at age >= lifetime at t1 (on_death events queued); the last live
 * particle fills each hole. */
void pfx_step_kill_expired(pfx_sim *s, size_t i, double t1);

#endif
