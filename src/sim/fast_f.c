/* The float operators of fast_f.h: straight particle loops with selects
 * instead of branches, so each vectorises (and gets an AVX2 copy on
 * x86-64). The arithmetic mirrors the double operators of motion_impl.h. */
#include "sim/fast_f.h"

#include <math.h>
#include <string.h>

/* sin and cos - 1 of n angles (|a| <= 1e5): a loop of its own, which vectorises where the
 * fused particle loop would not (the compiler threads the clamps' branches
 * through it). */
static inline __attribute__((always_inline)) void sincos_n(size_t n, const float *restrict a,
                                                           float *restrict s, float *restrict c) {
    for (size_t j = 0; j < n; j++)
        pfx_sincos_f(a[j], &s[j], &c[j]);
    for (size_t j = 0; j < n; j++) { /* c - 1, exact in itself for small angles */
        /* (a blend of the bits, which the compiler cannot turn into a
         * branch round the polynomial) */
        const float small = pfx_cosm1_small_f(a[j]), big = c[j] - 1.0f;
        const int32_t mask = -(int32_t)(a[j] * a[j] <= 0.61685f); /* |a| <= pi/4 */
        int32_t bs, bb;
        memcpy(&bs, &small, sizeof bs);
        memcpy(&bb, &big, sizeof bb);
        bs = (bs & mask) | (bb & ~mask);
        memcpy(&c[j], &bs, sizeof bs);
    }
}

/* The vortex's turn where no particle turns by more than 0.78 rad a step
 * and there is no inflow (the common case: 90 deg/s at 120 steps/s turns
 * by 0.013 rad): every angle is within pi/4, where pfx_sincos_f takes its
 * polynomials at r = a itself (k = 0, r = a exactly) and c - 1 is
 * pfx_cosm1_small_f(a), so the whole operator is one loop, with the same
 * bits as the general path below. The position is kept or replaced by a
 * mask on its bits (f > 0: its bits in [1, 0x7f800000]), which the
 * compiler cannot turn into a branch. wj: w[j], or 1 without a region. */
#define VORTEX_SMALL_LOOP(wj)                                                                      \
    for (size_t j = 0; j < n; j++) {                                                               \
        const float rx = X[j] - cx, ry = Y[j] - cy, rz = Z[j] - cz;                                \
        const float al = rx * ux + ry * uy + rz * uz;                                              \
        const float qx = rx - al * ux, qy = ry - al * uy, qz = rz - al * uz;                       \
        const float r2 = (qx * qx + qy * qy + qz * qz) * inv_rad2;                                 \
        int32_t bits;                                                                              \
        memcpy(&bits, &r2, sizeof bits);                                                           \
        bits = bits < 0x3f800000 ? bits : 0x3f800000;                                              \
        float rc;                                                                                  \
        memcpy(&rc, &bits, sizeof rc);                                                             \
        const float f = (rc * rc - 2.0f * rc + 1.0f) / (1.0f + d * rc) * (wj);                     \
        const float a = turn * f, a2 = a * a;                                                      \
        const float s =                                                                            \
            a + a * a2 * (-1.6666654611e-1f + a2 * (8.3321608736e-3f + a2 * -1.9515295891e-4f));   \
        const float cm1 = pfx_cosm1_small_f(a);                                                    \
        const float kx = uy * qz - uz * qy, ky = uz * qx - ux * qz, kz = ux * qy - uy * qx;        \
        const float nx = X[j] + (qx * cm1 + kx * s), ny = Y[j] + (qy * cm1 + ky * s),              \
                    nz = Z[j] + (qz * cm1 + kz * s);                                               \
        int32_t bf, bx, by, bz, ox, oy, oz;                                                        \
        memcpy(&bf, &f, sizeof bf);                                                                \
        const int32_t in = -(int32_t)((uint32_t)bf - 1u < 0x7f800000u);                            \
        memcpy(&bx, &nx, sizeof bx), memcpy(&by, &ny, sizeof by), memcpy(&bz, &nz, sizeof bz);     \
        memcpy(&ox, &X[j], sizeof ox), memcpy(&oy, &Y[j], sizeof oy),                              \
            memcpy(&oz, &Z[j], sizeof oz);                                                         \
        bx = (bx & in) | (ox & ~in), by = (by & in) | (oy & ~in), bz = (bz & in) | (oz & ~in);     \
        memcpy(&X[j], &bx, sizeof bx), memcpy(&Y[j], &by, sizeof by),                              \
            memcpy(&Z[j], &bz, sizeof bz);                                                         \
    }

PFX_CLONES
void pfx_vortex_f(const pfx_motion_force *F, size_t n, const float *restrict w, const float *EX,
                  const float *EY, const float *EZ, float *restrict X, float *restrict Y,
                  float *restrict Z, double h) {
    enum { CHUNK = 64 };
    const float ux = (float)F->axis[0], uy = (float)F->axis[1], uz = (float)F->axis[2];
    const float cx = (float)F->center[0], cy = (float)F->center[1], cz = (float)F->center[2];
    const float inv_rad2 = (float)(1.0 / (F->radius * F->radius)), d = (float)F->sims_d;
    const float turn = (float)(F->strength * h), pull = (float)(F->inflow * h);
    const int inflow = F->inflow != 0;
    /* |a| <= |turn| f w <= |turn|: f <= 1, 0 <= w <= 1 */
    if (!EX && !inflow && fabs(F->strength * h) <= 0.78 && fabsf(turn) <= 0.78f) {
        if (w)
            VORTEX_SMALL_LOOP(w[j])
        else
            VORTEX_SMALL_LOOP(1.0f)
        return;
    }
    float fw[CHUNK], ang[CHUNK], sn[CHUNK], cs[CHUNK], nxs[CHUNK], nys[CHUNK], nzs[CHUNK],
        one[CHUNK];
    for (size_t j = 0; j < CHUNK; j++)
        one[j] = 1;
    for (size_t j0 = 0; j0 < n; j0 += CHUNK) {
        const size_t m = n - j0 < CHUNK ? n - j0 : CHUNK;
        float *x = X + j0, *y = Y + j0, *z = Z + j0;
        const float *wj = w ? w + j0 : one;
        const float *ex = EX ? EX + j0 : x, *ey = EX ? EY + j0 : y, *ez = EX ? EZ + j0 : z;
        for (size_t j = 0; j < m; j++) {
            const float rx = ex[j] - cx, ry = ey[j] - cy, rz = ez[j] - cz;
            const float al = rx * ux + ry * uy + rz * uz;
            const float qx = rx - al * ux, qy = ry - al * uy, qz = rz - al * uz;
            const float r2 = (qx * qx + qy * qy + qz * qz) * inv_rad2;
            /* f(r) = (r^4 - 2 r^2 + 1) / (1 + d r^2), 0 from r = 1 on: r^2 is
             * clamped to 1, where the numerator is exactly 0 */
            int32_t bits; /* r2 >= 0 (or NaN): its bits order as it does */
            memcpy(&bits, &r2, sizeof bits);
            bits = bits < 0x3f800000 ? bits : 0x3f800000; /* min(r2, 1) */
            float rc;
            memcpy(&rc, &bits, sizeof rc);
            fw[j] = (rc * rc - 2.0f * rc + 1.0f) / (1.0f + d * rc) * wj[j];
        }
        for (size_t j = 0; j < m; j++) { /* sincos_n's range */
            const float a = turn * fw[j];
            ang[j] = a < 1e5f ? (a > -1e5f ? a : -1e5f) : 1e5f;
        }
        sincos_n(m, ang, sn, cs);
        /* The turned offset g (q cos + k sin) less q, added to the point
         * itself, so a small turn moves it by a small, accurate amount; g
         * pulls it in (never past the axis; not at all on the axis). */
        for (size_t j = 0; j < m && !inflow; j++) {
            const float rx = x[j] - cx, ry = y[j] - cy, rz = z[j] - cz;
            const float al = rx * ux + ry * uy + rz * uz;
            const float qx = rx - al * ux, qy = ry - al * uy, qz = rz - al * uz;
            const float s = sn[j], cm1 = cs[j];
            const float kx = uy * qz - uz * qy, ky = uz * qx - ux * qz, kz = ux * qy - uy * qx;
            nxs[j] = x[j] + (qx * cm1 + kx * s);
            nys[j] = y[j] + (qy * cm1 + ky * s);
            nzs[j] = z[j] + (qz * cm1 + kz * s);
        }
        for (size_t j = 0; j < m && inflow; j++) {
            const float rx = x[j] - cx, ry = y[j] - cy, rz = z[j] - cz;
            const float al = rx * ux + ry * uy + rz * uz;
            const float qx = rx - al * ux, qy = ry - al * uy, qz = rz - al * uz;
            const float rp = sqrtf(qx * qx + qy * qy + qz * qz);
            const float s = sn[j], cm1 = cs[j];
            const float kx = uy * qz - uz * qy, ky = uz * qx - ux * qz, kz = ux * qy - uy * qx;
            float gm1 = -pull * fw[j] / rp; /* g - 1; inf or NaN on the axis: not taken */
            gm1 = gm1 > -1.0f ? gm1 : -1.0f;
            gm1 = rp > 0 ? gm1 : 0.0f;
            const float g = 1.0f + gm1;
            nxs[j] = x[j] + (g * (qx * cm1 + kx * s) + gm1 * qx);
            nys[j] = y[j] + (g * (qy * cm1 + ky * s) + gm1 * qy);
            nzs[j] = z[j] + (g * (qz * cm1 + kz * s) + gm1 * qz);
        }
        /* Outside the vortex (f = 0) the position stays bit for bit: a
         * select of its own, which the compiler does not sink into a
         * branch round the arithmetic above. */
        for (size_t j = 0; j < m; j++) {
            const int in = fw[j] > 0;
            const float ox = x[j], oy = y[j], oz = z[j];
            x[j] = in ? nxs[j] : ox;
            y[j] = in ? nys[j] : oy;
            z[j] = in ? nzs[j] : oz;
        }
    }
}
#undef VORTEX_SMALL_LOOP

/* One falloff's loop: den(q, sq) the denominator of g = s / den for
 * q = r^2 + e^2 and sq = sqrt(q). g is kept (q > 0, inside the cut-off) or
 * zeroed by a mask on its bits, with the tests on the bits of q and r^2
 * (non-negative floats order as their bits do): a float compare or select
 * here would be turned into a branch round the divide (which may trap), and
 * the loop would not vectorise. The same g as the double loop's select. */
#define ATTRACT_LOOP(den, fresh, wj)                                                               \
    for (size_t j = 0; j < n; j++) {                                                               \
        const float dx = cx - X[j], dy = cy - Y[j], dz = cz - Z[j];                                \
        const float r2 = dx * dx + dy * dy + dz * dz, q = r2 + e2, sq = sqrtf(q);                  \
        const float g0 = s / (den);                                                                \
        (void)sq; /* (the linear falloff has no use for it) */                                     \
        int32_t bq, br, bg;                                                                        \
        memcpy(&bq, &q, sizeof bq);                                                                \
        memcpy(&br, &r2, sizeof br);                                                               \
        memcpy(&bg, &g0, sizeof bg);                                                               \
        /* q > 0 (q in (0, inf]: not NaN) and r2 <= cut2 (both >= 0) */                            \
        bg &= -(int32_t)(((uint32_t)bq - 1u < 0x7f800000u) & (br <= bcut));                        \
        float g;                                                                                   \
        memcpy(&g, &bg, sizeof g);                                                                 \
        g *= (wj);                                                                                 \
        ax[j] = (fresh ? 0.0f : ax[j]) + g * dx;                                                   \
        ay[j] = (fresh ? 0.0f : ay[j]) + g * dy;                                                   \
        az[j] = (fresh ? 0.0f : az[j]) + g * dz;                                                   \
    }

#define ATTRACT_CASES(den)                                                                         \
    if (fresh && w)                                                                                \
        ATTRACT_LOOP(den, 1, w[j])                                                                 \
    else if (fresh)                                                                                \
        ATTRACT_LOOP(den, 1, 1.0f)                                                                 \
    else if (w)                                                                                    \
        ATTRACT_LOOP(den, 0, w[j])                                                                 \
    else                                                                                           \
        ATTRACT_LOOP(den, 0, 1.0f)

PFX_CLONES
void pfx_attractor_f(const pfx_motion_force *F, size_t n, const float *restrict w,
                     const float *restrict X, const float *restrict Y, const float *restrict Z,
                     bool fresh, float *restrict ax, float *restrict ay, float *restrict az) {
    const float cx = (float)F->center[0], cy = (float)F->center[1], cz = (float)F->center[2];
    const float s = (float)F->strength, e2 = (float)(F->softening * F->softening);
    const double Ld = F->ref_radius > 0 ? F->ref_radius : 1.0;
    const float L = (float)Ld, L2 = (float)(Ld * Ld);
    const float cut2 = F->radius > 0 ? (float)(F->radius * F->radius) : INFINITY;
    int32_t bcut;
    memcpy(&bcut, &cut2, sizeof bcut);
    /* (fresh and w constant in each copy: the sum starts at 0 + g d, the
     * same bits as a column zeroed first; g times 1 is g) */
    switch (F->falloff) {
    case PFX_FALLOFF_INVERSE_SQUARE:
        ATTRACT_CASES(q * sq)
        break;
    case PFX_FALLOFF_LINEAR:
        ATTRACT_CASES(L * q)
        break;
    default:
        ATTRACT_CASES(L2 * sq)
        break;
    }
}
#undef ATTRACT_CASES
#undef ATTRACT_LOOP
