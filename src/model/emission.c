/* Bounds of an emitter's births that pool sizing, `pfx info` and the
 * schedule read: the integral of its rate, its highest rate, and the most
 * particles it can have alive at once. Pure functions of the model. */
#include <math.h>

#include "model/effect.h"

double pfx_emitter_births_by(const pfx_emitter *em, double tau) {
    switch (em->rate_kind) {
    case PFX_RATE_CONSTANT:
        return em->rate * tau;
    case PFX_RATE_RAMP: {
        double a = em->ramp_initial, b = em->ramp_delta;
        if (b < 0 && a > 0 && tau > -a / b)
            tau = -a / b; /* the rate stops at zero */
        if (a <= 0 && b <= 0)
            return 0;
        return a * tau + 0.5 * b * tau * tau;
    }
    case PFX_RATE_CURVE: {
        const pfx_curve *c = &em->rate_curve;
        if (tau <= c->t[0])
            return c->v[0] * tau;
        double base = c->v[0] * c->t[0];
        size_t i = 0;
        while (i + 1 < c->count && c->t[i + 1] <= tau)
            i++;
        double s = tau - c->t[i];
        double slope = i + 1 < c->count ? (c->v[i + 1] - c->v[i]) / (c->t[i + 1] - c->t[i]) : 0;
        return base + c->integral[i] + c->v[i] * s + 0.5 * slope * s * s;
    }
    default:
        return 0;
    }
}

double pfx_emitter_max_rate(const pfx_emitter *em) {
    double rate = 0;
    switch (em->rate_kind) {
    case PFX_RATE_CONSTANT:
        rate = em->rate;
        break;
    case PFX_RATE_RANDOM:
        rate = em->rate + em->rate_var;
        break;
    case PFX_RATE_RAMP: {
        double horizon = isfinite(em->duration) ? em->duration : 0;
        rate = fmax(em->ramp_initial, em->ramp_initial + em->ramp_delta * horizon);
        break;
    }
    case PFX_RATE_CURVE:
        for (size_t i = 0; i < em->rate_curve.count; i++)
            rate = fmax(rate, em->rate_curve.v[i]);
        break;
    case PFX_RATE_INTERVAL: {
        double lo = pfx_value_min(&em->interval);
        rate = lo > 0 ? 1.0 / lo : 0;
        break;
    }
    }
    return rate;
}

double pfx_emitter_peak(const pfx_emitter *em) {
    const double life = em->max_lifetime;
    /* Continuous births: at most floor(rate * L) + 1 inside any window of
     * length L when consecutive births are at least 1 / rate apart. */
    double peak = floor(pfx_emitter_max_rate(em) * life) + 1;
    /* Bursts: every burst event whose particles can overlap in one window. */
    for (size_t i = 0; i < em->burst_count; i++) {
        const pfx_burst *b = &em->bursts[i];
        double events = b->interval > 0 ? floor(life / b->interval) + 1 : 1;
        if (events > b->cycles)
            events = b->cycles;
        if (em->loop) /* the burst comes back every period */
            events *= floor(life / em->duration) + 1;
        peak += events * floor(pfx_value_max(&b->count));
    }
    return peak;
}
