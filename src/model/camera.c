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

/* gluLookAt's view then gluPerspective's (or glOrtho's) projection, the
 * matrices render.c builds, written out: view-space c = (s.q, u.q, -f.q)
 * for q = p - eye; perspective clip = (c.x t / aspect, c.y t) over w =
 * -c.z with t = 1 / tan(fov / 2); ortho (c.x / half-width, c.y /
 * half-height) over 1. */
bool pfx_camera_project(const pfx_camera *cam, int width, int height, const double p[3],
                        double px[2], double *depth) {
    double s[3], u[3], f[3], q[3];
    if (pfx_camera_frame(cam, s, u, f) != PFX_CAMERA_OK)
        return false;
    for (int i = 0; i < 3; i++)
        q[i] = p[i] - cam->position[i];
    double cx = s[0] * q[0] + s[1] * q[1] + s[2] * q[2];
    double cy = u[0] * q[0] + u[1] * q[1] + u[2] * q[2];
    double ahead = f[0] * q[0] + f[1] * q[1] + f[2] * q[2];
    double aspect = (double)width / (double)height, nx, ny, w;
    if (cam->ortho) {
        double half_h = 0.5 * cam->ortho_height;
        nx = cx / (half_h * aspect);
        ny = cy / half_h;
        w = 1.0;
    } else {
        double t = 1.0 / tan(0.5 * cam->fov);
        nx = cx * t / aspect;
        ny = cy * t;
        w = ahead;
    }
    if (!(w > 1e-6))
        return false;
    px[0] = (nx / w * 0.5 + 0.5) * width;
    px[1] = (ny / w * 0.5 + 0.5) * height;
    *depth = w;
    return true;
}

double pfx_camera_pixels_per_metre(const pfx_camera *cam, int height, const double p[3]) {
    if (cam->ortho)
        return height / cam->ortho_height;
    double view[3], len = 0, depth = 0;
    for (int a = 0; a < 3; a++) {
        view[a] = cam->target[a] - cam->position[a];
        len += view[a] * view[a];
    }
    len = sqrt(len);
    for (int a = 0; a < 3; a++)
        depth += (p[a] - cam->position[a]) * view[a] / (len > 0 ? len : 1);
    return depth > 1e-6 ? 0.5 * height / (tan(0.5 * cam->fov) * depth) : 0;
}
