/* Simulation state -> the sprites the renderer draws: size over life,
 * colour from the gradient, premultiplied, with the occluding alpha set to 0
 * for additive emitters (see pfx_sprite). It decides whether a depth sort is
 * needed: only when some emitter blends by alpha. */
#include "render/sprites.h"

bool pfx_sprites_need_sort(const pfx_effect *e) {
    for (size_t i = 0; i < e->emitter_count; i++)
        if (e->emitters[i].blend == PFX_BLEND_ALPHA)
            return true;
    return false;
}

size_t pfx_sprites_capacity(const pfx_effect *e) {
    size_t n = 0;
    for (size_t i = 0; i < e->emitter_count; i++)
        n += e->emitters[i].capacity;
    return n;
}

size_t pfx_sprites_build(const pfx_sim *s, pfx_sprite *out) {
    const pfx_effect *e = s->effect;
    size_t n = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        const pfx_pool *p = &s->pools[i];
        const bool additive = em->blend == PFX_BLEND_ADD;
        for (uint32_t j = 0; j < p->count; j++) {
            float c[4];
            pfx_particle_color(em, p, j, c);
            const float a = c[3];
            out[n++] = (pfx_sprite){
                .x = p->px[j],
                .y = p->py[j],
                .z = p->pz[j],
                .size = pfx_particle_size(em, p, j),
                .r = c[0] * a,
                .g = c[1] * a,
                .b = c[2] * a,
                .a = additive ? 0.0f : a,
                /* A round sprite looks the same at any angle: skip the work. */
                .angle = em->sprite != PFX_SPRITE_ROUND ? pfx_particle_angle(em, p, j) : 0,
                .shape = (float)em->sprite};
        }
    }
    return n;
}
