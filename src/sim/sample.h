/* Random sampling for emission: values (constant, uniform, clamped normal),
 * points uniform over shapes, and directions uniform over spherical caps.
 * Every sampler consumes a fixed number of draws for a given input, so the
 * stream stays aligned whatever the values drawn. Each comes in two forms
 * with the same bits: one sample from a generator, and a block of n from
 * units already drawn (unit d of sample k at u[d][k], the draws in the
 * order the one-sample form takes them), in straight loops over columns. */
#ifndef PFX_SAMPLE_H
#define PFX_SAMPLE_H

#include <stdbool.h>
#include <stddef.h>

#include "base/rng.h"
#include "model/effect.h"

/* One sample of v. Constant: no draw. Uniform: one. Normal: two
 * (Box-Muller), clamped to [lo, hi]. */
double pfx_sample_value(const pfx_value *v, pfx_rng *r);
/* The units (pfx_rng_unit draws) one sample of v takes: 0, 1 or 2. */
unsigned pfx_sample_value_units(const pfx_value *v);
/* out[k] = the sample of v from units u0[k] (and u1[k] for a normal);
 * a column a distribution does not read may be any readable one. */
void pfx_sample_value_n(const pfx_value *v, size_t n, const double *u0, const double *u1,
                        double *out);

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
/* The units one pfx_sample_shape takes: 0 to 3, as above. */
unsigned pfx_sample_shape_units(const pfx_shape *s);
/* n points (out[0][k], out[1][k], out[2][k]) and, unless normal is NULL,
 * their normals, from the units u[0..2][k] (rows past the shape's units
 * are read, not used: any readable columns). */
void pfx_sample_shape_n(const pfx_shape *s, size_t n, const double *const u[3],
                        double *const out[3], double *const normal[3]);

/* A unit vector uniform over the spherical cap of half-angle `spread` (radians)
 * around unit `axis`: cos(theta) uniform in [cos(spread), 1], azimuth
 * uniform. (Drawing theta itself uniformly would crowd the axis.) Two units. */
void pfx_sample_cone(const double axis[3], double spread, pfx_rng *r, double out[3]);
/* n such vectors from units u0[k] and u1[k], about the axis (axis[0][k],
 * axis[1][k], axis[2][k]), or about (axis[0][0], axis[1][0], axis[2][0])
 * for all where one_axis. */
void pfx_sample_cone_n(size_t n, const double *const axis[3], bool one_axis, double spread,
                       const double *u0, const double *u1, double *const out[3]);

/* A unit vector uniform over the whole sphere: z uniform in [-1, 1]. */
void pfx_sample_direction(pfx_rng *r, double out[3]);

#endif
