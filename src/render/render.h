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
#include "render/image.h"

/* One particle as drawn, 64 bytes, uploaded to GL as it is (four vec4s).
 * A quad of world-space width `size` centred at (x, y, z), facing as its
 * material says. Colour is premultiplied: (r, g, b) = colour * alpha *
 * intensity; `a` is the alpha that occludes what is behind: the particle's
 * alpha for alpha blending, 0 for additive blending. With the single blend
 * function (ONE, ONE_MINUS_SRC_ALPHA) this draws both modes in one pass
 * (premultiplied alpha; additive is "emission with zero coverage"). */
typedef struct pfx_sprite {
    float x, y, z, size;
    float r, g, b, a;
    float angle;      /* radians, turning the sprite in its plane */
    float material;   /* index into the renderer's materials, as a float */
    float frame;      /* flipbook: cell index plus the fraction towards the next */
    float variant;    /* in [0, 1): the particle's own random (smoke puff, start cell) */
    float vx, vy, vz; /* velocity, m/s: align velocity stretches along it on screen */
    float length;     /* align velocity: the length in metres (size x length + |v| x speed) */
} pfx_sprite;

/* A frame's sprites as the renderer reads them: `count` sprites in a fixed
 * order, made when asked rather than held, so that a frame needs no array
 * of them (render/sprites.h makes one from the simulation's pools). make
 * writes sprites first .. first + n - 1 of the order into out, or, when
 * index is not NULL, sprites index[0 .. n) (first is then unused);
 * centres writes the (x, y, z) of sprites first .. first + n - 1 into xyz,
 * what the depth sort reads. Both may be called from several threads at
 * once on different ranges, and must give the same sprite for the same
 * position whatever the call. */
typedef struct pfx_sprite_source {
    size_t count;
    void (*make)(const void *ctx, size_t first, size_t n, const uint32_t *index, pfx_sprite *out);
    void (*centres)(const void *ctx, size_t first, size_t n, float *xyz);
    const void *ctx;
} pfx_sprite_source;
/* The source of an array of count sprites, which must outlive its use. */
pfx_sprite_source pfx_sprite_source_array(const pfx_sprite *sprites, size_t count);

/* Sprites a draw call takes: the renderer makes, uploads and draws a
 * frame's sprites this many at a time (after one depth sort over all of
 * them), flushing GL between chunks, so neither its sprite buffer nor the
 * driver's binned triangles grow with the sprite count. One instanced draw
 * split into several in the same order, with the same blend state, gives
 * the same pixels. */
#define PFX_RENDER_CHUNK 4096u

/* One corner of a ribbon, 44 bytes: ribbons come as a triangle list (three
 * vertices a triangle) in world space, already facing the camera, so the
 * renderer only projects them. Colour is premultiplied as a sprite's is
 * (a = 0 for additive). `across` runs from -1 on one edge of the strip to
 * +1 on the other; `profile` is the cross-section over it: 0 soft, (1 -
 * across^2)^2 like a round sprite's falloff, 1 flat. `along` is the
 * fraction of the strip's length from its head (0) to its tail (1), and
 * with `across` the texture coordinate of a textured ribbon: the
 * material's texture (its index as a float, as a sprite's) spans the
 * strip once, u along, v across. */
typedef struct pfx_ribbon_vertex {
    float x, y, z, across;
    float r, g, b, a;
    float profile, along, material;
} pfx_ribbon_vertex;

/* The ribbons of a frame: `count` vertices (a multiple of 3), drawn in
 * order before every sprite. */
typedef struct pfx_ribbons {
    const pfx_ribbon_vertex *v;
    size_t count;
} pfx_ribbons;

/* How a run of sprites is drawn: one per emitter. Until
 * pfx_renderer_set_materials, material k is built-in sprite kind k facing
 * the camera. */
typedef struct pfx_material {
    pfx_sprite_kind sprite;
    const pfx_image *texture;    /* NULL: the built-in sprite */
    const pfx_image *normal_map; /* lit: NULL for a spherical normal */
    int cols, rows, frames;      /* flipbook grid and cells (1, 1, 1 without one) */
    bool frame_loop;             /* cells wrap (fps) or stop at the last (over life) */
    bool frame_blend;            /* cross-fade between consecutive cells */
    pfx_align align;
    double axis[3]; /* AXIS: world axis; WORLD: plane normal (unit) */
    bool lit;
    bool shadowed; /* lit: the direct light scaled by the shadow volume's exp(-depth) */
} pfx_material;

/* What turns the float image into bytes, and the light of lit materials.
 * pfx_render_settings_plain: straight alpha, no exposure, no tone curve,
 * no dither, over `bg`. */
typedef struct pfx_render_settings {
    float background[4]; /* straight RGBA */
    double exposure;     /* EV */
    pfx_tonemap tonemap;
    double preserve_hue; /* 0..1, render/convert.c */
    pfx_alpha_mode alpha;
    bool dither;
    double light_dir[3]; /* the direction light travels, unit */
    float light_color[3], ambient[3];
} pfx_render_settings;
pfx_render_settings pfx_render_settings_plain(const float bg[4]);
/* The part of the settings that turns the float image into bytes. */
pfx_tone pfx_render_tone(const pfx_render_settings *s);

/* Built-in sprites (model/kinds.h), with (x, y) the quad's corner
 * coordinates in [-1, 1] and d^2 = x^2 + y^2: round (1 - d^2)^2; square
 * (1 - x^2)^2 (1 - y^2)^2, a soft square whose rotation shows; spark, an
 * ellipse three times longer along y with a core three times brighter;
 * smoke, the round falloff times two octaves of value noise offset by the
 * particle's variant; flare, a soft halo, four rays and a hot core; ring,
 * a soft annulus at 0.72 of the radius. A sprite narrower than
 * PFX_MIN_FOOTPRINT_PX on screen is drawn that wide with its colour scaled
 * by the width ratio (for each of its two axes), so its summed brightness
 * does not depend on its size or where it falls on the pixel grid. */
#define PFX_MIN_FOOTPRINT_PX 4.0

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

/* The materials sprites name by index, one per emitter: textures are
 * uploaded now (with mipmaps of their premultiplied texels), once per
 * distinct image (the same pixels pointer), however many materials name
 * it. The renderer keeps pointers to the images, which must outlive it.
 * False (with an error in d) when a texture cannot be uploaded. */
bool pfx_renderer_set_materials(pfx_renderer *r, const pfx_material *m, size_t count, pfx_diags *d);
/* How many GL textures the current materials hold. */
size_t pfx_renderer_texture_count(const pfx_renderer *r);

/* Draws `count` sprites seen from `cam` and writes width*height*4 bytes of
 * 8-bit RGBA (straight or premultiplied as `s` says), top row first, into
 * rgba. When `sort` is true the sprites are drawn back to front by view
 * depth (one sort over all of them, stable, so ties keep input order); the
 * array is not changed (sprites may be NULL when count is 0). Consecutive
 * sprites of one material are one instanced draw (split at every
 * PFX_RENDER_CHUNK sprites). The ribbons (none: {NULL, 0}) are drawn
 * first, in their order, under every sprite: one draw of their triangles.
 * Returns false (with an error in d) on a GL failure or when the sort
 * scratch cannot be grown; rgba is then unspecified. */
bool pfx_renderer_draw_frame(pfx_renderer *r, const pfx_camera *cam, const pfx_render_settings *s,
                             const pfx_sprite *sprites, size_t count, bool sort,
                             pfx_ribbons ribbons, uint8_t *rgba, pfx_diags *d);
/* pfx_renderer_draw_frame without the conversion: the frame's float image
 * into img, whose pixels the caller owns (room for width * height * 4
 * floats); the renderer reads the drawn box back into them and sets the
 * rest of img. The conversion (pfx_float_image_to_rgba8 with
 * pfx_render_tone(s)) is then the caller's, on any thread. */
bool pfx_renderer_draw_float(pfx_renderer *r, const pfx_camera *cam, const pfx_render_settings *s,
                             const pfx_sprite_source *src, bool sort, pfx_ribbons ribbons,
                             pfx_float_image *img, pfx_diags *d);
/* pfx_renderer_draw_frame with pfx_render_settings_plain(bg). */
bool pfx_renderer_draw(pfx_renderer *r, const pfx_camera *cam, const float bg[4],
                       const pfx_sprite *sprites, size_t count, bool sort, uint8_t *rgba,
                       pfx_diags *d);

struct pfx_shadow_volume;
/* Uploads the opacity shadow map that shadowed materials read
 * (render/shadow.h) for the frames drawn next, until the next call. NULL
 * or an empty volume: no shadow. False with an error in d on a GL
 * failure. */
bool pfx_renderer_set_shadow(pfx_renderer *r, const struct pfx_shadow_volume *v, pfx_diags *d);

/* Motion blur: the float images of several sub-frame times, averaged.
 * begin clears the sum; each add draws the sprites as draw_frame would and
 * adds `weight` times the float image (weights summing to 1); resolve
 * converts the sum as draw_frame converts one image. The sum is kept in
 * a fixed order, so the bytes do not depend on anything but the inputs. */
bool pfx_renderer_blur_begin(pfx_renderer *r, pfx_diags *d);
bool pfx_renderer_blur_add(pfx_renderer *r, const pfx_camera *cam, const pfx_render_settings *s,
                           const pfx_sprite_source *src, bool sort, pfx_ribbons ribbons,
                           float weight, pfx_diags *d);
void pfx_renderer_blur_resolve(pfx_renderer *r, const pfx_render_settings *s, uint8_t *rgba);
/* The sum as a float image (the whole frame is its box) into img, whose
 * pixels the caller owns (width * height * 4 floats), unconverted. */
void pfx_renderer_blur_resolve_float(pfx_renderer *r, const pfx_render_settings *s,
                                     pfx_float_image *img);

/* Where a source's sprites are one frame later, in the source's order:
 * make writes (x, y, z, weight) of sprites first .. first + n - 1 into
 * xyzw, the centre in world space at the next frame and 1 to draw the
 * sprite into the motion-vector pass or 0 to leave it out. */
typedef struct pfx_sprite_ends {
    void (*make)(const void *ctx, size_t first, size_t n, float *xyzw);
    const void *ctx;
} pfx_sprite_ends;

/* Motion vectors: the sprites drawn as draw_frame draws them (the same
 * quads, falloff, flipbook alpha and minimum footprint, no ribbons), each
 * pixel getting the weighted mean of the displacements of the sprites over
 * it, where a sprite's displacement is its end's projected position (ends)
 * minus its centre's, in pixels of the frame, and its weight is the end's
 * weight times its falloff (texture alpha) times its alpha (1 for additive
 * sprites, whose colour pass alpha is 0), over the footprint widening,
 * clamped to [0, 1]. Writes width*height*3 floats, top row first: dx
 * (+right), dy (+up), and the coverage 1 - prod(1 - weight) in [0, 1]; a
 * pixel no sprite touches is (0, 0, 0). A sprite whose centre or end is
 * behind the camera weighs 0. Drawn into a float target of its own, made
 * on the first call. Draws the source's sprites in its order, a chunk at a
 * time, unsorted. False with an error in d on a GL failure. */
bool pfx_renderer_motion_vectors(pfx_renderer *r, const pfx_camera *cam,
                                 const pfx_render_settings *s, const pfx_sprite_source *src,
                                 const pfx_sprite_ends *ends, float *mv, pfx_diags *d);
/* The threads that make each chunk's sprites and run the depth sort of
 * alpha-blended ones (0: one per online core; a new renderer works on the
 * caller's thread alone). Neither sprites nor order depend on the count.
 * False (with an error in d, which may be NULL) when the threads cannot
 * start; the renderer then works on the caller's thread, with the same
 * result. */
bool pfx_renderer_set_threads(pfx_renderer *r, int threads, pfx_diags *d);

/* Sorts the sprites back to front, in place, in the order
 * pfx_renderer_draw_frame draws them with sort true, and draws nothing
 * (pfx bench times it; tests check the order). It keeps a sorted copy of
 * the array, which drawing never needs. False with an error in d when the
 * scratch cannot grow. */
bool pfx_renderer_sort(pfx_renderer *r, const pfx_camera *cam, pfx_sprite *sprites, size_t count,
                       pfx_diags *d);

/* Memory the GL driver holds for a frame's triangles beyond their vertex
 * buffer: Mesa's llvmpipe bins every triangle into screen tiles before
 * rasterising, in scenes it keeps in flight while its threads work.
 * Sprites go to it a chunk (PFX_RENDER_CHUNK) at a time with at most two
 * chunks in flight (render.c), so their share does not grow with the
 * sprite count: the peak RSS of 2e5 and 1.6e6 sprites, alpha-blended and
 * additive, at 128x128, 320x240 and 512x512 (2 cores), less the
 * libraries' own and the parts counted elsewhere, was 12 to 24 MB with
 * 4096-sprite chunks (the most for sprites covering most of the frame),
 * 33 to 35 MB with 16384 and 82 to 117 MB with 65536; drawn whole (before
 * chunking) 2e5 sprites took 74 to 108 MB and 3.2e6 took 246 MB. Counted
 * as PFX_RENDER_DRIVER_BYTES_PER_SPRITE for PFX_RENDER_DRIVER_CHUNKS
 * chunks (32 MiB). Ribbons are still one draw of all their triangles,
 * counted as whole frames of sprites were (a ribbon triangle is half a
 * sprite's two): 512 bytes a triangle for the first 96 MiB plus 64 bytes
 * a triangle, which bounded every whole frame measured.
 * tests/jobs/run_memory.sh checks both against real renders. */
#define PFX_RENDER_DRIVER_BYTES_PER_SPRITE 2048.0
#define PFX_RENDER_DRIVER_CHUNKS 4
#define PFX_RENDER_DRIVER_BYTES_PER_TRIANGLE 64.0
#define PFX_RENDER_DRIVER_FIRST_BYTES_PER_TRIANGLE 512.0
#define PFX_RENDER_DRIVER_FIRST_CAP (96.0 * 1024 * 1024)
/* LLVM's memory while llvmpipe compiles the shaders of a material that
 * samples a texture or normal map: 16 MB more peak RSS for one such
 * emitter than for untextured ones, whose programs cost next to nothing
 * beyond the first (measured with four emitters of different looks). */
#define PFX_RENDER_DRIVER_BYTES_PER_TEXTURED (16.0 * 1024 * 1024)

/* Sprites the depth sort sorts at once: a frame with more is sorted in
 * batches of this many (render/sort.c), each found by a radix select over
 * the keys (five more passes over them), so the sort's memory stops
 * growing here: 64 MiB of keys and positions, and 2 MiB of histograms. */
#define PFX_SORT_BATCH ((size_t)1 << 22)

/* Bytes of sort scratch a renderer holds once it has drawn `count` sorted
 * sprites (two key and two index arrays, the histograms: 16 bytes a sprite
 * and 1 KiB a 64 Ki block, for at most PFX_SORT_BATCH sprites, and the
 * batches' histograms beyond that; the sorted sprites are made a chunk at
 * a time, never copied whole): the memory estimate's share for the sort,
 * which no count takes past about 66 MiB. */
size_t pfx_renderer_sort_bytes(size_t count);

/* Sorts at most `batch` sprites at once from now on (at least 1; larger
 * than PFX_SORT_BATCH is not allowed): for the tests, which check that
 * batches give the order of one sort. */
void pfx_renderer_set_sort_batch(pfx_renderer *r, size_t batch);

/* The reference the pfx bench measures full rendering against: `frames`
 * times clears, uploads the sprites, makes the one instanced draw, glFinish
 * and reads the float framebuffer back; no sort and no 8-bit conversion.
 * Does not modify sprites. Returns frames per second (CLOCK_MONOTONIC), or a
 * negative value if frames <= 0, the camera is degenerate or GL fails. */
double pfx_renderer_bench_raw(pfx_renderer *r, const pfx_camera *cam, const pfx_sprite *sprites,
                              size_t count, int frames);

#endif
