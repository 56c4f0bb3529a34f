/* The kill rules and bounds of one emitter applied to its pool after a step:
 * positions wrapped into a wrapping box, particles a rule kills marked by
 * lifetime = PFX_KILLED. It removes nothing itself (sim.c's age pass does) and never
 * reports: the compiler validated the rules. */
#include "sim/kill.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>

#include "sim/state.h"

static_assert(PFX_KILL_ALPHA_LUT == PFX_GRADIENT_LUT, "alpha table indexed like the colour LUT");

/* The remainder is taken in double, where x - lo and hi - lo of floats are
 * exact (unless their exponents differ by more than 29, when they are within
 * one double ulp) and fmod is always exact, so the only float rounding is the
 * last one, to the nearest float. That rounding can land on hi (a remainder
 * just below the period), which is the same point of the torus as lo. */
float pfx_kill_wrap(float x, float lo, float hi) {
    const double period = (double)hi - (double)lo;
    double r = fmod((double)x - (double)lo, period);
    if (r < 0)
        r += period;
    const float w = (float)((double)lo + r);
    return w < hi ? w : lo; /* also maps a NaN to lo */
}

/* Float box of a centre and half extents: what the particles' float
 * positions are compared with. */
static void float_box(const double c[3], const double h[3], float lo[3], float hi[3]) {
    for (int a = 0; a < 3; a++) {
        lo[a] = (float)(c[a] - h[a]);
        hi[a] = (float)(c[a] + h[a]);
    }
}

/* Each axis on its own: almost every particle is inside, so the branch is
 * predicted and the rare wrap pays for the double arithmetic. */
static void wrap_axis(float *restrict x, float *restrict carried, uint8_t *restrict rest,
                      uint32_t n, float lo, float hi) {
    for (uint32_t i = 0; i < n; i++)
        if (!(x[i] >= lo && x[i] < hi)) {
            x[i] = pfx_kill_wrap(x[i], lo, hi);
            if (carried) /* the carried acceleration was of the old position */
                carried[i] = NAN;
            if (rest) /* moved: no longer the resting state it was flagged in */
                rest[i] = 0;
        }
}

/* The marking passes below are branch-free selects, lifetime = dead ?
 * PFX_KILLED : lifetime, so the compiler can vectorise them. */

static void mark_box(pfx_pool *p, const float lo[3], const float hi[3], bool kill_inside) {
    const uint32_t n = p->count;
    const float *restrict px = p->px, *restrict py = p->py, *restrict pz = p->pz;
    float *restrict life = p->lifetime;
    const float lx = lo[0], ly = lo[1], lz = lo[2], hx = hi[0], hy = hi[1], hz = hi[2];
    const int want = kill_inside;
    for (uint32_t i = 0; i < n; i++) {
        const int in = (px[i] >= lx) & (px[i] <= hx) & (py[i] >= ly) & (py[i] <= hy) &
                       (pz[i] >= lz) & (pz[i] <= hz);
        life[i] = in == want ? PFX_KILLED : life[i];
    }
}

/* |x - c|^2 against r^2: inside when <= r^2 (DISTANCE: dies when > r^2). */
static void mark_sphere(pfx_pool *p, const double center[3], double radius, bool kill_inside) {
    const uint32_t n = p->count;
    const float *restrict px = p->px, *restrict py = p->py, *restrict pz = p->pz;
    float *restrict life = p->lifetime;
    const float cx = (float)center[0], cy = (float)center[1], cz = (float)center[2];
    const float r2 = (float)(radius * radius);
    const int want = kill_inside;
    for (uint32_t i = 0; i < n; i++) {
        const float dx = px[i] - cx, dy = py[i] - cy, dz = pz[i] - cz;
        const int in = dx * dx + dy * dy + dz * dz <= r2;
        life[i] = in == want ? PFX_KILLED : life[i];
    }
}

/* (x - point) . normal >= 0 is inside. */
static void mark_half_space(pfx_pool *p, const double point[3], const double normal[3],
                            bool kill_inside) {
    const uint32_t n = p->count;
    const float *restrict px = p->px, *restrict py = p->py, *restrict pz = p->pz;
    float *restrict life = p->lifetime;
    const float cx = (float)point[0], cy = (float)point[1], cz = (float)point[2];
    const float nx = (float)normal[0], ny = (float)normal[1], nz = (float)normal[2];
    const int want = kill_inside;
    for (uint32_t i = 0; i < n; i++) {
        const int in = (px[i] - cx) * nx + (py[i] - cy) * ny + (pz[i] - cz) * nz >= 0;
        life[i] = in == want ? PFX_KILLED : life[i];
    }
}

/* The alpha test folded into a 256-entry table of deaths, then one lookup
 * per particle at the entry pfx_particle_color would read. */
static void mark_alpha(pfx_pool *p, const float alpha_at_age[PFX_KILL_ALPHA_LUT], double below) {
    unsigned char dies[PFX_KILL_ALPHA_LUT];
    for (int k = 0; k < PFX_KILL_ALPHA_LUT; k++)
        dies[k] = (double)alpha_at_age[k] < below;
    const uint32_t n = p->count;
    float *restrict life = p->lifetime;
    const double *restrict birth = p->birth;
    const double now = p->time;
    for (uint32_t i = 0; i < n; i++) {
        const float u = (float)(now - birth[i]) / life[i];
        int k = (int)(u * (PFX_KILL_ALPHA_LUT - 1) + 0.5f);
        k = k < 0 ? 0 : k >= PFX_KILL_ALPHA_LUT ? PFX_KILL_ALPHA_LUT - 1 : k;
        life[i] = dies[k] ? PFX_KILLED : life[i];
    }
}

void pfx_kill_apply(const pfx_kill_rules *k, pfx_pool *p, const double emitter_pos[3],
                    const float alpha_at_age[PFX_KILL_ALPHA_LUT]) {
    if (p->count == 0)
        return;
    if (k->bounds != PFX_BOUNDS_NONE) {
        float lo[3], hi[3];
        float_box(k->bounds_center, k->bounds_half, lo, hi);
        if (k->bounds == PFX_BOUNDS_WRAP) {
            assert(lo[0] < hi[0] && lo[1] < hi[1] && lo[2] < hi[2]);
            wrap_axis(p->px, p->ax, p->rest, p->count, lo[0], hi[0]);
            wrap_axis(p->py, p->ax, p->rest, p->count, lo[1], hi[1]);
            wrap_axis(p->pz, p->ax, p->rest, p->count, lo[2], hi[2]);
        } else {
            mark_box(p, lo, hi, false);
        }
    }
    for (size_t r = 0; r < k->count; r++) {
        const pfx_kill_rule *rule = &k->rules[r];
        const bool inside = rule->kind == PFX_KILL_INSIDE;
        switch (rule->kind) {
        case PFX_KILL_INSIDE:
        case PFX_KILL_OUTSIDE:
            if (rule->shape == PFX_KILL_BOX) {
                float lo[3], hi[3];
                float_box(rule->center, rule->half, lo, hi);
                mark_box(p, lo, hi, inside);
            } else if (rule->shape == PFX_KILL_SPHERE) {
                mark_sphere(p, rule->center, rule->radius, inside);
            } else {
                mark_half_space(p, rule->center, rule->normal, inside);
            }
            break;
        case PFX_KILL_ALPHA_BELOW:
            assert(alpha_at_age);
            mark_alpha(p, alpha_at_age, rule->threshold);
            break;
        case PFX_KILL_DISTANCE:
            assert(emitter_pos);
            mark_sphere(p, emitter_pos, rule->threshold, false);
            break;
        }
    }
}
