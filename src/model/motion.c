/* Resolving a motion request: which scheme runs (the `auto` rule and its
 * error model), how many substeps, and one line saying why; the forces'
 * linearised rates that the rule and the stability analysis
 * (model/stability.c) read. Pure functions of the model; the arithmetic of
 * a step is the simulation's (sim/motion_impl.h). */
#include "model/motion.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const char *pfx_integrator_name(pfx_integrator i) {
    return pfx_kind_name(pfx_integrator_names, (int)i);
}

bool pfx_integrator_parse(const char *s, pfx_integrator *out) {
    int i = pfx_kind_find(pfx_integrator_names, s);
    if (i >= 0)
        *out = (pfx_integrator)i;
    return i >= 0;
}

pfx_scheme pfx_integrator_scheme(pfx_integrator i) {
    switch (i) {
    case PFX_INTEGRATOR_EULER:
        return PFX_SCHEME_EULER;
    case PFX_INTEGRATOR_SYMPLECTIC:
        return PFX_SCHEME_SYMPLECTIC;
    case PFX_INTEGRATOR_MIDPOINT:
        return PFX_SCHEME_MIDPOINT;
    case PFX_INTEGRATOR_RK4:
        return PFX_SCHEME_RK4;
    case PFX_INTEGRATOR_VERLET:
        return PFX_SCHEME_VERLET;
    default:
        return PFX_SCHEME_SPLIT;
    }
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

unsigned pfx_motion_columns(const pfx_motion *m) {
    unsigned c = 0;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        if (f->kind == PFX_MOTION_GRAVITY)
            c |= PFX_COLUMN_GRAVITY_SCALE;
        if (f->kind == PFX_MOTION_MAGNETIC)
            c |= PFX_COLUMN_CHARGE | PFX_COLUMN_MASS;
        if (f->kind == PFX_MOTION_SPRING && f->use_birth)
            c |= PFX_COLUMN_BIRTH;
    }
    return c;
}

/* ---- Representative rates, shared with stability.c ---- */

/* Sum of the gravities, for the terminal speed of quadratic drag. */
static double gravity_magnitude(const pfx_motion *m) {
    double g[3] = {0, 0, 0};
    for (size_t i = 0; i < m->force_count; i++)
        if (m->forces[i].kind == PFX_MOTION_GRAVITY)
            for (int a = 0; a < 3; a++)
                g[a] += m->forces[i].accel[a];
    return norm3(g);
}

/* Angular frequency of a position force's linearisation (0: none): a spring
 * sqrt(k); an attractor sqrt(|s| / r^3) at its softening radius (where the
 * tidal rate peaks), else at ref_radius, else 1 m; turbulence sqrt(|s| /
 * scale), its acceleration gradient. Repulsion has no frequency. */
double pfx_motion_force_omega(const pfx_motion_force *f) {
    switch (f->kind) {
    case PFX_MOTION_SPRING:
        return f->k > 0 ? sqrt(f->k) : 0;
    case PFX_MOTION_ATTRACTOR: {
        if (f->strength <= 0)
            return 0;
        double r = f->softening > 0 ? f->softening : f->ref_radius > 0 ? f->ref_radius : 1.0;
        if (f->falloff == PFX_FALLOFF_INVERSE_SQUARE)
            return sqrt(f->strength / (r * r * r));
        double L = f->ref_radius > 0 ? f->ref_radius : 1.0;
        return f->falloff == PFX_FALLOFF_LINEAR ? sqrt(f->strength / (L * r * r))
                                                : sqrt(f->strength / (L * L * r));
    }
    case PFX_MOTION_TURBULENCE:
        return f->scale > 0 ? sqrt(fabs(f->strength) / f->scale) : 0;
    default:
        return 0;
    }
}

/* Decay rate of a velocity force's linearisation (0: none): linear drag k;
 * quadratic drag 2 c v_ref, v_ref the larger of the expected speed relative
 * to the wind and the terminal speed sqrt(g/c); spring damping 2 zeta omega. */
double pfx_motion_force_damping(const pfx_motion *m, const pfx_motion_force *f) {
    if (f->kind == PFX_MOTION_SPRING)
        return f->k > 0 ? 2 * f->zeta * sqrt(f->k) : 0;
    if (f->kind != PFX_MOTION_DRAG)
        return 0;
    double kq = 0;
    if (f->c > 0) {
        double v = f->speed_hint + norm3(f->wind), vt = sqrt(gravity_magnitude(m) / f->c);
        kq = 2 * f->c * (v > vt ? v : vt);
    }
    return f->k + kq;
}

/* ---- The error model of `auto` ----
 * Every scheme auto runs is second order, so its position error grows at a
 * rate C L w^3 h^2 (m per simulated second) for an oscillation of
 * frequency w and size L, and C u k^2 h^2 for a velocity force of rate k
 * acting on speeds u that it does not integrate exactly. The constants are
 * measured on the accuracy suite (pfx bench accuracy, the largest
 * error(t)/t over each run) and multiplied by a safety factor of 1.5:
 *   spring (leapfrog on x'' = -w^2 x)       C = 1/24  -> 1/16
 *   magnetic rotation, L the gyroradius      C = 1/24  -> 1/16
 *   attractor, w and L at its reference      C = 0.64  -> 1  (Kepler e = 0.5;
 *                                                     a circular orbit: 0.34)
 *   linear velocity forces (drag, damping)   C = 0.39  -> 0.6
 *   quadratic drag, Verlet                   C = 0.008 -> 0.012
 *   quadratic drag, split step (midpoint     C = 0.040 -> 0.06
 *     half kicks)
 * (quadratic drag measured from rest, k = 2 c v_t, u = v_t; the linear
 * constant applied to it, as before, over-worked it some 14 times).
 * Turbulence has no closed form to measure; it takes the spring's.
 * force_over_life: kick-drift-kick keeps v exact for an acceleration
 * linear in time and leaves h^3 j / 6 in x per step (j = |da/dt|), a rate
 * of j h^2 / 6 that velocity does not compound:  C = 1/6 -> 1/4. */
#define AUTO_C_SPRING (1.0 / 16)
#define AUTO_C_ROTATION (1.0 / 16)
#define AUTO_C_ATTRACTOR 1.0
#define AUTO_C_VELOCITY 0.6
#define AUTO_C_QUADRATIC_VERLET 0.012
#define AUTO_C_QUADRATIC_SPLIT 0.06
#define AUTO_C_JERK 0.25

/* Length over which an oscillation's phase error turns into position error:
 * the attractor's radius, the turbulence scale, 1 m for a spring. */
static double force_length(const pfx_motion_force *f) {
    if (f->kind == PFX_MOTION_ATTRACTOR)
        return f->softening > 0 ? f->softening : f->ref_radius > 0 ? f->ref_radius : 1.0;
    if (f->kind == PFX_MOTION_TURBULENCE)
        return f->scale;
    return 1.0;
}

/* C L w^3 of a position force (0 for the others). */
static double oscillation_error(const pfx_motion_force *f) {
    double w = pfx_motion_force_omega(f);
    double c = f->kind == PFX_MOTION_ATTRACTOR ? AUTO_C_ATTRACTOR : AUTO_C_SPRING;
    return w > 0 ? c * force_length(f) * w * w * w : 0;
}

/* C L W^3 of a magnetic field's rotation: W = |q/m| |B|, L the gyroradius
 * of the fastest emitted particle plus the E x B drift, u / W. */
static double rotation_error(const pfx_motion_force *f) {
    double W = fabs(f->charge) / (f->mass > 0 ? f->mass : 1.0) * norm3(f->field);
    if (!(W > 0))
        return 0;
    double u = f->speed_hint + norm3(f->electric) / norm3(f->field);
    return AUTO_C_ROTATION * (u / W) * W * W * W;
}

/* The speeds a velocity force acts on: the emission speed relative to the
 * wind, or the terminal speed under the gravities, whichever is larger. */
static double velocity_scale(const pfx_motion *m, const pfx_motion_force *f) {
    double g = gravity_magnitude(m), u = f->speed_hint + norm3(f->wind);
    double terminal = f->c > 0 ? sqrt(g / f->c) : f->k > 0 ? g / f->k : 0;
    if (f->kind == PFX_MOTION_SPRING)
        u = f->speed_hint + sqrt(f->k); /* a unit displacement's speed */
    return u > terminal ? u : terminal;
}

/* ---- Resolving ---- */

bool pfx_motion_force_folded(const pfx_motion_force *f) {
    if (f->region.kind != PFX_REGION_NONE)
        return false;
    return f->kind == PFX_MOTION_GRAVITY || (f->kind == PFX_MOTION_DRAG && f->k > 0) ||
           (f->kind == PFX_MOTION_SPRING && f->zeta > 0);
}

bool pfx_motion_split_kicks(const pfx_motion *m) {
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        switch (f->kind) {
        case PFX_MOTION_GRAVITY:
            if (!pfx_motion_force_folded(f))
                return true;
            break;
        case PFX_MOTION_DRAG:
            if (!pfx_motion_force_folded(f) || f->c > 0)
                return true;
            break;
        case PFX_MOTION_MAGNETIC:
            if (norm3(f->electric) > 0)
                return true;
            break;
        case PFX_MOTION_SPRING:
        case PFX_MOTION_ATTRACTOR:
        case PFX_MOTION_TURBULENCE:
        case PFX_MOTION_FORCE_OVER_LIFE:
            return true;
        default:
            break;
        }
    }
    return false;
}

bool pfx_motion_split_kicks_v(const pfx_motion *m) {
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        const bool folded = pfx_motion_force_folded(f);
        if ((f->kind == PFX_MOTION_DRAG && (f->c > 0 || !folded)) ||
            (f->kind == PFX_MOTION_SPRING && f->zeta > 0 && !folded))
            return true;
    }
    return false;
}

static int ceil_steps(double dt, double h) {
    if (!(h > 0) || !(dt / h < PFX_MOTION_MAX_SUBSTEPS))
        return h > 0 && dt / h < 1 ? 1 : PFX_MOTION_MAX_SUBSTEPS;
    int n = (int)ceil(dt / h * (1 - 1e-12));
    return n < 1 ? 1 : n;
}

/* What choose_auto learns from the forces: which kinds of force there are,
 * the summed rates (w2 = sum omega^2, kv = sum of the explicit decay
 * rates), the error coefficient err (error rate = err h^2), and the
 * largest step h allowed so far with what set it. */
typedef struct auto_survey {
    bool velocity, rotation, position;
    double w2, kv, h, err;
    const char *stiff;
} auto_survey;

/* The first pass: the kinds of force present, their oscillation rates and
 * the error terms that do not depend on the scheme. */
static void survey_forces(const pfx_motion *m, auto_survey *a) {
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        const bool unreg = f->region.kind == PFX_REGION_NONE;
        if (f->kind == PFX_MOTION_DRAG && (f->c > 0 || (!unreg && f->k > 0)))
            a->velocity = true;
        if (f->kind == PFX_MOTION_SPRING && f->zeta > 0 && !unreg)
            a->velocity = true;
        if (f->kind == PFX_MOTION_MAGNETIC && norm3(f->field) > 0) {
            a->rotation = true;
            a->err += rotation_error(f);
        }
        if (f->kind == PFX_MOTION_ATTRACTOR || f->kind == PFX_MOTION_SPRING ||
            f->kind == PFX_MOTION_TURBULENCE || (f->kind == PFX_MOTION_GRAVITY && !unreg) ||
            (f->kind == PFX_MOTION_MAGNETIC && norm3(f->electric) > 0))
            a->position = true;
        if (f->kind == PFX_MOTION_FORCE_OVER_LIFE) {
            a->position = true; /* a kick that reads no state */
            a->err += AUTO_C_JERK * f->jerk_hint;
        }
        double w = pfx_motion_force_omega(f);
        if (w > 0) {
            a->w2 += w * w;
            a->err += oscillation_error(f);
            if (1 / w < a->h)
                a->h = 1 / w, a->stiff = f->name;
        }
    }
}

/* With a velocity force: the decay rates the chosen scheme evaluates
 * explicitly (everything for Verlet, the unfolded velocity forces for the
 * split step), their error terms, and the step limits they and the summed
 * oscillation set. */
static void limit_by_damping(const pfx_motion *m, const pfx_motion_choice *c, auto_survey *a) {
    const double c_quad =
        c->scheme == PFX_SCHEME_SPLIT ? AUTO_C_QUADRATIC_SPLIT : AUTO_C_QUADRATIC_VERLET;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        double k = pfx_motion_force_damping(m, f);
        bool unreg = f->region.kind == PFX_REGION_NONE;
        if (c->scheme == PFX_SCHEME_SPLIT && unreg && f->kind == PFX_MOTION_SPRING)
            k = 0;
        if (c->scheme == PFX_SCHEME_SPLIT && unreg && f->kind == PFX_MOTION_DRAG)
            k -= f->k;
        a->kv += k;
        /* the linear part (what is left of k beyond the quadratic drag's
         * 2 c v) and the quadratic part, each with its own constant */
        const double kq =
            f->kind == PFX_MOTION_DRAG && f->c > 0 ? pfx_motion_force_damping(m, f) - f->k : 0;
        const double kl = k - kq;
        if (k > 0)
            a->err += velocity_scale(m, f) * (AUTO_C_VELOCITY * kl * kl + c_quad * kq * kq);
    }
    if (c->scheme == PFX_SCHEME_VERLET && a->w2 > 0 && 1 / sqrt(a->w2) < a->h)
        a->h = 1 / sqrt(a->w2), a->stiff = "the forces together";
    if (a->kv > 0 && 1 / a->kv < a->h)
        a->h = 1 / a->kv, a->stiff = "the drag";
}

/* c->why: the scheme and why it was chosen, then the substeps and what set
 * them when there is more than one step or any expected error. */
static void write_auto_why(const auto_survey *a, pfx_motion_choice *c) {
    const double hh = c->dt / c->steps;
    int len;
    if (!a->position && !a->velocity && !a->rotation)
        len = snprintf(c->why, sizeof c->why,
                       "exact: gravity and linear drag have a closed form, exact at any dt");
    else if (c->scheme == PFX_SCHEME_SPLIT)
        len = snprintf(
            c->why, sizeof c->why, "%s: exact gravity/drag drift%s%s",
            pfx_integrator_name(c->chosen), a->rotation ? ", Boris rotation keeps |v| in B" : "",
            a->position || a->velocity ? ", kick-drift-kick for the rest (2nd order)" : "");
    else
        len = snprintf(c->why, sizeof c->why,
                       "verlet: a velocity-dependent force needs it (2nd order, 2 evaluations)");
    if (len > 0 && (size_t)len < sizeof c->why && (c->steps > 1 || a->err > 0))
        snprintf(c->why + len, sizeof c->why - len,
                 "; %d substep%s (set by %s%s): omega*h = %.3g, k*h = %.3g, expected error "
                 "%.2g m/s",
                 c->steps, c->steps == 1 ? "" : "s", a->stiff ? a->stiff : "-",
                 c->steps == PFX_MOTION_MAX_SUBSTEPS ? ", capped" : "", sqrt(a->w2) * hh,
                 a->kv * hh, c->error_rate);
}

/* The rule per particle (c->radius), where it applies: split step, one
 * attractor, beside it only gravity (whose pull a particle's path bound
 * takes in) and spiral and speed_limit (which turn or slow v and move no
 * position). The survey's terms are then the attractor's alone. Its
 * omega, sqrt(S / (L^m r^n)), and C r omega^3 scale with r as r^-(n/2)
 * and r^-(3n/2 - 1). With a softening e (and several substeps) the field
 * softens within e, so r0 = e is the worst place and the levels run from
 * 1 substep far out to `steps` near it. Without one the field is singular:
 * r0 = reference_radius, where `steps` was judged, and a particle that
 * dips inside it (any eccentric orbit) takes more, up to the cap; judged
 * at reference_radius alone, an e = 0.5 orbit about it missed 1e-3 m/s by
 * 4.4 times at 10 steps/s. */
static void choose_by_radius(const pfx_motion *m, double tol, const auto_survey *a,
                             pfx_motion_choice *c) {
    const pfx_motion_force *at = NULL;
    double gravity = 0;
    if (c->scheme != PFX_SCHEME_SPLIT || a->rotation || a->velocity)
        return;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        if (f->kind == PFX_MOTION_ATTRACTOR && !at && f->strength > 0)
            at = f;
        else if (f->kind == PFX_MOTION_GRAVITY)
            gravity += norm3(f->accel);
        else if (f->kind != PFX_MOTION_SPIRAL && f->kind != PFX_MOTION_SPEED_LIMIT)
            return;
    }
    if (!at || (at->softening > 0 && c->steps <= 1))
        return;
    const double s = at->strength, e = at->softening, L = at->ref_radius > 0 ? at->ref_radius : 1;
    /* n = 3, 2, 1 for inverse square, linear, constant; the peak of
     * s r / (r^2 + e^2)^(3/2) is 2 s / (3 sqrt(3) e^2) at r = e / sqrt(2),
     * of s r / (L (r^2 + e^2)) s / (2 L e) at r = e, and s / L^2 bounds
     * the constant falloff's. */
    const int pw = at->falloff == PFX_FALLOFF_INVERSE_SQUARE ? 3
                   : at->falloff == PFX_FALLOFF_LINEAR       ? 2
                                                             : 1;
    c->radius.on = true;
    c->radius.singular = !(e > 0);
    c->radius.r0 = c->radius.singular ? L : e;
    c->radius.omega0 = pfx_motion_force_omega(at);
    c->radius.err0 = oscillation_error(at);
    c->radius.tol = tol;
    c->radius.omega_pow2 = pw;
    c->radius.err_pow2 = 3 * pw - 2;
    memcpy(c->radius.center, at->center, sizeof at->center);
    c->radius.peak = c->radius.singular ? INFINITY
                     : pw == 3          ? 2 * s / (3 * sqrt(3.0) * e * e)
                     : pw == 2          ? s / (2 * L * e)
                                        : s / (L * L);
    c->radius.peak_coef = pw == 3 ? s : pw == 2 ? s / L : s / (L * L);
    c->radius.gravity = gravity;
    c->radius.max_steps = c->radius.singular ? PFX_MOTION_MAX_SUBSTEPS : c->steps;
    size_t len = strlen(c->why);
    if (c->radius.singular)
        snprintf(c->why + len, sizeof c->why - len,
                 "; per particle by distance to '%s' (no softening: more inside "
                 "reference_radius, up to %d)",
                 at->name ? at->name : "-", c->radius.max_steps);
    else
        snprintf(c->why + len, sizeof c->why - len, "; fewer, per particle, away from '%s'",
                 at->name ? at->name : "-");
}

/* The auto rule, per emitter, from the forces it feels:
 *  - only gravity and unregioned linear drag (springs' damping counts):
 *    `exact`, the closed form, 1 step at any dt;
 *  - plus position forces (attractor, spring, turbulence, E) and/or B but
 *    no other velocity force: the split step (exact drift, kick-drift-kick,
 *    Boris rotation for B) - second order and symplectic - named `exact`,
 *    or `boris` when B is present;
 *  - any other velocity force (quadratic drag, regioned drag): `verlet`
 *    (2nd order, 2 evaluations), or `boris` with B;
 *  - substeps: h = dt/n with omega h <= 1 (half the leapfrog limit of 2,
 *    so the phase error stays below 5 %), k h <= 1 for the decay rates the
 *    scheme does not integrate exactly (no sign flips, inside every limit),
 *    and L omega^3 h^2 / 24 <= tolerance - the position error per second of
 *    a second-order symplectic scheme on an oscillation of size L. */
static void choose_auto(const pfx_motion *m, double tol, pfx_motion_choice *c) {
    auto_survey a = {.h = INFINITY};
    survey_forces(m, &a);
    if (!a.velocity) {
        c->scheme = PFX_SCHEME_SPLIT;
        c->chosen = a.rotation ? PFX_INTEGRATOR_BORIS : PFX_INTEGRATOR_EXACT;
    } else {
        c->scheme = a.rotation ? PFX_SCHEME_SPLIT : PFX_SCHEME_VERLET;
        c->chosen = a.rotation ? PFX_INTEGRATOR_BORIS : PFX_INTEGRATOR_VERLET;
        limit_by_damping(m, c, &a);
    }
    /* The tolerance: err h^2 <= tol. */
    if (a.err > 0 && sqrt(tol / a.err) < a.h)
        a.h = sqrt(tol / a.err), a.stiff = "the tolerance";
    c->steps = ceil_steps(c->dt, a.h);
    c->error_rate = a.err * (c->dt / c->steps) * (c->dt / c->steps);
    write_auto_why(&a, c);
    choose_by_radius(m, tol, &a, c);
}

void pfx_motion_choose(pfx_motion *m, double dt) {
    const double tol = m->tolerance > 0 ? m->tolerance : 1e-3;
    pfx_motion_choice *c = &m->choice;
    memset(c, 0, sizeof *c);
    c->dt = dt;
    if (m->integrator == PFX_INTEGRATOR_AUTO) {
        choose_auto(m, tol, c);
        if (m->substeps > 0) {
            c->steps = m->substeps;
            c->radius.on = false; /* the count asked for, for every particle */
        }
    } else {
        c->chosen = m->integrator;
        c->scheme = pfx_integrator_scheme(m->integrator);
        c->steps = m->substeps > 0 ? m->substeps : 1;
        snprintf(c->why, sizeof c->why, "%s as requested, %d substep%s",
                 pfx_integrator_name(c->chosen), c->steps, c->steps == 1 ? "" : "s");
    }
}

bool pfx_motion_full_step(double dt, double span) { return fabs(span - dt) <= 1e-9 * dt; }

int pfx_motion_substeps_over(int steps, double dt, double span) {
    if (pfx_motion_full_step(dt, span)) /* it keeps its count */
        return steps;
    double n = ceil(span * steps / dt * (1 - 1e-12));
    return n < 1 ? 1 : n > 1e6 ? 1000000 : (int)n;
}

int pfx_motion_evals_per_step(const pfx_motion *m) {
    const pfx_motion_choice *c = &m->choice;
    int per = 1;
    switch (c->scheme) {
    case PFX_SCHEME_EULER:
    case PFX_SCHEME_SYMPLECTIC:
        per = 1;
        break;
    case PFX_SCHEME_MIDPOINT:
    case PFX_SCHEME_VERLET:
        per = 2;
        break;
    case PFX_SCHEME_RK4:
        per = 4;
        break;
    case PFX_SCHEME_SPLIT:
        /* 1: the closed-form update itself; kicks that read v: a midpoint
         * stage each (sim/motion_impl.h, velocity_half_kick) */
        per = !pfx_motion_split_kicks(m) ? 1 : pfx_motion_split_kicks_v(m) ? 4 : 2;
        break;
    }
    return per * (c->steps > 0 ? c->steps : 1);
}

/* A region's weight at p: 1 inside, 1 - d / falloff at distance d outside,
 * 0 beyond (sim/motion_impl.h's region_weight, for one point in double). */
static double region_weight(const pfx_motion_region *g, const double p[3]) {
    if (g->kind == PFX_REGION_NONE)
        return 1;
    double q[3], out;
    for (int a = 0; a < 3; a++)
        q[a] = p[a] - g->center[a];
    if (g->kind == PFX_REGION_SPHERE) {
        out = norm3(q) - g->radius;
    } else {
        for (int a = 0; a < 3; a++)
            q[a] = fmax(fabs(q[a]) - g->half[a], 0);
        out = norm3(q);
    }
    double w = out <= 0 ? 1 : g->falloff > 0 ? 1 - out / g->falloff : 0;
    return w > 0 ? w : 0;
}

void pfx_motion_drift(const pfx_motion *m, const double p[3], double out[3]) {
    out[0] = out[1] = out[2] = 0;
    for (size_t f = 0; m && f < m->force_count; f++) {
        const pfx_motion_force *F = &m->forces[f];
        if (F->kind != PFX_MOTION_VORTEX)
            continue;
        const double *u = F->axis;
        double r[3], q[3];
        for (int a = 0; a < 3; a++)
            r[a] = p[a] - F->center[a];
        const double al = r[0] * u[0] + r[1] * u[1] + r[2] * u[2];
        for (int a = 0; a < 3; a++)
            q[a] = r[a] - al * u[a];
        const double rp = norm3(q), fr = pfx_vortex_falloff(rp / F->radius, F->sims_d);
        if (!(fr > 0))
            continue;
        /* d/dt of the turn by strength f w t about u: strength f w (u x q);
         * of the pull by inflow f w t: -inflow f w q / |q|. */
        const double w = fr * region_weight(&F->region, p), turn = F->strength * w;
        const double in = rp > 0 ? F->inflow * w / rp : 0;
        out[0] += turn * (u[1] * q[2] - u[2] * q[1]) - in * q[0];
        out[1] += turn * (u[2] * q[0] - u[0] * q[2]) - in * q[1];
        out[2] += turn * (u[0] * q[1] - u[1] * q[0]) - in * q[2];
    }
}
