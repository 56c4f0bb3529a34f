/* The collide pass: after the integrator has moved a pool through a step,
 * find each particle's earliest hit on the step's parabola, respond at that
 * exact time, continue from there, and store a state never on the wrong side
 * of a surface. It integrates no forces (the step's acceleration comes from
 * the integrator's velocities) and removes no particles (the kill pass does).
 * This file runs the pass: the broad phase, then each particle near a
 * surface; the shapes' geometry is in collide_shape.c and the response in
 * collide_resolve.c. */
#include "sim/collide_internal.h"

#include <assert.h>
#include <math.h>
#include <string.h>

#include "base/clones.h"

bool pfx_collide_lanes = true;

bool pfx_deflector_affects(const pfx_deflector *d, uint32_t id) {
    if (d->chance >= 1)
        return true;
    uint64_t h = pfx_mix64(d->seed ^ pfx_mix64((uint64_t)id + 0x9e3779b97f4a7c15ULL));
    return pfx_unit_of_hash(h) < d->chance;
}

/* The side of deflector k a particle starts the step on (see body). */
static int8_t start_side(const prep *p, const body *b) {
    double n[3], g = pfx_collide_constraint(p, 1, b->x, n);
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
 * to each surface (a lower bound for every shape, as
 * pfx_collide_constraint() is) is compared with the float reach plus a
 * margin far above float rounding (1e-4 of the coordinates' size), so every
 * particle the exact test would take is marked, and the results are the
 * same bits. */
enum { BROAD_CHUNK = PFX_SLIDE_CHUNK }; /* (exact_pass hands the walks a chunk at a time) */

/* reach[j]: how far particle j can get this step (the sweep bound), grown
 * by the margin; the same bound as the exact test's, in float. Inlined, as
 * broad_mark is, so that broad_phase's AVX2 clone runs them at its width. */
static inline __attribute__((always_inline)) void broad_reach(const pfx_collide_pool *pool,
                                                              uint32_t i0, uint32_t m, float dt,
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
static inline __attribute__((always_inline)) void
broad_mark(const prep *p, const pfx_collide_pool *pool, uint32_t i0, uint32_t m,
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

/* The broad phase of the m particles from i0: near[j] when particle i0 + j
 * may touch a deflector this step, or is stuck (held in place by
 * pfx_collide). An AVX2 clone does eight particles at a time, with the same
 * bits. Returns whether any is. */
PFX_CLONES static bool broad_phase(const prep *pr, size_t nd, float dt,
                                   const pfx_collide_pool *pool, uint32_t i0, uint32_t m,
                                   float *reach, uint8_t *near) {
    broad_reach(pool, i0, m, dt, reach);
    if (pool->stuck)
        memcpy(near, pool->stuck + i0, m);
    else
        memset(near, 0, m);
    for (size_t k = 0; k < nd; k++)
        broad_mark(&pr[k], pool, i0, m, reach, near);
    /* A particle at rest is always near its surface; one that is not has
     * moved off its fixed point, and its flag would be stale. */
    if (pool->rest) { /* read first: most chunks have no stale flag to write */
        uint8_t *restrict rest = pool->rest + i0, stale = 0;
        for (uint32_t j = 0; j < m; j++)
            stale |= near[j] ? 0 : rest[j];
        for (uint32_t j = 0; stale && j < m; j++)
            rest[j] = near[j] ? rest[j] : 0;
    }
    uint8_t any = 0;
    for (uint32_t j = 0; j < m; j++)
        any |= near[j];
    return any;
}

/* others[j]: particle i0 + j may touch a deflector other than k this step
 * (broad_phase's test, deflector by deflector). A clone, as broad_phase. */
PFX_CLONES static void near_others(const prep *pr, size_t nd, size_t k, float dt,
                                   const pfx_collide_pool *pool, uint32_t i0, uint32_t m,
                                   float *reach, uint8_t *others) {
    memset(others, 0, m);
    broad_reach(pool, i0, m, dt, reach);
    for (size_t d = 0; d < nd; d++)
        if (d != k)
            broad_mark(&pr[d], pool, i0, m, reach, others);
}

bool pfx_collide_near(const pfx_deflector *defl, size_t n_defl, double dt,
                      const pfx_collide_pool *pool, uint8_t *near) {
    assert(n_defl <= PFX_COLLIDE_MAX_DEFLECTORS);
    prep pr[PFX_COLLIDE_MAX_DEFLECTORS];
    for (size_t k = 0; k < n_defl; k++)
        pfx_collide_prepare(&defl[k], &pr[k]);
    float reach[BROAD_CHUNK];
    bool any = false;
    for (uint32_t i0 = 0; i0 < pool->count; i0 += BROAD_CHUNK) {
        const uint32_t m =
            pool->count - i0 < BROAD_CHUNK ? pool->count - i0 : (uint32_t)BROAD_CHUNK;
        any |= broad_phase(pr, n_defl, (float)dt, pool, i0, m, reach, near + i0);
    }
    return any;
}

/* Sets b's side of each deflector (0 for one whose chance says pass, see
 * body) and says whether one that concerns it is within reach this step.
 * The reach is how far the particle can get: along the parabola, and to the
 * integrator's end point x1 (the fallback below). A deflector whose surface
 * is farther than that from x0 cannot be touched; the constraint value is a
 * lower bound on the distance to the surface for every shape, so this
 * skips most particles exactly. */
static bool within_reach(const ctx *c, body *b, const double x0[3], const double v0[3],
                         const double x1[3]) {
    const pfx_collide_pool *pool = c->pool;
    const double dt = c->dt;
    double speed = sqrt(dot(v0, v0)), accel = sqrt(dot(b->a, b->a));
    double dx[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]};
    double reach = dmax(speed * dt + 0.5 * accel * dt * dt, sqrt(dot(dx, dx)));
    reach += 1e-6 * (1 + fabs(x0[0]) + fabs(x0[1]) + fabs(x0[2]));
    bool any = false;
    uint32_t id = pool->id ? pool->id[b->i] : b->i;
    for (size_t k = 0; k < c->nd; k++) {
        b->side[k] = pfx_deflector_affects(&c->defl[k], id) ? start_side(&c->pr[k], b) : 0;
        if (b->side[k]) {
            double n[3];
            any |= fabs(pfx_collide_constraint(&c->pr[k], 1, x0, n)) <= reach;
        }
    }
    return any;
}

/* A particle the parabola took past every surface is untouched, unless the
 * integrator's own end point x1 is behind a surface the parabola stayed in
 * front of (a force that is not constant over the step): then it is
 * re-solved on the parabola from (x0, v0) through x1,
 * a = 2 (x1 - x0 - v0 dt) / dt^2, from the start sides side0. Returns
 * whether it was. */
static bool fallback(const ctx *c, body *b, const int8_t *side0, const double x0[3],
                     const double v0[3], const double x1[3]) {
    const double dt = c->dt;
    bool behind = false;
    for (size_t k = 0; k < c->nd && !behind; k++) {
        double n[3];
        behind = side0[k] && !c->pr[k].thin && pfx_collide_constraint(&c->pr[k], 1, x1, n) < 0;
    }
    if (!behind)
        return false;
    if (c->stats)
        c->stats->fallbacks++;
    memcpy(b->side, side0, c->nd);
    for (int j = 0; j < 3; j++) {
        b->x[j] = x0[j], b->v[j] = v0[j];
        b->a[j] = 2 * (x1[j] - x0[j] - v0[j] * dt) / (dt * dt);
    }
    pfx_collide_resolve(c, b);
    return true;
}

/* The exact pass of particle i, which the broad phase marked: its step
 * resolved from the start state (x0, v0) with the step's effective
 * acceleration, and stored; untouched when no surface is in reach or
 * nothing is hit. b is the caller's scratch. Returns whether it stored. */
static bool collide_one(const ctx *c, uint32_t i, body *b) {
    const pfx_collide_pool *pool = c->pool;
    const double x0[3] = {pool->px0[i], pool->py0[i], pool->pz0[i]};
    const double v0[3] = {pool->vx0[i], pool->vy0[i], pool->vz0[i]};
    const double x1[3] = {pool->px[i], pool->py[i], pool->pz[i]};
    const double v1[3] = {pool->vx[i], pool->vy[i], pool->vz[i]};
    b->i = i;
    for (int j = 0; j < 3; j++) {
        b->x[j] = x0[j], b->v[j] = v0[j];
        b->a[j] = (v1[j] - v0[j]) / c->dt; /* the step's effective acceleration */
    }
    if (!within_reach(c, b, x0, v0, x1))
        return false;
    int8_t side0[PFX_COLLIDE_MAX_DEFLECTORS];
    memcpy(side0, b->side, c->nd);
    if (pfx_collide_resolve(c, b) == 0 && !fallback(c, b, side0, x0, v0, x1))
        return false;
    pfx_collide_store(c, b);
    return true;
}

/* ---- Resting as a state (pfx_collide_pool.rest) ----
 * Bits, not values, are compared: the pass must see exactly the inputs it
 * saw when it flagged the particle (a -0 or a NaN is an input too). */
static inline uint32_t bits(float f) {
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* *f = the float whose bits are u. */
static inline void put(float *f, uint32_t u) { memcpy(f, &u, sizeof u); }

/* The lanes of rest_chunk: k = the particle's flag is set and its end
 * state (x..w) is bit for bit the flagged one (kx..kw); then the start
 * state's bits (x0..w0) replace the end state's. The arrays are restrict
 * parameters of a function not inlined, so that GCC 12 believes them
 * apart: with locals, or inlined, it wanted over 100 run-time alias
 * checks and gave up vectorising. & and | stand for && and ||, which it
 * leaves as branches. */
PFX_CLONES __attribute__((noinline)) static uint32_t
rest_lanes(uint32_t m, const uint8_t *restrict rest, const uint8_t *restrict near,
           uint8_t *restrict todo, uint8_t *restrict keep, float *restrict x, float *restrict y,
           float *restrict z, float *restrict u, float *restrict v, float *restrict w,
           const float *restrict x0, const float *restrict y0, const float *restrict z0,
           const float *restrict u0, const float *restrict v0, const float *restrict w0,
           const float *restrict kx, const float *restrict ky, const float *restrict kz,
           const float *restrict ku, const float *restrict kv, const float *restrict kw) {
    uint32_t contacts = 0; /* (at most 126 a particle of 256) */
    for (uint32_t j = 0; j < m; j++) {
        const uint32_t X = bits(x[j]), Y = bits(y[j]), Z = bits(z[j]), U = bits(u[j]),
                       V = bits(v[j]), W = bits(w[j]);
        const uint32_t diff = (X ^ bits(kx[j])) | (Y ^ bits(ky[j])) | (Z ^ bits(kz[j])) |
                              (U ^ bits(ku[j])) | (V ^ bits(kv[j])) | (W ^ bits(kw[j]));
        const uint32_t r = rest[j], k = (uint32_t)(r != 0) & (uint32_t)(diff == 0);
        keep[j] = (uint8_t)k;
        todo[j] = (uint8_t)((uint32_t)(near[j] != 0) & (k ^ 1u));
        const uint32_t all = 0u - k; /* selects of loaded words */
        put(&x[j], (bits(x0[j]) & all) | (X & ~all)), put(&y[j], (bits(y0[j]) & all) | (Y & ~all));
        put(&z[j], (bits(z0[j]) & all) | (Z & ~all)), put(&u[j], (bits(u0[j]) & all) | (U & ~all));
        put(&v[j], (bits(v0[j]) & all) | (V & ~all)), put(&w[j], (bits(w0[j]) & all) | (W & ~all));
        contacts += ((r & 0x7fu) - 1u) & all;
    }
    return contacts;
}

/* The resting particles of [i0, i0 + m) (m <= BROAD_CHUNK), a chunk at a
 * time in straight loops (an AVX2 or AVX-512 clone): one flagged at rest
 * whose integrator end state is bit for bit the flagged one is put back
 * where the step found it, as the exact pass would (the carried
 * acceleration made NaN where that pass stores); todo[j] says which of the
 * marked particles near[j] are left for the exact pass. Returns the
 * contacts the kept ones count. */
PFX_CLONES static uint64_t rest_chunk(const pfx_collide_pool *pool, uint32_t i0, uint32_t m,
                                      const uint8_t *restrict near, uint8_t *restrict todo) {
    const uint8_t *rest = pool->rest + i0;
    uint8_t keep[BROAD_CHUNK];
    const uint32_t contacts = rest_lanes(
        m, rest, near, todo, keep, pool->px + i0, pool->py + i0, pool->pz + i0, pool->vx + i0,
        pool->vy + i0, pool->vz + i0, pool->px0 + i0, pool->py0 + i0, pool->pz0 + i0,
        pool->vx0 + i0, pool->vy0 + i0, pool->vz0 + i0, pool->rest_px + i0, pool->rest_py + i0,
        pool->rest_pz + i0, pool->rest_vx + i0, pool->rest_vy + i0, pool->rest_vz + i0);
    if (pool->ax) {
        float *restrict ax = pool->ax + i0;
        for (uint32_t j = 0; j < m; j++)
            ax[j] = (keep[j] & (rest[j] >> 7)) ? NAN : ax[j];
    }
    return contacts;
}

/* The exact pass of particle i with the resting state: run, then flagged
 * when it left the particle exactly as it found it with nothing but
 * contacts (no impact, kill, stick, event, hit count or lifetime change). */
static void collide_one_rest(const ctx *c, uint32_t i, body *b) {
    const pfx_collide_pool *pool = c->pool;
    const float key[6] = {pool->px[i], pool->py[i], pool->pz[i],
                          pool->vx[i], pool->vy[i], pool->vz[i]};
    const uint32_t hits = pool->hits ? pool->hits[i] : 0;
    const float life = pool->lifetime[i];
    pfx_collide_stats own = {0};
    ctx one = *c;
    one.stats = &own;
    const bool stored = collide_one(&one, i, b);
    if (c->stats)
        pfx_collide_stats_add(c->stats, &own);
    const uint32_t moved =
        (bits(pool->px[i]) ^ bits(pool->px0[i])) | (bits(pool->py[i]) ^ bits(pool->py0[i])) |
        (bits(pool->pz[i]) ^ bits(pool->pz0[i])) | (bits(pool->vx[i]) ^ bits(pool->vx0[i])) |
        (bits(pool->vy[i]) ^ bits(pool->vy0[i])) | (bits(pool->vz[i]) ^ bits(pool->vz0[i]));
    const bool still = !moved && own.impacts == 0 && own.kills == 0 && own.sticks == 0 &&
                       own.capped == 0 && own.fallbacks == 0 && own.contacts < 0x7f &&
                       (!pool->hits || pool->hits[i] == hits) &&
                       bits(pool->lifetime[i]) == bits(life);
    pool->rest[i] = still ? (uint8_t)((1 + own.contacts) | (stored ? 0x80 : 0)) : 0;
    if (still) {
        pool->rest_px[i] = key[0], pool->rest_py[i] = key[1], pool->rest_pz[i] = key[2];
        pool->rest_vx[i] = key[3], pool->rest_vy[i] = key[4], pool->rest_vz[i] = key[5];
    }
}

/* The exact pass of each particle of [i0, i0 + m) that near (indexed from
 * i0) marks near a surface or stuck, in index order (so are the hit
 * events); one the walks of the view `lanes` resolved (PFX_TODO_WALKED)
 * is committed in its turn. */
static void exact_range(const ctx *c, const ctx *lanes, uint32_t i0, uint32_t m,
                        const uint8_t *near) {
    const pfx_collide_pool *pool = c->pool;
    body b;
    /* Eight marks at a time: most particles are far from every surface and
     * untouched, as in collide_one, so most words are zero. */
    for (uint32_t j0 = 0; j0 < m; j0 += 8) {
        const uint32_t end = m - j0 < 8 ? m : j0 + 8;
        uint64_t word = 0;
        memcpy(&word, near + j0, end - j0);
        for (uint32_t j = j0; word && j < end; j++) {
            if (!near[j])
                continue;
            if (near[j] == PFX_TODO_WALKED && lanes && pfx_collide_slide_commit(lanes, i0, j))
                continue; /* walked in lanes, stored now, in pool order */
            const uint32_t i = i0 + j;
            if (pool->stuck && pool->stuck[i]) { /* held where it stuck */
                pool->px[i] = pool->px0[i], pool->py[i] = pool->py0[i], pool->pz[i] = pool->pz0[i];
                pool->vx[i] = pool->vy[i] = pool->vz[i] = 0;
                if (pool->ax)
                    pool->ax[i] = NAN;
                continue;
            }
            if (pool->rest)
                collide_one_rest(c, i, &b);
            else
                collide_one(c, i, &b);
        }
    }
}

/* The exact pass over particles [i0, i0 + m) where near (indexed from i0)
 * marks them, a chunk at a time: those near the first plane the walks take
 * and near no other deflector are walked in lanes (collide_slide.c, with
 * a view of that plane alone), then the rest one by one, in index order.
 * With every other deflector out of reach (the broad phase's own
 * conservative test, deflector by deflector), the general pass does for
 * such a particle exactly what it does with that plane alone: no other
 * surface is in reach, crossed, or near its stored point. */
static void exact_pass(const ctx *c, uint32_t i0, uint32_t m, const uint8_t *near) {
    /* A pass run from inside another's on_hit (on this thread) would
     * overwrite the lanes the outer one has yet to commit: it takes the
     * general pass. */
    static _Thread_local bool walking;
    const int k = pfx_collide_lanes && !walking ? pfx_collide_lane_plane(c) : -1;
    if (k < 0) {
        exact_range(c, NULL, i0, m, near);
        return;
    }
    walking = true;
    ctx one = *c;
    one.defl = c->defl + k, one.pr = c->pr + k, one.nd = 1, one.first = (size_t)k;
    uint8_t todo[BROAD_CHUNK], others[BROAD_CHUNK], alone[BROAD_CHUNK];
    float reach[BROAD_CHUNK];
    for (uint32_t k0 = 0; k0 < m; k0 += BROAD_CHUNK) {
        const uint32_t mk = m - k0 < BROAD_CHUNK ? m - k0 : (uint32_t)BROAD_CHUNK;
        /* marks as 0 or 1 (a stuck column's value is a mark too), so that
         * PFX_TODO_WALKED is only ever the walks' own; a chunk without
         * one is done */
        uint8_t any = 0;
        for (uint32_t j = 0; j < mk; j++) {
            todo[j] = near[k0 + j] != 0;
            any |= todo[j];
        }
        if (!any)
            continue;
        uint64_t contacts;
        if (c->nd > 1) {
            near_others(c->pr, c->nd, (size_t)k, (float)c->dt, c->pool, i0 + k0, mk, reach, others);
            for (uint32_t j = 0; j < mk; j++)
                alone[j] = others[j] ? 0 : todo[j];
            contacts = pfx_collide_slide(&one, i0 + k0, mk, alone);
            for (uint32_t j = 0; j < mk; j++)
                todo[j] = others[j] ? todo[j] : alone[j];
        } else {
            contacts = pfx_collide_slide(&one, i0 + k0, mk, todo);
        }
        if (c->stats)
            c->stats->contacts += contacts;
        exact_range(c, &one, i0 + k0, mk, todo);
    }
    walking = false;
}

uint64_t pfx_collide_rest(const pfx_collide_pool *pool, uint8_t *near, bool *any_near) {
    uint64_t contacts = 0;
    uint8_t any = 0;
    if (!pool->rest || !pool->rest_valid) {
        for (uint32_t i = 0; i < pool->count; i++)
            any |= near[i];
        *any_near = any;
        return 0;
    }
    uint8_t todo[BROAD_CHUNK];
    for (uint32_t i0 = 0; i0 < pool->count; i0 += BROAD_CHUNK) {
        const uint32_t m =
            pool->count - i0 < BROAD_CHUNK ? pool->count - i0 : (uint32_t)BROAD_CHUNK;
        contacts += rest_chunk(pool, i0, m, near + i0, todo);
        memcpy(near + i0, todo, m);
        for (uint32_t j = 0; j < m; j++)
            any |= todo[j];
    }
    *any_near = any;
    return contacts;
}

void pfx_collide(const pfx_deflector *defl, size_t n_defl, double dt, const pfx_collide_pool *pool,
                 const uint8_t *near, pfx_hit_fn on_hit, void *user, pfx_collide_stats *stats) {
    assert(n_defl <= PFX_COLLIDE_MAX_DEFLECTORS);
    if (!(dt > 0) || n_defl == 0)
        return;
    prep pr[PFX_COLLIDE_MAX_DEFLECTORS];
    for (size_t k = 0; k < n_defl; k++)
        pfx_collide_prepare(&defl[k], &pr[k]);
    ctx c = {defl, pr, n_defl, dt, pool, on_hit, user, stats, 0};
    if (near) {
        exact_pass(&c, 0, pool->count, near);
        return;
    }
    /* No marks given: the broad phase a chunk at a time, then the chunk's
     * exact pass. */
    uint8_t mark[BROAD_CHUNK];
    float reach[BROAD_CHUNK];
    for (uint32_t i0 = 0; i0 < pool->count; i0 += BROAD_CHUNK) {
        const uint32_t m =
            pool->count - i0 < BROAD_CHUNK ? pool->count - i0 : (uint32_t)BROAD_CHUNK;
        if (broad_phase(pr, n_defl, (float)dt, pool, i0, m, reach, mark))
            exact_pass(&c, i0, m, mark);
    }
}
