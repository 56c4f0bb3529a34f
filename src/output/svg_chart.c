/* Hand-written SVG for the accuracy charts: axes with decade ticks on log
 * scales, polylines, markers, bars, escaped text. No layout engine: callers
 * place panels in pixels. */
#include "output/svg_chart.h"

#include <math.h>

void pfx_svg_begin(FILE *f, int width, int height) {
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
            "viewBox=\"0 0 %d %d\" font-family=\"DejaVu Sans, Arial, sans-serif\">\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
            width, height, width, height);
}

void pfx_svg_end(FILE *f) { fputs("</svg>\n", f); }

void pfx_svg_text(FILE *f, double x, double y, double size, const char *anchor, const char *color,
                  const char *text) {
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"%.1f\" text-anchor=\"%s\" fill=\"%s\">", x,
            y, size, anchor, color);
    for (const char *p = text; *p; p++) {
        if (*p == '<')
            fputs("&lt;", f);
        else if (*p == '>')
            fputs("&gt;", f);
        else if (*p == '&')
            fputs("&amp;", f);
        else
            fputc(*p, f);
    }
    fputs("</text>\n", f);
}

static double frac(double v, double a, double b, bool lg) {
    if (lg)
        return (log10(v) - log10(a)) / (log10(b) - log10(a));
    return (v - a) / (b - a);
}

double pfx_chart_px(const pfx_chart *c, double x) {
    double t = frac(x, c->x0, c->x1, c->log_x);
    t = t < 0 || t != t ? 0 : t > 1 ? 1 : t;
    return c->left + t * c->width;
}

double pfx_chart_py(const pfx_chart *c, double y) {
    double t = frac(y, c->y0, c->y1, c->log_y);
    t = t < 0 || t != t ? 0 : t > 1 ? 1 : t;
    return c->top + (1 - t) * c->height;
}

/* Tick values: every decade on a log axis, else about 5 round steps. */
static int ticks(double a, double b, bool lg, double *out, int cap) {
    int n = 0;
    if (lg) {
        int step = (int)ceil((log10(b) - log10(a)) / 8); /* at most ~8 labels */
        step = step < 1 ? 1 : step;
        for (int e = (int)ceil(log10(a) - 1e-9); e <= (int)floor(log10(b) + 1e-9) && n < cap;
             e += step)
            out[n++] = pow(10, e);
        return n;
    }
    double raw = (b - a) / 5, mag = pow(10, floor(log10(raw))), st = mag;
    if (raw / mag > 5)
        st = 10 * mag;
    else if (raw / mag > 2)
        st = 5 * mag;
    else if (raw / mag > 1)
        st = 2 * mag;
    for (double v = ceil(a / st) * st; v <= b + 1e-9 * st && n < cap; v += st)
        out[n++] = fabs(v) < 1e-12 * st ? 0 : v;
    return n;
}

static void tick_label(double v, bool lg, char *buf, size_t size) {
    if (lg)
        snprintf(buf, size, "1e%d", (int)lround(log10(v)));
    else
        snprintf(buf, size, "%g", v);
}

void pfx_chart_axes(FILE *f, const pfx_chart *c, const char *title, const char *x_title,
                    const char *y_title) {
    double t[32];
    char buf[32];
    int n = ticks(c->x0, c->x1, c->log_x, t, 32);
    for (int i = 0; i < n; i++) {
        double x = pfx_chart_px(c, t[i]);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n",
                x, c->top, x, c->top + c->height);
        tick_label(t[i], c->log_x, buf, sizeof buf);
        pfx_svg_text(f, x, c->top + c->height + 14, 10, "middle", "#333", buf);
    }
    n = c->no_y_ticks ? 0 : ticks(c->y0, c->y1, c->log_y, t, 32);
    for (int i = 0; i < n; i++) {
        double y = pfx_chart_py(c, t[i]);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n",
                c->left, y, c->left + c->width, y);
        tick_label(t[i], c->log_y, buf, sizeof buf);
        pfx_svg_text(f, c->left - 4, y + 3.5, 10, "end", "#333", buf);
    }
    fprintf(f,
            "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
            "stroke=\"#555\"/>\n",
            c->left, c->top, c->width, c->height);
    if (title)
        pfx_svg_text(f, c->left + c->width / 2, c->top - 8, 13, "middle", "#000", title);
    if (x_title)
        pfx_svg_text(f, c->left + c->width / 2, c->top + c->height + 30, 11, "middle", "#333",
                     x_title);
    if (y_title) {
        double x = c->left - 44, y = c->top + c->height / 2;
        fprintf(f, "<g transform=\"rotate(-90 %.1f %.1f)\">\n", x, y);
        pfx_svg_text(f, x, y, 11, "middle", "#333", y_title);
        fputs("</g>\n", f);
    }
}

void pfx_chart_line(FILE *f, const pfx_chart *c, int n, const double *x, const double *y,
                    const bool *skip, const char *color, bool dashed) {
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.8\"%s points=\"", color,
            dashed ? " stroke-dasharray=\"5 3\"" : "");
    for (int i = 0; i < n; i++)
        if (!skip || !skip[i])
            fprintf(f, "%.1f,%.1f ", pfx_chart_px(c, x[i]), pfx_chart_py(c, y[i]));
    fputs("\"/>\n", f);
}

/* Marker `mark` centred at (px, py) in SVG pixels. */
static void mark_at(FILE *f, double px, double py, pfx_mark mark, const char *color) {
    if (mark == PFX_MARK_TRIANGLE)
        fprintf(f, "<path d=\"M%.1f %.1fl4 7h-8z\" fill=\"%s\"/>\n", px, py - 4, color);
    else if (mark == PFX_MARK_DIAMOND)
        fprintf(f, "<path d=\"M%.1f %.1fl4 4l-4 4l-4 -4z\" fill=\"%s\"/>\n", px, py - 4, color);
    else if (mark == PFX_MARK_RING)
        fprintf(f,
                "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4.5\" fill=\"none\" stroke=\"%s\" "
                "stroke-width=\"1.5\"/>\n",
                px, py, color);
    else if (mark == PFX_MARK_PLUS)
        fprintf(f, "<path d=\"M%.1f %.1fh10m-5 -5v10\" stroke=\"%s\" stroke-width=\"1.8\"/>\n",
                px - 5, py, color);
    else if (mark == PFX_MARK_DOT)
        fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"2.6\" fill=\"%s\"/>\n", px, py, color);
    else if (mark == PFX_MARK_SQUARE)
        fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"6\" height=\"6\" fill=\"%s\"/>\n", px - 3,
                py - 3, color);
    else
        fprintf(f, "<path d=\"M%.1f %.1fl8 8m0 -8l-8 8\" stroke=\"%s\" stroke-width=\"2.2\"/>\n",
                px - 4, py - 4, color);
}

void pfx_chart_mark(FILE *f, const pfx_chart *c, double x, double y, pfx_mark mark,
                    const char *color) {
    mark_at(f, pfx_chart_px(c, x), pfx_chart_py(c, y), mark, color);
}

void pfx_chart_segment(FILE *f, const pfx_chart *c, double xa, double ya, double xb, double yb,
                       const char *color, bool dashed) {
    fprintf(f,
            "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
            "stroke-width=\"1.2\"%s/>\n",
            pfx_chart_px(c, xa), pfx_chart_py(c, ya), pfx_chart_px(c, xb), pfx_chart_py(c, yb),
            color, dashed ? " stroke-dasharray=\"6 4\"" : "");
}

void pfx_chart_rect(FILE *f, const pfx_chart *c, double xa, double ya, double xb, double yb,
                    const char *color) {
    double x0 = pfx_chart_px(c, xa), x1 = pfx_chart_px(c, xb);
    double y0 = pfx_chart_py(c, ya), y1 = pfx_chart_py(c, yb);
    fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"%s\"/>\n",
            fmin(x0, x1), fmin(y0, y1), fabs(x1 - x0), fabs(y1 - y0), color);
}

void pfx_svg_legend(FILE *f, double x, double y, int n, const char *const *labels,
                    const char *const *colors) {
    pfx_svg_legend_marked(f, x, y, n, labels, colors, NULL);
}

void pfx_svg_legend_marked(FILE *f, double x, double y, int n, const char *const *labels,
                           const char *const *colors, const pfx_mark *marks) {
    for (int i = 0; i < n; i++) {
        double yy = y + 16 * i;
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
                "stroke-width=\"3\"/>\n",
                x, yy, x + 22, yy, colors[i]);
        if (marks)
            mark_at(f, x + 11, yy, marks[i], colors[i]);
        pfx_svg_text(f, x + 28, yy + 4, 11, "start", "#000", labels[i]);
    }
}
