/* The opacity shadow map of self-shadowing smoke (render/shadow.h): bounds,
 * splats and sums on the CPU in a fixed order. It knows points, radii and
 * alphas, not emitters or GL; render.c uploads the result. */
#include "render/shadow.h"

#include <math.h>
#include <string.h>

static double dot3(const double a[3], const float b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void pfx_shadow_begin(pfx_shadow_volume *v, const double dir[3]) {
    /* axis 2 along the light; axis 0 across it, from whichever world axis
     * is furthest from it; axis 1 = axis 2 x axis 0. */
    double *w = v->axis[2], *x = v->axis[0], *y = v->axis[1];
    memcpy(w, dir, 3 * sizeof *w);
    const double h[3] = {fabs(dir[0]) < 0.6 ? 1 : 0, fabs(dir[0]) < 0.6 ? 0 : 1, 0};
    x[0] = h[1] * w[2] - h[2] * w[1];
    x[1] = h[2] * w[0] - h[0] * w[2];
    x[2] = h[0] * w[1] - h[1] * w[0];
    const double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int a = 0; a < 3; a++)
        x[a] /= len;
    y[0] = w[1] * x[2] - w[2] * x[1];
    y[1] = w[2] * x[0] - w[0] * x[2];
    y[2] = w[0] * x[1] - w[1] * x[0];
    v->empty = true;
}

void pfx_shadow_bound(pfx_shadow_volume *v, const float p[3], float r) {
    for (int a = 0; a < 3; a++) {
        const double c = dot3(v->axis[a], p);
        if (v->empty || c - r < v->lo[a])
            v->lo[a] = c - r;
        if (v->empty || c + r > v->hi[a])
            v->hi[a] = c + r;
    }
    v->empty = false;
}

static const int cells[3] = {PFX_SHADOW_SIDE, PFX_SHADOW_SIDE, PFX_SHADOW_SLICES};

void pfx_shadow_frame(pfx_shadow_volume *v) {
    memset(v->depth, 0, sizeof v->depth);
    if (v->empty)
        return;
    /* One cell of margin each side, so the clamped edge of the texture
     * reads no caster; never thinner than 1 mm. */
    for (int a = 0; a < 3; a++) {
        const double span = fmax(v->hi[a] - v->lo[a], 1e-3), cell = span / (cells[a] - 2);
        v->lo[a] -= cell;
        v->hi[a] = v->lo[a] + cell * cells[a];
    }
}

/* The cell size along axis a. */
static double cell_of(const pfx_shadow_volume *v, int a) {
    return (v->hi[a] - v->lo[a]) / cells[a];
}

void pfx_shadow_splat(pfx_shadow_volume *v, const float p[3], float r, float a) {
    if (v->empty || !(r > 0) || !(a > 0))
        return;
    double c[3], size[3];
    int at[3];
    for (int k = 0; k < 3; k++) {
        size[k] = cell_of(v, k);
        c[k] = (dot3(v->axis[k], p) - v->lo[k]) / size[k]; /* in cells */
        at[k] = (int)floor(c[k]);
        at[k] = at[k] < 0 ? 0 : at[k] >= cells[k] ? cells[k] - 1 : at[k];
    }
    float *slice = v->depth + (size_t)at[2] * PFX_SHADOW_SIDE * PFX_SHADOW_SIDE;
    const double area = size[0] * size[1], total = a * 3.14159265358979323846 * r * r / 3;
    const double rx = r / size[0], ry = r / size[1];
    const int i0 = (int)fmax(0, ceil(c[0] - rx - 0.5)),
              i1 = (int)fmin(cells[0] - 1, floor(c[0] + rx - 0.5));
    const int j0 = (int)fmax(0, ceil(c[1] - ry - 0.5)),
              j1 = (int)fmin(cells[1] - 1, floor(c[1] + ry - 0.5));
    /* First the falloff's sum over the cell centres it covers, then each
     * cell's share of the total. */
    double sum = 0;
    for (int pass = 0; pass < 2; pass++)
        for (int j = j0; j <= j1; j++)
            for (int i = i0; i <= i1; i++) {
                const double dx = (i + 0.5 - c[0]) / rx, dy = (j + 0.5 - c[1]) / ry;
                const double d2 = dx * dx + dy * dy;
                if (d2 >= 1)
                    continue;
                const double f = (1 - d2) * (1 - d2);
                if (pass == 0)
                    sum += f;
                else
                    slice[j * PFX_SHADOW_SIDE + i] += (float)(total * f / (sum * area));
            }
    if (!(sum > 0))
        slice[at[1] * PFX_SHADOW_SIDE + at[0]] += (float)(total / area);
}

void pfx_shadow_finish(pfx_shadow_volume *v) {
    if (v->empty)
        return;
    const size_t n = PFX_SHADOW_SIDE * PFX_SHADOW_SIDE;
    for (size_t c = 0; c < n; c++) {
        float before = 0;
        for (int k = 0; k < PFX_SHADOW_SLICES; k++) {
            float *d = v->depth + (size_t)k * n + c, own = *d;
            *d = before + 0.5f * own;
            before += own;
        }
    }
}

void pfx_shadow_texture_matrix(const pfx_shadow_volume *v, double m[16]) {
    memset(m, 0, 16 * sizeof *m);
    for (int a = 0; a < 3; a++) {
        const double s = 1 / (v->hi[a] - v->lo[a]);
        for (int col = 0; col < 3; col++)
            m[col * 4 + a] = v->axis[a][col] * s;
        m[12 + a] = -v->lo[a] * s;
    }
    m[15] = 1;
}
