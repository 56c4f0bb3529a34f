/* Reading PNG textures through libpng, for emitters' `texture` and
 * `normal_map` (output/ holds every <png.h>). */
#ifndef PFX_PNG_READ_H
#define PFX_PNG_READ_H

#include <stdbool.h>

#include "base/arena.h"
#include "base/diag.h"
#include "model/effect.h"

/* Limits, checked before the pixels are decoded: a texture is at most
 * 8192 pixels on a side, its file at most 64 MiB, and its decoded RGBA at
 * most 256 MiB (an 8-bit 8192x8192; a 16-bit texture must be smaller). */
#define PFX_TEXTURE_MAX_SIDE 8192
#define PFX_TEXTURE_MAX_FILE_BYTES (64u << 20)
#define PFX_TEXTURE_MAX_BYTES ((size_t)256 << 20)

/* Reads the PNG at `path` (grey, grey + alpha, RGB, RGBA or palette; 8 or
 * 16 bits) into out as RGBA of the file's depth, rows top first, with
 * alpha premultiplied when `premultiply` (a colour texture: mipmaps of
 * premultiplied texels have no dark fringes) and as it is otherwise (a
 * normal map). The pixels live in arena a. Messages name the file `name`
 * as the user wrote it and go to `at`: not a regular file, cannot open,
 * not a PNG, truncated or corrupt, too large. */
bool pfx_png_read_texture(const char *path, const char *name, bool premultiply, pfx_arena *a,
                          pfx_image *out, const pfx_diag_at *at);

#endif
