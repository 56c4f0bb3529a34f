/* Resolving a motion model: which scheme runs (the `auto` rule), how many
 * substeps, what the split step folds into its exact drift, and one line
 * saying why. Also the curl noise of `turbulence`, the Sims falloff and the
 * scan for non-finite or exploding particles. The arithmetic of a step is in
 * motion_impl.h; the stability regions are in stability.c. */
#include "sim/motion.h"
#include "sim/rng.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const integrator_names[PFX_INTEGRATOR_COUNT] = {
    "auto", "euler", "symplectic", "midpoint", "rk4", "verlet", "exact", "boris"};

const char *pfx_integrator_name(pfx_integrator i) {
    return (unsigned)i < PFX_INTEGRATOR_COUNT ? integrator_names[i] : "?";
}

bool pfx_integrator_parse(const char *s, pfx_integrator *out) {
    for (int i = 0; i < PFX_INTEGRATOR_COUNT; i++)
        if (strcmp(s, integrator_names[i]) == 0) {
            *out = (pfx_integrator)i;
            return true;
        }
    return false;
}

pfx_scheme pfx_integrator_scheme(pfx_integrator i) {
    switch (i) {
    case PFX_INTEGRATOR_EULER:
        return PFX_SCHEME_EULER;
    case PFX_INTEGRATOR_SYMPLECTIC:
        return PFX_SCHEME_SYMPLECTIC;
    case PFX_INTEGRATOR_MIDPOINT:
        return PFX_SCHEME_MIDPOINT;
    case PFX_INTEGRATOR_RK4:
        return PFX_SCHEME_RK4;
    case PFX_INTEGRATOR_VERLET:
        return PFX_SCHEME_VERLET;
    default:
        return PFX_SCHEME_SPLIT;
    }
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

unsigned pfx_motion_columns(const pfx_motion *m) {
    unsigned c = 0;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        if (f->kind == PFX_MOTION_GRAVITY)
            c |= PFX_COLUMN_GRAVITY_SCALE;
        if (f->kind == PFX_MOTION_MAGNETIC)
            c |= PFX_COLUMN_CHARGE | PFX_COLUMN_MASS;
        if (f->kind == PFX_MOTION_SPRING && f->use_birth)
            c |= PFX_COLUMN_BIRTH;
    }
    return c;
}

double pfx_vortex_falloff(double r, double d) {
    if (!(r >= 0 && r <= 1))
        return 0;
    double r2 = r * r;
    return (r2 * r2 - 2 * r2 + 1) / (1 + d * r2);
}

/* ---- Representative rates, shared with stability.c ---- */

/* Sum of the gravities, for the terminal speed of quadratic drag. */
static double gravity_magnitude(const pfx_motion *m) {
    double g[3] = {0, 0, 0};
    for (size_t i = 0; i < m->force_count; i++)
        if (m->forces[i].kind == PFX_MOTION_GRAVITY)
            for (int a = 0; a < 3; a++)
                g[a] += m->forces[i].accel[a];
    return norm3(g);
}

/* Angular frequency of a position force's linearisation (0: none): a spring
 * sqrt(k); an attractor sqrt(|s| / r^3) at its softening radius (where the
 * tidal rate peaks), else at ref_radius, else 1 m; turbulence sqrt(|s| /
 * scale), its acceleration gradient. Repulsion has no frequency. */
double pfx_motion_force_omega(const pfx_motion_force *f) {
    switch (f->kind) {
    case PFX_MOTION_SPRING:
        return f->k > 0 ? sqrt(f->k) : 0;
    case PFX_MOTION_ATTRACTOR: {
        if (f->strength <= 0)
            return 0;
        double r = f->softening > 0 ? f->softening : f->ref_radius > 0 ? f->ref_radius : 1.0;
        if (f->falloff == PFX_FALLOFF_INVERSE_SQUARE)
            return sqrt(f->strength / (r * r * r));
        double L = f->ref_radius > 0 ? f->ref_radius : 1.0;
        return f->falloff == PFX_FALLOFF_LINEAR ? sqrt(f->strength / (L * r * r))
                                                : sqrt(f->strength / (L * L * r));
    }
    case PFX_MOTION_TURBULENCE:
        return f->scale > 0 ? sqrt(fabs(f->strength) / f->scale) : 0;
    default:
        return 0;
    }
}

/* Decay rate of a velocity force's linearisation (0: none): linear drag k;
 * quadratic drag 2 c v_ref, v_ref the larger of the expected speed relative
 * to the wind and the terminal speed sqrt(g/c); spring damping 2 zeta omega. */
double pfx_motion_force_damping(const pfx_motion *m, const pfx_motion_force *f) {
    if (f->kind == PFX_MOTION_SPRING)
        return f->k > 0 ? 2 * f->zeta * sqrt(f->k) : 0;
    if (f->kind != PFX_MOTION_DRAG)
        return 0;
    double kq = 0;
    if (f->c > 0) {
        double v = f->speed_hint + norm3(f->wind), vt = sqrt(gravity_magnitude(m) / f->c);
        kq = 2 * f->c * (v > vt ? v : vt);
    }
    return f->k + kq;
}

/* ---- The error model of `auto` ----
 * Every scheme auto runs is second order, so its position error grows at a
 * rate C L w^3 h^2 (m per simulated second) for an oscillation of
 * frequency w and size L, and C u k^2 h^2 for a velocity force of rate k
 * acting on speeds u that it does not integrate exactly. The constants are
 * measured on the accuracy suite (pfx bench accuracy, the largest
 * error(t)/t over each run) and multiplied by a safety factor of 1.5:
 *   spring (leapfrog on x'' = -w^2 x)       C = 1/24  -> 1/16
 *   magnetic rotation, L the gyroradius      C = 1/24  -> 1/16
 *   attractor, w and L at its reference      C = 0.64  -> 1  (Kepler e = 0.5;
 *                                                     a circular orbit: 0.34)
 *   velocity forces under Verlet or kicks    C = 0.39  -> 0.6 (linear drag;
 *                                                     quadratic drag: 0.008)
 * Turbulence has no closed form to measure; it takes the spring's. */
#define AUTO_C_SPRING (1.0 / 16)
#define AUTO_C_ROTATION (1.0 / 16)
#define AUTO_C_ATTRACTOR 1.0
#define AUTO_C_VELOCITY 0.6

/* Length over which an oscillation's phase error turns into position error:
 * the attractor's radius, the turbulence scale, 1 m for a spring. */
static double force_length(const pfx_motion_force *f) {
    if (f->kind == PFX_MOTION_ATTRACTOR)
        return f->softening > 0 ? f->softening : f->ref_radius > 0 ? f->ref_radius : 1.0;
    if (f->kind == PFX_MOTION_TURBULENCE)
        return f->scale;
    return 1.0;
}

/* C L w^3 of a position force (0 for the others). */
static double oscillation_error(const pfx_motion_force *f) {
    double w = pfx_motion_force_omega(f);
    double c = f->kind == PFX_MOTION_ATTRACTOR ? AUTO_C_ATTRACTOR : AUTO_C_SPRING;
    return w > 0 ? c * force_length(f) * w * w * w : 0;
}

/* C L W^3 of a magnetic field's rotation: W = |q/m| |B|, L the gyroradius
 * of the fastest emitted particle plus the E x B drift, u / W. */
static double rotation_error(const pfx_motion_force *f) {
    double W = fabs(f->charge) / (f->mass > 0 ? f->mass : 1.0) * norm3(f->field);
    if (!(W > 0))
        return 0;
    double u = f->speed_hint + norm3(f->electric) / norm3(f->field);
    return AUTO_C_ROTATION * (u / W) * W * W * W;
}

/* The speeds a velocity force acts on: the emission speed relative to the
 * wind, or the terminal speed under the gravities, whichever is larger. */
static double velocity_scale(const pfx_motion *m, const pfx_motion_force *f) {
    double g = gravity_magnitude(m), u = f->speed_hint + norm3(f->wind);
    double terminal = f->c > 0 ? sqrt(g / f->c) : f->k > 0 ? g / f->k : 0;
    if (f->kind == PFX_MOTION_SPRING)
        u = f->speed_hint + sqrt(f->k); /* a unit displacement's speed */
    return u > terminal ? u : terminal;
}

/* ---- Resolving ---- */

/* Fill the split step's aggregates: the unregioned gravity and linear
 * damping go into the exact drift (folded), B into the rotation, the rest
 * is kicked. */
static void fold_split(pfx_motion *m) {
    double kw[3] = {0, 0, 0};
    m->drift_k = 0;
    m->has_kick = m->has_rotation = false;
    for (int a = 0; a < 3; a++)
        m->drift_g[a] = m->drift_wind[a] = 0;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        const bool unreg = f->region.kind == PFX_REGION_NONE;
        m->folded[i] = false;
        switch (f->kind) {
        case PFX_MOTION_GRAVITY:
            if (unreg) {
                m->folded[i] = true;
                for (int a = 0; a < 3; a++)
                    m->drift_g[a] += f->accel[a];
            } else {
                m->has_kick = true;
            }
            break;
        case PFX_MOTION_DRAG:
            if (unreg && f->k > 0) {
                m->folded[i] = true;
                m->drift_k += f->k;
                for (int a = 0; a < 3; a++)
                    kw[a] += f->k * f->wind[a];
            }
            if (!m->folded[i] || f->c > 0)
                m->has_kick = true;
            break;
        case PFX_MOTION_SPRING:
            m->has_kick = true;
            if (unreg && f->zeta > 0) {
                m->folded[i] = true;
                m->drift_k += 2 * f->zeta * sqrt(f->k);
            }
            break;
        case PFX_MOTION_MAGNETIC:
            if (norm3(f->field) > 0)
                m->has_rotation = true;
            if (norm3(f->electric) > 0)
                m->has_kick = true;
            break;
        case PFX_MOTION_ATTRACTOR:
        case PFX_MOTION_TURBULENCE:
            m->has_kick = true;
            break;
        default:
            break;
        }
    }
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

static int ceil_steps(double dt, double h) {
    if (!(h > 0) || !(dt / h < PFX_MOTION_MAX_SUBSTEPS))
        return h > 0 && dt / h < 1 ? 1 : PFX_MOTION_MAX_SUBSTEPS;
    int n = (int)ceil(dt / h * (1 - 1e-12));
    return n < 1 ? 1 : n;
}

/* The auto rule, per emitter, from the forces it feels:
 *  - only gravity and unregioned linear drag (springs' damping counts):
 *    `exact`, the closed form, 1 step at any dt;
 *  - plus position forces (attractor, spring, turbulence, E) and/or B but
 *    no other velocity force: the split step (exact drift, kick-drift-kick,
 *    Boris rotation for B) - second order and symplectic - named `exact`,
 *    or `boris` when B is present;
 *  - any other velocity force (quadratic drag, regioned drag): `verlet`
 *    (2nd order, 2 evaluations), or `boris` with B;
 *  - substeps: h = dt/n with omega h <= 1 (half the leapfrog limit of 2,
 *    so the phase error stays below 5 %), k h <= 1 for the decay rates the
 *    scheme does not integrate exactly (no sign flips, inside every limit),
 *    and L omega^3 h^2 / 24 <= tolerance - the position error per second of
 *    a second-order symplectic scheme on an oscillation of size L. */
static void choose_auto(pfx_motion *m, double tol) {
    bool velocity = false, rotation = false, position = false;
    double w2 = 0, kv = 0, h = INFINITY, err = 0;
    const char *stiff = NULL;
    for (size_t i = 0; i < m->force_count; i++) {
        const pfx_motion_force *f = &m->forces[i];
        const bool unreg = f->region.kind == PFX_REGION_NONE;
        if (f->kind == PFX_MOTION_DRAG && (f->c > 0 || (!unreg && f->k > 0)))
            velocity = true;
        if (f->kind == PFX_MOTION_SPRING && f->zeta > 0 && !unreg)
            velocity = true;
        if (f->kind == PFX_MOTION_MAGNETIC && norm3(f->field) > 0) {
            rotation = true;
            err += rotation_error(f);
        }
        if (f->kind == PFX_MOTION_ATTRACTOR || f->kind == PFX_MOTION_SPRING ||
            f->kind == PFX_MOTION_TURBULENCE || (f->kind == PFX_MOTION_GRAVITY && !unreg) ||
            (f->kind == PFX_MOTION_MAGNETIC && norm3(f->electric) > 0))
            position = true;
        double w = pfx_motion_force_omega(f);
        if (w > 0) {
            w2 += w * w;
            err += oscillation_error(f);
            if (1 / w < h)
                h = 1 / w, stiff = f->name;
        }
    }
    if (!velocity) {
        m->scheme = PFX_SCHEME_SPLIT;
        m->chosen = rotation ? PFX_INTEGRATOR_BORIS : PFX_INTEGRATOR_EXACT;
    } else {
        m->scheme = rotation ? PFX_SCHEME_SPLIT : PFX_SCHEME_VERLET;
        m->chosen = rotation ? PFX_INTEGRATOR_BORIS : PFX_INTEGRATOR_VERLET;
        /* What the scheme evaluates explicitly: everything for Verlet, the
         * unfolded velocity forces for the split step. */
        for (size_t i = 0; i < m->force_count; i++) {
            const pfx_motion_force *f = &m->forces[i];
            double k = pfx_motion_force_damping(m, f);
            bool unreg = f->region.kind == PFX_REGION_NONE;
            if (m->scheme == PFX_SCHEME_SPLIT && unreg && f->kind == PFX_MOTION_SPRING)
                k = 0;
            if (m->scheme == PFX_SCHEME_SPLIT && unreg && f->kind == PFX_MOTION_DRAG)
                k -= f->k;
            kv += k;
            if (k > 0)
                err += AUTO_C_VELOCITY * velocity_scale(m, f) * k * k;
        }
        if (m->scheme == PFX_SCHEME_VERLET && w2 > 0 && 1 / sqrt(w2) < h)
            h = 1 / sqrt(w2), stiff = "the forces together";
        if (kv > 0 && 1 / kv < h)
            h = 1 / kv, stiff = "the drag";
    }
    /* The tolerance: err h^2 <= tol. */
    const bool accuracy = err > 0 && sqrt(tol / err) < h;
    if (accuracy)
        h = sqrt(tol / err), stiff = "the tolerance";
    m->steps = ceil_steps(m->dt, h);
    m->error_rate = err * (m->dt / m->steps) * (m->dt / m->steps);
    const double hh = m->dt / m->steps;
    int len;
    if (!position && !velocity && !rotation)
        len = snprintf(m->why, sizeof m->why,
                       "exact: gravity and linear drag have a closed form, exact at any dt");
    else if (m->scheme == PFX_SCHEME_SPLIT)
        len = snprintf(m->why, sizeof m->why, "%s: exact gravity/drag drift%s%s",
                       pfx_integrator_name(m->chosen),
                       rotation ? ", Boris rotation keeps |v| in B" : "",
                       position || velocity ? ", kick-drift-kick for the rest (2nd order)" : "");
    else
        len = snprintf(m->why, sizeof m->why,
                       "verlet: a velocity-dependent force needs it (2nd order, 2 evaluations)");
    if (len > 0 && (size_t)len < sizeof m->why && (m->steps > 1 || err > 0))
        snprintf(m->why + len, sizeof m->why - len,
                 "; %d substep%s (set by %s%s): omega*h = %.3g, k*h = %.3g, expected error "
                 "%.2g m/s",
                 m->steps, m->steps == 1 ? "" : "s", stiff ? stiff : "-",
                 m->steps == PFX_MOTION_MAX_SUBSTEPS ? ", capped" : "", sqrt(w2) * hh, kv * hh,
                 m->error_rate);
}

void pfx_motion_prepare(pfx_motion *m, double dt) {
    const double tol = m->tolerance > 0 ? m->tolerance : 1e-3;
    m->dt = dt;
    m->has_operators = false;
    for (size_t i = 0; i < m->force_count; i++) {
        pfx_motion_kind k = m->forces[i].kind;
        if (k == PFX_MOTION_VORTEX || k == PFX_MOTION_SPIRAL || k == PFX_MOTION_SPEED_LIMIT)
            m->has_operators = true;
    }
    if (m->integrator == PFX_INTEGRATOR_AUTO) {
        choose_auto(m, tol);
        if (m->substeps > 0)
            m->steps = m->substeps;
    } else {
        m->chosen = m->integrator;
        m->scheme = pfx_integrator_scheme(m->integrator);
        m->steps = m->substeps > 0 ? m->substeps : 1;
        snprintf(m->why, sizeof m->why, "%s as requested, %d substep%s",
                 pfx_integrator_name(m->chosen), m->steps, m->steps == 1 ? "" : "s");
    }
    for (size_t i = 0; i < PFX_MOTION_MAX_FORCES; i++)
        m->folded[i] = false;
    m->has_kick = m->has_rotation = m->uniform_rotation = false;
    m->drift_k = 0;
    for (int a = 0; a < 3; a++)
        m->drift_g[a] = m->drift_wind[a] = m->omega[a] = 0;
    if (m->scheme == PFX_SCHEME_SPLIT)
        fold_split(m);
}

const char *pfx_motion_explain(const pfx_motion *m) { return m->why; }

int pfx_motion_substeps_for(const pfx_motion *m, double span) {
    const int steps = m->steps > 0 ? m->steps : 1;
    /* The full step (up to the last bits of t1 - t0) keeps its count. */
    if (fabs(span - m->dt) <= 1e-9 * m->dt)
        return steps;
    double n = ceil(span * steps / m->dt * (1 - 1e-12));
    return n < 1 ? 1 : n > 1e6 ? 1000000 : (int)n;
}

int pfx_motion_evals_per_step(const pfx_motion *m) {
    int per = 1;
    switch (m->scheme) {
    case PFX_SCHEME_EULER:
    case PFX_SCHEME_SYMPLECTIC:
        per = 1;
        break;
    case PFX_SCHEME_MIDPOINT:
    case PFX_SCHEME_VERLET:
        per = 2;
        break;
    case PFX_SCHEME_RK4:
        per = 4;
        break;
    case PFX_SCHEME_SPLIT:
        per = m->has_kick ? 2 : 1; /* 1: the closed-form update itself */
        break;
    }
    return per * (m->steps > 0 ? m->steps : 1);
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
             pfx_integrator_name(m->chosen), m->steps, m->steps == 1 ? "" : "s");
}
