/* Motion through emission, where users meet it: a particle born inside a
 * step (at t = 0, off the step grid by `rate`, or exactly on a step end)
 * is stepped from its birth by its emitter's own integrator. Asserted
 * against closed forms and measured orders of convergence, never against
 * numbers pfx printed: the exactness of `exact` and `boris` at any step,
 * each integrator's order, the vortex without lag, `auto` within its
 * tolerance on every problem and step of the accuracy suite, and one trail
 * birth per trail time. */
#include "test.h"
#include "test_compile.h"

#include <stdio.h>
#include <string.h>

#include "base/rng.h"
#include "bench/accuracy_problems.h"
#include "sim/motion.h"
#include "sim/sim.h"
#include "sim/step.h"

static const pfx_acc_problem *problem(const char *name) {
    for (size_t i = 0; i < pfx_acc_problem_count; i++)
        if (!strncmp(pfx_acc_problems[i].name, name, strlen(name)))
            return &pfx_acc_problems[i];
    CHECK(!"no such problem");
    return &pfx_acc_problems[0];
}

/* ---- The birth step is the integrator's own partial step ---- */

/* The newborn's state after its birth step is, bit for bit, a lone float
 * particle set to the birth state and advanced by the same model over the
 * rest of the step: for every scheme, with substeps and an operator. */
static void test_birth_step_is_the_schemes(void) {
    static const char *const integrators[] = {"euler",  "symplectic", "midpoint", "rk4",
                                              "verlet", "exact",      "boris"};
    for (size_t k = 0; k < sizeof integrators / sizeof *integrators; k++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "pfx: 1\nsim: { rate: 10, integrator: %s, substeps: 3 }\n"
                 "forces:\n  g: { type: gravity, accel: [0, -9.81, 0] }\n"
                 "  d: { type: drag, k: 0.8, c: 0.1, wind: [1, 0, 0] }\n"
                 "  v: { type: vortex, axis: [0, 1, 0], strength: 2, radius: 5 }\n"
                 "  b: { type: magnetic, field: [0, 0.5, 0] }\n"
                 "emitters:\n  e:\n    shape: { type: point }\n    position: [1, 2, 0]\n"
                 "    rate: 3.7\n    spread: 0\n    direction: [0.3, 1, 0.2]\n"
                 "    speed: 4\n    lifetime: 5\n    charge: 1\n",
                 integrators[k]);
        compiled c;
        if (!compile_text(&c, text))
            return;
        pfx_sim *s = pfx_sim_create(c.e, NULL);
        pfx_sim_step(s);
        pfx_sim_step(s);
        pfx_sim_step(s); /* t = 0.3: the first birth was at 1/3.7 = 0.27 */
        const pfx_pool *p = &s->pools[0];
        CHECK(p->count == 1);
        const double tb = p->birth[0], age = s->time - tb;
        CHECK(age > 0 && age < s->dt);
        /* The birth state: the point, the direction at speed 4. */
        const double n = sqrt(0.09 + 1 + 0.04);
        float x[3] = {1, 2, 0}, v[3] = {(float)(4 * 0.3 / n), (float)(4 / n), (float)(4 * 0.2 / n)};
        float q = 1;
        pfx_motion_pool_f one = {.count = 1,
                                 .px = &x[0],
                                 .py = &x[1],
                                 .pz = &x[2],
                                 .vx = &v[0],
                                 .vy = &v[1],
                                 .vz = &v[2],
                                 .charge = p->charge ? &q : NULL};
        pfx_motion_advance_f(&s->plans[0], &one, tb, age);
        bool same = p->px[0] == x[0] && p->py[0] == x[1] && p->pz[0] == x[2] && p->vx[0] == v[0] &&
                    p->vy[0] == v[1] && p->vz[0] == v[2];
        if (!same)
            fprintf(stderr, "  %s: (%.9g %.9g %.9g) against (%.9g %.9g %.9g)\n", integrators[k],
                    p->px[0], p->py[0], p->pz[0], x[0], x[1], x[2]);
        CHECK(same);
        pfx_sim_destroy(s);
        compiled_free(&c);
    }
}

/* ---- Exact and Boris from the first instant ---- */

/* Gravity + linear drag k towards a wind, `exact`, dt = 0.1: every particle
 * matches the closed form at every step, born by a burst at 0 and by rate
 * off the grid, at k dt = 0.05, 5 and 50 (before the fix: 1.5 m and 14.7 m
 * off at k dt = 5 and 50). */
static void test_exact_from_birth(void) {
    const double ks[] = {0.5, 50, 500};
    for (size_t kk = 0; kk < 3; kk++)
        for (int mode = 0; mode < 2; mode++) {
            const double k = ks[kk], w[3] = {2, 0, 1}, g[3] = {0, -9.81, 0};
            char text[1024];
            snprintf(text, sizeof text,
                     "pfx: 1\nduration: 3\nsim: { rate: 10, integrator: exact }\nforces:\n"
                     "  g: { type: gravity, accel: [0, -9.81, 0] }\n"
                     "  d: { type: drag, k: %g, wind: [2, 0, 1] }\n"
                     "emitters:\n  e:\n    shape: { type: point }\n    spread: 0\n"
                     "    direction: [0.3, 1, -0.1]\n    speed: 5\n    lifetime: 10\n%s",
                     k,
                     mode ? "    rate: 7\n" : "    rate: 0\n    bursts: [{ time: 0, count: 3 }]\n");
            compiled c;
            if (!compile_text(&c, text))
                return;
            const double n = sqrt(0.09 + 1 + 0.01), v0[3] = {5 * 0.3 / n, 5 / n, -5 * 0.1 / n};
            pfx_sim *s = pfx_sim_create(c.e, NULL);
            double worst = 0;
            for (int step = 0; step < 30; step++) {
                pfx_sim_step(s);
                const pfx_pool *p = &s->pools[0];
                for (uint32_t j = 0; j < p->count; j++) {
                    double t = pfx_particle_age(p, j), e = exp(-k * t), E1 = -expm1(-k * t) / k,
                           E2 = (t - E1) / k;
                    const float *pos[3] = {p->px, p->py, p->pz}, *vel[3] = {p->vx, p->vy, p->vz};
                    for (int a = 0; a < 3; a++) {
                        double u0 = v0[a] - w[a];
                        double x = w[a] * t + u0 * E1 + g[a] * E2, v = w[a] + u0 * e + g[a] * E1;
                        worst = fmax(worst, fabs(pos[a][j] - x));
                        worst = fmax(worst, fabs(vel[a][j] - v) * 0.1);
                    }
                }
            }
            fprintf(stderr, "  exact, k*dt = %g, %s: worst error %.3g m\n", k * 0.1,
                    mode ? "rate births" : "burst at 0", worst);
            CHECK(worst < 1e-5); /* float round-off of metre-sized values */
            pfx_sim_destroy(s);
            compiled_free(&c);
        }
}

/* Boris keeps |v| from birth in a pure magnetic field, at Omega dt = 0.2
 * and 0.5, born at 0 and off the grid (before: +2 % and sqrt(1 + 0.5^2)). */
static void test_boris_from_birth(void) {
    const double omegas[] = {2, 5};
    for (int k = 0; k < 2; k++)
        for (int mode = 0; mode < 2; mode++) {
            char text[1024];
            snprintf(text, sizeof text,
                     "pfx: 1\nduration: 3\nsim: { rate: 10, integrator: boris }\nforces:\n"
                     "  b: { type: magnetic, field: [0, %g, 0] }\n"
                     "emitters:\n  e:\n    shape: { type: point }\n    spread: 0\n"
                     "    direction: [1, 0.2, 0.3]\n    speed: 3\n    lifetime: 10\n"
                     "    charge: 1\n%s",
                     omegas[k],
                     mode ? "    rate: 7\n" : "    rate: 0\n    bursts: [{ time: 0, count: 2 }]\n");
            compiled c;
            if (!compile_text(&c, text))
                return;
            pfx_sim *s = pfx_sim_create(c.e, NULL);
            double worst = 0;
            for (int step = 0; step < 30; step++) {
                pfx_sim_step(s);
                const pfx_pool *p = &s->pools[0];
                for (uint32_t j = 0; j < p->count; j++) {
                    double v = sqrt((double)p->vx[j] * p->vx[j] + (double)p->vy[j] * p->vy[j] +
                                    (double)p->vz[j] * p->vz[j]);
                    worst = fmax(worst, fabs(v - 3) / 3);
                }
            }
            fprintf(stderr, "  boris, Omega*dt = %g, %s: worst |v| change %.3g\n", omegas[k] * 0.1,
                    mode ? "rate births" : "burst at 0", worst);
            CHECK(worst < 1e-6);
            pfx_sim_destroy(s);
            compiled_free(&c);
        }
}

/* The Sims vortex turns a particle at rest by strength f(r) per second from
 * its birth: no step of lag, born at 0 or off the grid. */
static void test_vortex_from_birth(void) {
    for (int mode = 0; mode < 2; mode++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "pfx: 1\nduration: 3\nsim: { rate: 30 }\nforces:\n"
                 "  v: { type: vortex, axis: [0, 1, 0], strength: 0.5, radius: 4, d: 0 }\n"
                 "emitters:\n  e:\n    shape: { type: point }\n    position: [1, 0, 0]\n"
                 "    speed: 0\n    lifetime: 10\n%s",
                 mode ? "    rate: 7\n" : "    rate: 0\n    bursts: [{ time: 0, count: 1 }]\n");
        compiled c;
        if (!compile_text(&c, text))
            return;
        /* f(r) = r^4 - 2 r^2 + 1 at r = 1/4; strength 0.5 degrees/s */
        const double r = 0.25, f = r * r * r * r - 2 * r * r + 1, rate = 0.5 * M_PI / 180 * f;
        pfx_sim *s = pfx_sim_create(c.e, NULL);
        double worst = 0;
        for (int step = 0; step < 60; step++) {
            pfx_sim_step(s);
            const pfx_pool *p = &s->pools[0];
            for (uint32_t j = 0; j < p->count; j++) {
                /* turning about +y from +x goes towards -z */
                double angle = atan2(-(double)p->pz[j], p->px[j]);
                worst = fmax(worst, fabs(angle - rate * pfx_particle_age(p, j)));
            }
        }
        fprintf(stderr, "  vortex, %s: worst angle error %.3g rad\n",
                mode ? "rate births" : "burst at 0", worst);
        CHECK(worst < 1e-6);
        pfx_sim_destroy(s);
        compiled_free(&c);
    }
}

/* ---- Orders of convergence through emission ---- */

/* The order measured from the largest error(age)/age of two runs at steps
 * and 2 steps per T, for every birth mode; the pairs sit where truncation,
 * not float round-off, dominates. */
static void test_orders_through_emission(void) {
    static const struct {
        const char *problem, *integrator;
        long steps;
        double order, slack;
    } cases[] = {
        {"linear drag", "euler", 256, 1, 0.1},
        {"projectile", "symplectic", 256, 1, 0.1},
        {"quadratic drag", "midpoint", 64, 2, 0.15},
        {"damped spring", "verlet", 64, 2, 0.15},
        {"damped spring", "rk4", 16, 4, 0.3},
        {"charge in uniform B", "rk4", 8, 4, 0.3},
        {"charge in uniform B", "boris", 64, 2, 0.15},
        {"Kepler", "verlet", 512, 2, 0.15},
        {"Kepler", "rk4", 64, 4, 0.5}, /* pre-asymptotic on an eccentric orbit: 4.3-4.5 */
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        pfx_integrator integ;
        CHECK(pfx_integrator_parse(cases[i].integrator, &integ));
        const pfx_acc_problem *p = problem(cases[i].problem);
        for (int mode = 0; mode < PFX_BIRTH_MODE_COUNT; mode++) {
            pfx_acc_result a = pfx_acc_run_emitted(p, integ, cases[i].steps, mode);
            pfx_acc_result b = pfx_acc_run_emitted(p, integ, 2 * cases[i].steps, mode);
            double order = log(a.max_rate / b.max_rate) / log(2.0);
            fprintf(stderr, "  %-28s %-10s %-19s order %.3f\n", p->name, cases[i].integrator,
                    pfx_birth_mode_name(mode), order);
            CHECK(!a.failed && !b.failed);
            CHECK(fabs(order - cases[i].order) <= cases[i].slack);
        }
    }
}

/* `exact` on its two problems and `boris` on the gyration, through
 * emission at every step of the sweep: float round-off only. */
static void test_exact_through_emission_sweep(void) {
    const char *names[] = {"projectile", "linear drag", "charge in uniform B"};
    for (int k = 0; k < 3; k++) {
        const pfx_acc_problem *p = problem(names[k]);
        pfx_integrator integ = k < 2 ? PFX_INTEGRATOR_EXACT : PFX_INTEGRATOR_BORIS;
        /* The error is float round-off of 10-20 m values (1e-6 m an ulp),
         * summed step by step: it grows with the steps, never with dt. */
        double worst = 0;
        for (long steps = 8; steps <= 1024; steps *= 2)
            for (int mode = 0; mode < PFX_BIRTH_MODE_COUNT; mode++) {
                pfx_acc_result r = pfx_acc_run_emitted(p, integ, steps, mode);
                CHECK(!r.failed);
                if (k < 2) {
                    worst = fmax(worst, r.error);
                    CHECK(r.error <= 2e-6 * (1 + steps / 8.0));
                }
            }
        if (k < 2)
            fprintf(stderr, "  %s, exact: worst error over the sweep %.3g m\n", p->name, worst);
    }
}

/* ---- auto keeps its tolerance ---- */

/* On every problem of the suite and every step of its sweep, the largest
 * error(age)/age stays within the default tolerance of 1e-3 m/s, in the
 * model and through emission in every birth mode. The bounce through
 * emission is left out where a rebound would fly for less than two steps:
 * the deflector then lays the particle to rest on purpose (resting
 * contact, man pfx-effect(5)). */
static void test_auto_tolerance(void) {
    const double tol = 1e-3;
    for (size_t i = 0; i < pfx_acc_problem_count; i++) {
        const pfx_acc_problem *p = &pfx_acc_problems[i];
        double worst_model = 0, worst_emitted = 0;
        for (long steps = 4; steps <= 16384; steps *= 2) {
            pfx_motion m;
            pfx_acc_result r = pfx_acc_run_model(p, PFX_INTEGRATOR_AUTO, steps, &m);
            worst_model = fmax(worst_model, r.max_rate);
            CHECK(r.max_rate <= tol);
            const double dt = p->T / (double)steps, first_rebound = 0.7 * sqrt(2 * 9.81 * 1);
            if (p->bounce && first_rebound < 9.81 * dt)
                continue;
            for (int mode = 0; mode < PFX_BIRTH_MODE_COUNT; mode++) {
                pfx_acc_result e = pfx_acc_run_emitted(p, PFX_INTEGRATOR_AUTO, steps, mode);
                if (dt > 1)
                    continue; /* not an effect's step rate */
                worst_emitted = fmax(worst_emitted, e.max_rate);
                CHECK(!e.failed && e.max_rate <= tol);
            }
        }
        fprintf(stderr, "  auto, %-28s worst error rate %.3g m/s (model), %.3g m/s (emitted)\n",
                p->name, worst_model, worst_emitted);
    }
}

/* ---- Trails ---- */

/* A trail at r per second behind a parent of lifetime L lays exactly one
 * child at each age m / r < L: ceil(L r) - 1 children, whatever the step
 * rate and whenever the parent was born (before: duplicates when a trail
 * time fell on a step end, 15 instead of 9). */
static void test_trail_counts(void) {
    static const struct {
        double trail_rate, lifetime, sim_rate;
        int expect;
    } cases[] = {
        {10, 1, 120, 9},      {10, 1, 60, 9},        {10, 1, 100, 9},
        {10, 1, 7, 9},        {7, 0.5, 120, 3},      {4, 1.25, 30, 4},
        {500, 0.125, 30, 62}, {500, 0.125, 120, 62}, {30, 0.75, 90, 22},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++)
        for (int births = 0; births < 2; births++) {
            char text[1024];
            snprintf(text, sizeof text,
                     "pfx: 1\nduration: 4\nsim: { rate: %g }\nforces: {}\nemitters:\n"
                     "  parent:\n    %s\n    lifetime: %g\n    speed: 1\n"
                     "    trail: { emit: child, rate: %g }\n"
                     "  child:\n    rate: 0\n    lifetime: 10\n    speed: 0\n",
                     cases[i].sim_rate,
                     births ? "rate: 3.3\n    duration: 1"
                            : "rate: 0\n    bursts: [{ time: 0, "
                              "count: 10 }]",
                     cases[i].lifetime, cases[i].trail_rate);
            compiled c;
            if (!compile_text(&c, text))
                return;
            pfx_sim *s = pfx_sim_create(c.e, NULL);
            pfx_sim_run_to(s, 3.9);
            const uint64_t parents = s->emitters[0].born, children = s->emitters[1].born;
            CHECK(s->emitters[0].dropped == 0 && s->emitters[1].dropped == 0);
            if (children != parents * (uint64_t)cases[i].expect)
                fprintf(stderr,
                        "  trail %g/s, life %g, %g steps/s: %llu children of %llu parents\n",
                        cases[i].trail_rate, cases[i].lifetime, cases[i].sim_rate,
                        (unsigned long long)children, (unsigned long long)parents);
            CHECK(parents > 0 && children == parents * (uint64_t)cases[i].expect);
            pfx_sim_destroy(s);
            compiled_free(&c);
        }
}

/* pfx_step_may_run_away's shortcut (no square roots far inside the bounds)
 * answers as the exact test for states of every scale, near both bounds
 * (speed 5.7e5 m/s, reach half of PFX_MOTION_MAX_POSITION) included. */
static bool run_away_exact(const float x[3], const float v[3], const double a[3], double life) {
    double speed = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]) +
                   sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) * life;
    double far =
        sqrt((double)x[0] * x[0] + (double)x[1] * x[1] + (double)x[2] * x[2]) + speed * life;
    return !(speed < 5.7e5 && far < 0.5 * PFX_MOTION_MAX_POSITION);
}

static void test_may_run_away_shortcut(void) {
    pfx_rng r;
    pfx_rng_seed(&r, 11, 5);
    int differ = 0, yes = 0, no = 0;
    for (int i = 0; i < 400000; i++) {
        double sx = pow(10, pfx_rng_range(&r, -2, 7.5)), sv = pow(10, pfx_rng_range(&r, -2, 6.5)),
               sa = pow(10, pfx_rng_range(&r, -2, 5)), life = pow(10, pfx_rng_range(&r, -2, 2));
        float x[3], v[3];
        double a[3];
        for (int k = 0; k < 3; k++) {
            x[k] = (float)(sx * pfx_rng_range(&r, -1, 1));
            v[k] = (float)(sv * pfx_rng_range(&r, -1, 1));
            a[k] = sa * pfx_rng_range(&r, -1, 1);
        }
        bool got = pfx_step_may_run_away(x, v, a, life);
        differ += got != run_away_exact(x, v, a, life);
        yes += got, no += !got;
    }
    CHECK(differ == 0);
    CHECK(yes > 1000 && no > 1000);
}

int main(void) {
    RUN(test_may_run_away_shortcut);
    RUN(test_birth_step_is_the_schemes);
    RUN(test_exact_from_birth);
    RUN(test_boris_from_birth);
    RUN(test_vortex_from_birth);
    RUN(test_orders_through_emission);
    RUN(test_exact_through_emission_sweep);
    RUN(test_auto_tolerance);
    RUN(test_trail_counts);
    return TEST_EXIT();
}
