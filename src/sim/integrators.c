/* The integrators, instantiated twice from motion_impl.h: in float for the
 * simulation's pool and in double for the accuracy harness and the tests,
 * so both run one arithmetic. Choosing a scheme, stability and the noise
 * live elsewhere (motion.c, stability.c). */
#include "sim/motion.h"

#include <string.h>
#include <tgmath.h>

#include "model/effect.h"
#include "sim/fast_f.h"

#define PFX_CAT_(a, b) a##b
#define PFX_CAT(a, b) PFX_CAT_(a, b)

#define PFX_REAL float
#define PFX_SUFFIX _f
#define PFX_POOL pfx_motion_pool_f
#define PFX_REAL_IS_FLOAT 1
#include "sim/motion_impl.h"
#undef PFX_REAL_IS_FLOAT
#undef PFX_REAL
#undef PFX_SUFFIX
#undef PFX_POOL

#define PFX_REAL double
#define PFX_SUFFIX _d
#define PFX_POOL pfx_motion_pool_d
#include "sim/motion_impl.h"
#undef PFX_REAL
#undef PFX_SUFFIX
#undef PFX_POOL

void pfx_motion_accel_d(const pfx_motion_plan *m, const pfx_motion_pool_d *pool, size_t i0,
                        size_t n, const double *x, const double *y, const double *z,
                        const double *vx, const double *vy, const double *vz, double t, double *ax,
                        double *ay, double *az) {
    for (size_t b = 0; b < n; b += PFX_MOTION_BLOCK) {
        size_t nb = n - b < PFX_MOTION_BLOCK ? n - b : PFX_MOTION_BLOCK;
        accel_d(m, pool, i0 + b, nb, x + b, y + b, z + b, vx + b, vy + b, vz + b, t, 0, ax + b,
                ay + b, az + b);
    }
}
