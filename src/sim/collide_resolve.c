/* The response of the collide pass: one particle's walk through a step,
 * from hit to hit on its parabola (collide_shape.c finds them), with the
 * bounce, kill or stick at each, resting contact, sliding friction, and the
 * final store as floats on the right side of every surface. */
#include "sim/collide_internal.h"

#include <assert.h>
#include <string.h>

/* A random resilience or friction (`which` 0 or 1) of particle i's
 * impact on deflector d: a counter-based draw keyed by the emitter, the
 * deflector, the particle's id and its hit number, so that a particle's
 * n-th bounce draws the same numbers whatever the step, the order of the
 * pool or the thread (a stream drawn in pool order gave another particle
 * each draw when sim.rate changed). A constant range draws nothing. */
double pfx_collide_draw(const ctx *c, const pfx_deflector *d, uint32_t i, uint64_t which,
                        const double range[2]) {
    if (range[0] == range[1])
        return range[0];
    const pfx_collide_pool *pool = c->pool;
    const uint64_t id = pool->id ? pool->id[i] : i, n = pool->hits ? pool->hits[i] : 0;
    const uint64_t h = pfx_mix64(pool->key ^ d->seed ^ pfx_mix64((id << 32 | n) * 2 + which));
    return range[0] + (range[1] - range[0]) * pfx_unit_of_hash(h);
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
    const bool first = b->contacts == 0 || b->ck == k;
    double L[3] = {0, 0, 0}, l = 0;
    if (!first) { /* the crease line, only for a second surface */
        L[0] = b->cn[1] * n[2] - b->cn[2] * n[1], L[1] = b->cn[2] * n[0] - b->cn[0] * n[2];
        L[2] = b->cn[0] * n[1] - b->cn[1] * n[0];
        l = sqrt(dot(L, L));
    }
    if (first || (b->contacts == 1 && l < 1e-6)) {
        double an = dot(b->a, n);
        for (int j = 0; j < 3; j++)
            b->a[j] -= an * n[j];
        if (first)
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
        double eps = pfx_collide_draw(c, d, b->i, 0, d->resilience),
               mu = pfx_collide_draw(c, d, b->i, 1, d->friction);
        if (d->lifetime_loss > 0) {
            float *life = &pool->lifetime[b->i];
            *life -= (float)(d->lifetime_loss * *life);
        }
        if (c->stats)
            c->stats->impacts++;
        if (c->on_hit)
            c->on_hit(c->user, b->i, h->k, b->x, n, t);
        if (pool->hits) /* after on_hit, whose event number is the impacts before */
            pool->hits[b->i]++;
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

/* The acceleration ae of the next piece of path of b, with the Coulomb
 * deceleration b->fric of the surfaces it rests on: while it slides,
 * friction opposes the velocity (unit direction u) and the returned time is
 * when the speed along u reaches 0 (INFINITY if it never does); at rest,
 * friction cancels the push up to fric (static friction). */
static double slide_accel(const body *b, double ae[3], double u[3]) {
    double stop = INFINITY;
    memcpy(ae, b->a, sizeof b->a);
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
    return stop;
}

/* The earliest hit within `horizon` on the path of acceleration ae, over
 * the deflectors that concern b (not the sphere it slides inside: see
 * hold); best.s is INFINITY when there is none. */
static hit earliest_hit(const ctx *c, const body *b, const double ae[3], double horizon) {
    /* Within `touch` of a surface is on it: a stored float point sits up
     * to a few ulps off the surface it rests on, and a free fall through
     * that gap would escape the friction for part of every step. The
     * snap then moves it onto the surface, never through it. */
    double touch = TOUCH * (1 + dmax(fabs(b->x[0]), dmax(fabs(b->x[1]), fabs(b->x[2]))));
    hit best = {.s = INFINITY}, h;
    for (size_t k = 0; k < c->nd; k++) {
        if (!b->side[k] || (long)k == b->slide)
            continue;
        memset(&h, 0, sizeof h);
        if (pfx_collide_detect(&c->pr[k], b->side[k], b->x, b->v, ae, dmin(horizon, best.s), touch,
                               &h) &&
            h.s < best.s) {
            best = h;
            best.k = k;
        }
    }
    return best;
}

/* Moves b s seconds along the path of acceleration ae (kept on the sphere
 * it slides inside, if any). */
static void advance(const ctx *c, body *b, const double ae[3], double s) {
    pos_at(b->x, b->v, ae, s, b->x);
    for (int j = 0; j < 3; j++)
        b->v[j] += ae[j] * s;
    hold(c, b);
}

/* A slide along u stopped: the velocity along u is exactly gone, and
 * static friction holds the particle when it can (the push is at most
 * b->fric), so it does not creep on by rounding. */
static void stop_sliding(body *b, const double u[3]) {
    double vu = dot(b->v, u);
    for (int j = 0; j < 3; j++)
        b->v[j] -= vu * u[j];
    if (sqrt(dot(b->a, b->a)) <= b->fric)
        memset(b->v, 0, sizeof b->v);
}

/* Runs the step from b's start state; returns the number of hits (with
 * TERMINAL or'ed in when the particle was killed or stuck). Each turn of the
 * loop follows one piece of path: to the earliest hit, or else to the end
 * of the step, or to where a slide stops (then friction may start it again
 * along a new direction, a few times at most). */
int pfx_collide_resolve(const ctx *c, body *b) {
    double t = 0;
    int hits = 0, stops = 0;
    b->contacts = 0, b->fric = 0, b->slide = -1;
    for (;;) {
        double T = c->dt - t, ae[3], u[3] = {0, 0, 0};
        if (!(T > 0))
            break;
        double stop = slide_accel(b, ae, u);
        update_sides(c, b);
        double horizon = dmin(T, stop);
        hit best = earliest_hit(c, b, ae, horizon);
        if (!(best.s <= horizon)) {
            advance(c, b, ae, horizon);
            t += horizon;
            if (stop <= T) {
                stop_sliding(b, u);
                if (++stops < 4)
                    continue;
            }
            break;
        }
        double n[3];
        advance(c, b, ae, best.s);
        pfx_collide_snap(&c->pr[best.k], &best, b->x, n);
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
void pfx_collide_store(const ctx *c, body *b) {
    const pfx_collide_pool *pool = c->pool;
    update_sides(c, b);
    float xf[3] = {(float)b->x[0], (float)b->x[1], (float)b->x[2]};
    for (int round = 0; round < 64; round++) {
        bool ok = true;
        for (size_t k = 0; k < c->nd; k++) {
            if (!b->side[k])
                continue;
            double xd[3] = {xf[0], xf[1], xf[2]}, n[3];
            double g = pfx_collide_constraint(&c->pr[k], b->side[k], xd, n);
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
    if (pool->ax)
        pool->ax[i] = NAN;
}
