/* Motion-vector images as game engines read them for flipbook
 * motion-vector blending (Unreal's flipbook motion vectors, Unity VFX
 * Graph's Flipbook Motion Blend): R the horizontal and G the vertical
 * displacement to the next frame, 0.5 meaning none, scaled by a stated
 * maximum; B 0; A the coverage; 16 bits a channel. This file turns the
 * renderer's float displacements into those samples, lays them out like
 * the colour atlas, and describes the encoding in JSON. */
#ifndef PFX_OUTPUT_MOTION_VECTORS_H
#define PFX_OUTPUT_MOTION_VECTORS_H

#include <stdbool.h>
#include <stdint.h>

#include <jansson.h>

#include "base/diag.h"
#include "output/atlas.h"

/* Without --mv-max, max_px is this percentile of the covered pixels'
 * displacements over the sequence (jobs/motion_job.h). */
#define PFX_MV_PERCENTILE 95

typedef struct pfx_mv_meta {
    double max_px;  /* the displacement, in pixels of a frame, encoded as 0 or 1 (> 0) */
    bool max_given; /* --mv-max; else PFX_MV_PERCENTILE of the sequence's displacements */
    bool flip_y;    /* --mv-flip-y: +G = down (image rows) instead of up */
    double fps;     /* the displacement spans 1 / fps seconds */
} pfx_mv_meta;

/* Encodes w x h pixels of (dx, dy, coverage) floats, top row first, dx
 * +right and dy +up in pixels (render/render.h), into w x h x 4 samples:
 * R = 0.5 + dx / (2 max_px), G likewise from dy (-dy with flip_y), each
 * clamped to [0, 1], B = 0, A = coverage, as round(value x 65535). */
void pfx_mv_encode(const float *mv, int width, int height, const pfx_mv_meta *m, uint16_t *out);

/* The motion-vector sheet of a layout resolved for the colour atlas
 * (output/atlas.h): the same cells, crop, padding and extruded ring, the
 * rest of the gutter "no motion, no coverage" (R = G = 32768, B = A = 0).
 * frames[k] are frame_w x frame_h x 4 samples. Malloc'd (the caller
 * frees), NULL when out of memory. */
uint16_t *pfx_mv_atlas_compose(const pfx_atlas_layout *l, uint16_t *const *frames);

/* The encoding as a JSON object (a new reference): max_px, the formula,
 * the axes, the units; with a layout, the sheet `image` and the strength
 * an engine's flipbook wants (max_px over the cell's width and height). */
json_t *pfx_mv_json(const pfx_mv_meta *m, const pfx_atlas_layout *l, const char *image);

/* The sidecar of a render without an atlas: {"motion_vectors": ...} with
 * the frames' name pattern and range, whole or not at all. False with the
 * reason in d. */
bool pfx_mv_write_sidecar(const char *path, const pfx_mv_meta *m, const char *pattern, long first,
                          long last, pfx_diags *d);

#endif
