/* The collide pass: after the integrator has moved a pool through a step,
 * find each particle's earliest hit on the step's parabola, respond at that
 * exact time, continue from there, and store a state never on the wrong side
 * of a surface. It integrates no forces (the step's acceleration comes from
 * the integrator's velocities) and removes no particles (the kill pass does). */
#include "sim/collide.h"

#include <assert.h>
#include <math.h>
#include <string.h>

enum { TERMINAL = 1 << 30 };

/* Relative size of rounding noise in a component that was removed exactly
 * in real arithmetic (a few ulps of the vector it came from). */
#define NOISE 1e-12
/* Distance, relative to the coordinates, within which a point is on a
 * surface: 2^-21, four float ulps. */
#define TOUCH 4.76837158203125e-7

/* fmin/fmax are library calls on some targets; the hot loop has no NaNs */
static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }

/* A deflector in the form the hit tests need, derived once per call. */
typedef struct prep {
    pfx_deflector_shape shape;
    bool thin;           /* disc, bounded plane: either face, no wrong side */
    bool inside;         /* sphere, box */
    double p[3], n[3];   /* point or centre; unit normal */
    double u[3], w[3];   /* bounded plane: in-plane unit axes */
    double hu, hw;       /* bounded plane: half width and height */
    double r;            /* disc, sphere */
    double lo[3], hi[3]; /* box: face coordinates c -+ h, so a snapped face is exactly 0 */
    double edge_tol;     /* box: slack of the face bounds, so an edge hit is never lost */
    double mu_slide;     /* friction while sliding: the midpoint of the range */
} prep;

/* One particle's working state through the step. side[k]: 0 when deflector
 * k does not concern it this step (its chance says pass, or it started on
 * the solid side), +1 for an active one-sided shape, and for a thin shape
 * the side of its plane the particle is on (+1 in front of the normal). */
typedef struct body {
    double x[3], v[3], a[3];
    int8_t side[PFX_COLLIDE_MAX_DEFLECTORS];
    uint32_t i;
    int contacts; /* surfaces it rests on this step: 0, 1, 2 (a crease) or 3 (wedged) */
    size_t ck;    /* the first one */
    double cn[3]; /* and its normal */
    double fric;  /* Coulomb deceleration: sum of mu |a_N| over them */
    long slide;   /* an inside sphere it rests on (see hold), or -1 */
} body;

typedef struct ctx {
    const pfx_deflector *defl;
    const prep *pr;
    size_t nd;
    double dt;
    const pfx_collide_pool *pool;
    pfx_rng *rng;
    pfx_hit_fn on_hit;
    void *user;
    pfx_collide_stats *stats;
} ctx;

typedef struct hit {
    double s; /* time after the segment's start */
    size_t k;
    int face; /* box: 2 * axis + (0: high face, 1: low face) */
    int side; /* thin shapes: the face hit (+1: front of the normal) */
} hit;

static double dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize(double v[3]) {
    double l = sqrt(dot(v, v));
    for (int j = 0; j < 3; j++)
        v[j] /= l;
}

static void prepare(const pfx_deflector *d, prep *p) {
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
static double constraint(const prep *p, int side, const double x[3], double n[3]) {
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

static void pos_at(const double x[3], const double v[3], const double a[3], double s,
                   double out[3]) {
    for (int j = 0; j < 3; j++)
        out[j] = x[j] + (v[j] + 0.5 * a[j] * s) * s;
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

/* Earliest hit of deflector p by the path x + v s + a s^2/2, s in [0, T]. */
static bool detect(const prep *p, int side, const double x[3], const double v[3], const double a[3],
                   double T, double touch, hit *h) {
    double s[2], P[3];
    int dir[2];
    switch (p->shape) {
    case PFX_DEFLECTOR_PLANE:
    case PFX_DEFLECTOR_DISC: {
        double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
        double c = side * dot(q, p->n), b = side * dot(v, p->n), A = 0.5 * side * dot(a, p->n);
        if (fabs(c) > (fabs(b) + fabs(A) * T) * T + touch)
            return false; /* cannot reach the plane this segment */
        if (c <= touch) {
            /* On it (resting): normal parts left by rounding after the
             * normal was removed (1e-16 of the whole) are no motion; they
             * would otherwise report the same contact again at s = 0. */
            c = 0;
            if (fabs(b) <= NOISE * sqrt(dot(v, v)))
                b = 0;
            if (fabs(A) <= NOISE * sqrt(dot(a, a)))
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
    case PFX_DEFLECTOR_SPHERE: {
        double q[3] = {x[0] - p->p[0], x[1] - p->p[1], x[2] - p->p[2]};
        double lq = sqrt(dot(q, q));
        double reach = sqrt(dot(v, v)) * T + 0.5 * sqrt(dot(a, a)) * T * T;
        if (p->inside ? lq + reach + touch < p->r : lq - reach - touch > p->r)
            return false; /* cannot reach the surface this segment */
        double sg = p->inside ? -1 : 1, qv = dot(q, v), qa = dot(q, a);
        double c[5] = {sg * (dot(q, q) - p->r * p->r), 0, 0, sg * dot(v, a), sg * 0.25 * dot(a, a)};
        if (c[0] <= 2 * p->r * touch) { /* on it: as for planes */
            c[0] = 0;
            if (fabs(qv) <= NOISE * lq * sqrt(dot(v, v)))
                qv = 0;
            if (fabs(qa) <= NOISE * lq * sqrt(dot(a, a)))
                qa = 0;
        }
        c[1] = sg * 2 * qv;
        c[2] = sg * (dot(v, v) + qa);
        return first_entry(c, 4, T, &h->s);
    }
    case PFX_DEFLECTOR_BOX: {
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
    }
    return false;
}

/* Puts the hit point x exactly on the surface (as exactly as double allows:
 * for an axis-aligned plane, exactly) and returns the unit normal on the
 * particle's side in n. */
static void snap(const prep *p, const hit *h, double x[3], double n[3]) {
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

static double draw(pfx_rng *rng, const double range[2]) {
    return range[0] == range[1] ? range[0] : pfx_rng_range(rng, range[0], range[1]);
}

/* Rests b on the surface of deflector k with normal n (its velocity's normal
 * part is already gone): the acceleration loses its normal part, so the path
 * stays on the surface. Resting on a second surface (a crease) both velocity
 * and acceleration keep only their part along the crease line n1 x n2,
 * instead of bouncing between the two projections; on a third it is wedged
 * and stops. Touching the same (curved) surface again replaces its normal. */
static void rest(const ctx *c, body *b, size_t k, const double n[3], double fric) {
    b->fric += fric;
    if (c->pr[k].shape == PFX_DEFLECTOR_SPHERE && c->pr[k].inside)
        b->slide = (long)k;
    double L[3] = {b->cn[1] * n[2] - b->cn[2] * n[1], b->cn[2] * n[0] - b->cn[0] * n[2],
                   b->cn[0] * n[1] - b->cn[1] * n[0]};
    double l = sqrt(dot(L, L));
    if (b->contacts == 0 || b->ck == k || (b->contacts == 1 && l < 1e-6)) {
        double an = dot(b->a, n);
        for (int j = 0; j < 3; j++)
            b->a[j] -= an * n[j];
        if (b->contacts == 0 || b->ck == k)
            memcpy(b->cn, n, sizeof b->cn), b->ck = k, b->contacts = b->contacts ? b->contacts : 1;
        return;
    }
    if (b->contacts == 1) {
        double al = dot(b->a, L) / (l * l), vl = dot(b->v, L) / (l * l);
        for (int j = 0; j < 3; j++)
            b->a[j] = al * L[j], b->v[j] = vl * L[j];
        b->contacts = 2;
        return;
    }
    memset(b->a, 0, sizeof b->a);
    memset(b->v, 0, sizeof b->v);
    b->contacts = 3;
}

/* The response to hit h at x with normal n, t seconds into the step.
 * Impact or contact: the incoming normal speed w = -v.n is compared with
 * what one step of the acceleration pressing into the surface gives,
 * |a_N| dt. At or above it, an impact: v' = (1 - mu) v_T + eps w n, and when the
 * rebound eps w is itself below |a_N| dt the particle comes to rest. Below
 * it (a particle already resting, found again each step), a contact:
 * no on_hit, no lifetime loss, no draw. Resting means v_N = 0 and a_N
 * removed from the path for the rest of the step, so it slides exactly on
 * the surface, with Coulomb friction of deceleration mu |a_N| added to
 * `fric` (a per-second rule: a slide on a floor stops after |v_T| / (mu g)
 * seconds whatever the step). Returns TERMINAL for kill and stick. */
static int respond(const ctx *c, body *b, const hit *h, const double n[3], double t) {
    const pfx_deflector *d = &c->defl[h->k];
    const pfx_collide_pool *pool = c->pool;
    double vn = dot(b->v, n), an = dot(b->a, n);
    double w = vn < 0 ? -vn : 0, thr = an < 0 ? -an * c->dt : 0;
    bool contact = w < thr;
    if (d->response != PFX_DEFLECT_BOUNCE) {
        if (d->response == PFX_DEFLECT_KILL) {
            pool->lifetime[b->i] = PFX_KILLED;
            if (c->stats)
                c->stats->kills++;
        } else {
            b->v[0] = b->v[1] = b->v[2] = 0;
            if (pool->stuck)
                pool->stuck[b->i] = 1;
            if (c->stats)
                c->stats->sticks++;
        }
        if (c->on_hit)
            c->on_hit(c->user, b->i, h->k, b->x, n, t);
        return TERMINAL;
    }
    double vt[3];
    for (int j = 0; j < 3; j++)
        vt[j] = b->v[j] - vn * n[j];
    if (!contact) {
        double eps = draw(c->rng, d->resilience), mu = draw(c->rng, d->friction);
        if (d->lifetime_loss > 0) {
            float *life = &pool->lifetime[b->i];
            *life -= (float)(d->lifetime_loss * *life);
        }
        if (c->stats)
            c->stats->impacts++;
        if (c->on_hit)
            c->on_hit(c->user, b->i, h->k, b->x, n, t);
        for (int j = 0; j < 3; j++) {
            vt[j] *= 1 - mu;
            b->v[j] = vt[j] + eps * w * n[j];
        }
        if (!(an < 0 && eps * w < thr))
            return 0;
    } else if (c->stats) {
        c->stats->contacts++;
    }
    memcpy(b->v, vt, sizeof vt);
    if (an < 0)
        rest(c, b, h->k, n, c->pr[h->k].mu_slide * -an);
    return 0;
}

/* Thin shapes: the side of the plane the particle is on, kept while it is
 * within rounding distance of it (just after hitting it), else from d. */
static void update_sides(const ctx *c, body *b) {
    double scale = 1 + dmax(fabs(b->x[0]), dmax(fabs(b->x[1]), fabs(b->x[2])));
    for (size_t k = 0; k < c->nd; k++) {
        const prep *p = &c->pr[k];
        if (!p->thin || !b->side[k])
            continue;
        double q[3] = {b->x[0] - p->p[0], b->x[1] - p->p[1], b->x[2] - p->p[2]};
        double d = dot(q, p->n);
        if (fabs(d) > 1e-12 * scale)
            b->side[k] = d > 0 ? 1 : -1;
    }
}

/* Resting inside a sphere, the tangent path leaves the (concave) surface at
 * once, so the contact would repeat at s = 0 without progress. Instead the
 * particle slides by projection: that sphere is not tested while it rests
 * on it, and after each piece of path the point is put back on the sphere
 * along the radius, and the outward part of the velocity removed. */
static void hold(const ctx *c, body *b) {
    if (b->slide < 0)
        return;
    const prep *p = &c->pr[b->slide];
    double q[3] = {b->x[0] - p->p[0], b->x[1] - p->p[1], b->x[2] - p->p[2]};
    double l = sqrt(dot(q, q));
    if (!(l > p->r))
        return;
    double vr = dot(b->v, q) / l;
    for (int j = 0; j < 3; j++) {
        b->x[j] = p->p[j] + q[j] * (p->r / l);
        if (vr > 0)
            b->v[j] -= vr * q[j] / l;
    }
}

/* Runs the step from b's start state; returns the number of hits (with
 * TERMINAL or'ed in when the particle was killed or stuck). */
static int resolve(const ctx *c, body *b) {
    double t = 0;
    int hits = 0, stops = 0;
    b->contacts = 0, b->fric = 0, b->slide = -1;
    for (;;) {
        double T = c->dt - t, ae[3], u[3] = {0, 0, 0}, stop = INFINITY;
        if (!(T > 0))
            break;
        memcpy(ae, b->a, sizeof ae);
        const double fric = b->fric;
        if (fric > 0) { /* sliding: friction opposes the velocity, or holds it */
            double vm = sqrt(dot(b->v, b->v));
            if (vm > 0) {
                for (int j = 0; j < 3; j++) {
                    u[j] = b->v[j] / vm;
                    ae[j] -= fric * u[j];
                }
                double along = dot(ae, u);
                if (along < 0)
                    stop = vm / -along; /* the speed along u reaches 0 */
            } else {
                double am = sqrt(dot(b->a, b->a));
                for (int j = 0; j < 3; j++)
                    ae[j] = am <= fric ? 0 : b->a[j] - fric * b->a[j] / am;
            }
        }
        update_sides(c, b);
        /* Within `touch` of a surface is on it: a stored float point sits up
         * to a few ulps off the surface it rests on, and a free fall through
         * that gap would escape the friction for part of every step. The
         * snap then moves it onto the surface, never through it. */
        double touch = TOUCH * (1 + dmax(fabs(b->x[0]), dmax(fabs(b->x[1]), fabs(b->x[2]))));
        hit best = {.s = INFINITY}, h;
        double horizon = dmin(T, stop);
        for (size_t k = 0; k < c->nd; k++) {
            if (!b->side[k] || (long)k == b->slide)
                continue;
            memset(&h, 0, sizeof h);
            if (detect(&c->pr[k], b->side[k], b->x, b->v, ae, dmin(horizon, best.s), touch, &h) &&
                h.s < best.s) {
                best = h;
                best.k = k;
            }
        }
        if (!(best.s <= horizon)) {
            double s = dmin(T, stop);
            pos_at(b->x, b->v, ae, s, b->x);
            for (int j = 0; j < 3; j++)
                b->v[j] += ae[j] * s;
            hold(c, b);
            t += s;
            if (stop <= T) { /* stopped: the velocity along u is exactly gone, */
                double vu = dot(b->v, u);
                for (int j = 0; j < 3; j++)
                    b->v[j] -= vu * u[j];
                if (sqrt(dot(b->a, b->a)) <= fric) /* and static friction holds it */
                    memset(b->v, 0, sizeof b->v);
                if (++stops < 4)
                    continue;
            }
            break;
        }
        double n[3];
        pos_at(b->x, b->v, ae, best.s, b->x);
        for (int j = 0; j < 3; j++)
            b->v[j] += ae[j] * best.s;
        hold(c, b);
        snap(&c->pr[best.k], &best, b->x, n);
        if (c->pr[best.k].thin)
            b->side[best.k] = (int8_t)best.side;
        t += best.s;
        hits++;
        if (respond(c, b, &best, n, t) == TERMINAL)
            return hits | TERMINAL;
        if (hits >= PFX_COLLIDE_MAX_HITS) {
            /* stays at the hit point, its velocity already leaving the surface */
            if (c->stats)
                c->stats->capped++;
            break;
        }
    }
    return hits;
}

/* Stores b as floats. Rounding may put the point a fraction of an ulp on
 * the wrong side of a surface it touches; then it moves one ulp at a time
 * along that surface's outward direction (a few ulps at most, which cannot
 * cross another surface unless two are within ulps of each other). */
static void store(const ctx *c, body *b) {
    const pfx_collide_pool *pool = c->pool;
    update_sides(c, b);
    float xf[3] = {(float)b->x[0], (float)b->x[1], (float)b->x[2]};
    for (int round = 0; round < 64; round++) {
        bool ok = true;
        for (size_t k = 0; k < c->nd; k++) {
            if (!b->side[k])
                continue;
            double xd[3] = {xf[0], xf[1], xf[2]}, n[3];
            double g = constraint(&c->pr[k], b->side[k], xd, n);
            if (c->pr[k].thin ? g > 0 : g >= 0)
                continue;
            ok = false;
            for (int j = 0; j < 3; j++)
                if (n[j] != 0)
                    xf[j] = nextafterf(xf[j], n[j] > 0 ? INFINITY : -INFINITY);
        }
        if (ok)
            break;
    }
    uint32_t i = b->i;
    pool->px[i] = xf[0], pool->py[i] = xf[1], pool->pz[i] = xf[2];
    pool->vx[i] = (float)b->v[0], pool->vy[i] = (float)b->v[1], pool->vz[i] = (float)b->v[2];
}

bool pfx_deflector_affects(const pfx_deflector *d, uint32_t id) {
    if (d->chance >= 1)
        return true;
    uint64_t h = pfx_mix64(d->seed ^ pfx_mix64((uint64_t)id + 0x9e3779b97f4a7c15ULL));
    return (double)(h >> 11) * (1.0 / 9007199254740992.0) < d->chance;
}

/* The side of deflector k a particle starts the step on (see body). */
static int8_t start_side(const prep *p, const body *b) {
    double n[3], g = constraint(p, 1, b->x, n);
    if (!p->thin)
        return g >= 0 ? 1 : 0;
    if (g != 0)
        return g > 0 ? 1 : -1;
    /* exactly on the plane: the side it moves into, or is pressed against */
    double vn = dot(b->v, p->n), an = dot(b->a, p->n);
    return vn != 0 ? (vn > 0 ? 1 : -1) : (an > 0 ? -1 : 1);
}

/* ---- Broad phase ----
 * Most particles are far from every surface: a float pass over a chunk of
 * particles (straight loops, vectorised) marks those that might touch a
 * deflector this step, and only they go through the exact test below, in
 * double, exactly as before. The mark is conservative: the float distance
 * to each surface (a lower bound for every shape, as constraint() is) is
 * compared with the float reach plus a margin far above float rounding
 * (1e-4 of the coordinates' size), so every particle the exact test would
 * take is marked, and the results are the same bits. */
enum { BROAD_CHUNK = 256 };

/* reach[j]: how far particle j can get this step (the sweep bound), grown
 * by the margin; the same bound as the exact test's, in float. */
static void broad_reach(const pfx_collide_pool *pool, uint32_t i0, uint32_t m, float dt,
                        float *restrict reach) {
    const float *restrict x0 = pool->px0 + i0, *restrict y0 = pool->py0 + i0,
                          *restrict z0 = pool->pz0 + i0;
    const float *restrict u0 = pool->vx0 + i0, *restrict v0 = pool->vy0 + i0,
                          *restrict w0 = pool->vz0 + i0;
    const float *restrict x1 = pool->px + i0, *restrict y1 = pool->py + i0,
                          *restrict z1 = pool->pz + i0;
    const float *restrict u1 = pool->vx + i0, *restrict v1 = pool->vy + i0,
                          *restrict w1 = pool->vz + i0;
    for (uint32_t j = 0; j < m; j++) {
        const float dx = x1[j] - x0[j], dy = y1[j] - y0[j], dz = z1[j] - z0[j];
        const float du = u1[j] - u0[j], dv = v1[j] - v0[j], dw = w1[j] - w0[j];
        /* |v0| dt + |a| dt^2 / 2 with a dt = v1 - v0, and the chord */
        const float sweep = sqrtf(u0[j] * u0[j] + v0[j] * v0[j] + w0[j] * w0[j]) * dt +
                            0.5f * sqrtf(du * du + dv * dv + dw * dw) * dt;
        const float chord = sqrtf(dx * dx + dy * dy + dz * dz);
        const float r = sweep > chord ? sweep : chord;
        const float size = fabsf(x0[j]) + fabsf(y0[j]) + fabsf(z0[j]);
        reach[j] = r * 1.001f + 1e-4f * (1.0f + size);
    }
}

/* mark[j] |= particle j is within reach[j] (plus the deflector's own
 * margin) of deflector p's surface. */
static void broad_mark(const prep *p, const pfx_collide_pool *pool, uint32_t i0, uint32_t m,
                       const float *restrict reach, uint8_t *restrict mark) {
    const float *restrict x = pool->px0 + i0, *restrict y = pool->py0 + i0,
                          *restrict z = pool->pz0 + i0;
    const float px = (float)p->p[0], py = (float)p->p[1], pz = (float)p->p[2];
    const float extent =
        (float)(fabs(p->p[0]) + fabs(p->p[1]) + fabs(p->p[2]) + p->r + fabs(p->hi[0] - p->lo[0]) +
                fabs(p->hi[1] - p->lo[1]) + fabs(p->hi[2] - p->lo[2]));
    const float margin = 1e-4f * (1.0f + extent);
    switch (p->shape) {
    case PFX_DEFLECTOR_PLANE:
    case PFX_DEFLECTOR_DISC: {
        const float nx = (float)p->n[0], ny = (float)p->n[1], nz = (float)p->n[2];
        for (uint32_t j = 0; j < m; j++) {
            const float d = (x[j] - px) * nx + (y[j] - py) * ny + (z[j] - pz) * nz;
            mark[j] |= fabsf(d) <= reach[j] + margin;
        }
        break;
    }
    case PFX_DEFLECTOR_SPHERE: {
        const float r = (float)p->r;
        for (uint32_t j = 0; j < m; j++) {
            const float dx = x[j] - px, dy = y[j] - py, dz = z[j] - pz;
            const float d = sqrtf(dx * dx + dy * dy + dz * dz) - r;
            mark[j] |= fabsf(d) <= reach[j] + margin;
        }
        break;
    }
    case PFX_DEFLECTOR_BOX: {
        /* outside: the distance to the box; inside: to the nearest face;
         * the larger of the per-axis gaps is a lower bound of both */
        const float lx = (float)p->lo[0], ly = (float)p->lo[1], lz = (float)p->lo[2];
        const float hx = (float)p->hi[0], hy = (float)p->hi[1], hz = (float)p->hi[2];
        for (uint32_t j = 0; j < m; j++) {
            const float ex0 = x[j] - hx, ex1 = lx - x[j], ey0 = y[j] - hy, ey1 = ly - y[j];
            const float ez0 = z[j] - hz, ez1 = lz - z[j];
            const float ex = ex0 > ex1 ? ex0 : ex1, ey = ey0 > ey1 ? ey0 : ey1;
            const float ez = ez0 > ez1 ? ez0 : ez1;
            float e = ex > ey ? ex : ey;
            e = e > ez ? e : ez;
            mark[j] |= fabsf(e) <= reach[j] + margin;
        }
        break;
    }
    }
}

void pfx_collide(const pfx_deflector *defl, size_t n_defl, double dt, const pfx_collide_pool *pool,
                 pfx_rng *rng, pfx_hit_fn on_hit, void *user, pfx_collide_stats *stats) {
    assert(n_defl <= PFX_COLLIDE_MAX_DEFLECTORS);
    if (!(dt > 0) || n_defl == 0)
        return;
    prep pr[PFX_COLLIDE_MAX_DEFLECTORS];
    for (size_t k = 0; k < n_defl; k++)
        prepare(&defl[k], &pr[k]);
    ctx c = {defl, pr, n_defl, dt, pool, rng, on_hit, user, stats};
    body b;
    float reach[BROAD_CHUNK];
    uint8_t mark[BROAD_CHUNK];
    for (uint32_t i = 0; i < pool->count; i++) {
        const uint32_t j = i % BROAD_CHUNK;
        if (j == 0) { /* the next chunk's broad phase */
            const uint32_t m =
                pool->count - i < BROAD_CHUNK ? pool->count - i : (uint32_t)BROAD_CHUNK;
            broad_reach(pool, i, m, (float)dt, reach);
            memset(mark, 0, m);
            for (size_t k = 0; k < n_defl; k++)
                broad_mark(&pr[k], pool, i, m, reach, mark);
        }
        if (!mark[j] && !(pool->stuck && pool->stuck[i]))
            continue;                        /* far from every surface: untouched, as below */
        if (pool->stuck && pool->stuck[i]) { /* held where it stuck, whatever the integrator did */
            pool->px[i] = pool->px0[i], pool->py[i] = pool->py0[i], pool->pz[i] = pool->pz0[i];
            pool->vx[i] = pool->vy[i] = pool->vz[i] = 0;
            continue;
        }
        const double x0[3] = {pool->px0[i], pool->py0[i], pool->pz0[i]};
        const double v0[3] = {pool->vx0[i], pool->vy0[i], pool->vz0[i]};
        const double x1[3] = {pool->px[i], pool->py[i], pool->pz[i]};
        const double v1[3] = {pool->vx[i], pool->vy[i], pool->vz[i]};
        b.i = i;
        for (int j = 0; j < 3; j++) {
            b.x[j] = x0[j], b.v[j] = v0[j];
            b.a[j] = (v1[j] - v0[j]) / dt; /* the step's effective acceleration */
        }
        /* How far the particle can get this step: along the parabola, and
         * to the integrator's end point (the fallback below). A deflector
         * whose surface is farther than that from x0 cannot be touched; the
         * constraint value is a lower bound on the distance to the surface
         * for every shape, so this skips most particles exactly. */
        double speed = sqrt(dot(v0, v0)), accel = sqrt(dot(b.a, b.a));
        double dx[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]};
        double reach = dmax(speed * dt + 0.5 * accel * dt * dt, sqrt(dot(dx, dx)));
        reach += 1e-6 * (1 + fabs(x0[0]) + fabs(x0[1]) + fabs(x0[2]));
        bool any = false;
        uint32_t id = pool->id ? pool->id[i] : i;
        for (size_t k = 0; k < n_defl; k++) {
            b.side[k] = pfx_deflector_affects(&defl[k], id) ? start_side(&pr[k], &b) : 0;
            if (b.side[k]) {
                double n[3];
                any |= fabs(constraint(&pr[k], 1, x0, n)) <= reach;
            }
        }
        if (!any)
            continue;
        int8_t side0[PFX_COLLIDE_MAX_DEFLECTORS];
        memcpy(side0, b.side, n_defl);
        int hits = resolve(&c, &b);
        if (hits == 0) {
            /* Untouched, unless the integrator's own end point is behind a
             * surface the parabola stayed in front of (a force that is not
             * constant over the step): then re-solve on the parabola from
             * (x0, v0) through x1, a = 2 (x1 - x0 - v0 dt) / dt^2. */
            bool behind = false;
            for (size_t k = 0; k < n_defl && !behind; k++) {
                double n[3];
                behind = side0[k] && !pr[k].thin && constraint(&pr[k], 1, x1, n) < 0;
            }
            if (!behind)
                continue;
            if (stats)
                stats->fallbacks++;
            memcpy(b.side, side0, n_defl);
            for (int j = 0; j < 3; j++) {
                b.x[j] = x0[j], b.v[j] = v0[j];
                b.a[j] = 2 * (x1[j] - x0[j] - v0[j] * dt) / (dt * dt);
            }
            resolve(&c, &b);
        }
        store(&c, &b);
    }
}
