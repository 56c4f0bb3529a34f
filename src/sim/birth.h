/* One birth: the emitter's pose at a time (keyframed position and
 * rotation), and every random draw of a new particle in a fixed order (shape
 * point and normal, direction, speed, lifetime, size, ...). Shared by the
 * scheduled births (sim.c) and sub-emitter births (spawn.c). */
#ifndef PFX_BIRTH_H
#define PFX_BIRTH_H

#include "base/rng.h"
#include "model/effect.h"
#include "sim/motion.h"

/* Which optional per-particle values an emitter draws and keeps. */
static inline bool pfx_needs_gravity_scale(const pfx_emitter *em) {
    return em->gravity_scale.dist != PFX_DIST_CONST;
}
static inline bool pfx_needs_size0(const pfx_emitter *em) { return em->size_varies; }
static inline bool pfx_needs_size1(const pfx_emitter *em) {
    return em->size_varies && !em->size_same;
}
static inline bool pfx_needs_angle(const pfx_emitter *em) {
    return em->angle.dist != PFX_DIST_CONST;
}
static inline bool pfx_needs_spin(const pfx_emitter *em) {
    return !em->spin_curve && em->spin.dist != PFX_DIST_CONST;
}
static inline bool pfx_needs_tint(const pfx_emitter *em) {
    return em->color_mode != PFX_COLOR_OVER_LIFE;
}
static inline unsigned pfx_motion_columns_of(const pfx_emitter *em) {
    return em->motion ? pfx_motion_columns(em->motion) : 0;
}
static inline bool pfx_needs_charge(const pfx_emitter *em) {
    return (pfx_motion_columns_of(em) & PFX_COLUMN_CHARGE) && em->charge.dist != PFX_DIST_CONST;
}
static inline bool pfx_needs_mass(const pfx_emitter *em) {
    return (pfx_motion_columns_of(em) & PFX_COLUMN_MASS) && em->mass.dist != PFX_DIST_CONST;
}
static inline bool pfx_needs_birth(const pfx_emitter *em) {
    return (pfx_motion_columns_of(em) & PFX_COLUMN_BIRTH) != 0;
}
/* A hit count keys the random draws of a deflector response and numbers
 * on_hit events: needed where some deflector's resilience or friction is
 * a range, or a sub-emitter fires on hits. */
static inline bool pfx_needs_hit_count(const pfx_emitter *em) {
    for (size_t k = 0; k < em->spawn_count; k++)
        if (em->spawns[k].event == PFX_SPAWN_HIT && em->deflector_count)
            return true;
    for (size_t k = 0; k < em->deflector_count; k++) {
        const pfx_deflector *d = &em->deflectors[k];
        if (d->resilience[0] != d->resilience[1] || d->friction[0] != d->friction[1])
            return true;
    }
    return false;
}
/* Carried accelerations (sim/motion.h, carry_accel) cost 12 bytes a
 * particle; in a pool of fewer than PFX_CARRY_MIN_PARTICLES they would save
 * under 0.1 ms a step, so such a pool evaluates twice and stays small. Both
 * ways give the same bits. */
#define PFX_CARRY_MIN_PARTICLES 4096
static inline bool pfx_needs_carried_accel(const pfx_emitter *em) {
    return em->motion && em->capacity >= PFX_CARRY_MIN_PARTICLES &&
           pfx_motion_carries_accel(em->motion);
}

/* What one birth draws (see pfx_birth_draw). */
typedef struct birth_draws {
    double pos[3], vel[3];
    double life, s0, s1, gs, q, mass, tint, angle, spin;
} birth_draws;

/* Draws birth at effect time t from r: a fixed number of generator outputs
 * for the emitter, so skipped births can be jumped over. `place` overrides
 * the pose (a sub-emitter's parent particle: position and velocity added,
 * the emitter's own position is an offset); `normal` overrides the shape's
 * normal for `direction: normal` (a deflector hit). Both may be NULL. */
void pfx_birth_draw(const pfx_emitter *em, double t, pfx_rng *r, const double place[3],
                    const double normal[3], birth_draws *b);

#endif
