/* The motion model: the forces one emitter feels and the scheme that
 * integrates them. The compiler fills the request part of `pfx_motion`
 * (forces in SI, validated); pfx_motion_prepare resolves it for a step size
 * (auto choice, substeps, aggregates); the simulation then calls
 * pfx_motion_step_f on its float pool. The same arithmetic is instantiated
 * in double (`_d`) for the accuracy harness and the tests. Gravity-only
 * emitters keep the simulation's own exact kernel and never come here. */
#ifndef PFX_MOTION_H
#define PFX_MOTION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define PFX_MOTION_MAX_FORCES 32
/* Particles per block: the stack scratch of one RK4 block is 15 columns of
 * this many reals (15 KB in double), so no step ever allocates. */
#define PFX_MOTION_BLOCK 128
/* Substeps auto may choose at most; beyond this it says so in `why` and
 * `validate` warns that the tolerance is not met. */
#define PFX_MOTION_MAX_SUBSTEPS 1024

/* Zero means default: AUTO. EXACT and BORIS both run the split step
 * (kick, rotate, exact drift, rotate, kick); they differ only in intent. */
typedef enum {
    PFX_INTEGRATOR_AUTO = 0,
    PFX_INTEGRATOR_EULER,      /* explicit: x += v h, v += a(x, v) h */
    PFX_INTEGRATOR_SYMPLECTIC, /* semi-implicit: v first, then x with the new v */
    PFX_INTEGRATOR_MIDPOINT,   /* explicit midpoint (RK2), 2 evaluations */
    PFX_INTEGRATOR_RK4,        /* classical Runge-Kutta, 4 evaluations */
    PFX_INTEGRATOR_VERLET,     /* velocity Verlet, 2 evaluations */
    PFX_INTEGRATOR_EXACT,      /* closed form: constant accel + linear drag */
    PFX_INTEGRATOR_BORIS,      /* split step with the Boris rotation for q v x B */
    PFX_INTEGRATOR_COUNT
} pfx_integrator;

typedef enum {
    PFX_MOTION_GRAVITY,     /* accel, times the particle's gravity_scale */
    PFX_MOTION_ATTRACTOR,   /* strength m^3/s^2 towards center */
    PFX_MOTION_DRAG,        /* linear k (1/s) and/or quadratic c (1/m) vs wind */
    PFX_MOTION_VORTEX,      /* Sims: rotate the position about an axis */
    PFX_MOTION_MAGNETIC,    /* (q/m)(E + v x B) */
    PFX_MOTION_SPIRAL,      /* rotate the velocity about an axis */
    PFX_MOTION_SPRING,      /* -k (x - anchor) - 2 zeta sqrt(k) v */
    PFX_MOTION_TURBULENCE,  /* strength * curl of a noise potential */
    PFX_MOTION_SPEED_LIMIT, /* clamp |v| */
    PFX_MOTION_KIND_COUNT
} pfx_motion_kind;

typedef enum {
    PFX_FALLOFF_INVERSE_SQUARE = 0, /* |a| = s / r^2 */
    PFX_FALLOFF_LINEAR,             /* |a| = s / (L r) */
    PFX_FALLOFF_CONSTANT            /* |a| = s / L^2 */
} pfx_falloff;

typedef enum { PFX_REGION_NONE = 0, PFX_REGION_SPHERE, PFX_REGION_BOX } pfx_region_kind;

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
    double k;           /* drag: linear 1/s; spring: stiffness per mass 1/s^2 */
    double c;           /* drag: quadratic 1/m, a = -c |v - w| (v - w) */
    double wind[3];     /* drag: fluid velocity, m/s */
    double speed_hint;  /* drag: largest speed expected (emission), for stability */
    double zeta;        /* spring: damping ratio */
    bool use_birth;     /* spring: anchor is the birth position (bx, by, bz) */
    double field[3];    /* magnetic B, tesla */
    double electric[3]; /* magnetic E, V/m */
    double charge;      /* coulomb, when the pool has no charge column; with a
                           column, the largest |q| (stability is judged there) */
    double mass;        /* kg, likewise (the smallest mass); 0 means 1 kg */
    double rate;        /* spiral: rad/s about axis */
    double sims_d;      /* vortex: d of f(r) = (r^4 - 2r^2 + 1)/(1 + d r^2) */
    double inflow;      /* vortex: m/s towards the axis, times f(r) */
    double scale;       /* turbulence: feature size, m */
    int octaves;        /* turbulence: >= 1 */
    double speed;       /* turbulence: drift of the pattern, m/s */
    uint64_t seed;      /* turbulence */
    double max_speed;   /* speed_limit, m/s */
} pfx_motion_force;

/* What pfx_motion_prepare resolved: the scheme that runs. */
typedef enum {
    PFX_SCHEME_EULER,
    PFX_SCHEME_SYMPLECTIC,
    PFX_SCHEME_MIDPOINT,
    PFX_SCHEME_RK4,
    PFX_SCHEME_VERLET,
    PFX_SCHEME_SPLIT /* kick h/2, rotate h/2, exact drift h, rotate h/2, kick h/2 */
} pfx_scheme;

typedef struct pfx_motion {
    /* Request, filled by the compiler. */
    pfx_integrator integrator; /* AUTO chooses */
    int substeps;              /* 0: auto chooses (other integrators: 1) */
    double tolerance;          /* auto: position error, m per simulated s; 0: 1e-3 */
    size_t force_count;
    pfx_motion_force forces[PFX_MOTION_MAX_FORCES];

    /* Resolved by pfx_motion_prepare; read-only afterwards. */
    double dt;             /* the step it was prepared for */
    pfx_integrator chosen; /* never AUTO */
    pfx_scheme scheme;
    int steps;             /* substeps per step, >= 1 */
    double error_rate;     /* auto: the expected position error, m per simulated s
                              (0 for other integrators and exact flows) */
    bool has_operators;    /* vortex, spiral or speed_limit present */
    bool has_rotation;     /* split: some magnetic B to rotate by */
    bool has_kick;         /* split: some force left to kick with */
    bool uniform_rotation; /* split: B unregioned, so one Omega unless charge/mass vary */
    double omega[3];       /* its -(q/m) B sum with the forces' constants */
    double drift_k;        /* split drift: sum of unregioned linear drag */
    double drift_wind[3];  /* its k-weighted wind */
    double drift_g[3];     /* split drift: sum of unregioned gravity */
    bool folded[PFX_MOTION_MAX_FORCES]; /* split: handled by the drift, not kicked */
    char why[192];                      /* one line for `pfx info` */
} pfx_motion;

/* A view of one emitter's dense pool. Positions and velocities are updated
 * in place. Optional columns may be NULL: gravity_scale -> 1, charge/mass ->
 * the force's constants, birth (bx, by, bz) is required only by a spring with
 * use_birth. */
#define PFX_MOTION_POOL_FIELDS(T)                                                                  \
    size_t count;                                                                                  \
    T *px, *py, *pz, *vx, *vy, *vz;                                                                \
    const T *gravity_scale, *charge, *mass, *bx, *by, *bz;
typedef struct pfx_motion_pool_f {
    PFX_MOTION_POOL_FIELDS(float)
} pfx_motion_pool_f;
typedef struct pfx_motion_pool_d {
    PFX_MOTION_POOL_FIELDS(double)
} pfx_motion_pool_d;

/* Columns a pool may carry for this model (bits below); the simulation
 * allocates a column only when its bit is set and the value varies. */
enum {
    PFX_COLUMN_GRAVITY_SCALE = 1u << 0,
    PFX_COLUMN_CHARGE = 1u << 1,
    PFX_COLUMN_MASS = 1u << 2,
    PFX_COLUMN_BIRTH = 1u << 3 /* required, not optional, when set */
};
unsigned pfx_motion_columns(const pfx_motion *m);

/* Resolve the request for step dt (> 0): the auto choice, substeps, the
 * drift aggregates and the `why` line. Call again if dt changes. */
void pfx_motion_prepare(pfx_motion *m, double dt);

/* One line saying what runs and why, for `pfx info` (same as m->why). */
const char *pfx_motion_explain(const pfx_motion *m);

/* Advance every particle of the pool from time t by the prepared dt, with
 * m->steps substeps. Never allocates; the pool stays dense and its order is
 * kept. Results depend only on the particle's own state. */
void pfx_motion_step_f(const pfx_motion *m, pfx_motion_pool_f *pool, double t);
void pfx_motion_step_d(const pfx_motion *m, pfx_motion_pool_d *pool, double t);

/* Advance every particle of the pool from time t by `span` seconds (0 <
 * span, normally <= dt) with the prepared scheme and operators, in
 * pfx_motion_substeps_for(m, span) equal substeps: never longer than the
 * prepared substep dt/steps, so a newborn's partial step or a frame's
 * remainder is integrated exactly as a particle started alone at t and
 * stepped at that span would be. pfx_motion_step_* is span = dt. */
void pfx_motion_advance_f(const pfx_motion *m, pfx_motion_pool_f *pool, double t, double span);
void pfx_motion_advance_d(const pfx_motion *m, pfx_motion_pool_d *pool, double t, double span);
/* Substeps of a span: m->steps for the full step, else the fewest whose
 * length is at most dt/steps (at least 1). */
int pfx_motion_substeps_for(const pfx_motion *m, double span);

/* Acceleration of the n particles starting at pool index i0, at state
 * (x, v) given in block arrays, time t, from the ODE forces (all but the
 * operators vortex, spiral, speed_limit). Writes a[0..n). n <= any. */
void pfx_motion_accel_d(const pfx_motion *m, const pfx_motion_pool_d *pool, size_t i0, size_t n,
                        const double *x, const double *y, const double *z, const double *vx,
                        const double *vy, const double *vz, double t, double *ax, double *ay,
                        double *az);

/* Angular frequency of a position force's linearisation (spring sqrt(k),
 * attractor sqrt(s/r^3) at its softening or reference radius, turbulence
 * sqrt(s/scale)); 0 for forces that do not oscillate. */
double pfx_motion_force_omega(const pfx_motion_force *f);
/* Decay rate of a velocity force's linearisation, 1/s: linear k, quadratic
 * 2 c v_ref, spring damping 2 zeta sqrt(k); 0 for the others. */
double pfx_motion_force_damping(const pfx_motion *m, const pfx_motion_force *f);

/* Force evaluations per step (all substeps) the prepared scheme costs. */
int pfx_motion_evals_per_step(const pfx_motion *m);

const char *pfx_integrator_name(pfx_integrator i);
/* Parse a name ("auto", "euler", ...); returns false when unknown. */
bool pfx_integrator_parse(const char *s, pfx_integrator *out);

/* The Sims vortex falloff at normalised radius r: (r^4 - 2r^2 + 1)/(1 + d r^2)
 * for 0 <= r <= 1, else 0. */
double pfx_vortex_falloff(double r, double d);

/* Divergence-free noise: out = curl of a 3-component gradient-noise
 * potential at p (in feature units), evolving with t_shift, `octaves`
 * octaves (each half the amplitude of the last). Magnitude is O(1). */
void pfx_curl_noise(const double p[3], double t_shift, int octaves, uint64_t seed, double out[3]);

/* ---- Stability (stability.c) ---- */

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

/* Check the prepared model against its scheme's stability region at its
 * dt and steps. Writes up to cap warnings and returns how many there are
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
pfx_scheme pfx_integrator_scheme(pfx_integrator i);

/* ---- Non-finite and exploding states ---- */

#define PFX_MOTION_MAX_SPEED 1e6    /* m/s */
#define PFX_MOTION_MAX_POSITION 1e7 /* m */
typedef enum { PFX_BAD_NONE = 0, PFX_BAD_NONFINITE, PFX_BAD_SPEED, PFX_BAD_POSITION } pfx_bad_kind;

/* First index in [0, pool->count) whose state is NaN/Inf, faster than
 * PFX_MOTION_MAX_SPEED or farther than PFX_MOTION_MAX_POSITION; returns
 * pool->count when none is and sets *why. */
size_t pfx_motion_find_bad_f(const pfx_motion_pool_f *pool, pfx_bad_kind *why);
size_t pfx_motion_find_bad_d(const pfx_motion_pool_d *pool, pfx_bad_kind *why);

/* The likely cause of a bad state, for the simulation's error: the first
 * stability warning of m, or a generic line. Writes into buf. */
void pfx_motion_blame(const pfx_motion *m, pfx_bad_kind why, char *buf, size_t size);

#endif
