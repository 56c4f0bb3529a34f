/* The emission samplers. Each is uniform by construction: inverse CDFs
 * (sqrt for areas in r, cbrt for volumes, tables for an ellipse's rim and a
 * mesh's triangles), never rejection, so every call takes a fixed number of
 * draws; cos(theta) uniform for caps. The sphere's, the cone's and the
 * spread's turns and cube roots go through fast_d.h's inline kernels (no
 * libm call: about a third of a birth's time was sincos and cbrt there).
 * The biased textbook variants (docs/physics.md, Uniform sampling) are not here; the
 * tests carry them to show the uniformity tests can fail. */
#include "sim/sample.h"

#include <assert.h>
#include <math.h>

#include "sim/fast_d.h"

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
    double z = 2.0 * pfx_rng_unit(r) - 1.0, sp, cp;
    pfx_sincos_turn(pfx_rng_unit(r), &sp, &cp);
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    out[0] = s * cp;
    out[1] = s * sp;
    out[2] = z;
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

static void set3(double v[3], double x, double y, double z) { v[0] = x, v[1] = y, v[2] = z; }

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
static void mesh_surface(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    double u = pfx_rng_unit(r), r1 = sqrt(pfx_rng_unit(r)), r2 = pfx_rng_unit(r);
    uint32_t n = s->cum_count;
    uint32_t t = search_cum(s->cum, n, u * s->cum[n - 1]);
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
static void box_surface(const double size[3], pfx_rng *r, double out[3], double normal[3]) {
    double u = pfx_rng_unit(r), v = pfx_rng_unit(r), w = pfx_rng_unit(r);
    double area[3] = {size[1] * size[2], size[0] * size[2], size[0] * size[1]};
    double x = u * 2 * (area[0] + area[1] + area[2]);
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
    out[p] = (v - 0.5) * size[p];
    out[q] = (w - 0.5) * size[q];
    set3(normal, 0, 0, 0);
    normal[axis] = sign;
}

/* One sampler per shape kind, each drawing in the order the header's draw
 * counts describe; pfx_sample_shape dispatches through the table below, so a
 * new kind is one function and one row. */
typedef void shape_sampler(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]);

static void sample_point(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    (void)s, (void)r;
    set3(out, 0, 0, 0), set3(normal, 0, 1, 0);
}

static void sample_line(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    double u = pfx_rng_unit(r), d[3], n[3];
    for (int i = 0; i < 3; i++) {
        out[i] = s->line_from[i] + u * (s->line_to[i] - s->line_from[i]);
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

static void sample_rect(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    if (s->from == PFX_EMIT_EDGE) {
        rect_edge(s->size[0], s->size[1], pfx_rng_unit(r), out, normal);
    } else {
        double u = pfx_rng_unit(r), v = pfx_rng_unit(r);
        set3(out, (u - 0.5) * s->size[0], 0, (v - 0.5) * s->size[1]);
        set3(normal, 0, 1, 0);
    }
}

/* Area: the ring's inverse CDF r = R sqrt(u (1 - k^2) + k^2), k = inner / R
 * (k = 0: the solid disc's R sqrt(u)). Edge: the rim. */
static void sample_disc(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    double frac = s->arc_turns > 0 ? s->arc_turns : 1.0;
    double rad = s->radius;
    if (s->from != PFX_EMIT_EDGE) {
        double k = s->radius > 0 ? s->inner / s->radius : 0;
        rad = s->radius * sqrt(pfx_rng_unit(r) * (1 - k * k) + k * k);
    }
    double th = 2.0 * M_PI * frac * pfx_rng_unit(r), c = cos(th), sn = sin(th);
    set3(out, rad * c, 0, rad * sn);
    if (s->from == PFX_EMIT_EDGE)
        set3(normal, c, 0, sn);
    else
        set3(normal, 0, 1, 0);
}

static void sample_ellipse(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    if (s->from == PFX_EMIT_EDGE) {
        ellipse_edge(s, pfx_rng_unit(r), out, normal);
    } else {
        /* The unit disc's uniform point, stretched: a linear map keeps the
         * density uniform (unlike the thesis's x-then-y method). */
        double rad = sqrt(pfx_rng_unit(r)), th = 2.0 * M_PI * pfx_rng_unit(r);
        set3(out, s->radii[0] * rad * cos(th), 0, s->radii[1] * rad * sin(th));
        set3(normal, 0, 1, 0);
    }
}

static void sample_box(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    if (s->from == PFX_EMIT_SURFACE) {
        box_surface(s->size, r, out, normal);
    } else {
        for (int i = 0; i < 3; i++)
            out[i] = (pfx_rng_unit(r) - 0.5) * s->size[i];
        unit_or(out, 0, 1, 0, normal);
    }
}

/* The point at unit direction d from the centre, drawn after d: r = R
 * cbrt(u (1 - k^3) + k^3) for the volume between k R and R (k = 0: R
 * cbrt(u)); the surface is r = R. The normal is d. */
static void along_direction(const pfx_shape *s, pfx_rng *r, const double d[3], double out[3],
                            double normal[3]) {
    double rad = s->radius;
    if (s->from != PFX_EMIT_SURFACE) {
        double k = s->radius > 0 ? s->inner / s->radius : 0, k3 = k * k * k;
        rad = s->radius * pfx_cbrt_unit(pfx_rng_unit(r) * (1 - k3) + k3);
    }
    for (int i = 0; i < 3; i++) {
        out[i] = d[i] * rad;
        normal[i] = d[i];
    }
}

/* A direction with z uniform on [-1, 1], then the radius. */
static void sample_sphere(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    double d[3];
    pfx_sample_direction(r, d);
    along_direction(s, r, d, out, normal);
}

/* A direction in the +Y half with y uniform on [0, 1], then the radius. */
static void sample_hemisphere(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    double y = pfx_rng_unit(r), phi = 2.0 * M_PI * pfx_rng_unit(r);
    double sr = sqrt(fmax(0.0, 1.0 - y * y)), d[3];
    set3(d, sr * cos(phi), y, sr * sin(phi));
    along_direction(s, r, d, out, normal);
}

/* Base disc at y = 0, top at y = height; surface is the side only. */
static void sample_cylinder(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    double rad = s->radius;
    if (s->from != PFX_EMIT_SURFACE)
        rad *= sqrt(pfx_rng_unit(r));
    double th = 2.0 * M_PI * pfx_rng_unit(r), y = s->height * pfx_rng_unit(r);
    double c = cos(th), sn = sin(th);
    set3(out, rad * c, y, rad * sn);
    set3(normal, c, 0, sn);
}

/* With q = 1 - y / h (1 at the base, 0 at the apex), the section at q is a
 * disc of radius R q: the volume below the apex has density ~ q^2 (q =
 * cbrt(u)), the lateral area ~ q (q = sqrt(u)). */
static void sample_cone(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    double R = s->radius, h = s->height;
    double c, sn;
    pfx_sincos_turn(pfx_rng_unit(r), &sn, &c);
    if (s->from == PFX_EMIT_SURFACE) {
        double q = sqrt(pfx_rng_unit(r));
        set3(out, R * q * c, h * (1 - q), R * q * sn);
        double n[3] = {h * c, R, h * sn};
        unit_or(n, 0, 1, 0, normal);
    } else {
        double q = pfx_cbrt_unit(pfx_rng_unit(r)), rho = R * q * sqrt(pfx_rng_unit(r));
        set3(out, rho * c, h * (1 - q), rho * sn);
        /* +Y tilted outward by angle * rho / R (Unity's cone fan). */
        double tilt = R > 0 ? s->angle * rho / R : 0;
        set3(normal, sin(tilt) * c, cos(tilt), sin(tilt) * sn);
    }
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

void pfx_sample_shape(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]) {
    assert((size_t)s->type < sizeof samplers / sizeof *samplers && samplers[s->type]);
    samplers[s->type](s, r, out, normal);
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

void pfx_sample_cone(const double axis[3], double spread, pfx_rng *r, double out[3]) {
    double cos_max = cos_of_spread(spread);
    double ct = 1.0 - pfx_rng_unit(r) * (1.0 - cos_max);
    double st = sqrt(fmax(0.0, 1.0 - ct * ct)), sphi, cphi;
    pfx_sincos_turn(pfx_rng_unit(r), &sphi, &cphi);
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
