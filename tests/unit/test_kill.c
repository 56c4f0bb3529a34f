/* Kill rules and wrapping bounds against geometry: hand-built pools with
 * points just inside and just outside every region boundary (1e-4 off a
 * face, a sphere or a plane), the alpha rule against its table, the distance
 * rule against a moving emitter, and the wrap against the exact remainder
 * (within one float ulp, never outside the box, velocity untouched). Then the
 * compiler through the real parser, and whole effects through pfx_compile
 * and the simulation (those need the module wired into compile.c/sim.c). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "compile/compile.h"
#include "compile/compile_kill.h"
#include "sim/kill.h"
#include "sim/sim.h"
#include "test.h"
#include "test_compile.h"

/* ---- Helpers ---- */

#define EPS 1e-4

/* A pool of n particles with every column but the optional ones; age 0
 * (born at the pool's time 0),
 * lifetime 1, velocity (i, -i, 2i) so a changed velocity shows. */
static pfx_pool pool_make(uint32_t n) {
    pfx_pool p = {0};
    p.count = p.capacity = n;
    float **cols[] = {&p.px, &p.py, &p.pz, &p.vx, &p.vy, &p.vz, &p.lifetime};
    for (size_t c = 0; c < sizeof cols / sizeof *cols; c++)
        *cols[c] = calloc(n ? n : 1, sizeof(float));
    p.birth = calloc(n ? n : 1, sizeof(double));
    p.id = calloc(n ? n : 1, sizeof(uint32_t));
    for (uint32_t i = 0; i < n; i++) {
        p.lifetime[i] = 1;
        p.vx[i] = (float)i, p.vy[i] = -(float)i, p.vz[i] = 2.0f * (float)i;
        p.id[i] = i;
    }
    return p;
}

static void pool_free(pfx_pool *p) {
    free(p->px), free(p->py), free(p->pz), free(p->vx), free(p->vy), free(p->vz);
    free(p->birth), free(p->lifetime), free(p->id);
}

static void set_pos(pfx_pool *p, uint32_t i, double x, double y, double z) {
    p->px[i] = (float)x, p->py[i] = (float)y, p->pz[i] = (float)z;
}

static bool marked(const pfx_pool *p, uint32_t i) {
    return p->lifetime[i] == PFX_KILLED || pfx_particle_age(p, i) >= p->lifetime[i];
}

/* Sets particle i's age at the pool's time 0. */
static void set_age(pfx_pool *p, uint32_t i, double age) { p->birth[i] = -age; }

/* Points just inside and just outside each of the six faces of the box
 * [c - h, c + h], at the middle of the face: entries 2k (inside) and 2k + 1
 * (outside) for face k; entry 12 is the centre. */
static pfx_pool box_probe(const double c[3], const double h[3]) {
    pfx_pool p = pool_make(13);
    for (int a = 0; a < 3; a++)
        for (int s = 0; s < 2; s++) {
            const double sign = s ? 1 : -1;
            for (int in = 0; in < 2; in++) {
                double x[3] = {c[0], c[1], c[2]};
                x[a] = c[a] + sign * (h[a] + (in ? -EPS : EPS));
                set_pos(&p, (uint32_t)(2 * (2 * a + s) + !in), x[0], x[1], x[2]);
            }
        }
    set_pos(&p, 12, c[0], c[1], c[2]);
    return p;
}

/* ---- Regions ---- */

static void test_box_inside_outside(void) {
    const double c[3] = {1, -2, 3.5}, h[3] = {1, 2.5, 0.75};
    for (int kind = 0; kind < 2; kind++) {
        pfx_kill_rules k = {0};
        k.count = 1;
        k.rules[0] = (pfx_kill_rule){.kind = kind ? PFX_KILL_OUTSIDE : PFX_KILL_INSIDE,
                                     .shape = PFX_KILL_BOX,
                                     .center = {c[0], c[1], c[2]},
                                     .half = {h[0], h[1], h[2]}};
        pfx_pool p = box_probe(c, h);
        pfx_kill_apply(&k, &p, NULL, NULL);
        for (uint32_t i = 0; i < 12; i++) {
            bool inside = i % 2 == 0;
            CHECK(marked(&p, i) == (kind ? !inside : inside));
        }
        CHECK(marked(&p, 12) == !kind);
        pool_free(&p);
        /* Exactly on a face (float-exact edges): the box is closed. */
        pfx_pool q = pool_make(6);
        for (int a = 0; a < 3; a++)
            for (int s = 0; s < 2; s++) {
                double x[3] = {c[0], c[1], c[2]};
                x[a] = c[a] + (s ? h[a] : -h[a]);
                set_pos(&q, (uint32_t)(2 * a + s), x[0], x[1], x[2]);
            }
        pfx_kill_apply(&k, &q, NULL, NULL);
        for (uint32_t i = 0; i < 6; i++)
            CHECK(marked(&q, i) == !kind);
        pool_free(&q);
    }
}

/* Unit directions: the axes, a diagonal and an irregular one. */
static const double dirs[][3] = {{1, 0, 0},
                                 {-1, 0, 0},
                                 {0, 1, 0},
                                 {0, -1, 0},
                                 {0, 0, 1},
                                 {0, 0, -1},
                                 {0.57735026918962573, 0.57735026918962573, 0.57735026918962573},
                                 {0.6, -0.8, 0}};
enum { NDIRS = sizeof dirs / sizeof *dirs };

static void test_sphere_inside_outside(void) {
    const double c[3] = {1, -2, 0.5}, radius = 1.5;
    for (int kind = 0; kind < 2; kind++) {
        pfx_kill_rules k = {0};
        k.count = 1;
        k.rules[0] = (pfx_kill_rule){.kind = kind ? PFX_KILL_OUTSIDE : PFX_KILL_INSIDE,
                                     .shape = PFX_KILL_SPHERE,
                                     .center = {c[0], c[1], c[2]},
                                     .radius = radius};
        pfx_pool p = pool_make(2 * NDIRS);
        for (int d = 0; d < NDIRS; d++)
            for (int out = 0; out < 2; out++) {
                double r = radius + (out ? EPS : -EPS);
                set_pos(&p, (uint32_t)(2 * d + out), c[0] + r * dirs[d][0], c[1] + r * dirs[d][1],
                        c[2] + r * dirs[d][2]);
            }
        pfx_kill_apply(&k, &p, NULL, NULL);
        for (uint32_t i = 0; i < p.count; i++) {
            bool outside = i % 2 == 1;
            CHECK(marked(&p, i) == (kind ? outside : !outside));
        }
        pool_free(&p);
    }
}

/* Points at signed distance +-EPS from the plane through q with unit normal
 * n, shifted along the plane by large tangent offsets: only the side counts. */
static void test_half_space(void) {
    const double q[3] = {0.5, 1, -2};
    const double n[3] = {0.70710678118654752, 0.70710678118654752, 0};
    const double t1[3] = {0.70710678118654752, -0.70710678118654752, 0}, t2[3] = {0, 0, 1};
    const double offsets[][2] = {{0, 0}, {3, 0}, {-2, 5}, {0.25, -7}};
    enum { NOFF = sizeof offsets / sizeof *offsets };
    for (int kind = 0; kind < 2; kind++) {
        pfx_kill_rules k = {0};
        k.count = 1;
        k.rules[0] = (pfx_kill_rule){.kind = kind ? PFX_KILL_OUTSIDE : PFX_KILL_INSIDE,
                                     .shape = PFX_KILL_HALF_SPACE,
                                     .center = {q[0], q[1], q[2]},
                                     .normal = {n[0], n[1], n[2]}};
        pfx_pool p = pool_make(2 * NOFF);
        for (int o = 0; o < NOFF; o++)
            for (int front = 0; front < 2; front++) {
                double s = front ? EPS : -EPS, x[3];
                for (int a = 0; a < 3; a++)
                    x[a] = q[a] + s * n[a] + offsets[o][0] * t1[a] + offsets[o][1] * t2[a];
                set_pos(&p, (uint32_t)(2 * o + front), x[0], x[1], x[2]);
            }
        pfx_kill_apply(&k, &p, NULL, NULL);
        /* The side the normal points to is the inside. */
        for (uint32_t i = 0; i < p.count; i++) {
            bool front = i % 2 == 1;
            CHECK(marked(&p, i) == (kind ? !front : front));
        }
        pool_free(&p);
    }
}

/* ---- Alpha and distance ---- */

/* Entry k of the table is the alpha at age fraction k / 255, read at the
 * nearest entry. A table with a dip in the middle: the rule reads the table,
 * not a threshold on age. */
static void test_alpha_below(void) {
    float alpha[PFX_KILL_ALPHA_LUT];
    for (int i = 0; i < PFX_KILL_ALPHA_LUT; i++)
        alpha[i] = 1.0f - (float)i / 255.0f;
    for (int i = 60; i <= 70; i++)
        alpha[i] = 0.1f;
    pfx_kill_rules k = {0};
    k.count = 1;
    k.rules[0] = (pfx_kill_rule){.kind = PFX_KILL_ALPHA_BELOW, .threshold = 0.5};
    /* Ages at exact entries (lifetime 2 so the fraction is age / 2). */
    const int entries[] = {0, 59, 60, 65, 70, 71, 127, 128, 200, 255, 127, 128};
    const bool dies[] = {false, false, true, true, true,  false,
                         false, true,  true, true, false, true};
    /* The last two sit 0.4 of an entry away, 127.4 and 127.6: the nearest
     * entry is read, as the colour lookup does. */
    const float offset[] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.4f, -0.4f};
    enum { N = sizeof entries / sizeof *entries };
    pfx_pool p = pool_make(N + 1);
    for (uint32_t i = 0; i < N; i++) {
        p.lifetime[i] = 2;
        set_age(&p, i, 2.0f * ((float)entries[i] + offset[i]) / 255.0f);
    }
    /* Past its lifetime: the last entry, and marked (it would die anyway). */
    p.lifetime[N] = 1, set_age(&p, N, 1.5f);
    pfx_kill_apply(&k, &p, NULL, alpha);
    for (uint32_t i = 0; i < N; i++) {
        CHECK(marked(&p, i) == dies[i]);
        CHECK((alpha[entries[i]] < 0.5f) == dies[i]); /* the table says so */
    }
    CHECK(marked(&p, N));
    /* Threshold 0: nothing is below it. */
    k.rules[0].threshold = 0;
    pfx_pool q = pool_make(3);
    set_age(&q, 0, 0), set_age(&q, 1, 0.5f), set_age(&q, 2, 0.99f);
    pfx_kill_apply(&k, &q, NULL, alpha);
    for (uint32_t i = 0; i < 3; i++)
        CHECK(!marked(&q, i));
    pool_free(&q);
    pool_free(&p);
}

/* Farther than d from the emitter dies; the emitter's position is the one
 * passed, so moving it changes who dies. */
static void test_distance_from_emitter(void) {
    const double d = 2;
    pfx_kill_rules k = {0};
    k.count = 1;
    k.rules[0] = (pfx_kill_rule){.kind = PFX_KILL_DISTANCE, .threshold = d};
    const double e0[3] = {3, 0, -1};
    pfx_pool p = pool_make(2 * NDIRS);
    for (int i = 0; i < NDIRS; i++)
        for (int out = 0; out < 2; out++) {
            double r = d + (out ? EPS : -EPS);
            set_pos(&p, (uint32_t)(2 * i + out), e0[0] + r * dirs[i][0], e0[1] + r * dirs[i][1],
                    e0[2] + r * dirs[i][2]);
        }
    pfx_kill_apply(&k, &p, e0, NULL);
    for (uint32_t i = 0; i < p.count; i++)
        CHECK(marked(&p, i) == (i % 2 == 1));
    /* The emitter moved 10 m away: everything is now too far. */
    for (uint32_t i = 0; i < p.count; i++)
        p.lifetime[i] = 1;
    const double e1[3] = {13, 0, -1};
    pfx_kill_apply(&k, &p, e1, NULL);
    for (uint32_t i = 0; i < p.count; i++)
        CHECK(marked(&p, i));
    pool_free(&p);
}

/* ---- Bounds ---- */

/* The exact wrapped value of float x in the float box [lo, hi), rounded to
 * float once: long double holds x - lo and the period exactly for these
 * magnitudes, and fmodl is exact. */
static float wrap_expected(float x, float lo, float hi) {
    long double period = (long double)hi - (long double)lo;
    long double r = fmodl((long double)x - (long double)lo, period);
    if (r < 0)
        r += period;
    return (float)((long double)lo + r);
}

/* got is expected within one ulp, or the seam: expected rounds to hi, which
 * is lo on the torus. */
static bool wrap_ok(float got, float x, float lo, float hi) {
    if (!(got >= lo && got < hi))
        return false;
    float want = wrap_expected(x, lo, hi);
    if (want >= hi)
        return got == lo || got == nextafterf(hi, -INFINITY);
    return got == want || got == nextafterf(want, INFINITY) || got == nextafterf(want, -INFINITY);
}

static pfx_kill_rules wrap_rules(const double c[3], const double h[3], pfx_bounds_mode mode) {
    pfx_kill_rules k = {0};
    k.bounds = mode;
    memcpy(k.bounds_center, c, sizeof k.bounds_center);
    memcpy(k.bounds_half, h, sizeof k.bounds_half);
    return k;
}

/* Through each face: a particle 0.01 past it re-enters 0.01 inside the
 * opposite face; the other coordinates and the velocity do not change. */
static void test_wrap_faces(void) {
    const double c[3] = {0.5, 2, -3}, h[3] = {1, 2, 0.75};
    pfx_kill_rules k = wrap_rules(c, h, PFX_BOUNDS_WRAP);
    float lo[3], hi[3];
    for (int a = 0; a < 3; a++)
        lo[a] = (float)(c[a] - h[a]), hi[a] = (float)(c[a] + h[a]);
    pfx_pool p = box_probe(c, h);
    for (uint32_t i = 0; i < 12; i++) /* push the outside probes 0.01 out */
        if (i % 2 == 1) {
            int a = (int)(i / 4), s = (int)(i / 2) % 2;
            float *col = a == 0 ? p.px : a == 1 ? p.py : p.pz;
            col[i] = (float)(c[a] + (s ? 1 : -1) * (h[a] + 0.01));
        }
    pfx_pool before = pool_make(13);
    float *const cols_b[] = {before.px, before.py, before.pz, before.vx, before.vy, before.vz};
    float *const cols_p[] = {p.px, p.py, p.pz, p.vx, p.vy, p.vz};
    for (int k2 = 0; k2 < 6; k2++)
        memcpy(cols_b[k2], cols_p[k2], 13 * sizeof(float));
    pfx_kill_apply(&k, &p, NULL, NULL);
    for (uint32_t i = 0; i < 13; i++) {
        CHECK(!marked(&p, i));
        CHECK(p.vx[i] == before.vx[i] && p.vy[i] == before.vy[i] && p.vz[i] == before.vz[i]);
        for (int a = 0; a < 3; a++) {
            float x0 = cols_b[a][i], x1 = cols_p[a][i];
            int axis = (int)(i / 4), s = (int)(i / 2) % 2;
            if (i == 12 || i % 2 == 0 || axis != a) {
                CHECK(x1 == x0); /* inside on this axis: untouched */
                continue;
            }
            CHECK(wrap_ok(x1, x0, lo[a], hi[a]));
            /* Geometrically: 0.01 inside the opposite face. */
            double want = s ? lo[a] + 0.01 : hi[a] - 0.01;
            CHECK_NEAR(x1, want, 2e-6);
        }
    }
    pool_free(&before);
    pool_free(&p);
}

/* Far away (up to a million box sizes), at the faces exactly and one float
 * off them: always inside [lo, hi) and within an ulp of the exact value. */
static void test_wrap_far_and_seams(void) {
    const float lo = -0.5f, hi = 1.5f, P = hi - lo;
    const double ks[] = {-1e6, -12345, -3, -1, 0, 1, 2, 7, 99999, 1e6};
    const float fracs[] = {0, 1e-7f, 0.3f, 1.0f, 1.9999f, 2.0f - 1e-7f};
    for (size_t a = 0; a < sizeof ks / sizeof *ks; a++)
        for (size_t b = 0; b < sizeof fracs / sizeof *fracs; b++) {
            float x = (float)(lo + ks[a] * P + fracs[b]);
            CHECK(wrap_ok(pfx_kill_wrap(x, lo, hi), x, lo, hi));
        }
    CHECK(pfx_kill_wrap(hi, lo, hi) == lo);
    CHECK(pfx_kill_wrap(lo, lo, hi) == lo);
    const float below_hi = nextafterf(hi, -INFINITY), below_lo = nextafterf(lo, -INFINITY);
    CHECK(pfx_kill_wrap(below_hi, lo, hi) == below_hi);
    CHECK(wrap_ok(pfx_kill_wrap(below_lo, lo, hi), below_lo, lo, hi));
    CHECK(
        wrap_ok(pfx_kill_wrap(nextafterf(hi, INFINITY), lo, hi), nextafterf(hi, INFINITY), lo, hi));
    /* A box whose edges are not binary fractions, through the pool. */
    const double c[3] = {0.1, -0.3, 1e3}, h[3] = {0.35, 1.7, 0.05};
    pfx_kill_rules k = wrap_rules(c, h, PFX_BOUNDS_WRAP);
    float flo[3], fhi[3];
    for (int i = 0; i < 3; i++)
        flo[i] = (float)(c[i] - h[i]), fhi[i] = (float)(c[i] + h[i]);
    enum { N = 4000 };
    pfx_pool p = pool_make(N);
    float orig[3][N];
    uint64_t s = 0x9e3779b97f4a7c15ull;
    for (uint32_t i = 0; i < N; i++) {
        float *col[3] = {p.px, p.py, p.pz};
        for (int a = 0; a < 3; a++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            double u = (double)(s >> 11) / 9007199254740992.0; /* [0, 1) */
            /* Within +-1e4 box sizes, a third of them near a face. */
            double span = 2 * h[a];
            double x = i % 3 == 0   ? c[a] + (u - 0.5) * 2e4 * span
                       : i % 3 == 1 ? c[a] + h[a] + (u - 0.5) * 1e-5
                                    : c[a] - h[a] + (u - 0.5) * 1e-5;
            col[a][i] = orig[a][i] = (float)x;
        }
    }
    pfx_kill_apply(&k, &p, NULL, NULL);
    int bad = 0;
    for (uint32_t i = 0; i < N; i++) {
        const float *col[3] = {p.px, p.py, p.pz};
        for (int a = 0; a < 3; a++) {
            bool inside0 = orig[a][i] >= flo[a] && orig[a][i] < fhi[a];
            bool ok =
                inside0 ? col[a][i] == orig[a][i] : wrap_ok(col[a][i], orig[a][i], flo[a], fhi[a]);
            bad += !ok;
        }
        bad += marked(&p, i) || p.vx[i] != (float)i;
    }
    CHECK(bad == 0);
    pool_free(&p);
}

/* Kill mode marks exactly the particles outside the closed box. */
static void test_bounds_kill(void) {
    const double c[3] = {1, -2, 3.5}, h[3] = {1, 2.5, 0.75};
    pfx_kill_rules k = wrap_rules(c, h, PFX_BOUNDS_KILL);
    pfx_pool p = box_probe(c, h);
    const float x0 = p.px[1];
    pfx_kill_apply(&k, &p, NULL, NULL);
    for (uint32_t i = 0; i < 12; i++)
        CHECK(marked(&p, i) == (i % 2 == 1));
    CHECK(!marked(&p, 12));
    CHECK(p.px[1] == x0); /* kill mode never moves a particle */
    pool_free(&p);
}

/* Bounds wrap first, then the rules see the wrapped positions; several rules
 * combine (any of them kills); an empty set is empty. */
static void test_order_and_combination(void) {
    pfx_kill_rules k = wrap_rules((double[]){0, 0, 0}, (double[]){1, 1, 1}, PFX_BOUNDS_WRAP);
    k.count = 2;
    /* Kill in the slab x in [-1, -0.5] (a box) and beyond y > 0.9 (half-space). */
    k.rules[0] = (pfx_kill_rule){.kind = PFX_KILL_INSIDE,
                                 .shape = PFX_KILL_BOX,
                                 .center = {-0.75, 0, 0},
                                 .half = {0.25, 1, 1}};
    k.rules[1] = (pfx_kill_rule){.kind = PFX_KILL_INSIDE,
                                 .shape = PFX_KILL_HALF_SPACE,
                                 .center = {0, 0.9, 0},
                                 .normal = {0, 1, 0}};
    pfx_pool p = pool_make(4);
    set_pos(&p, 0, 1.2, 0, 0);   /* wraps to -0.8: inside the slab */
    set_pos(&p, 1, 0.2, 0, 0);   /* stays */
    set_pos(&p, 2, 0, 0.95, 0);  /* beyond the plane */
    set_pos(&p, 3, 0, -1.05, 0); /* wraps to y = 0.95: beyond the plane */
    pfx_kill_apply(&k, &p, NULL, NULL);
    CHECK(marked(&p, 0) && !marked(&p, 1) && marked(&p, 2) && marked(&p, 3));
    CHECK_NEAR(p.px[0], -0.8, 1e-6);
    CHECK_NEAR(p.py[3], 0.95, 1e-6);
    pfx_kill_rules none = {0};
    CHECK(pfx_kill_rules_empty(&none));
    CHECK(!pfx_kill_rules_empty(&k));
    CHECK(!pfx_kill_needs_alpha(&k));
    pool_free(&p);
}

/* ---- The compiler, through the parser ---- */

typedef struct parsed {
    pfx_doc doc;
    pfx_arena arena;
    pfx_diags diags;
    pfx_reader r;
} parsed;

/* Parses text (an emitter mapping) and compiles its kill/bounds; returns the
 * compiler's verdict. */
static bool compile_rules(parsed *ps, const char *text, pfx_kill_rules *out) {
    memset(ps, 0, sizeof *ps);
    size_t len = strlen(text);
    pfx_diags_init(&ps->diags, "inline.yaml", text, len);
    if (!pfx_parse(text, len, &ps->doc, &ps->diags))
        return false;
    ps->r = (pfx_reader){.d = &ps->diags, .arena = &ps->arena};
    const pfx_node *root = ps->doc.root;
    return pfx_compile_kill(&ps->r, pfx_node_get(root, "kill"), pfx_node_get(root, "bounds"), out);
}

static void parsed_free(parsed *ps) {
    pfx_doc_free(&ps->doc);
    pfx_arena_free(&ps->arena);
    pfx_diags_free(&ps->diags);
}

static void test_compile(void) {
    parsed ps;
    pfx_kill_rules k;
    const char *text = "kill:\n"
                       "  - inside: { box: { center: [1, 2, 3], size: [2, 4, 6] } }\n"
                       "  - outside: { sphere: { radius: 5 } }\n"
                       "  - inside: { half_space: { point: [0, -1, 0], normal: [0, -3, 4] } }\n"
                       "  - alpha_below: 0.05\n"
                       "  - distance_from_emitter: 12\n"
                       "bounds: { box: { center: [0, 4, 0], size: [8, 8, 6] }, mode: wrap }\n";
    CHECK(compile_rules(&ps, text, &k));
    CHECK(k.count == 5);
    CHECK(k.rules[0].kind == PFX_KILL_INSIDE && k.rules[0].shape == PFX_KILL_BOX);
    CHECK(k.rules[0].center[2] == 3 && k.rules[0].half[0] == 1 && k.rules[0].half[2] == 3);
    CHECK(k.rules[1].kind == PFX_KILL_OUTSIDE && k.rules[1].shape == PFX_KILL_SPHERE);
    CHECK(k.rules[1].radius == 5 && k.rules[1].center[0] == 0);
    CHECK(k.rules[2].shape == PFX_KILL_HALF_SPACE && k.rules[2].center[1] == -1);
    CHECK_NEAR(k.rules[2].normal[1], -0.6, 1e-15);
    CHECK_NEAR(k.rules[2].normal[2], 0.8, 1e-15);
    CHECK(k.rules[3].kind == PFX_KILL_ALPHA_BELOW && k.rules[3].threshold == 0.05);
    CHECK(k.rules[4].kind == PFX_KILL_DISTANCE && k.rules[4].threshold == 12);
    CHECK(k.bounds == PFX_BOUNDS_WRAP && k.bounds_center[1] == 4 && k.bounds_half[2] == 3);
    CHECK(pfx_kill_needs_alpha(&k));
    CHECK(ps.diags.errors == 0);
    parsed_free(&ps);

    /* Mode defaults to kill; nothing given is empty. */
    CHECK(compile_rules(&ps, "bounds: { box: { size: [1, 2, 3] } }\n", &k));
    CHECK(k.bounds == PFX_BOUNDS_KILL && k.count == 0 && k.bounds_half[1] == 1);
    parsed_free(&ps);
    CHECK(compile_rules(&ps, "rate: 1\n", &k)); /* neither key */
    CHECK(pfx_kill_rules_empty(&k));
    parsed_free(&ps);

    /* Errors are all reported, each once (the diag cases pin the text). */
    CHECK(!compile_rules(&ps,
                         "kill:\n"
                         "  - inside: { sphere: { radius: 0 } }\n"
                         "  - outside: { box: { size: [1, -1, 1] } }\n"
                         "  - inside: { half_space: { normal: [0, 0, 0] } }\n"
                         "  - alpha_below: 1.01\n"
                         "  - insde: { box: { size: [1, 1, 1] } }\n"
                         "bounds: { box: { size: [1, 0, 1] }, mode: wrap }\n",
                         &k));
    CHECK(ps.diags.errors == 6);
    parsed_free(&ps);
}

/* ---- Whole effects through pfx_compile and the simulation ---- */

/* Particles fly out in every direction from the centre of a 2 m box for 4 s
 * (lifetime 100 s, so age never kills). Wrap: after every step every
 * particle is inside [lo, hi) and none has died (the pool holds every
 * birth). Kill: every live particle is inside the closed box and some died. */
#define BOX_EFFECT                                                                                 \
    "pfx: 1\nseed: 4\nsim: { rate: 60 }\n"                                                         \
    "emitters:\n  e:\n    position: [0.25, 1, 0]\n    rate: 50\n    lifetime: 100\n"               \
    "    speed: [0.5, 3]\n    spread: 180\n"                                                       \
    "    bounds: { box: { center: [0.25, 1, 0], size: [2, 2, 2] }, mode: %s }\n"

static void run_box(const char *mode) {
    char text[1024];
    snprintf(text, sizeof text, BOX_EFFECT, mode);
    compiled c;
    if (!compile_text(&c, text)) {
        compiled_free(&c);
        return;
    }
    const bool wrap = !strcmp(mode, "wrap");
    pfx_sim *s = pfx_sim_create(c.e, NULL);
    CHECK(s != NULL);
    const float lo[3] = {-0.75f, 0, -1}, hi[3] = {1.25f, 2, 1};
    int outside = 0;
    for (int step = 0; step < 240 && s; step++) {
        pfx_sim_step(s);
        const pfx_pool *p = &s->pools[0];
        const float *col[3] = {p->px, p->py, p->pz};
        for (uint32_t i = 0; i < p->count; i++)
            for (int a = 0; a < 3; a++)
                outside += wrap ? !(col[a][i] >= lo[a] && col[a][i] < hi[a])
                                : !(col[a][i] >= lo[a] && col[a][i] <= hi[a]);
    }
    CHECK(outside == 0);
    if (s) {
        if (wrap)
            CHECK(s->pools[0].count == s->emitters[0].born);
        else
            CHECK(s->pools[0].count < s->emitters[0].born / 2);
    }
    pfx_sim_destroy(s);
    compiled_free(&c);
}

static void test_effect_wrap(void) { run_box("wrap"); }
static void test_effect_bounds_kill(void) { run_box("kill"); }

/* A kill plane under a fountain: no live particle is ever below it. */
static void test_effect_kill_plane(void) {
    compiled c;
    if (!compile_text(&c, "pfx: 1\nseed: 9\nsim: { rate: 60 }\n"
                          "forces:\n  g: { type: gravity }\n"
                          "emitters:\n  e:\n    rate: 100\n    lifetime: 100\n"
                          "    speed: 4\n    spread: 30\n"
                          "    kill:\n      - inside: { half_space: { point: [0, -0.5, 0], "
                          "normal: [0, -1, 0] } }\n")) {
        compiled_free(&c);
        return;
    }
    pfx_sim *s = pfx_sim_create(c.e, NULL);
    int below = 0;
    for (int step = 0; step < 300; step++) {
        pfx_sim_step(s);
        const pfx_pool *p = &s->pools[0];
        for (uint32_t i = 0; i < p->count; i++)
            below += p->py[i] <= -0.5f;
    }
    CHECK(below == 0);
    /* 5 s of 100/s, the first to die after about 0.9 s of flight. */
    CHECK(s->pools[0].count < s->emitters[0].born / 2);
    pfx_sim_destroy(s);
    compiled_free(&c);
}

int main(void) {
    RUN(test_box_inside_outside);
    RUN(test_sphere_inside_outside);
    RUN(test_half_space);
    RUN(test_alpha_below);
    RUN(test_distance_from_emitter);
    RUN(test_wrap_faces);
    RUN(test_wrap_far_and_seams);
    RUN(test_bounds_kill);
    RUN(test_order_and_combination);
    RUN(test_compile);
    RUN(test_effect_wrap);
    RUN(test_effect_bounds_kill);
    RUN(test_effect_kill_plane);
    return TEST_EXIT();
}
