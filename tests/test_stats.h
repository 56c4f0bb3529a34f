/* Statistics shared by the sampling tests: the chi-square critical value
 * and the small geometry helpers their equal-measure bins use. */
#ifndef PFX_TEST_STATS_H
#define PFX_TEST_STATS_H

#include <math.h>

#include "base/rng.h"

#define PI 3.14159265358979323846

/* The upper p = 0.001 point of chi-square with k degrees of freedom, by the
 * Wilson-Hilferty approximation: k (1 - 2/(9k) + z sqrt(2/(9k)))^3 with z the
 * standard normal's upper 0.001 point (checked against tables in
 * test_sampling.c). */
static inline double chi2_critical(int k) {
    const double z = 3.090232306167813;
    double h = 2.0 / (9.0 * k);
    return k * pow(1 - h + z * sqrt(h), 3);
}

typedef void (*sampler_fn)(const void *ctx, pfx_rng *r, double out[3]);
/* The bin of a point, or -1 when the point is outside the support. */
typedef int (*binner_fn)(const void *ctx, const double p[3]);

static inline int clampi(double x, int n) {
    int i = (int)floor(x * n);
    return i < 0 ? 0 : i >= n ? n - 1 : i;
}

static inline double norm3(const double p[3]) {
    return sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
}
static inline double dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
/* Azimuth fraction in [0, 1) of the angle atan2(y, x). */
static inline double azimuth01(double y, double x) {
    double a = atan2(y, x) / (2 * PI);
    return a < 0 ? a + 1 : a;
}

#endif
