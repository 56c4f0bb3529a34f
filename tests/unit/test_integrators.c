/* The integrators against exact solutions and theory: orders of
 * convergence, the closed form at any k*dt, |v| under Boris, Kepler energy,
 * the forces' shapes (vortex falloff, gyration, circular orbits), the auto
 * choice, and the scan for bad states. Stability limits are in
 * test_stability.c. */
#include "test.h"

#include <string.h>

#include "sim/fast_f.h"
#include "sim/motion.h"

/* The plan of m for dt (the choice made first); m must outlive it. */
static pfx_motion_plan plan_of(pfx_motion *m, double dt) {
    pfx_motion_plan p;
    pfx_motion_plan_prepare(&p, m, dt);
    return p;
}

#define TWO_PI 6.283185307179586

typedef struct st {
    double x, y, z, u, v, w;
} st;

static pfx_motion make(pfx_integrator integ) {
    pfx_motion m;
    memset(&m, 0, sizeof m);
    m.integrator = integ;
    return m;
}

static pfx_motion_force *add(pfx_motion *m, pfx_motion_kind kind) {
    pfx_motion_force *f = &m->forces[m->force_count++];
    memset(f, 0, sizeof *f);
    f->kind = kind;
    f->name = "f";
    return f;
}

/* n steps of dt from t = 0 on one double particle. */
static void simulate(pfx_motion *m, st *s, double dt, long n) {
    pfx_motion_plan plan = plan_of(m, dt);
    pfx_motion_pool_d p = {
        .count = 1, .px = &s->x, .py = &s->y, .pz = &s->z, .vx = &s->u, .vy = &s->v, .vz = &s->w};
    for (long i = 0; i < n; i++)
        pfx_motion_step_d(&plan, &p, (double)i * dt);
}

static double speed(const st *s) { return sqrt(s->u * s->u + s->v * s->v + s->w * s->w); }

/* ---- Problems with exact solutions ---- */

/* Damped spring, k = 4 (omega 2), zeta = 0.1, from x = 1 at rest:
 * x = e^{-zeta w t}(A cos wd t + B sin wd t), A = 1, B = zeta w / wd. */
static void spring_setup(pfx_motion *m, st *s) {
    pfx_motion_force *f = add(m, PFX_MOTION_SPRING);
    f->k = 4, f->zeta = 0.1;
    *s = (st){1, 0, 0, 0, 0, 0};
}
static void spring_exact(double t, st *e) {
    double w = 2, z = 0.1, wd = w * sqrt(1 - z * z), A = 1, B = z * w / wd, d = exp(-z * w * t);
    double c = cos(wd * t), sn = sin(wd * t);
    *e = (st){d * (A * c + B * sn),
              0,
              0,
              d * ((-z * w * A + wd * B) * c + (-z * w * B - wd * A) * sn),
              0,
              0};
}

/* Gravity + linear drag k = 0.7 towards wind (2, 0, 1): with u = v - w,
 * v = w + u0 e^{-kt} + g (1 - e^{-kt})/k, x = x0 + w t + u0 (1 - e^{-kt})/k
 * + g (t - (1 - e^{-kt})/k)/k. */
static const double DK = 0.7, DW[3] = {2, 0, 1}, DG[3] = {0, -9.81, 0};
static void drag_setup(pfx_motion *m, st *s) {
    pfx_motion_force *g = add(m, PFX_MOTION_GRAVITY);
    memcpy(g->accel, DG, sizeof DG);
    pfx_motion_force *d = add(m, PFX_MOTION_DRAG);
    d->k = DK;
    memcpy(d->wind, DW, sizeof DW);
    *s = (st){0, 0, 0, 3, 10, -1};
}
static void drag_exact_k(double k, const double w[3], const double g[3], const st *s0, double t,
                         st *e) {
    double ek = exp(-k * t), E1 = (1 - ek) / k, E2 = (t - E1) / k, z = k * t;
    if (z < 1e-3) /* (t - E1)/k cancels: its series t^2 (1/2 - z/6 + z^2/24) */
        E1 = t * (1 - z / 2 + z * z / 6), E2 = t * t * (0.5 - z / 6 + z * z / 24);
    double x0[3] = {s0->x, s0->y, s0->z}, v0[3] = {s0->u, s0->v, s0->w}, x[3], v[3];
    for (int a = 0; a < 3; a++) {
        double u0 = v0[a] - w[a];
        v[a] = w[a] + u0 * ek + g[a] * E1;
        x[a] = x0[a] + w[a] * t + u0 * E1 + g[a] * E2;
    }
    *e = (st){x[0], x[1], x[2], v[0], v[1], v[2]};
}
static void drag_exact(double t, st *e) {
    st s0 = {0, 0, 0, 3, 10, -1};
    drag_exact_k(DK, DW, DG, &s0, t, e);
}

static double state_error(const st *a, const st *b) {
    double d[6] = {a->x - b->x, a->y - b->y, a->z - b->z, a->u - b->u, a->v - b->v, a->w - b->w};
    double s = 0;
    for (int i = 0; i < 6; i++)
        s += d[i] * d[i];
    return sqrt(s);
}

/* Least-squares slope of log2(error) against -log2(dt) over dt = T/2^j. */
static double measured_order(pfx_integrator integ, void (*setup)(pfx_motion *, st *),
                             void (*exact)(double, st *), double T, int j0, int j1) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    st e;
    exact(T, &e);
    for (int j = j0; j <= j1; j++) {
        pfx_motion m = make(integ);
        st s;
        setup(&m, &s);
        long steps = 1L << j;
        simulate(&m, &s, T / (double)steps, steps);
        double x = (double)j, y = log2(state_error(&s, &e));
        sx += x, sy += y, sxx += x * x, sxy += x * y, n++;
    }
    return -(n * sxy - sx * sy) / (n * sxx - sx * sx);
}

static void test_orders(void) {
    /* dt ranges in the asymptotic regime and above round-off */
    struct {
        pfx_integrator integ;
        double order;
        int j0, j1;
    } cases[] = {
        {PFX_INTEGRATOR_EULER, 1, 9, 13},    {PFX_INTEGRATOR_SYMPLECTIC, 1, 9, 13},
        {PFX_INTEGRATOR_MIDPOINT, 2, 6, 10}, {PFX_INTEGRATOR_RK4, 4, 3, 7},
        {PFX_INTEGRATOR_VERLET, 2, 6, 10},   {PFX_INTEGRATOR_BORIS, 2, 6, 10},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double ps = measured_order(cases[i].integ, spring_setup, spring_exact, 2.0, cases[i].j0,
                                   cases[i].j1);
        fprintf(stderr, "  order %-10s damped spring %.3f", pfx_integrator_name(cases[i].integ),
                ps);
        CHECK_NEAR(ps, cases[i].order, 0.15);
        if (cases[i].integ == PFX_INTEGRATOR_BORIS) {
            fprintf(stderr, "\n");
            continue; /* the split step is exact on drag: no order to measure */
        }
        double pd =
            measured_order(cases[i].integ, drag_setup, drag_exact, 2.0, cases[i].j0, cases[i].j1);
        fprintf(stderr, "  linear drag %.3f\n", pd);
        CHECK_NEAR(pd, cases[i].order, 0.15);
    }
}

/* Quadratic drag c = 0.2 from rest under g: v = -v_t tanh(g t / v_t),
 * y = -(v_t^2 / g) ln cosh(g t / v_t), v_t = sqrt(g / c). */
static void quad_setup(pfx_motion *m, st *s) {
    add(m, PFX_MOTION_GRAVITY)->accel[1] = -9.81;
    add(m, PFX_MOTION_DRAG)->c = 0.2;
    *s = (st){0, 0, 0, 0, 0, 0};
}
static void quad_exact(double t, st *e) {
    double vt = sqrt(9.81 / 0.2), a = 9.81 * t / vt;
    *e = (st){0, -(vt * vt / 9.81) * log(cosh(a)), 0, 0, -vt * tanh(a), 0};
}
/* drag_setup's drag inside a sphere the particle never leaves: the same
 * solution, but kicked by the split step instead of folded into its drift. */
static void region_drag_setup(pfx_motion *m, st *s) {
    drag_setup(m, s);
    m->forces[1].region.kind = PFX_REGION_SPHERE;
    m->forces[1].region.radius = 1e3;
}

/* The split step (exact, boris) on the forces it kicks that read v:
 * second order (each half kick a midpoint stage), where one Euler stage a
 * half kick measured 1.00-1.12. */
static void test_split_velocity_kicks(void) {
    const pfx_integrator which[] = {PFX_INTEGRATOR_EXACT, PFX_INTEGRATOR_BORIS};
    for (int i = 0; i < 2; i++) {
        double pq = measured_order(which[i], quad_setup, quad_exact, 3.0, 6, 10);
        double pr = measured_order(which[i], region_drag_setup, drag_exact, 2.0, 6, 10);
        fprintf(stderr, "  order %-6s quadratic drag %.3f, drag in a region %.3f\n",
                pfx_integrator_name(which[i]), pq, pr);
        CHECK_NEAR(pq, 2, 0.15);
        CHECK_NEAR(pr, 2, 0.15);
    }
    /* each half kick then costs two evaluations */
    pfx_motion m = make(PFX_INTEGRATOR_EXACT);
    st s;
    quad_setup(&m, &s);
    pfx_motion_choose(&m, 0.1);
    CHECK(pfx_motion_evals_per_step(&m) == 4);
}

/* `exact` is the flow itself: float round-off at any k*dt, while explicit
 * Euler's error is multiplied by |1 - k dt| = 9 every step. */
static void test_exact_any_kdt(void) {
    const double ks[] = {0, 1e-9, 1e-3, 0.7, 10, 1e3};
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++) {
        double k = ks[i], dt = k >= 1 ? 10 / k : 0.05; /* k dt = 10 for the stiff ones */
        pfx_motion m = make(PFX_INTEGRATOR_AUTO);
        pfx_motion_force *g = add(&m, PFX_MOTION_GRAVITY);
        memcpy(g->accel, DG, sizeof DG);
        pfx_motion_force *d = add(&m, PFX_MOTION_DRAG);
        d->k = k;
        memcpy(d->wind, DW, sizeof DW);
        pfx_motion_plan plan = plan_of(&m, dt);
        CHECK(m.choice.chosen == PFX_INTEGRATOR_EXACT);
        float x = 0, y = 0, z = 0, u = 3, v = 10, w = -1;
        pfx_motion_pool_f p = {
            .count = 1, .px = &x, .py = &y, .pz = &z, .vx = &u, .vy = &v, .vz = &w};
        const int n = 20;
        for (int s = 0; s < n; s++)
            pfx_motion_step_f(&plan, &p, s * dt);
        st e, s0 = {0, 0, 0, 3, 10, -1};
        double T = n * dt;
        if (k == 0) /* the projectile */
            e = (st){3 * T, 10 * T - 0.5 * 9.81 * T * T, -T, 3, 10 - 9.81 * T, -1};
        else
            drag_exact_k(k, DW, DG, &s0, T, &e);
        st got = {x, y, z, u, v, w};
        double scale = fabs(e.x) + fabs(e.y) + fabs(e.z) + fabs(e.u) + fabs(e.v) + fabs(e.w);
        /* float: 2^-24 per operation, a few operations per step */
        fprintf(stderr, "  exact in float, k*dt = %g: error %.3g of scale %.3g\n", k * dt,
                state_error(&got, &e), scale);
        CHECK(state_error(&got, &e) <= 8 * n * 6e-8 * scale);
    }
    /* Explicit Euler at k dt = 10: the velocity error grows 9x per step. */
    pfx_motion m = make(PFX_INTEGRATOR_EULER);
    pfx_motion_force *d = add(&m, PFX_MOTION_DRAG);
    d->k = 10;
    st s = {0, 0, 0, 1, 0, 0};
    simulate(&m, &s, 1.0, 10);
    fprintf(stderr, "  euler at k*dt = 10: |v| after 10 steps = %.3g (exact %.3g)\n", speed(&s),
            exp(-100.0));
    CHECK_NEAR(fabs(s.u), pow(9, 10), 1e-3 * pow(9, 10));
    pfx_stability_warning warn[4];
    CHECK(pfx_motion_check_stability(&m, warn, 4) == 1 && warn[0].kind == PFX_STABILITY_UNSTABLE);
}

/* Gravity only (the simulation's own fast path) stays the exact projectile. */
static void test_gravity_only(void) {
    pfx_motion m = make(PFX_INTEGRATOR_AUTO);
    pfx_motion_force *g = add(&m, PFX_MOTION_GRAVITY);
    memcpy(g->accel, DG, sizeof DG);
    st s = {1, 2, 3, 3, 10, -1};
    simulate(&m, &s, 1.0 / 24, 96);
    CHECK(m.choice.chosen == PFX_INTEGRATOR_EXACT && m.choice.steps == 1);
    CHECK_NEAR(s.y, 2 + 10 * 4.0 - 0.5 * 9.81 * 16, 1e-12);
    CHECK_NEAR(s.x, 1 + 12.0, 1e-12);
    CHECK_NEAR(s.v, 10 - 9.81 * 4, 1e-12);
}

/* q/m = 1 in B = z: Omega = 1, Omega dt = 0.5, 1,000 gyrations. */
static double gyration_speed(pfx_integrator integ, int in_float) {
    pfx_motion m = make(integ);
    pfx_motion_force *f = add(&m, PFX_MOTION_MAGNETIC);
    f->field[2] = 1, f->charge = 1, f->mass = 1;
    const double dt = 0.5;
    const long n = (long)(1000 * TWO_PI / dt);
    if (!in_float) {
        st s = {0, 0, 0, 1, 0, 0};
        simulate(&m, &s, dt, n);
        return speed(&s);
    }
    pfx_motion_plan plan = plan_of(&m, dt);
    float x = 0, y = 0, z = 0, u = 1, v = 0, w = 0;
    pfx_motion_pool_f p = {.count = 1, .px = &x, .py = &y, .pz = &z, .vx = &u, .vy = &v, .vz = &w};
    for (long i = 0; i < n; i++)
        pfx_motion_step_f(&plan, &p, i * dt);
    return sqrt((double)u * u + (double)v * v + (double)w * w);
}

static void test_boris_speed(void) {
    double b = gyration_speed(PFX_INTEGRATOR_BORIS, 0),
           bf = gyration_speed(PFX_INTEGRATOR_BORIS, 1);
    double r = gyration_speed(PFX_INTEGRATOR_RK4, 0);
    fprintf(
        stderr,
        "  |v|/|v0| after 1000 gyrations at Omega*dt = 0.5: boris %.9f (float %.7f), rk4 %.4f\n", b,
        bf, r);
    CHECK_NEAR(b, 1, 1e-4);
    CHECK_NEAR(bf, 1, 1e-4);
    CHECK(r < 0.5);
    /* theory: |R(i theta)|^N with |R|^2 = 1 - theta^6/72 + theta^8/576 */
    double th = 0.5, g = sqrt(1 - pow(th, 6) / 72 + pow(th, 8) / 576);
    CHECK_NEAR(r, pow(g, (double)(long)(1000 * TWO_PI / th)), 1e-6);
}

/* Kepler e = 0.5, mu = 1, a = 1: start at perihelion r = 0.5 with
 * v = sqrt(mu (1 + e)/(a (1 - e))) = sqrt(3); energy -mu/(2a) = -0.5,
 * period 2 pi. Largest relative energy error over the first and the last 10
 * orbits (the error oscillates along an orbit; a trend shows as growth). */
static void kepler_energy(pfx_integrator integ, int orbits, int per_orbit, double *first,
                          double *last, double *worst) {
    pfx_motion m = make(integ);
    pfx_motion_force *f = add(&m, PFX_MOTION_ATTRACTOR);
    f->strength = 1;
    st s = {0.5, 0, 0, 0, sqrt(3.0), 0};
    const double dt = TWO_PI / per_orbit;
    pfx_motion_plan plan = plan_of(&m, dt);
    pfx_motion_pool_d p = {
        .count = 1, .px = &s.x, .py = &s.y, .pz = &s.z, .vx = &s.u, .vy = &s.v, .vz = &s.w};
    *worst = *first = *last = 0;
    long i = 0;
    for (int o = 1; o <= orbits; o++) {
        for (int k = 0; k < per_orbit; k++, i++) {
            pfx_motion_step_d(&plan, &p, i * dt);
            double r = sqrt(s.x * s.x + s.y * s.y + s.z * s.z);
            double E = 0.5 * (s.u * s.u + s.v * s.v + s.w * s.w) - 1 / r;
            double err = fabs((E + 0.5) / 0.5);
            if (!(err < INFINITY))
                err = INFINITY;
            if (o <= 10 && err > *first)
                *first = err;
            if (o > orbits - 10 && err > *last)
                *last = err;
            if (err > *worst)
                *worst = err;
        }
    }
}

static void test_kepler(void) {
    double f, l, w;
    kepler_energy(PFX_INTEGRATOR_SYMPLECTIC, 1000, 1000, &f, &l, &w);
    fprintf(stderr,
            "  kepler symplectic: max energy error orbits 1-10 %.3g, 991-1000 %.3g, all %.3g\n", f,
            l, w);
    CHECK(w < 0.02);    /* bounded ... */
    CHECK(l < 1.2 * f); /* ... with no trend */
    kepler_energy(PFX_INTEGRATOR_VERLET, 1000, 1000, &f, &l, &w);
    fprintf(stderr,
            "  kepler verlet:     max energy error orbits 1-10 %.3g, 991-1000 %.3g, all %.3g\n", f,
            l, w);
    CHECK(w < 1e-3);
    CHECK(l < 1.2 * f);
    double fe, le, we;
    /* Euler at 10x finer steps still gains energy every orbit */
    kepler_energy(PFX_INTEGRATOR_EULER, 100, 10000, &fe, &le, &we);
    fprintf(stderr, "  kepler euler:      max energy error orbits 1-10 %.3g, 91-100 %.3g (dt/10)\n",
            fe, le);
    CHECK(le > 3 * fe); /* grows */
    CHECK(le > 10 * w);
}

/* A particle at rest at radius r R from the axis turns by strength f(r) dt
 * in one step. */
static void test_vortex_falloff(void) {
    const double d = 0.5, R = 2, a = 1.5, dt = 1e-3;
    for (double r = 0.05; r < 1.2; r += 0.1) {
        pfx_motion m = make(PFX_INTEGRATOR_AUTO);
        pfx_motion_force *f = add(&m, PFX_MOTION_VORTEX);
        f->axis[2] = 1, f->strength = a, f->radius = R, f->sims_d = d;
        st s = {r * R, 0, 0.3, 0, 0, 0};
        simulate(&m, &s, dt, 1);
        double turned = atan2(s.y, s.x) / (a * dt);
        double q = r * r, expect = r <= 1 ? (q * q - 2 * q + 1) / (1 + d * q) : 0;
        CHECK_NEAR(turned, expect, 1e-9);
        CHECK_NEAR(sqrt(s.x * s.x + s.y * s.y), r * R, 1e-12);
        CHECK_NEAR(pfx_vortex_falloff(r, d), expect, 1e-15);
    }
}

/* q = 2 C, m = 0.5 kg, B = 3 T: Omega = 12 rad/s; v_perp = 5 m/s, so the
 * gyroradius m v/(|q| B) = 5/12 m and the period 2 pi m/(|q| B) = pi/6 s. */
static void test_gyration(void) {
    const double q = 2, mass = 0.5, B = 3, vp = 5;
    const double rg = mass * vp / (q * B), T = TWO_PI * mass / (q * B), dt = T / 400;
    pfx_motion m = make(PFX_INTEGRATOR_BORIS);
    pfx_motion_force *f = add(&m, PFX_MOTION_MAGNETIC);
    f->field[2] = B, f->charge = q, f->mass = mass;
    st s = {0, 0, 0, vp, 0, 0.7};
    pfx_motion_plan plan = plan_of(&m, dt);
    pfx_motion_pool_d p = {
        .count = 1, .px = &s.x, .py = &s.y, .pz = &s.z, .vx = &s.u, .vy = &s.v, .vz = &s.w};
    double ymin = 0, ymax = 0, prev_v = s.v, t_cross = -1;
    for (int i = 0; i < 600; i++) {
        pfx_motion_step_d(&plan, &p, i * dt);
        ymin = s.y < ymin ? s.y : ymin;
        ymax = s.y > ymax ? s.y : ymax;
        /* v_y = -5 sin(Omega t): falls through 0 again after one turn */
        if (t_cross < 0 && i > 300 && prev_v > 0 && s.v <= 0)
            t_cross = (i + prev_v / (prev_v - s.v)) * dt;
        prev_v = s.v;
    }
    fprintf(stderr, "  gyration: radius %.6f (theory %.6f), period %.6f (theory %.6f)\n",
            0.5 * (ymax - ymin), rg, t_cross, T);
    CHECK_NEAR(0.5 * (ymax - ymin), rg, 1e-4 * rg);
    CHECK_NEAR(t_cross, T, 1e-4 * T);
    CHECK_NEAR(s.w, 0.7, 1e-12); /* the parallel speed is untouched */
}

/* mu = 2, r = 1.5: circular at v = sqrt(mu/r); radius held over 100 orbits. */
static void test_circular_orbit(void) {
    const pfx_integrator which[] = {PFX_INTEGRATOR_VERLET, PFX_INTEGRATOR_AUTO};
    for (int k = 0; k < 2; k++) {
        pfx_motion m = make(which[k]);
        pfx_motion_force *f = add(&m, PFX_MOTION_ATTRACTOR);
        f->strength = 2, f->ref_radius = 1.5;
        const double r0 = 1.5, v0 = sqrt(2 / r0), T = TWO_PI * r0 / v0, dt = 1.0 / 60;
        st s = {r0, 0, 0, 0, 0, v0};
        pfx_motion_plan plan = plan_of(&m, dt);
        pfx_motion_pool_d p = {
            .count = 1, .px = &s.x, .py = &s.y, .pz = &s.z, .vx = &s.u, .vy = &s.v, .vz = &s.w};
        double worst = 0;
        long n = (long)(100 * T / dt);
        for (long i = 0; i < n; i++) {
            pfx_motion_step_d(&plan, &p, i * dt);
            double r = sqrt(s.x * s.x + s.y * s.y + s.z * s.z);
            worst = fabs(r - r0) > worst ? fabs(r - r0) : worst;
        }
        fprintf(stderr, "  circular orbit %s (%s): max |r - r0|/r0 = %.3g over 100 orbits\n",
                pfx_integrator_name(which[k]), m.choice.why, worst / r0);
        CHECK(worst < 1e-3 * r0);
    }
}

/* The auto rule (motion.c, choose_auto). */
static void test_auto_choice(void) {
    pfx_motion m = make(PFX_INTEGRATOR_AUTO);
    st s;
    drag_setup(&m, &s);
    pfx_motion_plan plan = plan_of(&m, 1.0 / 30);
    CHECK(m.choice.chosen == PFX_INTEGRATOR_EXACT && m.choice.scheme == PFX_SCHEME_SPLIT &&
          m.choice.steps == 1);
    CHECK(!plan.has_kick && pfx_motion_evals_per_step(&m) == 1);
    fprintf(stderr, "  auto, gravity + drag: %s\n", m.choice.why);

    m = make(PFX_INTEGRATOR_AUTO);
    pfx_motion_force *f = add(&m, PFX_MOTION_MAGNETIC);
    f->field[1] = 2, f->charge = 1, f->mass = 1, f->electric[0] = 1;
    f = add(&m, PFX_MOTION_GRAVITY);
    f->accel[1] = -9.81;
    plan = plan_of(&m, 1.0 / 30);
    CHECK(m.choice.chosen == PFX_INTEGRATOR_BORIS && m.choice.scheme == PFX_SCHEME_SPLIT &&
          plan.has_rotation);
    fprintf(stderr, "  auto, magnetic: %s\n", m.choice.why);

    /* A stiff spring: omega = 100 rad/s at dt = 1/30 (omega dt = 3.3, beyond
     * the leapfrog limit 2): auto substeps to omega h <= 1 at least. */
    m = make(PFX_INTEGRATOR_AUTO);
    f = add(&m, PFX_MOTION_SPRING);
    f->k = 1e4, f->zeta = 0.05;
    const double dt = 1.0 / 30;
    plan = plan_of(&m, dt);
    fprintf(stderr, "  auto, stiff spring: %s\n", m.choice.why);
    CHECK(m.choice.steps >= (int)ceil(100 * dt) && m.choice.steps <= PFX_MOTION_MAX_SUBSTEPS);
    pfx_stability_warning w[4];
    CHECK(pfx_motion_check_stability(&m, w, 4) == 0);
    s = (st){1, 0, 0, 0, 0, 0};
    simulate(&m, &s, dt, 300); /* 10 s: amplitude e^{-zeta omega t} = e^{-50} */
    CHECK(fabs(s.x) < 1e-6 && fabs(s.u) < 1e-4);
    /* the same spring without substeps is unstable, and the check says so */
    m.substeps = 1;
    m.integrator = PFX_INTEGRATOR_VERLET;
    pfx_motion_choose(&m, dt);
    CHECK(pfx_motion_check_stability(&m, w, 4) >= 1 && w[0].kind == PFX_STABILITY_UNSTABLE);

    /* quadratic drag is velocity-dependent: verlet */
    m = make(PFX_INTEGRATOR_AUTO);
    f = add(&m, PFX_MOTION_DRAG);
    f->c = 0.2;
    f = add(&m, PFX_MOTION_GRAVITY);
    f->accel[1] = -9.81;
    plan = plan_of(&m, 1.0 / 30);
    CHECK(m.choice.chosen == PFX_INTEGRATOR_VERLET);
    fprintf(stderr, "  auto, quadratic drag: %s\n", m.choice.why);
}

static void test_bad_state(void) {
    float x[8] = {0}, y[8] = {0}, z[8] = {0}, u[8] = {0}, v[8] = {0}, w[8] = {0};
    pfx_motion_pool_f p = {.count = 8, .px = x, .py = y, .pz = z, .vx = u, .vy = v, .vz = w};
    pfx_bad_kind why;
    CHECK(pfx_motion_find_bad_f(&p, &why) == 8 && why == PFX_BAD_NONE);
    v[6] = 2e6f;
    CHECK(pfx_motion_find_bad_f(&p, &why) == 6 && why == PFX_BAD_SPEED);
    z[3] = NAN;
    CHECK(pfx_motion_find_bad_f(&p, &why) == 3 && why == PFX_BAD_NONFINITE);
    z[3] = 0, x[1] = -2e7f;
    CHECK(pfx_motion_find_bad_f(&p, &why) == 1 && why == PFX_BAD_POSITION);
    u[0] = INFINITY;
    CHECK(pfx_motion_find_bad_f(&p, &why) == 0 && why == PFX_BAD_NONFINITE);
}

/* The numerical divergence of the turbulence field (div curl = 0): central
 * differences at spacing e over many points, against the size of the
 * field's own derivatives d c_k / d x_k, which the divergence sums. For a
 * field with no divergence only the differences' truncation error remains:
 * small against those derivatives, and falling as e^2 (a quarter for half
 * the spacing), where a field with sources would keep a divergence of the
 * derivatives' size at any spacing. */
static double curl_divergence(double e, double *deriv, double *rms) {
    enum { N = 512 };
    float x[7][N], y[7][N], z[7][N], c[7][3][N];
    for (int i = 0; i < N; i++) {
        float p[3] = {0.37f * (float)i - 40, 1.3f - 0.11f * (float)i, 0.0005f * (float)(i * i)};
        for (int k = 0; k < 7; k++) {
            float q[3] = {p[0], p[1], p[2]};
            if (k > 0)
                q[(k - 1) / 2] += (k % 2 ? 1 : -1) * (float)e;
            x[k][i] = q[0], y[k][i] = q[1], z[k][i] = q[2];
        }
    }
    for (int k = 0; k < 7; k++)
        pfx_curl_noise_f(N, x[k], y[k], z[k], 1.0f, 0.3, 2, 42, c[k][0], c[k][1], c[k][2]);
    double worst = 0, sum_d = 0, sum2 = 0;
    for (int i = 0; i < N; i++) {
        double div = 0;
        for (int a = 0; a < 3; a++) {
            /* the step actually taken, in float */
            double h = (double)(a == 0   ? x[1 + 2 * a][i] - x[2 + 2 * a][i]
                                : a == 1 ? y[1 + 2 * a][i] - y[2 + 2 * a][i]
                                         : z[1 + 2 * a][i] - z[2 + 2 * a][i]);
            double d = ((double)c[1 + 2 * a][a][i] - (double)c[2 + 2 * a][a][i]) / h;
            div += d;
            sum_d += fabs(d) / (3 * N);
            sum2 += (double)c[0][a][i] * c[0][a][i] / (3 * N);
        }
        worst = fabs(div) > worst ? fabs(div) : worst;
    }
    *deriv = sum_d;
    *rms = sqrt(sum2);
    return worst;
}

static void test_curl_noise(void) {
    double d1, d2, rms;
    double div1 = curl_divergence(1.0 / 128, &d1, &rms);
    double div2 = curl_divergence(1.0 / 256, &d2, &rms);
    fprintf(stderr,
            "  curl noise: rms component %.3f, mean |dc_k/dx_k| %.3f, max |div| %.2g (e = 1/128),"
            " %.2g (e = 1/256)\n",
            rms, d1, div1, div2);
    CHECK(rms > 0.5 && rms < 1.5);
    CHECK(d1 > 0.3);
    CHECK(div1 < 0.01 * d1);
    CHECK(div2 < 0.35 * div1); /* second order: the divergence is the differences' error */
}

/* The float kernels against libm and the double operator: the polynomial
 * sine and cosine to 3e-7 over |x| <= 100 (cos - 1 of a small angle to
 * float precision in itself), and the float vortex turning a
 * particle at radius r R by strength f(r) dt, as the double one does, to
 * float accuracy; outside the radius a particle is not touched at all. */
static void test_fast_float(void) {
    double worst = 0;
    for (double x = -100; x <= 100; x += 0.00123) {
        float s, c;
        pfx_sincos_f((float)x, &s, &c);
        double xf = (float)x, e = fmax(fabs(s - sin(xf)), fabs(c - cos(xf)));
        worst = e > worst ? e : worst;
    }
    fprintf(stderr, "  float sincos: max error %.2g over |x| <= 100\n", worst);
    CHECK(worst < 3e-7);
    /* cos - 1 of a small angle to float precision in itself */
    for (double x = 1e-4; x < 0.1; x *= 1.7) {
        float cm1 = pfx_cosm1_small_f((float)x);
        double want = -2 * sin(0.5 * (float)x) * sin(0.5 * (float)x);
        CHECK(fabs(cm1 - want) <= 1e-6 * fabs(want));
    }
    /* a small turn (the one-loop path, weights or none) and a large one
     * (the general path) */
    const double d = 0.5, R = 2, a = 1.5, dts[3] = {0.05, 0.05, 1.0};
    pfx_motion_force f = {.kind = PFX_MOTION_VORTEX, .strength = a, .radius = R, .sims_d = d};
    f.axis[2] = 1;
    enum { N = 13 };
    for (int k = 0; k < 3; k++) {
        const double dt = dts[k];
        float x[N], y[N], z[N], w[N];
        for (int i = 0; i < N; i++)
            x[i] = (float)(0.1 * (i + 0.5) * R), y[i] = 0, z[i] = 0.3f, w[i] = 1;
        pfx_vortex_f(&f, N, k == 1 ? NULL : w, NULL, NULL, NULL, x, y, z, dt);
        for (int i = 0; i < N; i++) {
            double r = 0.1 * (i + 0.5), q = r * r;
            double expect = r < 1 ? a * dt * (q * q - 2 * q + 1) / (1 + d * q) : 0;
            CHECK_NEAR(atan2(y[i], x[i]), expect, 2e-6);
            CHECK_NEAR(sqrt((double)x[i] * x[i] + (double)y[i] * y[i]), r * R, 2e-6 * R);
            CHECK(z[i] == 0.3f);
            if (r >= 1) /* untouched, bit for bit */
                CHECK(x[i] == (float)(0.1 * (i + 0.5) * R) && y[i] == 0);
        }
    }
}

/* Spiral: the velocity turns by rate dt exactly; speed_limit clamps. */
static void test_operators(void) {
    pfx_motion m = make(PFX_INTEGRATOR_AUTO);
    pfx_motion_force *f = add(&m, PFX_MOTION_SPIRAL);
    f->axis[1] = 1, f->rate = 2.0;
    f = add(&m, PFX_MOTION_SPEED_LIMIT);
    f->max_speed = 3;
    st s = {0, 0, 0, 4, 1, 0};
    simulate(&m, &s, 0.1, 5); /* turned by 1 rad about y */
    double sc = 3 / sqrt(17.0);
    CHECK_NEAR(s.u, 4 * cos(1.0) * sc, 1e-12);
    CHECK_NEAR(s.w, -4 * sin(1.0) * sc, 1e-12);
    CHECK_NEAR(s.v, 1 * sc, 1e-12);
}

/* Unregioned gravities and one unregioned drag (plan gravity_drag) run the
 * fused kernels of motion_impl.h: the same bits as the general path (the
 * plan with the flag cleared), in float and double, for midpoint, Verlet
 * and RK4 with substeps, operators beside them and a drag with k, c and a
 * wind; and the flag is off where the order or a region forbids it. */
#define FUSED_N 300
static void test_gravity_drag_fused(void) {
    const pfx_integrator which[] = {PFX_INTEGRATOR_MIDPOINT, PFX_INTEGRATOR_VERLET,
                                    PFX_INTEGRATOR_RK4, PFX_INTEGRATOR_AUTO};
    for (int i = 0; i < 4; i++) {
        pfx_motion m = make(which[i]);
        m.substeps = 3;
        pfx_motion_force *f = add(&m, PFX_MOTION_GRAVITY);
        f->accel[1] = -9.81;
        f = add(&m, PFX_MOTION_VORTEX);
        f->axis[1] = 1, f->strength = 90, f->radius = 2;
        f = add(&m, PFX_MOTION_GRAVITY);
        f->accel[0] = 0.5, f->accel[1] = 0.25, f->accel[2] = -0.125;
        f = add(&m, PFX_MOTION_DRAG);
        f->k = 0.1, f->c = 0.7, f->wind[0] = 0.3, f->wind[1] = -0.2;
        pfx_motion_plan fused = plan_of(&m, 1.0 / 30), general = fused;
        CHECK(fused.gravity_drag && fused.scheme != PFX_SCHEME_SPLIT);
        general.gravity_drag = false;
        static float xf[2][6][FUSED_N];
        static double xd[2][6][FUSED_N];
        for (int c = 0; c < 6; c++)
            for (int j = 0; j < FUSED_N; j++) {
                double val = sin(0.37 * j + c) * (c < 3 ? 2 : 9);
                xf[0][c][j] = xf[1][c][j] = (float)val;
                xd[0][c][j] = xd[1][c][j] = val;
            }
        for (int k = 0; k < 2; k++) {
            const pfx_motion_plan *plan = k ? &general : &fused;
            pfx_motion_pool_f pf = {.count = FUSED_N,
                                    .px = xf[k][0],
                                    .py = xf[k][1],
                                    .pz = xf[k][2],
                                    .vx = xf[k][3],
                                    .vy = xf[k][4],
                                    .vz = xf[k][5]};
            pfx_motion_pool_d pd = {.count = FUSED_N,
                                    .px = xd[k][0],
                                    .py = xd[k][1],
                                    .pz = xd[k][2],
                                    .vx = xd[k][3],
                                    .vy = xd[k][4],
                                    .vz = xd[k][5]};
            for (int s = 0; s < 10; s++) {
                pfx_motion_step_f(plan, &pf, s / 30.0);
                pfx_motion_step_d(plan, &pd, s / 30.0);
            }
        }
        CHECK(memcmp(xf[0], xf[1], sizeof xf[0]) == 0);
        CHECK(memcmp(xd[0], xd[1], sizeof xd[0]) == 0);
        CHECK(xf[0][4][7] != (float)sin(0.37 * 7 + 4) * 9); /* it moved */
    }
    /* a gravity after the drag, or a drag in a region: the general path */
    pfx_motion m = make(PFX_INTEGRATOR_RK4);
    add(&m, PFX_MOTION_DRAG)->c = 0.2;
    add(&m, PFX_MOTION_GRAVITY)->accel[1] = -9.81;
    CHECK(!plan_of(&m, 0.1).gravity_drag);
    m = make(PFX_INTEGRATOR_RK4);
    add(&m, PFX_MOTION_GRAVITY)->accel[1] = -9.81;
    pfx_motion_force *d = add(&m, PFX_MOTION_DRAG);
    d->c = 0.2, d->region.kind = PFX_REGION_SPHERE, d->region.radius = 1;
    CHECK(!plan_of(&m, 0.1).gravity_drag);
}

int main(void) {
    RUN(test_orders);
    RUN(test_split_velocity_kicks);
    RUN(test_exact_any_kdt);
    RUN(test_gravity_only);
    RUN(test_boris_speed);
    RUN(test_kepler);
    RUN(test_vortex_falloff);
    RUN(test_gyration);
    RUN(test_circular_orbit);
    RUN(test_auto_choice);
    RUN(test_bad_state);
    RUN(test_curl_noise);
    RUN(test_fast_float);
    RUN(test_operators);
    RUN(test_gravity_drag_fused);
    return TEST_EXIT();
}
