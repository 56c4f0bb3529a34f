/* The simulation's side of motion: a model's choice turned into the plan
 * the kernels run (what the split step folds into its exact drift, and the
 * rotation), the curl noise of `turbulence`, and the scan for non-finite
 * or exploding particles. The arithmetic of a step is in motion_impl.h;
 * the choice and the stability regions are the model's (model/motion.c,
 * model/stability.c). */
#include "sim/motion.h"

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

void pfx_motion_plan_init(pfx_motion_plan *p, const pfx_motion *m) {
    memset(p, 0, sizeof *p);
    p->model = m;
    p->forces = m->forces;
    p->force_count = m->force_count;
    p->dt = m->choice.dt;
    p->chosen = m->choice.chosen;
    p->scheme = m->choice.scheme;
    p->steps = m->choice.steps > 0 ? m->choice.steps : 1;
    for (size_t i = 0; i < m->force_count; i++) {
        pfx_motion_kind k = m->forces[i].kind;
        if (k == PFX_MOTION_VORTEX || k == PFX_MOTION_SPIRAL || k == PFX_MOTION_SPEED_LIMIT)
            p->has_operators = true;
    }
    if (p->scheme == PFX_SCHEME_SPLIT)
        fold_split(p);
}

void pfx_motion_plan_prepare(pfx_motion_plan *p, pfx_motion *m, double dt) {
    pfx_motion_choose(m, dt);
    pfx_motion_plan_init(p, m);
}

/* ---- Curl noise ---- */

/* Perlin gradient noise with its analytic gradient: trilinear blend, by the
 * quintic fade u = 6f^5 - 15f^4 + 10f^3 (C2, du = 30 f^2 (f-1)^2), of the
 * corner ramps g_c . (f - c), g_c one of the 12 cube-edge directions. */
static void noise_grad(const double p[3], uint64_t seed, double grad[3]) {
    static const signed char G[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0},
                                         {1, 0, 1}, {-1, 0, 1}, {1, 0, -1}, {-1, 0, -1},
                                         {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
    double fl[3], f[3], u[3], du[3];
    for (int a = 0; a < 3; a++) {
        fl[a] = floor(p[a]);
        f[a] = p[a] - fl[a];
        u[a] = f[a] * f[a] * f[a] * (f[a] * (f[a] * 6 - 15) + 10);
        du[a] = 30 * f[a] * f[a] * (f[a] - 1) * (f[a] - 1);
    }
    /* Lattice hashes per axis first (6 mixes), then one mix per corner:
     * 14 mixes a noise instead of 24, and the gradient index by a
     * multiply-shift instead of a 64-bit modulo. */
    uint64_t ax[2][3];
    for (int a = 0; a < 3; a++)
        for (int o = 0; o < 2; o++)
            ax[o][a] = pfx_mix64(
                seed ^ ((uint64_t)(int64_t)(fl[a] + o) * 0x9e3779b97f4a7c15ull + (uint64_t)a));
    grad[0] = grad[1] = grad[2] = 0;
    for (int c = 0; c < 8; c++) {
        int o[3] = {c & 1, (c >> 1) & 1, c >> 2};
        uint64_t hy = ax[o[1]][1], hz = ax[o[2]][2];
        uint64_t h = pfx_mix64(ax[o[0]][0] ^ (hy << 21 | hy >> 43) ^ (hz << 42 | hz >> 22));
        const signed char *g = G[((h >> 32) * 12) >> 32];
        double w[3], dw[3], val = 0;
        for (int a = 0; a < 3; a++) {
            w[a] = o[a] ? u[a] : 1 - u[a];
            dw[a] = o[a] ? du[a] : -du[a];
            val += g[a] * (f[a] - o[a]);
        }
        grad[0] += dw[0] * w[1] * w[2] * val + w[0] * w[1] * w[2] * g[0];
        grad[1] += w[0] * dw[1] * w[2] * val + w[0] * w[1] * w[2] * g[1];
        grad[2] += w[0] * w[1] * dw[2] * val + w[0] * w[1] * w[2] * g[2];
    }
}

/* curl psi of psi = (n1, n2, n3), three independent noises; divergence-free
 * because div curl = 0 identically, whatever the noise. Time moves each
 * potential along its own direction, which keeps that true. */
void pfx_curl_noise(const double p[3], double t_shift, int octaves, uint64_t seed, double out[3]) {
    static const double drift[3][3] = {
        {0.57, 0.31, 0.76}, {-0.42, 0.81, 0.41}, {0.69, -0.28, 0.67}};
    double d[3][3] = {{0}}, amp = 1, freq = 1, norm = 0;
    if (octaves < 1)
        octaves = 1;
    for (int o = 0; o < octaves; o++) {
        for (int i = 0; i < 3; i++) {
            double q[3], g[3];
            for (int a = 0; a < 3; a++)
                q[a] = p[a] * freq + drift[i][a] * t_shift + 17.3 * i + 3.1 * o;
            noise_grad(q, pfx_mix64(seed + 0x1000 * (uint64_t)o + (uint64_t)i), g);
            /* psi_o = amp/freq noise(freq p): its curl has amplitude amp */
            for (int a = 0; a < 3; a++)
                d[i][a] += amp * g[a];
        }
        norm += amp;
        amp *= 0.5;
        freq *= 2;
    }
    out[0] = (d[2][1] - d[1][2]) / norm;
    out[1] = (d[0][2] - d[2][0]) / norm;
    out[2] = (d[1][0] - d[0][1]) / norm;
}

/* ---- Bad states ---- */

#define FIND_BAD(T)                                                                                \
    const T vmax2 = (T)(PFX_MOTION_MAX_SPEED * PFX_MOTION_MAX_SPEED);                              \
    const T xmax = (T)PFX_MOTION_MAX_POSITION;                                                     \
    for (size_t i = 0; i < p->count; i++) {                                                        \
        T x = p->px[i], y = p->py[i], z = p->pz[i], u = p->vx[i], v = p->vy[i], w = p->vz[i];      \
        T s = x + y + z + u + v + w;                                                               \
        if (s - s != 0) { /* NaN or Inf anywhere in the sum */                                     \
            *why = PFX_BAD_NONFINITE;                                                              \
            return i;                                                                              \
        }                                                                                          \
        if (u * u + v * v + w * w > vmax2) {                                                       \
            *why = PFX_BAD_SPEED;                                                                  \
            return i;                                                                              \
        }                                                                                          \
        if (fabs((double)x) > xmax || fabs((double)y) > xmax || fabs((double)z) > xmax) {          \
            *why = PFX_BAD_POSITION;                                                               \
            return i;                                                                              \
        }                                                                                          \
    }                                                                                              \
    *why = PFX_BAD_NONE;                                                                           \
    return p->count;

size_t pfx_motion_find_bad_f(const pfx_motion_pool_f *p, pfx_bad_kind *why){FIND_BAD(float)} size_t
    pfx_motion_find_bad_d(const pfx_motion_pool_d *p, pfx_bad_kind *why) {
    FIND_BAD(double)
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
