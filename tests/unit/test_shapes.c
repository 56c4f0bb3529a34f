/* Emitter shapes: every shape and emit_from mode, compiled from effect text,
 * is uniform by a chi-square test over equal-measure bins (N = 200000, p =
 * 0.001 by Wilson-Hilferty), takes a fixed number of generator outputs per
 * sample, and returns the outward normal it documents. The biased methods
 * (the thesis's ellipse, a ring with r uniform, a deviation angle drawn
 * uniformly, faces or triangles picked without their areas, ...) must fail
 * the same tests. The OBJ reader is tested on text: fans, negative indices,
 * skipped statements and every malformed-file message. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/rng.h"
#include "compile/compile.h"
#include "compile/mesh_load.h"
#include "sim/fast_d.h"
#include "sim/sample.h"
#include "test.h"
#include "test_stats.h"

#define N_CHI 200000
#define MAX_BINS 512

/* ---- Compiling a shape from effect text ---- */

typedef struct compiled {
    char *text;
    pfx_doc doc;
    pfx_arena arena;
    pfx_diags diags;
    pfx_effect *e;
} compiled;

/* Compiles one emitter whose `shape:` is `shape` (a flow mapping), as if
 * the file were at `path`. Returns the shape, or NULL after printing. */
static const pfx_shape *compile_shape_text(compiled *c, const char *shape, const char *path) {
    memset(c, 0, sizeof *c);
    size_t len = strlen(shape) + 64;
    c->text = malloc(len);
    snprintf(c->text, len, "pfx: 1\nemitters:\n  e:\n    shape: %s\n", shape);
    len = strlen(c->text);
    pfx_diags_init(&c->diags, path, c->text, len);
    if (pfx_parse(c->text, len, &c->doc, &c->diags))
        c->e = pfx_compile(c->doc.root, path, NULL, &c->arena, &c->diags);
    if (!c->e) {
        pfx_diags_print(&c->diags, stderr, false);
        return NULL;
    }
    return &c->e->emitters[0].shape;
}

static void compiled_free(compiled *c) {
    pfx_doc_free(&c->doc);
    pfx_arena_free(&c->arena);
    pfx_diags_free(&c->diags);
    free(c->text);
}

/* ---- Chi-square ---- */

/* Pearson's statistic over `bins` bins of probabilities prob[b] (NULL:
 * equal), from N_CHI samples of its own stream; true when it passes. */
static bool uniform_test(const char *what, sampler_fn sample, const void *sctx, binner_fn bin,
                         const void *bctx, int bins, const double *prob) {
    static long count[MAX_BINS];
    memset(count, 0, sizeof count);
    pfx_rng r;
    pfx_rng_seed(&r, 31337, pfx_rng_stream_for(what));
    long outside = 0;
    for (int i = 0; i < N_CHI; i++) {
        double p[3];
        sample(sctx, &r, p);
        int b = bin(bctx, p);
        if (b < 0 || b >= bins)
            outside++;
        else
            count[b]++;
    }
    double chi2 = 0;
    for (int b = 0; b < bins; b++) {
        double expect = N_CHI * (prob ? prob[b] : 1.0 / bins);
        chi2 += (count[b] - expect) * (count[b] - expect) / expect;
    }
    double crit = chi2_critical(bins - 1);
    bool pass = outside == 0 && chi2 < crit;
    fprintf(stderr,
            "  %-36s chi2 = %10.1f  df = %3d  critical(p=0.001) = %.1f  outside = %ld  %s\n", what,
            chi2, bins - 1, crit, outside, pass ? "uniform" : "REJECTED");
    return pass;
}

static void shape_sampler(const void *ctx, pfx_rng *r, double out[3]) {
    double n[3];
    pfx_sample_shape(ctx, r, out, n);
}

/* ---- Binners: each maps equal measure (length, area, volume) to equal
 * bins from the shape's geometry alone, independently of the sampler ---- */

#define EPS 1e-9

/* Line: the fraction along from -> to, 50 bins. */
static int bin_line(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double d[3], q[3];
    for (int i = 0; i < 3; i++)
        d[i] = s->line_to[i] - s->line_from[i], q[i] = p[i] - s->line_from[i];
    double t = dot3(q, d) / dot3(d, d), off[3];
    for (int i = 0; i < 3; i++)
        off[i] = q[i] - t * d[i];
    if (norm3(off) > EPS || t < 0 || t > 1)
        return -1;
    return clampi(t, 50);
}

/* Rect area: a 10 x 10 grid over x and z. */
static int bin_rect(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double fx = p[0] / s->size[0] + 0.5, fz = p[2] / s->size[1] + 0.5;
    if (p[1] != 0 || fx < 0 || fx > 1 || fz < 0 || fz > 1)
        return -1;
    return clampi(fx, 10) * 10 + clampi(fz, 10);
}

/* Rect perimeter: the distance along it from (-w/2, -h/2) via +X, in 50
 * equal lengths. */
static int bin_rect_edge(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double w = s->size[0], h = s->size[1], x = p[0], z = p[2], at;
    if (p[1] != 0 || fabs(x) > w / 2 + EPS || fabs(z) > h / 2 + EPS)
        return -1;
    if (fabs(z + h / 2) < EPS)
        at = x + w / 2;
    else if (fabs(x - w / 2) < EPS)
        at = w + z + h / 2;
    else if (fabs(z - h / 2) < EPS)
        at = w + h + w / 2 - x;
    else if (fabs(x + w / 2) < EPS)
        at = 2 * w + h + h / 2 - z;
    else
        return -1;
    return clampi(at / (2 * (w + h)), 50);
}

/* Disc area (ring, arc): (r^2 - k^2 R^2) / (R^2 - k^2 R^2) quantiles (8) x
 * the angle's fraction of the arc (16). */
static int bin_disc(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double R = s->radius, a = s->inner, r = hypot(p[0], p[2]);
    double arc = s->arc_turns > 0 ? s->arc_turns : 1, f = azimuth01(p[2], p[0]) / arc;
    if (p[1] != 0 || r > R * (1 + EPS) || r < a * (1 - EPS) || f > 1 + EPS)
        return -1;
    return clampi((r * r - a * a) / (R * R - a * a), 8) * 16 + clampi(f, 16);
}

/* Disc rim: on the circle r = R, the angle's fraction of the arc, 64 bins. */
static int bin_disc_edge(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double arc = s->arc_turns > 0 ? s->arc_turns : 1, f = azimuth01(p[2], p[0]) / arc;
    if (p[1] != 0 || fabs(hypot(p[0], p[2]) - s->radius) > EPS || f > 1 + EPS)
        return -1;
    return clampi(f, 64);
}

/* Ellipse area: (x/a, z/b) is uniform in the unit disc (the linear map
 * scales every area by a b), binned as a disc. */
static int bin_ellipse(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double x = p[0] / s->radii[0], z = p[2] / s->radii[1], r2 = x * x + z * z;
    if (p[1] != 0 || r2 > 1 + EPS)
        return -1;
    return clampi(r2, 8) * 16 + clampi(azimuth01(z, x), 16);
}

/* Ellipse rim: 64 bins of equal arc length. The bounds t_k, where the arc
 * length from t = 0 is k L / 64, come from Simpson's rule on 2^17 panels,
 * independently of the sampler's trapezoid table. */
#define ELL_BINS 64
typedef struct ellipse_rim {
    double a, b, len, bound[ELL_BINS + 1];
} ellipse_rim;

static double ellipse_speed(double a, double b, double t) { return hypot(a * sin(t), b * cos(t)); }

static void ellipse_rim_init(ellipse_rim *e, double a, double b) {
    enum { PANELS = 1 << 17 };
    static double s[PANELS + 1];
    double h = 2 * PI / PANELS;
    s[0] = 0;
    for (int i = 0; i < PANELS; i++) {
        double t = h * i;
        s[i + 1] = s[i] + h / 6 *
                              (ellipse_speed(a, b, t) + 4 * ellipse_speed(a, b, t + h / 2) +
                               ellipse_speed(a, b, t + h));
    }
    e->a = a, e->b = b, e->len = s[PANELS];
    int i = 0;
    for (int k = 0; k <= ELL_BINS; k++) {
        double want = s[PANELS] * k / ELL_BINS;
        while (i < PANELS - 1 && s[i + 1] < want)
            i++;
        e->bound[k] = h * (i + (want - s[i]) / (s[i + 1] - s[i]));
    }
}

static int bin_ellipse_edge(const void *ctx, const double p[3]) {
    const ellipse_rim *e = ctx;
    double x = p[0] / e->a, z = p[2] / e->b;
    if (p[1] != 0 || fabs(x * x + z * z - 1) > EPS)
        return -1;
    double t = 2 * PI * azimuth01(z, x);
    int k = 0;
    while (k < ELL_BINS - 1 && t >= e->bound[k + 1])
        k++;
    return k;
}

/* Box faces: cells of 0.5 x 0.5 on every face of a 1 x 2 x 3 box (88 cells
 * of equal area), the face found by the coordinate at +-size/2. */
static int bin_box_surface(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    int base = 0;
    for (int axis = 0; axis < 3; axis++) {
        int u = (axis + 1) % 3, v = (axis + 2) % 3;
        int nu = (int)lround(s->size[u] / 0.5), nv = (int)lround(s->size[v] / 0.5);
        if (fabs(fabs(p[axis]) - s->size[axis] / 2) < EPS) {
            double fu = p[u] / s->size[u] + 0.5, fv = p[v] / s->size[v] + 0.5;
            if (fu < 0 || fu > 1 || fv < 0 || fv > 1 || fabs(p[u]) > s->size[u] / 2 + EPS)
                return -1;
            return base + (p[axis] > 0) * nu * nv + clampi(fu, nu) * nv + clampi(fv, nv);
        }
        base += 2 * nu * nv;
    }
    return -1;
}

/* Sphere volume between inner and R: (r^3 - a^3) / (R^3 - a^3) quantiles
 * (4) x z / r (4: uniform for a uniform direction) x azimuth (8). */
static int bin_sphere(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double R = s->radius, a = s->inner, r = norm3(p);
    if (r > R * (1 + EPS) || r < a * (1 - EPS))
        return -1;
    double z = r > 0 ? p[2] / r : 0;
    double f = (r * r * r - a * a * a) / (R * R * R - a * a * a);
    return (clampi(f, 4) * 4 + clampi((z + 1) / 2, 4)) * 8 + clampi(azimuth01(p[1], p[0]), 8);
}

/* Sphere surface: on r = R, z uniform (Archimedes) (8) x azimuth (16). */
static int bin_sphere_surface(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    if (fabs(norm3(p) - s->radius) > EPS)
        return -1;
    return clampi((p[2] / s->radius + 1) / 2, 8) * 16 + clampi(azimuth01(p[1], p[0]), 16);
}

/* Hemisphere volume: r^3 quantiles (4) x y / r in [0, 1] (4) x azimuth about
 * Y (8). */
static int bin_hemisphere(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double R = s->radius, r = norm3(p);
    if (r > R * (1 + EPS) || p[1] < 0)
        return -1;
    double y = r > 0 ? p[1] / r : 0;
    return (clampi(pow(r / R, 3), 4) * 4 + clampi(y, 4)) * 8 + clampi(azimuth01(p[2], p[0]), 8);
}

/* Dome: on r = R with y >= 0, y uniform (8) x azimuth about Y (16). */
static int bin_dome(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    if (fabs(norm3(p) - s->radius) > EPS || p[1] < 0)
        return -1;
    return clampi(p[1] / s->radius, 8) * 16 + clampi(azimuth01(p[2], p[0]), 16);
}

/* Cylinder volume: rho^2 / R^2 (4) x y / h (8) x azimuth (8). */
static int bin_cylinder(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double rho = hypot(p[0], p[2]), y = p[1] / s->height;
    if (rho > s->radius * (1 + EPS) || y < 0 || y > 1)
        return -1;
    return (clampi(rho * rho / (s->radius * s->radius), 4) * 8 + clampi(y, 8)) * 8 +
           clampi(azimuth01(p[2], p[0]), 8);
}

/* Cylinder side: on rho = R, y / h (8) x azimuth (16). */
static int bin_cylinder_side(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double y = p[1] / s->height;
    if (fabs(hypot(p[0], p[2]) - s->radius) > EPS || y < 0 || y > 1)
        return -1;
    return clampi(y, 8) * 16 + clampi(azimuth01(p[2], p[0]), 16);
}

/* Solid cone, q = 1 - y/h: the volume below height y is 1 - q^3 of the
 * whole (8 bins), and within the section (a disc of radius R q) the area
 * fraction (rho / R q)^2 (4) x azimuth (8): a product of equal measures. */
static int bin_cone(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double q = 1 - p[1] / s->height, rho = hypot(p[0], p[2]);
    if (q < 0 || q > 1 || rho > s->radius * q * (1 + EPS) + EPS)
        return -1;
    double f = q > 0 ? rho / (s->radius * q) : 0;
    return (clampi(1 - q * q * q, 8) * 4 + clampi(f * f, 4)) * 8 + clampi(azimuth01(p[2], p[0]), 8);
}

/* Cone side: on rho = R q; the slant area between the base and height y is
 * 1 - q^2 of the whole (8) x azimuth (16). */
static int bin_cone_side(const void *ctx, const double p[3]) {
    const pfx_shape *s = ctx;
    double q = 1 - p[1] / s->height;
    if (q < 0 || q > 1 || fabs(hypot(p[0], p[2]) - s->radius * q) > EPS)
        return -1;
    return clampi(1 - q * q, 8) * 16 + clampi(azimuth01(p[2], p[0]), 16);
}

/* Mesh: each triangle cut into 16 equal sub-triangles (four per side, by
 * barycentric coordinates), bin probability area / total / 16. */
#define TRI_SUB 4
typedef struct mesh_bins {
    const pfx_shape *s;
    double prob[MAX_BINS];
    int bins;
} mesh_bins;

static void mesh_bins_init(mesh_bins *m, const pfx_shape *s) {
    m->s = s;
    m->bins = (int)s->cum_count * TRI_SUB * TRI_SUB;
    double total = s->cum[s->cum_count - 1];
    for (uint32_t t = 0; t < s->cum_count; t++) {
        double area = s->cum[t] - (t ? s->cum[t - 1] : 0);
        for (int k = 0; k < TRI_SUB * TRI_SUB; k++)
            m->prob[t * TRI_SUB * TRI_SUB + k] = area / total / (TRI_SUB * TRI_SUB);
    }
}

static int bin_mesh(const void *ctx, const double p[3]) {
    const mesh_bins *m = ctx;
    const pfx_shape *s = m->s;
    for (uint32_t t = 0; t < s->cum_count; t++) {
        const double *A = s->verts + 3 * s->tris[3 * t], *B = s->verts + 3 * s->tris[3 * t + 1],
                     *C = s->verts + 3 * s->tris[3 * t + 2];
        /* Barycentric (l1, l2) of p on B, C by least squares, then the
         * distance off the plane. */
        double e1[3], e2[3], q[3];
        for (int i = 0; i < 3; i++)
            e1[i] = B[i] - A[i], e2[i] = C[i] - A[i], q[i] = p[i] - A[i];
        double d11 = dot3(e1, e1), d12 = dot3(e1, e2), d22 = dot3(e2, e2);
        double q1 = dot3(q, e1), q2 = dot3(q, e2), det = d11 * d22 - d12 * d12;
        double l1 = (d22 * q1 - d12 * q2) / det, l2 = (d11 * q2 - d12 * q1) / det, off[3];
        for (int i = 0; i < 3; i++)
            off[i] = q[i] - l1 * e1[i] - l2 * e2[i];
        if (norm3(off) > EPS || l1 < -EPS || l2 < -EPS || l1 + l2 > 1 + EPS)
            continue;
        /* Sub-triangle: cell (i, j) of the grid, lower or upper half. */
        double x = l1 * TRI_SUB, y = l2 * TRI_SUB;
        int i = clampi(l1, TRI_SUB), j = clampi(l2, TRI_SUB);
        if (i + j > TRI_SUB - 1)
            j = TRI_SUB - 1 - i;
        int upper = (x - i) + (y - j) > 1 && i + j < TRI_SUB - 1;
        /* Cells (i, j) with i + j <= n - 1 have a lower half; those with
         * i + j <= n - 2 an upper half too: n^2 in all. */
        int index = 0;
        for (int a = 0; a < i; a++)
            index += 2 * (TRI_SUB - a) - 1;
        index += 2 * j + upper;
        return (int)t * TRI_SUB * TRI_SUB + index;
    }
    return -1;
}

/* ---- Biased samplers, which must fail ---- */

/* The thesis: x uniform in [-a, a], then z uniform in +-b sqrt(1 - (x/a)^2). */
static void ellipse_thesis(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double a = s->radii[0], b = s->radii[1];
    double x = pfx_rng_range(r, -a, a), h = b * sqrt(fmax(0.0, 1 - (x / a) * (x / a)));
    out[0] = x, out[1] = 0, out[2] = pfx_rng_range(r, -h, h);
}

/* The rim at a uniform parameter t (crowds the ends of the minor axis). */
static void ellipse_edge_uniform_t(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double t = 2 * PI * pfx_rng_unit(r);
    out[0] = s->radii[0] * cos(t), out[1] = 0, out[2] = s->radii[1] * sin(t);
}

/* A ring with r uniform in [inner, R] (crowds the inner edge). */
static void ring_linear_radius(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double rad = pfx_rng_range(r, s->inner, s->radius), th = 2 * PI * pfx_rng_unit(r);
    out[0] = rad * cos(th), out[1] = 0, out[2] = rad * sin(th);
}

/* A shell with r uniform in [inner, R]. */
static void shell_linear_radius(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double d[3];
    pfx_sample_direction(r, d);
    double rad = pfx_rng_range(r, s->inner, s->radius);
    for (int i = 0; i < 3; i++)
        out[i] = d[i] * rad;
}

/* Box faces each picked with probability 1/6. */
static void box_faces_equal(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    int face = clampi(pfx_rng_unit(r), 6), axis = face / 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
    out[axis] = (face % 2 ? 0.5 : -0.5) * s->size[axis];
    out[u] = (pfx_rng_unit(r) - 0.5) * s->size[u];
    out[v] = (pfx_rng_unit(r) - 0.5) * s->size[v];
}

/* A solid cone with its height uniform (crowds the apex). */
static void cone_height_uniform(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double q = pfx_rng_unit(r), rho = s->radius * q * sqrt(pfx_rng_unit(r));
    double th = 2 * PI * pfx_rng_unit(r);
    out[0] = rho * cos(th), out[1] = s->height * (1 - q), out[2] = rho * sin(th);
}

/* A cone's side with q uniform (area ~ q: crowds the apex). */
static void cone_side_q_uniform(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double q = pfx_rng_unit(r), th = 2 * PI * pfx_rng_unit(r);
    out[0] = s->radius * q * cos(th), out[1] = s->height * (1 - q),
    out[2] = s->radius * q * sin(th);
}

/* Mesh triangles picked with equal probability (ignores the areas). */
static void mesh_triangles_equal(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    uint32_t t = (uint32_t)clampi(pfx_rng_unit(r), (int)s->cum_count);
    double r1 = sqrt(pfx_rng_unit(r)), r2 = pfx_rng_unit(r);
    const double *A = s->verts + 3 * s->tris[3 * t], *B = s->verts + 3 * s->tris[3 * t + 1],
                 *C = s->verts + 3 * s->tris[3 * t + 2];
    for (int i = 0; i < 3; i++)
        out[i] = (1 - r1) * A[i] + r1 * (1 - r2) * B[i] + r1 * r2 * C[i];
}

/* Barycentric without the square root (crowds vertex A). */
static void mesh_no_sqrt(const void *ctx, pfx_rng *r, double out[3]) {
    const pfx_shape *s = ctx;
    double u = pfx_rng_unit(r), r1 = pfx_rng_unit(r), r2 = pfx_rng_unit(r);
    uint32_t t = 0;
    while (t + 1 < s->cum_count && s->cum[t] <= u * s->cum[s->cum_count - 1])
        t++;
    const double *A = s->verts + 3 * s->tris[3 * t], *B = s->verts + 3 * s->tris[3 * t + 1],
                 *C = s->verts + 3 * s->tris[3 * t + 2];
    for (int i = 0; i < 3; i++)
        out[i] = (1 - r1) * A[i] + r1 * (1 - r2) * B[i] + r1 * r2 * C[i];
}

/* ---- The cases ---- */

/* Checks the normal n at point p of shape s; returns false when wrong. */
typedef bool (*normal_fn)(const pfx_shape *s, const double p[3], const double n[3]);

static bool near(double a, double b) { return fabs(a - b) < 1e-9; }
static bool normal_up(const pfx_shape *s, const double p[3], const double n[3]) {
    (void)s, (void)p;
    return n[0] == 0 && n[1] == 1 && n[2] == 0;
}
/* n = p / |p|: sphere, hemisphere, box volume (from the centre). */
static bool normal_radial(const pfx_shape *s, const double p[3], const double n[3]) {
    (void)s;
    double r = norm3(p);
    return r == 0 || (near(n[0], p[0] / r) && near(n[1], p[1] / r) && near(n[2], p[2] / r));
}
/* n = (x, 0, z) / rho: disc rim, cylinder. */
static bool normal_from_axis(const pfx_shape *s, const double p[3], const double n[3]) {
    (void)s;
    double rho = hypot(p[0], p[2]);
    return rho == 0 || (near(n[0], p[0] / rho) && n[1] == 0 && near(n[2], p[2] / rho));
}
/* Perpendicular to the line, in the plane of the line and +Y. */
static bool normal_line(const pfx_shape *s, const double p[3], const double n[3]) {
    (void)p;
    double d[3] = {s->line_to[0] - s->line_from[0], s->line_to[1] - s->line_from[1],
                   s->line_to[2] - s->line_from[2]};
    return near(dot3(n, d), 0) && n[1] > 0 && near(d[0] * n[2] - d[2] * n[0], 0);
}
/* An axis in the plane, pointing out of the rectangle. */
static bool normal_rect_edge(const pfx_shape *s, const double p[3], const double n[3]) {
    (void)s;
    return n[1] == 0 && fabs(n[0]) + fabs(n[2]) == 1 && dot3(n, p) > 0;
}
/* Perpendicular to the rim's tangent (-a sin t, 0, b cos t), outward. */
static bool normal_ellipse_edge(const pfx_shape *s, const double p[3], const double n[3]) {
    double ct = p[0] / s->radii[0], st = p[2] / s->radii[1];
    double tangent[3] = {-s->radii[0] * st, 0, s->radii[1] * ct};
    return near(dot3(n, tangent), 0) && n[1] == 0 && dot3(n, p) > 0;
}
/* The face's axis, outward. */
static bool normal_box_face(const pfx_shape *s, const double p[3], const double n[3]) {
    for (int a = 0; a < 3; a++)
        if (n[a] != 0)
            return fabs(n[a]) == 1 && n[a] * p[a] == s->size[a] / 2 && n[(a + 1) % 3] == 0 &&
                   n[(a + 2) % 3] == 0;
    return false;
}
/* Perpendicular to the generator from p to the apex, outward. */
static bool normal_cone_side(const pfx_shape *s, const double p[3], const double n[3]) {
    double g[3] = {-p[0], s->height - p[1], -p[2]}, out[3] = {p[0], 0, p[2]};
    return near(dot3(n, g), 0) && dot3(n, out) >= 0 && n[1] > 0;
}
/* +Y tilted outward by angle * rho / R. */
static bool normal_cone_fan(const pfx_shape *s, const double p[3], const double n[3]) {
    double rho = hypot(p[0], p[2]), tilt = s->angle * rho / s->radius;
    return near(n[1], cos(tilt)) && near(hypot(n[0], n[2]), sin(tilt)) &&
           (rho == 0 || near(n[0] * p[2] - n[2] * p[0], 0));
}

typedef struct shape_case {
    const char *name, *shape; /* the test's name; the `shape:` mapping */
    binner_fn bin;
    int bins;
    int units; /* pfx_rng_unit calls (two outputs each) per sample */
    normal_fn normal;
    sampler_fn biased; /* a wrong sampler the test must reject, or NULL */
    const char *biased_name;
} shape_case;

static const shape_case cases[] = {
    {"line", "{type: line, from: [1, -2, 0.5], to: [3, 1, -1]}", bin_line, 50, 1, normal_line, NULL,
     NULL},
    {"rect area", "{type: rect, size: [2, 0.5]}", bin_rect, 100, 2, normal_up, NULL, NULL},
    {"rect edge", "{type: rect, size: [2, 0.5], emit_from: edge}", bin_rect_edge, 50, 1,
     normal_rect_edge, NULL, NULL},
    {"disc area", "{type: disc, radius: 0.6}", bin_disc, 128, 2, normal_up, NULL, NULL},
    {"disc ring (inner)", "{type: disc, radius: 1.5, inner: 0.6}", bin_disc, 128, 2, normal_up,
     ring_linear_radius, "ring, biased r uniform in [inner, R]"},
    {"disc arc 135", "{type: disc, radius: 1, arc: 135}", bin_disc, 128, 2, normal_up, NULL, NULL},
    {"disc ring arc 250", "{type: disc, radius: 2, inner: 1.9, arc: 250}", bin_disc, 128, 2,
     normal_up, NULL, NULL},
    {"disc edge", "{type: disc, radius: 0.8, emit_from: edge}", bin_disc_edge, 64, 1,
     normal_from_axis, NULL, NULL},
    {"disc edge arc 90", "{type: disc, radius: 0.8, arc: 90, emit_from: edge}", bin_disc_edge, 64,
     1, normal_from_axis, NULL, NULL},
    {"ellipse area", "{type: ellipse, radii: [2, 0.5]}", bin_ellipse, 128, 2, normal_up,
     ellipse_thesis, "ellipse, biased thesis method"},
    {"box volume", "{type: box, size: [1, 2, 3]}", NULL, 0, 3, normal_radial, NULL, NULL},
    {"box surface", "{type: box, size: [1, 2, 3], emit_from: surface}", bin_box_surface, 88, 3,
     normal_box_face, box_faces_equal, "box surface, biased faces 1/6"},
    {"sphere volume", "{type: sphere, radius: 1.2}", bin_sphere, 128, 3, normal_radial, NULL, NULL},
    {"sphere shell (inner)", "{type: sphere, radius: 1.2, inner: 0.9}", bin_sphere, 128, 3,
     normal_radial, shell_linear_radius, "shell, biased r uniform in [inner, R]"},
    {"sphere surface", "{type: sphere, radius: 1.2, emit_from: surface}", bin_sphere_surface, 128,
     2, normal_radial, NULL, NULL},
    {"hemisphere volume", "{type: hemisphere, radius: 0.7}", bin_hemisphere, 128, 3, normal_radial,
     NULL, NULL},
    {"hemisphere surface", "{type: hemisphere, radius: 0.7, emit_from: surface}", bin_dome, 128, 2,
     normal_radial, NULL, NULL},
    {"cylinder volume", "{type: cylinder, radius: 0.5, height: 2}", bin_cylinder, 256, 3,
     normal_from_axis, NULL, NULL},
    {"cylinder side (surface)", "{type: cylinder, radius: 0.5, height: 2, emit_from: surface}",
     bin_cylinder_side, 128, 2, normal_from_axis, NULL, NULL},
    {"cone volume", "{type: cone, radius: 1, height: 2, angle: 30}", bin_cone, 256, 3,
     normal_cone_fan, cone_height_uniform, "cone volume, biased height uniform"},
    {"cone surface", "{type: cone, radius: 1, height: 2, emit_from: surface}", bin_cone_side, 128,
     2, normal_cone_side, cone_side_q_uniform, "cone side, biased q uniform"},
};

/* Every sample takes the same number of generator outputs, 2 per unit. */
static bool fixed_draws(const pfx_shape *s, int units, normal_fn check_normal, int *bad_normals) {
    pfx_rng r;
    pfx_rng_seed(&r, 99, 7);
    bool fixed = true;
    *bad_normals = 0;
    for (int i = 0; i < 2000; i++) {
        uint64_t before = r.draws;
        double p[3], n[3];
        pfx_sample_shape(s, &r, p, n);
        fixed &= r.draws - before == (uint64_t)(2 * units);
        bool ok = fabs(norm3(n) - 1) < 1e-12 && (!check_normal || check_normal(s, p, n));
        if (!ok && (*bad_normals)++ < 3)
            fprintf(stderr, "  normal (%g, %g, %g) at (%g, %g, %g) is wrong\n", n[0], n[1], n[2],
                    p[0], p[1], p[2]);
    }
    return fixed;
}

static void test_shape_cases(void) {
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        const shape_case *c = &cases[i];
        compiled cc;
        const pfx_shape *s = compile_shape_text(&cc, c->shape, "inline.yaml");
        CHECK(s != NULL);
        if (!s) {
            fprintf(stderr, "  %s: does not compile\n", c->name);
            continue;
        }
        if (c->bin) {
            CHECK(uniform_test(c->name, shape_sampler, s, c->bin, s, c->bins, NULL));
            if (c->biased)
                CHECK(!uniform_test(c->biased_name, c->biased, s, c->bin, s, c->bins, NULL));
        }
        int bad;
        bool fixed = fixed_draws(s, c->units, c->normal, &bad);
        if (!fixed)
            fprintf(stderr, "  %s: draws per sample are not %d\n", c->name, 2 * c->units);
        CHECK(fixed);
        CHECK(bad == 0);
        compiled_free(&cc);
    }
}

/* The rim of an eccentric ellipse (4:1): the arc-length table against
 * Simpson-rule bounds; uniform t must fail. */
static void test_ellipse_edge(void) {
    static const char *const shapes[] = {"{type: ellipse, radii: [2, 0.5], emit_from: edge}",
                                         "{type: ellipse, radii: [0.3, 3], emit_from: edge}"};
    for (int k = 0; k < 2; k++) {
        compiled cc;
        const pfx_shape *s = compile_shape_text(&cc, shapes[k], "inline.yaml");
        CHECK(s != NULL);
        if (!s)
            continue;
        static ellipse_rim rim;
        ellipse_rim_init(&rim, s->radii[0], s->radii[1]);
        char what[64];
        snprintf(what, sizeof what, "ellipse edge [%g, %g]", s->radii[0], s->radii[1]);
        CHECK(uniform_test(what, shape_sampler, s, bin_ellipse_edge, &rim, ELL_BINS, NULL));
        snprintf(what, sizeof what, "ellipse edge [%g, %g], biased t", s->radii[0], s->radii[1]);
        CHECK(
            !uniform_test(what, ellipse_edge_uniform_t, s, bin_ellipse_edge, &rim, ELL_BINS, NULL));
        /* The table's length against Simpson's (the trapezoid rule on a
         * periodic function converges geometrically). */
        CHECK_NEAR(s->cum[s->cum_count - 1], rim.len, 1e-9 * rim.len);
        int bad;
        CHECK(fixed_draws(s, 1, normal_ellipse_edge, &bad));
        CHECK(bad == 0);
        compiled_free(&cc);
    }
}

/* The committed two-triangle OBJ (areas 1 and 3): 16 sub-triangles each,
 * probabilities by area; the count on each triangle is 1/4 and 3/4 of the
 * samples within 5 binomial standard errors. */
static void test_mesh_surface(void) {
    char path[4200];
    snprintf(path, sizeof path, "%s/tests/diag/inline.yaml", test_source_dir());
    compiled cc;
    const pfx_shape *s =
        compile_shape_text(&cc, "{type: mesh, file: shape_mesh_two_triangles.obj}", path);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK(s->cum_count == 2 && s->from == PFX_EMIT_SURFACE);
    CHECK_NEAR(s->cum[0], 1, 1e-12);
    CHECK_NEAR(s->cum[1], 4, 1e-12);
    static mesh_bins mb;
    mesh_bins_init(&mb, s);
    CHECK(uniform_test("mesh surface (areas 1, 3)", shape_sampler, s, bin_mesh, &mb, mb.bins,
                       mb.prob));
    CHECK(!uniform_test("mesh, biased triangles 1/2 each", mesh_triangles_equal, s, bin_mesh, &mb,
                        mb.bins, mb.prob));
    CHECK(!uniform_test("mesh, biased no sqrt", mesh_no_sqrt, s, bin_mesh, &mb, mb.bins, mb.prob));

    pfx_rng r;
    pfx_rng_seed(&r, 5, 5);
    long on_second = 0;
    for (int i = 0; i < N_CHI; i++) {
        double p[3], n[3];
        pfx_sample_shape(s, &r, p, n);
        on_second += p[1] > 0.5;
    }
    double frac = (double)on_second / N_CHI;
    fprintf(stderr, "  mesh: %.4f of the samples on the area-3 triangle (expected 0.75)\n", frac);
    CHECK_NEAR(frac, 0.75, 5 * sqrt(0.75 * 0.25 / N_CHI));
    int bad;
    CHECK(fixed_draws(s, 3, normal_up, &bad));
    CHECK(bad == 0);
    compiled_free(&cc);
}

/* The uniform-angle cone of directions (docs/physics.md, Uniform sampling) fails the
 * cap test that the shipped sampler passes: (1 - cos theta) / (1 - cos
 * spread) quantiles (8) x azimuth (16) about +Y. */
static double cap_cos_max;
static int bin_cap_y(const void *ctx, const double p[3]) {
    (void)ctx;
    if (fabs(norm3(p) - 1) > 1e-12 || p[1] < cap_cos_max - 1e-12)
        return -1;
    return clampi((1 - p[1]) / (1 - cap_cos_max), 8) * 16 + clampi(azimuth01(p[2], p[0]), 16);
}
static void cap_sampler(const void *ctx, pfx_rng *r, double out[3]) {
    static const double up[3] = {0, 1, 0};
    pfx_sample_cone(up, *(const double *)ctx * PI / 180, r, out);
}
static void cap_uniform_angle(const void *ctx, pfx_rng *r, double out[3]) {
    double th = pfx_rng_unit(r) * *(const double *)ctx * PI / 180, ph = 2 * PI * pfx_rng_unit(r);
    out[0] = sin(th) * cos(ph), out[1] = cos(th), out[2] = sin(th) * sin(ph);
}

static void test_direction_cap(void) {
    double spread = 40;
    cap_cos_max = cos(spread * PI / 180);
    CHECK(uniform_test("cap 40 deg about +Y", cap_sampler, &spread, bin_cap_y, NULL, 128, NULL));
    CHECK(!uniform_test("cap 40 deg, biased uniform angle", cap_uniform_angle, &spread, bin_cap_y,
                        NULL, 128, NULL));
}

/* The shapes that existed before emit_from (sphere, box and disc volumes,
 * the point) draw exactly the values of their former formulas, so effects
 * and their pinned hashes do not change; the sphere's radius is fast_d.h's
 * cube root (and its direction's turn fast_d.h's sincos) since
 * PFX_RESULTS 4's emission kernels. */
static void test_old_shapes_unchanged(void) {
    pfx_shape sphere = {.type = PFX_SHAPE_SPHERE, .radius = 1.7};
    pfx_shape box = {.type = PFX_SHAPE_BOX, .size = {1, 2.5, 0.4}};
    pfx_shape disc = {.type = PFX_SHAPE_DISC, .radius = 0.6};
    pfx_shape point = {.type = PFX_SHAPE_POINT};
    pfx_rng a, b;
    pfx_rng_seed(&a, 3, 4);
    pfx_rng_seed(&b, 3, 4);
    int differ = 0;
    for (int i = 0; i < 1000; i++) {
        double p[3], n[3], q[3], d[3];
        pfx_sample_shape(&sphere, &a, p, n);
        pfx_sample_direction(&b, d);
        double rad = sphere.radius * pfx_cbrt_unit(pfx_rng_unit(&b));
        for (int k = 0; k < 3; k++)
            q[k] = d[k] * rad;
        differ += memcmp(p, q, sizeof p) != 0;
        pfx_sample_shape(&box, &a, p, n);
        for (int k = 0; k < 3; k++)
            q[k] = (pfx_rng_unit(&b) - 0.5) * box.size[k];
        differ += memcmp(p, q, sizeof p) != 0;
        pfx_sample_shape(&disc, &a, p, n);
        double dr = disc.radius * sqrt(pfx_rng_unit(&b)), th = 2.0 * M_PI * pfx_rng_unit(&b);
        q[0] = dr * cos(th), q[1] = 0, q[2] = dr * sin(th);
        differ += memcmp(p, q, sizeof p) != 0;
        pfx_sample_shape(&point, &a, p, n);
        differ += p[0] != 0 || p[1] != 0 || p[2] != 0;
    }
    CHECK(differ == 0);
    CHECK(a.state == b.state && a.draws == b.draws);
    int bad;
    CHECK(fixed_draws(&point, 0, normal_up, &bad));
    CHECK(bad == 0);
}

/* ---- The OBJ reader ---- */

/* The reader's diagnostics go to a list; err gets the first message. */
static bool first_error(bool ok, pfx_diags *d, char *err) {
    snprintf(err, 256, "%s", d->count ? d->items[0].message : "");
    pfx_diags_free(d);
    return ok;
}

static bool parse_scaled(const char *text, size_t len, double scale, pfx_arena *a, pfx_mesh *m,
                         char *err) {
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    pfx_diag_at at = {&d, 0, 0, 0};
    return first_error(pfx_mesh_parse(text, len, "t.obj", scale, a, m, &at), &d, err);
}

static bool parse(const char *text, pfx_arena *a, pfx_mesh *m, char *err) {
    return parse_scaled(text, strlen(text), 1, a, m, err);
}

static void check_error(const char *text, const char *want) {
    pfx_arena a = {0};
    pfx_mesh m;
    char err[256] = "";
    bool ok = parse(text, &a, &m, err);
    CHECK(!ok);
    if (ok || strcmp(err, want)) {
        fprintf(stderr, "  got   '%s'\n  wanted '%s'\n", err, want);
        CHECK(!strcmp(err, want));
    }
    pfx_arena_free(&a);
}

static void test_obj_reader(void) {
    pfx_arena a = {0};
    pfx_mesh m;
    char err[256] = "";
    /* A quad and a pentagon fan into 2 + 3 triangles; vt, vn, o, g, s,
     * usemtl, comments, CRLF and the i/t/n forms are skipped or read. */
    const char *text = "\xEF\xBB\xBF# comment\r\nmtllib x.mtl\r\no thing\r\n"
                       "v 0 0 0\r\nv 1 0 0\r\nv 1 0 1 1.0\r\nv 0 0 1 # trailing\r\n"
                       "vt 0 0\nvn 0 1 0\ng g1\ns off\nusemtl m\n"
                       "f 1/1/1 4/1/1 3/1/1 2/1/1\n"
                       "v 0 1 0\nv 2 1 0\nv 2 1 2\nv 1 1 3\nv 0 1 2\n"
                       "f -5 -1 -2//1 -3/1 -4\n"
                       "l 1 2\n";
    CHECK(parse(text, &a, &m, err));
    if (*err)
        fprintf(stderr, "  %s\n", err);
    CHECK(m.vert_count == 9 && m.tri_count == 5);
    /* Fans from the first corner: (0, 3, 2), (0, 2, 1); then from v5. */
    static const uint32_t want[] = {0, 3, 2, 0, 2, 1, 4, 8, 7, 4, 7, 6, 4, 6, 5};
    CHECK(m.tri_count == 5 && !memcmp(m.tris, want, sizeof want));
    /* Areas: the unit quad 1; the pentagon 2 x 2 square plus a triangle of 1. */
    CHECK_NEAR(m.cum[1], 1, 1e-12);
    CHECK_NEAR(m.cum[4], 1 + 4 + 1, 1e-12);
    pfx_arena_free(&a);

    /* scale multiplies every coordinate (areas by scale^2). */
    memset(&a, 0, sizeof a);
    CHECK(parse_scaled("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 32, 3, &a, &m, err));
    CHECK(m.verts[3] == 3 && m.verts[7] == 3);
    CHECK_NEAR(m.cum[0], 4.5, 1e-12);
    pfx_arena_free(&a);

    check_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n\n# x\nf 1 2 9\n",
                "'t.obj' line 6: face index 9 is out of range (3 vertices)");
    check_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
                "'t.obj' line 4: face index 0 is out of range (3 vertices)");
    check_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n",
                "'t.obj' line 4: face index -4 is out of range (3 vertices)");
    /* A face may use only the vertices above it. */
    check_error("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n",
                "'t.obj' line 3: face index 3 is out of range (2 vertices)");
    check_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x/1\n",
                "'t.obj' line 4: 'x/1' is not a face index");
    check_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf //1 2 3\n",
                "'t.obj' line 4: '//1' is not a face index");
    check_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
                "'t.obj' line 4: a face needs at least 3 vertices");
    check_error("v 0 0 0\nv 1 zero 0\n", "'t.obj' line 2: 'zero' is not a number");
    check_error("v 0 0 0\nv 1 nan 0\n", "'t.obj' line 2: 'nan' is not a number");
    check_error("v 0 0 0\nv 1 1e999 0\n", "'t.obj' line 2: '1e999' is not a number");
    check_error("v 0 0\n", "'t.obj' line 1: a vertex needs 3 coordinates");
    check_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "'t.obj' has no faces");
    check_error("", "'t.obj' has no faces");
    check_error("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 1\n",
                "the faces of 't.obj' have zero total area");
    check_error("v 0 0 0\nv 1e200 0 0\nv 0 1e200 0\nf 1 2 3\n",
                "the faces of 't.obj' have an infinite total area (coordinates too large)");
    /* A binary byte is quoted as '?', so messages stay UTF-8. */
    check_error("v 0 \xff 0\n", "'t.obj' line 1: '?' is not a number");

    /* More than a million triangles. */
    size_t n = PFX_MESH_MAX_TRIANGLES + 1, len = 0;
    char *big = malloc(32 + 8 * n);
    len += (size_t)sprintf(big, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for (size_t i = 0; i < n; i++)
        memcpy(big + len, "f 1 2 3\n", 8), len += 8;
    big[len] = '\0';
    char want_big[128];
    snprintf(want_big, sizeof want_big, "'t.obj' line %zu: more than %u triangles", n + 3,
             PFX_MESH_MAX_TRIANGLES);
    check_error(big, want_big);
    free(big);

    /* The file reader: a missing file says so. */
    memset(&a, 0, sizeof a);
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    pfx_diag_at at = {&d, 0, 0, 0};
    CHECK(!first_error(pfx_mesh_load("/nonexistent/dir/x.obj", "x.obj", 1, &a, &m, &at), &d, err));
    CHECK(!strcmp(err, "cannot open 'x.obj': No such file or directory"));
    pfx_arena_free(&a);
}

/* ---- Blocks: the simulation's path ---- */

#define BLOCK_N 4099 /* samples per shape: blocks of every size up to 64, odd ends */

static bool same_bits(const double *a, const double *b, size_t n) {
    return !memcmp(a, b, n * sizeof *a);
}

/* The block form (pfx_sample_shape_n, what births use) gives every shape's
 * samples bit for bit as the one-sample form the uniformity tests above
 * check, with and without normals, in blocks of 1 to 64 whose ends fall
 * anywhere in a vector: so the simulation's samples are those tested. */
static bool block_matches_one(const pfx_shape *s, const char *name) {
    static double u[3][BLOCK_N], one[6][BLOCK_N], blk[6][BLOCK_N], pos_only[3][BLOCK_N];
    const unsigned units = pfx_sample_shape_units(s);
    pfx_rng a, b;
    pfx_rng_seed(&a, 1234, 77);
    b = a;
    for (size_t k = 0; k < BLOCK_N; k++) {
        double p[3], n[3];
        pfx_sample_shape(s, &a, p, n);
        for (int i = 0; i < 3; i++)
            one[i][k] = p[i], one[3 + i][k] = n[i];
        for (unsigned d = 0; d < 3; d++)
            u[d][k] = d < units ? pfx_rng_unit(&b) : 0.25;
    }
    bool draws = a.draws == b.draws; /* units: as many as the sampler takes */
    for (size_t k0 = 0, len = 1; k0 < BLOCK_N; k0 += len, len = len % 64 + 1) {
        size_t n = BLOCK_N - k0 < len ? BLOCK_N - k0 : len;
        const double *const cu[3] = {u[0] + k0, u[1] + k0, u[2] + k0};
        pfx_sample_shape_n(s, n, cu, (double *const[3]){blk[0] + k0, blk[1] + k0, blk[2] + k0},
                           (double *const[3]){blk[3] + k0, blk[4] + k0, blk[5] + k0});
        pfx_sample_shape_n(s, n, cu,
                           (double *const[3]){pos_only[0] + k0, pos_only[1] + k0, pos_only[2] + k0},
                           NULL);
    }
    bool same = draws;
    for (int i = 0; i < 6; i++)
        same &= same_bits(one[i], blk[i], BLOCK_N);
    for (int i = 0; i < 3; i++)
        same &= same_bits(one[i], pos_only[i], BLOCK_N);
    if (!same)
        fprintf(stderr, "  %s: the block form differs from one sample at a time%s\n", name,
                draws ? "" : " (unit count)");
    return same;
}

static void test_blocks_match_one(void) {
    static const char *const more[] = {
        "{type: point}",
        "{type: ellipse, radii: [2, 0.5], emit_from: edge}",
        "{type: sphere, radius: 1, inner: 1e-100}",
        "{type: cone, radius: 0.3, height: 0, angle: 90}",
        "{type: mesh, file: shape_mesh_two_triangles.obj}",
    };
    char path[4200];
    snprintf(path, sizeof path, "%s/tests/diag/inline.yaml", test_source_dir());
    size_t ncases = sizeof cases / sizeof *cases, nmore = sizeof more / sizeof *more;
    for (size_t i = 0; i < ncases + nmore; i++) {
        const char *text = i < ncases ? cases[i].shape : more[i - ncases];
        compiled cc;
        const pfx_shape *s = compile_shape_text(&cc, text, path);
        CHECK(s != NULL);
        if (!s)
            continue;
        CHECK(block_matches_one(s, text));
        compiled_free(&cc);
    }
}

int main(void) {
    RUN(test_old_shapes_unchanged);
    RUN(test_shape_cases);
    RUN(test_ellipse_edge);
    RUN(test_mesh_surface);
    RUN(test_blocks_match_one);
    RUN(test_direction_cap);
    RUN(test_obj_reader);
    return TEST_EXIT();
}
