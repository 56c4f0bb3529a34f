/* A particle's looks over its life (sim/appearance.c): the one place size,
 * colour and sprite angle are computed, for sprites, bakes and what
 * sub-emitters inherit. */
#ifndef PFX_SIM_APPEARANCE_H
#define PFX_SIM_APPEARANCE_H

#include "sim/state.h"

/* Particle i's size and straight-alpha colour now (by its normalised age). */
float pfx_particle_size(const pfx_emitter *em, const pfx_pool *p, uint32_t i);
void pfx_particle_color(const pfx_emitter *em, const pfx_pool *p, uint32_t i, float out[4]);
/* Particle i's sprite angle now, radians: angle at birth plus its spin. */
float pfx_particle_angle(const pfx_emitter *em, const pfx_pool *p, uint32_t i);

#endif
