/* A small hand-written SVG chart vocabulary: panels with linear or log
 * axes, polylines, markers, bars, text and a legend. Enough for the
 * accuracy charts; not a plotting library. Writes straight to a FILE. */
#ifndef PFX_SVG_CHART_H
#define PFX_SVG_CHART_H

#include <stdbool.h>
#include <stdio.h>

/* A panel: the plot rectangle in SVG pixels and the data range it shows. */
typedef struct pfx_chart {
    double left, top, width, height; /* plot area, px */
    double x0, x1, y0, y1;           /* data range */
    bool log_x, log_y;               /* base-10 axes (ranges must be > 0) */
    bool no_y_ticks;                 /* categories on y: the caller labels them */
} pfx_chart;

/* (new kinds are added at the end: callers may store these) */
typedef enum {
    PFX_MARK_DOT,
    PFX_MARK_CROSS,
    PFX_MARK_SQUARE,
    PFX_MARK_TRIANGLE,
    PFX_MARK_DIAMOND,
    PFX_MARK_RING, /* an open circle: shows what lies under it */
    PFX_MARK_PLUS
} pfx_mark;

void pfx_svg_begin(FILE *f, int width, int height);
void pfx_svg_end(FILE *f);
/* anchor: "start", "middle" or "end"; text is escaped. */
void pfx_svg_text(FILE *f, double x, double y, double size, const char *anchor, const char *color,
                  const char *text);
/* Frame, grid, ticks (decades on log axes) and the axis titles. */
void pfx_chart_axes(FILE *f, const pfx_chart *c, const char *title, const char *x_title,
                    const char *y_title);
/* Data -> px; values outside the range are clamped to the frame. */
double pfx_chart_px(const pfx_chart *c, double x);
double pfx_chart_py(const pfx_chart *c, double y);
/* A polyline through the points whose `skip` is false (NULL: all). */
void pfx_chart_line(FILE *f, const pfx_chart *c, int n, const double *x, const double *y,
                    const bool *skip, const char *color, bool dashed);
void pfx_chart_mark(FILE *f, const pfx_chart *c, double x, double y, pfx_mark mark,
                    const char *color);
/* A rectangle in data coordinates (bars). */
void pfx_chart_rect(FILE *f, const pfx_chart *c, double xa, double ya, double xb, double yb,
                    const char *color);
/* Legend entries in a column from (x, y) px. */
void pfx_svg_legend(FILE *f, double x, double y, int n, const char *const *labels,
                    const char *const *colors);
/* The same with each entry's marker drawn on its line (marks may be NULL:
 * none). */
void pfx_svg_legend_marked(FILE *f, double x, double y, int n, const char *const *labels,
                           const char *const *colors, const pfx_mark *marks);
/* A straight segment between two data points, clipped to nothing (the
 * caller keeps it in range): reference lines. dashed as pfx_chart_line. */
void pfx_chart_segment(FILE *f, const pfx_chart *c, double xa, double ya, double xb, double yb,
                       const char *color, bool dashed);

#endif
