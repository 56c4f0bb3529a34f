/* The deflectors against exact solutions: bounce apexes eps^(2n) h0 and
 * unsnapped hit times, friction (1 - mu)^n, resting contact without jitter,
 * no tunnelling at 10 km/s, the chance statistics, kill/stick/lifetime loss,
 * the move pass's marks giving the same result as the pass's own broad
 * phase, sliders giving the same bits on the chunked walk as on the general
 * pass, and a randomized stress test that no particle ever ends a step on the
 * wrong side of a surface. The integrator here is the exact constant-
 * acceleration update, as the simulation's gravity kernel. */
#include "test.h"

#include <stdint.h>
#include <string.h>

#include "sim/collide.h"

#define G 9.81

/* A pool with its start-of-step scratch, all owned here. */
typedef struct tpool {
    uint32_t n;
    float *x0[6], *x[6]; /* px py pz vx vy vz */
    float *life;
    uint32_t *id;
    uint8_t *stuck;
    uint32_t *hits;
    pfx_collide_pool view;
} tpool;

static tpool *tpool_new(uint32_t n, bool with_stuck) {
    tpool *p = calloc(1, sizeof *p);
    p->n = n;
    for (int c = 0; c < 6; c++) {
        p->x0[c] = calloc(n, sizeof(float));
        p->x[c] = calloc(n, sizeof(float));
    }
    p->life = calloc(n, sizeof(float));
    p->id = calloc(n, sizeof(uint32_t));
    p->stuck = with_stuck ? calloc(n, 1) : NULL;
    p->hits = calloc(n, sizeof(uint32_t));
    for (uint32_t i = 0; i < n; i++)
        p->id[i] = i, p->life[i] = 1e9f;
    p->view = (pfx_collide_pool){.count = n,
                                 .px0 = p->x0[0],
                                 .py0 = p->x0[1],
                                 .pz0 = p->x0[2],
                                 .vx0 = p->x0[3],
                                 .vy0 = p->x0[4],
                                 .vz0 = p->x0[5],
                                 .px = p->x[0],
                                 .py = p->x[1],
                                 .pz = p->x[2],
                                 .vx = p->x[3],
                                 .vy = p->x[4],
                                 .vz = p->x[5],
                                 .lifetime = p->life,
                                 .id = p->id,
                                 .stuck = p->stuck,
                                 .hits = p->hits};
    return p;
}

static void tpool_free(tpool *p) {
    for (int c = 0; c < 6; c++)
        free(p->x0[c]), free(p->x[c]);
    free(p->life), free(p->id), free(p->stuck), free(p->hits), free(p);
}

static void set(tpool *p, uint32_t i, double x, double y, double z, double u, double v, double w) {
    double s[6] = {x, y, z, u, v, w};
    for (int c = 0; c < 6; c++)
        p->x[c][i] = (float)s[c];
}

/* Saves the start state, moves every particle by the exact constant-
 * acceleration update (in float, as the simulation), then collides. */
static void step(tpool *p, const double g[3], double dt, const pfx_deflector *d, size_t nd,
                 pfx_hit_fn fn, void *user, pfx_collide_stats *st) {
    for (int c = 0; c < 6; c++)
        memcpy(p->x0[c], p->x[c], p->n * sizeof(float));
    const float h = (float)(0.5 * dt * dt), fdt = (float)dt;
    for (uint32_t i = 0; i < p->n; i++) {
        for (int j = 0; j < 3; j++) {
            p->x[j][i] += p->x[3 + j][i] * fdt + (float)g[j] * h;
            p->x[3 + j][i] += (float)g[j] * fdt;
        }
    }
    pfx_collide(d, nd, dt, &p->view, NULL, fn, user, st);
}

static pfx_deflector plane(double px, double py, double pz, double nx, double ny, double nz) {
    pfx_deflector d;
    memset(&d, 0, sizeof d);
    d.name = "plane";
    d.shape = PFX_DEFLECTOR_PLANE;
    d.point[0] = px, d.point[1] = py, d.point[2] = pz;
    d.normal[0] = nx, d.normal[1] = ny, d.normal[2] = nz;
    d.resilience[0] = d.resilience[1] = 1;
    d.chance = 1;
    return d;
}

static pfx_deflector sphere(double cx, double cy, double cz, double r, bool inside) {
    pfx_deflector d = plane(cx, cy, cz, 0, 1, 0);
    d.shape = PFX_DEFLECTOR_SPHERE;
    d.radius = r;
    d.inside = inside;
    return d;
}

static pfx_deflector box(double cx, double cy, double cz, double sx, double sy, double sz,
                         bool inside) {
    pfx_deflector d = plane(cx, cy, cz, 0, 1, 0);
    d.shape = PFX_DEFLECTOR_BOX;
    d.size[0] = sx, d.size[1] = sy, d.size[2] = sz;
    d.inside = inside;
    return d;
}

typedef struct rec {
    int n;
    uint32_t index[64];
    double pos[64][3], normal[64][3], t[64];
} rec;

static void record(void *user, uint32_t index, size_t k, const double pos[3],
                   const double normal[3], double t) {
    (void)k;
    rec *r = user;
    if (r->n < 64) {
        r->index[r->n] = index;
        memcpy(r->pos[r->n], pos, sizeof r->pos[0]);
        memcpy(r->normal[r->n], normal, sizeof r->normal[0]);
        r->t[r->n] = t;
    }
    r->n++;
}

static const double gravity[3] = {0, -G, 0};

/* Dropped from h0 onto y = 0: the apex after n bounces is eps^(2n) h0, and
 * the hits come at T1 = sqrt(2 h0/g), T(n+1) = Tn + 2 eps^n sqrt(2 g h0)/g. */
static void test_bounce(void) {
    const double dt = 1.0 / 60, eps = 0.8, h0 = 1;
    pfx_deflector d = plane(0, 0, 0, 0, 1, 0);
    d.resilience[0] = d.resilience[1] = eps;
    tpool *p = tpool_new(1, false);
    set(p, 0, 0, h0, 0, 0, 0, 0);
    double texact = sqrt(2 * h0 / G), v0 = sqrt(2 * G * h0);
    int bounces = 0;
    double worst_t = 0, worst_apex = 0;
    for (int k = 0; k < 2000 && bounces < 10; k++) {
        rec r = {0};
        step(p, gravity, dt, &d, 1, record, &r, NULL);
        if (r.n == 0)
            continue;
        CHECK(r.n == 1);
        bounces++;
        double t = k * dt + r.t[0];
        CHECK_NEAR(t, texact, 1e-6);
        if (bounces == 1) /* not snapped to a step */
            CHECK(fabs(r.t[0]) > 1e-3 * dt && fabs(r.t[0] - dt) > 1e-3 * dt);
        CHECK(r.pos[0][1] == 0);
        double y = p->x[1][0], vy = p->x[4][0];
        double apex = y + vy * vy / (2 * G), want = pow(eps, 2 * bounces) * h0;
        CHECK_NEAR(apex / want, 1, 1e-4);
        worst_t = fmax(worst_t, fabs(t - texact));
        worst_apex = fmax(worst_apex, fabs(apex / want - 1));
        texact += 2 * pow(eps, bounces) * v0 / G;
    }
    CHECK(bounces == 10);
    fprintf(stderr, "  10 bounces: hit times within %.2g s, apexes within %.2g relative\n", worst_t,
            worst_apex);
    tpool_free(p);
}

/* Sliding into the floor at an angle: each impact keeps (1 - mu) of the
 * tangential speed (no tangential force acts in flight). */
static void test_friction(void) {
    const double dt = 1.0 / 60, mu = 0.15, u0 = 3;
    pfx_deflector d = plane(0, 0, 0, 0, 1, 0);
    d.resilience[0] = d.resilience[1] = 0.95;
    d.friction[0] = d.friction[1] = mu;
    tpool *p = tpool_new(1, false);
    set(p, 0, 0, 0.5, 0, u0, -2, 0.5 * u0);
    int bounces = 0;
    double worst = 0;
    for (int k = 0; k < 2000 && bounces < 10; k++) {
        rec r = {0};
        step(p, gravity, dt, &d, 1, record, &r, NULL);
        bounces += r.n;
        double want = pow(1 - mu, bounces);
        worst = fmax(worst, fabs(p->x[3][0] / u0 - want));
        CHECK_NEAR(p->x[3][0] / u0, want, 1e-6);
        CHECK_NEAR(p->x[5][0] / (0.5 * u0), want, 1e-6);
    }
    CHECK(bounces == 10);
    fprintf(stderr, "  friction: u_n / u0 within %.2g of (1 - mu)^n\n", worst);
    tpool_free(p);
}

/* eps = 0.3: the ball comes to rest exactly on the plane and stays there. */
static void test_resting(void) {
    const double dt = 1.0 / 60;
    pfx_deflector d = plane(0, 0, 0, 0, 1, 0);
    d.resilience[0] = d.resilience[1] = 0.3;
    d.friction[0] = d.friction[1] = 0.4;
    tpool *p = tpool_new(2, false);
    set(p, 0, 0, 1, 0, 0, 0, 0);
    set(p, 1, 5, 1, 0, 2, 0, 0); /* one sliding away: it stops by friction */
    for (int k = 0; k < 300; k++)
        step(p, gravity, dt, &d, 1, NULL, NULL, NULL);
    CHECK(p->x[1][0] == 0.0f && p->x[4][0] == 0.0f);
    CHECK(p->x[1][1] == 0.0f && p->x[4][1] == 0.0f);
    CHECK(p->x[3][1] == 0.0f); /* stopped by Coulomb friction 0.4 g */
    float x1 = p->x[0][1];
    pfx_collide_stats st = {0};
    for (int k = 0; k < 100; k++) {
        step(p, gravity, dt, &d, 1, NULL, NULL, &st);
        for (uint32_t i = 0; i < 2; i++)
            CHECK(p->x[1][i] == 0.0f && p->x[4][i] == 0.0f && p->x[3][i] == 0.0f);
        CHECK(p->x[0][0] == 0.0f && p->x[0][1] == x1);
    }
    CHECK(st.impacts == 0 && st.contacts == 200);

    /* The Coulomb slide on its own: at rest on the floor with u = 2 m/s and
     * mu = 0.4, it stops after u / (mu g) s, having slid u^2 / (2 mu g). */
    set(p, 0, 0, 0, 0, 2, 0, 0);
    set(p, 1, 0, 0, 0, -1, 0, 0);
    for (int k = 0; k < 120; k++)
        step(p, gravity, dt, &d, 1, NULL, NULL, NULL);
    CHECK_NEAR(p->x[0][0], 4 / (2 * 0.4 * G), 1e-5);
    CHECK_NEAR(p->x[0][1], -1 / (2 * 0.4 * G), 1e-5);
    CHECK(p->x[1][0] == 0.0f && p->x[3][0] == 0.0f);
    tpool_free(p);
}

/* Resting on a 20 degree slope: Coulomb friction holds the particle when
 * mu >= tan 20 deg, and otherwise it slides with a = g (sin - mu cos). */
static void test_slope(void) {
    const double dt = 1.0 / 60, th = 20 * 3.14159265358979323846 / 180;
    const double n[3] = {sin(th), cos(th), 0}; /* downhill is +x */
    pfx_deflector d[2] = {plane(0, 0, 0, n[0], n[1], n[2]), plane(0, 0, 0, n[0], n[1], n[2])};
    d[0].resilience[0] = d[0].resilience[1] = 0.2;
    d[0].friction[0] = d[0].friction[1] = 0.5;
    d[1].resilience[0] = d[1].resilience[1] = 0.2;
    d[1].friction[0] = d[1].friction[1] = 0.1;
    tpool *p = tpool_new(1, false);
    for (int k = 0; k < 2; k++) {
        set(p, 0, 0, 1e-6, 0, 0, 0, 0); /* just above the plane, at rest */
        for (int s = 0; s < 5; s++)
            step(p, gravity, dt, &d[k], 1, NULL, NULL, NULL);
        double x0[3] = {p->x[0][0], p->x[1][0], p->x[2][0]};
        double u0 = p->x[3][0] * cos(th) - p->x[4][0] * sin(th); /* speed downhill */
        pfx_collide_stats st = {0};
        for (int s = 0; s < 60; s++) {
            step(p, gravity, dt, &d[k], 1, NULL, NULL, &st);
            double x[3] = {p->x[0][0], p->x[1][0], p->x[2][0]};
            double dn = x[0] * n[0] + x[1] * n[1];
            CHECK(dn >= 0 && dn < 1e-6);
        }
        double u1 = p->x[3][0] * cos(th) - p->x[4][0] * sin(th);
        double vn = p->x[3][0] * n[0] + p->x[4][0] * n[1];
        CHECK(st.impacts == 0);
        CHECK(fabs(vn) < 1e-6);
        if (k == 0) { /* held: it has not moved */
            CHECK(fabs(p->x[0][0] - x0[0]) < 1e-6 && fabs(p->x[1][0] - x0[1]) < 1e-6);
            CHECK(u0 == 0 && u1 == 0);
        } else {
            double acc = G * (sin(th) - 0.1 * cos(th));
            CHECK_NEAR((u1 - u0) / 1.0, acc, 1e-4 * acc);
            fprintf(stderr, "  slope: slide acceleration %.7g, exact g (sin - mu cos) = %.7g\n",
                    u1 - u0, acc);
        }
    }
    tpool_free(p);
}

/* The plane crossing when the quadratic cancels badly: 1 mm above the
 * floor at 1 km/s, t = 2c / (-b + sqrt(b^2 - 4Ac)). */
static void test_cancellation(void) {
    const double dt = 1.0 / 60;
    pfx_deflector d = plane(0, 0, 0, 0, 1, 0);
    tpool *p = tpool_new(1, false);
    set(p, 0, 0, 1e-3, 0, 0, -1000, 0);
    float v1 = (float)(-1000 - G * dt);
    double c = (double)1e-3f, b = -1000, A = 0.5 * ((double)v1 + 1000) / dt;
    double want = 2 * c / (-b + sqrt(b * b - 4 * A * c));
    rec r = {0};
    step(p, gravity, dt, &d, 1, record, &r, NULL);
    CHECK(r.n == 1);
    CHECK_NEAR(r.t[0] / want, 1, 1e-14);
    tpool_free(p);
}

/* At 10,000 m/s (333 m per step) into a 0.1 m sphere, a 0.1 m disc, and a
 * chord of 9 mm through the sphere (0.9 us inside it): all caught. */
static void test_tunnelling(void) {
    const double dt = 1.0 / 30, zero[3] = {0, 0, 0};
    pfx_deflector s = sphere(0, 0, 0, 0.1, false);
    pfx_deflector disc = plane(0, 0, 0, 0, 0, 1);
    disc.shape = PFX_DEFLECTOR_DISC;
    disc.radius = 0.1;
    tpool *p = tpool_new(3, false);
    set(p, 0, 0, 0, -100, 0, 0, 10000);
    set(p, 1, 0.0999, 0, -100, 0, 0, 10000);
    set(p, 2, 0.05, 0.05, -100, 0, 0, 10000);
    rec r = {0};
    step(p, zero, dt, &s, 1, record, &r, NULL);
    CHECK(r.n == 3);
    for (int h = 0; h < 3 && h < r.n; h++) {
        double *q = r.pos[h];
        CHECK_NEAR(sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]), 0.1, 1e-12);
    }
    for (uint32_t i = 0; i < 3; i++) {
        double x = p->x[0][i], y = p->x[1][i], z = p->x[2][i];
        CHECK(sqrt(x * x + y * y + z * z) >= 0.1);
    }
    CHECK(p->x[5][0] == -10000.0f && p->x[2][0] < -0.1f); /* head-on: straight back */
    set(p, 0, 0, 0, -100, 0, 0, 10000);
    set(p, 1, 0.0999, 0, -100, 0, 0, 10000);
    set(p, 2, 0.05, 0.05, -100, 0, 0, 10000);
    r.n = 0;
    step(p, zero, dt, &disc, 1, record, &r, NULL);
    CHECK(r.n == 3);
    for (uint32_t i = 0; i < 3; i++)
        CHECK(p->x[2][i] < 0 && p->x[5][i] == -10000.0f);
    tpool_free(p);
}

/* Chance 0.3: a fixed 30 % of the particles bounce, always the same ones. */
static void test_chance(void) {
    const uint32_t n = 100000;
    const double dt = 1.0 / 30, zero[3] = {0, 0, 0};
    pfx_deflector d = plane(0, 0, 0, 0, 1, 0);
    d.chance = 0.3;
    d.seed = 12345;
    tpool *p = tpool_new(n, false);
    for (uint32_t i = 0; i < n; i++)
        set(p, i, 0, 1, 0, 0, -100, 0);
    step(p, zero, dt, &d, 1, NULL, NULL, NULL);
    uint32_t passed = 0, same = 0;
    for (uint32_t i = 0; i < n; i++) {
        bool through = p->x[1][i] < 0;
        passed += through;
        same += through == !pfx_deflector_affects(&d, i);
    }
    double frac = (double)passed / n, sigma = sqrt(0.3 * 0.7 / n);
    CHECK_NEAR(frac, 0.7, 4 * sigma);
    CHECK(same == n);
    tpool_free(p);
}

static void test_kill_stick_loss(void) {
    const double dt = 1.0 / 60;
    pfx_deflector d = plane(0, 0, 0, 0, 1, 0);
    d.response = PFX_DEFLECT_KILL;
    tpool *p = tpool_new(1, true);
    set(p, 0, 0.5, 0.01, 0, 1, -2, 0);
    p->life[0] = 3;
    rec r = {0};
    step(p, gravity, dt, &d, 1, record, &r, NULL);
    CHECK(r.n == 1 && p->life[0] == PFX_KILLED && p->x[1][0] == 0.0f);

    /* Stick on a sphere's side: held at the hit point from then on. */
    pfx_deflector s = sphere(0, 0, 0, 1, false);
    s.response = PFX_DEFLECT_STICK;
    set(p, 0, -2, 0.3, 0, 20, 0, 0);
    p->life[0] = 3;
    r.n = 0;
    for (int k = 0; k < 30 && r.n == 0; k++)
        step(p, gravity, dt, &s, 1, record, &r, NULL);
    CHECK(r.n == 1 && p->stuck[0] == 1);
    float hold[3] = {p->x[0][0], p->x[1][0], p->x[2][0]};
    CHECK_NEAR(hypot(hypot(hold[0], hold[1]), hold[2]), 1, 1e-6);
    CHECK(hypot(hypot(hold[0], hold[1]), hold[2]) >= 1.0);
    for (int k = 0; k < 50; k++)
        step(p, gravity, dt, &s, 1, record, &r, NULL);
    CHECK(r.n == 1 && p->x[0][0] == hold[0] && p->x[1][0] == hold[1] && p->x[2][0] == hold[2]);
    CHECK(p->x[3][0] == 0 && p->x[4][0] == 0 && p->x[5][0] == 0);

    /* lifetime_loss 0.25: three impacts leave 0.75^3 of the lifetime. */
    tpool_free(p);
    p = tpool_new(1, false);
    d.response = PFX_DEFLECT_BOUNCE;
    d.lifetime_loss = 0.25;
    p->life[0] = 8;
    set(p, 0, 0, 0.5, 0, 0, 0, 0);
    int hits = 0;
    for (int k = 0; k < 600 && hits < 3; k++) {
        r.n = 0;
        step(p, gravity, dt, &d, 1, record, &r, NULL);
        hits += r.n;
    }
    CHECK(hits == 3);
    CHECK_NEAR(p->life[0], 8 * 0.75 * 0.75 * 0.75, 1e-5);
    tpool_free(p);
}

/* Particles that touch nothing keep the integrator's state bit for bit; an
 * end point behind a plane that the parabola misses (a non-constant force)
 * is still caught. */
static void test_untouched_and_fallback(void) {
    const double dt = 1.0 / 60;
    pfx_deflector d[2] = {plane(0, -5, 0, 0, 1, 0), sphere(3, 3, 3, 1, false)};
    tpool *p = tpool_new(100, false);
    pfx_rng rng;
    pfx_rng_seed(&rng, 7, 1);
    for (uint32_t i = 0; i < 100; i++)
        set(p, i, pfx_rng_range(&rng, -1, 1), pfx_rng_range(&rng, -1, 1), 0,
            pfx_rng_range(&rng, -5, 5), pfx_rng_range(&rng, -5, 5), 0.1);
    for (int c = 0; c < 6; c++)
        memcpy(p->x0[c], p->x[c], 100 * sizeof(float));
    for (uint32_t i = 0; i < 100; i++)
        p->x[1][i] += 0.1f, p->x[4][i] -= 0.2f;
    float before[6][100];
    for (int c = 0; c < 6; c++)
        memcpy(before[c], p->x[c], sizeof before[c]);
    pfx_collide(d, 2, dt, &p->view, NULL, NULL, NULL, NULL);
    for (int c = 0; c < 6; c++)
        CHECK(memcmp(before[c], p->x[c], sizeof before[c]) == 0);

    /* x0 0.1 above, v0 = v1 = 0, but x1 0.1 below (a fake integrator) */
    pfx_deflector f = plane(0, 0, 0, 0, 1, 0);
    set(p, 0, 0, 0.1, 0, 0, 0, 0);
    p->view.count = 1;
    for (int c = 0; c < 6; c++)
        p->x0[c][0] = p->x[c][0];
    p->x[1][0] = -0.1f;
    pfx_collide_stats st = {0};
    pfx_collide(&f, 1, dt, &p->view, NULL, NULL, NULL, &st);
    CHECK(st.fallbacks == 1 && st.impacts + st.contacts == 1 && p->x[1][0] >= 0);
    tpool_free(p);
}

/* ---- stress ------------------------------------------------------------ */

static double dist_plane(const pfx_deflector *d, const double x[3]) {
    double n = sqrt(d->normal[0] * d->normal[0] + d->normal[1] * d->normal[1] +
                    d->normal[2] * d->normal[2]);
    double s = 0;
    for (int j = 0; j < 3; j++)
        s += d->normal[j] * (x[j] - d->point[j]);
    return s / n;
}

/* Signed distance, positive on the particles' side (thin shapes: none). */
static double dist(const pfx_deflector *d, const double x[3]) {
    double q[3] = {x[0] - d->point[0], x[1] - d->point[1], x[2] - d->point[2]};
    switch (d->shape) {
    case PFX_DEFLECTOR_PLANE:
        return d->size[0] > 0 ? INFINITY : dist_plane(d, x);
    case PFX_DEFLECTOR_DISC:
        return INFINITY;
    case PFX_DEFLECTOR_SPHERE: {
        double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        return d->inside ? d->radius - l : l - d->radius;
    }
    case PFX_DEFLECTOR_BOX: {
        double e = -INFINITY; /* max over axes of |q| - h: the distance inside */
        for (int j = 0; j < 3; j++)
            e = fmax(e, fabs(q[j]) - 0.5 * d->size[j]);
        return d->inside ? -e : e;
    }
    }
    return 0;
}

/* n particles at random places on the right side of every deflector, with
 * random velocities up to 200 m/s, 300 steps at dt = 1/30: the worst signed
 * distance ever seen must be >= -1e-5 m. */
static double stress(pfx_deflector *d, size_t nd, const double lo[3], const double hi[3],
                     uint32_t n, pfx_collide_stats *st) {
    const double dt = 1.0 / 30;
    pfx_rng rng;
    pfx_rng_seed(&rng, 2024, 9);
    for (size_t k = 0; k < nd; k++) {
        d[k].resilience[0] = 0.2, d[k].resilience[1] = 1;
        d[k].friction[0] = 0, d[k].friction[1] = 0.5;
    }
    tpool *p = tpool_new(n, false);
    for (uint32_t i = 0; i < n; i++) {
        double x[3];
        bool ok;
        do {
            for (int j = 0; j < 3; j++)
                x[j] = pfx_rng_range(&rng, lo[j], hi[j]);
            ok = true;
            for (size_t k = 0; k < nd; k++)
                ok &= dist(&d[k], x) > 0;
        } while (!ok);
        double v[3], s = pfx_rng_range(&rng, 0, 200), l;
        do {
            for (int j = 0; j < 3; j++)
                v[j] = pfx_rng_range(&rng, -1, 1);
            l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        } while (l > 1 || l < 1e-3);
        set(p, i, x[0], x[1], x[2], v[0] * s / l, v[1] * s / l, v[2] * s / l);
    }
    double worst = INFINITY;
    bool finite = true;
    for (int k = 0; k < 300; k++) {
        step(p, gravity, dt, d, nd, NULL, NULL, st);
        for (uint32_t i = 0; i < n; i++) {
            double x[3] = {p->x[0][i], p->x[1][i], p->x[2][i]};
            for (size_t j = 0; j < nd; j++)
                worst = fmin(worst, dist(&d[j], x));
            finite &= isfinite(p->x[3][i] + p->x[4][i] + p->x[5][i]);
        }
    }
    CHECK(finite);
    tpool_free(p);
    return worst;
}

/* The marks pfx_collide_near leaves give pfx_collide the result of its
 * own broad phase, bit for bit: two copies of a crowd falling through
 * bouncing, sticking (by chance), killing and life-shortening surfaces,
 * one collided without marks and one with them, agree in every column,
 * the counters and the random stream after every step. */
static void test_marks_given(void) {
    const double dt = 1.0 / 60;
    pfx_deflector d[4] = {plane(0, 0, 0, 0, 1, 0), sphere(0.5, 1, 0, 0.6, false),
                          box(-1, 1.5, 0, 0.8, 0.4, 0.8, false), plane(0, 2.5, 0, 0.3, -1, 0)};
    d[0].resilience[0] = 0.3, d[0].resilience[1] = 0.8, d[0].friction[1] = 0.4;
    d[1].response = PFX_DEFLECT_STICK, d[1].chance = 0.5;
    d[2].lifetime_loss = 0.1;
    d[3].response = PFX_DEFLECT_KILL, d[3].chance = 0.4;
    enum { N = 3000 };
    tpool *a = tpool_new(N, true), *b = tpool_new(N, true);
    pfx_rng place;
    pfx_rng_seed(&place, 11, 3);
    for (uint32_t i = 0; i < N; i++) {
        double s[6] = {pfx_rng_range(&place, -2, 2), pfx_rng_range(&place, 0, 3),
                       pfx_rng_range(&place, -1, 1), pfx_rng_range(&place, -3, 3),
                       pfx_rng_range(&place, -2, 6), pfx_rng_range(&place, -1, 1)};
        set(a, i, s[0], s[1], s[2], s[3], s[4], s[5]);
        set(b, i, s[0], s[1], s[2], s[3], s[4], s[5]);
    }
    pfx_collide_stats sa = {0}, sb = {0};
    uint8_t near[N];
    int agree = 0, marked_some = 0, marked_all = 0;
    for (int k = 0; k < 120; k++) {
        step(a, gravity, dt, d, 4, NULL, NULL, &sa);
        /* b: the same move, then the marks, then the exact pass */
        for (int c = 0; c < 6; c++)
            memcpy(b->x0[c], b->x[c], N * sizeof(float));
        const float h = (float)(0.5 * dt * dt), fdt = (float)dt;
        for (uint32_t i = 0; i < N; i++)
            for (int j = 0; j < 3; j++) {
                b->x[j][i] += b->x[3 + j][i] * fdt + (float)gravity[j] * h;
                b->x[3 + j][i] += (float)gravity[j] * fdt;
            }
        bool any = pfx_collide_near(d, 4, dt, &b->view, near);
        size_t count = 0;
        for (uint32_t i = 0; i < N; i++)
            count += near[i] != 0;
        marked_some += any && count > 0;
        marked_all += count == N;
        pfx_collide(d, 4, dt, &b->view, near, NULL, NULL, &sb);
        bool same = memcmp(a->life, b->life, N * sizeof(float)) == 0 &&
                    memcmp(a->stuck, b->stuck, N) == 0 && memcmp(&sa, &sb, sizeof sa) == 0;
        for (int c = 0; c < 6; c++)
            same = same && memcmp(a->x[c], b->x[c], N * sizeof(float)) == 0;
        agree += same;
    }
    fprintf(stderr,
            "  %d of 120 steps agree; some marked in %d, all in %d; %llu impacts, "
            "%llu kills, %llu sticks\n",
            agree, marked_some, marked_all, (unsigned long long)sa.impacts,
            (unsigned long long)sa.kills, (unsigned long long)sa.sticks);
    CHECK(agree == 120);
    CHECK(marked_some > 0 && marked_all < 120);
    CHECK(sa.impacts > 0 && sa.kills > 0 && sa.sticks > 0);
    tpool_free(a);
    tpool_free(b);
}

/* Sliding particles on one plane take collide_slide.c's chunked walk (and
 * those that hit nothing its flight verdict), alone or beside a second
 * plane no particle can reach; with pfx_collide_lanes off they take the
 * general pass. Both must store the same
 * bits, step after step, for sliders at every speed (stopping, resting,
 * -0 components, a hair above the plane) on a level and a tilted plane,
 * with and without friction, beside particles that bounce, fly, and rise
 * from behind the plane. Particles that strike the plane from the air
 * take a walk too (a bounce, a landing, a rest, a second strike within
 * the step), dropped from heights up to 1.2 m, straight down or at an
 * angle, with a random and a constant resilience and friction, and with
 * a lifetime loss; and with on_hit events, which must come in the same
 * order with the same point, normal, time and velocity. */
typedef struct hit_record {
    uint32_t index, deflector;
    double pos[3], normal[3], t;
    float vel[3], life;
    uint32_t hits;
} hit_record;

typedef struct hit_log {
    const tpool *pool;
    hit_record *e;
    size_t n, cap;
} hit_log;

/* An on_hit callback: what an event sees, as sim/step.c's reads it. */
static void log_hit(void *user, uint32_t index, size_t deflector, const double pos[3],
                    const double normal[3], double t) {
    hit_log *h = user;
    if (h->n == h->cap) {
        h->cap = h->cap ? 2 * h->cap : 1024;
        h->e = realloc(h->e, h->cap * sizeof *h->e);
    }
    hit_record *r = &h->e[h->n++];
    memset(r, 0, sizeof *r);
    r->index = index, r->deflector = (uint32_t)deflector, r->t = t, r->life = h->pool->life[index],
    r->hits = h->pool->hits[index];
    for (int j = 0; j < 3; j++)
        r->pos[j] = pos[j], r->normal[j] = normal[j], r->vel[j] = h->pool->x[3 + j][index];
}

static void test_slide_same_bits(void) {
    const double tilt[3] = {0.3, 1, 0.1};
    size_t events = 0;
    for (int variant = 0; variant < 32; variant++) {
        const bool tilted = variant & 1, constant = variant & 4, hits = variant & 8;
        const size_t nd = variant & 16 ? 2 : 1;
        pfx_deflector one[2] = {tilted ? plane(0, -0.2, 0, tilt[0], tilt[1], tilt[2])
                                       : plane(0, 0, 0, 0, 1, 0),
                                plane(0, -1000, 0, 0, 1, 0)};
        one[0].resilience[0] = constant ? 0.5 : 0.3, one[0].resilience[1] = constant ? 0.5 : 0.6;
        one[0].friction[0] = variant & 2 ? 0 : constant ? 0.1 : 0.05;
        one[0].friction[1] = variant & 2 ? 0 : constant ? 0.1 : 0.3;
        one[0].lifetime_loss = (variant & 6) == 6 ? 0.1 : 0;
        const uint32_t n = 3000;
        tpool *a = tpool_new(n, false), *b = tpool_new(n, false);
        for (uint32_t i = 0; i < n; i++) {
            const double u = (double)(i % 101) / 50 - 1, w = (double)(i % 37) / 18 - 1;
            const double x = 0.01 * (i % 53), z = -0.02 * (i % 29);
            /* on the plane (level: exactly; tilted: its float rounding) */
            double y = tilted ? -0.2 - (tilt[0] * x + tilt[2] * z) / tilt[1] : 0;
            double vy = 0, uu = u, ww = w;
            switch (i % 7) {
            case 0: /* at rest */
                uu = ww = 0;
                break;
            case 1: /* -0 components */
                uu = -0.0, vy = -0.0;
                break;
            case 2: /* a hair above it */
                y += 1e-7;
                break;
            case 3: /* falling onto it */
                y += 0.05 * (i % 7), vy = -1;
                break;
            case 6: /* half of them dropped from up to 1.2 m, some straight down */
                if (i % 2)
                    break;
                y += 0.1 * (i % 13), vy = -0.1 * (i % 5);
                uu = i % 3 ? uu : 0, ww = i % 3 ? ww : 0;
                break;
            case 4: /* slow enough to stop within a few steps */
                uu *= 0.01, ww *= 0.01;
                break;
            case 5: /* behind the plane, rising through it */
                y -= 0.002 * (i % 11), vy = 0.3;
                break;
            default:
                break;
            }
            set(a, i, x, y, z, uu, vy, ww);
            set(b, i, x, y, z, uu, vy, ww);
        }
        pfx_collide_stats sa = {0}, sb = {0};
        hit_log la = {a, NULL, 0, 0}, lb = {b, NULL, 0, 0};
        bool same = true;
        for (int k = 0; k < 240 && same; k++) {
            step(a, gravity, 1.0 / 120, one, nd, hits ? log_hit : NULL, &la, &sa);
            pfx_collide_lanes = false;
            step(b, gravity, 1.0 / 120, one, nd, hits ? log_hit : NULL, &lb, &sb);
            pfx_collide_lanes = true;
            same = la.n == lb.n && (!la.n || !memcmp(la.e, lb.e, la.n * sizeof *la.e));
            for (int c = 0; c < 6; c++)
                same = same && !memcmp(a->x[c], b->x[c], n * sizeof(float));
            same = same && !memcmp(a->hits, b->hits, n * sizeof(uint32_t));
            same = same && !memcmp(a->life, b->life, n * sizeof(float));
        }
        CHECK(same);
        CHECK(sa.contacts == sb.contacts && sa.impacts == sb.impacts && sa.contacts > 0);
        CHECK(!hits || la.n == sa.impacts);
        events += la.n;
        free(la.e), free(lb.e);
        tpool_free(a), tpool_free(b);
    }
    fprintf(stderr, "  %zu on_hit events, the same in both passes\n", events);
}

/* Beside a sphere and a box, the particles near the ground plane alone
 * take the walks, those near the others the general pass: a fountain of
 * 4000 particles (most bounce, slide and rest on the ground, some strike
 * the sphere and the box, some rest on the box) stores the same bits and
 * raises the same events, deflector indices included, with the lanes as
 * without. */
static void test_lanes_beside_others(void) {
    pfx_deflector room[3] = {sphere(0.5, 0.4, 0, 0.3, false), plane(0, 0, 0, 0, 1, 0),
                             box(-0.6, 0.2, 0, 0.4, 0.4, 0.4, false)};
    room[1].resilience[0] = 0.3, room[1].resilience[1] = 0.6;
    room[1].friction[0] = room[1].friction[1] = 0.2;
    room[0].resilience[0] = room[2].resilience[0] = room[0].resilience[1] = room[2].resilience[1] =
        0.4;
    const uint32_t n = 4000;
    tpool *a = tpool_new(n, false), *b = tpool_new(n, false);
    for (uint32_t i = 0; i < n; i++) {
        const double ang = 6.283185307179586 * (double)(i % 97) / 97, sp = 0.2 + 0.01 * (i % 61);
        const double x = 0.02 * (double)(i % 41) - 0.4, y = 0.05 + 0.02 * (i % 53);
        set(a, i, x, y, 0.01 * (i % 7), sp * cos(ang), 1 + 0.01 * (i % 89), sp * sin(ang));
        set(b, i, x, y, 0.01 * (i % 7), sp * cos(ang), 1 + 0.01 * (i % 89), sp * sin(ang));
    }
    pfx_collide_stats sa = {0}, sb = {0};
    hit_log la = {a, NULL, 0, 0}, lb = {b, NULL, 0, 0};
    bool same = true;
    for (int k = 0; k < 360 && same; k++) {
        step(a, gravity, 1.0 / 120, room, 3, log_hit, &la, &sa);
        pfx_collide_lanes = false;
        step(b, gravity, 1.0 / 120, room, 3, log_hit, &lb, &sb);
        pfx_collide_lanes = true;
        same = la.n == lb.n && (!la.n || !memcmp(la.e, lb.e, la.n * sizeof *la.e));
        for (int c = 0; c < 6; c++)
            same = same && !memcmp(a->x[c], b->x[c], n * sizeof(float));
        same = same && !memcmp(a->hits, b->hits, n * sizeof(uint32_t));
    }
    size_t on[3] = {0};
    for (size_t e = 0; e < la.n; e++)
        on[la.e[e].deflector]++;
    fprintf(stderr, "  %zu events (sphere %zu, ground %zu, box %zu), %llu contacts\n", la.n, on[0],
            on[1], on[2], (unsigned long long)sa.contacts);
    CHECK(same);
    CHECK(on[0] > 0 && on[1] > 0 && on[2] > 0 && sa.contacts > 0);
    CHECK(memcmp(&sa, &sb, sizeof sa) == 0);
    free(la.e), free(lb.e);
    tpool_free(a), tpool_free(b);
}

/* An on_hit that runs a collide pass of its own (on this thread), and a
 * plane whose rebound outruns the impact (resilience 6: the compiler
 * allows at most 1, pfx_collide does not check): both take the general
 * pass, so lanes on and off agree. */
typedef struct nested_hit {
    tpool *other;
    const pfx_deflector *d;
} nested_hit;

static void collide_again(void *user, uint32_t index, size_t deflector, const double pos[3],
                          const double normal[3], double t) {
    (void)index, (void)deflector, (void)pos, (void)normal, (void)t;
    nested_hit *h = user;
    step(h->other, gravity, 1.0 / 120, h->d, 1, NULL, NULL, NULL);
}

static void test_lanes_guards(void) {
    pfx_deflector floor = plane(0, 0, 0, 0, 1, 0);
    floor.resilience[0] = floor.resilience[1] = 0.5, floor.friction[0] = floor.friction[1] = 0.1;
    tpool *a[2], *o[2];
    for (int r = 0; r < 2; r++) {
        a[r] = tpool_new(200, false), o[r] = tpool_new(200, false);
        for (uint32_t i = 0; i < 200; i++) {
            set(a[r], i, 0.01 * i, 0.002 * (i % 50), 0, 0.3, -1, 0);
            set(o[r], i, -0.01 * i, 0.001 * (i % 70), 0.1, -0.2, -0.5, 0.1);
        }
    }
    bool same = true;
    for (int k = 0; k < 60; k++) {
        for (int r = 0; r < 2; r++) {
            nested_hit h = {o[r], &floor};
            pfx_collide_lanes = r == 0;
            step(a[r], gravity, 1.0 / 120, &floor, 1, collide_again, &h, NULL);
        }
        pfx_collide_lanes = true;
        for (int c = 0; c < 6; c++)
            same = same && !memcmp(a[0]->x[c], a[1]->x[c], 200 * sizeof(float)) &&
                   !memcmp(o[0]->x[c], o[1]->x[c], 200 * sizeof(float));
    }
    CHECK(same);
    for (int r = 0; r < 2; r++)
        tpool_free(a[r]), tpool_free(o[r]);

    pfx_deflector room[2] = {plane(0, 0, 0, 0, 1, 0), sphere(0, 0.35, 0, 0.1, false)};
    room[0].resilience[0] = room[0].resilience[1] = 6;
    tpool *p[2];
    for (int r = 0; r < 2; r++) {
        p[r] = tpool_new(1, false);
        set(p[r], 0, 0, 0.05, 0, 0, -1, 0);
        pfx_collide_lanes = r == 0;
        step(p[r], gravity, 0.1, room, 2, NULL, NULL, NULL);
    }
    pfx_collide_lanes = true;
    fprintf(stderr, "  resilience 6 under a sphere: y %.4f and %.4f\n", p[0]->x[1][0],
            p[1]->x[1][0]);
    CHECK(p[0]->x[1][0] == p[1]->x[1][0]);
    tpool_free(p[0]), tpool_free(p[1]);
}

static uint32_t stress_n = 100000;

static void test_stress(void) {
    /* A room: inside a sphere and a box, around an outside sphere and box,
     * above a floor that meets a wall in a corner, with a bounded plane and
     * a tilted disc in the air. */
    pfx_deflector room[8] = {
        sphere(0, 0, 0, 5, true),         box(0, 0, 0, 8, 8, 8, true), sphere(2, 0, 0, 1, false),
        box(-2, -1, 0, 1, 1.5, 1, false), plane(0, -3, 0, 0, 1, 0),    plane(3, 0, 0, -1, 0, 0),
        plane(0, 2, 0, 0, 1, 0),          plane(0, -2, 2, 0, 1, 1),
    };
    room[6].size[0] = 2, room[6].size[1] = 2;
    room[7].shape = PFX_DEFLECTOR_DISC, room[7].radius = 1;
    double lo[3] = {-4, -4, -4}, hi[3] = {4, 4, 4};
    pfx_collide_stats st = {0};
    double worst = stress(room, 8, lo, hi, stress_n, &st);
    fprintf(stderr,
            "  room: worst signed distance %.3g m; %llu impacts, %llu contacts, "
            "%llu capped, %llu fallbacks\n",
            worst, (unsigned long long)st.impacts, (unsigned long long)st.contacts,
            (unsigned long long)st.capped, (unsigned long long)st.fallbacks);
    CHECK(worst >= -1e-5);

    /* A gap of 1 cm between two planes, and a corner of two tilted planes. */
    pfx_deflector gap[2] = {plane(0, 0, 0, 0, 1, 0), plane(0, 0.01, 0, 0, -1, 0)};
    double glo[3] = {-1, 0, -1}, ghi[3] = {1, 0.01, 1};
    memset(&st, 0, sizeof st);
    worst = stress(gap, 2, glo, ghi, stress_n, &st);
    fprintf(stderr, "  gap: worst signed distance %.3g m; %llu impacts, %llu capped\n", worst,
            (unsigned long long)st.impacts, (unsigned long long)st.capped);
    CHECK(worst >= -1e-5);

    pfx_deflector corner[2] = {plane(0, 0, 0, 0.3, 1, 0.1), plane(0, 0, 0, -1, 0.3, 0)};
    double clo[3] = {-5, 0, -5}, chi[3] = {5, 10, 5};
    memset(&st, 0, sizeof st);
    worst = stress(corner, 2, clo, chi, stress_n, &st);
    fprintf(stderr,
            "  corner: worst signed distance %.3g m; %llu impacts, %llu contacts, %llu capped\n",
            worst, (unsigned long long)st.impacts, (unsigned long long)st.contacts,
            (unsigned long long)st.capped);
    CHECK(worst >= -1e-5);
}

int main(int argc, char **argv) {
    /* A smaller stress run for the sanitizer build: an argument or
     * PFX_TEST_QUICK (set by tests/sanitize/sanitize.sh). */
    if (argc > 1)
        stress_n = (uint32_t)atoi(argv[1]);
    else if (getenv("PFX_TEST_QUICK"))
        stress_n = 20000;
    RUN(test_bounce);
    RUN(test_friction);
    RUN(test_resting);
    RUN(test_slope);
    RUN(test_cancellation);
    RUN(test_tunnelling);
    RUN(test_chance);
    RUN(test_kill_stick_loss);
    RUN(test_untouched_and_fallback);
    RUN(test_marks_given);
    RUN(test_slide_same_bits);
    RUN(test_lanes_beside_others);
    RUN(test_lanes_guards);
    RUN(test_stress);
    return TEST_EXIT();
}
