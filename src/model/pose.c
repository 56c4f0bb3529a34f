/* Where an emitter is at any time: its keyframed position and rotation,
 * and the rotation matrix of Euler angles. Pure functions of the model. */
#include <math.h>
#include <string.h>

#include "model/effect.h"

/* The emitter's placement at effect time t: position, rotation matrix
 * (angles X then Y then Z about fixed axes) and velocity (the slope of the
 * position keyframes; zero when fixed). Keyframes interpolate linearly and
 * hold before the first and after the last. */

static size_t key_segment(const pfx_keys3 *k, double t, double *u) {
    size_t i = 0;
    while (i + 2 < k->count && k->t[i + 1] <= t)
        i++;
    double span = k->t[i + 1] - k->t[i];
    double x = (t - k->t[i]) / span;
    *u = x < 0 ? 0 : x > 1 ? 1 : x;
    return i;
}

void pfx_rotation_from_angles(const double rad[3], double m[9]) {
    double cx = cos(rad[0]), sx = sin(rad[0]), cy = cos(rad[1]), sy = sin(rad[1]), cz = cos(rad[2]),
           sz = sin(rad[2]);
    double r[9] = {cz * cy,
                   cz * sy * sx - sz * cx,
                   cz * sy * cx + sz * sx,
                   sz * cy,
                   sz * sy * sx + cz * cx,
                   sz * sy * cx - cz * sx,
                   -sy,
                   cy * sx,
                   cy * cx};
    memcpy(m, r, sizeof r);
}

void pfx_emitter_pose_at(const pfx_emitter *em, double t, emitter_pose *p) {
    if (em->key_period > 0) /* a looping effect repeats its keyframes */
        t = fmod(t, em->key_period);
    memcpy(p->position, em->position, sizeof p->position);
    memcpy(p->rotation, em->rotation, sizeof p->rotation);
    p->velocity[0] = p->velocity[1] = p->velocity[2] = 0;
    double u;
    if (em->position_keys.count > 1) {
        const pfx_keys3 *k = &em->position_keys;
        size_t i = key_segment(k, t, &u);
        bool moving = t > k->t[0] && t < k->t[k->count - 1];
        for (int a = 0; a < 3; a++) {
            p->position[a] = k->v[i][a] + (k->v[i + 1][a] - k->v[i][a]) * u;
            if (moving)
                p->velocity[a] = (k->v[i + 1][a] - k->v[i][a]) / (k->t[i + 1] - k->t[i]);
        }
    }
    if (em->rotation_keys.count > 1) {
        const pfx_keys3 *k = &em->rotation_keys;
        size_t i = key_segment(k, t, &u);
        double rad[3];
        for (int a = 0; a < 3; a++)
            rad[a] = k->v[i][a] + (k->v[i + 1][a] - k->v[i][a]) * u;
        pfx_rotation_from_angles(rad, p->rotation);
    }
}
