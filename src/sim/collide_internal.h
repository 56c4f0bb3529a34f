/* What the files of the collide pass share; private to src/sim/collide*.c.
 * collide.c runs the pass (broad phase, then each near particle),
 * collide_shape.c holds the exact geometry of each deflector shape (time of
 * impact, constraint, snap), collide_resolve.c the response and the walk
 * through a step from hit to hit. All three are built with -fno-math-errno
 * (CMakeLists.txt), as the one file they came from was. */
#ifndef PFX_COLLIDE_INTERNAL_H
#define PFX_COLLIDE_INTERNAL_H

#include <math.h>

#include "sim/collide.h"

/* Or'ed into a hit count: the particle was killed or stuck. */
enum { TERMINAL = 1 << 30 };

/* Relative size of rounding noise in a component that was removed exactly
 * in real arithmetic (a few ulps of the vector it came from). */
#define NOISE 1e-12
/* Distance, relative to the coordinates, within which a point is on a
 * surface: 2^-21, four float ulps. */
#define TOUCH 4.76837158203125e-7

/* fmin/fmax are library calls on some targets; the hot loop has no NaNs */
static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }

/* A deflector in the form the hit tests need, derived once per call. */
typedef struct prep {
    pfx_deflector_shape shape;
    bool thin;           /* disc, bounded plane: either face, no wrong side */
    bool inside;         /* sphere, box */
    double p[3], n[3];   /* point or centre; unit normal */
    double u[3], w[3];   /* bounded plane: in-plane unit axes */
    double hu, hw;       /* bounded plane: half width and height */
    double r;            /* disc, sphere */
    double lo[3], hi[3]; /* box: face coordinates c -+ h, so a snapped face is exactly 0 */
    double edge_tol;     /* box: slack of the face bounds, so an edge hit is never lost */
    double mu_slide;     /* friction while sliding: the midpoint of the range */
} prep;

/* One particle's working state through the step. side[k]: 0 when deflector
 * k does not concern it this step (its chance says pass, or it started on
 * the solid side), +1 for an active one-sided shape, and for a thin shape
 * the side of its plane the particle is on (+1 in front of the normal). */
typedef struct body {
    double x[3], v[3], a[3];
    int8_t side[PFX_COLLIDE_MAX_DEFLECTORS];
    uint32_t i;
    int contacts; /* surfaces it rests on this step: 0, 1, 2 (a crease) or 3 (wedged) */
    size_t ck;    /* the first one */
    double cn[3]; /* and its normal */
    double fric;  /* Coulomb deceleration: sum of mu |a_N| over them */
    long slide;   /* an inside sphere it rests on (see hold), or -1 */
} body;

typedef struct ctx {
    const pfx_deflector *defl;
    const prep *pr;
    size_t nd;
    double dt;
    const pfx_collide_pool *pool;
    pfx_hit_fn on_hit;
    void *user;
    pfx_collide_stats *stats;
    size_t first; /* the pass's index of defl[0] (a view of one of its deflectors) */
} ctx;

typedef struct hit {
    double s; /* time after the segment's start */
    size_t k;
    int face; /* box: 2 * axis + (0: high face, 1: low face) */
    int side; /* thin shapes: the face hit (+1: front of the normal) */
} hit;

static inline double dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The point at time s on the path x + v s + a s^2/2. */
static inline void pos_at(const double x[3], const double v[3], const double a[3], double s,
                          double out[3]) {
    for (int j = 0; j < 3; j++)
        out[j] = x[j] + (v[j] + 0.5 * a[j] * s) * s;
}

/* collide_shape.c: the geometry of one deflector. */
void pfx_collide_prepare(const pfx_deflector *d, prep *p);
double pfx_collide_constraint(const prep *p, int side, const double x[3], double n[3]);
bool pfx_collide_detect(const prep *p, int side, const double x[3], const double v[3],
                        const double a[3], double T, double touch, hit *h);
void pfx_collide_snap(const prep *p, const hit *h, double x[3], double n[3]);

/* collide_slide.c: the particles of a chunk near one plane at once. The
 * index of the first of c's deflectors of the one kind it handles (an
 * infinite plane that bounces), or -1; then, for c a view of that one
 * deflector, of particles [i0, i0 + m) where todo (indexed from i0) is
 * set, each that starts on the plane and slides through the step is
 * resolved and stored exactly as collide_one would, each that hits
 * nothing is left as it would leave it, and each that strikes it once
 * from the air is resolved likewise (all flagged at rest as
 * collide_one_rest would), its todo cleared; returns the contacts (the
 * impacts go to c->stats). */
int pfx_collide_lane_plane(const ctx *c);
uint64_t pfx_collide_slide(const ctx *c, uint32_t i0, uint32_t m, uint8_t *todo);
/* Particles a chunk of the walks holds. With on_hit events a strike the
 * walk resolved waits: pfx_collide_slide leaves its todo mark as
 * PFX_TODO_WALKED (where m <= PFX_SLIDE_CHUNK), and the pass commits it
 * in pool order with pfx_collide_slide_commit(c, i0, j) (the same i0,
 * before the thread's next pfx_collide_slide): stored and its event
 * raised, or false where the general pass must take it after all. */
enum { PFX_SLIDE_CHUNK = 256, PFX_TODO_WALKED = 2 };
bool pfx_collide_slide_commit(const ctx *c, uint32_t i0, uint32_t j);

/* collide_resolve.c: one particle through one step. */
int pfx_collide_resolve(const ctx *c, body *b);
/* The resilience (which 0) or friction (1) of particle i's next impact on
 * deflector d, drawn from `range` (see its body). */
double pfx_collide_draw(const ctx *c, const pfx_deflector *d, uint32_t i, uint64_t which,
                        const double range[2]);
void pfx_collide_store(const ctx *c, body *b);

#endif
