/* The sheet of output/atlas.h. Each cell is the (cropped) frame with
 * `padding` pixels on every side: the inner `extrude` of them repeat the
 * frame's edge pixels (clamp-to-edge within the cell, so filtering at the
 * border samples the frame, not its neighbour), the rest are transparent.
 * Then every fully transparent pixel of a cell takes the colour of its
 * visible neighbours (alpha stays 0): up to BLEED_PASSES rings by
 * dilation, the cell's mean visible colour beyond, so that a mip level
 * averaging transparent and visible pixels does not darken towards black.
 * A premultiplied sheet gets no bleed: there a transparent texel's colour
 * is light added to what is behind it, and premultiplied filtering has no
 * halo to hide. */
#include "output/atlas.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/json_text.h"
#include "output/json_file.h"
#include "output/motion_vectors.h"

#define BLEED_PASSES 16

static int next_pow2(int v) {
    int p = 1;
    while (p < v)
        p *= 2;
    return p;
}

bool pfx_atlas_layout_resolve(pfx_atlas_layout *l, pfx_diags *d) {
    if (l->frames < 1) {
        pfx_diag_error(d, PFX_RULE_IMPOSSIBLE_REQUEST, "an atlas needs at least one frame");
        return false;
    }
    if (!l->columns && !l->rows) {
        l->columns = (int)ceil(sqrt((double)l->frames));
        l->rows = (l->frames + l->columns - 1) / l->columns;
    } else if (!l->rows) {
        l->rows = (l->frames + l->columns - 1) / l->columns;
    } else if (!l->columns) {
        l->columns = (l->frames + l->rows - 1) / l->rows;
    }
    if ((long long)l->columns * l->rows < l->frames) {
        pfx_diag_error(d, PFX_RULE_IMPOSSIBLE_REQUEST,
                       "an atlas of %dx%d cells cannot hold %d frames", l->columns, l->rows,
                       l->frames);
        return false;
    }
    if (!l->crop_w) {
        l->crop_x = l->crop_y = 0;
        l->crop_w = l->frame_w;
        l->crop_h = l->frame_h;
    }
    l->cell_w = l->crop_w + 2 * l->padding;
    l->cell_h = l->crop_h + 2 * l->padding;
    long long w = (long long)l->cell_w * l->columns, h = (long long)l->cell_h * l->rows;
    if (w > PFX_ATLAS_MAX_SIDE || h > PFX_ATLAS_MAX_SIDE) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE,
                       "an atlas of %dx%d cells of %dx%d pixels is %lldx%lld, over the %d "
                       "limit; use fewer frames, a smaller --size or --crop",
                       l->columns, l->rows, l->cell_w, l->cell_h, w, h, PFX_ATLAS_MAX_SIDE);
        return false;
    }
    l->used_w = l->width = (int)w;
    l->used_h = l->height = (int)h;
    if (l->pot) { /* 16384 is a power of two: the limit still holds */
        l->width = next_pow2(l->width);
        l->height = next_pow2(l->height);
    }
    return true;
}

void pfx_atlas_find_crop(pfx_atlas_layout *l, uint8_t *const *frames, int n) {
    int x0 = l->frame_w, y0 = l->frame_h, x1 = -1, y1 = -1;
    for (int k = 0; k < n; k++)
        for (int y = 0; y < l->frame_h; y++) {
            const uint8_t *row = frames[k] + (size_t)y * l->frame_w * 4;
            for (int x = 0; x < l->frame_w; x++)
                if (row[4 * x + 3]) {
                    x0 = x < x0 ? x : x0;
                    x1 = x > x1 ? x : x1;
                    y0 = y < y0 ? y : y0;
                    y1 = y > y1 ? y : y1;
                }
        }
    if (x1 < 0) {
        x0 = y0 = 0;
        x1 = l->frame_w - 1;
        y1 = l->frame_h - 1;
    }
    l->crop_x = x0;
    l->crop_y = y0;
    l->crop_w = x1 - x0 + 1;
    l->crop_h = y1 - y0 + 1;
}

static int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

/* Fills the cell's transparent pixels with colour (see the file comment).
 * `known` is scratch of cell_w x cell_h bytes. */
static void bleed(uint8_t *sheet, int stride, int cw, int ch, uint8_t *known) {
    double sum[3] = {0, 0, 0};
    long visible = 0;
    for (int y = 0; y < ch; y++)
        for (int x = 0; x < cw; x++) {
            const uint8_t *p = sheet + (size_t)y * stride + 4 * (size_t)x;
            known[y * cw + x] = p[3] != 0;
            if (p[3]) {
                sum[0] += p[0], sum[1] += p[1], sum[2] += p[2];
                visible++;
            }
        }
    if (!visible)
        return; /* nothing to bleed: the cell stays transparent black */
    for (int pass = 0; pass < BLEED_PASSES; pass++) {
        bool changed = false;
        for (int y = 0; y < ch; y++)
            for (int x = 0; x < cw; x++) {
                if (known[y * cw + x])
                    continue;
                int acc[3] = {0, 0, 0}, n = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int nx = x + dx, ny = y + dy;
                        if (nx < 0 || ny < 0 || nx >= cw || ny >= ch || known[ny * cw + nx] != 1)
                            continue;
                        const uint8_t *q = sheet + (size_t)ny * stride + 4 * (size_t)nx;
                        acc[0] += q[0], acc[1] += q[1], acc[2] += q[2];
                        n++;
                    }
                if (n) {
                    uint8_t *p = sheet + (size_t)y * stride + 4 * (size_t)x;
                    for (int c = 0; c < 3; c++)
                        p[c] = (uint8_t)((acc[c] + n / 2) / n);
                    known[y * cw + x] = 2; /* filled this pass; a source from the next */
                    changed = true;
                }
            }
        for (int i = 0; i < cw * ch; i++)
            known[i] = known[i] ? 1 : 0;
        if (!changed)
            return;
    }
    for (int y = 0; y < ch; y++)
        for (int x = 0; x < cw; x++)
            if (!known[y * cw + x]) {
                uint8_t *p = sheet + (size_t)y * stride + 4 * (size_t)x;
                for (int c = 0; c < 3; c++)
                    p[c] = (uint8_t)(sum[c] / (double)visible + 0.5);
            }
}

uint8_t *pfx_atlas_compose(const pfx_atlas_layout *l, uint8_t *const *frames) {
    size_t stride = (size_t)l->width * 4;
    uint8_t *sheet = calloc((size_t)l->height, stride);
    uint8_t *known = malloc((size_t)l->cell_w * l->cell_h);
    if (!sheet || !known) {
        free(sheet);
        free(known);
        return NULL;
    }
    const int p = l->padding, e = l->extrude < l->padding ? l->extrude : l->padding;
    for (int k = 0; k < l->frames; k++) {
        int cx = (k % l->columns) * l->cell_w, cy = (k / l->columns) * l->cell_h;
        uint8_t *cell = sheet + (size_t)cy * stride + 4 * (size_t)cx;
        /* The frame and its extruded ring: cell pixel (x, y) samples the
         * crop at (x - p, y - p) clamped to its edge. */
        for (int y = p - e; y < p + l->crop_h + e; y++)
            for (int x = p - e; x < p + l->crop_w + e; x++) {
                int sx = l->crop_x + clampi(x - p, 0, l->crop_w - 1);
                int sy = l->crop_y + clampi(y - p, 0, l->crop_h - 1);
                memcpy(cell + (size_t)y * stride + 4 * (size_t)x,
                       frames[k] + ((size_t)sy * l->frame_w + sx) * 4, 4);
            }
        if (!l->premultiplied)
            bleed(cell, (int)stride, l->cell_w, l->cell_h, known);
    }
    free(known);
    return sheet;
}

static json_t *rect(int x, int y, int w, int h) {
    return json_pack("{s:i, s:i, s:i, s:i}", "x", x, "y", y, "w", w, "h", h);
}

/* The fractions of the sheet a pixel rectangle covers, top left origin
 * (as the pixel rectangles; an engine with V up takes 1 - y - h). */
static json_t *uv_rect(const pfx_atlas_layout *l, int x, int y, int w, int h) {
    return json_pack("{s:f, s:f, s:f, s:f}", "x", (double)x / l->width, "y", (double)y / l->height,
                     "w", (double)w / l->width, "h", (double)h / l->height);
}

/* TexturePacker's entry for frame k (without the name). */
static json_t *frame_entry(const pfx_atlas_layout *l, int k) {
    int x = (k % l->columns) * l->cell_w + l->padding;
    int y = (k / l->columns) * l->cell_h + l->padding;
    return json_pack("{s:o, s:b, s:b, s:o, s:{s:i, s:i}, s:o}", "frame",
                     rect(x, y, l->crop_w, l->crop_h), "rotated", 0, "trimmed", l->crop,
                     "spriteSourceSize", rect(l->crop_x, l->crop_y, l->crop_w, l->crop_h),
                     "sourceSize", "w", l->frame_w, "h", l->frame_h, "uv",
                     uv_rect(l, x, y, l->crop_w, l->crop_h));
}

bool pfx_atlas_write_json(pfx_atomic_group *g, const char *path, const pfx_atlas_layout *l,
                          const char *image, const char *const *names, double fps, bool loop,
                          pfx_diags *d) {
    json_t *frames = l->json_array ? json_array() : json_object();
    for (int k = 0; k < l->frames; k++) {
        json_t *entry = frame_entry(l, k);
        if (l->json_array) {
            json_object_set_new(entry, "filename", json_string_nocheck(names[k]));
            json_array_append_new(frames, entry);
        } else {
            json_object_set_new_nocheck(frames, names[k], entry);
        }
    }
    json_t *root = json_pack(
        "{s:o, s:{s:s, s:s, s:o, s:s, s:{s:i, s:i}, s:s, s:s}, "
        "s:{s:i, s:i, s:i, s:f, s:b, s:{s:i, s:i}, s:i, s:i, s:b, s:{s:i, s:i}}, "
        "s:{s:i, s:i, s:i, s:f}, s:{s:i, s:i}, s:{s:i, s:i}}",
        "frames", frames, "meta", "app", "pfx", "version", PFX_VERSION, "image",
        pfx_json_bytes(image), "format", "RGBA8888", "size", "w", l->width, "h", l->height, "scale",
        "1", "alpha", l->premultiplied ? "premultiplied" : "straight", "grid", "columns",
        l->columns, "rows", l->rows, "frames", l->frames, "fps", fps, "loop", loop, "cell", "w",
        l->cell_w, "h", l->cell_h, "padding", l->padding, "extrude",
        l->extrude < l->padding ? l->extrude : l->padding, "crop", l->crop, "used", "w", l->used_w,
        "h", l->used_h, "unity", "tiles_x", l->columns, "tiles_y", l->rows, "frames", l->frames,
        "fps", fps, "unreal", "sub_images_horizontal", l->columns, "sub_images_vertical", l->rows,
        "godot", "h_frames", l->columns, "v_frames", l->rows);
    if (root && l->motion)
        json_object_set_new(root, "motion_vectors", pfx_mv_json(l->motion, l, l->motion_image));
    bool ok = pfx_json_file_write_in(g, path, root, d);
    json_decref(root);
    return ok;
}
