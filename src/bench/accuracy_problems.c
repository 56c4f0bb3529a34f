/* The accuracy suite's problems and their closed forms, and the two ways to
 * run them (see accuracy_problems.h). The closed forms are the oracle: each
 * is the textbook solution written out, never a number pfx printed. */
#include "bench/accuracy_problems.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "compile/compile.h"
#include "sim/motion.h"
#include "sim/sim.h"

#define G 9.81

static pfx_motion_force *add(pfx_motion *m, pfx_motion_kind kind) {
    pfx_motion_force *f = &m->forces[m->force_count++];
    memset(f, 0, sizeof *f);
    f->kind = kind;
    f->name = "f";
    return f;
}

/* ---- The problems and their exact solutions ---- */

static void projectile_setup(pfx_motion *m, pfx_acc_state *s) {
    add(m, PFX_MOTION_GRAVITY)->accel[1] = -G;
    *s = (pfx_acc_state){0, 0, 0, 3, 10, 0};
}
static void projectile_exact(double t, pfx_acc_state *e) {
    *e = (pfx_acc_state){3 * t, 10 * t - 0.5 * G * t * t, 0, 3, 10 - G * t, 0};
}

/* v' = g - k (v - w): u = v - w decays as e^{-kt} while g accumulates. */
static const double DK = 0.7, DW[3] = {2, 0, 1};
static void drag_setup(pfx_motion *m, pfx_acc_state *s) {
    add(m, PFX_MOTION_GRAVITY)->accel[1] = -G;
    pfx_motion_force *d = add(m, PFX_MOTION_DRAG);
    d->k = DK;
    memcpy(d->wind, DW, sizeof DW);
    *s = (pfx_acc_state){0, 0, 0, 3, 10, -1};
}
static void drag_exact(double t, pfx_acc_state *e) {
    double g[3] = {0, -G, 0}, v0[3] = {3, 10, -1}, x[3], v[3];
    double ek = exp(-DK * t), E1 = -expm1(-DK * t) / DK, E2 = (t - E1) / DK;
    for (int a = 0; a < 3; a++) {
        double u0 = v0[a] - DW[a];
        v[a] = DW[a] + u0 * ek + g[a] * E1;
        x[a] = DW[a] * t + u0 * E1 + g[a] * E2;
    }
    *e = (pfx_acc_state){x[0], x[1], x[2], v[0], v[1], v[2]};
}

/* Quadratic drag c from rest: v = -v_t tanh(g t / v_t), v_t = sqrt(g/c),
 * y = -(v_t^2/g) ln cosh(g t / v_t). */
static const double QC = 0.2;
static void quad_setup(pfx_motion *m, pfx_acc_state *s) {
    add(m, PFX_MOTION_GRAVITY)->accel[1] = -G;
    add(m, PFX_MOTION_DRAG)->c = QC;
    *s = (pfx_acc_state){0, 0, 0, 0, 0, 0};
}
static void quad_exact(double t, pfx_acc_state *e) {
    double vt = sqrt(G / QC), a = G * t / vt;
    *e = (pfx_acc_state){0, -(vt * vt / G) * log(cosh(a)), 0, 0, -vt * tanh(a), 0};
}

/* Springs, omega = 2: x = cos 2t; damped zeta = 0.1. */
static void spring_setup(pfx_motion *m, pfx_acc_state *s) {
    add(m, PFX_MOTION_SPRING)->k = 4;
    *s = (pfx_acc_state){1, 0, 0, 0, 0, 0};
}
static void spring_exact(double t, pfx_acc_state *e) {
    *e = (pfx_acc_state){cos(2 * t), 0, 0, -2 * sin(2 * t), 0, 0};
}
static void dspring_setup(pfx_motion *m, pfx_acc_state *s) {
    pfx_motion_force *f = add(m, PFX_MOTION_SPRING);
    f->k = 4, f->zeta = 0.1;
    *s = (pfx_acc_state){1, 0, 0, 0, 0, 0};
}
static void dspring_exact(double t, pfx_acc_state *e) {
    double w = 2, z = 0.1, wd = w * sqrt(1 - z * z), B = z * w / wd, d = exp(-z * w * t);
    double c = cos(wd * t), sn = sin(wd * t);
    *e = (pfx_acc_state){
        d * (c + B * sn), 0, 0, d * ((-z * w + wd * B) * c + (-z * w * B - wd) * sn), 0, 0};
}

/* q/m = 1, B = z: v = (cos t, -sin t, 0.2), x = (sin t, cos t - 1, 0.2 t). */
static void gyro_setup(pfx_motion *m, pfx_acc_state *s) {
    pfx_motion_force *f = add(m, PFX_MOTION_MAGNETIC);
    f->field[2] = 1, f->charge = 1, f->mass = 1;
    *s = (pfx_acc_state){0, 0, 0, 1, 0, 0.2};
}
static void gyro_exact(double t, pfx_acc_state *e) {
    *e = (pfx_acc_state){sin(t), cos(t) - 1, 0.2 * t, cos(t), -sin(t), 0.2};
}

/* Kepler e = 0.5, mu = a = 1, from perihelion (0.5, 0) with speed sqrt(3):
 * the mean anomaly is t (n = sqrt(mu / a^3) = 1); Newton's method solves
 * Kepler's equation E - e sin E = t; x = a (cos E - e), y = b sin E,
 * b = a sqrt(1 - e^2), and dE/dt = n / (1 - e cos E). */
static void kepler_setup(pfx_motion *m, pfx_acc_state *s) {
    pfx_motion_force *f = add(m, PFX_MOTION_ATTRACTOR);
    f->strength = 1, f->ref_radius = 0.5;
    *s = (pfx_acc_state){0.5, 0, 0, 0, sqrt(3.0), 0};
}
static void kepler_exact(double t, pfx_acc_state *e) {
    const double ecc = 0.5, b = sqrt(1 - ecc * ecc);
    double E = t + ecc * sin(t);
    for (int i = 0; i < 50; i++) {
        double d = (E - ecc * sin(E) - t) / (1 - ecc * cos(E));
        E -= d;
        if (fabs(d) < 1e-16)
            break;
    }
    double dE = 1 / (1 - ecc * cos(E));
    *e = (pfx_acc_state){cos(E) - ecc, b * sin(E), 0, -sin(E) * dE, b * cos(E) * dE, 0};
}

/* Bounce: dropped from h0 = 1 at rest onto y = 0 with resilience 0.7; each
 * rebound leaves with eps times the impact speed, so the apexes are
 * eps^(2n) h0. */
static const double H0 = 1, EPS = 0.7;
static void bounce_setup(pfx_motion *m, pfx_acc_state *s) {
    add(m, PFX_MOTION_GRAVITY)->accel[1] = -G;
    *s = (pfx_acc_state){0, H0, 0, 0, 0, 0};
}
static void bounce_exact(double t, pfx_acc_state *e) {
    double t1 = sqrt(2 * H0 / G), u = G * t1;
    if (t < t1) {
        *e = (pfx_acc_state){0, H0 - 0.5 * G * t * t, 0, 0, -G * t, 0};
        return;
    }
    t -= t1;
    u *= EPS;
    while (t > 2 * u / G) {
        t -= 2 * u / G;
        u *= EPS;
    }
    *e = (pfx_acc_state){0, u * t - 0.5 * G * t * t, 0, 0, u - G * t, 0};
}

#define TWO_PI 6.283185307179586
const pfx_acc_problem pfx_acc_problems[] = {
    {"projectile", 2, true, false, false, projectile_setup, projectile_exact,
     "  g: { type: gravity, accel: [0, -9.81, 0] }\n",
     "    direction: [3, 10, 0]\n    speed: 10.440306508910550\n"},
    {"linear drag + wind + gravity", 2, true, false, false, drag_setup, drag_exact,
     "  g: { type: gravity, accel: [0, -9.81, 0] }\n  d: { type: drag, k: 0.7, wind: [2, 0, 1] }\n",
     "    direction: [3, 10, -1]\n    speed: 10.488088481701515\n"},
    {"quadratic drag from rest", 3, false, false, false, quad_setup, quad_exact,
     "  g: { type: gravity, accel: [0, -9.81, 0] }\n  d: { type: drag, c: 0.2 }\n",
     "    speed: 0\n"},
    {"undamped spring", TWO_PI, false, false, false, spring_setup, spring_exact,
     "  s: { type: spring, anchor: [0, 0, 0], k: 4 }\n", "    position: [1, 0, 0]\n    speed: 0\n"},
    {"damped spring", TWO_PI, false, false, false, dspring_setup, dspring_exact,
     "  s: { type: spring, anchor: [0, 0, 0], k: 4, zeta: 0.1 }\n",
     "    position: [1, 0, 0]\n    speed: 0\n"},
    {"charge in uniform B", TWO_PI, false, true, false, gyro_setup, gyro_exact,
     "  b: { type: magnetic, field: [0, 0, 1] }\n",
     "    direction: [1, 0, 0.2]\n    speed: 1.0198039027185569\n    charge: 1\n    mass: 1\n"},
    {"Kepler e = 0.5", TWO_PI, false, false, false, kepler_setup, kepler_exact,
     "  sun: { type: attractor, center: [0, 0, 0], strength: 1, reference_radius: 0.5 }\n",
     "    position: [0.5, 0, 0]\n    direction: [0, 1, 0]\n    speed: 1.7320508075688772\n"},
    {"bounce, eps = 0.7", 1.3, false, false, true, bounce_setup, bounce_exact,
     "  g: { type: gravity, accel: [0, -9.81, 0] }\n", "    position: [0, 1, 0]\n    speed: 0\n"},
};
const size_t pfx_acc_problem_count = sizeof pfx_acc_problems / sizeof pfx_acc_problems[0];

bool pfx_acc_applies(const pfx_acc_problem *p, pfx_integrator i) {
    if (i == PFX_INTEGRATOR_EXACT)
        return p->closed_form;
    if (i == PFX_INTEGRATOR_BORIS)
        return p->magnetic;
    return true;
}

const char *pfx_birth_mode_name(pfx_birth_mode mode) {
    static const char *const names[PFX_BIRTH_MODE_COUNT] = {"born at t = 0", "born off the grid",
                                                            "born on a step end"};
    return (unsigned)mode < PFX_BIRTH_MODE_COUNT ? names[mode] : "?";
}

static double distance(const pfx_acc_state *a, const pfx_acc_state *b) {
    double dx = a->x - b->x, dy = a->y - b->y, dz = a->z - b->z;
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* ---- The model run ---- */

/* Earliest root in (0, h] of y + v t - g t^2/2 = 0, without cancellation:
 * q = -(b + sign(b) sqrt(b^2 - 4ac))/2, roots q/a and c/q. */
static double impact_time(double y, double v, double h) {
    double a = -0.5 * G, b = v, c = y, disc = b * b - 4 * a * c;
    if (disc < 0)
        return -1;
    double q = -0.5 * (b + (b >= 0 ? 1 : -1) * sqrt(disc));
    double r1 = q / a, r2 = q != 0 ? c / q : -1, best = -1;
    if (r1 > 0 && r1 <= h)
        best = r1;
    if (r2 > 0 && r2 <= h && (best < 0 || r2 < best))
        best = r2;
    return best;
}

pfx_acc_result pfx_acc_run_model(const pfx_acc_problem *pr, pfx_integrator integ, long steps,
                                 pfx_motion *m) {
    pfx_acc_result r = {0};
    pfx_acc_state s, e;
    memset(m, 0, sizeof *m);
    m->integrator = integ;
    pr->setup(m, &s);
    /* As the compiler does: forces judge accuracy by the emission speed. */
    for (size_t f = 0; f < m->force_count; f++)
        m->forces[f].speed_hint = sqrt(s.u * s.u + s.v * s.v + s.w * s.w);
    const double dt = pr->T / (double)steps;
    pfx_motion_plan plan;
    pfx_motion_plan_prepare(&plan, m, dt);
    r.substeps = m->choice.steps;
    r.evals = pfx_motion_evals_per_step(m);
    pfx_motion_pool_d pool = {
        .count = 1, .px = &s.x, .py = &s.y, .pz = &s.z, .vx = &s.u, .vy = &s.v, .vz = &s.w};
    for (long i = 0; i < steps; i++) {
        pfx_acc_state before = s;
        double t = (double)i * dt;
        pfx_motion_step_d(&plan, &pool, t);
        if (pr->bounce && s.y < 0) {
            /* the ground: integrate to the hit, reflect, finish the step */
            double tau = impact_time(before.y, before.v, dt);
            if (tau > 0) {
                s = before;
                pfx_motion_advance_d(&plan, &pool, t, tau);
                s.y = 0;
                s.v = -EPS * s.v;
                pfx_motion_advance_d(&plan, &pool, t + tau, dt - tau);
            }
        }
        if (!(fabs(s.x) + fabs(s.y) + fabs(s.z) < 1e12)) {
            r.failed = true;
            r.error = r.max_rate = r.max_error = INFINITY;
            return r;
        }
        double age = (double)(i + 1) * dt;
        pr->exact(age, &e);
        double err = distance(&s, &e);
        r.max_rate = fmax(r.max_rate, err / age);
        r.max_error = fmax(r.max_error, err);
        r.error = err;
    }
    return r;
}

/* ---- The emitted run ---- */

/* The problem as an effect file: one point emitter, no spread, a lifetime
 * well past T, born by `mode`. */
static void effect_text(const pfx_acc_problem *pr, pfx_integrator integ, double rate,
                        pfx_birth_mode mode, char *buf, size_t size) {
    const double dt = 1 / rate;
    char birth[160];
    if (mode == PFX_BIRTH_AT_ZERO)
        snprintf(birth, sizeof birth, "    rate: 0\n    bursts: [{ time: 0, count: 1 }]\n");
    else if (mode == PFX_BIRTH_STEP_END)
        snprintf(birth, sizeof birth, "    rate: 0\n    bursts: [{ time: %.17g, count: 1 }]\n",
                 3.0 / rate);
    else
        snprintf(birth, sizeof birth, "    rate: %.17g\n    duration: %.17g\n", 1 / (2.37 * dt),
                 3 * dt);
    snprintf(buf, size,
             "pfx: 1\nduration: %.17g\nsim: { rate: %.17g, integrator: %s }\n"
             "forces:\n%s%s"
             "emitters:\n  p:\n    shape: { type: point }\n    spread: 0\n"
             "    lifetime: %.17g\n%s%s",
             pr->T + 8 * dt, rate, pfx_integrator_name(integ), pr->forces_yaml,
             pr->bounce ? "deflectors:\n  ground: { type: plane, point: [0, 0, 0], normal: [0, 1, "
                          "0], resilience: 0.7, friction: 0 }\n"
                        : "",
             2 * pr->T + 10, pr->emitter_yaml, birth);
}

pfx_acc_result pfx_acc_run_emitted(const pfx_acc_problem *pr, pfx_integrator integ, long steps,
                                   pfx_birth_mode mode) {
    pfx_acc_result r = {
        .failed = true, .error = INFINITY, .max_rate = INFINITY, .max_error = INFINITY};
    const double rate = (double)steps / pr->T;
    if (!(rate >= 1 && rate <= 1e5))
        return r;
    char text[2048];
    effect_text(pr, integ, rate, mode, text, sizeof text);
    size_t len = strlen(text);
    pfx_diags d;
    pfx_doc doc = {0};
    pfx_arena arena = {0};
    pfx_diags_init(&d, "accuracy.yaml", text, len);
    pfx_effect *e = NULL;
    if (pfx_parse(text, len, &doc, &d))
        e = pfx_compile(doc.root, "accuracy.yaml", NULL, &arena, &d);
    pfx_sim *s = e ? pfx_sim_create(e, NULL) : NULL;
    if (s) {
        r.failed = false;
        r.max_rate = r.max_error = 0;
        r.substeps = e->emitters[0].motion ? e->emitters[0].motion->choice.steps : 1;
        r.evals = e->emitters[0].motion ? pfx_motion_evals_per_step(e->emitters[0].motion) : 1;
        const long limit = 4 * steps + 64;
        for (long k = 0; k < limit && !s->failed; k++) {
            pfx_sim_step(s);
            const pfx_pool *p = &s->pools[0];
            if (p->count == 0 || p->id[0] != 0)
                continue; /* not born yet */
            double age = pfx_particle_age(p, 0);
            if (!(age > 0))
                continue;
            pfx_acc_state got = {p->px[0], p->py[0], p->pz[0], p->vx[0], p->vy[0], p->vz[0]}, want;
            pr->exact(age, &want);
            double err = distance(&got, &want);
            r.max_rate = fmax(r.max_rate, err / age);
            r.max_error = fmax(r.max_error, err);
            r.error = err;
            if (age >= pr->T * (1 - 1e-12))
                break;
        }
        if (s->failed || !(r.error < INFINITY))
            r.failed = true, r.error = r.max_rate = r.max_error = INFINITY;
    }
    pfx_sim_destroy(s);
    pfx_doc_free(&doc);
    pfx_arena_free(&arena);
    pfx_diags_free(&d);
    return r;
}
