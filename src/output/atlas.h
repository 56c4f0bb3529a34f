/* Sprite sheets: frames packed into one even grid read row by row from the
 * top left, as every engine's flipbook expects (Unity's Texture Sheet
 * Animation, Unreal's SubUV, Godot's particle animation), with a
 * transparent gutter, edge extrusion and colour bled into transparent
 * pixels so that bilinear filtering and mipmaps show no dark halos; and
 * the JSON that describes it (TexturePacker's hash format plus the numbers
 * each engine asks for). */
#ifndef PFX_OUTPUT_ATLAS_H
#define PFX_OUTPUT_ATLAS_H

#include <stdbool.h>
#include <stdint.h>

#include "base/diag.h"
#include "output/atomic_file.h"

#define PFX_ATLAS_MAX_SIDE 16384

typedef struct pfx_atlas_layout {
    /* In. */
    int frame_w, frame_h; /* every frame's size */
    int frames;
    int columns, rows; /* 0: chosen from the frame count */
    int padding;       /* transparent pixels around each frame in its cell */
    int extrude;       /* of those, how many repeat the frame's edge (<= padding) */
    bool crop;         /* cut every frame to one box around all visible pixels */
    /* The frames' colour is premultiplied by alpha (image.alpha or
     * --alpha premultiplied): the sheet is too, so no colour is bled into
     * transparent texels (under premultiplied alpha it would be added
     * light), and the JSON says "premultiplied". */
    bool premultiplied;
    bool pot;        /* --atlas-pot: the sheet padded to powers of two, right and down */
    bool json_array; /* --atlas-json array: TexturePacker's array form, not the hash */
    /* --motion-vectors: the sheet of motion vectors laid out alike (NULL:
     * none), described in the JSON as "motion_vectors" with its image. */
    const struct pfx_mv_meta *motion;
    const char *motion_image;
    /* Out, from pfx_atlas_layout_resolve and pfx_atlas_compose. */
    int crop_x, crop_y, crop_w, crop_h; /* the box within a frame */
    int cell_w, cell_h;                 /* crop + 2 padding */
    int used_w, used_h;                 /* the grid of cells */
    int width, height;                  /* the sheet: the grid, or with pot the next powers of 2 */
} pfx_atlas_layout;

/* Chooses the grid (columns = ceil(sqrt(frames)), rows to fit, when not
 * given) and checks it: enough cells, a sheet at most 16384 pixels a side
 * (with pot, each side then rounded up to a power of two, still at most
 * 16384).
 * False with the reason in d. Call after the crop box is known. */
bool pfx_atlas_layout_resolve(pfx_atlas_layout *l, pfx_diags *d);

/* The box around every pixel with alpha > 0 of frames[0..n) (each
 * frame_w x frame_h RGBA), into l->crop_*; the whole frame when none is
 * visible. */
void pfx_atlas_find_crop(pfx_atlas_layout *l, uint8_t *const *frames, int n);

/* Composes the sheet (l->width x l->height RGBA, straight or premultiplied
 * as the frames are, malloc'd, the caller frees) from the resolved layout;
 * colour is bled into transparent texels of straight sheets only. NULL
 * when out of memory. */
uint8_t *pfx_atlas_compose(const pfx_atlas_layout *l, uint8_t *const *frames);

/* Writes the JSON at path (whole or not at all, as a file of group g:
 * output/atomic_file.h): frames by name (names[i]
 * for frame i; a hash by name, or with json_array an array of objects
 * with a "filename") with their rectangles in pixels and as UV fractions
 * of the sheet, the grid, fps, loop and the alpha mode, for the sheet
 * named `image`. False with the reason in d. */
bool pfx_atlas_write_json(pfx_atomic_group *g, const char *path, const pfx_atlas_layout *l,
                          const char *image, const char *const *names, double fps, bool loop,
                          pfx_diags *d);

#endif
