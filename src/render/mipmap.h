/* A texture's mip levels, made by pfx on the CPU (render/mipmap.c).
 * Private to src/render. */
#ifndef PFX_RENDER_MIPMAP_H
#define PFX_RENDER_MIPMAP_H

#include <stdint.h>

#include "render/render_internal.h"

/* The level below a w x h level of RGBA texels (uint8_t, or uint16_t when
 * bits is 16, rows top first): max(1, w / 2) x max(1, h / 2) texels into
 * *dw, *dh, each the mean of the source texels under it weighted by the
 * area they share, rounded to nearest (half up). Returns a new buffer the
 * caller frees, or NULL when out of memory. */
void *pfx_mipmap_halve(const void *src, int w, int h, int bits, int *dw, int *dh);

/* The GL format every level of img is held in: half floats for 8-bit
 * images, floats for 16-bit ones (half floats keep 11 bits). Not the
 * images' own 8 or 16 bits: llvmpipe filters normalised 8-bit texels with
 * weights of a few bits and a GPU with finer ones, which put egl-gpu up to
 * 7/255 from egl-cpu (measured on an H200) with the same texels at the
 * same level, while both filter float texels in float: llvmpipe's frames
 * are then identical to exact bilinear filtering done in the shader in
 * float, at the same speed, for twice the memory of 8-bit texels. */
GLenum pfx_texture_format(const pfx_image *img);

/* Uploads levels 1 and below of img (level 0 already in the bound
 * GL_TEXTURE_2D) down to 1 x 1; false when out of memory for one. */
bool pfx_mipmap_upload(pfx_renderer *r, const pfx_image *img);

#endif
