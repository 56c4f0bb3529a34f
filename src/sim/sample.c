/* The emission samplers. Each is uniform by construction: the inverse-CDF
 * radius for discs (sqrt) and spheres (cbrt), cos(theta) uniform for caps.
 * The biased textbook variants (REFERENCE.md section 3) are not here; the
 * tests carry them to show the uniformity tests can fail. */
#include "sim/sample.h"

#include <math.h>

double pfx_sample_value(const pfx_value *v, pfx_rng *r) {
    switch (v->dist) {
    case PFX_DIST_CONST:
        return v->a;
    case PFX_DIST_UNIFORM:
        return pfx_rng_range(r, v->a, v->b);
    case PFX_DIST_NORMAL: {
        /* Box-Muller; 1 - u keeps the logarithm's argument in (0, 1]. */
        double u1 = 1.0 - pfx_rng_unit(r), u2 = pfx_rng_unit(r);
        double x = v->a + v->b * sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
        return x < v->lo ? v->lo : x > v->hi ? v->hi : x;
    }
    }
    return v->a;
}

void pfx_sample_direction(pfx_rng *r, double out[3]) {
    double z = 2.0 * pfx_rng_unit(r) - 1.0, phi = 2.0 * M_PI * pfx_rng_unit(r);
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    out[0] = s * cos(phi);
    out[1] = s * sin(phi);
    out[2] = z;
}

void pfx_sample_shape(const pfx_shape *s, pfx_rng *r, double out[3]) {
    switch (s->type) {
    case PFX_SHAPE_POINT:
        out[0] = out[1] = out[2] = 0;
        return;
    case PFX_SHAPE_SPHERE: {
        double d[3];
        pfx_sample_direction(r, d);
        double rad = s->radius * cbrt(pfx_rng_unit(r));
        for (int i = 0; i < 3; i++)
            out[i] = d[i] * rad;
        return;
    }
    case PFX_SHAPE_BOX:
        for (int i = 0; i < 3; i++)
            out[i] = (pfx_rng_unit(r) - 0.5) * s->size[i];
        return;
    case PFX_SHAPE_DISC: {
        double rad = s->radius * sqrt(pfx_rng_unit(r)), th = 2.0 * M_PI * pfx_rng_unit(r);
        out[0] = rad * cos(th);
        out[1] = 0;
        out[2] = rad * sin(th);
        return;
    }
    }
}

void pfx_sample_cone(const double axis[3], double spread_deg, pfx_rng *r, double out[3]) {
    double cos_max = cos(spread_deg * M_PI / 180.0);
    double ct = 1.0 - pfx_rng_unit(r) * (1.0 - cos_max);
    double st = sqrt(fmax(0.0, 1.0 - ct * ct)), phi = 2.0 * M_PI * pfx_rng_unit(r);
    /* An orthonormal basis (t, b, axis) without a branch on a fixed up vector
     * (Duff et al. 2017, "Building an orthonormal basis, revisited"). */
    double sign = copysign(1.0, axis[2]);
    double a = -1.0 / (sign + axis[2]), b = axis[0] * axis[1] * a;
    double t[3] = {1.0 + sign * axis[0] * axis[0] * a, sign * b, -sign * axis[0]};
    double bt[3] = {b, sign + axis[1] * axis[1] * a, -axis[1]};
    double cp = st * cos(phi), sp = st * sin(phi);
    for (int i = 0; i < 3; i++)
        out[i] = t[i] * cp + bt[i] * sp + axis[i] * ct;
}
