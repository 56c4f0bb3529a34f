/* The accuracy suite's test problems: each a motion model with a closed-form
 * solution, runnable two ways. The model run steps one particle in double
 * through pfx_motion (the integrator alone); the emitted run writes the
 * problem as an effect, compiles it and lets pfx_sim emit and step the
 * particle in its float pool, born at time 0, off the step grid (by `rate`)
 * or on a step end: the path users take. Both report the position error
 * against the closed form at the particle's own age. */
#ifndef PFX_BENCH_ACCURACY_PROBLEMS_H
#define PFX_BENCH_ACCURACY_PROBLEMS_H

#include <stdbool.h>
#include <stddef.h>

#include "sim/motion.h"

typedef struct pfx_acc_state {
    double x, y, z, u, v, w;
} pfx_acc_state;

typedef struct pfx_acc_problem {
    const char *name;
    double T;         /* the particle's age at the end of a run, s */
    bool closed_form; /* `exact` applies (gravity and linear drag only) */
    bool magnetic;    /* `boris` applies */
    bool bounce;      /* a ground plane y = 0 with resilience 0.7 */
    void (*setup)(pfx_motion *m, pfx_acc_state *s0);
    void (*exact)(double age, pfx_acc_state *out);
    const char *forces_yaml;  /* the `forces:` entries, one per line, indented 2 */
    const char *emitter_yaml; /* position, direction, speed...: lines indented 4 */
} pfx_acc_problem;

extern const pfx_acc_problem pfx_acc_problems[];
extern const size_t pfx_acc_problem_count;

/* When the emitted particle is born. */
typedef enum {
    PFX_BIRTH_AT_ZERO,  /* a burst at t = 0: the first step is a birth step */
    PFX_BIRTH_OFF_GRID, /* by `rate`, at 1/rate = 2.37 steps: a partial step */
    PFX_BIRTH_STEP_END, /* a burst exactly on a step end: no partial step */
    PFX_BIRTH_MODE_COUNT
} pfx_birth_mode;
const char *pfx_birth_mode_name(pfx_birth_mode mode);

typedef struct pfx_acc_result {
    double error;     /* position error at age T, m */
    double max_error; /* the largest position error over every step end, m */
    double max_rate;  /* the largest error(age) / age over every step end, m/s */
    int substeps;     /* substeps per step the prepared model runs */
    int evals;        /* force evaluations per step (all substeps) */
    bool failed;      /* blew up, or (emitted) did not compile or stopped */
} pfx_acc_result;

/* The problem with `integrator` at dt = T / steps, in double. m receives
 * the prepared model (for its cost and stability). */
pfx_acc_result pfx_acc_run_model(const pfx_acc_problem *p, pfx_integrator integrator, long steps,
                                 pfx_motion *m);

/* The same through emission: an effect at sim.rate steps / T compiled and
 * simulated by pfx_sim, the particle born by `mode`, compared at its age
 * at the first step end where it is T old or older. Returns failed when the
 * rate is outside what an effect may ask (below 1 or above 1e5 steps/s). */
pfx_acc_result pfx_acc_run_emitted(const pfx_acc_problem *p, pfx_integrator integrator, long steps,
                                   pfx_birth_mode mode);

/* Whether integrator applies to the problem (exact needs a closed form,
 * boris a magnetic field; the others always do). */
bool pfx_acc_applies(const pfx_acc_problem *p, pfx_integrator integrator);

#endif
