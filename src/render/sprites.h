/* From simulation state to renderer input: sprites (sprites_from_sim.c)
 * and ribbons (ribbons_from_sim.c). */
#ifndef PFX_SPRITES_H
#define PFX_SPRITES_H

#include "render/render.h"
#include "render/shadow.h"
#include "sim/sim.h"

/* True when any emitter blends by alpha: then every sprite, of every
 * emitter, is drawn in one back-to-front order. Additive alone needs none. */
bool pfx_sprites_need_sort(const pfx_effect *e);
/* Whether frames need the opacity shadow map: the light casts shadows and
 * some sprite emitter is lit (a look nobody lights reads no shadow). */
bool pfx_sprites_shadowed(const pfx_effect *e);
/* One material per emitter, in emitter order (sprites name them by
 * index), into out (room for e->emitter_count). */
void pfx_sprites_materials(const pfx_effect *e, pfx_material *out);
/* The image settings and light of the effect. */
pfx_render_settings pfx_sprites_settings(const pfx_effect *e);
/* The most sprites a frame can have: the sum of the pool capacities. */
size_t pfx_sprites_capacity(const pfx_effect *e);
/* Writes one sprite per live particle of every `draw: sprite` emitter into
 * out (room for pfx_sprites_capacity); returns how many. A render does not
 * hold them all: it reads them through pfx_sprite_feed_source, a chunk at
 * a time; this is for the callers that want an array (pfx bench, tests). */
size_t pfx_sprites_build(const pfx_sim *s, pfx_sprite *out);

/* The sprites of a state as the renderer reads them (pfx_sprite_source):
 * made from the pools when asked, in the order pfx_sprites_build writes
 * them, so a frame holds no sprite array, only the renderer's chunk.
 * `start` holds where each emitter's sprites begin (emitter_count + 1
 * entries). */
typedef struct pfx_sprite_feed {
    const pfx_sim *sim;
    size_t *start;
    struct pfx_shadow_volume *shadow; /* pfx_sprites_shadowed effects only */
} pfx_sprite_feed;
/* False when out of memory; the caller frees it with pfx_sprite_feed_free. */
bool pfx_sprite_feed_init(pfx_sprite_feed *f, const pfx_effect *e);
void pfx_sprite_feed_free(pfx_sprite_feed *f);
/* Points f at state s (which must outlive the source's use) and returns the
 * source of its sprites. Its callbacks only read s, so the renderer may
 * call them from several threads at once. */
pfx_sprite_source pfx_sprite_feed_source(pfx_sprite_feed *f, const pfx_sim *s);
/* The opacity shadow map of state s (render/shadow.h), in f, until the
 * next call; NULL when nothing reads it (pfx_sprites_shadowed). */
const struct pfx_shadow_volume *pfx_sprite_feed_shadow(pfx_sprite_feed *f, const pfx_sim *s);
/* The emitter whose sprites hold sprite n of f's source: sprite n is
 * particle n - f->start[i] of emitter i's pool. */
size_t pfx_sprite_feed_emitter(const pfx_sprite_feed *f, size_t n);

/* The intensity multiplier of a look at normalised age u. */
static inline float pfx_look_intensity(const pfx_look *k, float u) {
    if (!k->intensity_curve)
        return k->intensity;
    int i = (int)(u * (PFX_GRADIENT_LUT - 1) + 0.5f);
    return k->intensity_lut[i < 0 ? 0 : i >= PFX_GRADIENT_LUT ? PFX_GRADIENT_LUT - 1 : i];
}

/* The vertices and sort scratch of a frame's ribbons, sized once from the
 * effect's `draw: ribbon` pools. */
typedef struct pfx_ribbon_buffer pfx_ribbon_buffer;
/* NULL when out of memory; the caller frees it with pfx_ribbons_destroy. */
pfx_ribbon_buffer *pfx_ribbons_create(const pfx_effect *e);
void pfx_ribbons_destroy(pfx_ribbon_buffer *b);
/* The bytes pfx_ribbons_create allocates for e, with the GL buffer its
 * vertices are uploaded to, and the most triangles a frame's ribbons have:
 * for the memory estimate. */
size_t pfx_ribbons_bytes(const pfx_effect *e);
size_t pfx_ribbons_triangles(const pfx_effect *e);
/* The ribbons of state s as triangles, facing s->effect's camera: for each
 * `draw: ribbon` emitter in order, one strip per parent (by parent id),
 * through its trail points in birth order. The result points into b and
 * lives until the next build. */
pfx_ribbons pfx_ribbons_build(pfx_ribbon_buffer *b, const pfx_sim *s);

#endif
