/* force_over_life through emission, as users meet it: particles born at
 * their exact times (off the step grid) feel an acceleration that is a
 * function of their normalised age u = age / lifetime. Asserted against
 * the closed forms (a particle at rest at birth):
 *   a = A u            v = A tau^2 / (2 L),   x = A tau^3 / (6 L)
 *   a = A (constant)   v = A tau,             x = A tau^2 / 2
 * and, for a vector given in a rotating emitter's space, against the
 * integral of the turning vector. */
#include "test.h"
#include "test_compile.h"

#include <math.h>
#include <stdio.h>

#include "sim/sim.h"
#include "sim/state.h"

/* Steps the effect to time `until` and checks every live particle of
 * emitter 0 with check(tau, x, v) -> error; returns the largest error over
 * age (m per s of age), and the particle count in *count. */
typedef void (*exact_fn)(double tau, double x[3], double v[3]);

static double worst_error_rate(const char *text, double until, exact_fn exact, size_t *count) {
    compiled c;
    if (!compile_text(&c, text))
        return INFINITY;
    pfx_sim *s = pfx_sim_create(c.e, NULL);
    while (s->time < until - 1e-9)
        pfx_sim_step(s);
    const pfx_pool *p = &s->pools[0];
    double worst = 0;
    for (uint32_t i = 0; i < p->count; i++) {
        double tau = pfx_particle_age(p, i), x[3], v[3];
        if (!(tau > 0))
            continue;
        exact(tau, x, v);
        double got[3] = {p->px[i], p->py[i], p->pz[i]};
        for (int a = 0; a < 3; a++)
            worst = fmax(worst, fabs(got[a] - x[a]) / tau);
    }
    *count = p->count;
    pfx_sim_destroy(s);
    compiled_free(&c);
    return worst;
}

/* a = (0, 6 u, 0) over L = 2 s. */
static void ramp_exact(double tau, double x[3], double v[3]) {
    const double A = 6, L = 2;
    x[0] = x[2] = v[0] = v[2] = 0;
    v[1] = A * tau * tau / (2 * L);
    x[1] = A * tau * tau * tau / (6 * L);
}

static const char ramp_effect[] =
    "pfx: 1\nsim: { rate: %g, integrator: %s%s }\n"
    "forces:\n  lift:\n    type: force_over_life\n"
    "    accel: [{at: 0, value: [0, 0, 0]}, {at: 1, value: [0, 6, 0]}]\n"
    "emitters:\n  e: { shape: { type: point }, rate: 3.7, speed: 0, lifetime: 2 }\n";

/* RK4 integrates a cubic exactly: only float rounding is left. */
static void test_ramp_rk4_is_exact(void) {
    char text[1024];
    snprintf(text, sizeof text, ramp_effect, 30.0, "rk4", "");
    size_t n;
    double err = worst_error_rate(text, 1.9, ramp_exact, &n);
    CHECK(n >= 6);
    if (!(err < 2e-6))
        fprintf(stderr, "  rk4 ramp: %.3g m/s\n", err);
    CHECK(err < 2e-6);
}

/* auto keeps its tolerance (error per second of age) at every step rate,
 * and a looser tolerance lets the error grow: the model is not idle. */
static void test_ramp_auto_meets_tolerance(void) {
    const double rates[] = {10, 30, 120};
    for (int k = 0; k < 3; k++) {
        char text[1024];
        snprintf(text, sizeof text, ramp_effect, rates[k], "auto", ", tolerance: 1e-4");
        size_t n;
        double err = worst_error_rate(text, 1.9, ramp_exact, &n);
        if (!(err <= 1e-4))
            fprintf(stderr, "  auto ramp at %g steps/s: %.3g m/s\n", rates[k], err);
        CHECK(err <= 1e-4);
    }
    /* Kick-drift-kick leaves j h^2 / 6 per second: 3 / 6 / 100 at 10/s. */
    char text[1024];
    snprintf(text, sizeof text, ramp_effect, 10.0, "auto", ", tolerance: 1, substeps: 1");
    size_t n;
    double err = worst_error_rate(text, 1.9, ramp_exact, &n);
    CHECK_NEAR(err, 3.0 / 6 / 100, 1e-3 * 0.5);
}

/* A constant vector is exact at any step under auto (kicks of a constant
 * are the projectile's closed form). */
static void const_exact(double tau, double x[3], double v[3]) {
    const double A[3] = {1, -2, 0.5};
    for (int a = 0; a < 3; a++) {
        v[a] = A[a] * tau;
        x[a] = 0.5 * A[a] * tau * tau;
    }
}

static void test_constant_is_exact(void) {
    const char *text = "pfx: 1\nsim: { rate: 7 }\n"
                       "forces:\n  push: { type: force_over_life, accel: [1, -2, 0.5] }\n"
                       "emitters:\n  e: { shape: { type: point }, rate: 3.7, speed: 0, "
                       "lifetime: 3 }\n";
    size_t n;
    double err = worst_error_rate(text, 2.5, const_exact, &n);
    CHECK(n >= 8);
    CHECK(err < 1e-6);
}

/* Held before the first key and after the last: keys at 0.25 and 0.5
 * give a = 2 until u = 0.25 (tau = 0.5 s), then a ramp to 4 at tau = 1 s,
 * then 4. */
static void held_exact(double tau, double x[3], double v[3]) {
    double t1 = 0.5, t2 = 1.0;
    x[0] = x[2] = v[0] = v[2] = 0;
    if (tau <= t1) {
        v[1] = 2 * tau, x[1] = tau * tau;
        return;
    }
    double v1 = 2 * t1, x1 = t1 * t1, d = fmin(tau, t2) - t1; /* a = 2 + 4 d on the ramp */
    double v2 = v1 + 2 * d + 2 * d * d, x2 = x1 + v1 * d + d * d + 2 * d * d * d / 3;
    double e = tau > t2 ? tau - t2 : 0;
    v[1] = v2 + 4 * e;
    x[1] = x2 + v2 * e + 2 * e * e;
}

static void test_held_beyond_keys(void) {
    const char *text = "pfx: 1\nsim: { rate: 200, integrator: rk4 }\n"
                       "forces:\n  f:\n    type: force_over_life\n"
                       "    accel: [{at: 0.25, value: [0, 2, 0]}, {at: 0.5, value: [0, 4, 0]}]\n"
                       "emitters:\n  e: { shape: { type: point }, rate: 3.7, speed: 0, "
                       "lifetime: 2 }\n";
    size_t n;
    double err = worst_error_rate(text, 1.95, held_exact, &n);
    CHECK(n >= 6);
    /* RK4 across a kink is second order there: (1/200)^2 of the slope 4. */
    CHECK(err < 1e-4);
}

/* space: emitter with a fixed rotation of 90 degrees about z turns +x
 * into +y; exact at a long step (float rounding grows with the number of
 * steps, so few of them). */
static void turned_exact(double tau, double x[3], double v[3]) {
    x[0] = x[2] = v[0] = v[2] = 0;
    v[1] = tau;
    x[1] = 0.5 * tau * tau;
}

static void test_emitter_space_fixed(void) {
    const char *text = "pfx: 1\nsim: { rate: 7 }\n"
                       "forces:\n  f: { type: force_over_life, accel: [1, 0, 0], "
                       "space: emitter }\n"
                       "emitters:\n  e: { shape: { type: point }, rotation: [0, 0, 90], "
                       "rate: 3.7, speed: 0, lifetime: 2 }\n";
    size_t n;
    double err = worst_error_rate(text, 1.9, turned_exact, &n);
    CHECK(n >= 6);
    CHECK(err < 1e-6);
}

/* A keyframed rotation turns the vector at every step: the emitter turns
 * about z from 0 to 90 degrees over [0, 1] s and holds; a unit vector
 * along its x axis is (cos w t, sin w t, 0), w = pi/2 per s. For the
 * particle born at t0: v(t) = integral of it from t0, x the integral of v. */
static double born_at;
static void rotating_exact(double tau, double x[3], double v[3]) {
    const double w = M_PI / 2, t0 = born_at, t = t0 + tau;
    /* t <= 1 in this test: the turning phase only. */
    v[0] = (sin(w * t) - sin(w * t0)) / w;
    v[1] = (cos(w * t0) - cos(w * t)) / w;
    x[0] = (cos(w * t0) - cos(w * t)) / (w * w) - sin(w * t0) / w * tau;
    x[1] = (sin(w * t0) - sin(w * t)) / (w * w) + cos(w * t0) / w * tau;
    v[2] = x[2] = 0;
}

static void test_emitter_space_keyframed(void) {
    const char *text = "pfx: 1\nsim: { rate: 240, integrator: rk4 }\n"
                       "forces:\n  f: { type: force_over_life, accel: [1, 0, 0], "
                       "space: emitter }\n"
                       "emitters:\n  e:\n    shape: { type: point }\n"
                       "    rotation: [{t: 0, value: [0, 0, 0]}, {t: 1, value: [0, 0, 90]}]\n"
                       "    bursts: [{time: 0.1, count: 1}]\n    rate: 0\n    speed: 0\n"
                       "    lifetime: 2\n";
    compiled c;
    if (!compile_text(&c, text))
        return;
    pfx_sim *s = pfx_sim_create(c.e, NULL);
    while (s->time < 0.95)
        pfx_sim_step(s);
    const pfx_pool *p = &s->pools[0];
    CHECK(p->count == 1);
    if (p->count == 1) {
        born_at = p->birth[0];
        double tau = pfx_particle_age(p, 0), x[3], v[3];
        rotating_exact(tau, x, v);
        /* Linear keyframes turn at a constant rate: the closed form is exact;
         * RK4 at 240/s leaves ~1e-9, float rounding ~1e-7. */
        CHECK_NEAR(p->px[0], x[0], 1e-6);
        CHECK_NEAR(p->py[0], x[1], 1e-6);
        CHECK_NEAR(p->vx[0], v[0], 1e-6);
        CHECK_NEAR(p->vy[0], v[1], 1e-6);
        CHECK(fabs(p->py[0]) > 0.05); /* it did turn */
    }
    pfx_sim_destroy(s);
    compiled_free(&c);
}

int main(void) {
    RUN(test_ramp_rk4_is_exact);
    RUN(test_ramp_auto_meets_tolerance);
    RUN(test_constant_is_exact);
    RUN(test_held_beyond_keys);
    RUN(test_emitter_space_fixed);
    RUN(test_emitter_space_keyframed);
    return TEST_EXIT();
}
