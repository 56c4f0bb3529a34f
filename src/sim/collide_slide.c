/* Sliding contact on one infinite plane, many particles at once: the exact
 * pass of a particle that starts the step on the plane, pressed against it
 * and not moving into it, is always the same walk (a contact at s = 0, the
 * normal parts removed, one slide with Coulomb friction to the end of the
 * step); that of a particle near the plane that reaches nothing is to
 * leave it as the integrator did. This file runs both verdicts as
 * straight-line double arithmetic over a chunk of particles in vector
 * lanes, the very operations in the very order of collide.c,
 * collide_shape.c and collide_resolve.c, so the bits are theirs; a
 * particle that strays from them anywhere (a second hit, a stop within
 * the step, a nudge at the store, a fallback) is left to the general pass
 * untouched. A third verdict is a particle in flight that strikes the
 * plane once within the step: the impact (its draws, lifetime loss and
 * on_hit event), the bounce or the landing, and the rest of the step in
 * the air or sliding; an event waits for the general pass to reach its
 * particle, so that events keep pool order. It sees one plane (a view
 * of the emitter's first bouncing plane: collide.c hands it only the
 * particles near that plane and no other surface); other shapes, kill and
 * stick responses stay with the general pass. */
#include "sim/collide_internal.h"

#include <float.h>
#include <string.h>

#include "base/clones.h"

/* Particles a chunk of the walk holds (the broad phase's chunk). */
enum { SLIDE_CHUNK = PFX_SLIDE_CHUNK };

/* Whether range lies within [0, 1]. */
static bool unit_range(const double range[2]) {
    return range[0] >= 0 && range[0] <= 1 && range[1] >= 0 && range[1] <= 1;
}

int pfx_collide_lane_plane(const ctx *c) {
    /* (A rebound no faster than the impact keeps the rest of the step
     * within the reach the broad phase measured, which the view beside
     * other deflectors relies on; the compiler allows no other.) */
    for (size_t k = 0; k < c->nd; k++)
        if (c->pr[k].shape == PFX_DEFLECTOR_PLANE && !c->pr[k].thin &&
            c->defl[k].response == PFX_DEFLECT_BOUNCE && unit_range(c->defl[k].resilience) &&
            unit_range(c->defl[k].friction))
            return (int)k;
    return -1;
}

/* The chunk's particles as doubles, gathered: start state, the integrator's
 * end state; out: the walk's end state and whether the walk held. */
typedef struct slide_chunk {
    double x0[3][SLIDE_CHUNK], v0[3][SLIDE_CHUNK], x1[3][SLIDE_CHUNK], v1[3][SLIDE_CHUNK];
    double xe[3][SLIDE_CHUNK], ve[3][SLIDE_CHUNK];
    uint8_t ok[SLIDE_CHUNK];     /* the walk held (slide_walk: slid; flight_walk: no hit) */
    uint8_t impact[SLIDE_CHUNK]; /* impact_walk: the strike was an impact, not a contact */
    double eps[SLIDE_CHUNK], mu[SLIDE_CHUNK];   /* impact_walk: the impact's draws */
    double xh[3][SLIDE_CHUNK], th[SLIDE_CHUNK]; /* impact_walk: the strike's point and time */
    uint16_t lane[SLIDE_CHUNK]; /* with on_hit: particle j's walked lane (TODO_WALKED) */
} slide_chunk;

/* noise_test: the general pass compares a normal part N with NOISE
 * sqrt(w.w), w a vector of three doubles. Rounding moves the computed
 * sqrt(w.w) and |w|_1 by a few ulps, and |w|_1 / sqrt(3) <= |w|_2 <= |w|_1,
 * so |N| > 2 NOISE |w|_1 is surely not noise and |N| <= NOISE |w|_1 / 2
 * surely is, by the same comparison the general pass makes; the walk
 * leaves the rare lane between the two to it. */

/* What both walks read of lane k first, as collide_one and its callers
 * compute it: the start and end states, the step's acceleration a, the
 * sum of magnitudes that is finite only for finite inputs (fin), the
 * signed distance g0 from the plane (start_side: side 1 when g0 >= 0),
 * the touch tolerance from x0 (earliest_hit, detect_plane) and the
 * normal parts b of v0 and A of a / 2. A macro, so that each walk's
 * loop keeps its lanes in registers as one straight-line body. */
#define LANE_START(P, n, dt, s, k)                                                                 \
    double x0[3], v0[3], x1[3], a[3];                                                              \
    for (int j = 0; j < 3; j++) {                                                                  \
        x0[j] = (s)->x0[j][k], v0[j] = (s)->v0[j][k], x1[j] = (s)->x1[j][k];                       \
        a[j] = ((s)->v1[j][k] - v0[j]) / (dt); /* collide_one */                                   \
    }                                                                                              \
    const double fin = fabs(x0[0]) + fabs(x0[1]) + fabs(x0[2]) + fabs(v0[0]) + fabs(v0[1]) +       \
                       fabs(v0[2]) + fabs(x1[0]) + fabs(x1[1]) + fabs(x1[2]) + fabs(a[0]) +        \
                       fabs(a[1]) + fabs(a[2]);                                                    \
    const double q0[3] = {x0[0] - (P)[0], x0[1] - (P)[1], x0[2] - (P)[2]};                         \
    const double g0 = dot(q0, (n));                                                                \
    const double touch = TOUCH * (1 + dmax(fabs(x0[0]), dmax(fabs(x0[1]), fabs(x0[2]))));          \
    const double b = dot(v0, (n)), A = 0.5 * dot(a, (n))

/* detect_plane over dt from g0 in front of the plane (side 1, off it:
 * c = g0), with the normal parts b and A: the cull, then crossings' roots
 * (computed in every lane) and their directions; hit: a downward crossing
 * within (0, dt], the first at s. */
typedef struct strike {
    int culled, hit;
    double s;
} strike;

static inline __attribute__((always_inline)) strike first_strike(double g0, double b, double A,
                                                                 double dt, double touch) {
    strike r;
    r.culled = fabs(g0) > (fabs(b) + fabs(A) * dt) * dt + touch;
    const double lin = -g0 / b;
    const double disc = b * b - 4 * A * g0;
    const double qq = -0.5 * (b + copysign(sqrt(disc), b));
    const double r1 = qq / A, r2 = g0 / qq;
    const double lo = r1 > r2 ? r2 : r1, hi = r1 > r2 ? r1 : r2;
    const int down_first = A > 0; /* d1 = -1: the first root is a downward crossing */
    const int hit_lin = (b < 0) & (lin > 0) & (lin <= dt);
    const int hit_quad = (disc > 0) & (((lo > 0) & (lo <= dt) & down_first) |
                                       ((hi > 0) & (hi <= dt) & (1 - down_first)));
    r.hit = (1 - r.culled) & (A == 0 ? hit_lin : hit_quad);
    r.s = A == 0 ? lin : (down_first ? lo : hi);
    return r;
}

/* The last piece of a walk, from x on the plane with velocity v and
 * acceleration ae (slide_accel's, with its speed vm along u and stop
 * time), over the T seconds left: its horizon (to the stop, if sooner)
 * and what detect_plane sees from there (c, b, A against touch; culled:
 * the plane is out of reach). */
typedef struct last_piece {
    double horizon, touch, c, b, A;
    int culled;
} last_piece;

static inline __attribute__((always_inline)) last_piece
last_piece_from(const double P[3], const double n[3], const double x[3], const double v[3],
                const double ae[3], double T, double stop) {
    last_piece l;
    l.horizon = dmin(T, stop);
    l.touch = TOUCH * (1 + dmax(fabs(x[0]), dmax(fabs(x[1]), fabs(x[2]))));
    const double q[3] = {x[0] - P[0], x[1] - P[1], x[2] - P[2]};
    l.c = dot(q, n);
    l.b = dot(v, n), l.A = 0.5 * dot(ae, n);
    l.culled = fabs(l.c) > (fabs(l.b) + fabs(l.A) * l.horizon) * l.horizon + l.touch;
    return l;
}

/* advance over the last piece; the end state to lane k. */
static inline __attribute__((always_inline)) void finish_lane(slide_chunk *restrict s, uint32_t k,
                                                              double x[3], double v[3],
                                                              const double ae[3], double horizon) {
    pos_at(x, v, ae, horizon, x);
    for (int j = 0; j < 3; j++) {
        v[j] += ae[j] * horizon;
        s->xe[j][k] = x[j], s->ve[j][k] = v[j];
    }
}

/* The walk of m gathered particles on plane p (point P, unit normal n),
 * step dt. Each line names the function of the general pass whose
 * arithmetic it repeats; ok[k] is 0 where that pass would branch
 * elsewhere. Straight-line and branch-free, so the clones run it four
 * particles to a vector (with the file's -fno-trapping-math and
 * -fno-tree-pre, CMakeLists.txt): division and square root are correctly
 * rounded in every lane, so the bits do not depend on the width. */
static inline __attribute__((always_inline)) void walk(const prep *p, double dt, uint32_t m,
                                                       slide_chunk *restrict s, const bool held) {
    const double P[3] = {p->p[0], p->p[1], p->p[2]}, n[3] = {p->n[0], p->n[1], p->n[2]};
    const double mu = p->mu_slide;
    for (uint32_t k = 0; k < m; k++) {
        LANE_START(P, n, dt, s, k);
        /* within_reach is certain for finite inputs starting within touch
         * of the plane on its front (reach >= 1e-6 (1 + |x|_1) > touch).
         * The normal parts b, A as the general pass zeroes them when they
         * are rounding noise (below NOISE times |v|, |a|): the walk takes
         * only b exactly 0 and an A surely not noise, so it needs neither
         * square root (sureness: see noise_test). */
        const double a1 = fabs(a[0]) + fabs(a[1]) + fabs(a[2]);
        /* crossings(A, b, 0, dt): a hit at s = 0 when the first of b, A
         * is negative (and no later one with b = 0). (| and &, not || and
         * &&: no branch in the loop.) */
        int ok = (fin <= DBL_MAX) & (g0 >= 0) & (g0 <= touch) & (b == 0) & (A < 0) &
                 (fabs(A) > 2 * NOISE * a1);
        /* advance 0 seconds, then pfx_collide_snap */
        double x[3], v[3];
        pos_at(x0, v0, a, 0, x);
        for (int j = 0; j < 3; j++)
            v[j] = v0[j] + a[j] * 0;
        const double q[3] = {x[0] - P[0], x[1] - P[1], x[2] - P[2]};
        const double d = dot(q, n);
        for (int j = 0; j < 3; j++)
            x[j] -= d * n[j];
        /* respond: a contact (w < |a_N| dt), the normal parts removed */
        const double vn = dot(v, n), an = dot(a, n);
        const double pressed = -an * dt;
        const double w = vn < 0 ? -vn : 0, thr = an < 0 ? pressed : 0;
        ok &= w < thr;
        for (int j = 0; j < 3; j++)
            v[j] = v[j] - vn * n[j];
        const double fric = 0 + mu * -an; /* rest */
        const double an2 = dot(a, n);
        for (int j = 0; j < 3; j++)
            a[j] -= an2 * n[j];
        /* slide_accel over the rest of the step, T = dt - 0 */
        const double T = dt - 0;
        const double vm = sqrt(dot(v, v));
        /* Sliding (vm > 0: friction against the velocity), or `held` by
         * static friction (vm = 0: friction against the push, up to fric;
         * its square root and divisions only in held_walk's lanes). */
        double u[3], ae[3], am = 0;
        if (held) {
            ok &= (fric > 0) & (1 - (vm > 0));
            am = sqrt(dot(a, a));
        } else {
            ok &= (1 - (fric > 0)) | (vm > 0);
        }
        for (int j = 0; j < 3; j++) {
            u[j] = v[j] / vm;
            if (held) {
                const double scaled = a[j] - fric * a[j] / am;
                ae[j] = am <= fric ? 0 : scaled;
            } else {
                const double sliding = a[j] - fric * u[j];
                ae[j] = !(fric > 0) ? a[j] : sliding;
            }
        }
        const double along = dot(ae, u);
        const double reached = vm / -along;
        const double stop = (fric > 0) & (vm > 0) & (along < 0) ? reached : INFINITY;
        ok &= !(stop <= T); /* no stop within the step */
        /* detect_plane from the contact: no crossing, by the cull or by
         * c, b, A all zero (then crossings finds none) */
        const last_piece l = last_piece_from(P, n, x, v, ae, T, stop);
        /* noise: b against sqrt(v.v), which is vm; A against |ae|,
         * surely noise below half the NOISE of |ae|_1 (else, unless surely
         * not, left to the general pass: the walk needs A zeroed) */
        const int b_zero = (l.b == 0) | (fabs(l.b) <= NOISE * vm);
        const int A_zero =
            (l.A == 0) | (fabs(l.A) <= 0.5 * NOISE * (fabs(ae[0]) + fabs(ae[1]) + fabs(ae[2])));
        ok &= l.culled | ((l.c <= l.touch) & b_zero & A_zero);
        finish_lane(s, k, x, v, ae, l.horizon);
        s->ok[k] = (uint8_t)ok;
    }
}

/* The walk of a sliding particle, and of one held at rest by static
 * friction (a newborn at rest, or one that stopped: the general pass
 * would flag it for the restore), in separate loops: a slider does not
 * pay for the held branch's square root and divisions. */
PFX_CLONES static void slide_walk(const prep *p, double dt, uint32_t m, slide_chunk *restrict s) {
    walk(p, dt, m, s, false);
}
PFX_CLONES static void held_walk(const prep *p, double dt, uint32_t m, slide_chunk *restrict s) {
    walk(p, dt, m, s, true);
}

/* The other verdict, for the m gathered particles whose walk did not
 * hold: collide_one leaves a particle as the integrator did when it starts
 * behind the plane (side 0), or when detect_plane finds no downward
 * crossing off the plane (culled, or none among crossings(A, b, c, dt)
 * with c > touch) and the end point x1 is not behind the plane (no
 * fallback); ok[k] says so. Apart from slide_walk, so that a slider does
 * not pay for the roots. */
PFX_CLONES static void flight_walk(const prep *p, double dt, uint32_t m, slide_chunk *restrict s) {
    const double P[3] = {p->p[0], p->p[1], p->p[2]}, n[3] = {p->n[0], p->n[1], p->n[2]};
    for (uint32_t k = 0; k < m; k++) {
        LANE_START(P, n, dt, s, k);
        const strike h = first_strike(g0, b, A, dt, touch);
        const double q1[3] = {x1[0] - P[0], x1[1] - P[1], x1[2] - P[2]};
        const int behind = dot(q1, n) < 0; /* fallback */
        /* (1 - x, not !x or x == 0: GCC 12 does not vectorise those as
         * _Bool here) */
        s->ok[k] = (uint8_t)((1 - (g0 >= 0)) | ((fin <= DBL_MAX) & (h.culled | (g0 > touch)) &
                                                (1 - h.hit) & (1 - behind)));
    }
}

/* The third verdict, for the m gathered particles flight_walk did not
 * take: one that starts in flight in front of the plane, in reach
 * (within_reach), and whose parabola crosses it downward within the step
 * (detect_plane's roots, as flight_walk) is moved to the crossing and
 * snapped onto the plane (advance, pfx_collide_snap); respond's impact
 * (eps[k] and mu[k], respond's draws) or contact follows, and with
 * it the rebound or the rest (rest(): the normal part of a gone, friction
 * mu_slide |a_N|); then the rest of the step (slide_accel, then
 * detect_plane from the contact, which must find nothing, and advance).
 * ok[k] is 0 where the general pass would go elsewhere: a second strike or
 * a slide that stops within the step, a start on or behind the plane, no
 * crossing. impact[k]: the strike was an impact (it counts in the hits
 * column and in the stats), not a contact. */
PFX_CLONES static void impact_walk(const prep *p, double dt, uint32_t m, slide_chunk *restrict s) {
    const double P[3] = {p->p[0], p->p[1], p->p[2]}, n[3] = {p->n[0], p->n[1], p->n[2]};
    const double mu_slide = p->mu_slide;
    for (uint32_t k = 0; k < m; k++) {
        LANE_START(P, n, dt, s, k);
        const double eps = s->eps[k], mu = s->mu[k];
        /* within_reach: side 1 (g0 >= 0), the constraint within reach */
        const double speed = sqrt(dot(v0, v0)), accel = sqrt(dot(a, a));
        const double dx[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]};
        double reach = dmax(speed * dt + 0.5 * accel * dt * dt, sqrt(dot(dx, dx)));
        reach += 1e-6 * (1 + fabs(x0[0]) + fabs(x0[1]) + fabs(x0[2]));
        int ok = (fin <= DBL_MAX) & (g0 > touch) & (fabs(g0) <= reach);
        /* detect_plane over dt from off the plane: the first downward
         * root */
        const strike h = first_strike(g0, b, A, dt, touch);
        ok &= h.hit;
        const double s1 = h.s;
        /* advance to the strike, then pfx_collide_snap */
        double x[3], v[3];
        pos_at(x0, v0, a, s1, x);
        for (int j = 0; j < 3; j++)
            v[j] = v0[j] + a[j] * s1;
        const double q[3] = {x[0] - P[0], x[1] - P[1], x[2] - P[2]};
        const double d = dot(q, n);
        for (int j = 0; j < 3; j++) {
            x[j] -= d * n[j];
            s->xh[j][k] = x[j];
        }
        s->th[k] = s1; /* t = 0 + s1 */
        /* respond: an impact (w >= |a_N| dt) rebounds at eps w, the
         * tangent kept at 1 - mu, and rests when the rebound is below
         * |a_N| dt; a contact rests */
        const double vn = dot(v, n), an = dot(a, n);
        const double w = vn < 0 ? -vn : 0, thr = an < 0 ? -an * dt : 0;
        const int contact = w < thr;
        double vt[3], vb[3];
        for (int j = 0; j < 3; j++) {
            vt[j] = v[j] - vn * n[j];
            const double kept = vt[j] * (1 - mu);
            vb[j] = kept + eps * w * n[j];
            vt[j] = contact ? vt[j] : kept;
        }
        const int rests = contact | ((an < 0) & (eps * w < thr));
        /* rest(): the acceleration loses its normal part; friction */
        const double fric = rests ? 0 + mu_slide * -an : 0;
        double af[3];
        for (int j = 0; j < 3; j++) {
            v[j] = rests ? vt[j] : vb[j];
            af[j] = rests ? a[j] - an * n[j] : a[j];
        }
        /* the rest of the step: slide_accel */
        const double T = dt - s1;
        ok &= T > 0;
        const double vm = sqrt(dot(v, v)), am = sqrt(dot(af, af));
        double u[3], ae[3];
        for (int j = 0; j < 3; j++) {
            u[j] = v[j] / vm;
            const double sliding = af[j] - fric * u[j];
            const double held = am <= fric ? 0 : af[j] - fric * af[j] / am;
            ae[j] = !(fric > 0) ? af[j] : (vm > 0 ? sliding : held);
        }
        const double along = dot(ae, u);
        const double reached = vm / -along;
        const double stop = (fric > 0) & (vm > 0) & (along < 0) ? reached : INFINITY;
        ok &= !(stop <= T);
        /* detect_plane from the strike: culled, or on the plane with the
         * noise zeroed and no crossing (crossings with c = 0) */
        const last_piece l = last_piece_from(P, n, x, v, ae, T, stop);
        const double bz = (l.b == 0) | (fabs(l.b) <= NOISE * vm) ? 0 : l.b;
        const double Az = (l.A == 0) | (fabs(l.A) <= NOISE * sqrt(dot(ae, ae))) ? 0 : l.A;
        const double first = bz != 0 ? bz : Az;
        const double back = -bz / Az; /* when it comes back to the plane */
        const int again = (first < 0) | ((bz > 0) & (Az < 0) & (back <= l.horizon));
        ok &= l.culled | ((l.c <= l.touch) & (1 - again));
        finish_lane(s, k, x, v, ae, l.horizon);
        s->ok[k] = (uint8_t)ok;
        s->impact[k] = (uint8_t)(1 - contact);
    }
}

/* pfx_collide_store and collide_one_rest for lane k of the chunk, particle
 * i0 + j, whose walk held: the end state stored as floats, flagged at rest
 * where no bit moved and nothing but a contact happened, the todo mark
 * (*mark) cleared. A strike (with `impacts`, s->impact[k]) that was an impact does
 * what respond does first: the lifetime loss, the count, the on_hit event
 * (while the pool still holds the integrator's end state, as the general
 * pass's event sees it; at the strike's point and time) and the hit count.
 * False, with nothing done, where the store would nudge the point off the
 * plane: the general pass does that. */
static bool store_lane(const ctx *c, uint32_t i0, const slide_chunk *s, uint32_t k, uint32_t j,
                       uint8_t *mark, uint64_t *contacts, uint64_t *impacts) {
    const pfx_collide_pool *pool = c->pool;
    const prep *p = &c->pr[0];
    /* pfx_collide_store: a float point behind the plane would be nudged.
     * (Through a volatile: GCC 12's SLP pass here took (double)(float)x
     * for x.) */
    volatile float round[3] = {(float)s->xe[0][k], (float)s->xe[1][k], (float)s->xe[2][k]};
    const float xf[3] = {round[0], round[1], round[2]};
    /* pfx_collide_constraint of a plane on side 1, inline */
    const double q[3] = {(double)xf[0] - p->p[0], (double)xf[1] - p->p[1], (double)xf[2] - p->p[2]};
    if (!(1 * dot(q, p->n) >= 0))
        return false;
    const uint32_t i = i0 + j;
    const float vf[3] = {(float)s->ve[0][k], (float)s->ve[1][k], (float)s->ve[2][k]};
    const bool impact = impacts && s->impact[k];
    if (impact) { /* respond */
        const pfx_deflector *d = &c->defl[0];
        if (d->lifetime_loss > 0) {
            float *life = &pool->lifetime[i];
            *life -= (float)(d->lifetime_loss * *life);
        }
        (*impacts)++;
        if (c->on_hit) {
            const double x[3] = {s->xh[0][k], s->xh[1][k], s->xh[2][k]};
            c->on_hit(c->user, i, c->first, x, p->n, s->th[k]);
        }
        if (pool->hits)
            pool->hits[i]++;
    }
    if (pool->rest) { /* collide_one_rest: still when no bit moved */
        const float start[6] = {pool->px0[i], pool->py0[i], pool->pz0[i],
                                pool->vx0[i], pool->vy0[i], pool->vz0[i]};
        const bool still =
            !impact && !memcmp(xf, start, sizeof xf) && !memcmp(vf, start + 3, sizeof vf);
        pool->rest[i] = still ? (uint8_t)(2 | 0x80) : 0;
        if (still) {
            pool->rest_px[i] = pool->px[i], pool->rest_py[i] = pool->py[i];
            pool->rest_pz[i] = pool->pz[i], pool->rest_vx[i] = pool->vx[i];
            pool->rest_vy[i] = pool->vy[i], pool->rest_vz[i] = pool->vz[i];
        }
    }
    pool->px[i] = xf[0], pool->py[i] = xf[1], pool->pz[i] = xf[2];
    pool->vx[i] = vf[0], pool->vy[i] = vf[1], pool->vz[i] = vf[2];
    if (pool->ax)
        pool->ax[i] = NAN;
    *mark = 0;
    *contacts += !impact;
    return true;
}

/* store_lane for the lanes done[0..n) of the chunk's idx. */
static void store_slides(const ctx *c, uint32_t i0, const slide_chunk *s, const uint32_t *idx,
                         const uint32_t *done, uint32_t n, uint8_t *todo, uint64_t *contacts,
                         uint64_t *impacts) {
    for (uint32_t e = 0; e < n; e++)
        store_lane(c, i0, s, done[e], idx[done[e]], &todo[idx[done[e]]], contacts, impacts);
}

/* Moves the gathered particles list[0..n) (ascending, list[e] >= e) to
 * the front of the chunk, with their indices. */
static void pack(slide_chunk *s, uint32_t *idx, const uint32_t *list, uint32_t n) {
    for (uint32_t e = 0; e < n; e++) {
        const uint32_t k = list[e];
        for (int j = 0; j < 3; j++) {
            s->x0[j][e] = s->x0[j][k], s->v0[j][e] = s->v0[j][k];
            s->x1[j][e] = s->x1[j][k], s->v1[j][e] = s->v1[j][k];
        }
        idx[e] = idx[k];
    }
}

/* Gathers particles i0 + idx[0..n) into the chunk as doubles (cloned:
 * with AVX-512's gathers a fountain of 10^5 over a plane with hits, one
 * thread, went from 12.1-12.5 to 11.3-11.6 ns a particle step, the same
 * bits). */
PFX_CLONES static void gather(const pfx_collide_pool *pool, uint32_t i0, const uint32_t *idx,
                              uint32_t n, slide_chunk *s) {
    for (uint32_t k = 0; k < n; k++) {
        const uint32_t i = i0 + idx[k];
        s->x0[0][k] = pool->px0[i], s->x0[1][k] = pool->py0[i], s->x0[2][k] = pool->pz0[i];
        s->v0[0][k] = pool->vx0[i], s->v0[1][k] = pool->vy0[i], s->v0[2][k] = pool->vz0[i];
        s->x1[0][k] = pool->px[i], s->x1[1][k] = pool->py[i], s->x1[2][k] = pool->pz[i];
        s->v1[0][k] = pool->vx[i], s->v1[1][k] = pool->vy[i], s->v1[2][k] = pool->vz[i];
    }
}

/* The candidates idx[0..n) that start on the plane (LANE_START's g0 within
 * [0, touch]: the only ones slide_walk and held_walk can take) to on[],
 * the others (only flight_walk and impact_walk can take them) to off[];
 * *n_on of them on. */
static void split_on_plane(const pfx_collide_pool *pool, const prep *p, uint32_t i0,
                           const uint32_t *idx, uint32_t n, uint32_t *on, uint32_t *off,
                           uint32_t *n_on) {
    const double P[3] = {p->p[0], p->p[1], p->p[2]}, nn[3] = {p->n[0], p->n[1], p->n[2]};
    uint32_t a = 0, b = 0;
    for (uint32_t k = 0; k < n; k++) {
        const uint32_t i = i0 + idx[k];
        const double x0[3] = {pool->px0[i], pool->py0[i], pool->pz0[i]};
        const double q0[3] = {x0[0] - P[0], x0[1] - P[1], x0[2] - P[2]};
        const double g0 = dot(q0, nn);
        const double touch = TOUCH * (1 + dmax(fabs(x0[0]), dmax(fabs(x0[1]), fabs(x0[2]))));
        const uint32_t is_on = (g0 >= 0) & (g0 <= touch);
        on[a] = idx[k], off[b] = idx[k];
        a += is_on, b += 1u - is_on;
    }
    *n_on = a;
}

/* The walks of the candidates idx[0..n) that start on the plane: a slide,
 * or held by static friction; the others stay marked for the general
 * pass. */
static void walk_on_plane(const ctx *c, uint32_t i0, slide_chunk *s, uint32_t *idx, uint32_t n,
                          uint8_t *todo, uint64_t *contacts) {
    const prep *p = &c->pr[0];
    gather(c->pool, i0, idx, n, s);
    slide_walk(p, c->dt, n, s);
    /* the walks that held, and the others, compacted */
    uint32_t done[SLIDE_CHUNK], n_done = 0, left[SLIDE_CHUNK], n_left = 0;
    for (uint32_t k = 0; k < n; k++) {
        done[n_done] = k, left[n_left] = k;
        n_done += s->ok[k], n_left += 1u - s->ok[k];
    }
    store_slides(c, i0, s, idx, done, n_done, todo, contacts, NULL);
    /* held_walk for the others, if one of them starts still (its only
     * candidates), packed to the front (left[e] >= e) */
    uint32_t n_still = 0;
    for (uint32_t e = 0; e < n_left; e++) {
        const uint32_t k = left[e];
        n_still += (s->v0[0][k] == 0) & (s->v0[1][k] == 0) & (s->v0[2][k] == 0);
    }
    if (!n_still)
        return;
    pack(s, idx, left, n_left);
    held_walk(p, c->dt, n_left, s);
    uint32_t n_held = 0;
    for (uint32_t k = 0; k < n_left; k++) {
        done[n_held] = k;
        n_held += s->ok[k];
    }
    store_slides(c, i0, s, idx, done, n_held, todo, contacts, NULL);
}

/* The walks of the candidates idx[0..n) that start off the plane: those
 * that reach nothing are left as the integrator did; with `strikes`, those
 * that strike it take impact_walk; the others stay marked. */
static void walk_off_plane(const ctx *c, uint32_t i0, slide_chunk *s, uint32_t *idx, uint32_t n,
                           uint8_t *todo, uint64_t *contacts, uint64_t *impacts, bool strikes) {
    const pfx_collide_pool *pool = c->pool;
    const prep *p = &c->pr[0];
    const pfx_deflector *d = &c->defl[0];
    gather(pool, i0, idx, n, s);
    flight_walk(p, c->dt, n, s);
    uint32_t struck[SLIDE_CHUNK], n_struck = 0;
    for (uint32_t e = 0; e < n; e++) {
        struck[n_struck] = e;
        n_struck += 1u - s->ok[e];
        if (!s->ok[e])
            continue;
        const uint32_t j = idx[e], i = i0 + j;
        if (pool->rest) { /* collide_one_rest: still when the step moved no bit */
            const float start[6] = {pool->px0[i], pool->py0[i], pool->pz0[i],
                                    pool->vx0[i], pool->vy0[i], pool->vz0[i]};
            const float end[6] = {pool->px[i], pool->py[i], pool->pz[i],
                                  pool->vx[i], pool->vy[i], pool->vz[i]};
            const bool still = !memcmp(start, end, sizeof end);
            pool->rest[i] = still ? 1 : 0;
            if (still) {
                pool->rest_px[i] = end[0], pool->rest_py[i] = end[1], pool->rest_pz[i] = end[2];
                pool->rest_vx[i] = end[3], pool->rest_vy[i] = end[4], pool->rest_vz[i] = end[5];
            }
        }
        todo[j] = 0;
    }
    if (!n_struck || !strikes)
        return;
    pack(s, idx, struck, n_struck);
    for (uint32_t k = 0; k < n_struck; k++) { /* respond's draws, in case it is an impact */
        s->eps[k] = pfx_collide_draw(c, d, i0 + idx[k], 0, d->resilience);
        s->mu[k] = pfx_collide_draw(c, d, i0 + idx[k], 1, d->friction);
    }
    impact_walk(p, c->dt, n_struck, s);
    uint32_t done[SLIDE_CHUNK], n_walked = 0;
    for (uint32_t k = 0; k < n_struck; k++) {
        done[n_walked] = k;
        n_walked += s->ok[k];
    }
    if (!c->on_hit) {
        store_slides(c, i0, s, idx, done, n_walked, todo, contacts, impacts);
        return;
    }
    /* Events are raised in pool order: each walked particle is stored
     * (and its event raised) when the general pass over this chunk
     * reaches it (pfx_collide_slide_commit). */
    for (uint32_t e = 0; e < n_walked; e++) {
        todo[idx[done[e]]] = PFX_TODO_WALKED;
        s->lane[idx[done[e]]] = (uint16_t)done[e];
    }
}

/* The chunk of this thread's walks (on a worker's stack it would take 60
 * KiB); with on_hit, its walked strikes wait here for their commit. */
static _Thread_local slide_chunk s;

bool pfx_collide_slide_commit(const ctx *c, uint32_t i0, uint32_t j) {
    uint8_t mark = PFX_TODO_WALKED;
    uint64_t contacts = 0, impacts = 0;
    if (!store_lane(c, i0, &s, s.lane[j], j, &mark, &contacts, &impacts))
        return false;
    if (c->stats)
        c->stats->contacts += contacts, c->stats->impacts += impacts;
    return true;
}

uint64_t pfx_collide_slide(const ctx *c, uint32_t i0, uint32_t m, uint8_t *todo) {
    const pfx_collide_pool *pool = c->pool;
    const pfx_deflector *d = &c->defl[0];
    uint32_t idx[SLIDE_CHUNK], on[SLIDE_CHUNK], off[SLIDE_CHUNK];
    uint64_t contacts = 0, impacts = 0;
    /* (a walked strike waiting for its commit holds its lane of s: one
     * chunk a call) */
    const bool strikes = !c->on_hit || m <= SLIDE_CHUNK;
    for (uint32_t j0 = 0; j0 < m; j0 += SLIDE_CHUNK) {
        const uint32_t end = m - j0 < SLIDE_CHUNK ? m : j0 + SLIDE_CHUNK;
        /* The candidates, compacted without a branch on each mark (they
         * fall at random: a branch mispredicted half of them). */
        uint32_t count = 0;
        const uint8_t *stuck = pool->stuck ? pool->stuck + i0 : NULL;
        for (uint32_t j = j0; j < end; j++) {
            idx[count] = j;
            count += (todo[j] != 0) & (stuck ? stuck[j] == 0 : 1);
        }
        if (d->chance < 1) { /* those the chance lets pass take no part */
            uint32_t kept = 0;
            for (uint32_t k = 0; k < count; k++) {
                const uint32_t i = i0 + idx[k];
                idx[kept] = idx[k];
                kept += pfx_deflector_affects(d, pool->id ? pool->id[i] : i);
            }
            count = kept;
        }
        if (!count)
            continue;
        uint32_t n_on;
        split_on_plane(pool, &c->pr[0], i0, idx, count, on, off, &n_on);
        if (n_on)
            walk_on_plane(c, i0, &s, on, n_on, todo, &contacts);
        if (count - n_on)
            walk_off_plane(c, i0, &s, off, count - n_on, todo, &contacts, &impacts, strikes);
    }
    if (c->stats)
        c->stats->impacts += impacts;
    return contacts;
}
