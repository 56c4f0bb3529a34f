/* The exact geometry of each deflector shape for the collide pass: the
 * prepared form of a deflector, the constraint a stored position must meet,
 * the earliest time of impact on a step's parabola (closed-form roots for
 * planes, discs and box faces, an exact root isolation of the quartic for
 * spheres) and the snap of a hit point onto the surface. */
#include "sim/collide_internal.h"

#include <string.h>

static void normalize(double v[3]) {
    double l = sqrt(dot(v, v));
    for (int j = 0; j < 3; j++)
        v[j] /= l;
}

void pfx_collide_prepare(const pfx_deflector *d, prep *p) {
    memset(p, 0, sizeof *p);
    p->shape = d->shape;
    p->inside = d->inside;
    memcpy(p->p, d->point, sizeof p->p);
    p->r = d->radius;
    p->mu_slide = 0.5 * (d->friction[0] + d->friction[1]);
    if (d->shape == PFX_DEFLECTOR_PLANE || d->shape == PFX_DEFLECTOR_DISC) {
        memcpy(p->n, d->normal, sizeof p->n);
        normalize(p->n);
    }
    if (d->shape == PFX_DEFLECTOR_DISC)
        p->thin = true;
    if (d->shape == PFX_DEFLECTOR_PLANE && d->size[0] > 0 && d->size[1] > 0) {
        p->thin = true;
        p->hu = 0.5 * d->size[0];
        p->hw = 0.5 * d->size[1];
        double e[3] = {d->axis_u[0], d->axis_u[1], d->axis_u[2]};
        if (dot(e, e) == 0) {
            /* world x, or z when the normal is within 25 deg of x */
            bool near_x = fabs(p->n[0]) > cos(25.0 * 3.14159265358979323846 / 180.0);
            e[0] = near_x ? 0 : 1;
            e[2] = near_x ? 1 : 0;
        }
        double en = dot(e, p->n);
        for (int j = 0; j < 3; j++)
            p->u[j] = e[j] - en * p->n[j];
        normalize(p->u);
        p->w[0] = p->n[1] * p->u[2] - p->n[2] * p->u[1];
        p->w[1] = p->n[2] * p->u[0] - p->n[0] * p->u[2];
        p->w[2] = p->n[0] * p->u[1] - p->n[1] * p->u[0];
    }
    if (d->shape == PFX_DEFLECTOR_BOX) {
        double ext = 1;
        for (int j = 0; j < 3; j++) {
            p->lo[j] = d->point[j] - 0.5 * d->size[j];
            p->hi[j] = d->point[j] + 0.5 * d->size[j];
            ext = dmax(ext, dmax(fabs(p->lo[j]), fabs(p->hi[j])));
        }
        p->edge_tol = 1e-9 * ext;
    }
}

/* The constraint a stored position must meet for deflector p: g >= 0 for a
 * one-sided shape (signed distance, positive on the particles' side), g > 0
 * for a thin one on side `side` (so its side is never ambiguous next step).
 * n receives the direction that increases g (the nudge direction). */
double pfx_collide_constraint(const prep *p, int side, const double x[3], double n[3]) {
    switch (p->shape) {
    case PFX_DEFLECTOR_PLANE:
    case PFX_DEFLECTOR_DISC: {
        double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
        for (int j = 0; j < 3; j++)
            n[j] = side * p->n[j];
        return side * dot(q, p->n);
    }
    case PFX_DEFLECTOR_SPHERE: {
        double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
        double l = sqrt(dot(q, q));
        double s = p->inside ? -1 : 1;
        for (int j = 0; j < 3; j++)
            n[j] = l > 0 ? s * q[j] / l : (j == 1 ? 1 : 0);
        return s * (l - p->r);
    }
    case PFX_DEFLECTOR_BOX: {
        /* e_j > 0: beyond the slab of axis j by e_j, on the side of sgn_j */
        double e[3], sgn[3];
        for (int j = 0; j < 3; j++) {
            double above = x[j] - p->hi[j], below = p->lo[j] - x[j];
            e[j] = dmax(above, below);
            sgn[j] = above >= below ? 1 : -1;
        }
        int m = 0;
        for (int j = 1; j < 3; j++)
            if (e[j] > e[m]) /* outside: farthest slab; inside: nearest face */
                m = j;
        n[0] = n[1] = n[2] = 0;
        if (p->inside) { /* g = margin to the nearest face, >= 0 inside */
            n[m] = -sgn[m];
            return -e[m];
        }
        n[m] = sgn[m];
        if (e[m] <= 0)
            return e[m];
        double s2 = 0;
        for (int j = 0; j < 3; j++)
            s2 += e[j] > 0 ? e[j] * e[j] : 0;
        return sqrt(s2);
    }
    }
    return 0;
}

/* Sign changes in [0, T] of f(s) = c + b s + A s^2, ascending: dir -1 where
 * f turns negative, +1 where it turns positive. The roots come from
 * q = -(b + sgn(b) sqrt(b^2 - 4Ac)) / 2 as q/A and c/q, which never
 * subtracts nearly equal numbers; A = 0 (or tiny: q/A is then far beyond T
 * and c/q is the linear root -c/b to full precision) needs no special case
 * beyond avoiding the division. A double root (graze) is not a crossing. */
static int crossings(double A, double b, double c, double T, double s[2], int dir[2]) {
    int m = 0;
    if (c == 0) { /* on the surface: which way does it go first, and does it come back */
        double first = b != 0 ? b : A;
        if (first < 0) {
            s[m] = 0;
            dir[m++] = -1;
        }
        if (b != 0 && A != 0 && (b > 0) != (A > 0)) {
            double r = -b / A;
            if (r <= T) {
                s[m] = r;
                dir[m++] = b > 0 ? -1 : 1;
            }
        }
        return m;
    }
    if (A == 0) {
        double r = b != 0 ? -c / b : -1;
        if (r > 0 && r <= T) {
            s[m] = r;
            dir[m++] = b < 0 ? -1 : 1;
        }
        return m;
    }
    double disc = b * b - 4 * A * c;
    if (!(disc > 0))
        return 0;
    double q = -0.5 * (b + copysign(sqrt(disc), b));
    double r1 = q / A, r2 = c / q;
    if (r1 > r2) {
        double t = r1;
        r1 = r2;
        r2 = t;
    }
    int d1 = A > 0 ? -1 : 1; /* A > 0: negative between the roots */
    if (r1 > 0 && r1 <= T) {
        s[m] = r1;
        dir[m++] = d1;
    }
    if (r2 > 0 && r2 <= T) {
        s[m] = r2;
        dir[m++] = -d1;
    }
    return m;
}

/* ---- Sphere: the quartic |q0 + v s + a s^2/2|^2 - r^2 -------------------
 * Roots are isolated exactly, without sampling, by the derivative cascade:
 * between consecutive real roots of p' the polynomial p is monotone, so each
 * such piece holds at most one root and a sign test at its ends decides.
 * The roots of p' come the same way from p'', down to a linear polynomial.
 * Each bracketed root is refined by Newton's method kept inside the bracket
 * (bisection when a step leaves it) to full double precision. No grazing
 * double crossing can be missed at any speed: the only approximation is
 * floating-point evaluation of p. */

static double horner(const double *c, int n, double s) {
    double r = c[n];
    for (int k = n - 1; k >= 0; k--)
        r = r * s + c[k];
    return r;
}

static double horner_d(const double *c, int n, double s) {
    double r = n * c[n];
    for (int k = n - 1; k >= 1; k--)
        r = r * s + k * c[k];
    return r;
}

/* The root of p in [a, b], where p(a) has the sign of fa (nonzero) and p(b)
 * the other sign. */
static double refine(const double *c, int n, double a, double b, double fa) {
    double x = 0.5 * (a + b);
    for (int it = 0; it < 100; it++) {
        double f = horner(c, n, x);
        if (f == 0)
            return x;
        if ((f > 0) == (fa > 0))
            a = x;
        else
            b = x;
        double df = horner_d(c, n, x);
        double xn = df != 0 ? x - f / df : 0.5 * (a + b);
        if (!(xn > a && xn < b))
            xn = 0.5 * (a + b);
        if (fabs(xn - x) <= 1e-16 * dmax(fabs(a), fabs(b)) || !(xn > a && xn < b))
            return xn;
        x = xn;
    }
    return x;
}

static int degree(const double *c, int n) {
    while (n > 0 && c[n] == 0)
        n--;
    return n;
}

/* Points in (lo, hi) where p (degree n <= 4) changes sign, ascending. */
static int sign_roots(const double *c, int n, double lo, double hi, double *out) {
    n = degree(c, n);
    if (n == 0)
        return 0;
    if (n == 1) {
        double r = -c[0] / c[1];
        if (r > lo && r < hi) {
            out[0] = r;
            return 1;
        }
        return 0;
    }
    double dc[4] = {0}, pts[6];
    for (int k = 1; k <= n; k++)
        dc[k - 1] = k * c[k];
    int np = 0;
    pts[np++] = lo;
    np += sign_roots(dc, n - 1, lo, hi, pts + np);
    pts[np++] = hi;
    int m = 0;
    double fa = horner(c, n, lo);
    for (int i = 0; i + 1 < np; i++) {
        double fb = horner(c, n, pts[i + 1]);
        if ((fa < 0 && fb > 0) || (fa > 0 && fb < 0))
            out[m++] = refine(c, n, pts[i], pts[i + 1], fa);
        else if (fb == 0 && i + 2 < np)
            out[m++] = pts[i + 1];
        fa = fb;
    }
    return m;
}

/* Earliest s in [0, T] where p (c[0] >= 0) turns negative. */
static bool first_entry(const double *c, int n, double T, double *s) {
    n = degree(c, n);
    if (n == 0)
        return false;
    double dc[4] = {0}, pts[6];
    for (int k = 1; k <= n; k++)
        dc[k - 1] = k * c[k];
    int np = 0;
    pts[np++] = 0;
    np += sign_roots(dc, n - 1, 0, T, pts + np);
    pts[np++] = T;
    double fa = c[0];
    for (int i = 0; i + 1 < np; i++) {
        double fb = horner(c, n, pts[i + 1]);
        if (fa < 0) {
            *s = pts[i];
            return true;
        }
        if (fb < 0) {
            *s = fa == 0 ? pts[i] : refine(c, n, pts[i], pts[i + 1], fa);
            return true;
        }
        fa = fb;
    }
    return false;
}

static bool in_bounds(const prep *p, const double x[3]) {
    double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
    if (p->shape == PFX_DEFLECTOR_DISC) {
        double qn = dot(q, p->n);
        for (int j = 0; j < 3; j++)
            q[j] -= qn * p->n[j];
        return dot(q, q) <= p->r * p->r;
    }
    return fabs(dot(q, p->u)) <= p->hu && fabs(dot(q, p->w)) <= p->hw;
}

/* The three time-of-impact tests below find the earliest hit of deflector
 * p by the path x + v s + a s^2/2, s in [0, T], for one family of shapes
 * each: a plane's or a box face's signed distance along the path is a
 * quadratic (closed-form roots), a sphere's is a quartic (the cascade
 * above). Each first culls what cannot be reached this segment. */

/* Planes and discs: the crossings of the plane, then (thin shapes) the
 * first one within the bounds. */
static bool detect_plane(const prep *p, int side, const double x[3], const double v[3],
                         const double a[3], double T, double touch, hit *h) {
    double s[2], P[3];
    int dir[2];
    double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
    double c = side * dot(q, p->n), b = side * dot(v, p->n), A = 0.5 * side * dot(a, p->n);
    if (fabs(c) > (fabs(b) + fabs(A) * T) * T + touch)
        return false; /* cannot reach the plane this segment */
    if (c <= touch) {
        /* On it (resting): normal parts left by rounding after the
         * normal was removed (1e-16 of the whole) are no motion; they
         * would otherwise report the same contact again at s = 0. */
        c = 0;
        if (b == 0 || fabs(b) <= NOISE * sqrt(dot(v, v))) /* (no square root for a 0) */
            b = 0;
        if (A == 0 || fabs(A) <= NOISE * sqrt(dot(a, a)))
            A = 0;
    }
    int m = crossings(A, b, c, T, s, dir);
    for (int e = 0; e < m; e++) {
        if (!p->thin) {
            if (dir[e] > 0)
                continue;
            h->s = s[e], h->side = 1;
            return true;
        }
        pos_at(x, v, a, s[e], P);
        if (in_bounds(p, P)) {
            h->s = s[e], h->side = dir[e] < 0 ? side : -side;
            return true;
        }
    }
    return false;
}

/* Spheres, from either side: the first entry of the quartic. */
static bool detect_sphere(const prep *p, const double x[3], const double v[3], const double a[3],
                          double T, double touch, hit *h) {
    double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
    double lq = sqrt(dot(q, q));
    double reach = sqrt(dot(v, v)) * T + 0.5 * sqrt(dot(a, a)) * T * T;
    if (p->inside ? lq + reach + touch < p->r : lq - reach - touch > p->r)
        return false; /* cannot reach the surface this segment */
    double sg = p->inside ? -1 : 1, qv = dot(q, v), qa = dot(q, a);
    double c[5] = {sg * (dot(q, q) - p->r * p->r), 0, 0, sg * dot(v, a), sg * 0.25 * dot(a, a)};
    if (c[0] <= 2 * p->r * touch) { /* on it: as for planes */
        c[0] = 0;
        if (qv == 0 || fabs(qv) <= NOISE * lq * sqrt(dot(v, v)))
            qv = 0;
        if (qa == 0 || fabs(qa) <= NOISE * lq * sqrt(dot(a, a)))
            qa = 0;
    }
    c[1] = sg * 2 * qv;
    c[2] = sg * (dot(v, v) + qa);
    return first_entry(c, 4, T, &h->s);
}

/* Boxes, from either side: the earliest downward crossing of a face plane
 * that lands on the face; inside, no bounds test is needed, since the first
 * face plane the path reaches is crossed on the box itself. */
static bool detect_box(const prep *p, const double x[3], const double v[3], const double a[3],
                       double T, double touch, hit *h) {
    double s[2], P[3];
    int dir[2];
    /* cull: the largest excess beyond a slab bounds the distance from
     * below outside, the smallest margin bounds it from above inside */
    double reach = sqrt(dot(v, v)) * T + 0.5 * sqrt(dot(a, a)) * T * T, e = -INFINITY;
    for (int j = 0; j < 3; j++)
        e = dmax(e, dmax(x[j] - p->hi[j], p->lo[j] - x[j]));
    if (p->inside ? -e > reach + touch : e > reach + touch)
        return false;
    bool found = false;
    for (int f = 0; f < 6; f++) {
        int j = f / 2;
        double sg = f % 2 ? -1 : 1, F = f % 2 ? p->lo[j] : p->hi[j];
        /* outside: the face's outer side is positive; inside: its inner side */
        double o = p->inside ? -sg : sg;
        double c = o * (x[j] - F), b = o * v[j], A = 0.5 * o * a[j];
        if (p->inside ? c < touch : c >= 0 && c < touch)
            c = 0; /* on the face (within `touch`) */
        int m = crossings(A, b, c, found ? h->s : T, s, dir);
        for (int e = 0; e < m; e++) {
            if (dir[e] > 0)
                continue;
            if (!p->inside) {
                pos_at(x, v, a, s[e], P);
                int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
                if (P[j1] < p->lo[j1] - p->edge_tol || P[j1] > p->hi[j1] + p->edge_tol ||
                    P[j2] < p->lo[j2] - p->edge_tol || P[j2] > p->hi[j2] + p->edge_tol)
                    break; /* the only downward crossing of this face plane */
            }
            if (!found || s[e] < h->s)
                h->s = s[e], h->face = f, found = true;
            break;
        }
    }
    return found;
}

/* Earliest hit of deflector p by the path x + v s + a s^2/2, s in [0, T]. */
bool pfx_collide_detect(const prep *p, int side, const double x[3], const double v[3],
                        const double a[3], double T, double touch, hit *h) {
    switch (p->shape) {
    case PFX_DEFLECTOR_PLANE:
    case PFX_DEFLECTOR_DISC:
        return detect_plane(p, side, x, v, a, T, touch, h);
    case PFX_DEFLECTOR_SPHERE:
        return detect_sphere(p, x, v, a, T, touch, h);
    case PFX_DEFLECTOR_BOX:
        return detect_box(p, x, v, a, T, touch, h);
    }
    return false;
}

/* Puts the hit point x exactly on the surface (as exactly as double allows:
 * for an axis-aligned plane, exactly) and returns the unit normal on the
 * particle's side in n. */
void pfx_collide_snap(const prep *p, const hit *h, double x[3], double n[3]) {
    switch (p->shape) {
    case PFX_DEFLECTOR_PLANE:
    case PFX_DEFLECTOR_DISC: {
        double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
        double d = dot(q, p->n);
        for (int j = 0; j < 3; j++) {
            x[j] -= d * p->n[j];
            n[j] = h->side * p->n[j];
        }
        return;
    }
    case PFX_DEFLECTOR_SPHERE: {
        double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
        double l = sqrt(dot(q, q)), sg = p->inside ? -1 : 1;
        for (int j = 0; j < 3; j++) {
            double u = l > 0 ? q[j] / l : (j == 1 ? 1 : 0);
            x[j] = p->p[j] + p->r * u;
            n[j] = sg * u;
        }
        return;
    }
    case PFX_DEFLECTOR_BOX: {
        int j = h->face / 2;
        double sg = h->face % 2 ? -1 : 1;
        x[j] = h->face % 2 ? p->lo[j] : p->hi[j];
        n[0] = n[1] = n[2] = 0;
        n[j] = p->inside ? -sg : sg;
        return;
    }
    }
}
