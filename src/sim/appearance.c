/* A particle's looks at the pool's time: its size, colour and sprite angle
 * over its normalised age, from the emitter's tables and its own columns.
 * The one place appearance is computed: sprites, bakes and the colour and
 * size sub-emitters inherit all read it. */
#include "sim/appearance.h"

#include <math.h>
#include <string.h>

/* The lookup-table entry for normalised age (or any u in [0, 1]): nearest. */
static int lut_index(float u) {
    int k = (int)(u * (PFX_GRADIENT_LUT - 1) + 0.5f);
    return k < 0 ? 0 : k >= PFX_GRADIENT_LUT ? PFX_GRADIENT_LUT - 1 : k;
}

float pfx_particle_size(const pfx_emitter *em, const pfx_pool *p, uint32_t i) {
    float u = (float)pfx_particle_age(p, i) / p->lifetime[i];
    float scale = p->size_scale ? p->size_scale[i] : 1.0f;
    if (em->size_curve)
        return em->size_lut[lut_index(u)] * scale;
    float s0 = p->size0 ? p->size0[i] : (float)em->size_start.a;
    float s1 = p->size1 ? p->size1[i] : em->size_same ? s0 : (float)em->size_end.a;
    return (s0 + (s1 - s0) * u) * scale;
}

void pfx_particle_color(const pfx_emitter *em, const pfx_pool *p, uint32_t i, float out[4]) {
    int k = lut_index((float)pfx_particle_age(p, i) / p->lifetime[i]);
    switch (em->color_mode) {
    case PFX_COLOR_RANDOM: {
        float t = p->tint[i];
        for (int c = 0; c < 4; c++)
            out[c] = em->color_a[c] + (em->color_b[c] - em->color_a[c]) * t;
        break;
    }
    case PFX_COLOR_PICK:
        memcpy(out, em->color.lut[lut_index(p->tint[i])], 4 * sizeof(float));
        break;
    default:
        memcpy(out, em->color.lut[k], 4 * sizeof(float));
    }
    if (em->alpha_curve)
        out[3] *= em->alpha_lut[k];
    if (p->pr) {
        out[0] *= p->pr[i];
        out[1] *= p->pg[i];
        out[2] *= p->pb[i];
    }
}

float pfx_particle_angle(const pfx_emitter *em, const pfx_pool *p, uint32_t i) {
    const float age = (float)pfx_particle_age(p, i);
    float a0 = p->angle0 ? p->angle0[i] : (float)em->angle.a;
    float turned = em->spin_curve
                       ? p->lifetime[i] * em->spin_turn_lut[lut_index(age / p->lifetime[i])]
                       : (p->spin ? p->spin[i] : (float)em->spin.a) * age;
    return a0 + turned;
}
