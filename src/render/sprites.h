/* From simulation state to renderer input. */
#ifndef PFX_SPRITES_H
#define PFX_SPRITES_H

#include "render/render.h"
#include "sim/sim.h"

/* True when any emitter blends by alpha: then every sprite, of every
 * emitter, is drawn in one back-to-front order. Additive alone needs none. */
bool pfx_sprites_need_sort(const pfx_effect *e);
/* One material per emitter, in emitter order (sprites name them by
 * index), into out (room for e->emitter_count). */
void pfx_sprites_materials(const pfx_effect *e, pfx_material *out);
/* The image settings and light of the effect. */
pfx_render_settings pfx_sprites_settings(const pfx_effect *e);
/* The most sprites a frame can have: the sum of the pool capacities. */
size_t pfx_sprites_capacity(const pfx_effect *e);
/* Writes one sprite per live particle into out (room for
 * pfx_sprites_capacity); returns how many. */
size_t pfx_sprites_build(const pfx_sim *s, pfx_sprite *out);

#endif
