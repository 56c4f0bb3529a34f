/* The camera's frame: the one definition of a usable camera, which compile
 * checks (with the key to blame) and render builds its matrices from. */
#include <math.h>

#include "model/effect.h"

/* Scales v to unit length; false when it is too short to have a direction. */
static bool unit(double v[3]) {
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(len > 1e-12))
        return false;
    v[0] /= len;
    v[1] /= len;
    v[2] /= len;
    return true;
}

pfx_camera_fault pfx_camera_frame(const pfx_camera *cam, double side[3], double up[3],
                                  double forward[3]) {
    double *f = forward, *s = side;
    for (int i = 0; i < 3; i++)
        f[i] = cam->target[i] - cam->position[i];
    if (!unit(f))
        return PFX_CAMERA_SAME_POINT;
    const double *w = cam->up;
    s[0] = f[1] * w[2] - f[2] * w[1];
    s[1] = f[2] * w[0] - f[0] * w[2];
    s[2] = f[0] * w[1] - f[1] * w[0];
    if (!unit(s))
        return PFX_CAMERA_UP_PARALLEL;
    up[0] = s[1] * f[2] - s[2] * f[1];
    up[1] = s[2] * f[0] - s[0] * f[2];
    up[2] = s[0] * f[1] - s[1] * f[0];
    return PFX_CAMERA_OK;
}
