/* The float operators of fast_f.h: straight particle loops with selects
 * instead of branches, so each vectorises (and gets an AVX2 copy on
 * x86-64). The arithmetic mirrors the double operators of motion_impl.h. */
#include "sim/fast_f.h"

#include <math.h>
#include <string.h>

/* sin and cos of n angles: a loop of its own, which vectorises where the
 * fused particle loop would not (the compiler threads the clamps' branches
 * through it). */
static inline __attribute__((always_inline)) void sincos_n(size_t n, const float *restrict a,
                                                           float *restrict s, float *restrict c) {
    for (size_t j = 0; j < n; j++)
        pfx_sincos_f(a[j], &s[j], &c[j]);
}

PFX_CLONES
void pfx_vortex_f(const pfx_motion_force *F, size_t n, const float *restrict w, float *restrict X,
                  float *restrict Y, float *restrict Z, double h) {
    enum { CHUNK = 64 };
    const float ux = (float)F->axis[0], uy = (float)F->axis[1], uz = (float)F->axis[2];
    const float cx = (float)F->center[0], cy = (float)F->center[1], cz = (float)F->center[2];
    const float inv_rad2 = (float)(1.0 / (F->radius * F->radius)), d = (float)F->sims_d;
    const float turn = (float)(F->strength * h), pull = (float)(F->inflow * h);
    const int inflow = F->inflow != 0;
    float fw[CHUNK], ang[CHUNK], sn[CHUNK], cs[CHUNK], nxs[CHUNK], nys[CHUNK], nzs[CHUNK];
    for (size_t j0 = 0; j0 < n; j0 += CHUNK) {
        const size_t m = n - j0 < CHUNK ? n - j0 : CHUNK;
        float *x = X + j0, *y = Y + j0, *z = Z + j0;
        const float *wj = w + j0;
        for (size_t j = 0; j < m; j++) {
            const float rx = x[j] - cx, ry = y[j] - cy, rz = z[j] - cz;
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
        for (size_t j = 0; j < m; j++) {
            const float rx = x[j] - cx, ry = y[j] - cy, rz = z[j] - cz;
            const float al = rx * ux + ry * uy + rz * uz;
            const float qx = rx - al * ux, qy = ry - al * uy, qz = rz - al * uz;
            const float rp = sqrtf(qx * qx + qy * qy + qz * qz);
            const float s = sn[j], c = cs[j];
            const float kx = uy * qz - uz * qy, ky = uz * qx - ux * qz, kz = ux * qy - uy * qx;
            /* the pull in, never past the axis; none on the axis itself (in
             * scratch: where f = 0 the select below keeps the old point) */
            float g = 1.0f - pull * fw[j] / rp; /* inf or NaN on the axis: not taken */
            g = g > 0 ? g : 0.0f;
            g = (inflow & (rp > 0)) ? g : 1.0f;
            const float nx = (qx * c + kx * s) * g, ny = (qy * c + ky * s) * g,
                        nz = (qz * c + kz * s) * g;
            nxs[j] = cx + al * ux + nx;
            nys[j] = cy + al * uy + ny;
            nzs[j] = cz + al * uz + nz;
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
