/* Self-shadowing smoke (light: { shadows: true }): an opacity shadow map
 * built on the CPU each frame. The particles' optical depth is splatted
 * into a grid seen from the light (PFX_SHADOW_SIDE x PFX_SHADOW_SIDE cells
 * across the light, PFX_SHADOW_SLICES slices along it) and summed towards
 * the light, so that each cell holds the optical depth between it and the
 * light; lit sprites read it per fragment (render/shader.c) and scale the
 * light's direct term by exp(-depth). Plain data and arithmetic in a fixed
 * order: the same bytes on every run, thread count and GL backend. */
#ifndef PFX_RENDER_SHADOW_H
#define PFX_RENDER_SHADOW_H

#include <stdbool.h>
#include <stddef.h>

#define PFX_SHADOW_SIDE 64
#define PFX_SHADOW_SLICES 32
#define PFX_SHADOW_CELLS (PFX_SHADOW_SIDE * PFX_SHADOW_SIDE * PFX_SHADOW_SLICES)

/* The grid: cell (i, j, k) spans [lo + i du, lo + (i + 1) du) along axis
 * 0 (and likewise j, k along axes 1, 2: axis 2 is the direction the light
 * travels). depth holds, x fastest, the optical depth from the light to
 * the centre of each cell: the whole of the slices before it and half of
 * its own. */
typedef struct pfx_shadow_volume {
    double axis[3][3]; /* unit, right-handed; axis[2] the light's travel */
    double lo[3], hi[3];
    bool empty; /* nothing bounded yet; after frame: nothing to shadow */
    float depth[PFX_SHADOW_CELLS];
} pfx_shadow_volume;

/* Starts a frame's volume for a light travelling along the unit vector
 * dir. Then pfx_shadow_bound every caster and receiver, pfx_shadow_frame,
 * pfx_shadow_splat every caster, pfx_shadow_finish. */
void pfx_shadow_begin(pfx_shadow_volume *v, const double dir[3]);
/* Widens the grid to hold a sphere of radius r at p. */
void pfx_shadow_bound(pfx_shadow_volume *v, const float p[3], float r);
/* Fixes the grid (a cell's margin round what was bounded) and clears it. */
void pfx_shadow_frame(pfx_shadow_volume *v);
/* Adds a caster of radius r and alpha a at p: an optical depth a f(d) a
 * cell over its disc across the light, f(d) = (1 - d^2)^2 the round
 * sprite's falloff at d = distance / r, scaled so that its integral over
 * the disc is a pi r^2 / 3 (the round sprite's), however few cells it
 * covers; in the one cell holding p when it covers no cell's centre. */
void pfx_shadow_splat(pfx_shadow_volume *v, const float p[3], float r, float a);
/* Sums the slices towards the light. */
void pfx_shadow_finish(pfx_shadow_volume *v);
/* The affine map from world points to the grid's texture coordinates
 * ([0, 1] over lo..hi on each axis), as a column-major 4x4 matrix. */
void pfx_shadow_texture_matrix(const pfx_shadow_volume *v, double m[16]);

#endif
