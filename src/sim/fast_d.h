/* Double kernels for the emission samplers, behind plain C: sine and
 * cosine of a fraction of a turn, and a cube root on [0, 1], by
 * polynomial and bit operations only (no libm call, no branch on the
 * value), so a birth's sampling is inline code the compiler can keep in
 * registers and vectorise, and every build (the AVX2/AVX-512/baseline
 * clones, -ffp-contract=off) gives the same bits. Their error bounds over
 * the whole input range are swept by tests/unit/test_fast_d.c. Internal to
 * src/sim. */
#ifndef PFX_SIM_FAST_D_H
#define PFX_SIM_FAST_D_H

#include <stdint.h>
#include <string.h>

/* sin and cos of 2 pi u for u in [0, 1] to within 3e-16 absolute: the
 * turn is reduced in quarter turns, x = 4 u = k + f with k the nearest
 * integer, which is exact (no pi in the reduction, so no Cody-Waite
 * split), then a = f pi/2 (|a| <= pi/4) goes through fdlibm's
 * __kernel_sin and __kernel_cos polynomials (Sun, 1993: 2^-58 relative
 * on |a| <= pi/4), the quadrant k mod 4 choosing and signing them. */
static inline __attribute__((always_inline)) void pfx_sincos_turn(double u, double *s, double *c) {
    /* k = round(4 u) by the 1.5 2^52 trick: exact for |4 u| < 2^51 */
    const double magic = 6755399441055744.0, sum = u * 4.0 + magic, kf = sum - magic;
    int64_t bits;
    memcpy(&bits, &sum, sizeof bits);
    const int64_t k = bits - 0x4338000000000000LL;
    const double a = (u * 4.0 - kf) * 1.57079632679489661923, z = a * a;
    const double ps =
        a +
        a * z *
            (-1.66666666666666324348e-01 +
             z * (8.33333333332248946124e-03 +
                  z * (-1.98412698298579493134e-04 +
                       z * (2.75573137070700676789e-06 +
                            z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))));
    const double pc =
        1.0 - 0.5 * z +
        z * z *
            (4.16666666666666019037e-02 +
             z * (-1.38888888888741095749e-03 +
                  z * (2.48015872894767294178e-05 +
                       z * (-2.75573143513906633035e-07 +
                            z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
    const int64_t q = k & 3;
    const double sv = (q & 1) ? pc : ps, cv = (q & 1) ? ps : pc;
    *s = (q & 2) ? -sv : sv;
    *c = ((q + 1) & 2) ? -cv : cv;
}

/* The cube root of x in [0, 1] to within 1 ulp (2.3e-16 relative): FreeBSD's
 * cbrt (Bruce Evans, 2005), without its branches. An estimate from the bits
 * (the exponent divided by 3), a polynomial to 23 bits, rounding to 21 bits
 * so the square below is exact, then one Newton step to 53 bits. Inputs
 * under 2^-900 are scaled by 2^900 first (and the root by 2^-300), so
 * subnormals need no special case; 0 gives 0. */
static inline __attribute__((always_inline)) double pfx_cbrt_unit(double x) {
    /* The scalings multiply by 1 or by the power of 2, made from the bits
     * (2^900 and 2^-300 differ from 1.0 by 900 and -300 in the exponent
     * field), so no operation is under a condition and a loop of this
     * vectorises on any clone: with -ftrapping-math the compiler cannot
     * if-convert a multiply it sees as conditional. x 1 is exact. */
    const uint64_t tiny = (uint64_t)0 - (uint64_t)(x < 0x1p-900); /* all ones or 0 */
    const uint64_t up_bits = 0x3ff0000000000000ULL + (tiny & (900ULL << 52)),
                   down_bits = 0x3ff0000000000000ULL - (tiny & (300ULL << 52));
    double up, down;
    memcpy(&up, &up_bits, sizeof up);
    memcpy(&down, &down_bits, sizeof down);
    const double xs = x * up;
    uint64_t hx;
    memcpy(&hx, &xs, sizeof hx);
    /* 715094163 = (1023 - 1023/3 - 0.03306235651) 2^20: the bias, minus
     * a shift that minimises the estimate's error */
    uint64_t ht = (uint64_t)((uint32_t)(hx >> 32) / 3u + 715094163u) << 32;
    double t;
    memcpy(&t, &ht, sizeof t);
    /* t / xs, or t / 1 for 0 (so no division by zero), the divisor also
     * chosen by its bits so that the division is unconditional */
    const uint64_t pos = (uint64_t)0 - (uint64_t)(xs > 0),
                   den_bits = (hx & pos) | (0x3ff0000000000000ULL & ~pos);
    double den;
    memcpy(&den, &den_bits, sizeof den);
    double r = (t * t) * (t / den);
    t = t *
        ((1.87595182427177009643 + r * (-1.88497979543377169875 + r * 1.621429720105354466140)) +
         ((r * r) * r) * (-0.758397934778766047437 + r * 0.145996192886612446982));
    uint64_t bt;
    memcpy(&bt, &t, sizeof bt);
    bt = (bt + 0x80000000ULL) & 0xffffffffc0000000ULL;
    memcpy(&t, &bt, sizeof t);
    const double sq = t * t, w = t + t;
    double q = xs / sq;
    q = (q - t) / (w + q);
    t = t + t * q;
    t = t * down;
    /* x > 0 ? t : +0.0, by the bits (+0.0 is all zeros), for the same
     * reason */
    uint64_t out;
    memcpy(&out, &t, sizeof out);
    out &= (uint64_t)0 - (uint64_t)(x > 0);
    memcpy(&t, &out, sizeof t);
    return t;
}

#endif
