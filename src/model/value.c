/* The pure questions about values and the effect's frames. */
#include <math.h>

#include "model/effect.h"

double pfx_value_max(const pfx_value *v) {
    return v->dist == PFX_DIST_CONST ? v->a : v->dist == PFX_DIST_UNIFORM ? v->b : v->hi;
}

double pfx_value_min(const pfx_value *v) {
    return v->dist == PFX_DIST_CONST ? v->a : v->dist == PFX_DIST_UNIFORM ? v->a : v->lo;
}

pfx_value pfx_value_scaled(pfx_value v, double k) {
    v.a *= k;
    v.b *= k;
    v.lo *= k;
    v.hi *= k;
    return v;
}

long pfx_effect_frame_count(const pfx_effect *e) {
    long n = lround(e->duration * e->fps);
    return n < 1 ? 1 : n;
}
