/* The random sampling behind emission: the PCG32 generator against the
 * published reference outputs, value sampling (constant, uniform, clamped
 * normal) against its moments, chi-square uniformity of the shape and
 * direction samplers over equal-measure bins, and the gradient lookup table
 * against linear interpolation. Every statistical test is also run on a
 * deliberately biased sampler written here, which it must reject: a test
 * that cannot fail proves nothing. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "base/rng.h"
#include "compile/compile.h"
#include "sim/sample.h"
#include "test.h"
#include "test_compile.h"
#include "test_stats.h"

#define N_CHI 200000
#define N_MOMENTS 1000000

/* ---- PCG32 ---- */

/* pcg32-demo (O'Neill's pcg-c-basic) seeds with pcg32_srandom_r(&rng, 42u,
 * 54u) and prints these first outputs. */
static void test_pcg32_reference(void) {
    static const uint32_t want[] = {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u,
                                    0x83d2f293u, 0xbfa4784bu, 0xcbed606eu};
    pfx_rng r;
    pfx_rng_seed(&r, 42, 54);
    for (size_t i = 0; i < sizeof want / sizeof *want; i++) {
        uint32_t got = pfx_rng_next(&r);
        if (got != want[i])
            fprintf(stderr, "  output %zu: got 0x%08x, want 0x%08x\n", i, got, want[i]);
        CHECK(got == want[i]);
    }
}

/* Two streams of one seed (and two seeds of one stream) are different
 * sequences: over 1000 outputs, equal outputs at the same position occur
 * with probability 2^-32 each, so more than 2 means the streams coincide. */
static int matches(uint64_t seed_a, uint64_t stream_a, uint64_t seed_b, uint64_t stream_b) {
    pfx_rng a, b;
    pfx_rng_seed(&a, seed_a, stream_a);
    pfx_rng_seed(&b, seed_b, stream_b);
    int same = 0;
    for (int i = 0; i < 1000; i++)
        same += pfx_rng_next(&a) == pfx_rng_next(&b);
    return same;
}

static void test_pcg32_streams_differ(void) {
    CHECK(matches(42, 54, 42, 54) == 1000); /* the comparison itself works */
    CHECK(matches(42, 54, 42, 55) <= 2);
    CHECK(matches(42, 54, 43, 54) <= 2);
    CHECK(matches(7, pfx_rng_stream_for("flame"), 7, pfx_rng_stream_for("embers")) <= 2);
    CHECK(matches(7, pfx_rng_stream_for("a"), 7, pfx_rng_stream_for("b")) <= 2);
    CHECK(pfx_rng_stream_for("flame") == pfx_rng_stream_for("flame"));
}

/* A biased unit: 1% short of the top of the interval. */
static double biased_unit(pfx_rng *r) { return 0.99 * pfx_rng_unit(r); }

/* Every value in [0, 1); the mean of n units within 5 standard errors of
 * 1/2 (the standard deviation of a unit is 1/sqrt(12)). */
static bool unit_ok(double (*unit)(pfx_rng *), double *z_out) {
    pfx_rng r;
    pfx_rng_seed(&r, 2024, 1);
    double sum = 0;
    bool in_range = true;
    for (int i = 0; i < N_MOMENTS; i++) {
        double u = unit(&r);
        in_range &= u >= 0.0 && u < 1.0;
        sum += u;
    }
    double z = (sum / N_MOMENTS - 0.5) / sqrt(1.0 / 12.0 / N_MOMENTS);
    *z_out = z;
    return in_range && fabs(z) < 5.0;
}

static void test_pcg32_unit(void) {
    double z, zb;
    CHECK(unit_ok(pfx_rng_unit, &z));
    CHECK(!unit_ok(biased_unit, &zb));
    fprintf(stderr, "  unit mean: z = %.2f; biased unit: z = %.2f (bound 5)\n", z, zb);
    /* The largest possible unit, (2^53 - 1) / 2^53, is still below 1. */
    CHECK((double)((uint64_t)(UINT32_MAX >> 5) * 67108864.0 + (UINT32_MAX >> 6)) *
              (1.0 / 9007199254740992.0) <
          1.0);
}

/* ---- Value sampling ---- */

/* pfx_rng_units (the births' draws, taken 16 outputs at a time) gives
 * the units n calls of pfx_rng_unit give, bit for bit, and leaves the
 * generator (state and count of draws) where they leave it, for runs
 * shorter than its lanes, across its chunks and between. */
static void test_pcg32_units(void) {
    static const size_t runs[] = {0, 1, 2, 7, 8, 15, 16, 17, 127, 128, 129, 1000, 3333};
    static double want[3333], got[3333 + 1];
    for (size_t k = 0; k < sizeof runs / sizeof *runs; k++) {
        const size_t n = runs[k];
        pfx_rng a, b;
        pfx_rng_seed(&a, 0x853c49e6748fea9bULL + k, 0xda3e39cb94b95bdbULL ^ k);
        pfx_rng_advance(&a, 3 * k);
        b = a;
        for (size_t i = 0; i < n; i++)
            want[i] = pfx_rng_unit(&a);
        got[n] = -1;
        pfx_rng_units(&b, got, n);
        CHECK(!memcmp(want, got, n * sizeof *got));
        CHECK(got[n] == -1); /* nothing past the run */
        CHECK(a.state == b.state && a.inc == b.inc && a.draws == b.draws);
        CHECK(pfx_rng_next(&a) == pfx_rng_next(&b));
    }
}

static void test_value_const(void) {
    pfx_value v = {.dist = PFX_DIST_CONST, .a = 2.5, .b = 99};
    pfx_rng r, before;
    pfx_rng_seed(&r, 5, 6);
    before = r;
    for (int i = 0; i < 10; i++)
        CHECK(pfx_sample_value(&v, &r) == 2.5);
    CHECK(r.state == before.state && r.inc == before.inc);
}

/* Moments of n samples. */
typedef struct moments {
    double mean, var, lo, hi;
} moments;

typedef double (*value_fn)(const pfx_value *v, pfx_rng *r);

static moments sample_moments(value_fn f, const pfx_value *v, uint64_t seed, int n) {
    pfx_rng r;
    pfx_rng_seed(&r, seed, 3);
    moments m = {0, 0, INFINITY, -INFINITY};
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; i++) {
        double x = f(v, &r);
        sum += x;
        sum2 += x * x;
        m.lo = fmin(m.lo, x);
        m.hi = fmax(m.hi, x);
    }
    m.mean = sum / n;
    m.var = (sum2 - sum * sum / n) / (n - 1);
    return m;
}

/* Uniform on [a, b]: mean (a+b)/2, variance w^2/12 (w = b - a). The sample
 * mean has standard error w/sqrt(12 n); the sample variance has standard
 * error sqrt((mu4 - sigma^4) / n) with mu4 = w^4/80, sigma^4 = w^4/144. */
static bool uniform_ok(value_fn f, const pfx_value *v, double *zm, double *zv) {
    moments m = sample_moments(f, v, 11, N_MOMENTS);
    double w = v->b - v->a;
    *zm = (m.mean - (v->a + v->b) / 2) / (w / sqrt(12.0 * N_MOMENTS));
    *zv = (m.var - w * w / 12) / sqrt(pow(w, 4) * (1.0 / 80 - 1.0 / 144) / N_MOMENTS);
    return m.lo >= v->a && m.hi <= v->b && fabs(*zm) < 5 && fabs(*zv) < 5;
}

/* Biased: right mean, variance 4% low (squeezed towards the middle). */
static double squeezed_uniform(const pfx_value *v, pfx_rng *r) {
    double m = (v->a + v->b) / 2;
    return m + 0.98 * (pfx_rng_range(r, v->a, v->b) - m);
}
/* Biased: right range, mean pulled low (u^1.05). */
static double skewed_uniform(const pfx_value *v, pfx_rng *r) {
    return v->a + (v->b - v->a) * pow(pfx_rng_unit(r), 1.05);
}

static void test_value_uniform(void) {
    pfx_value v = {.dist = PFX_DIST_UNIFORM, .a = -1.5, .b = 4.0};
    double zm, zv;
    CHECK(uniform_ok(pfx_sample_value, &v, &zm, &zv));
    fprintf(stderr, "  uniform: z(mean) = %.2f, z(var) = %.2f (bound 5)\n", zm, zv);
    CHECK(!uniform_ok(squeezed_uniform, &v, &zm, &zv));
    fprintf(stderr, "  squeezed uniform: z(mean) = %.2f, z(var) = %.2f\n", zm, zv);
    CHECK(!uniform_ok(skewed_uniform, &v, &zm, &zv));
    fprintf(stderr, "  skewed uniform: z(mean) = %.2f, z(var) = %.2f\n", zm, zv);
    /* One draw per sample: the stream stays aligned. */
    pfx_rng a, b;
    pfx_rng_seed(&a, 1, 2);
    pfx_rng_seed(&b, 1, 2);
    pfx_sample_value(&v, &a);
    pfx_rng_unit(&b);
    CHECK(a.state == b.state);
}

static double phi_cdf(double x) { return 0.5 * erfc(-x / sqrt(2.0)); }

/* Normal (mean mu, sd s) with a clamp wide enough to never bind: the sample
 * mean has standard error s/sqrt(n), the sample variance sqrt(2/n) s^2; the
 * fraction within one sd of the mean is 2 Phi(1) - 1 (binomial error), which
 * rejects a non-normal shape with the right moments. */
static bool normal_ok(value_fn f, const pfx_value *v, double z[3]) {
    pfx_rng r;
    pfx_rng_seed(&r, 77, 3);
    double sum = 0, sum2 = 0, inside = 0;
    for (int i = 0; i < N_MOMENTS; i++) {
        double x = f(v, &r);
        sum += x;
        sum2 += x * x;
        inside += fabs(x - v->a) < v->b;
    }
    double n = N_MOMENTS, mean = sum / n, var = (sum2 - sum * sum / n) / (n - 1);
    double p = 2 * phi_cdf(1) - 1;
    z[0] = (mean - v->a) / (v->b / sqrt(n));
    z[1] = (var - v->b * v->b) / (sqrt(2.0 / n) * v->b * v->b);
    z[2] = (inside / n - p) / sqrt(p * (1 - p) / n);
    return fabs(z[0]) < 5 && fabs(z[1]) < 5 && fabs(z[2]) < 5;
}

/* Biased: Box-Muller without the factor 2 under the root (sd / sqrt 2). */
static double narrow_normal(const pfx_value *v, pfx_rng *r) {
    double u1 = 1.0 - pfx_rng_unit(r), u2 = pfx_rng_unit(r);
    return v->a + v->b * sqrt(-log(u1)) * cos(2 * PI * u2);
}
/* Biased: a uniform with the normal's mean and sd (the wrong shape). */
static double flat_normal(const pfx_value *v, pfx_rng *r) {
    return v->a + v->b * sqrt(3.0) * (2 * pfx_rng_unit(r) - 1);
}

static void test_value_normal(void) {
    pfx_value v = {
        .dist = PFX_DIST_NORMAL, .a = 3.0, .b = 0.75, .lo = 3.0 - 20 * 0.75, .hi = 3.0 + 20 * 0.75};
    double z[3];
    CHECK(normal_ok(pfx_sample_value, &v, z));
    fprintf(stderr, "  normal: z(mean) = %.2f, z(var) = %.2f, z(P|x-m|<sd) = %.2f (bound 5)\n",
            z[0], z[1], z[2]);
    CHECK(!normal_ok(narrow_normal, &v, z));
    fprintf(stderr, "  narrow normal: z = %.1f, %.1f, %.1f\n", z[0], z[1], z[2]);
    CHECK(!normal_ok(flat_normal, &v, z));
    fprintf(stderr, "  flat normal: z = %.1f, %.1f, %.1f\n", z[0], z[1], z[2]);

    /* Clamped to [lo, hi] = [mu - 0.5 sd, mu + 1.5 sd]: nothing outside, and
     * the clamps take the tails: P(x = lo) = Phi(-0.5), P(x = hi) =
     * 1 - Phi(1.5), each within 5 binomial standard errors. */
    pfx_value c = {.dist = PFX_DIST_NORMAL, .a = 0.0, .b = 1.0, .lo = -0.5, .hi = 1.5};
    pfx_rng r;
    pfx_rng_seed(&r, 8, 9);
    double at_lo = 0, at_hi = 0, n = N_MOMENTS;
    bool inside = true;
    for (int i = 0; i < N_MOMENTS; i++) {
        double x = pfx_sample_value(&c, &r);
        inside &= x >= c.lo && x <= c.hi;
        at_lo += x == c.lo;
        at_hi += x == c.hi;
    }
    CHECK(inside);
    double plo = phi_cdf(-0.5), phi = 1 - phi_cdf(1.5);
    CHECK_NEAR(at_lo / n, plo, 5 * sqrt(plo * (1 - plo) / n));
    CHECK_NEAR(at_hi / n, phi, 5 * sqrt(phi * (1 - phi) / n));
}

/* ---- Blocks: the simulation's path ---- */

#define BLOCK_N 3001

/* The block forms births use (pfx_sample_cone_n, pfx_sample_value_n) give
 * bit for bit what the one-sample forms tested above give, in blocks of 1
 * to 64 ending anywhere in a vector: about one axis for all (an emitter's
 * direction) or each its own (normal, radial, tangent directions), for
 * spreads 0, 30 and 180 degrees, and values of each distribution. */
static void test_blocks_match_one(void) {
    static double u0[BLOCK_N], u1[BLOCK_N], ax[3][BLOCK_N], one[3][BLOCK_N], blk[3][BLOCK_N];
    const double spreads[3] = {0, 30 * PI / 180, PI};
    for (int sp = 0; sp < 3; sp++)
        for (int one_axis = 0; one_axis < 2; one_axis++) {
            pfx_rng r, axes;
            pfx_rng_seed(&r, 3, 4);
            pfx_rng_seed(&axes, 5, 6);
            for (size_t k = 0; k < BLOCK_N; k++) {
                double a[3] = {0.48, -0.6, 0.64}, o[3];
                if (!one_axis)
                    pfx_sample_direction(&axes, a);
                for (int i = 0; i < 3; i++)
                    ax[i][k] = a[i];
                pfx_rng before = r;
                pfx_sample_cone(a, spreads[sp], &r, o);
                for (int i = 0; i < 3; i++)
                    one[i][k] = o[i];
                u0[k] = pfx_rng_unit(&before), u1[k] = pfx_rng_unit(&before);
            }
            for (size_t k0 = 0, len = 1; k0 < BLOCK_N; k0 += len, len = len % 64 + 1) {
                size_t n = BLOCK_N - k0 < len ? BLOCK_N - k0 : len;
                pfx_sample_cone_n(n, (const double *const[3]){ax[0] + k0, ax[1] + k0, ax[2] + k0},
                                  one_axis, spreads[sp], u0 + k0, u1 + k0,
                                  (double *const[3]){blk[0] + k0, blk[1] + k0, blk[2] + k0});
            }
            bool same = true;
            for (int i = 0; i < 3; i++)
                same &= !memcmp(one[i], blk[i], sizeof one[i]);
            if (!same)
                fprintf(stderr, "  spread %g rad, %s: block and one sample differ\n", spreads[sp],
                        one_axis ? "one axis" : "an axis each");
            CHECK(same);
        }
    const pfx_value values[3] = {
        {.dist = PFX_DIST_CONST, .a = 2.5},
        {.dist = PFX_DIST_UNIFORM, .a = -1.5, .b = 4},
        {.dist = PFX_DIST_NORMAL, .a = 3, .b = 0.75, .lo = 2, .hi = 5},
    };
    for (int v = 0; v < 3; v++) {
        pfx_rng r;
        pfx_rng_seed(&r, 9, 10);
        for (size_t k = 0; k < BLOCK_N; k++) {
            pfx_rng before = r;
            one[0][k] = pfx_sample_value(&values[v], &r);
            unsigned units = pfx_sample_value_units(&values[v]);
            CHECK(r.draws - before.draws == 2 * units);
            u0[k] = units > 0 ? pfx_rng_unit(&before) : 0;
            u1[k] = units > 1 ? pfx_rng_unit(&before) : 0;
        }
        for (size_t k0 = 0, len = 1; k0 < BLOCK_N; k0 += len, len = len % 64 + 1) {
            size_t n = BLOCK_N - k0 < len ? BLOCK_N - k0 : len;
            pfx_sample_value_n(&values[v], n, u0 + k0, u1 + k0, blk[0] + k0);
        }
        CHECK(!memcmp(one[0], blk[0], sizeof one[0]));
    }
}

/* ---- Chi-square uniformity over equal-measure bins ---- */

#define MAX_BINS 512

/* Pearson's statistic of N_CHI samples over `bins` equal-probability bins;
 * *outside counts samples off the support. */
static double chi_square(sampler_fn sample, const void *sctx, binner_fn bin, const void *bctx,
                         int bins, uint64_t stream, long *outside) {
    static long count[MAX_BINS];
    memset(count, 0, sizeof count);
    pfx_rng r;
    pfx_rng_seed(&r, 31337, stream);
    *outside = 0;
    for (int i = 0; i < N_CHI; i++) {
        double p[3];
        sample(sctx, &r, p);
        int b = bin(bctx, p);
        if (b < 0 || b >= bins)
            ++*outside;
        else
            count[b]++;
    }
    double expect = (double)N_CHI / bins, chi2 = 0;
    for (int b = 0; b < bins; b++)
        chi2 += (count[b] - expect) * (count[b] - expect) / expect;
    return chi2;
}

/* Runs the test; true when the sampler passes as uniform. Each case draws
 * from its own stream (named by `what`), so the cases are independent. */
static bool uniform_test(const char *what, sampler_fn sample, const void *sctx, binner_fn bin,
                         const void *bctx, int bins) {
    long outside;
    double chi2 = chi_square(sample, sctx, bin, bctx, bins, pfx_rng_stream_for(what), &outside);
    double crit = chi2_critical(bins - 1);
    bool pass = outside == 0 && chi2 < crit;
    fprintf(stderr,
            "  %-34s chi2 = %10.1f  df = %3d  critical(p=0.001) = %.1f  outside = %ld  %s\n", what,
            chi2, bins - 1, crit, outside, pass ? "uniform" : "REJECTED");
    return pass;
}

/* Sphere of radius R: r^3/R^3 quantiles (4) x z/r (4, uniform for a uniform
 * direction) x azimuth (8): every bin holds 1/128 of the volume. */
#define SPH_R 4
#define SPH_Z 4
#define SPH_P 8
static int bin_sphere(const void *ctx, const double p[3]) {
    double R = *(const double *)ctx, r = norm3(p);
    if (r > R * (1 + 1e-12))
        return -1;
    double z = r > 0 ? p[2] / r : 0;
    int a = clampi(pow(r / R, 3), SPH_R), b = clampi((z + 1) / 2, SPH_Z),
        c = clampi(azimuth01(p[1], p[0]), SPH_P);
    return (a * SPH_Z + b) * SPH_P + c;
}

static void shape_sampler(const void *ctx, pfx_rng *r, double out[3]) {
    double normal[3];
    pfx_sample_shape(ctx, r, out, normal);
}

/* Biased: r = R u instead of R cbrt(u) (crowds the centre). */
static void sphere_linear_radius(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double d[3];
    pfx_sample_direction(r, d);
    double rad = s->radius * pfx_rng_unit(r);
    for (int i = 0; i < 3; i++)
        out[i] = d[i] * rad;
}

static void test_chi2_sphere(void) {
    pfx_shape s = {.type = PFX_SHAPE_SPHERE, .radius = 1.7};
    int bins = SPH_R * SPH_Z * SPH_P;
    CHECK(uniform_test("sphere volume", shape_sampler, &s, bin_sphere, &s.radius, bins));
    CHECK(!uniform_test("sphere, biased r = R u", sphere_linear_radius, &s, bin_sphere, &s.radius,
                        bins));
}

/* Box of edges (sx, sy, sz) centred on the origin: a 5 x 5 x 5 grid. */
#define BOX_N 5
static int bin_box(const void *ctx, const double p[3]) {
    const double *size = ctx;
    int idx = 0;
    for (int i = 0; i < 3; i++) {
        double f = p[i] / size[i] + 0.5;
        if (f < 0 || f > 1)
            return -1;
        idx = idx * BOX_N + clampi(f, BOX_N);
    }
    return idx;
}

/* Biased: each coordinate the mean of two uniforms (crowds the centre). */
static void box_triangular(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    for (int i = 0; i < 3; i++)
        out[i] = ((pfx_rng_unit(r) + pfx_rng_unit(r)) / 2 - 0.5) * s->size[i];
}

static void test_chi2_box(void) {
    pfx_shape s = {.type = PFX_SHAPE_BOX, .size = {1.0, 2.5, 0.4}};
    int bins = BOX_N * BOX_N * BOX_N;
    CHECK(uniform_test("box volume", shape_sampler, &s, bin_box, s.size, bins));
    CHECK(!uniform_test("box, biased triangular", box_triangular, &s, bin_box, s.size, bins));
}

/* Disc of radius R in the XZ plane: r^2/R^2 quantiles (8) x angle (16). */
#define DISC_R 8
#define DISC_A 16
static int bin_disc(const void *ctx, const double p[3]) {
    double R = *(const double *)ctx, r = hypot(p[0], p[2]);
    if (p[1] != 0 || r > R * (1 + 1e-12))
        return -1;
    return clampi(r * r / (R * R), DISC_R) * DISC_A + clampi(azimuth01(p[2], p[0]), DISC_A);
}

/* Biased: the thesis's ellipse method with a = b = R: x uniform in [-R, R],
 * then y uniform in [-R sqrt(1 - (x/R)^2), +...] (crowds the ends of x). */
static void disc_thesis_ellipse(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double a = s->radius, b = s->radius;
    double x = pfx_rng_range(r, -a, a);
    double h = b * sqrt(fmax(0.0, 1 - (x / a) * (x / a)));
    out[0] = x;
    out[1] = 0;
    out[2] = pfx_rng_range(r, -h, h);
}
/* Biased: r = R u instead of R sqrt(u) (crowds the centre). */
static void disc_linear_radius(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double rad = s->radius * pfx_rng_unit(r), th = 2 * PI * pfx_rng_unit(r);
    out[0] = rad * cos(th);
    out[1] = 0;
    out[2] = rad * sin(th);
}

static void test_chi2_disc(void) {
    pfx_shape s = {.type = PFX_SHAPE_DISC, .radius = 0.6};
    int bins = DISC_R * DISC_A;
    CHECK(uniform_test("disc area", shape_sampler, &s, bin_disc, &s.radius, bins));
    CHECK(!uniform_test("disc, biased thesis ellipse", disc_thesis_ellipse, &s, bin_disc, &s.radius,
                        bins));
    CHECK(!uniform_test("disc, biased r = R u", disc_linear_radius, &s, bin_disc, &s.radius, bins));
}

/* A spherical cap of half-angle `spread` around unit `axis`: (1 - cos
 * theta) / (1 - cos spread) quantiles (8) x azimuth (16) about the axis, in a
 * basis (e1, e2) built here independently of the sampler's. */
#define CAP_T 8
#define CAP_A 16
typedef struct cap {
    double axis[3], e1[3], e2[3];
    double spread_deg, cos_max;
} cap;

static cap make_cap(const double dir[3], double spread_deg) {
    cap c = {.spread_deg = spread_deg, .cos_max = cos(spread_deg * PI / 180)};
    double n = norm3(dir);
    for (int i = 0; i < 3; i++)
        c.axis[i] = dir[i] / n;
    double h[3] = {1, 0, 0};
    if (fabs(c.axis[0]) > 0.9)
        h[0] = 0, h[1] = 1;
    double d = dot3(h, c.axis);
    for (int i = 0; i < 3; i++)
        c.e1[i] = h[i] - d * c.axis[i];
    n = norm3(c.e1);
    for (int i = 0; i < 3; i++)
        c.e1[i] /= n;
    c.e2[0] = c.axis[1] * c.e1[2] - c.axis[2] * c.e1[1];
    c.e2[1] = c.axis[2] * c.e1[0] - c.axis[0] * c.e1[2];
    c.e2[2] = c.axis[0] * c.e1[1] - c.axis[1] * c.e1[0];
    return c;
}

static int bin_cap(const void *ctx, const double p[3]) {
    const cap *c = ctx;
    double ct = dot3(p, c->axis);
    if (fabs(norm3(p) - 1) > 1e-12 || ct < c->cos_max - 1e-12)
        return -1;
    double f = (1 - ct) / (1 - c->cos_max);
    return clampi(f, CAP_T) * CAP_A + clampi(azimuth01(dot3(p, c->e2), dot3(p, c->e1)), CAP_A);
}

static void cone_sampler(const void *ctx, pfx_rng *r, double out[3]) {
    const cap *c = ctx;
    pfx_sample_cone(c->axis, c->spread_deg * PI / 180, r, out);
}

/* Biased: the deviation angle theta uniform in [0, spread] (crowds the axis). */
static void cone_uniform_angle(const void *ctx, pfx_rng *r, double out[3]) {
    const cap *c = ctx;
    double th = pfx_rng_unit(r) * c->spread_deg * PI / 180, ph = 2 * PI * pfx_rng_unit(r);
    double ct = cos(th), st = sin(th);
    for (int i = 0; i < 3; i++)
        out[i] = c->axis[i] * ct + st * (c->e1[i] * cos(ph) + c->e2[i] * sin(ph));
}

static void test_chi2_cone(void) {
    const double axes[][3] = {{0.3, 1.0, -0.4}, {0, 0, -1}};
    const double spreads[] = {30, 90};
    for (size_t a = 0; a < 2; a++)
        for (size_t s = 0; s < 2; s++) {
            cap c = make_cap(axes[a], spreads[s]);
            char what[96];
            snprintf(what, sizeof what, "cap %g deg, axis (%g, %g, %g)", spreads[s], axes[a][0],
                     axes[a][1], axes[a][2]);
            CHECK(uniform_test(what, cone_sampler, &c, bin_cap, &c, CAP_T * CAP_A));
            snprintf(what, sizeof what, "cap %g deg, axis %zu, biased angle", spreads[s], a + 1);
            CHECK(!uniform_test(what, cone_uniform_angle, &c, bin_cap, &c, CAP_T * CAP_A));
        }
    /* Spread 0 is the axis itself, exactly. */
    double axis[3] = {0, 0.6, 0.8}, out[3];
    pfx_rng r;
    pfx_rng_seed(&r, 1, 1);
    pfx_sample_cone(axis, 0, &r, out);
    CHECK(out[0] == 0 && out[1] == axis[1] && out[2] == axis[2]);
}

/* Emitters of different spreads take turns (pfx_sample_cone remembers the
 * last spread's cosine): each draw stays in its own cap and the wide one
 * still reaches past the narrow one's, in either order. */
static void test_cone_spreads_alternate(void) {
    const double axis[3] = {0, 1, 0}, spreads[2] = {0.3, 1.2};
    pfx_rng r;
    pfx_rng_seed(&r, 7, 2);
    int outside = 0, wide_past_narrow = 0;
    for (int i = 0; i < 4000; i++) {
        double spread = spreads[(i ^ (i >> 7)) & 1], out[3];
        pfx_sample_cone(axis, spread, &r, out);
        outside += out[1] < cos(spread) - 1e-12;
        wide_past_narrow += spread > 1 && out[1] < cos(spreads[0]);
    }
    CHECK(outside == 0);
    CHECK(wide_past_narrow > 1000);
}

/* Whole sphere of directions: z quantiles (8, z uniform on [-1, 1] by
 * Archimedes) x azimuth (16). */
#define DIR_Z 8
#define DIR_A 16
static int bin_direction(const void *ctx, const double p[3]) {
    (void)ctx;
    if (fabs(norm3(p) - 1) > 1e-12)
        return -1;
    return clampi((p[2] + 1) / 2, DIR_Z) * DIR_A + clampi(azimuth01(p[1], p[0]), DIR_A);
}

static void direction_sampler(const void *ctx, pfx_rng *r, double out[3]) {
    (void)ctx;
    pfx_sample_direction(r, out);
}

/* Biased: a point uniform in the cube [-1, 1]^3, normalised (crowds the
 * directions towards the cube's corners). */
static void direction_from_cube(const void *ctx, pfx_rng *r, double out[3]) {
    (void)ctx;
    for (int i = 0; i < 3; i++)
        out[i] = 2 * pfx_rng_unit(r) - 1;
    double n = norm3(out);
    for (int i = 0; i < 3; i++)
        out[i] /= n;
}

static void test_chi2_direction(void) {
    CHECK(uniform_test("full-sphere directions", direction_sampler, NULL, bin_direction, NULL,
                       DIR_Z * DIR_A));
    CHECK(!uniform_test("directions, biased normalised cube", direction_from_cube, NULL,
                        bin_direction, NULL, DIR_Z * DIR_A));
}

/* The Wilson-Hilferty approximation against tabulated chi-square quantiles
 * (p = 0.001, by numerical inversion of the regularised incomplete gamma
 * function): 10 -> 29.588, 100 -> 149.449, 124 -> 178.408, 127 -> 181.993.
 * The approximation is within 0.6% at 10 dof and within 0.1% from 100. */
static void test_chi2_critical(void) {
    CHECK_NEAR(chi2_critical(10), 29.588, 0.006 * 29.588);
    CHECK_NEAR(chi2_critical(100), 149.449, 0.001 * 149.449);
    CHECK_NEAR(chi2_critical(124), 178.408, 0.001 * 178.408);
    CHECK_NEAR(chi2_critical(127), 181.993, 0.001 * 181.993);
}

/* ---- Gradient lookup ---- */

/* The piecewise-linear gradient through (at[k], col[k]) at t, ends held. */
static double lerp_stops(const double *at, const double (*col)[4], int n, int ch, double t) {
    if (t <= at[0])
        return col[0][ch];
    for (int k = 0; k + 1 < n; k++)
        if (t <= at[k + 1])
            return col[k][ch] + (col[k + 1][ch] - col[k][ch]) * (t - at[k]) / (at[k + 1] - at[k]);
    return col[n - 1][ch];
}

static void check_lut(const pfx_gradient *g, const double *at, const double (*col)[4], int n) {
    int bad = 0;
    for (int i = 0; i < PFX_GRADIENT_LUT; i++)
        for (int ch = 0; ch < 4; ch++) {
            double want = lerp_stops(at, col, n, ch, (double)i / (PFX_GRADIENT_LUT - 1));
            if (!(fabs(g->lut[i][ch] - want) <= 1e-6) && bad++ < 5)
                fprintf(stderr, "  lut[%d][%d] = %.9g, want %.9g\n", i, ch, g->lut[i][ch], want);
        }
    CHECK(bad == 0);
}

static void test_gradient_lut(void) {
    compiled c;
    const char *two = "pfx: 1\nemitters:\n  e:\n    color: [\"#000000\", \"#ffffff\"]\n";
    if (compile_text(&c, two)) {
        const double at[] = {0, 1}, col[][4] = {{0, 0, 0, 1}, {1, 1, 1, 1}};
        check_lut(&c.e->emitters[0].color, at, col, 2);
        CHECK(!c.e->emitters[0].color.constant);
        CHECK_NEAR(c.e->emitters[0].color.lut[51][0], 0.2, 1e-6);
    }
    CHECK(c.e != NULL);
    compiled_free(&c);

    const char *stops = "pfx: 1\nemitters:\n  e:\n    color:\n"
                        "      - {at: 0, color: \"#ff0000\"}\n"
                        "      - {at: 0.25, color: \"#00ff00\"}\n"
                        "      - {at: 1, color: \"#0000ff\"}\n";
    if (compile_text(&c, stops)) {
        const double at[] = {0, 0.25, 1}, col[][4] = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}};
        check_lut(&c.e->emitters[0].color, at, col, 3);
        CHECK(!c.e->emitters[0].color.constant);
    }
    CHECK(c.e != NULL);
    compiled_free(&c);

    /* Stops inside (0, 1): the end colours hold outside them. */
    const char *inner = "pfx: 1\nemitters:\n  e:\n    color:\n"
                        "      - {at: 0.2, color: [0.2, 0.4, 0.6, 0.8]}\n"
                        "      - {at: 0.7, color: \"#ffffff00\"}\n";
    if (compile_text(&c, inner)) {
        const double at[] = {0.2, 0.7}, col[][4] = {{0.2, 0.4, 0.6, 0.8}, {1, 1, 1, 0}};
        check_lut(&c.e->emitters[0].color, at, col, 2);
    }
    CHECK(c.e != NULL);
    compiled_free(&c);

    const char *one = "pfx: 1\nemitters:\n  e:\n    color: \"#336699\"\n";
    if (compile_text(&c, one)) {
        const pfx_gradient *g = &c.e->emitters[0].color;
        CHECK(g->constant);
        const double at[] = {0}, col[][4] = {{0x33 / 255.0, 0x66 / 255.0, 0x99 / 255.0, 1}};
        check_lut(g, at, col, 1);
    }
    CHECK(c.e != NULL);
    compiled_free(&c);
}

int main(void) {
    RUN(test_pcg32_reference);
    RUN(test_pcg32_streams_differ);
    RUN(test_pcg32_unit);
    RUN(test_pcg32_units);
    RUN(test_value_const);
    RUN(test_value_uniform);
    RUN(test_value_normal);
    RUN(test_chi2_critical);
    RUN(test_chi2_sphere);
    RUN(test_chi2_box);
    RUN(test_chi2_disc);
    RUN(test_chi2_cone);
    RUN(test_cone_spreads_alternate);
    RUN(test_blocks_match_one);
    RUN(test_chi2_direction);
    RUN(test_gradient_lut);
    return TEST_EXIT();
}
