/* The pose of an emitter at any time and the draws of a block of births.
 * Every birth consumes the same number of generator outputs for its
 * emitter (no rejection sampling), which is what lets the simulation jump
 * over births it does not need without changing any other particle, and
 * lets a block draw all its units first: then each stage (shape, direction,
 * spread, values, placement) is one loop over the block's columns, the
 * same arithmetic per birth as one at a time, so the same bits. */
#include "sim/birth.h"

#include <assert.h>
#include <math.h>
#include <string.h>

#include "base/clones.h"
#include "sim/sample.h"

/* Where each draw of a birth starts among its units (pfx_birth_units's
 * order); a value the emitter does not draw takes none. */
typedef struct birth_layout {
    unsigned shape, spread, speed, life, distance, s0, s1, gs, q, mass, tint, angle, spin;
    unsigned units; /* in all */
} birth_layout;

static birth_layout layout_of(const pfx_emitter *em) {
    birth_layout L = {0};
    unsigned d = pfx_sample_shape_units(&em->shape);
    L.spread = d, d += 2;
#define TAKE(field, value, drawn) L.field = d, d += (drawn) ? pfx_sample_value_units(&(value)) : 0
    TAKE(speed, em->speed, true);
    TAKE(life, em->lifetime, true);
    TAKE(distance, em->distance, true);
    TAKE(s0, em->size_start, pfx_needs_size0(em));
    TAKE(s1, em->size_end, pfx_needs_size1(em));
    TAKE(gs, em->gravity_scale, pfx_needs_gravity_scale(em));
    TAKE(q, em->charge, pfx_needs_charge(em));
    TAKE(mass, em->mass, pfx_needs_mass(em));
    L.tint = d, d += pfx_needs_tint(em) ? 1 : 0;
    TAKE(angle, em->angle, pfx_needs_angle(em));
    TAKE(spin, em->spin, pfx_needs_spin(em));
#undef TAKE
    L.units = d;
    assert(d <= PFX_BIRTH_UNITS_MAX);
    return L;
}

unsigned pfx_birth_units(const pfx_emitter *em) { return layout_of(em).units; }

/* Unit row d of the block (any row past the last: a value that does not
 * read it). */
static const double *row(const pfx_birth_block *b, unsigned d) {
    return b->u[d < PFX_BIRTH_UNITS_MAX ? d : PFX_BIRTH_UNITS_MAX - 1];
}

/* Column `out` of the block: the value v drawn from its units at `at`
 * where `drawn`, else `otherwise` (the constant the birth keeps). */
static void values(const pfx_birth_block *b, const pfx_value *v, unsigned at, bool drawn,
                   double otherwise, double *out) {
    if (drawn) {
        pfx_sample_value_n(v, b->n, row(b, at), row(b, at + 1), out);
    } else {
        for (uint32_t k = 0; k < b->n; k++)
            out[k] = otherwise;
    }
}

static void rotate(const double m[9], const double v[3], double out[3]) {
    for (int a = 0; a < 3; a++)
        out[a] = m[3 * a] * v[0] + m[3 * a + 1] * v[1] + m[3 * a + 2] * v[2];
}

/* The thesis's two-angle spread: alpha_r uniform in [-alpha/2, alpha/2]
 * about Z, then beta_r in [-beta/2, beta/2] about X (two draws, like the
 * cone). Not uniform over any cap: it is what the thesis specifies. */
static void two_angle_spread(const pfx_emitter *em, const double d[3], double u0, double u1,
                             double out[3]) {
    double a = (u0 - 0.5) * em->spread_alpha;
    double b = (u1 - 0.5) * em->spread_beta;
    double x = d[0] * cos(a) - d[1] * sin(a), y = d[0] * sin(a) + d[1] * cos(a), z = d[2];
    out[0] = x;
    out[1] = y * cos(b) - z * sin(b);
    out[2] = y * sin(b) + z * cos(b);
}

/* The base direction of each birth before the spread, in the emitter's
 * frame, by the emitter's direction mode (the constant direction needs no
 * column: the spread reads em->direction). */
PFX_CLONES
static void base_directions(const pfx_emitter *em, pfx_birth_block *restrict b) {
    const uint32_t n = b->n;
    switch (em->direction_mode) {
    case PFX_DIRECTION_RADIAL:
    case PFX_DIRECTION_INWARD: {
        const double sign = em->direction_mode == PFX_DIRECTION_INWARD ? -1 : 1;
        for (uint32_t k = 0; k < n; k++) {
            const double x = b->local[0][k], y = b->local[1][k], z = b->local[2][k];
            const double len = sqrt(x * x + y * y + z * z);
            b->base[0][k] = len > 0 ? sign * x / len : sign * b->normal[0][k];
            b->base[1][k] = len > 0 ? sign * y / len : sign * b->normal[1][k];
            b->base[2][k] = len > 0 ? sign * z / len : sign * b->normal[2][k];
        }
        break;
    }
    case PFX_DIRECTION_TANGENT:
        /* Y x local = (z, 0, -x): the orbit direction about the shape's
         * axis (counter-clockwise seen from +Y), whatever the height. On
         * the axis there is no orbit: along the axis (+Y), as `direction`'s
         * default. */
        for (uint32_t k = 0; k < n; k++) {
            const double x = b->local[0][k], z = b->local[2][k];
            const double h = sqrt(x * x + z * z);
            b->base[0][k] = h > 0 ? z / h : 0;
            b->base[1][k] = h > 0 ? 0 : 1;
            b->base[2][k] = h > 0 ? -x / h : 0;
        }
        break;
    default:
        break;
    }
}

/* Each birth's position and velocity in the world from its pose: the
 * shape's point and the direction turned by the rotation, the point moved
 * `distance` along the direction, the emitter's velocity inherited. With a
 * fixed pose (no keyframes, no parent) every birth has `fixed`: the loop
 * then reads it as constants. */
#define PLACE_LOOP(pose_k)                                                                         \
    for (uint32_t k = 0; k < n; k++) {                                                             \
        const emitter_pose *p = (pose_k);                                                          \
        const double local[3] = {b->local[0][k], b->local[1][k], b->local[2][k]};                  \
        const double dir[3] = {b->dir[0][k], b->dir[1][k], b->dir[2][k]};                          \
        double wl[3], wd[3];                                                                       \
        rotate(p->rotation, local, wl);                                                            \
        rotate(p->rotation, dir, wd);                                                              \
        for (int a = 0; a < 3; a++) {                                                              \
            b->pos[a][k] = p->position[a] + wl[a] + wd[a] * b->distance[k];                        \
            b->vel[a][k] = wd[a] * b->speed[k] + inherit * p->velocity[a];                         \
        }                                                                                          \
    }

PFX_CLONES
static void place_fixed(const emitter_pose *restrict fixed, double inherit,
                        pfx_birth_block *restrict b) {
    const uint32_t n = b->n;
    PLACE_LOOP(fixed)
}

static void place_each(double inherit, pfx_birth_block *restrict b) {
    const uint32_t n = b->n;
    PLACE_LOOP(&b->pose[k])
}

/* The three rows of a block's vector column, as the samplers take them. */
#define COLUMNS(c) ((double *const[3]){(c)[0], (c)[1], (c)[2]})

void pfx_birth_draw_block(const pfx_emitter *em, pfx_birth_block *b) {
    const birth_layout L = layout_of(em);
    const uint32_t n = b->n;
    /* The pose: the emitter's own where nothing moves it, else each
     * birth's, with its parent's position added. */
    const bool fixed = em->position_keys.count <= 1 && em->rotation_keys.count <= 1;
    emitter_pose fixed_pose;
    if (fixed)
        pfx_emitter_pose_at(em, 0, &fixed_pose);
    if (!fixed || b->placed)
        for (uint32_t k = 0; k < n; k++) {
            emitter_pose *p = &b->pose[k];
            if (fixed)
                *p = fixed_pose;
            else
                pfx_emitter_pose_at(em, b->t[k], p);
            if (b->placed)
                for (int a = 0; a < 3; a++)
                    p->position[a] += b->place[a][k];
        }
    /* The shape's points; their normals only where a direction reads them. */
    const pfx_direction_mode mode = em->direction_mode;
    const bool normals = mode == PFX_DIRECTION_NORMAL || mode == PFX_DIRECTION_RADIAL ||
                         mode == PFX_DIRECTION_INWARD;
    pfx_sample_shape_n(
        &em->shape, n,
        (const double *const[3]){row(b, L.shape), row(b, L.shape + 1), row(b, L.shape + 2)},
        COLUMNS(b->local), normals ? COLUMNS(b->normal) : NULL);
    if (normals && b->placed)
        for (uint32_t k = 0; k < n; k++) {
            if (!b->has_normal[k])
                continue;
            /* a world-space hit normal: into the emitter's frame (R^T) */
            const double *m = b->pose[k].rotation,
                         h[3] = {b->hit_normal[0][k], b->hit_normal[1][k], b->hit_normal[2][k]};
            for (int a = 0; a < 3; a++)
                b->normal[a][k] = m[a] * h[0] + m[3 + a] * h[1] + m[6 + a] * h[2];
        }
    base_directions(em, b);
    const bool one_axis = mode != PFX_DIRECTION_NORMAL && mode != PFX_DIRECTION_RADIAL &&
                          mode != PFX_DIRECTION_INWARD && mode != PFX_DIRECTION_TANGENT;
    const double *axis[3] = {&em->direction[0], &em->direction[1], &em->direction[2]};
    if (!one_axis)
        for (int a = 0; a < 3; a++)
            axis[a] = mode == PFX_DIRECTION_NORMAL ? b->normal[a] : b->base[a];
    const double *su = row(b, L.spread), *sv = row(b, L.spread + 1);
    if (em->spread_two_angle) {
        for (uint32_t k = 0; k < n; k++) {
            double d[3] = {em->direction[0], em->direction[1], em->direction[2]}, o[3];
            if (!one_axis)
                d[0] = axis[0][k], d[1] = axis[1][k], d[2] = axis[2][k];
            two_angle_spread(em, d, su[k], sv[k], o);
            b->dir[0][k] = o[0], b->dir[1][k] = o[1], b->dir[2][k] = o[2];
        }
    } else {
        pfx_sample_cone_n(n, axis, one_axis, em->spread, su, sv, COLUMNS(b->dir));
    }
    values(b, &em->speed, L.speed, true, 0, b->speed);
    values(b, &em->lifetime, L.life, true, 0, b->life);
    values(b, &em->distance, L.distance, true, 0, b->distance);
    values(b, &em->size_start, L.s0, pfx_needs_size0(em), 0, b->s0);
    values(b, &em->size_end, L.s1, pfx_needs_size1(em), 0, b->s1);
    values(b, &em->gravity_scale, L.gs, pfx_needs_gravity_scale(em), em->gravity_scale.a, b->gs);
    values(b, &em->charge, L.q, pfx_needs_charge(em), em->charge.a, b->q);
    values(b, &em->mass, L.mass, pfx_needs_mass(em), em->mass.a, b->mass);
    if (pfx_needs_tint(em))
        memcpy(b->tint, row(b, L.tint), n * sizeof *b->tint);
    else
        memset(b->tint, 0, n * sizeof *b->tint);
    values(b, &em->angle, L.angle, pfx_needs_angle(em), em->angle.a, b->angle);
    values(b, &em->spin, L.spin, pfx_needs_spin(em), em->spin.a, b->spin);
    if (fixed && !b->placed)
        place_fixed(&fixed_pose, em->inherit_velocity, b);
    else
        place_each(em->inherit_velocity, b);
}
