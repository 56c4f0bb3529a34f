/* Motion in the simulation: the plan a model's motion resolves to for the
 * pool (which forces the split step folds into its exact drift, the drift
 * and rotation aggregates), and the kernels that advance a pool by it. The
 * same arithmetic is instantiated in float (`_f`, the pools) and double
 * (`_d`, the accuracy harness and the tests) from motion_impl.h. Private to
 * src/sim: compile and render never see a plan. Gravity-only emitters keep
 * the simulation's own exact kernel and never come here. */
#ifndef PFX_SIM_MOTION_H
#define PFX_SIM_MOTION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "model/motion.h"

/* Particles per block: the stack scratch of one RK4 block is 15 columns of
 * this many reals (15 KB in double), so no step ever allocates. */
#define PFX_MOTION_BLOCK 128

/* What the kernels run: the model's forces and choice, and the aggregates
 * of the split step. The field names are those the kernels read. */
typedef struct pfx_motion_plan {
    const pfx_motion_force *forces; /* the model's; not owned */
    size_t force_count;
    double dt;             /* the step it was chosen for */
    pfx_integrator chosen; /* never AUTO */
    pfx_scheme scheme;
    int steps;             /* substeps per step, >= 1 (per particle: the most any takes) */
    bool has_operators;    /* vortex, spiral or speed_limit present */
    bool has_rotation;     /* split: some magnetic B to rotate by */
    bool has_kick;         /* split: some force left to kick with */
    bool kick_carries;     /* split: the kicks read positions only (not v, not t) and no
                              operator moves a position, so a substep's closing kick's
                              acceleration is the next one's opening kick's */
    bool kick_reads_v;     /* split: a kicked force reads v (drag, or damping, not folded), so
                              each half kick is a midpoint stage (motion_impl.h) */
    bool carry_accel;      /* kick_carries across steps too: the pool keeps the closing
                              kick's acceleration (ax, ay, az) for the next step's opening
                              one, where a force costs more than that column's traffic */
    bool uniform_rotation; /* split: B unregioned, so one Omega unless charge/mass vary */
    /* Forces: unregioned gravities, then one unregioned drag (operators
     * aside), the sky of most effects: the general schemes then run each
     * particle's whole step in registers (motion_impl.h, FN(gd_accel)). */
    bool gravity_drag;
    size_t gd_drag;                     /* that drag's index in forces */
    double omega[3];                    /* its -(q/m) B sum with the forces' constants */
    double drift_k;                     /* split drift: sum of unregioned linear drag */
    double drift_wind[3];               /* its k-weighted wind */
    double drift_g[3];                  /* split drift: sum of unregioned gravity */
    bool folded[PFX_MOTION_MAX_FORCES]; /* split: handled by the drift, not kicked */
    /* Substeps per particle (the model's choice.radius), for a full step
     * of dt: level k < radius_top runs 2^k substeps where a particle's
     * nearest reach to the attractor is at least radius_r[k], the top
     * level all `steps`; radius_top = 0: off. */
    int radius_top;
    double radius_r[11];
    double radius_peak[11]; /* the attractor's largest pull outside radius_r[k] */
    bool radius_radial;     /* the reach counts the approach speed alone (no spiral turns v) */
    const pfx_motion *model;
} pfx_motion_plan;

/* The plan of model m for its choice (pfx_motion_choose must have run). The
 * plan points into m, which must outlive it. */
void pfx_motion_plan_init(pfx_motion_plan *p, const pfx_motion *m);
/* pfx_motion_choose(m, dt) then pfx_motion_plan_init: for the tests and
 * the accuracy harness, which build their own models. */
void pfx_motion_plan_prepare(pfx_motion_plan *p, pfx_motion *m, double dt);
/* Whether m's plan carries accelerations across steps (carry_accel): the
 * pool then keeps the ax, ay, az column (sim/columns.h). */
bool pfx_motion_carries_accel(const pfx_motion *m);

/* A view of one emitter's dense pool. Positions and velocities are updated
 * in place. Optional columns may be NULL: gravity_scale -> 1, charge/mass ->
 * the force's constants, birth (bx, by, bz) is required only by a spring with
 * use_birth, birth_time and lifetime only by force_over_life. */
#define PFX_MOTION_POOL_FIELDS(T)                                                                  \
    size_t count;                                                                                  \
    T *px, *py, *pz, *vx, *vy, *vz;                                                                \
    const T *gravity_scale, *charge, *mass, *bx, *by, *bz;                                         \
    const double *birth_time;                                                                      \
    const T *lifetime;                                                                             \
    T *ax, *ay, *az;
typedef struct pfx_motion_pool_f {
    PFX_MOTION_POOL_FIELDS(float)
} pfx_motion_pool_f;
typedef struct pfx_motion_pool_d {
    PFX_MOTION_POOL_FIELDS(double)
} pfx_motion_pool_d;

/* Advance every particle of the pool from time t by the plan's dt, with
 * its steps substeps. Never allocates; the pool stays dense and its order
 * is kept. Results depend only on the particle's own state. */
void pfx_motion_step_f(const pfx_motion_plan *m, pfx_motion_pool_f *pool, double t);
void pfx_motion_step_d(const pfx_motion_plan *m, pfx_motion_pool_d *pool, double t);

/* Advance every particle of the pool from time t by `span` seconds (0 <
 * span, normally <= dt) with the plan's scheme and operators, in
 * pfx_motion_substeps_over(steps, dt, span) equal substeps: never longer than the
 * planned substep dt/steps, so a newborn's partial step or a frame's
 * remainder is integrated exactly as a particle started alone at t and
 * stepped at that span would be. Under the rule per particle (radius_top >
 * 0) and a span up to dt, each particle takes instead its level's count for
 * the span (ceil(2^k span / dt), 2^k for a full step).
 * pfx_motion_step_* is span = dt. */
void pfx_motion_advance_f(const pfx_motion_plan *m, pfx_motion_pool_f *pool, double t, double span);
void pfx_motion_advance_d(const pfx_motion_plan *m, pfx_motion_pool_d *pool, double t, double span);

/* The simulation's step from t0 to t1 (span t1 - t0): as advance, with the
 * last kick evaluated at t1 itself, the next step's t0, and with the plan's
 * carry_accel the pool's ax, ay, az read (where no particle of a block has
 * NaN there) for the first kick and written by the last. Returns whether a
 * particle may have ended in a bad state: the quick, conservative test of
 * pfx_motion_find_bad, run on each block of PFX_MOTION_BLOCK as it is
 * done; pfx_motion_find_bad says which. */
bool pfx_motion_move_f(const pfx_motion_plan *m, pfx_motion_pool_f *pool, double t0, double t1);
bool pfx_motion_move_d(const pfx_motion_plan *m, pfx_motion_pool_d *pool, double t0, double t1);

/* Divergence-free noise at n points (x, y, z)[j] in metres: (ox, oy,
 * oz)[j] = the curl of a three-component value-noise potential of
 * `octaves` octaves (each half the amplitude of the last) at position
 * times inv (1 / scale: feature units), the pattern shifted by t_shift
 * feature units along each octave's drift. Each component's RMS is about
 * 1. Float arithmetic; the result of a point depends on that point only. */
void pfx_curl_noise_f(size_t n, const float *x, const float *y, const float *z, float inv,
                      double t_shift, int octaves, uint64_t seed, float *ox, float *oy, float *oz);

/* ---- Non-finite and exploding states ---- */

#define PFX_MOTION_MAX_SPEED 1e6    /* m/s */
#define PFX_MOTION_MAX_POSITION 1e7 /* m */
typedef enum { PFX_BAD_NONE = 0, PFX_BAD_NONFINITE, PFX_BAD_SPEED, PFX_BAD_POSITION } pfx_bad_kind;

/* The quick test of a bad state, branch-free so that loops of it
 * vectorise: 1 when the position (x, y, z) or velocity (u, v, w), of type
 * T, is non-finite, has a velocity component above the speed limit /
 * sqrt(3) or a coordinate above the position limit. Every bad state trips
 * it; pfx_motion_find_bad then looks at the particles one by one. ABS:
 * fabsf or fabs. */
#define PFX_MOTION_MAY_BE_BAD(T, ABS, x, y, z, u, v, w)                                            \
    (!(ABS(u) <= (T)(PFX_MOTION_MAX_SPEED * 0.57)) |                                               \
     !(ABS(v) <= (T)(PFX_MOTION_MAX_SPEED * 0.57)) |                                               \
     !(ABS(w) <= (T)(PFX_MOTION_MAX_SPEED * 0.57)) | !(ABS(x) <= (T)PFX_MOTION_MAX_POSITION) |     \
     !(ABS(y) <= (T)PFX_MOTION_MAX_POSITION) | !(ABS(z) <= (T)PFX_MOTION_MAX_POSITION))

/* First index in [0, pool->count) whose state is NaN/Inf, faster than
 * PFX_MOTION_MAX_SPEED or farther than PFX_MOTION_MAX_POSITION; returns
 * pool->count when none is and sets *why. */
size_t pfx_motion_find_bad_f(const pfx_motion_pool_f *pool, pfx_bad_kind *why);
size_t pfx_motion_find_bad_d(const pfx_motion_pool_d *pool, pfx_bad_kind *why);

/* The likely cause of a bad state, for the simulation's error: the first
 * stability warning of m, or a generic line. Writes into buf. */
void pfx_motion_blame(const pfx_motion *m, pfx_bad_kind why, char *buf, size_t size);

#endif
