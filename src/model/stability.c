/* Where each scheme fails, from its stability function: one step of the
 * scheme on the test system x'' = -omega^2 x - c x' is a 2x2 matrix; the
 * scheme is stable when that matrix's spectral radius is <= 1. The checks
 * below apply it to each force's linearisation and say which fix works.
 * It does not simulate anything (the tests and the bench measure). */
#include "model/motion.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* One step with h = 1 of `scheme` on (x, y) with y = h v, so that
 * f(x, y) = (y, -w2 x - b y) with w2 = (omega h)^2, b = c h. */
static void one_step(pfx_scheme s, double w2, double b, double *x, double *y) {
    double x0 = *x, y0 = *y;
#define ACC(X, Y) (-w2 * (X)-b * (Y))
    switch (s) {
    case PFX_SCHEME_EULER:
        *x = x0 + y0;
        *y = y0 + ACC(x0, y0);
        break;
    case PFX_SCHEME_SYMPLECTIC:
        *y = y0 + ACC(x0, y0);
        *x = x0 + *y;
        break;
    case PFX_SCHEME_MIDPOINT: {
        double xm = x0 + 0.5 * y0, ym = y0 + 0.5 * ACC(x0, y0);
        *x = x0 + ym;
        *y = y0 + ACC(xm, ym);
        break;
    }
    case PFX_SCHEME_VERLET: {
        double a0 = ACC(x0, y0), yh = y0 + 0.5 * a0, x1 = x0 + yh, yp = yh + 0.5 * a0;
        *x = x1;
        *y = yh + 0.5 * ACC(x1, yp);
        break;
    }
    case PFX_SCHEME_RK4: {
        double k1x = y0, k1y = ACC(x0, y0);
        double k2x = y0 + 0.5 * k1y, k2y = ACC(x0 + 0.5 * k1x, y0 + 0.5 * k1y);
        double k3x = y0 + 0.5 * k2y, k3y = ACC(x0 + 0.5 * k2x, y0 + 0.5 * k2y);
        double k4x = y0 + k3y, k4y = ACC(x0 + k3x, y0 + k3y);
        *x = x0 + (k1x + 2 * k2x + 2 * k3x + k4x) / 6;
        *y = y0 + (k1y + 2 * k2y + 2 * k3y + k4y) / 6;
        break;
    }
    case PFX_SCHEME_SPLIT: {
        /* kick by the spring, exact damped drift, kick */
        double yh = y0 - 0.5 * w2 * x0;
        double e = exp(-b), E1 = b > 0 ? -expm1(-b) / b : 1;
        double x1 = x0 + yh * E1;
        *x = x1;
        *y = yh * e - 0.5 * w2 * x1;
        break;
    }
    }
#undef ACC
}

/* Spectral radius of the step matrix; a double eigenvalue of modulus 1
 * (a Jordan block: growth linear in the step count) counts as 1 + 1e-6. */
double pfx_stability_radius(pfx_scheme s, double w2, double b) {
    double a = 1, c = 0, bb = 0, d = 1;
    one_step(s, w2, b, &a, &c);  /* first column: (a, c) */
    one_step(s, w2, b, &bb, &d); /* second column: (bb, d) */
    double tr = a + d, det = a * d - bb * c, disc = tr * tr - 4 * det;
    double rho;
    if (disc >= 0) {
        double sq = sqrt(disc), l1 = fabs(0.5 * (tr + sq)), l2 = fabs(0.5 * (tr - sq));
        rho = l1 > l2 ? l1 : l2;
        if (w2 > 0 && fabs(disc) <= 1e-12 * (1 + tr * tr) && rho >= 1 - 1e-12)
            rho = 1 + 1e-6;
    } else {
        rho = sqrt(det);
    }
    return rho;
}

double pfx_stability_rotation_gain(pfx_scheme s, double th) {
    double t2 = th * th, re, im;
    switch (s) {
    case PFX_SCHEME_EULER:
    case PFX_SCHEME_SYMPLECTIC: /* on v' = Omega x v both are 1 + i theta */
        return sqrt(1 + t2);
    case PFX_SCHEME_MIDPOINT:
    case PFX_SCHEME_VERLET: /* 1 + i theta - theta^2/2 */
        return sqrt(1 + t2 * t2 / 4);
    case PFX_SCHEME_RK4:
        re = 1 - t2 / 2 + t2 * t2 / 24;
        im = th - th * t2 / 6;
        return sqrt(re * re + im * im);
    default:
        return 1; /* the Boris rotation */
    }
}

double pfx_stability_decay_limit(pfx_scheme s) {
    switch (s) {
    case PFX_SCHEME_RK4:
        return 2.785293563405282; /* real root of 1 - z + z^2/2 - z^3/6 + z^4/24 = 1 */
    case PFX_SCHEME_SPLIT:
        return INFINITY; /* e^{-z} */
    default:
        return 2; /* |1 - z| (Euler, symplectic), |1 - z + z^2/2| (midpoint, Verlet) */
    }
}

double pfx_stability_oscillator_limit(pfx_scheme s) {
    switch (s) {
    case PFX_SCHEME_SYMPLECTIC:
    case PFX_SCHEME_VERLET:
    case PFX_SCHEME_SPLIT:
        return 2; /* trace 2 - w^2 reaches -2 */
    case PFX_SCHEME_RK4:
        return 2 * sqrt(2.0); /* |R(i w)|^2 = 1 - w^6/72 + w^8/576 */
    default:
        return 0; /* Euler: |1 + i w| > 1; midpoint: |R|^2 = 1 + w^4/4 */
    }
}

static bool unstable(pfx_scheme s, double w2, double b) {
    return pfx_stability_radius(s, w2, b) > 1 + 1e-9;
}

/* Substeps of dt (more than now) that make rate omega/c stable, or 0. */
static int fix_steps(pfx_scheme s, double omega, double c, double dt, int steps) {
    /* omega*h exactly on the limit is marginal (|lambda| = 1 but no margin,
     * and a float step a hair longer crosses it): require strictly inside. */
    double limit = pfx_stability_oscillator_limit(s);
    for (int n = steps + 1; n <= 4096; n = n < 16 ? n + 1 : n + n / 8) {
        double h = dt / n;
        if (!unstable(s, omega * omega * h * h, c * h) &&
            (omega == 0 || limit == 0 || omega * h < limit * (1 - 1e-9)))
            return n;
    }
    return 0;
}

static const char *force_word(const pfx_motion_force *f) {
    return pfx_kind_name(pfx_force_words, (int)f->kind);
}

/* A number and the limit it crossed, each with the fewest significant
 * digits (at least 3) that tell them apart: "2.786 > 2.785", never
 * "2.79 > 2.79". */
typedef struct number_pair {
    char x[32], limit[32];
} number_pair;

static number_pair pair_text(double x, double limit) {
    number_pair p;
    for (int digits = 3; digits <= 17; digits++) {
        snprintf(p.x, sizeof p.x, "%.*g", digits, x);
        snprintf(p.limit, sizeof p.limit, "%.*g", digits, limit);
        if (strcmp(p.x, p.limit) != 0)
            break;
    }
    return p;
}

static void add(pfx_stability_warning *out, size_t cap, size_t *count,
                const pfx_stability_warning *w) {
    if (*count < cap)
        out[*count] = *w;
    (*count)++;
}

/* "use sim.substeps: N" when more steps of the same scheme fix it, else
 * the other integrator (and the substeps it needs, if any). */
static void fix_text(const pfx_stability_warning *w, pfx_integrator chosen, char *buf,
                     size_t size) {
    if (w->fix == chosen && w->fix_substeps > 0)
        snprintf(buf, size, "use sim.substeps: %d", w->fix_substeps);
    else if (w->fix_substeps > 0)
        snprintf(buf, size, "use integrator '%s' with sim.substeps: %d",
                 pfx_integrator_name(w->fix), w->fix_substeps);
    else
        snprintf(buf, size, "use integrator '%s'", pfx_integrator_name(w->fix));
}

/* What every check reads: the scheme, its substep h and the integrator's name. */
typedef struct checker {
    const pfx_motion *m;
    pfx_scheme s;
    int steps;
    double h;
    const char *iname;
} checker;

/* The linearised rates of force f as the scheme sees them: omega (0 for
 * turbulence, not an oscillator) and the damping c (less the drag that the
 * split scheme integrates exactly). */
static void force_rates(const checker *k, const pfx_motion_force *f, double *omega, double *c) {
    *omega = pfx_motion_force_omega(f);
    *c = pfx_motion_force_damping(k->m, f);
    if (f->kind == PFX_MOTION_TURBULENCE)
        *omega = 0; /* not an oscillator: its gradient rate is used for accuracy only */
    if (f->kind == PFX_MOTION_DRAG && k->s == PFX_SCHEME_SPLIT && pfx_motion_force_folded(f))
        *c -= f->k; /* integrated exactly */
}

/* A magnetic force: the scheme's drift of |v| per gyration, when it has one. */
static bool magnetic_warning(const checker *k, const pfx_motion_force *f, const char *name,
                             pfx_stability_warning *w) {
    double qm = fabs(f->charge) / (f->mass > 0 ? f->mass : 1.0);
    double B =
        sqrt(f->field[0] * f->field[0] + f->field[1] * f->field[1] + f->field[2] * f->field[2]);
    double th = qm * B * k->h;
    if (k->s == PFX_SCHEME_SPLIT || !(th > 0))
        return false;
    double gain = pfx_stability_rotation_gain(k->s, th);
    w->kind = PFX_STABILITY_DRIFT;
    w->number = pow(gain, 6.283185307179586 / th) - 1;
    w->limit = 0;
    w->fix = PFX_INTEGRATOR_BORIS;
    w->fix_substeps = 0;
    snprintf(w->message, sizeof w->message,
             "%s does not keep |v| in %s '%s': %+.3g%% per gyration at Omega*dt = %.3g; "
             "use integrator 'boris'",
             k->iname, force_word(f), name, 100 * w->number, th);
    return true;
}

/* An oscillator of rate omega (damped by c) outside the stability region. */
static bool oscillator_warning(const checker *k, const pfx_motion_force *f, const char *name,
                               double omega, double c, pfx_stability_warning *w) {
    const pfx_motion *m = k->m;
    if (!unstable(k->s, omega * omega * k->h * k->h, c * k->h))
        return false;
    w->kind = PFX_STABILITY_UNSTABLE;
    w->number = omega * k->h;
    w->limit = pfx_stability_oscillator_limit(k->s);
    w->fix = m->choice.chosen;
    /* Euler and midpoint grow on an oscillator at any step: only another
     * scheme fixes it, however many substeps. */
    w->fix_substeps = w->limit > 0 ? fix_steps(k->s, omega, c, m->choice.dt, k->steps) : 0;
    if (w->fix_substeps == 0) {
        w->fix = PFX_INTEGRATOR_VERLET;
        w->fix_substeps = fix_steps(PFX_SCHEME_VERLET, omega, c, m->choice.dt, 0);
        if (w->fix_substeps == 1)
            w->fix_substeps = 0;
    }
    char fix[96];
    fix_text(w, m->choice.chosen, fix, sizeof fix);
    number_pair np = pair_text(w->number, w->limit);
    if (w->limit > 0)
        snprintf(w->message, sizeof w->message,
                 "%s is unstable on %s '%s': omega*dt = %s >= %s (energy grows every step); %s",
                 k->iname, force_word(f), name, np.x, np.limit, fix);
    else
        snprintf(w->message, sizeof w->message,
                 "%s is unstable on %s '%s' at any step (omega*dt = %.3g: energy grows every "
                 "step); %s",
                 k->iname, force_word(f), name, w->number, fix);
    return true;
}

/* A pure damping c: unstable past the decay limit, or (Euler, symplectic)
 * flipping the velocity's sign every step past k*dt = 1. */
static bool damping_warning(const checker *k, const pfx_motion_force *f, const char *name, double c,
                            pfx_stability_warning *w) {
    const pfx_motion *m = k->m;
    double z = c * k->h;
    bool unst = unstable(k->s, 0, z);
    bool flips = (k->s == PFX_SCHEME_EULER || k->s == PFX_SCHEME_SYMPLECTIC) && z > 1;
    if (!unst && !flips)
        return false;
    bool linear = f->kind == PFX_MOTION_DRAG && f->c == 0 && f->region.kind == PFX_REGION_NONE;
    w->kind = unst ? PFX_STABILITY_UNSTABLE : PFX_STABILITY_OSCILLATES;
    w->number = z;
    w->limit = unst ? pfx_stability_decay_limit(k->s) : 1;
    w->fix = linear ? PFX_INTEGRATOR_EXACT : PFX_INTEGRATOR_RK4;
    /* substeps with the same scheme, or (linear drag) the exact flow */
    w->fix_substeps = unst ? fix_steps(k->s, 0, c, m->choice.dt, k->steps)
                           : (int)ceil(z * k->steps * (1 - 1e-12));
    if (!linear)
        w->fix = m->choice.chosen;
    char fix[96];
    fix_text(w, m->choice.chosen, fix, sizeof fix);
    if (linear && w->fix_substeps > 0) /* the closed form needs no substeps */
        snprintf(fix, sizeof fix, "use integrator 'exact' or sim.substeps: %d", w->fix_substeps);
    else if (linear)
        snprintf(fix, sizeof fix, "use integrator 'exact'");
    number_pair np = pair_text(z, w->limit);
    snprintf(w->message, sizeof w->message,
             unst ? "%s is unstable on %s '%s': k*dt = %s > %s (the velocity grows "
                    "every step); %s"
                  : "%s makes %s '%s' oscillate: k*dt = %s > %s (the velocity flips "
                    "sign every step); %s",
             k->iname, force_word(f), name, np.x, np.limit, fix);
    return true;
}

/* The check of force i alone, by what it is: a rotation, an oscillator or a
 * pure damping. */
static bool force_warning(const checker *k, size_t i, double omega, double c,
                          pfx_stability_warning *w) {
    const pfx_motion_force *f = &k->m->forces[i];
    const char *name = f->name ? f->name : force_word(f);
    *w = (pfx_stability_warning){.force = (int)i};
    if (f->kind == PFX_MOTION_MAGNETIC)
        return magnetic_warning(k, f, name, w);
    if (omega > 0)
        return oscillator_warning(k, f, name, omega, c, w);
    if (c > 0)
        return damping_warning(k, f, name, c, w);
    return false;
}

/* Forces that are each stable can still be unstable together: the summed
 * rates sum_w2 = sum omega^2 and sum_c. */
static bool combined_warning(const checker *k, double sum_w2, double sum_c,
                             pfx_stability_warning *w) {
    const pfx_motion *m = k->m;
    if (!unstable(k->s, sum_w2 * k->h * k->h, sum_c * k->h))
        return false;
    *w = (pfx_stability_warning){.force = -1, .kind = PFX_STABILITY_UNSTABLE};
    w->number = sqrt(sum_w2) * k->h;
    w->limit = pfx_stability_oscillator_limit(k->s);
    w->fix = m->choice.chosen;
    w->fix_substeps = fix_steps(k->s, sqrt(sum_w2), sum_c, m->choice.dt, k->steps);
    char fix[96];
    fix_text(w, m->choice.chosen, fix, sizeof fix);
    snprintf(w->message, sizeof w->message,
             "%s is unstable on the forces together: omega*dt = %.3g, k*dt = %.3g; %s", k->iname,
             w->number, sum_c * k->h, fix);
    return true;
}

size_t pfx_motion_check_stability(const pfx_motion *m, pfx_stability_warning *out, size_t cap) {
    const int steps = m->choice.steps > 0 ? m->choice.steps : 1;
    const checker k = {.m = m,
                       .s = m->choice.scheme,
                       .steps = steps,
                       .h = m->choice.dt / steps,
                       .iname = pfx_integrator_name(m->choice.chosen)};
    size_t count = 0;
    double sum_w2 = 0, sum_c = 0;
    int stiff = 0;
    bool flagged = false;
    for (size_t i = 0; i < m->force_count; i++) {
        double omega, c;
        force_rates(&k, &m->forces[i], &omega, &c);
        if (omega > 0 || c > 0)
            stiff++;
        sum_w2 += omega * omega;
        sum_c += c;
        pfx_stability_warning w;
        if (force_warning(&k, i, omega, c, &w)) {
            add(out, cap, &count, &w);
            flagged = flagged || w.kind == PFX_STABILITY_UNSTABLE;
        }
    }
    pfx_stability_warning w;
    if (stiff > 1 && !flagged && combined_warning(&k, sum_w2, sum_c, &w))
        add(out, cap, &count, &w);
    return count;
}
