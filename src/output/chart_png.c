/* The rasteriser of output/chart_png.h: lines as runs of 2x2 dots along
 * their longer axis (a DDA), markers from their shapes' equations. Pixels
 * are set, not blended: charts are a few hundred strokes. */
#include "output/chart_png.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "output/png_write.h"

struct pfx_chart_png {
    int width, height;
    uint8_t *rgba;
};

pfx_chart_png *pfx_chart_png_create(int width, int height) {
    pfx_chart_png *p = malloc(sizeof *p);
    if (!p)
        return NULL;
    p->width = width;
    p->height = height;
    p->rgba = malloc((size_t)width * (size_t)height * 4);
    if (!p->rgba) {
        free(p);
        return NULL;
    }
    for (size_t i = 0; i < (size_t)width * (size_t)height * 4; i++)
        p->rgba[i] = 255;
    return p;
}

void pfx_chart_png_destroy(pfx_chart_png *p) {
    if (p)
        free(p->rgba);
    free(p);
}

static void dot(pfx_chart_png *p, int x, int y, unsigned rgb) {
    if (x < 0 || y < 0 || x >= p->width || y >= p->height)
        return;
    uint8_t *q = p->rgba + 4 * ((size_t)y * (size_t)p->width + (size_t)x);
    q[0] = (uint8_t)(rgb >> 16);
    q[1] = (uint8_t)(rgb >> 8);
    q[2] = (uint8_t)rgb;
    q[3] = 255;
}

/* A line in pixels, `w` pixels wide; dashed: 6 on, 4 off. */
static void segment(pfx_chart_png *p, double xa, double ya, double xb, double yb, int w,
                    unsigned rgb, bool dashed) {
    double dx = xb - xa, dy = yb - ya;
    int n = (int)ceil(fmax(fabs(dx), fabs(dy)));
    for (int i = 0; i <= n; i++) {
        if (dashed && i % 10 >= 6)
            continue;
        double t = n ? (double)i / n : 0;
        int x = (int)lround(xa + t * dx), y = (int)lround(ya + t * dy);
        for (int a = 0; a < w; a++)
            for (int b = 0; b < w; b++)
                dot(p, x + a, y + b, rgb);
    }
}

void pfx_chart_png_axes(pfx_chart_png *p, const pfx_chart *c) {
    double l = c->left, t = c->top, r = c->left + c->width, b = c->top + c->height;
    /* Grid: a light line at every decade (log axes) inside the frame. */
    if (c->log_x)
        for (double v = c->x0 * 10; v < c->x1 * 0.999; v *= 10)
            segment(p, pfx_chart_px(c, v), t, pfx_chart_px(c, v), b, 1, 0xdddddd, false);
    if (c->log_y)
        for (double v = c->y0 * 10; v < c->y1 * 0.999; v *= 10)
            segment(p, l, pfx_chart_py(c, v), r, pfx_chart_py(c, v), 1, 0xdddddd, false);
    segment(p, l, t, r, t, 1, 0x000000, false);
    segment(p, l, b, r, b, 1, 0x000000, false);
    segment(p, l, t, l, b, 1, 0x000000, false);
    segment(p, r, t, r, b, 1, 0x000000, false);
}

void pfx_chart_png_line(pfx_chart_png *p, const pfx_chart *c, double xa, double ya, double xb,
                        double yb, unsigned rgb, bool dashed) {
    segment(p, pfx_chart_px(c, xa), pfx_chart_py(c, ya), pfx_chart_px(c, xb), pfx_chart_py(c, yb),
            2, rgb, dashed);
}

void pfx_chart_png_mark(pfx_chart_png *p, const pfx_chart *c, double x, double y, pfx_mark mark,
                        unsigned rgb) {
    int cx = (int)lround(pfx_chart_px(c, x)), cy = (int)lround(pfx_chart_py(c, y));
    for (int a = -5; a <= 5; a++)
        for (int b = -5; b <= 5; b++) {
            bool on = mark == PFX_MARK_DOT ? a * a + b * b <= 16
                      : mark == PFX_MARK_CROSS
                          ? abs(abs(a) - abs(b)) <= 0
                          : abs(a) == 5 || abs(b) == 5 || abs(a) == 4 || abs(b) == 4;
            if (on)
                dot(p, cx + a, cy + b, rgb);
        }
}

bool pfx_chart_png_write(const pfx_chart_png *p, const char *path, pfx_diags *d) {
    return pfx_png_write(path, p->rgba, p->width, p->height, d);
}
