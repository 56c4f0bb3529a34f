/* A rendered frame as floats, and the one conversion of it to 8-bit RGBA.
 * Plain data and pure functions with no GL: render/ fills these images,
 * output/ converts and encodes them on its encoder threads (PNG) or writes
 * them as they are (EXR). */
#ifndef PFX_RENDER_IMAGE_H
#define PFX_RENDER_IMAGE_H

#include <stdbool.h>
#include <stdint.h>

#include "model/effect.h"

/* A frame as the framebuffer held it: linear premultiplied colour (r, g, b)
 * and coverage a. Only the box [x0, x1) x [y0, y1) (GL window coordinates,
 * y up) holds drawn pixels; every other pixel is `clear`. An empty box
 * (x1 <= x0 or y1 <= y0) is a frame of background alone. */
typedef struct pfx_float_image {
    int width, height;  /* the whole frame */
    int x0, y0, x1, y1; /* the drawn box */
    float *pixels;      /* the box: (x1 - x0) x (y1 - y0) RGBA, bottom row first */
    float clear[4];     /* the background, premultiplied */
} pfx_float_image;

/* The pixel at column x of row y counted from the top, as the frame holds
 * it (box or background). */
static inline const float *pfx_float_image_at(const pfx_float_image *img, int x, int y) {
    const int gl_y = img->height - 1 - y;
    if (x >= img->x0 && x < img->x1 && gl_y >= img->y0 && gl_y < img->y1)
        return img->pixels +
               ((size_t)(gl_y - img->y0) * (size_t)(img->x1 - img->x0) + (size_t)(x - img->x0)) * 4;
    return img->clear;
}

/* What turns the float image into 8-bit bytes (render/convert.c says how):
 * the effect's exposure, tone curve, alpha mode and dither. */
typedef struct pfx_tone {
    double exposure; /* EV: colour x 2^exposure */
    pfx_tonemap tonemap;
    double preserve_hue; /* 0: each channel by itself; 1: by the brightest */
    pfx_alpha_mode alpha;
    bool dither;
} pfx_tone;

/* Writes width x height x 4 bytes of 8-bit RGBA, top row first, into
 * rgba. Pure: the bytes depend on the image and the tone alone, so any
 * thread may convert any frame. */
void pfx_float_image_to_rgba8(const pfx_float_image *img, const pfx_tone *t, uint8_t *rgba);

#endif
