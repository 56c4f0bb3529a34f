/* The emission samplers, each uniform by construction (inverse CDFs, never
 * rejection, so a fixed number of draws) and each a function of its units:
 * a block of births samples its drawn units in straight loops over columns
 * (vectorised for the sphere, cone and spread through fast_d.h's kernels),
 * and one sample runs the same kernel: the same bits. The biased textbook
 * variants (docs/physics.md) live in the tests, to show theirs can fail. */
#include "sim/sample.h"

#include <assert.h>
#include <math.h>

#include "base/clones.h"
#include "sim/fast_d.h"

/* Force-inlined, so a loop over a block is one straight body. */
#define INLINE static inline __attribute__((always_inline))

/* One value from its units (two for a normal, one for a uniform). */
INLINE double value_at(const pfx_value *v, double u0, double u1) {
    switch (v->dist) {
    case PFX_DIST_CONST:
        return v->a;
    case PFX_DIST_UNIFORM:
        return v->a + (v->b - v->a) * u0; /* pfx_rng_range */
    case PFX_DIST_NORMAL: {
        /* Box-Muller; 1 - u keeps the logarithm's argument in (0, 1]. */
        double x = v->a + v->b * sqrt(-2.0 * log(1.0 - u0)) * cos(2.0 * M_PI * u1);
        return x < v->lo ? v->lo : x > v->hi ? v->hi : x;
    }
    }
    return v->a;
}

unsigned pfx_sample_value_units(const pfx_value *v) {
    return v->dist == PFX_DIST_CONST ? 0 : v->dist == PFX_DIST_NORMAL ? 2 : 1;
}

double pfx_sample_value(const pfx_value *v, pfx_rng *r) {
    double u[2] = {0, 0};
    for (unsigned d = 0; d < pfx_sample_value_units(v); d++)
        u[d] = pfx_rng_unit(r);
    return value_at(v, u[0], u[1]);
}

PFX_CLONES
void pfx_sample_value_n(const pfx_value *v, size_t n, const double *restrict u0,
                        const double *restrict u1, double *restrict out) {
    const double a = v->a, w = v->b - v->a;
    switch (v->dist) {
    case PFX_DIST_CONST:
        for (size_t k = 0; k < n; k++)
            out[k] = a;
        break;
    case PFX_DIST_UNIFORM:
        for (size_t k = 0; k < n; k++)
            out[k] = a + w * u0[k];
        break;
    case PFX_DIST_NORMAL:
        for (size_t k = 0; k < n; k++)
            out[k] = value_at(v, u0[k], u1[k]);
        break;
    }
}

/* max(0, x) for x not NaN, as fmax(0.0, x) gives it, without the libm
 * call: x = 1 - z z is never -0, so the two agree bit for bit. */
INLINE double clamp0(double x) { return x > 0.0 ? x : 0.0; }

/* The unit direction with z = 2 u0 - 1 and azimuth u1 turns. */
INLINE void direction_at(double u0, double u1, double out[3]) {
    double z = 2.0 * u0 - 1.0, sp, cp;
    pfx_sincos_turn(u1, &sp, &cp);
    double s = sqrt(clamp0(1.0 - z * z));
    out[0] = s * cp;
    out[1] = s * sp;
    out[2] = z;
}

void pfx_sample_direction(pfx_rng *r, double out[3]) {
    double u0 = pfx_rng_unit(r), u1 = pfx_rng_unit(r);
    direction_at(u0, u1, out);
}

/* n = v / |v|, or `fallback` when v is (nearly) zero. */
static void unit_or(const double v[3], double fx, double fy, double fz, double n[3]) {
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len > 1e-300) {
        for (int i = 0; i < 3; i++)
            n[i] = v[i] / len;
    } else {
        n[0] = fx, n[1] = fy, n[2] = fz;
    }
}

INLINE void set3(double v[3], double x, double y, double z) { v[0] = x, v[1] = y, v[2] = z; }

/* The index i of the first cum[i] > x, for x in [0, cum[n - 1]): one
 * binary search. Entries equal to their predecessor (zero measure) are
 * never returned. */
static uint32_t search_cum(const double *cum, uint32_t n, double x) {
    uint32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (cum[mid] > x)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* One unit: rect perimeter by length, from (-w/2, -h/2) along +X, +Z, -X,
 * -Z; the normal is the side's outward in-plane normal. */
static void rect_edge(double w, double h, double u, double out[3], double normal[3]) {
    double s = u * 2 * (w + h);
    if (s < w) {
        set3(out, s - w / 2, 0, -h / 2), set3(normal, 0, 0, -1);
    } else if ((s -= w) < h) {
        set3(out, w / 2, 0, s - h / 2), set3(normal, 1, 0, 0);
    } else if ((s -= h) < w) {
        set3(out, w / 2 - s, 0, h / 2), set3(normal, 0, 0, 1);
    } else {
        s -= w;
        set3(out, -w / 2, 0, h / 2 - fmin(s, h)), set3(normal, -1, 0, 0);
    }
}

/* One unit: the ellipse (a cos t, 0, b sin t) uniform by arc length. The
 * compiler tabulated cum[i] = arc length to t_i = 2 pi i / m by the
 * trapezoid rule on the speed v(t) = sqrt(a^2 sin^2 t + b^2 cos^2 t); here
 * the speed is taken linear inside the segment, so the arc length there is
 * v0 tau + c tau^2 with c = (v1 - v0) / (2 h), inverted in closed form.
 * The density is then exact for the tabulated speed: its error is that of
 * linear interpolation, O(h^2) (about 1e-4 relative for m = 512, b/a = 0.1). */
static void ellipse_edge(const pfx_shape *s, double u, double out[3], double normal[3]) {
    double a = s->radii[0], b = s->radii[1];
    uint32_t m = s->cum_count - 1;
    double len = s->cum[m], t = 0;
    if (len > 0) {
        double x = u * len;
        uint32_t i = search_cum(s->cum, m + 1, x);
        i = i == 0 ? 0 : i - 1; /* cum[i] <= x < cum[i + 1] */
        double h = 2 * M_PI / m, t0 = h * i, t1 = h * (i + 1);
        double v0 = hypot(a * sin(t0), b * cos(t0)), v1 = hypot(a * sin(t1), b * cos(t1));
        double d = x - s->cum[i], c = (v1 - v0) / (2 * h);
        double root = v0 + sqrt(fmax(0.0, v0 * v0 + 4 * c * d));
        double tau = root > 0 ? 2 * d / root : 0;
        t = t0 + fmin(tau, h);
    }
    double ct = cos(t), st = sin(t);
    set3(out, a * ct, 0, b * st);
    double n[3] = {b * ct, 0, a * st};
    unit_or(n, ct, 0, st, normal);
}

/* Three units: a triangle by area (binary search on the cumulative areas),
 * then p = (1 - sqrt r1) A + sqrt r1 (1 - r2) B + sqrt r1 r2 C, uniform over
 * it (Osada et al. 2002). The normal is (B - A) x (C - A): counter-
 * clockwise faces, OBJ's convention, face out. */
static void mesh_surface(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    double r1 = sqrt(u[1]), r2 = u[2];
    uint32_t n = s->cum_count;
    uint32_t t = search_cum(s->cum, n, u[0] * s->cum[n - 1]);
    const double *A = s->verts + 3 * s->tris[3 * t], *B = s->verts + 3 * s->tris[3 * t + 1],
                 *C = s->verts + 3 * s->tris[3 * t + 2];
    double wa = 1 - r1, wb = r1 * (1 - r2), wc = r1 * r2, e1[3], e2[3];
    for (int i = 0; i < 3; i++) {
        out[i] = wa * A[i] + wb * B[i] + wc * C[i];
        e1[i] = B[i] - A[i];
        e2[i] = C[i] - A[i];
    }
    double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    unit_or(c, 0, 1, 0, normal);
}

/* Three units: the six faces of a box by area, then a point on the face. */
static void box_surface(const double size[3], const double u[3], double out[3], double normal[3]) {
    double area[3] = {size[1] * size[2], size[0] * size[2], size[0] * size[1]};
    double x = u[0] * 2 * (area[0] + area[1] + area[2]);
    int axis = 2;
    for (int k = 0; k < 2; k++)
        if (x < 2 * area[k]) {
            axis = k;
            break;
        } else {
            x -= 2 * area[k];
        }
    double sign = x < area[axis] ? -1 : 1;
    int p = (axis + 1) % 3, q = (axis + 2) % 3;
    out[axis] = sign * size[axis] / 2;
    out[p] = (u[1] - 0.5) * size[p];
    out[q] = (u[2] - 0.5) * size[q];
    set3(normal, 0, 0, 0);
    normal[axis] = sign;
}

/* One sampler per shape kind: the point and normal of units u[0], u[1],
 * u[2] (as many as pfx_sample_shape_units says, in that order).
 * pfx_sample_shape_n dispatches through the table below, so a new kind is
 * one function and one row. */
typedef void shape_sampler(const pfx_shape *s, const double u[3], double out[3], double normal[3]);

static void sample_point(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    (void)s, (void)u;
    set3(out, 0, 0, 0), set3(normal, 0, 1, 0);
}

static void sample_line(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    double d[3], n[3];
    for (int i = 0; i < 3; i++) {
        out[i] = s->line_from[i] + u[0] * (s->line_to[i] - s->line_from[i]);
        d[i] = s->line_to[i] - s->line_from[i];
    }
    /* +Y made perpendicular to the line; +X for a vertical line. */
    double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    double k = dd > 0 ? d[1] / dd : 0;
    set3(n, -k * d[0], 1 - k * d[1], -k * d[2]);
    if (dd > 0 && n[1] < 1e-9)
        set3(n, 1, 0, 0);
    unit_or(n, 0, 1, 0, normal);
}

static void sample_rect(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    if (s->from == PFX_EMIT_EDGE) {
        rect_edge(s->size[0], s->size[1], u[0], out, normal);
    } else {
        set3(out, (u[0] - 0.5) * s->size[0], 0, (u[1] - 0.5) * s->size[1]);
        set3(normal, 0, 1, 0);
    }
}

/* Area: the ring's inverse CDF r = R sqrt(u (1 - k^2) + k^2), k = inner / R
 * (k = 0: the solid disc's R sqrt(u)), then the angle. Edge: the rim, the
 * angle alone. */
static void sample_disc(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    double frac = s->arc_turns > 0 ? s->arc_turns : 1.0;
    double rad = s->radius, ua = u[0];
    if (s->from != PFX_EMIT_EDGE) {
        double k = s->radius > 0 ? s->inner / s->radius : 0;
        rad = s->radius * sqrt(u[0] * (1 - k * k) + k * k);
        ua = u[1];
    }
    double th = 2.0 * M_PI * frac * ua, c = cos(th), sn = sin(th);
    set3(out, rad * c, 0, rad * sn);
    if (s->from == PFX_EMIT_EDGE)
        set3(normal, c, 0, sn);
    else
        set3(normal, 0, 1, 0);
}

static void sample_ellipse(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    if (s->from == PFX_EMIT_EDGE) {
        ellipse_edge(s, u[0], out, normal);
    } else {
        /* The unit disc's uniform point, stretched: a linear map keeps the
         * density uniform (unlike the thesis's x-then-y method). */
        double rad = sqrt(u[0]), th = 2.0 * M_PI * u[1];
        set3(out, s->radii[0] * rad * cos(th), 0, s->radii[1] * rad * sin(th));
        set3(normal, 0, 1, 0);
    }
}

static void sample_box(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    if (s->from == PFX_EMIT_SURFACE) {
        box_surface(s->size, u, out, normal);
    } else {
        for (int i = 0; i < 3; i++)
            out[i] = (u[i] - 0.5) * s->size[i];
        unit_or(out, 0, 1, 0, normal);
    }
}

/* (inner / R)^3, 0 for a shape of radius 0: the volume's inner bound. */
static double inner_cubed(const pfx_shape *s) {
    double k = s->radius > 0 ? s->inner / s->radius : 0;
    return k * k * k;
}

/* The point at unit direction d from the centre, from the unit drawn after
 * d: r = R cbrt(u (1 - k^3) + k^3) for the volume between k R and R (k = 0:
 * R cbrt(u)); the surface is r = R. The normal is d. k3: inner_cubed, and
 * R the radius, read once for a block. */
INLINE void along_direction(double R, double k3, bool surface, double u, const double d[3],
                            double out[3], double normal[3]) {
    const double rad = surface ? R : R * pfx_cbrt_unit(u * (1 - k3) + k3);
    for (int i = 0; i < 3; i++) {
        out[i] = d[i] * rad;
        normal[i] = d[i];
    }
}

/* A direction with z uniform on [-1, 1], then the radius. */
INLINE void sphere_at(double R, double k3, bool surface, const double u[3], double out[3],
                      double normal[3]) {
    double d[3];
    direction_at(u[0], u[1], d);
    along_direction(R, k3, surface, u[2], d, out, normal);
}

static void sample_sphere(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    sphere_at(s->radius, inner_cubed(s), s->from == PFX_EMIT_SURFACE, u, out, normal);
}

/* A direction in the +Y half with y uniform on [0, 1], then the radius. */
static void sample_hemisphere(const pfx_shape *s, const double u[3], double out[3],
                              double normal[3]) {
    double y = u[0], phi = 2.0 * M_PI * u[1];
    double sr = sqrt(fmax(0.0, 1.0 - y * y)), d[3];
    set3(d, sr * cos(phi), y, sr * sin(phi));
    along_direction(s->radius, inner_cubed(s), s->from == PFX_EMIT_SURFACE, u[2], d, out, normal);
}

/* Base disc at y = 0, top at y = height; surface is the side only (no
 * radius drawn: the angle and the height come first). */
static void sample_cylinder(const pfx_shape *s, const double u[3], double out[3],
                            double normal[3]) {
    double rad = s->radius;
    const double *v = u;
    if (s->from != PFX_EMIT_SURFACE)
        rad *= sqrt(u[0]), v = u + 1;
    double th = 2.0 * M_PI * v[0], y = s->height * v[1];
    double c = cos(th), sn = sin(th);
    set3(out, rad * c, y, rad * sn);
    set3(normal, c, 0, sn);
}

/* With q = 1 - y / h (1 at the base, 0 at the apex), the section at q is a
 * disc of radius R q: the volume below the apex has density ~ q^2 (q =
 * cbrt(u)), the lateral area ~ q (q = sqrt(u)). The volume's normal (libm
 * sin and cos of its tilt) only where `with_normal`: most directions never
 * read it, and without it the loop over a block vectorises. */
INLINE void cone_at(double R, double h, double angle, bool surface, const double u[3],
                    double out[3], double normal[3], bool with_normal) {
    double c, sn;
    pfx_sincos_turn(u[0], &sn, &c);
    if (surface) {
        double q = sqrt(u[1]);
        set3(out, R * q * c, h * (1 - q), R * q * sn);
        if (with_normal) {
            double n[3] = {h * c, R, h * sn};
            unit_or(n, 0, 1, 0, normal);
        }
    } else {
        double q = pfx_cbrt_unit(u[1]), rho = R * q * sqrt(u[2]);
        set3(out, rho * c, h * (1 - q), rho * sn);
        if (with_normal) {
            /* +Y tilted outward by angle * rho / R (Unity's cone fan). */
            double tilt = R > 0 ? angle * rho / R : 0;
            set3(normal, sin(tilt) * c, cos(tilt), sin(tilt) * sn);
        }
    }
}

static void sample_cone(const pfx_shape *s, const double u[3], double out[3], double normal[3]) {
    cone_at(s->radius, s->height, s->angle, s->from == PFX_EMIT_SURFACE, u, out, normal, true);
}

static shape_sampler *const samplers[] = {
    [PFX_SHAPE_POINT] = sample_point,       [PFX_SHAPE_LINE] = sample_line,
    [PFX_SHAPE_RECT] = sample_rect,         [PFX_SHAPE_DISC] = sample_disc,
    [PFX_SHAPE_ELLIPSE] = sample_ellipse,   [PFX_SHAPE_BOX] = sample_box,
    [PFX_SHAPE_SPHERE] = sample_sphere,     [PFX_SHAPE_HEMISPHERE] = sample_hemisphere,
    [PFX_SHAPE_CYLINDER] = sample_cylinder, [PFX_SHAPE_CONE] = sample_cone,
    [PFX_SHAPE_MESH] = mesh_surface,
};
#define PFX_SHAPE_ONE(e, name) +1
static_assert(sizeof samplers / sizeof *samplers == 0 PFX_SHAPE_KINDS(PFX_SHAPE_ONE),
              "one sampler per shape kind");
#undef PFX_SHAPE_ONE

unsigned pfx_sample_shape_units(const pfx_shape *s) {
    switch (s->type) {
    case PFX_SHAPE_POINT:
        return 0;
    case PFX_SHAPE_LINE:
        return 1;
    case PFX_SHAPE_BOX:
    case PFX_SHAPE_MESH:
        return 3;
    case PFX_SHAPE_RECT:
    case PFX_SHAPE_DISC:
    case PFX_SHAPE_ELLIPSE:
        return s->from == PFX_EMIT_EDGE ? 1 : 2;
    default: /* sphere, hemisphere, cylinder, cone */
        return s->from == PFX_EMIT_SURFACE ? 2 : 3;
    }
}

void pfx_sample_shape(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    assert((size_t)s->type < sizeof samplers / sizeof *samplers && samplers[s->type]);
    double u[3] = {0, 0, 0};
    for (unsigned d = 0; d < pfx_sample_shape_units(s); d++)
        u[d] = pfx_rng_unit(r);
    samplers[s->type](s, u, out, normal);
}

/* A block through one per-sample kernel, inlined into a straight loop:
 * sample k's units from the columns u0, u1, u2, its point into (ox, oy,
 * oz) and, where `with_normal` (a constant), its normal into (nx, ny, nz). */
#define SHAPE_LOOP(call, with_normal)                                                              \
    for (size_t k = 0; k < n; k++) {                                                               \
        const double uk[3] = {u0[k], u1[k], u2[k]};                                                \
        double o[3], nr[3] = {0, 0, 0};                                                            \
        call;                                                                                      \
        ox[k] = o[0], oy[k] = o[1], oz[k] = o[2];                                                  \
        if (with_normal)                                                                           \
            nx[k] = nr[0], ny[k] = nr[1], nz[k] = nr[2];                                           \
    }

/* The columns of a block's shape samples, restrict: no two overlap. */
#define SHAPE_COLUMNS                                                                              \
    const pfx_shape *restrict s, size_t n, const double *restrict u0, const double *restrict u1,   \
        const double *restrict u2, double *restrict ox, double *restrict oy, double *restrict oz,  \
        double *restrict nx, double *restrict ny, double *restrict nz

/* The sphere's and the cone's loops: fast_d.h's kernels, sqrt and
 * division only, so they vectorise (the clones run 4 or 8 samples at once
 * with the same bits). */
PFX_CLONES
static void sphere_n(SHAPE_COLUMNS) {
    const double R = s->radius, k3 = inner_cubed(s);
    if (s->from == PFX_EMIT_SURFACE)
        SHAPE_LOOP(sphere_at(R, k3, true, uk, o, nr), nx)
    else if (nx)
        SHAPE_LOOP(sphere_at(R, k3, false, uk, o, nr), true)
    else
        SHAPE_LOOP(sphere_at(R, k3, false, uk, o, nr), false)
}

PFX_CLONES
static void cone_n(SHAPE_COLUMNS) {
    const double R = s->radius, h = s->height, angle = s->angle;
    const bool surface = s->from == PFX_EMIT_SURFACE;
    if (nx)
        SHAPE_LOOP(cone_at(R, h, angle, surface, uk, o, nr, true), true)
    else if (surface)
        SHAPE_LOOP(cone_at(R, h, angle, true, uk, o, nr, false), false)
    else
        SHAPE_LOOP(cone_at(R, h, angle, false, uk, o, nr, false), false)
}

/* The point: constants, no call per sample. */
PFX_CLONES
static void point_n(SHAPE_COLUMNS) {
    if (nx)
        SHAPE_LOOP(sample_point(s, uk, o, nr), true)
    else
        SHAPE_LOOP(sample_point(s, uk, o, nr), false)
}

/* Every other kind: its sampler called per sample (libm, table searches). */
static void any_n(SHAPE_COLUMNS) {
    shape_sampler *f = samplers[s->type];
    if (nx)
        SHAPE_LOOP(f(s, uk, o, nr), true)
    else
        SHAPE_LOOP(f(s, uk, o, nr), false)
}

void pfx_sample_shape_n(const pfx_shape *s, size_t n, const double *const u[3],
                        double *const out[3], double *const normal[3]) {
    assert((size_t)s->type < sizeof samplers / sizeof *samplers && samplers[s->type]);
    void (*loop)(SHAPE_COLUMNS) = s->type == PFX_SHAPE_POINT    ? point_n
                                  : s->type == PFX_SHAPE_SPHERE ? sphere_n
                                  : s->type == PFX_SHAPE_CONE   ? cone_n
                                                                : any_n;
    loop(s, n, u[0], u[1], u[2], out[0], out[1], out[2], normal ? normal[0] : NULL,
         normal ? normal[1] : NULL, normal ? normal[2] : NULL);
}

/* cos(spread), remembered per thread: an emitter's births come in runs with
 * one spread, and libm's cos of it was 6 % of a birth's time. A pure
 * function of the spread, so the bits do not depend on the order of
 * calls or on the thread. */
static double cos_of_spread(double spread) {
    static _Thread_local double last_spread = 0, last_cos = 1;
    if (spread != last_spread) {
        last_cos = cos(spread);
        last_spread = spread;
    }
    return last_cos;
}

/* One direction in the cap about unit `axis` from units u0 (cos theta)
 * and u1 (the azimuth in turns). */
INLINE void cone_dir_at(const double axis[3], double cos_max, double u0, double u1, double out[3]) {
    double ct = 1.0 - u0 * (1.0 - cos_max);
    double st = sqrt(clamp0(1.0 - ct * ct)), sphi, cphi;
    pfx_sincos_turn(u1, &sphi, &cphi);
    /* An orthonormal basis (t, b, axis) without a branch on a fixed up vector
     * (Duff et al. 2017, "Building an orthonormal basis, revisited"). */
    double sign = copysign(1.0, axis[2]);
    double a = -1.0 / (sign + axis[2]), b = axis[0] * axis[1] * a;
    double t[3] = {1.0 + sign * axis[0] * axis[0] * a, sign * b, -sign * axis[0]};
    double bt[3] = {b, sign + axis[1] * axis[1] * a, -axis[1]};
    double cp = st * cphi, sp = st * sphi;
    for (int i = 0; i < 3; i++)
        out[i] = t[i] * cp + bt[i] * sp + axis[i] * ct;
}

void pfx_sample_cone(const double axis[3], double spread, pfx_rng *r, double out[3]) {
    double u0 = pfx_rng_unit(r), u1 = pfx_rng_unit(r);
    cone_dir_at(axis, cos_of_spread(spread), u0, u1, out);
}

/* The columns of a block's spread, restrict: no two overlap. */
#define CONE_COLUMNS                                                                               \
    size_t n, const double *restrict ax, const double *restrict ay, const double *restrict az,     \
        double cos_max, const double *restrict u0, const double *restrict u1, double *restrict ox, \
        double *restrict oy, double *restrict oz

/* One axis a sample (stride 1) or one for the block (stride 0, the basis
 * then computed once): the same kernel, specialised by the constant. */
#define CONE_LOOP(stride)                                                                          \
    for (size_t k = 0; k < n; k++) {                                                               \
        const double a[3] = {ax[k * (stride)], ay[k * (stride)], az[k * (stride)]};                \
        double o[3];                                                                               \
        cone_dir_at(a, cos_max, u0[k], u1[k], o);                                                  \
        ox[k] = o[0], oy[k] = o[1], oz[k] = o[2];                                                  \
    }

PFX_CLONES
static void cone_dirs_n(CONE_COLUMNS){CONE_LOOP(1)}

PFX_CLONES static void cone_dirs_one_axis(CONE_COLUMNS) {
    CONE_LOOP(0)
}

void pfx_sample_cone_n(size_t n, const double *const axis[3], bool one_axis, double spread,
                       const double *u0, const double *u1, double *const out[3]) {
    (one_axis ? cone_dirs_one_axis : cone_dirs_n)(
        n, axis[0], axis[1], axis[2], cos_of_spread(spread), u0, u1, out[0], out[1], out[2]);
}
