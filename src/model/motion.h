/* The motion model of an emitter, as the compiled effect holds it: the
 * forces it feels (SI units, radians) and the integrator it asked for, plus
 * the choice that request resolves to for a step (pfx_motion_choose: the
 * `auto` rule, substeps, the expected error) and the stability analysis of
 * that choice. Pure data and functions: compile fills and checks it, `pfx
 * info` explains it, the simulation builds its private plan from it
 * (sim/motion.h). */
#ifndef PFX_MODEL_MOTION_H
#define PFX_MODEL_MOTION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "model/kinds.h"

#define PFX_MOTION_MAX_FORCES 32
/* Substeps auto may choose at most; beyond this it says so in `why` and
 * `validate` warns that the tolerance is not met. */
#define PFX_MOTION_MAX_SUBSTEPS 1024

/* Zero means default: AUTO. EXACT and BORIS both run the split step
 * (kick, rotate, exact drift, rotate, kick); they differ only in intent. */
typedef enum {
#define PFX_INTEGRATOR_ENUM(e, name, order, use) PFX_INTEGRATOR_##e,
    PFX_INTEGRATOR_KINDS(PFX_INTEGRATOR_ENUM)
#undef PFX_INTEGRATOR_ENUM
        PFX_INTEGRATOR_COUNT
} pfx_integrator;

/* The forces (model/kinds.h): gravity (accel times gravity_scale),
 * attractor (strength m^3/s^2 towards center), drag (linear k 1/s and/or
 * quadratic c 1/m against a wind), vortex (Sims: turns positions about an
 * axis), magnetic ((q/m)(E + v x B)), spiral (turns velocities about an
 * axis), spring (-k (x - anchor) - 2 zeta sqrt(k) v), turbulence (strength
 * times the curl of a noise potential), speed_limit (clamps |v|),
 * force_over_life (an acceleration that is a function of the particle's
 * normalised age, Unity's "Force over Lifetime"). */
typedef enum {
#define PFX_FORCE_ENUM(e, name, word, doc) PFX_MOTION_##e,
    PFX_FORCE_KINDS(PFX_FORCE_ENUM)
#undef PFX_FORCE_ENUM
        PFX_MOTION_KIND_COUNT
} pfx_motion_kind;

/* Attractor falloffs: |a| = s / r^2, s / (L r), s / L^2. */
typedef enum {
#define PFX_FALLOFF_ENUM(e, name) PFX_FALLOFF_##e,
    PFX_FALLOFF_KINDS(PFX_FALLOFF_ENUM)
#undef PFX_FALLOFF_ENUM
} pfx_falloff;

/* The frame a force's vectors are given in (force_over_life). */
typedef enum {
#define PFX_FORCE_SPACE_ENUM(e, name) PFX_SPACE_##e,
    PFX_FORCE_SPACES(PFX_FORCE_SPACE_ENUM)
#undef PFX_FORCE_SPACE_ENUM
} pfx_force_space;

/* An acceleration over normalised age u = age / lifetime: keys (at[i],
 * accel[i]) with at increasing in [0, 1], linear between keys and held
 * before the first and after the last. One key is a constant. */
#define PFX_LIFE_CURVE_MAX_KEYS 64
typedef struct pfx_life_curve {
    size_t count;
    double at[PFX_LIFE_CURVE_MAX_KEYS];
    double accel[PFX_LIFE_CURVE_MAX_KEYS][3];
} pfx_life_curve;

/* The acceleration at normalised age u: the curve's linear interpolation,
 * held outside [at[0], at[count-1]]. Inline: the kernel calls it per
 * particle. */
static inline void pfx_life_curve_at(const pfx_life_curve *c, double u, double out[3]) {
    size_t i = 0;
    while (i + 2 < c->count && c->at[i + 1] <= u)
        i++;
    if (c->count == 1 || u <= c->at[0]) {
        out[0] = c->accel[0][0], out[1] = c->accel[0][1], out[2] = c->accel[0][2];
        return;
    }
    size_t j = i + 1;
    if (u >= c->at[j]) {
        out[0] = c->accel[j][0], out[1] = c->accel[j][1], out[2] = c->accel[j][2];
        return;
    }
    double s = (u - c->at[i]) / (c->at[j] - c->at[i]);
    for (int a = 0; a < 3; a++)
        out[a] = c->accel[i][a] + (c->accel[j][a] - c->accel[i][a]) * s;
}

struct pfx_emitter;

/* Zero: no region (everywhere); then the kinds of model/kinds.h. */
typedef enum {
    PFX_REGION_NONE = 0,
#define PFX_REGION_ENUM(e, name) PFX_REGION_##e,
    PFX_REGION_KINDS(PFX_REGION_ENUM)
#undef PFX_REGION_ENUM
} pfx_region_kind;

/* Where a force acts: full strength inside the shape, falling linearly to
 * zero over `falloff` metres outside it (0: a hard edge). */
typedef struct pfx_motion_region {
    pfx_region_kind kind;
    double center[3];
    double radius;  /* sphere */
    double half[3]; /* box: half edge lengths, axis-aligned */
    double falloff; /* metres */
} pfx_motion_region;

/* One force, flat (no union) so the compiler fills only what its kind reads;
 * every other field stays zero. Units are SI; angles are radians. */
typedef struct pfx_motion_force {
    pfx_motion_kind kind;
    const char *name; /* for messages; not owned */
    pfx_motion_region region;
    double accel[3];   /* gravity, m/s^2 */
    double center[3];  /* attractor centre; vortex/spiral axis point; spring anchor */
    double axis[3];    /* vortex/spiral: unit axis direction */
    double strength;   /* attractor m^3/s^2 (< 0 repels); vortex rad/s at the
                          axis; turbulence m/s^2 */
    double softening;  /* attractor: Plummer radius, m */
    double radius;     /* attractor cut-off (0: none); vortex radius (> 0) */
    double ref_radius; /* attractor: L of the linear/constant falloffs and the
                          radius where stability is judged (0: 1 m) */
    pfx_falloff falloff;
    double k;                   /* drag: linear 1/s; spring: stiffness per mass 1/s^2 */
    double c;                   /* drag: quadratic 1/m, a = -c |v - w| (v - w) */
    double wind[3];             /* drag: fluid velocity, m/s */
    double speed_hint;          /* the fastest emission speed, m/s (drag and magnetic judge
                                   stability and accuracy by it) */
    double zeta;                /* spring: damping ratio */
    bool use_birth;             /* spring: anchor is the birth position (bx, by, bz) */
    double field[3];            /* magnetic B, tesla */
    double electric[3];         /* magnetic E, V/m */
    double charge;              /* coulomb, when the pool has no charge column; with a
                                   column, the largest |q| (stability is judged there) */
    double mass;                /* kg, likewise (the smallest mass); 0 means 1 kg */
    double rate;                /* spiral: rad/s about axis */
    double sims_d;              /* vortex: d of f(r) = (r^4 - 2r^2 + 1)/(1 + d r^2) */
    double inflow;              /* vortex: m/s towards the axis, times f(r) */
    double scale;               /* turbulence: feature size, m */
    int octaves;                /* turbulence: >= 1 */
    double speed;               /* turbulence: drift of the pattern, m/s */
    uint64_t seed;              /* turbulence */
    double max_speed;           /* speed_limit, m/s */
    const pfx_life_curve *life; /* force_over_life: m/s^2 over normalised age, in
                             world axes unless `frame` is set */
    pfx_force_space space;      /* force_over_life: as written */
    /* force_over_life in the space of an emitter whose rotation is
     * keyframed: its vectors turn with the emitter's rotation at the time
     * of the step (a fixed rotation is applied when the model is built). */
    const struct pfx_emitter *frame;
    double jerk_hint; /* force_over_life: the steepest |da/dt|, m/s^3, at the
                         shortest lifetime (auto judges accuracy by it) */
} pfx_motion_force;

/* The scheme a choice runs. */
typedef enum {
    PFX_SCHEME_EULER,
    PFX_SCHEME_SYMPLECTIC,
    PFX_SCHEME_MIDPOINT,
    PFX_SCHEME_RK4,
    PFX_SCHEME_VERLET,
    PFX_SCHEME_SPLIT /* kick h/2, rotate h/2, exact drift h, rotate h/2, kick h/2 */
} pfx_scheme;

/* What a request resolves to for a step dt (pfx_motion_choose). */
typedef struct pfx_motion_choice {
    double dt;             /* the step it was chosen for */
    pfx_integrator chosen; /* never AUTO */
    pfx_scheme scheme;
    int steps;         /* substeps per step, >= 1 */
    double error_rate; /* auto: the expected position error, m per simulated s
                          (0 for other integrators and exact flows) */
    char why[256];     /* one line for `pfx info` */
    /* auto, where one attractor sets the substeps with nothing beside it
     * but gravity and operators on v: the same rule at each particle's own
     * distance r from it, so particles far from it take fewer substeps
     * (sim/motion_impl.h): never more than `steps` with a softening, more
     * inside reference_radius without one. Beyond r0 (the softening) the
     * attractor's omega and error term fall as (r0 / r)^(omega_pow2 / 2)
     * and (r0 / r)^(err_pow2 / 2). */
    struct {
        bool on;
        double r0, omega0, err0, tol; /* the rule's terms at r0, and its tolerance */
        int omega_pow2, err_pow2;
        double center[3];
        double peak;    /* the attractor's largest acceleration, m/s^2 */
        double gravity; /* the sum of |g| over the gravities, m/s^2 */
        /* An unsoftened attractor (singular): r0 is reference_radius, the
         * power laws hold at every r, particles inside r0 take more than
         * `steps` (up to max_steps), and the pull outside r is
         * peak_coef / r^(omega_pow2 - 1), unbounded at the centre. */
        bool singular;
        double peak_coef;
        int max_steps; /* the most substeps a particle takes: steps, or more if singular */
    } radius;
} pfx_motion_choice;

/* An emitter's motion: the request the compiler fills, and its choice for
 * the effect's step, filled by pfx_motion_choose. */
typedef struct pfx_motion {
    pfx_integrator integrator; /* AUTO chooses */
    int substeps;              /* 0: auto chooses (other integrators: 1) */
    double tolerance;          /* auto: position error, m per simulated s; 0: 1e-3 */
    size_t force_count;
    pfx_motion_force forces[PFX_MOTION_MAX_FORCES];
    pfx_motion_choice choice;
} pfx_motion;

/* Resolves the request for step dt (> 0) into m->choice: the auto choice,
 * the substeps and the `why` line. Call again if dt changes. */
void pfx_motion_choose(pfx_motion *m, double dt);

/* Columns a pool may carry for this model (bits below); the simulation
 * allocates a column only when its bit is set and the value varies. */
enum {
    PFX_COLUMN_GRAVITY_SCALE = 1u << 0,
    PFX_COLUMN_CHARGE = 1u << 1,
    PFX_COLUMN_MASS = 1u << 2,
    PFX_COLUMN_BIRTH = 1u << 3 /* required, not optional, when set */
};
unsigned pfx_motion_columns(const pfx_motion *m);

/* Whether span is the full step dt (up to the last bits of t1 - t0). */
bool pfx_motion_full_step(double dt, double span);
/* Substeps of a span for `steps` a step: `steps` for the full step, else
 * the fewest whose length is at most dt/steps (at least 1). */
int pfx_motion_substeps_over(int steps, double dt, double span);

/* Whether the split step integrates force f exactly in its drift (an
 * unregioned gravity, linear drag or spring damping) instead of kicking. */
bool pfx_motion_force_folded(const pfx_motion_force *f);
/* Whether the split step kicks: some force is left after folding. */
bool pfx_motion_split_kicks(const pfx_motion *m);
/* Whether a force the split step kicks reads v (quadratic drag, drag or
 * damping in a region): its half kicks are then midpoint stages. */
bool pfx_motion_split_kicks_v(const pfx_motion *m);

/* Angular frequency of a position force's linearisation (spring sqrt(k),
 * attractor sqrt(s/r^3) at its softening or reference radius, turbulence
 * sqrt(s/scale)); 0 for forces that do not oscillate. */
double pfx_motion_force_omega(const pfx_motion_force *f);
/* Decay rate of a velocity force's linearisation, 1/s: linear k, quadratic
 * 2 c v_ref, spring damping 2 zeta sqrt(k); 0 for the others. */
double pfx_motion_force_damping(const pfx_motion *m, const pfx_motion_force *f);

/* Force evaluations per step (all substeps) the chosen scheme costs. */
int pfx_motion_evals_per_step(const pfx_motion *m);

const char *pfx_integrator_name(pfx_integrator i);
/* Parse a name ("auto", "euler", ...); returns false when unknown. */
bool pfx_integrator_parse(const char *s, pfx_integrator *out);
pfx_scheme pfx_integrator_scheme(pfx_integrator i);

/* The Sims vortex falloff at normalised radius r: (r^4 - 2r^2 + 1)/(1 + d r^2)
 * for 0 <= r <= 1, else 0. Inline: the vortex kernel calls it per particle. */
static inline double pfx_vortex_falloff(double r, double d) {
    if (!(r >= 0 && r <= 1))
        return 0;
    double r2 = r * r;
    return (r2 * r2 - 2 * r2 + 1) / (1 + d * r2);
}

/* The velocity with which the operators that move positions directly (the
 * Sims vortex: strength f(r) w about its axis, inflow f(r) w towards it,
 * w the region weight) carry a particle at p, m/s, into out. The velocity
 * column does not hold it; what is drawn from motion (align: velocity,
 * stretch) adds it. Zero where no such operator acts. */
void pfx_motion_drift(const pfx_motion *m, const double p[3], double out[3]);

/* ---- Stability (model/stability.c) ---- */

typedef enum {
    PFX_STABILITY_UNSTABLE,   /* amplitude grows every step */
    PFX_STABILITY_OSCILLATES, /* stable but the decay flips sign every step */
    PFX_STABILITY_DRIFT       /* |v| is not kept under the magnetic rotation */
} pfx_stability_kind;

typedef struct pfx_stability_warning {
    int force; /* index into m->forces; -1: the forces together */
    pfx_stability_kind kind;
    double number;      /* the dimensionless k*h or omega*h that breaks it (h =
                           dt/steps); DRIFT: relative |v| change per gyration */
    double limit;       /* where the scheme's stability region ends (0: nowhere) */
    pfx_integrator fix; /* an integrator that fixes it */
    int fix_substeps;   /* substeps that fix it with the same scheme (0: none do) */
    char message[256];  /* lowercase, no full stop, numbers included */
} pfx_stability_warning;

/* Checks the chosen scheme against its stability region at its dt and
 * steps. Writes up to cap warnings and returns how many there are
 * (possibly more than cap). */
size_t pfx_motion_check_stability(const pfx_motion *m, pfx_stability_warning *out, size_t cap);

/* Spectral radius of one step of `scheme` on x'' = -w2 x - b x' in units of
 * the step (w2 = (omega h)^2, b = c h); > 1 means growth. For the magnetic
 * rotation use pfx_stability_rotation_gain. */
double pfx_stability_radius(pfx_scheme scheme, double w2, double b);
/* |v| gain of one step of `scheme` on v' = Omega x v, theta = Omega h. */
double pfx_stability_rotation_gain(pfx_scheme scheme, double theta);
/* Theoretical limits: largest stable k*h on decay and omega*h on an
 * undamped oscillator (0: none; INFINITY: unconditionally stable). */
double pfx_stability_decay_limit(pfx_scheme scheme);
double pfx_stability_oscillator_limit(pfx_scheme scheme);

#endif
