/* Random sampling for emission: values (constant, uniform, clamped normal),
 * points uniform over shapes, and directions uniform over spherical caps.
 * Every sampler consumes a fixed number of draws for a given input, so the
 * stream stays aligned whatever the values drawn. */
#ifndef PFX_SAMPLE_H
#define PFX_SAMPLE_H

#include "base/rng.h"
#include "model/effect.h"

/* One sample of v. Constant: no draw. Uniform: one. Normal: two
 * (Box-Muller), clamped to [lo, hi]. */
double pfx_sample_value(const pfx_value *v, pfx_rng *r);

/* A point uniform over the shape in its local frame (by volume, area or
 * length as s->from says; conventions in src/compile/compile_shape.c), and
 * the unit outward normal there: the surface's normal for surface and
 * flat-area samples, the rim's in-plane outward normal for edges, and for
 * volume samples the direction from the centre (sphere, hemisphere, box) or
 * from the axis (cylinder; cone: +Y tilted outward by angle * rho / R).
 * Draws per call are fixed by type and mode: 0 units (point), 1 (line,
 * edges), 2 (areas; sphere, hemisphere, cylinder and cone surfaces) or 3
 * (volumes, box surface, mesh), each unit two generator outputs. */
void pfx_sample_shape(const pfx_shape *s, pfx_rng *r, double out[3], double normal[3]);

/* A unit vector uniform over the spherical cap of half-angle `spread` (radians)
 * around unit `axis`: cos(theta) uniform in [cos(spread), 1], azimuth
 * uniform. (Drawing theta itself uniformly would crowd the axis.) */
void pfx_sample_cone(const double axis[3], double spread, pfx_rng *r, double out[3]);

/* A unit vector uniform over the whole sphere: z uniform in [-1, 1]. */
void pfx_sample_direction(pfx_rng *r, double out[3]);

#endif
