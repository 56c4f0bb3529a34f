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

/* Births per block: a block's draws, samples and writes go column by
 * column through straight loops (sim/birth.c, sim/newborn.c), so the
 * compiler runs them 4 or 8 births at once. 64 keeps the columns an
 * emitter uses in the first-level cache and wastes little on a short run. */
#define PFX_BIRTH_BLOCK 64
/* The most units (pfx_rng_unit draws) a birth takes: the shape's 3, the
 * spread's 2, 2 for each of ten values, 1 for the tint. */
#define PFX_BIRTH_UNITS_MAX 26

/* A block of births of one emitter, column by column: what the caller
 * sets (count, times, units, parents' places and hit normals), what
 * pfx_birth_draw_block computes from them (each birth's state and drawn
 * attributes, in double), and its working columns. About 52 KB, allocated
 * once per simulation; of it a block touches the columns its emitter
 * needs. */
typedef struct pfx_birth_block {
    uint32_t n; /* births in the block, at most PFX_BIRTH_BLOCK */
    /* In: birth times; unit d of birth k at u[d][k], in the order of
     * pfx_birth_units; with `placed` (sub-emitter children) the parent's
     * position, added to the pose, and, where has_normal[k], a world-space
     * hit normal replacing the shape's normal. */
    double t[PFX_BIRTH_BLOCK];
    double u[PFX_BIRTH_UNITS_MAX][PFX_BIRTH_BLOCK];
    double drawn[PFX_BIRTH_UNITS_MAX * PFX_BIRTH_BLOCK]; /* the units in draw order */
    bool placed;
    double place[3][PFX_BIRTH_BLOCK], hit_normal[3][PFX_BIRTH_BLOCK];
    bool has_normal[PFX_BIRTH_BLOCK];
    /* Out: position and velocity in the world, and the attributes. */
    double pos[3][PFX_BIRTH_BLOCK], vel[3][PFX_BIRTH_BLOCK];
    double life[PFX_BIRTH_BLOCK], s0[PFX_BIRTH_BLOCK], s1[PFX_BIRTH_BLOCK], gs[PFX_BIRTH_BLOCK];
    double q[PFX_BIRTH_BLOCK], mass[PFX_BIRTH_BLOCK], tint[PFX_BIRTH_BLOCK];
    double angle[PFX_BIRTH_BLOCK], spin[PFX_BIRTH_BLOCK];
    /* Working columns: the shape's point and normal, the direction before
     * and after the spread, speed, distance, and each birth's pose where
     * the emitter moves. */
    double local[3][PFX_BIRTH_BLOCK], normal[3][PFX_BIRTH_BLOCK];
    double base[3][PFX_BIRTH_BLOCK], dir[3][PFX_BIRTH_BLOCK];
    double speed[PFX_BIRTH_BLOCK], distance[PFX_BIRTH_BLOCK];
    emitter_pose pose[PFX_BIRTH_BLOCK];
} pfx_birth_block;

/* The units one birth of em takes (twice that many generator outputs, the
 * same for every birth, so skipped births can be jumped over): the
 * shape's, the spread's two, then speed, lifetime, distance, and the
 * attributes the emitter keeps (pfx_needs_*), in that order. */
unsigned pfx_birth_units(const pfx_emitter *em);

/* Computes the births of block b (b->n, b->t, b->u and, for children,
 * b->place and the hit normals set) at their times: the emitter's pose,
 * the shape's point, the direction and its spread, the values. Bits do not
 * depend on how births are split into blocks. */
void pfx_birth_draw_block(const pfx_emitter *em, pfx_birth_block *b);

#endif
