/* The screen box a frame's sprites and ribbons can touch
 * (render_internal.h): only it is cleared, read back and converted. */
#include "render/render_internal.h"

#include <math.h>

pfx_bounds pfx_bounds_empty(void) {
    return (pfx_bounds){{INFINITY, INFINITY}, {-INFINITY, -INFINITY}, false};
}

void pfx_bounds_merge(pfx_bounds *b, const pfx_bounds *part) {
    for (int a = 0; a < 2; a++) {
        b->lo[a] = part->lo[a] < b->lo[a] ? part->lo[a] : b->lo[a];
        b->hi[a] = part->hi[a] > b->hi[a] ? part->hi[a] : b->hi[a];
    }
    b->full = b->full || part->full;
}

void pfx_bounds_scissor(pfx_renderer *r, const pfx_bounds *b) {
    const pixel_box box = pfx_bounds_box(r, b);
    r->gl.Enable(GL_SCISSOR_TEST);
    r->gl.Scissor(box.x0, box.y0, box.x1 - box.x0, box.y1 - box.y0);
}

static void bounds_widen(pfx_bounds *b, double x, double y) {
    b->lo[0] = x < b->lo[0] ? x : b->lo[0];
    b->hi[0] = x > b->hi[0] ? x : b->hi[0];
    b->lo[1] = y < b->lo[1] ? y : b->lo[1];
    b->hi[1] = y > b->hi[1] ? y : b->hi[1];
}

/* Ribbon corners are final world points: each projects as it is. */
void pfx_bounds_ribbons(const pfx_view *v, pfx_ribbons ribbons, pfx_bounds *b) {
    const double *m = v->m, *p = v->proj;
    for (size_t i = 0; i < ribbons.count && !b->full; i++) {
        const pfx_ribbon_vertex *q = &ribbons.v[i];
        double c[4] = {0, 0, 0, 1}, clip[4];
        for (int row = 0; row < 3; row++)
            c[row] = m[row] * q->x + m[4 + row] * q->y + m[8 + row] * q->z + m[12 + row];
        for (int row = 0; row < 4; row++)
            clip[row] = p[row] * c[0] + p[4 + row] * c[1] + p[8 + row] * c[2] + p[12 + row];
        if (!(clip[3] > 1e-6) || !(fabs(clip[0]) < 1e30) || !(fabs(clip[1]) < 1e30))
            b->full = true;
        else
            bounds_widen(b, clip[0] / clip[3], clip[1] / clip[3]);
    }
}

void pfx_bounds_sprites(const pfx_renderer *r, const pfx_view *v, const pfx_sprite *sp,
                        size_t count, pfx_bounds *b) {
    const double *m = v->m, *p = v->proj;
    for (size_t i = 0; i < count && !b->full; i++) {
        pfx_align align = pfx_render_material_of(r, &sp[i])->m.align;
        if (align == PFX_ALIGN_AXIS || align == PFX_ALIGN_WORLD) {
            b->full = true;
            break;
        }
        double c[3];
        for (int row = 0; row < 3; row++)
            c[row] = m[row] * sp[i].x + m[4 + row] * sp[i].y + m[8 + row] * sp[i].z + m[12 + row];
        double side =
            align == PFX_ALIGN_VELOCITY && sp[i].length > sp[i].size ? sp[i].length : sp[i].size;
        double rad = 0.5 * side * 1.4142136;
        double w = p[3] * c[0] + p[7] * c[1] + p[11] * c[2] + p[15];
        if (!(w > 1e-6) || !(rad < 1e30)) {
            b->full = true;
            break;
        }
        for (int cx = -1; cx <= 1; cx += 2)
            for (int cy = -1; cy <= 1; cy += 2) {
                double x = c[0] + cx * rad, y = c[1] + cy * rad;
                bounds_widen(b, (p[0] * x + p[4] * y + p[8] * c[2] + p[12]) / w,
                             (p[1] * x + p[5] * y + p[9] * c[2] + p[13]) / w);
            }
    }
}

pixel_box pfx_bounds_box(const pfx_renderer *r, const pfx_bounds *bd) {
    if (bd->full)
        return (pixel_box){0, 0, r->width, r->height};
    if (!(bd->lo[0] <= bd->hi[0]))
        return (pixel_box){0, 0, 0, 0}; /* nothing drawn */
    const double margin = 2 + PFX_MIN_FOOTPRINT_PX * 0.7072;
    double size[2] = {r->width, r->height};
    int b[4];
    for (int a = 0; a < 2; a++) {
        double l = floor((bd->lo[a] * 0.5 + 0.5) * size[a] - margin),
               h = ceil((bd->hi[a] * 0.5 + 0.5) * size[a] + margin);
        l = l < 0 ? 0 : l > size[a] ? size[a] : l;
        h = h < 0 ? 0 : h > size[a] ? size[a] : h;
        b[a] = (int)l;
        b[a + 2] = (int)h;
    }
    if (b[2] <= b[0] || b[3] <= b[1])
        return (pixel_box){0, 0, 0, 0};
    return (pixel_box){b[0], b[1], b[2], b[3]};
}
