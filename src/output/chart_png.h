/* The work-precision charts as PNG: a small rasteriser of the same chart
 * geometry as output/svg_chart.h (frame, decade grid, lines, markers),
 * written through output/png_write.h. No text: the SVG beside it carries
 * the titles and labels. No Debian library fits better: librsvg would
 * render the SVG but pulls in GLib, Cairo and Pango for a chart. */
#ifndef PFX_CHART_PNG_H
#define PFX_CHART_PNG_H

#include <stdbool.h>

#include "base/diag.h"
#include "output/svg_chart.h"

typedef struct pfx_chart_png pfx_chart_png;

/* A white width x height canvas; NULL when out of memory. Free with
 * pfx_chart_png_destroy. */
pfx_chart_png *pfx_chart_png_create(int width, int height);
void pfx_chart_png_destroy(pfx_chart_png *p);
/* The frame of c's plot area and its grid (decades on log axes). */
void pfx_chart_png_axes(pfx_chart_png *p, const pfx_chart *c);
/* A line between two data points, 2 px wide, rgb 0xRRGGBB. */
void pfx_chart_png_line(pfx_chart_png *p, const pfx_chart *c, double xa, double ya, double xb,
                        double yb, unsigned rgb, bool dashed);
void pfx_chart_png_mark(pfx_chart_png *p, const pfx_chart *c, double x, double y, pfx_mark mark,
                        unsigned rgb);
/* Writes the canvas as an 8-bit RGBA PNG, whole or absent. */
bool pfx_chart_png_write(const pfx_chart_png *p, const char *path, pfx_diags *d);

#endif
