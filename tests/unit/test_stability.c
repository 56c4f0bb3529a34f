/* Where the integrators fail: limits measured by stepping the real kernel
 * (bisection on growth) against the theoretical values of the methods'
 * stability functions, and the stability check against a parameter sweep:
 * it must warn on every unstable configuration and on no stable one. */
#include "test.h"

#include <string.h>

#include "bench/accuracy.h"
#include "sim/motion.h"

/* Theory, typed here from the stability functions, not read from pfx:
 * decay: |1 - z| (Euler, symplectic), |1 - z + z^2/2| (midpoint, Verlet
 * with a predicted velocity), RK4's real-axis root 2.7853; oscillator:
 * symplectic/Verlet trace 2 - w^2 >= -2, RK4 |R(iw)| = 1 at w = 2 sqrt 2,
 * Euler |1 + iw| > 1 and midpoint |1 + iw - w^2/2| > 1 for all w > 0. */
static const struct {
    pfx_integrator integ;
    double decay, oscillator; /* 0: unstable at any step */
} theory[] = {
    {PFX_INTEGRATOR_EULER, 2, 0},    {PFX_INTEGRATOR_SYMPLECTIC, 2, 2},
    {PFX_INTEGRATOR_MIDPOINT, 2, 0}, {PFX_INTEGRATOR_RK4, 2.7853, 2.8284271},
    {PFX_INTEGRATOR_VERLET, 2, 2},   {PFX_INTEGRATOR_EXACT, INFINITY, 2},
};
#define NT (sizeof theory / sizeof theory[0])

static void test_measured_limits(void) {
    for (size_t i = 0; i < NT; i++) {
        double d = pfx_bench_stability_limit(theory[i].integ, 0);
        double o = pfx_bench_stability_limit(theory[i].integ, 1);
        fprintf(stderr,
                "  %-10s decay k*dt %.5g (theory %.5g), oscillator omega*dt %.5g (theory %.5g)\n",
                pfx_integrator_name(theory[i].integ), d, theory[i].decay, o, theory[i].oscillator);
        if (isinf(theory[i].decay))
            CHECK(isinf(d));
        else
            CHECK_NEAR(d, theory[i].decay, 0.01 * theory[i].decay);
        if (theory[i].oscillator > 0)
            CHECK_NEAR(o, theory[i].oscillator, 0.01 * theory[i].oscillator);
        else
            CHECK(o < 0.3); /* grows at any step; slow growth needs many steps to show */
    }
}

static pfx_motion one_force(pfx_integrator integ, pfx_motion_kind kind) {
    pfx_motion m;
    memset(&m, 0, sizeof m);
    m.integrator = integ;
    m.force_count = 1;
    m.forces[0].kind = kind;
    m.forces[0].name = "f";
    return m;
}

static int unstable_warnings(const pfx_motion *m, pfx_stability_warning *w) {
    size_t n = pfx_motion_check_stability(m, w, 8);
    int u = 0;
    for (size_t i = 0; i < n && i < 8; i++)
        u += w[i].kind == PFX_STABILITY_UNSTABLE;
    return u;
}

/* k*dt and omega*dt grids, 1 % clear of each limit; dt = 1, so k = z. */
static void test_sweep(void) {
    int configs = 0, warned = 0;
    for (size_t i = 0; i < NT; i++) {
        for (double z = 0.05; z < 6; z += 0.05) {
            pfx_stability_warning w[8];
            /* decay: linear drag */
            if (isinf(theory[i].decay) || fabs(z - theory[i].decay) > 0.01 * theory[i].decay) {
                pfx_motion m = one_force(theory[i].integ, PFX_MOTION_DRAG);
                m.forces[0].k = z;
                pfx_motion_choose(&m, 1.0);
                bool expect = z > theory[i].decay;
                int got = unstable_warnings(&m, w);
                CHECK((got > 0) == expect);
                if ((got > 0) != expect)
                    fprintf(stderr, "  %s drag k*dt = %g: %d warnings\n",
                            pfx_integrator_name(theory[i].integ), z, got);
                configs++, warned += got > 0;
                if (got) { /* the suggested substeps do fix it */
                    CHECK(w[0].fix_substeps > 1 && w[0].number == z);
                    CHECK_NEAR(w[0].limit, theory[i].decay, 1e-4 * theory[i].decay);
                    m.substeps = w[0].fix_substeps;
                    pfx_motion_choose(&m, 1.0);
                    CHECK(unstable_warnings(&m, w) == 0);
                    CHECK(z / m.substeps <= theory[i].decay);
                }
            }
            /* oscillator: undamped spring, omega = z */
            if (fabs(z - theory[i].oscillator) > 0.01 * theory[i].oscillator) {
                pfx_motion m = one_force(theory[i].integ, PFX_MOTION_SPRING);
                m.forces[0].k = z * z;
                pfx_motion_choose(&m, 1.0);
                bool expect = z >= theory[i].oscillator;
                int got = unstable_warnings(&m, w);
                CHECK((got > 0) == expect);
                if ((got > 0) != expect)
                    fprintf(stderr, "  %s spring omega*dt = %g: %d warnings\n",
                            pfx_integrator_name(theory[i].integ), z, got);
                configs++, warned += got > 0;
                if (got && w[0].fix_substeps > 0) {
                    if (w[0].fix != m.choice.chosen) { /* Euler/midpoint: another scheme */
                        m.integrator = w[0].fix;
                    }
                    m.substeps = w[0].fix_substeps;
                    pfx_motion_choose(&m, 1.0);
                    CHECK(unstable_warnings(&m, w) == 0);
                }
                /* the attractor's circular frequency sqrt(s/r^3) at its
                 * softening radius goes through the same check */
                pfx_motion a = one_force(theory[i].integ, PFX_MOTION_ATTRACTOR);
                a.forces[0].strength = z * z * 8, a.forces[0].softening = 2;
                pfx_motion_choose(&a, 1.0);
                CHECK((unstable_warnings(&a, w) > 0) == expect);
            }
        }
    }
    fprintf(stderr, "  %d configurations, %d warned\n", configs, warned);
}

/* Oscillation note: Euler-family decay with 1 < k*dt <= 2 flips sign. */
static void test_oscillation_note(void) {
    pfx_motion m = one_force(PFX_INTEGRATOR_SYMPLECTIC, PFX_MOTION_DRAG);
    m.forces[0].k = 1.5;
    pfx_motion_choose(&m, 1.0);
    pfx_stability_warning w[4];
    CHECK(pfx_motion_check_stability(&m, w, 4) == 1);
    CHECK(w[0].kind == PFX_STABILITY_OSCILLATES && w[0].fix == PFX_INTEGRATOR_EXACT &&
          w[0].fix_substeps == 2);
    fprintf(stderr, "  %s\n", w[0].message);
    m.forces[0].k = 0.9;
    pfx_motion_choose(&m, 1.0);
    CHECK(pfx_motion_check_stability(&m, w, 4) == 0);
}

/* The magnetic force: |v| drifts under every scheme but the Boris rotation;
 * the number is the change per gyration, |R(i theta)|^(2 pi / theta) - 1. */
static void test_magnetic_drift(void) {
    const pfx_integrator all[] = {PFX_INTEGRATOR_EULER,    PFX_INTEGRATOR_SYMPLECTIC,
                                  PFX_INTEGRATOR_MIDPOINT, PFX_INTEGRATOR_RK4,
                                  PFX_INTEGRATOR_VERLET,   PFX_INTEGRATOR_BORIS,
                                  PFX_INTEGRATOR_AUTO};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) {
        pfx_motion m = one_force(all[i], PFX_MOTION_MAGNETIC);
        m.forces[0].field[2] = 2, m.forces[0].charge = 1, m.forces[0].mass = 4; /* Omega 0.5 */
        pfx_motion_choose(&m, 1.0);
        pfx_stability_warning w[4];
        size_t n = pfx_motion_check_stability(&m, w, 4);
        bool boris = all[i] == PFX_INTEGRATOR_BORIS || all[i] == PFX_INTEGRATOR_AUTO;
        CHECK(n == (boris ? 0u : 1u));
        if (n == 1) {
            CHECK(w[0].kind == PFX_STABILITY_DRIFT && w[0].fix == PFX_INTEGRATOR_BORIS);
            if (all[i] == PFX_INTEGRATOR_RK4) {
                double th = 0.5, g = sqrt(1 - pow(th, 6) / 72 + pow(th, 8) / 576);
                CHECK_NEAR(w[0].number, pow(g, 2 * 3.141592653589793 / th) - 1, 1e-12);
            }
            if (all[i] == PFX_INTEGRATOR_EULER)
                CHECK_NEAR(w[0].number, pow(1 + 0.25, 3.141592653589793 / 0.5) - 1, 1e-12);
        }
    }
}

/* Exact/boris integrate linear drag exactly: no warning at any k*dt. */
static void test_exact_never_warns(void) {
    for (double z = 0.5; z < 1000; z *= 3) {
        pfx_motion m = one_force(PFX_INTEGRATOR_EXACT, PFX_MOTION_DRAG);
        m.forces[0].k = z;
        pfx_motion_choose(&m, 1.0);
        pfx_stability_warning w[2];
        CHECK(pfx_motion_check_stability(&m, w, 2) == 0);
    }
}

/* The blame line for a blown-up state names the unstable force. */
static void test_blame(void) {
    pfx_motion m = one_force(PFX_INTEGRATOR_EULER, PFX_MOTION_DRAG);
    m.forces[0].k = 30;
    m.forces[0].name = "air";
    pfx_motion_choose(&m, 0.1);
    char buf[256];
    pfx_motion_blame(&m, PFX_BAD_NONFINITE, buf, sizeof buf);
    fprintf(stderr, "  %s\n", buf);
    CHECK(strstr(buf, "'air'") && strstr(buf, "k*dt = 3"));
}

int main(void) {
    RUN(test_measured_limits);
    RUN(test_sweep);
    RUN(test_oscillation_note);
    RUN(test_magnetic_drift);
    RUN(test_exact_never_warns);
    RUN(test_blame);
    return TEST_EXIT();
}
