/* The simulation's side of motion: a model's choice turned into the plan
 * the kernels run (what the split step folds into its exact drift, and the
 * rotation), the curl noise of `turbulence`, and the scan for non-finite
 * or exploding particles. The arithmetic of a step is in motion_impl.h;
 * the choice and the stability regions are the model's (model/motion.c,
 * model/stability.c). */
#include "sim/motion.h"

#include "sim/fast_f.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/rng.h"

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* Fill the split step's aggregates: the unregioned gravity and linear
 * damping go into the exact drift (folded), B into the rotation, the rest
 * is kicked. */
static void fold_split(pfx_motion_plan *m) {
    double kw[3] = {0, 0, 0};
    m->drift_k = 0;
    m->has_rotation = false;
    for (int a = 0; a < 3; a++)
        m->drift_g[a] = m->drift_wind[a] = 0;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        const bool unreg = f->region.kind == PFX_REGION_NONE;
        m->folded[i] = pfx_motion_force_folded(f);
        switch (f->kind) {
        case PFX_MOTION_GRAVITY:
            if (unreg) {
                m->folded[i] = true;
                for (int a = 0; a < 3; a++)
                    m->drift_g[a] += f->accel[a];
            }
            break;
        case PFX_MOTION_DRAG:
            if (unreg && f->k > 0) {
                m->folded[i] = true;
                m->drift_k += f->k;
                for (int a = 0; a < 3; a++)
                    kw[a] += f->k * f->wind[a];
            }
            break;
        case PFX_MOTION_SPRING:
            if (unreg && f->zeta > 0) {
                m->folded[i] = true;
                m->drift_k += 2 * f->zeta * sqrt(f->k);
            }
            break;
        case PFX_MOTION_MAGNETIC:
            if (norm3(f->field) > 0)
                m->has_rotation = true;
            break;
        default:
            break;
        }
    }
    m->has_kick = pfx_motion_split_kicks(m->model); /* what is not folded or rotated */
    /* Forces of x alone (gravity, attractors) or of x and t (turbulence:
     * a substep's closing kick and the next one's opening kick see one
     * time, motion_impl.h's substep_time) and operators on v alone: the
     * kicks read nothing a kick or an operator changes. (An undamped
     * spring or E would qualify too, but their loops multiply v by a zero,
     * which could flip the sign of a zero result: left out, so that carrying
     * gives the same bits always.) */
    m->kick_carries = m->has_kick;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_kind k = m->forces[i].kind;
        if (k != PFX_MOTION_GRAVITY && k != PFX_MOTION_ATTRACTOR && k != PFX_MOTION_SPIRAL &&
            k != PFX_MOTION_SPEED_LIMIT && k != PFX_MOTION_TURBULENCE)
            m->kick_carries = false;
    }
    m->kick_reads_v = m->has_kick && pfx_motion_split_kicks_v(m->model);
    if (m->drift_k > 0)
        for (int a = 0; a < 3; a++)
            m->drift_wind[a] = kw[a] / m->drift_k;
    m->uniform_rotation = m->has_rotation;
    m->omega[0] = m->omega[1] = m->omega[2] = 0;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        if (f->kind != PFX_MOTION_MAGNETIC)
            continue;
        if (f->region.kind != PFX_REGION_NONE)
            m->uniform_rotation = false;
        double qm = f->charge / (f->mass > 0 ? f->mass : 1.0);
        for (int a = 0; a < 3; a++)
            m->omega[a] -= qm * f->field[a];
    }
    if (!(norm3(m->omega) > 0))
        m->uniform_rotation = false; /* fields that cancel: the general path skips them */
}

/* The levels of the rule per particle (model/motion.c, choose_by_radius):
 * at distance r >= r0 from the attractor, with rho = r0 / r, its omega is
 * omega0 rho^(a/2) and its error term err0 rho^(b/2) (b = 3a - 2), so
 * 2^k substeps of h = dt / 2^k pass the rule's tests, omega h <= 1 and
 * err h^2 <= tol, from r = r0 max(1, (omega0 h)^(2/a), (err0 h^2 /
 * tol)^(2/b)) out. A part in 10^5 more covers the pools' float compare. */
static void radius_levels(pfx_motion_plan *p, const pfx_motion *m) {
    const pfx_motion_choice *c = &m->choice;
    p->radius_top = 0;
    if (!c->radius.on || p->steps <= 1 || p->scheme != PFX_SCHEME_SPLIT)
        return;
    const double a = c->radius.omega_pow2, b = 3 * a - 2;
    int top = 0;
    while ((1 << top) < p->steps && top < 11)
        top++;
    for (int k = 0; k < top; k++) {
        const double h = p->dt / (double)(1 << k);
        /* (a softened field is at its worst at r0: no level inside it) */
        double r = fmax(c->radius.singular ? 0 : 1, pow(c->radius.omega0 * h, 2 / a));
        r = fmax(r, pow(c->radius.err0 * h * h / c->radius.tol, 2 / b));
        p->radius_r[k] = c->radius.r0 * r * (1 + 1e-5);
        /* The pull a particle that stays outside radius_r[k] can feel: a
         * softened field's peak, or a singular one's at radius_r[k] itself
         * (so a path bound by it cannot cross radius_r[k] within the step:
         * up to the crossing the bound holds). */
        p->radius_peak[k] =
            c->radius.singular ? c->radius.peak_coef / pow(p->radius_r[k], a - 1) : c->radius.peak;
    }
    p->radius_top = top;
    p->radius_radial = true;
    for (size_t i = 0; i < m->force_count; i++)
        if (m->forces[i].kind == PFX_MOTION_SPIRAL)
            p->radius_radial = false;
}

/* Whether the forces are unregioned gravities followed by one unregioned
 * drag (operators anywhere): their sum is then (0 + g1 + g2 ...) - (k + c
 * |u|) u in the order accel adds it, which the fused kernels repeat. */
static void gravity_drag(pfx_motion_plan *p) {
    size_t drags = 0;
    p->gravity_drag = false;
    for (size_t i = 0; i < p->force_count; i++) {
        const pfx_motion_force *f = &p->forces[i];
        const bool whole = f->region.kind == PFX_REGION_NONE;
        switch (f->kind) {
        case PFX_MOTION_GRAVITY:
            if (!whole || drags)
                return;
            break;
        case PFX_MOTION_DRAG:
            if (!whole || drags++)
                return;
            p->gd_drag = i;
            break;
        case PFX_MOTION_VORTEX:
        case PFX_MOTION_SPIRAL:
        case PFX_MOTION_SPEED_LIMIT:
            break;
        default:
            return;
        }
    }
    p->gravity_drag = drags == 1;
}

void pfx_motion_plan_init(pfx_motion_plan *p, const pfx_motion *m) {
    memset(p, 0, sizeof *p);
    p->model = m;
    p->forces = m->forces;
    p->force_count = m->force_count;
    p->dt = m->choice.dt;
    p->chosen = m->choice.chosen;
    p->scheme = m->choice.scheme;
    p->steps = m->choice.steps > 0 ? m->choice.steps : 1;
    if (m->choice.radius.on && m->choice.radius.max_steps > p->steps)
        p->steps = m->choice.radius.max_steps; /* a singular attractor's innermost level */
    for (size_t i = 0; i < m->force_count; i++) {
        pfx_motion_kind k = m->forces[i].kind;
        if (k == PFX_MOTION_VORTEX || k == PFX_MOTION_SPIRAL || k == PFX_MOTION_SPEED_LIMIT)
            p->has_operators = true;
    }
    if (p->scheme == PFX_SCHEME_SPLIT)
        fold_split(p);
    radius_levels(p, m);
    gravity_drag(p);
    /* Across steps, where it pays: a turbulence evaluation (two octaves,
     * some 20 ns a particle) costs far more than reading and writing 12
     * bytes; an attractor's (about 3 ns) does not. Not with substeps per
     * particle, whose levels end a step at different substeps. */
    p->carry_accel = false;
    if (p->kick_carries && p->radius_top == 0)
        for (size_t i = 0; i < p->force_count; i++)
            if (p->forces[i].kind == PFX_MOTION_TURBULENCE && !p->folded[i])
                p->carry_accel = true;
}

bool pfx_motion_carries_accel(const pfx_motion *m) {
    pfx_motion_plan p;
    pfx_motion_plan_init(&p, m);
    return p.carry_accel;
}

void pfx_motion_plan_prepare(pfx_motion_plan *p, pfx_motion *m, double dt) {
    pfx_motion_choose(m, dt);
    pfx_motion_plan_init(p, m);
}

/* ---- Curl noise ----
 * The field is the curl of a potential psi = (n1, n2, n3) of three value
 * noises (Perlin, "An Image Synthesizer", SIGGRAPH 1985, with his 2002
 * quintic fade; curl noise after Bridson, Hourihan and Nordenstam, "Curl-
 * Noise for Procedural Fluid Flow", SIGGRAPH 2007). The three potentials
 * share one lattice: each corner is hashed once (32 bits, Wellons'
 * lowbias32 finaliser) and the hash gives all three corner values, 10
 * bits each. Within a cell, n is the trilinear blend of the corner values
 * by u = 6f^5 - 15f^4 + 10f^3, and its gradient is that blend's own exact
 * derivative (du = 30 f^2 (f-1)^2), so n is C2 and div curl psi = 0
 * holds exactly up to rounding. All float, no table: the particle loop is
 * straight arithmetic the compiler vectorises. */

/* An octave's pattern drifts along its own direction (unit vectors), so
 * octaves slide over each other and the field changes in time without
 * sources. */
static const float curl_drift[4][3] = {{0.5773503f, 0.5773503f, 0.5773503f},
                                       {-0.4082483f, 0.8164966f, 0.4082483f},
                                       {0.7071068f, -0.7071068f, 0.0f},
                                       {0.0f, 0.4472136f, -0.8944272f}};

/* One octave's curl of these value noises has an RMS component of about
 * 1.08 (measured over 10^5 points); the gain brings it to 1, the size of
 * the Perlin gradient-noise field it replaced, so `strength` keeps its
 * meaning. */
#define CURL_GAIN 0.92f

static inline uint32_t lattice_hash(uint32_t x, uint32_t y, uint32_t z, uint32_t seed) {
    uint32_t h = seed ^ x ^ y ^ z;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

/* The gradient (in q) of the value noise whose corner values are bits
 * [shift, shift + 10) of the corner hashes h[4x + 2y + z]: the blend along
 * z (values and z-differences), then y, then x, each derivative that of
 * the blend itself. */
static inline __attribute__((always_inline)) void value_gradient(const uint32_t h[8], int shift,
                                                                 const float u[3],
                                                                 const float du[3], float *gx,
                                                                 float *gy, float *gz) {
    const float to_unit = 1.0f / 511.5f;
#define CORNER(k) ((float)(int32_t)((h[k] >> shift) & 1023u) * to_unit - 1.0f)
    const float v0 = CORNER(0), v1 = CORNER(1), v2 = CORNER(2), v3 = CORNER(3);
    const float v4 = CORNER(4), v5 = CORNER(5), v6 = CORNER(6), v7 = CORNER(7);
#undef CORNER
    const float dz[4] = {v1 - v0, v3 - v2, v5 - v4, v7 - v6};
    const float e[4] = {v0 + u[2] * dz[0], v2 + u[2] * dz[1], v4 + u[2] * dz[2], v6 + u[2] * dz[3]};
    const float f0 = e[0] + u[1] * (e[1] - e[0]), f1 = e[2] + u[1] * (e[3] - e[2]);
    const float g0 = e[1] - e[0], g1 = e[3] - e[2];
    const float h0 = dz[0] + u[1] * (dz[1] - dz[0]), h1 = dz[2] + u[1] * (dz[3] - dz[2]);
    *gx = du[0] * (f1 - f0);
    *gy = du[1] * (g0 + u[0] * (g1 - g0));
    *gz = du[2] * (h0 + u[0] * (h1 - h0));
}

/* The cell of lattice coordinate q (|q| <= 1e9) and the fade u of its
 * fraction f, with du/dq. */
static inline __attribute__((always_inline)) void lattice_coord(float q, uint32_t *cell, float *u,
                                                                float *du) {
    int32_t i = (int32_t)q;
    i -= (float)i > q; /* floor */
    const float f = q - (float)i;
    *u = f * f * f * (f * (f * 6.0f - 15.0f) + 10.0f);
    *du = 30.0f * f * f * (f - 1.0f) * (f - 1.0f);
    *cell = (uint32_t)i;
}

/* a[j] = x[j] * freq + o clamped to +-1e9 (NaN to -1e9), so the lattice
 * coordinate's conversion to a cell is defined; a loop of its own, which
 * the compiler vectorises where the fused one would not be. */
static inline __attribute__((always_inline)) void
lattice_scale(size_t n, const float *restrict x, float freq, float o, float *restrict a) {
    const float lim = 1e9f;
    for (size_t j = 0; j < n; j++) {
        float v = x[j] * freq + o;
        v = v < lim ? v : lim;
        a[j] = v > -lim ? v : -lim;
    }
}

/* One octave over points [0, n): adds amp times the gradients (in q) of
 * the three potentials at q = (x, y, z) * freq + offset into g[9 * CHUNK]
 * (potential-major, then axis, then point). */
enum { CURL_CHUNK = 64 };
static inline __attribute__((always_inline)) void
curl_octave(size_t n, const float *restrict x, const float *restrict y, const float *restrict z,
            float freq, const float offset[3], uint32_t seed, float amp, float *restrict g) {
    /* Lattice coordinates scattered by three odd constants, so X*P + P is
     * the next corner's term: no multiply per corner. */
    const uint32_t P0 = 0x8da6b343u, P1 = 0xd8163841u, P2 = 0xcb1ab31fu;
    float qx[CURL_CHUNK], qy[CURL_CHUNK], qz[CURL_CHUNK];
    lattice_scale(n, x, freq, offset[0], qx);
    lattice_scale(n, y, freq, offset[1], qy);
    lattice_scale(n, z, freq, offset[2], qz);
    for (size_t j = 0; j < n; j++) {
        float u[3], du[3];
        uint32_t c[3];
        lattice_coord(qx[j], &c[0], &u[0], &du[0]);
        lattice_coord(qy[j], &c[1], &u[1], &du[1]);
        lattice_coord(qz[j], &c[2], &u[2], &du[2]);
        const uint32_t x0 = c[0] * P0, y0 = c[1] * P1, z0 = c[2] * P2;
        const uint32_t x1 = x0 + P0, y1 = y0 + P1, z1 = z0 + P2;
        const uint32_t h[8] = {lattice_hash(x0, y0, z0, seed), lattice_hash(x0, y0, z1, seed),
                               lattice_hash(x0, y1, z0, seed), lattice_hash(x0, y1, z1, seed),
                               lattice_hash(x1, y0, z0, seed), lattice_hash(x1, y0, z1, seed),
                               lattice_hash(x1, y1, z0, seed), lattice_hash(x1, y1, z1, seed)};
        float gx, gy, gz;
        value_gradient(h, 0, u, du, &gx, &gy, &gz);
        g[0 * CURL_CHUNK + j] += amp * gx;
        g[1 * CURL_CHUNK + j] += amp * gy;
        g[2 * CURL_CHUNK + j] += amp * gz;
        value_gradient(h, 11, u, du, &gx, &gy, &gz);
        g[3 * CURL_CHUNK + j] += amp * gx;
        g[4 * CURL_CHUNK + j] += amp * gy;
        g[5 * CURL_CHUNK + j] += amp * gz;
        value_gradient(h, 22, u, du, &gx, &gy, &gz);
        g[6 * CURL_CHUNK + j] += amp * gx;
        g[7 * CURL_CHUNK + j] += amp * gy;
        g[8 * CURL_CHUNK + j] += amp * gz;
    }
}

/* PFX_CLONES (sim/fast_f.h): an AVX2 copy beside the baseline one on x86-64,
 * giving the same bits. */

PFX_CLONES
void pfx_curl_noise_f(size_t n, const float *x, const float *y, const float *z, float inv,
                      double t_shift, int octaves, uint64_t seed, float *ox, float *oy, float *oz) {
    float g[9 * CURL_CHUNK];
    if (octaves < 1)
        octaves = 1;
    float norm = 0;
    for (int o = 0; o < octaves; o++)
        norm += 1.0f / (float)(1 << (o < 30 ? o : 30));
    const float gain = CURL_GAIN / norm;
    for (size_t j0 = 0; j0 < n; j0 += CURL_CHUNK) {
        const size_t m = n - j0 < CURL_CHUNK ? n - j0 : CURL_CHUNK;
        memset(g, 0, sizeof g);
        float amp = 1, freq = inv;
        for (int o = 0; o < octaves; o++) {
            /* psi_o = amp scale / 2^o n_o(2^o p / scale): each octave's curl
             * has amplitude amp, and the sum is the curl of one potential. */
            const float *d = curl_drift[o & 3];
            const float offset[3] = {(float)(d[0] * t_shift) + 17.3f * (float)o,
                                     (float)(d[1] * t_shift) + 5.1f * (float)o,
                                     (float)(d[2] * t_shift) + 3.7f * (float)o};
            const uint32_t os = (uint32_t)pfx_mix64(seed + 0x1000 * (uint64_t)o);
            curl_octave(m, x + j0, y + j0, z + j0, freq, offset, os, amp, g);
            amp *= 0.5f;
            freq *= 2;
        }
        /* curl psi = (d n3/dy - d n2/dz, d n1/dz - d n3/dx, d n2/dx - d n1/dy) */
        const float *n1 = g, *n2 = g + 3 * CURL_CHUNK, *n3 = g + 6 * CURL_CHUNK;
        for (size_t j = 0; j < m; j++) {
            ox[j0 + j] = gain * (n3[CURL_CHUNK + j] - n2[2 * CURL_CHUNK + j]);
            oy[j0 + j] = gain * (n1[2 * CURL_CHUNK + j] - n3[j]);
            oz[j0 + j] = gain * (n2[j] - n1[CURL_CHUNK + j]);
        }
    }
}

/* ---- Bad states ---- */

/* The first bad particle, in order. Most calls find none: a branch-free
 * pass over blocks of 64 (which vectorises) says whether a block may hold
 * one (non-finite, |v_c| above the speed limit / sqrt(3) or |x_c| above the
 * position limit: every bad state trips one of these), and only such a
 * block is searched particle by particle. */
#define FIND_BAD(T, ABS)                                                                           \
    const T vmax2 = (T)(PFX_MOTION_MAX_SPEED * PFX_MOTION_MAX_SPEED);                              \
    const T xmax = (T)PFX_MOTION_MAX_POSITION;                                                     \
    for (size_t i0 = 0; i0 < p->count; i0 += 64) {                                                 \
        const size_t end = p->count - i0 < 64 ? p->count : i0 + 64;                                \
        int alarm = 0;                                                                             \
        for (size_t i = i0; i < end; i++)                                                          \
            alarm |= PFX_MOTION_MAY_BE_BAD(T, ABS, p->px[i], p->py[i], p->pz[i], p->vx[i],         \
                                           p->vy[i], p->vz[i]);                                    \
        if (!alarm)                                                                                \
            continue;                                                                              \
        for (size_t i = i0; i < end; i++) {                                                        \
            T x = p->px[i], y = p->py[i], z = p->pz[i], u = p->vx[i], v = p->vy[i], w = p->vz[i];  \
            T s = x + y + z + u + v + w;                                                           \
            if (s - s != 0) { /* NaN or Inf anywhere in the sum */                                 \
                *why = PFX_BAD_NONFINITE;                                                          \
                return i;                                                                          \
            }                                                                                      \
            if (u * u + v * v + w * w > vmax2) {                                                   \
                *why = PFX_BAD_SPEED;                                                              \
                return i;                                                                          \
            }                                                                                      \
            if (fabs((double)x) > xmax || fabs((double)y) > xmax || fabs((double)z) > xmax) {      \
                *why = PFX_BAD_POSITION;                                                           \
                return i;                                                                          \
            }                                                                                      \
        }                                                                                          \
    }                                                                                              \
    *why = PFX_BAD_NONE;                                                                           \
    return p->count;

/* PFX_CLONES: the float scan, run after every block of every step, in
 * AVX2 too. */
PFX_CLONES size_t pfx_motion_find_bad_f(const pfx_motion_pool_f *p, pfx_bad_kind *why) {
    FIND_BAD(float, fabsf);
}

size_t pfx_motion_find_bad_d(const pfx_motion_pool_d *p, pfx_bad_kind *why) {
    FIND_BAD(double, fabs);
}

void pfx_motion_blame(const pfx_motion *m, pfx_bad_kind why, char *buf, size_t size) {
    /* The warning `validate` printed for this emitter: growth (UNSTABLE) or
     * a speed the rotation does not keep (DRIFT), whichever comes first. */
    pfx_stability_warning w[8];
    size_t n = pfx_motion_check_stability(m, w, 8);
    for (size_t i = 0; i < n && i < 8; i++)
        if (w[i].kind == PFX_STABILITY_UNSTABLE || w[i].kind == PFX_STABILITY_DRIFT) {
            snprintf(buf, size, "%s (as validate warns)", w[i].message);
            return;
        }
    snprintf(buf, size,
             "%s with %s (%d substep%s): no stability limit is crossed; a force may be "
             "singular (an attractor without softening?)",
             why == PFX_BAD_NONFINITE ? "a value became NaN or infinite"
             : why == PFX_BAD_SPEED   ? "a particle exceeded 1e6 m/s"
                                      : "a particle went beyond 1e7 m",
             pfx_integrator_name(m->choice.chosen), m->choice.steps,
             m->choice.steps == 1 ? "" : "s");
}
