/* output/motion_vectors.h: float displacements to 16-bit samples, the
 * sheet, and the JSON that says how to read them back. No PNG here
 * (output/png_write.c encodes the samples). */
#include "output/motion_vectors.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/json_text.h"
#include "output/json_file.h"

/* round(v x 65535) of v clamped to [0, 1]: 0.5 is 32768. */
static uint16_t sample(double v) {
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    return (uint16_t)floor(v * 65535.0 + 0.5);
}

void pfx_mv_encode(const float *mv, int width, int height, const pfx_mv_meta *m, uint16_t *out) {
    const double scale = 1.0 / (2.0 * m->max_px), sy = m->flip_y ? -scale : scale;
    const size_t n = (size_t)width * (size_t)height;
    for (size_t i = 0; i < n; i++, mv += 3, out += 4) {
        out[0] = sample(0.5 + mv[0] * scale);
        out[1] = sample(0.5 + mv[1] * sy);
        out[2] = 0;
        out[3] = sample(mv[2]);
    }
}

static int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

uint16_t *pfx_mv_atlas_compose(const pfx_atlas_layout *l, uint16_t *const *frames) {
    const size_t stride = (size_t)l->width * 4;
    uint16_t *sheet = malloc((size_t)l->height * stride * sizeof *sheet);
    if (!sheet)
        return NULL;
    for (size_t i = 0; i < (size_t)l->height * stride; i += 4) {
        sheet[i] = sheet[i + 1] = 32768;
        sheet[i + 2] = sheet[i + 3] = 0;
    }
    /* Cell pixel (x, y) samples the crop at (x - p, y - p) clamped to its
     * edge, over the frame and its extruded ring: output/atlas.c's rule. */
    const int p = l->padding, e = l->extrude < l->padding ? l->extrude : l->padding;
    for (int k = 0; k < l->frames; k++) {
        int cx = (k % l->columns) * l->cell_w, cy = (k / l->columns) * l->cell_h;
        uint16_t *cell = sheet + (size_t)cy * stride + 4 * (size_t)cx;
        for (int y = p - e; y < p + l->crop_h + e; y++)
            for (int x = p - e; x < p + l->crop_w + e; x++) {
                int sx = l->crop_x + clampi(x - p, 0, l->crop_w - 1);
                int sy = l->crop_y + clampi(y - p, 0, l->crop_h - 1);
                memcpy(cell + (size_t)y * stride + 4 * (size_t)x,
                       frames[k] + ((size_t)sy * l->frame_w + sx) * 4, 4 * sizeof *sheet);
            }
    }
    return sheet;
}

json_t *pfx_mv_json(const pfx_mv_meta *m, const pfx_atlas_layout *l, const char *image) {
    char from[120];
    snprintf(from, sizeof from,
             "the %dth percentile of the covered pixels' displacements in the sequence",
             PFX_MV_PERCENTILE);
    json_t *o = json_pack(
        "{s:s, s:f, s:s, s:s, s:f, s:s, s:s, s:s, s:s, s:b, s:s}", "format", "RGBA16", "max_px",
        m->max_px, "max_from", m->max_given ? "--mv-max" : from, "encoding",
        "value = 0.5 + displacement_px / (2 * max_px), clamped to [0, 1]; 0.5 (32768) "
        "is no motion",
        "interval_s", 1.0 / m->fps, "units",
        "pixels of a frame, to the next frame (atlas cells hold frames unscaled, so also pixels "
        "of a cell)",
        "r", "+x: right", "g", m->flip_y ? "+y: down (image rows, --mv-flip-y)" : "+y: up", "b",
        "0", "flip_y", m->flip_y, "a",
        "coverage: 1 - prod(1 - weight) of the sprites over the pixel");
    if (o && l) {
        /* An engine scales the decoded [-1, 1] by a strength in units of
         * one cell: max_px over the cell's side (padding included, since
         * the engine divides the sheet evenly). */
        json_object_set_new(o, "image", pfx_json_bytes(image));
        json_object_set_new(
            o, "strength_cell",
            json_pack("{s:f, s:f}", "x", m->max_px / l->cell_w, "y", m->max_px / l->cell_h));
    }
    return o;
}

bool pfx_mv_write_sidecar(const char *path, const pfx_mv_meta *m, const char *pattern, long first,
                          long last, pfx_diags *d) {
    json_t *mv = pfx_mv_json(m, NULL, NULL);
    json_t *root =
        mv ? json_pack("{s:s, s:o, s:I, s:I, s:o}", "app", "pfx", "frames", pfx_json_bytes(pattern),
                       "first", (json_int_t)first, "last", (json_int_t)last, "motion_vectors", mv)
           : NULL;
    bool ok = pfx_json_file_write(path, root, d);
    json_decref(root);
    return ok;
}
