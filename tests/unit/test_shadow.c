/* The opacity shadow map (render/shadow.c) against exact answers: the
 * light's frame is orthonormal with the light along axis 2; a caster's
 * splat holds its whole optical depth a pi r^2 / 3 however many cells it
 * covers; the summed slices give each cell the depth of every slice before
 * it and half its own; the texture map sends the grid's corners to 0 and 1. */
#include "render/shadow.h"

#include <math.h>
#include <stdlib.h>

#include "test.h"

#define PI 3.14159265358979323846
#define LAYER (PFX_SHADOW_SIDE * PFX_SHADOW_SIDE)

static double dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void test_frame(void) {
    static pfx_shadow_volume v;
    const double dirs[3][3] = {{1, 0, 0}, {0, -1, 0}, {0.6, 0, 0.8}};
    for (int k = 0; k < 3; k++) {
        pfx_shadow_begin(&v, dirs[k]);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                CHECK_NEAR(dot3(v.axis[a], v.axis[b]), a == b, 1e-12);
        for (int a = 0; a < 3; a++)
            CHECK_NEAR(v.axis[2][a], dirs[k][a], 0);
    }
}

/* The depth a splat left in its slice, times the cell area: its total. */
static double slice_total(const pfx_shadow_volume *v, int slice) {
    double sum = 0;
    for (int c = 0; c < LAYER; c++)
        sum += v->depth[(size_t)slice * LAYER + c];
    return sum * (v->hi[0] - v->lo[0]) / PFX_SHADOW_SIDE * (v->hi[1] - v->lo[1]) / PFX_SHADOW_SIDE;
}

static void test_splat_keeps_the_total(void) {
    static pfx_shadow_volume v;
    const double down[3] = {0, -1, 0};
    /* A 2 m box of bounds: cells of 2 / 62 m. Radii from far below a cell
     * to a third of the grid. */
    const float radii[4] = {0.001f, 0.02f, 0.1f, 0.6f};
    for (int k = 0; k < 4; k++) {
        pfx_shadow_begin(&v, down);
        pfx_shadow_bound(&v, (const float[3]){-1, -1, -1}, 0);
        pfx_shadow_bound(&v, (const float[3]){1, 1, 1}, 0);
        pfx_shadow_frame(&v);
        const float r = radii[k], a = 0.7f;
        pfx_shadow_splat(&v, (const float[3]){0.013f, 0.0f, -0.21f}, r, a);
        const double want = a * PI * r * r / 3;
        int slice = -1;
        for (int s = 0; s < PFX_SHADOW_SLICES; s++)
            if (slice_total(&v, s) > 0)
                slice = s;
        CHECK(slice >= 0);
        CHECK_NEAR(slice_total(&v, slice), want, 1e-5 * want);
    }
}

static void test_slices_sum_towards_the_light(void) {
    static pfx_shadow_volume v;
    const double along_x[3] = {1, 0, 0};
    pfx_shadow_begin(&v, along_x);
    /* Two casters on the light's line through the origin, x = -1 (nearer
     * the light, which travels +x) and x = +1. */
    const float front[3] = {-1, 0, 0}, back[3] = {1, 0, 0};
    pfx_shadow_bound(&v, front, 0.5f);
    pfx_shadow_bound(&v, back, 0.5f);
    pfx_shadow_frame(&v);
    pfx_shadow_splat(&v, front, 0.5f, 0.8f);
    pfx_shadow_splat(&v, back, 0.5f, 0.4f);
    /* The centre cells across the light before summing: each caster's peak. */
    int f = -1, b = -1;
    size_t centre = 0;
    float peak_f = 0, peak_b = 0;
    for (int s = 0; s < PFX_SHADOW_SLICES; s++)
        for (size_t c = 0; c < LAYER; c++) {
            float d = v.depth[(size_t)s * LAYER + c];
            if (d > 0 && f < 0)
                f = s;
            if (d > 0)
                b = s;
        }
    CHECK(f >= 0 && b > f);
    for (size_t c = 0; c < LAYER; c++)
        if (v.depth[(size_t)f * LAYER + c] > peak_f)
            peak_f = v.depth[(size_t)f * LAYER + c], centre = c;
    peak_b = v.depth[(size_t)b * LAYER + centre];
    /* Peaks near alpha x f(0) = alpha (the cell centres sit off the disc's). */
    CHECK_NEAR(peak_f, 0.8, 0.03);
    CHECK_NEAR(peak_b, 0.4, 0.015);
    pfx_shadow_finish(&v);
    CHECK_NEAR(v.depth[(size_t)f * LAYER + centre], 0.5 * peak_f, 1e-6);
    CHECK_NEAR(v.depth[(size_t)(f + 1) * LAYER + centre], peak_f, 1e-6);
    CHECK_NEAR(v.depth[(size_t)b * LAYER + centre], peak_f + 0.5 * peak_b, 1e-6);
    CHECK_NEAR(v.depth[(size_t)(PFX_SHADOW_SLICES - 1) * LAYER + centre], peak_f + peak_b, 1e-6);
    CHECK_NEAR(v.depth[0], 0, 0); /* a margin corner: never a caster */
}

static void test_texture_matrix(void) {
    static pfx_shadow_volume v;
    const double dir[3] = {0.6, 0, 0.8};
    pfx_shadow_begin(&v, dir);
    pfx_shadow_bound(&v, (const float[3]){-2, 1, 3}, 0.25f);
    pfx_shadow_bound(&v, (const float[3]){4, -1, 0}, 0.5f);
    pfx_shadow_frame(&v);
    double m[16];
    pfx_shadow_texture_matrix(&v, m);
    /* The world point at lo (and at hi) on every axis: sum of lo[a] axis[a]. */
    for (int end = 0; end < 2; end++) {
        double p[3] = {0, 0, 0};
        for (int a = 0; a < 3; a++)
            for (int k = 0; k < 3; k++)
                p[k] += (end ? v.hi[a] : v.lo[a]) * v.axis[a][k];
        for (int row = 0; row < 3; row++) {
            double t = m[12 + row];
            for (int k = 0; k < 3; k++)
                t += m[k * 4 + row] * p[k];
            CHECK_NEAR(t, end, 1e-12);
        }
    }
}

int main(void) {
    RUN(test_frame);
    RUN(test_splat_keeps_the_total);
    RUN(test_slices_sum_towards_the_light);
    RUN(test_texture_matrix);
    return TEST_EXIT();
}
