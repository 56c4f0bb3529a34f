/* Unit tests of the sprite renderer: blending sums and order, the falloff
 * shape, background handling, orientation, perspective size, the stable
 * depth sort and determinism, through the renderer kind PFX_RENDERER names
 * (auto when unset; CTest runs this once per built backend), and OSMesa
 * against egl-cpu byte for byte where both are built. Expected pixels are
 * computed here from the documented formulas, never taken from the
 * renderer's own output. */
/* Sprites are written as their first ten fields (position, size, colour,
 * angle, material); the flipbook, variant, velocity and length stay zero. */
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include "render/render.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "test.h"

/* An odd image size puts a pixel centre exactly on the image centre. With
 * 65 pixels over an ortho view 6.5 m high, one pixel is 0.1 m, so offsets in
 * pixels convert exactly to offsets in metres. */
#define W 65
#define H 65
#define MID 32

static const float transparent[4] = {0, 0, 0, 0};

/* The kind every test renders with, from PFX_RENDERER. */
static pfx_renderer_kind kind = PFX_RENDERER_AUTO;

static pfx_camera ortho_camera(double view_height) {
    pfx_camera c = {.position = {0, 0, 10},
                    .target = {0, 0, 0},
                    .up = {0, 1, 0},
                    .ortho = true,
                    .ortho_height = view_height};
    return c;
}

static const uint8_t *px(const uint8_t *img, int width, int x, int y) {
    return img + ((size_t)y * (size_t)width + (size_t)x) * 4;
}

/* The renderer's byte conversion, restated from its contract: premultiplied
 * (c, a) -> straight alpha with A' = min(1, max(a, c...)). */
static void expect_straight(const double c[3], double a, int out[4]) {
    double ap = fmin(1.0, fmax(fmax(a, c[0]), fmax(c[1], c[2])));
    for (int i = 0; i < 3; i++)
        out[i] = ap > 0 ? (int)lround(255.0 * fmin(1.0, c[i] / ap)) : 0;
    out[3] = (int)lround(255.0 * ap);
}

static void check_pixel(const uint8_t *p, const int want[4], int tol) {
    for (int i = 0; i < 4; i++)
        CHECK_NEAR(p[i], want[i], tol);
}

static pfx_renderer *make_kind(pfx_renderer_kind k, int width, int height) {
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    pfx_renderer *r = pfx_renderer_create(k, width, height, &d);
    if (!r)
        pfx_diags_print(&d, stderr, false);
    pfx_diags_free(&d);
    CHECK(r != NULL);
    return r;
}

static pfx_renderer *make(int width, int height) { return make_kind(kind, width, height); }

static bool draw(pfx_renderer *r, const pfx_camera *cam, const float bg[4], pfx_sprite *s, size_t n,
                 bool sort, uint8_t *img) {
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    bool ok = pfx_renderer_draw(r, cam, bg, s, n, sort, img, &d);
    if (!ok)
        pfx_diags_print(&d, stderr, false);
    pfx_diags_free(&d);
    CHECK(ok);
    return ok;
}

/* Additive sprites (a = 0) add light with no coverage: two give the sum, and
 * the stored alpha is the brightest channel so that compositing over black
 * reproduces the sum. */
static void test_additive_overlap_sums(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    uint8_t img[W * H * 4];
    pfx_camera cam = ortho_camera(6.5);
    pfx_sprite s[2] = {{0, 0, 0, 2, 0.2f, 0.1f, 0, 0, 0, 0}, {0, 0, 0, 2, 0.2f, 0.1f, 0, 0, 0, 0}};

    if (draw(r, &cam, transparent, s, 2, false, img)) {
        const uint8_t *p = px(img, W, MID, MID);
        CHECK_NEAR(p[3], 102, 1); /* alpha = max channel = 0.4 */
        CHECK_NEAR(p[0], 255, 1); /* 0.4 / 0.4 */
        CHECK_NEAR(p[1], 128, 1); /* 0.2 / 0.4 */
        CHECK(p[2] == 0);
        /* Over black: colour * alpha = the premultiplied sum. */
        CHECK_NEAR(p[0] * p[3] / 255.0, 102, 1);
        CHECK_NEAR(p[1] * p[3] / 255.0, 51, 1);
    }
    if (draw(r, &cam, transparent, s, 1, false, img)) {
        const uint8_t *p = px(img, W, MID, MID);
        CHECK_NEAR(p[3], 51, 1);
        CHECK_NEAR(p[0] * p[3] / 255.0, 51, 1);
        CHECK_NEAR(p[1] * p[3] / 255.0, 25.5, 1);
    }
    pfx_renderer_destroy(r);
}

/* Red (far) and blue (near), both half transparent, given near first. Sorted,
 * blue is composited over red: C = a_n c_n + (1 - a_n) a_f c_f,
 * A = a_n + (1 - a_n) a_f. Unsorted, red lands over blue instead. */
static void test_alpha_order(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    uint8_t img[W * H * 4];
    pfx_camera cam = ortho_camera(6.5);
    const double an = 0.5, af = 0.5;
    const pfx_sprite blue_near = {0, 0, 1, 2, 0, 0, (float)an, (float)an, 0, 0};
    const pfx_sprite red_far = {0, 0, -1, 2, (float)af, 0, 0, (float)af, 0, 0};

    double c_sorted[3] = {(1 - an) * af * 1.0, 0, an * 1.0};
    int want_sorted[4];
    expect_straight(c_sorted, an + (1 - an) * af, want_sorted);
    CHECK(want_sorted[0] == 85 && want_sorted[2] == 170 && want_sorted[3] == 191);

    pfx_sprite s[2] = {blue_near, red_far};
    if (draw(r, &cam, transparent, s, 2, true, img)) {
        check_pixel(px(img, W, MID, MID), want_sorted, 1);
        CHECK(s[0].b > 0 && s[1].r > 0); /* drawn far first, the array left as it was */
    }

    double c_unsorted[3] = {af * 1.0, 0, (1 - af) * an * 1.0};
    int want_unsorted[4];
    expect_straight(c_unsorted, af + (1 - af) * an, want_unsorted);
    pfx_sprite u[2] = {blue_near, red_far};
    if (draw(r, &cam, transparent, u, 2, false, img)) {
        const uint8_t *p = px(img, W, MID, MID);
        check_pixel(p, want_unsorted, 1);
        CHECK(abs(p[0] - want_sorted[0]) > 40);
        CHECK(u[0].b > 0 && u[1].r > 0); /* not reordered */
    }
    pfx_renderer_destroy(r);
}

/* Equal depths keep their input order: sorting must then draw exactly what
 * the unsorted call draws. */
static void test_sort_ties_keep_order(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    uint8_t a[W * H * 4], b[W * H * 4];
    pfx_camera cam = ortho_camera(6.5);
    pfx_sprite s[2] = {{0, 0, 0, 2, 0.5f, 0, 0, 0.5f, 0, 0},
                       {0.3f, 0, 0, 2, 0, 0, 0.5f, 0.5f, 0, 0}};
    pfx_sprite t[2];
    memcpy(t, s, sizeof s);
    if (draw(r, &cam, transparent, s, 2, true, a) && draw(r, &cam, transparent, t, 2, false, b)) {
        CHECK(memcmp(a, b, sizeof a) == 0);
        CHECK(s[0].r > 0 && s[1].b > 0);
    }
    pfx_renderer_destroy(r);
}

/* Many sprites on a few depth levels, tagged with their input position in
 * `r`: after pfx_renderer_sort (the order drawing uses), depth never increases (the camera looks
 * down -z, so z never decreases) and within a level the tags increase. Uses n above 65536 so every
 * radix pass that can move sprites does. */
static void test_sort_is_stable_back_to_front(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    /* The camera sits among the sprites, so depths have both signs. */
    pfx_camera cam = ortho_camera(6.5);
    cam.position[2] = 0.5;
    const size_t n = 70000;
    pfx_sprite *s = malloc(n * sizeof *s);
    CHECK(s != NULL);
    if (!s) {
        pfx_renderer_destroy(r);
        return;
    }
    uint32_t state = 12345;
    for (size_t i = 0; i < n; i++) {
        state = state * 1664525u + 1013904223u;
        float z = (float)((state >> 16) % 7) - 3.0f + ((state >> 8) & 1 ? -0.001f : 0.0f);
        s[i] = (pfx_sprite){0, 0, z, 0, (float)i, 0, 0, 0, 0, 0};
    }
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    CHECK(pfx_renderer_sort(r, &cam, s, n, &d));
    pfx_diags_free(&d);
    {
        size_t bad = 0;
        for (size_t i = 1; i < n; i++) {
            if (s[i].z < s[i - 1].z || (s[i].z == s[i - 1].z && s[i].r <= s[i - 1].r))
                bad++;
        }
        CHECK(bad == 0);
    }
    free(s);
    pfx_renderer_destroy(r);
}

/* The sort in batches (a frame of more sprites than the renderer sorts at
 * once, render/sort.c) gives the order of one sort: the same sprites,
 * sorted whole and in batches must come out in the same order, on depths
 * that tie in long runs (a third of the sprites at one depth, which most
 * batch sizes cut), with the camera among them, and once with every depth
 * the same. 70001 sprites in batches of 1000, 4096 and 70000 (two
 * batches), and 3001 in batches of 1 and 7 (each batch scans every
 * sprite, so small batches are for small counts). On 2 threads, where the
 * passes share out blocks. */
static void sort_batches(pfx_renderer *r, const pfx_camera *cam, size_t n, const size_t *batches,
                         size_t nb, pfx_diags *d) {
    pfx_sprite *in = malloc(n * sizeof *in), *whole = malloc(n * sizeof *whole),
               *part = malloc(n * sizeof *part);
    CHECK(in && whole && part);
    for (int flat = 0; flat < 2 && in && whole && part; flat++) {
        uint32_t state = 777;
        for (size_t i = 0; i < n; i++) {
            state = state * 1664525u + 1013904223u;
            float z = i < n / 3 ? 1.25f : (float)((state >> 10) % 1000) / 97.0f - 5.0f;
            in[i] = (pfx_sprite){0, 0, flat ? 2.0f : z, 0, (float)i, 0, 0, 0, 0, 0};
        }
        memcpy(whole, in, n * sizeof *in);
        pfx_renderer_set_sort_batch(r, PFX_SORT_BATCH);
        CHECK(pfx_renderer_sort(r, cam, whole, n, d));
        for (size_t k = 0; k < nb; k++) {
            memcpy(part, in, n * sizeof *in);
            pfx_renderer_set_sort_batch(r, batches[k]);
            CHECK(pfx_renderer_sort(r, cam, part, n, d));
            size_t differ = 0;
            for (size_t i = 0; i < n; i++)
                differ += part[i].r != whole[i].r;
            if (differ)
                fprintf(stderr, "  batch %zu%s: %zu of %zu places differ\n", batches[k],
                        flat ? " (all ties)" : "", differ, n);
            CHECK(differ == 0);
        }
    }
    free(part);
    free(whole);
    free(in);
}

/* Drawing in batches (the sort's, here 1000 sprites) gives the frame of
 * one sort, byte for byte: 20000 overlapping alpha-blended sprites of
 * different colours on a few depth levels, where any change of order
 * changes pixels; and the frame does change when the order does (the
 * same sprites unsorted). */
static void test_sort_batches_draw_the_same(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    const size_t n = 20000;
    pfx_sprite *s = malloc(n * sizeof *s);
    uint8_t *one = malloc(W * H * 4), *batched = malloc(W * H * 4), *unsorted = malloc(W * H * 4);
    CHECK(s && one && batched && unsorted);
    if (s && one && batched && unsorted) {
        pfx_camera cam = ortho_camera(6.5);
        uint32_t state = 99;
        for (size_t i = 0; i < n; i++) {
            state = state * 1664525u + 1013904223u;
            const float x = (float)((state >> 8) % 1000) / 100.0f - 5.0f;
            const float y = (float)((state >> 18) % 1000) / 100.0f - 5.0f;
            s[i] = (pfx_sprite){x,
                                y,
                                (float)(i % 5),
                                0.6f,
                                (float)(i % 3 == 0),
                                (float)(i % 3 == 1),
                                (float)(i % 3 == 2),
                                0.7f,
                                0,
                                0};
        }
        draw(r, &cam, transparent, s, n, true, one);
        pfx_renderer_set_sort_batch(r, 1000);
        draw(r, &cam, transparent, s, n, true, batched);
        draw(r, &cam, transparent, s, n, false, unsorted);
        CHECK(memcmp(one, batched, W * H * 4) == 0);
        CHECK(memcmp(one, unsorted, W * H * 4) != 0);
    }
    free(unsorted);
    free(batched);
    free(one);
    free(s);
    pfx_renderer_destroy(r);
}

static void test_sort_batches_match_one_sort(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    CHECK(pfx_renderer_set_threads(r, 2, &d));
    pfx_camera cam = ortho_camera(6.5);
    cam.position[2] = 0.5;
    const size_t large[] = {1000, 4096, 70000}, small[] = {1, 7};
    sort_batches(r, &cam, 70001, large, 3, &d);
    sort_batches(r, &cam, 3001, small, 2, &d);
    pfx_diags_free(&d);
    pfx_renderer_destroy(r);
}

/* f(d) = (1 - d^2)^2: 1 at the centre, 0.5625 at half radius, 0.4096 at
 * d = 0.6, 0.25 at d = sqrt(0.5), nothing at or beyond the radius. One pixel
 * is 0.1 m and the radius 1 m, so an offset of k pixels is d = k / 10. */
static void test_falloff(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    uint8_t img[W * H * 4];
    pfx_camera cam = ortho_camera(6.5);
    pfx_sprite s = {0, 0, 0, 2, 1, 1, 1, 1, 0, 0};
    if (draw(r, &cam, transparent, &s, 1, false, img)) {
        const uint8_t *c = px(img, W, MID, MID);
        CHECK(c[0] == 255 && c[1] == 255 && c[2] == 255 && c[3] == 255);
        const int half[4][2] = {{MID + 5, MID}, {MID - 5, MID}, {MID, MID + 5}, {MID, MID - 5}};
        for (int i = 0; i < 4; i++) {
            const uint8_t *p = px(img, W, half[i][0], half[i][1]);
            CHECK_NEAR(p[3] / 255.0, 0.5625, 1.0 / 255);
            CHECK(p[0] == 255); /* straight colour stays white */
        }
        /* d = 0.6 (6 pixels): (1 - 0.36)^2 = 0.4096 */
        CHECK_NEAR(px(img, W, MID + 6, MID)[3] / 255.0, 0.4096, 1.0 / 255);
        /* d = 0.5 * sqrt(2) on the diagonal: (1 - 0.5)^2 = 0.25 */
        CHECK_NEAR(px(img, W, MID + 5, MID + 5)[3] / 255.0, 0.25, 1.0 / 255);
        const uint8_t *out = px(img, W, MID + 11, MID);
        CHECK(out[0] == 0 && out[1] == 0 && out[2] == 0 && out[3] == 0);
        const uint8_t *rim = px(img, W, MID + 10, MID); /* d = 1: discarded */
        CHECK(rim[3] == 0);
    }
    pfx_renderer_destroy(r);
}

/* World +y is up in the image (top row first) and +x is right. */
static void test_orientation(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    uint8_t img[W * H * 4];
    pfx_camera cam = ortho_camera(6.5);
    pfx_sprite s[2] = {{0, 2, 0, 1, 1, 0, 0, 1, 0, 0}, {2, 0, 0, 1, 0, 1, 0, 1, 0, 0}};
    if (draw(r, &cam, transparent, s, 2, false, img)) {
        CHECK(px(img, W, MID, MID - 20)[3] == 255);
        CHECK(px(img, W, MID, MID - 20)[0] == 255);
        CHECK(px(img, W, MID, MID + 20)[3] == 0);
        CHECK(px(img, W, MID + 20, MID)[1] == 255);
        CHECK(px(img, W, MID - 20, MID)[3] == 0);
    }
    pfx_renderer_destroy(r);
}

static void test_backgrounds(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    uint8_t img[W * H * 4];
    pfx_camera cam = ortho_camera(6.5);

    const float opaque[4] = {0.2f, 0.4f, 0.6f, 1};
    if (draw(r, &cam, opaque, NULL, 0, true, img)) {
        size_t bad = 0;
        for (int i = 0; i < W * H; i++) {
            const uint8_t *p = img + 4 * i;
            bad += !(p[0] == 51 && p[1] == 102 && p[2] == 153 && p[3] == 255);
        }
        CHECK(bad == 0);
    }
    /* An additive sprite adds to an opaque background and keeps alpha 255. */
    pfx_sprite s = {0, 0, 0, 2, 0.3f, 0.1f, 0, 0, 0, 0};
    if (draw(r, &cam, opaque, &s, 1, false, img)) {
        const int centre[4] = {128, 128, 153, 255}; /* (0.5, 0.5, 0.6) */
        check_pixel(px(img, W, MID, MID), centre, 1);
        const int bg[4] = {51, 102, 153, 255};
        check_pixel(px(img, W, 0, 0), bg, 0);
        check_pixel(px(img, W, W - 1, H - 1), bg, 0);
    }
    /* A half transparent background comes back as it went in. */
    const float half_red[4] = {1, 0, 0, 0.5f};
    if (draw(r, &cam, half_red, NULL, 0, false, img)) {
        const int want[4] = {255, 0, 0, 128};
        check_pixel(px(img, W, 3, 7), want, 0);
    }
    pfx_renderer_destroy(r);
}

/* Diameter in pixels of the sprite along the centre row. */
static int row_coverage(const uint8_t *img, int width, int y) {
    int n = 0;
    for (int x = 0; x < width; x++)
        n += px(img, width, x, y)[3] > 0;
    return n;
}

/* Under perspective a sprite of world size s at distance D spans
 * s / (2 D tan(fov / 2)) of the image height. */
static void test_perspective_size(void) {
    enum { P = 257 };
    pfx_renderer *r = make(P, P);
    if (!r)
        return;
    static uint8_t img[P * P * 4];
    pfx_camera cam = {
        .position = {0, 0, 0}, .target = {0, 0, -1}, .up = {0, 1, 0}, .fov = 60 * M_PI / 180};
    const double t = tan(30.0 * 3.14159265358979323846 / 180.0);
    int diam[2] = {0, 0};
    const double dist[2] = {5, 10};
    for (int i = 0; i < 2; i++) {
        pfx_sprite s = {0, 0, (float)-dist[i], 1, 1, 1, 1, 1, 0, 0};
        if (draw(r, &cam, transparent, &s, 1, false, img)) {
            diam[i] = row_coverage(img, P, P / 2);
            CHECK_NEAR(diam[i], 1.0 / (2 * dist[i] * t) * P, 2);
        }
    }
    CHECK(diam[1] > 0);
    if (diam[1] > 0)
        CHECK_NEAR((double)diam[0] / diam[1], 2.0, 0.1);
    pfx_renderer_destroy(r);
}

static void random_sprites(pfx_sprite *s, size_t n, uint32_t seed) {
    uint32_t state = seed;
#define NEXT() (state = state * 1664525u + 1013904223u, (float)(state >> 8) / 16777216.0f)
    for (size_t i = 0; i < n; i++) {
        float a = NEXT() < 0.5f ? 0 : NEXT();
        s[i] = (pfx_sprite){NEXT() * 4 - 2,
                            NEXT() * 4 - 2,
                            NEXT() * 4 - 2,
                            NEXT() * 0.5f,
                            NEXT() * 0.3f,
                            NEXT() * 0.3f,
                            NEXT() * 0.3f,
                            a,
                            0,
                            0};
        if (a > 0) { /* premultiply alpha sprites */
            s[i].r *= a;
            s[i].g *= a;
            s[i].b *= a;
        }
    }
#undef NEXT
}

/* Same input, byte-identical output: twice in r1 and once in r2, both alive
 * at the same time and taking turns in this thread. */
static void same_pixels(pfx_renderer *r1, pfx_renderer *r2) {
    enum { D = 128, N = 5000 };
    static uint8_t a[D * D * 4], b[D * D * 4], c[D * D * 4];
    static pfx_sprite src[N], s[N];
    random_sprites(src, N, 99);
    pfx_camera cam = {
        .position = {1, 2, 8}, .target = {0, 0, 0}, .up = {0, 1, 0}, .fov = 45 * M_PI / 180};
    const float bg[4] = {0.05f, 0.05f, 0.1f, 0.5f};
    if (r1 && r2) {
        memcpy(s, src, sizeof s);
        bool ok = draw(r1, &cam, bg, s, N, true, a);
        memcpy(s, src, sizeof s);
        ok = ok && draw(r2, &cam, bg, s, N, true, b);
        memcpy(s, src, sizeof s);
        ok = ok && draw(r1, &cam, bg, s, N, true, c);
        CHECK(ok);
        CHECK(memcmp(a, b, sizeof a) == 0);
        CHECK(memcmp(a, c, sizeof a) == 0);
        size_t lit = 0;
        for (size_t i = 0; i < sizeof a; i += 4)
            lit += a[i + 3] > 128;
        CHECK(lit > 100); /* the scene really drew something */
    }
}

/* Sprites are made, uploaded and drawn PFX_RENDER_CHUNK at a time after
 * one sort over all of them: a scene of several chunks (random materials,
 * alpha and additive), drawn sorted, gives the bytes of the same sprites
 * put in that order first (pfx_renderer_sort) and drawn unsorted, so the
 * chunks follow the sorted order across their boundaries; and a second
 * frame elsewhere on the screen, with the first one's pixels left to
 * clear, gives the bytes a fresh renderer gives. */
static void test_chunks(void) {
    enum { D = 96, N = 3 * PFX_RENDER_CHUNK + 77 };
    static uint8_t a[D * D * 4], b[D * D * 4], c[D * D * 4];
    static pfx_sprite s[N], t[N];
    pfx_renderer *r1 = make(D, D), *r2 = make(D, D);
    random_sprites(s, N, 7);
    for (size_t i = 0; i < N; i++) {
        s[i].material = (float)(i % 3);
        s[i].size *= 0.2f;
    }
    memcpy(t, s, sizeof s);
    pfx_camera cam = {
        .position = {1, 2, 8}, .target = {0, 0, 0}, .up = {0, 1, 0}, .fov = 45 * M_PI / 180};
    const float bg[4] = {0.05f, 0.05f, 0.1f, 0.5f};
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    bool sorted = r1 && r2 && pfx_renderer_sort(r2, &cam, t, N, &d);
    CHECK(sorted);
    if (sorted && draw(r1, &cam, bg, s, N, true, a) && draw(r2, &cam, bg, t, N, false, b)) {
        CHECK(memcmp(a, b, sizeof a) == 0);
        /* One sprite at the left edge, then one at the right: the second
         * frame must not keep the first one's pixels. */
        pfx_sprite left = {-2.5f, 0, 0, 1, 0.5f, 0.5f, 0.5f, 0.5f, 0, 0};
        pfx_sprite right = {2.5f, 0, 0, 1, 0, 0.5f, 0, 0.5f, 0, 0};
        if (draw(r1, &cam, bg, &left, 1, true, a) && draw(r1, &cam, bg, &right, 1, true, a) &&
            draw(r2, &cam, transparent, &right, 1, true, c) &&
            draw(r2, &cam, bg, &right, 1, true, b))
            CHECK(memcmp(a, b, sizeof a) == 0);
    }
    pfx_diags_free(&d);
    pfx_renderer_destroy(r1);
    pfx_renderer_destroy(r2);
}

static void test_determinism(void) {
    pfx_renderer *r1 = make(128, 128), *r2 = make(128, 128);
    same_pixels(r1, r2);
    pfx_renderer_destroy(r1);
    pfx_renderer_destroy(r2);
}

/* OSMesa and EGL on Mesa's software device are the same llvmpipe behind two
 * doors: the same scene (alpha and additive sprites, depth sorted) gives the
 * same bytes, with the two contexts alive in one thread and taking turns. */
static void test_osmesa_equals_egl_cpu(void) {
#if defined(PFX_HAVE_OSMESA) && defined(PFX_HAVE_EGL)
    pfx_renderer *r1 = make_kind(PFX_RENDERER_OSMESA, 128, 128);
    pfx_renderer *r2 = make_kind(PFX_RENDERER_EGL_CPU, 128, 128);
    same_pixels(r1, r2);
    pfx_renderer_destroy(r1);
    pfx_renderer_destroy(r2);
#else
    fprintf(stderr, "skip test_osmesa_equals_egl_cpu: pfx is built with only one backend\n");
#endif
}

/* Every kind's name parses back to it, nothing else parses, and a renderer
 * reports the kind it runs (auto resolved, never to a GPU). */
static void test_kinds(void) {
    for (int k = 0; k < PFX_RENDERER_KIND_COUNT; k++) {
        pfx_renderer_kind back = PFX_RENDERER_KIND_COUNT;
        CHECK(pfx_renderer_kind_parse(pfx_renderer_kind_name((pfx_renderer_kind)k), &back));
        CHECK(back == (pfx_renderer_kind)k);
    }
    pfx_renderer_kind unused;
    CHECK(!pfx_renderer_kind_parse("frobnicate", &unused));
    CHECK(!pfx_renderer_kind_parse("EGL-CPU", &unused));
    CHECK(!pfx_renderer_kind_parse("", &unused));
    pfx_renderer *r = make(8, 8);
    if (!r)
        return;
#ifdef PFX_HAVE_OSMESA
    const char *auto_name = "osmesa";
#else
    const char *auto_name = "egl-cpu";
#endif
    CHECK(!strcmp(pfx_renderer_name(r),
                  kind == PFX_RENDERER_AUTO ? auto_name : pfx_renderer_kind_name(kind)));
    pfx_renderer_destroy(r);
}

/* True when d holds exactly one error, worded exactly `want`. */
static bool one_error(pfx_diags *d, const char *want) {
    bool ok = d->count == 1 && d->errors == 1 && !strcmp(d->items[0].message, want);
    if (!ok)
        pfx_diags_print(d, stderr, false);
    pfx_diags_free(d);
    pfx_diags_init_runtime(d);
    return ok;
}

static void test_errors(void) {
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    CHECK(pfx_renderer_create(kind, 0, 10, &d) == NULL);
    CHECK(one_error(&d, "invalid image size 0x10"));
    pfx_renderer *r = make(8, 8);
    if (!r)
        return;
    uint8_t img[8 * 8 * 4];
    /* The words compile uses for the same cameras (tests/diag/camera_*). */
    pfx_camera cam = ortho_camera(1);
    cam.target[2] = cam.position[2]; /* position == target */
    CHECK(!pfx_renderer_draw(r, &cam, transparent, NULL, 0, true, img, &d));
    CHECK(one_error(&d, "camera 'position' and 'target' are the same point"));
    cam = ortho_camera(1);
    cam.up[1] = 0;
    cam.up[2] = 1; /* up along the view direction */
    CHECK(!pfx_renderer_draw(r, &cam, transparent, NULL, 0, true, img, &d));
    CHECK(one_error(&d, "camera 'up' is parallel to the view direction"));
    pfx_diags_free(&d);
    pfx_renderer_destroy(NULL);
    pfx_renderer_destroy(r);
}

static void test_bench_raw(void) {
    pfx_renderer *r = make(64, 64);
    if (!r)
        return;
    pfx_sprite s[100];
    random_sprites(s, 100, 7);
    pfx_sprite copy[100];
    memcpy(copy, s, sizeof s);
    pfx_camera cam = {
        .position = {0, 0, 8}, .target = {0, 0, 0}, .up = {0, 1, 0}, .fov = 45 * M_PI / 180};
    CHECK(pfx_renderer_bench_raw(r, &cam, s, 100, 3) > 0);
    CHECK(pfx_renderer_bench_raw(r, &cam, s, 100, 0) < 0);
    CHECK(memcmp(copy, s, sizeof s) == 0);
    pfx_renderer_destroy(r);
}

/* A square sprite turns with its angle: at 45 degrees the pixel on its
 * diagonal (sprite coordinates (0.5, 0.5) unturned) lies on its axis
 * instead; the falloff (1 - x^2)^2 (1 - y^2)^2 at the pixel's coordinates in
 * the turned frame is known either way. A round sprite looks the same at
 * any angle. */
static void test_square_rotation(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    uint8_t img[W * H * 4];
    pfx_camera cam = ortho_camera(6.5); /* 10 pixels per metre, sprite radius 1 m */
    const double ppm = H / 6.5;
    /* The pixel whose centre is nearest (0.5, 0.5) m from the sprite centre. */
    int dx = (int)lround(0.5 * ppm);
    double x = dx / ppm, y = dx / ppm; /* its true offset, metres = sprite units */
    for (int turned = 0; turned < 2; turned++) {
        double ang = turned ? M_PI / 4 : 0;
        pfx_sprite s = {0, 0, 0, 2, 1, 1, 1, 1, (float)ang, PFX_SPRITE_SQUARE};
        if (!draw(r, &cam, transparent, &s, 1, false, img))
            break;
        /* The pixel's coordinates in the sprite's own (turned) frame. */
        double u = cos(ang) * x + sin(ang) * y, v = -sin(ang) * x + cos(ang) * y;
        double f = (1 - u * u) * (1 - u * u) * (1 - v * v) * (1 - v * v);
        const uint8_t *p = px(img, W, MID + dx, MID - dx);
        CHECK_NEAR(p[3], 255 * f, 2);
    }
    pfx_sprite round = {0, 0, 0, 2, 1, 1, 1, 1, 0, PFX_SPRITE_ROUND};
    uint8_t a[W * H * 4];
    if (draw(r, &cam, transparent, &round, 1, false, a)) {
        round.angle = 1.0f;
        if (draw(r, &cam, transparent, &round, 1, false, img)) {
            /* The turned quad rasterises the same disc: equal up to the
             * interpolation's last bit. Compared premultiplied (colour x
             * alpha), as straight colour is arbitrary where alpha is ~0. */
            int worst = 0;
            for (size_t k = 0; k < sizeof img; k += 4)
                for (int ch = 0; ch < 4; ch++) {
                    int pa = ch == 3 ? a[k + 3] : a[k + ch] * a[k + 3] / 255;
                    int pb = ch == 3 ? img[k + 3] : img[k + ch] * img[k + 3] / 255;
                    worst = abs(pa - pb) > worst ? abs(pa - pb) : worst;
                }
            CHECK(worst <= 1);
        }
    }
    pfx_renderer_destroy(r);
}

/* Materials naming the same pixels (as the compiler gives every emitter
 * naming one file) share one GL texture: three materials on two images and
 * a normal map hold three textures, and a sprite drawn through the shared
 * texture is the known colour (a white texel tinted green), through either
 * material. Setting the materials again frees them and counts afresh. */
static void test_shared_textures(void) {
    pfx_renderer *r = make(W, H);
    if (!r)
        return;
    uint8_t white[4 * 4 * 4], red[4 * 4 * 4], flat[4 * 4 * 4];
    for (int i = 0; i < 16; i++) {
        memcpy(white + 4 * i, (uint8_t[4]){255, 255, 255, 255}, 4);
        memcpy(red + 4 * i, (uint8_t[4]){255, 0, 0, 255}, 4);
        memcpy(flat + 4 * i, (uint8_t[4]){128, 128, 255, 255}, 4);
    }
    const pfx_image a = {"a.png", "a.png", 4, 4, 8, white},
                    a2 = {"./a.png", "./a.png", 4, 4, 8, white},
                    b = {"b.png", "b.png", 4, 4, 8, red}, n = {"n.png", "n.png", 4, 4, 8, flat};
    pfx_material m[5] = {{.texture = &a},
                         {.texture = &a2},
                         {.texture = &b},
                         {0},
                         {.texture = &a2, .normal_map = &n, .lit = true}};
    for (int i = 0; i < 5; i++)
        m[i].cols = m[i].rows = m[i].frames = 1;
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    CHECK(pfx_renderer_set_materials(r, m, 5, &d));
    CHECK(pfx_renderer_texture_count(r) == 3);
    uint8_t img[2][W * H * 4];
    pfx_camera cam = ortho_camera(6.5);
    for (int k = 0; k < 2; k++) {
        pfx_sprite s = {0, 0, 0, 2, 0, 1, 0, 1, 0, (float)k};
        if (draw(r, &cam, transparent, &s, 1, false, img[k]))
            check_pixel(px(img[k], W, MID, MID), (int[4]){0, 255, 0, 255}, 2);
    }
    CHECK(memcmp(img[0], img[1], sizeof img[0]) == 0);
    CHECK(pfx_renderer_set_materials(r, m + 2, 1, &d));
    CHECK(pfx_renderer_texture_count(r) == 1);
    pfx_diags_free(&d);
    pfx_renderer_destroy(r);
}

int main(void) {
    const char *env = getenv("PFX_RENDERER");
    if (env && !pfx_renderer_kind_parse(env, &kind)) {
        fprintf(stderr, "PFX_RENDERER: no renderer '%s'\n", env);
        return 1;
    }
    fprintf(stderr, "renderer %s\n", pfx_renderer_kind_name(kind));
    RUN(test_kinds);
    RUN(test_square_rotation);
    RUN(test_additive_overlap_sums);
    RUN(test_alpha_order);
    RUN(test_sort_ties_keep_order);
    RUN(test_sort_is_stable_back_to_front);
    RUN(test_sort_batches_match_one_sort);
    RUN(test_sort_batches_draw_the_same);
    RUN(test_falloff);
    RUN(test_orientation);
    RUN(test_backgrounds);
    RUN(test_perspective_size);
    RUN(test_determinism);
    RUN(test_chunks);
    RUN(test_osmesa_equals_egl_cpu);
    RUN(test_shared_textures);
    RUN(test_errors);
    RUN(test_bench_raw);
    return TEST_EXIT();
}
