/* The pose of an emitter at any time and the draws of one birth. Every
 * birth consumes the same number of generator outputs for its emitter (no
 * rejection sampling), which is what lets the simulation jump over births
 * it does not need without changing any other particle. */
#include "sim/birth.h"

#include <math.h>
#include <string.h>

#include "sim/sample.h"

static void rotate(const double m[9], const double v[3], double out[3]) {
    for (int a = 0; a < 3; a++)
        out[a] = m[3 * a] * v[0] + m[3 * a + 1] * v[1] + m[3 * a + 2] * v[2];
}

/* The thesis's two-angle spread: alpha_r uniform in [-alpha/2, alpha/2]
 * about Z, then beta_r in [-beta/2, beta/2] about X (two draws, like the
 * cone). Not uniform over any cap: it is what the thesis specifies. */
static void two_angle_spread(const pfx_emitter *em, const double d[3], pfx_rng *r, double out[3]) {
    double a = (pfx_rng_unit(r) - 0.5) * em->spread_alpha;
    double b = (pfx_rng_unit(r) - 0.5) * em->spread_beta;
    double x = d[0] * cos(a) - d[1] * sin(a), y = d[0] * sin(a) + d[1] * cos(a), z = d[2];
    out[0] = x;
    out[1] = y * cos(b) - z * sin(b);
    out[2] = y * sin(b) + z * cos(b);
}

void pfx_birth_draw(const pfx_emitter *em, double t, pfx_rng *r, const double place[3],
                    const double normal_override[3], birth_draws *b) {
    emitter_pose pose;
    pfx_emitter_pose_at(em, t, &pose);
    if (place)
        for (int a = 0; a < 3; a++)
            pose.position[a] += place[a];
    double local[3], normal[3], base[3], dir[3];
    pfx_sample_shape(&em->shape, r, local, normal);
    if (normal_override) /* a world-space hit normal: into the emitter's frame (R^T) */
        for (int a = 0; a < 3; a++)
            normal[a] = pose.rotation[a] * normal_override[0] +
                        pose.rotation[3 + a] * normal_override[1] +
                        pose.rotation[6 + a] * normal_override[2];
    double len = sqrt(local[0] * local[0] + local[1] * local[1] + local[2] * local[2]);
    switch (em->direction_mode) {
    case PFX_DIRECTION_NORMAL:
        memcpy(base, normal, sizeof base);
        break;
    case PFX_DIRECTION_RADIAL:
    case PFX_DIRECTION_INWARD: {
        double sign = em->direction_mode == PFX_DIRECTION_INWARD ? -1 : 1;
        for (int a = 0; a < 3; a++)
            base[a] = len > 0 ? sign * local[a] / len : sign * normal[a];
        break;
    }
    case PFX_DIRECTION_TANGENT: {
        /* Y x local = (z, 0, -x): the orbit direction about the shape's
         * axis (counter-clockwise seen from +Y), whatever the height. On
         * the axis there is no orbit: along the axis (+Y), as `direction`'s
         * default. */
        double h = sqrt(local[0] * local[0] + local[2] * local[2]);
        base[0] = h > 0 ? local[2] / h : 0;
        base[1] = h > 0 ? 0 : 1;
        base[2] = h > 0 ? -local[0] / h : 0;
        break;
    }
    default:
        memcpy(base, em->direction, sizeof base);
    }
    if (em->spread_two_angle)
        two_angle_spread(em, base, r, dir);
    else
        pfx_sample_cone(base, em->spread, r, dir);
    double speed = pfx_sample_value(&em->speed, r);
    b->life = pfx_sample_value(&em->lifetime, r);
    double distance = pfx_sample_value(&em->distance, r);
    b->s0 = pfx_needs_size0(em) ? pfx_sample_value(&em->size_start, r) : 0;
    b->s1 = pfx_needs_size1(em) ? pfx_sample_value(&em->size_end, r) : 0;
    b->gs =
        pfx_needs_gravity_scale(em) ? pfx_sample_value(&em->gravity_scale, r) : em->gravity_scale.a;
    b->q = pfx_needs_charge(em) ? pfx_sample_value(&em->charge, r) : em->charge.a;
    b->mass = pfx_needs_mass(em) ? pfx_sample_value(&em->mass, r) : em->mass.a;
    b->tint = pfx_needs_tint(em) ? pfx_rng_unit(r) : 0;
    b->angle = pfx_needs_angle(em) ? pfx_sample_value(&em->angle, r) : em->angle.a;
    b->spin = pfx_needs_spin(em) ? pfx_sample_value(&em->spin, r) : em->spin.a;
    double world_local[3], world_dir[3];
    rotate(pose.rotation, local, world_local);
    rotate(pose.rotation, dir, world_dir);
    for (int a = 0; a < 3; a++) {
        b->pos[a] = pose.position[a] + world_local[a] + world_dir[a] * distance;
        b->vel[a] = world_dir[a] * speed + em->inherit_velocity * pose.velocity[a];
    }
}
