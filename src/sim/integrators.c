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
