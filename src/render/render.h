/* Offscreen rendering of particle sprites through a GL context with no
 * window: OSMesa, or EGL on Mesa's software device or on a GPU. This is the
 * only part of pfx that includes GL, OSMesa or EGL headers. It knows sprites
 * and a camera, not emitters or the simulation. */
#ifndef PFX_RENDER_H
#define PFX_RENDER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/diag.h"
#include "model/effect.h"

/* One particle as drawn: a camera-facing soft round sprite of world-space
 * diameter `size` centred at (x, y, z). Colour is premultiplied:
 * (r, g, b) = colour * alpha. `a` is the alpha that occludes what is behind:
 * the particle's alpha for alpha blending, 0 for additive blending. With the
 * single blend function (ONE, ONE_MINUS_SRC_ALPHA) this draws both modes in
 * one pass (premultiplied alpha; additive is "emission with zero coverage"). */
typedef struct pfx_sprite {
    float x, y, z, size;
    float r, g, b, a;
    float angle; /* radians, turning the sprite in the view plane */
    float shape; /* the pfx_sprite_kind (PFX_SPRITE_ROUND, ...), as a float for the GPU */
} pfx_sprite;

/* Sprite kinds (model/kinds.h). Round: alpha (1 - d^2)^2 with d the
 * distance from the centre over the radius (rotation does not show).
 * Square: the product of that falloff along the sprite's two axes,
 * (1 - x^2)^2 (1 - y^2)^2, a soft square whose rotation shows. */

/* Where the GL context comes from, one row each: the kind and its name as
 * --renderer and PFX_RENDERER spell it. auto is OSMesa where this pfx was
 * built with it, else egl-cpu: never a GPU, whose pixels may differ. */
#define PFX_RENDERER_KINDS(X)                                                                      \
    X(PFX_RENDERER_AUTO, "auto")                                                                   \
    X(PFX_RENDERER_OSMESA, "osmesa")                                                               \
    X(PFX_RENDERER_EGL_CPU, "egl-cpu")                                                             \
    X(PFX_RENDERER_EGL_GPU, "egl-gpu")

typedef enum pfx_renderer_kind {
#define PFX_RENDERER_ENUM(kind, name) kind,
    PFX_RENDERER_KINDS(PFX_RENDERER_ENUM)
#undef PFX_RENDERER_ENUM
        PFX_RENDERER_KIND_COUNT
} pfx_renderer_kind;

/* The kind's name ("egl-cpu"); a static string. */
const char *pfx_renderer_kind_name(pfx_renderer_kind kind);
/* The kind named `name`, exactly as in the table; false if there is none. */
bool pfx_renderer_kind_parse(const char *name, pfx_renderer_kind *kind);

typedef struct pfx_renderer pfx_renderer;

/* Creates a core-profile 3.3 context of the given kind drawing into a width
 * x height float framebuffer. Returns NULL and writes a one-line message
 * into d on failure, naming what is missing when the kind cannot start
 * here (not built in, no such device, an EGL extension lacking). The caller
 * owns the result and frees it with pfx_renderer_destroy. Each call on a
 * renderer makes its context current in the calling thread, so several
 * renderers may coexist, but one renderer must be used by one thread at a
 * time. */
pfx_renderer *pfx_renderer_create(pfx_renderer_kind kind, int width, int height, pfx_diags *d);
/* The renderer's kind as --renderer names it, auto resolved ("osmesa");
 * a static string. */
const char *pfx_renderer_name(const pfx_renderer *r);
/* Frees the context, its GL objects and scratch memory; NULL is a no-op. */
void pfx_renderer_destroy(pfx_renderer *r);

/* Draws `count` sprites seen from `cam` over the straight-alpha background
 * `bg` and writes width*height*4 bytes of 8-bit straight-alpha RGBA, top row
 * first, into rgba. When `sort` is true the sprites are drawn back to front by
 * view depth (one sort over all of them, stable, so ties keep input order);
 * the sprites array is reordered in place (sprites may be NULL when count is
 * 0). Returns false (with an error in d) on a GL failure or when
 * the sort scratch cannot be grown; rgba is then unspecified. */
bool pfx_renderer_draw(pfx_renderer *r, const pfx_camera *cam, const float bg[4],
                       pfx_sprite *sprites, size_t count, bool sort, uint8_t *rgba, pfx_diags *d);

/* The reference the pfx bench measures full rendering against: `frames`
 * times clears, uploads the sprites, makes the one instanced draw, glFinish
 * and reads the float framebuffer back; no sort and no 8-bit conversion.
 * Does not modify sprites. Returns frames per second (CLOCK_MONOTONIC), or a
 * negative value if frames <= 0, the camera is degenerate or GL fails. */
double pfx_renderer_bench_raw(pfx_renderer *r, const pfx_camera *cam, const pfx_sprite *sprites,
                              size_t count, int frames);

#endif
