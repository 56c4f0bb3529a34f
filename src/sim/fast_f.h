/* Float kernels the compiler vectorises, behind plain C: a sine and cosine
 * by polynomial (no libm call, so a particle loop that needs them stays one
 * vectorised loop), and the float operators built on it. The motion kernels
 * (motion_impl.h) call these for the pools, which are float; the double
 * instantiation keeps libm for the accuracy harness. Internal to src/sim. */
#ifndef PFX_SIM_FAST_F_H
#define PFX_SIM_FAST_F_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "base/clones.h"
#include "model/motion.h"

/* sin and cos of x (|x| <= 1e5: the caller clamps, in a loop of its own,
 * or the compiler will not vectorise the loop that calls this) to within
 * 2e-7 absolute: x = k pi/2 + r, |r| <= pi/4 (k rounded to nearest), by a
 * three-part pi/2 (Cody and Waite), then the minimax polynomials of
 * Cephes' sinf and cosf on r (Moshier, "Methods and Programs for
 * Mathematical Functions", 1989), the quadrant k mod 4 choosing and
 * signing them. Selects only, no branches. */
static inline __attribute__((always_inline)) void pfx_sincos_f(float x, float *s, float *c) {
    /* k = round(x 2/pi) by the 1.5 2^23 trick: adding it leaves k in the
     * low bits of the sum, and subtracting it gives k as a float, both
     * exactly for |k| < 2^22 (no float-to-int conversion, which would need
     * its own range check). */
    const float magic = 12582912.0f, sum = x * 0.636619772f + magic, kf = sum - magic;
    int32_t bits;
    memcpy(&bits, &sum, sizeof bits);
    const int32_t k = bits - 0x4b400000;
    float r = x - kf * 1.5703125f;
    r = r - kf * 4.837512969970703125e-4f;
    r = r - kf * 7.549789948768648e-8f;
    const float r2 = r * r;
    const float ps =
        r + r * r2 * (-1.6666654611e-1f + r2 * (8.3321608736e-3f + r2 * -1.9515295891e-4f));
    const float pc =
        1.0f - 0.5f * r2 +
        r2 * r2 *
            (4.166664568298827e-2f + r2 * (-1.388731625493765e-3f + r2 * 2.443315711809948e-5f));
    const int32_t q = k & 3;
    const float sv = (q & 1) ? pc : ps, cv = (q & 1) ? ps : pc;
    *s = (q & 2) ? -sv : sv;
    *c = ((q + 1) & 2) ? -cv : cv;
}

/* cos x - 1 for |x| <= pi/4 by the same polynomial without its 1, so a
 * small turn applied as x + (q (cos - 1) + k sin) is good to float
 * precision in the change itself, not only in the whole. */
static inline __attribute__((always_inline)) float pfx_cosm1_small_f(float x) {
    const float r2 = x * x;
    return -0.5f * r2 +
           r2 * r2 *
               (4.166664568298827e-2f + r2 * (-1.388731625493765e-3f + r2 * 2.443315711809948e-5f));
}

/* The Sims vortex of force F (kind VORTEX) over n particles for time h:
 * each position turns about the axis by strength f(r) w h and moves in by
 * inflow f(r) w h (w the region weight per particle; NULL: 1), as motion_impl.h's
 * double operator does, in float. f(r) is read at (EX, EY, EZ) (the
 * midpoint of a second-order step), or at the position itself where EX is
 * NULL. */
void pfx_vortex_f(const pfx_motion_force *F, size_t n, const float *w, const float *EX,
                  const float *EY, const float *EZ, float *X, float *Y, float *Z, double h);

/* The attractor of force F (kind ATTRACTOR) over n <= PFX_MOTION_BLOCK
 * particles: adds w times its acceleration at (X, Y, Z) to (ax, ay, az)
 * (w NULL: 1; fresh: to 0, the columns unread), as motion_impl.h's double
 * force loop does, in float and in the same order of operations (so the
 * same bits as that loop instantiated in float): one loop per falloff, so
 * each is straight arithmetic with sqrtf and one divide. */
void pfx_attractor_f(const pfx_motion_force *F, size_t n, const float *w, const float *X,
                     const float *Y, const float *Z, bool fresh, float *ax, float *ay, float *az);

#endif
