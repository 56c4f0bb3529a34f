/* Birth times. A continuous rate r(tau) makes births where its integral
 * Lambda(tau) crosses 1, 2, 3, ...: tau_k = Lambda^-1(k), solved in closed
 * form (linear pieces give quadratics, solved without cancellation), so no
 * birth time depends on the step. Bursts are merged in time order. It does
 * not draw any particle's attributes: that is sim.c's, from its own stream. */
#include "sim/schedule.h"

#include <math.h>
#include <string.h>

#include "sim/sample.h"

/* Smallest s >= 0 with a s + b s^2 / 2 = c (c >= 0), for rate a + b s;
 * INFINITY if the rate reaches 0 first. The form 2c / (a + sqrt(a^2 + 2bc))
 * avoids the cancellation of (-a + sqrt(...)) / b for small b. */
static double solve_linear_rate(double a, double b, double c) {
    if (c <= 0)
        return 0;
    double disc = a * a + 2 * b * c;
    if (disc < 0)
        return INFINITY;
    double den = a + sqrt(disc);
    return den > 0 ? 2 * c / den : INFINITY;
}

/* Lambda^-1(k) within one period for the closed-form kinds. */
static double inverse_integral(const pfx_emitter *em, double k) {
    switch (em->rate_kind) {
    case PFX_RATE_CONSTANT:
        return em->rate > 0 ? k / em->rate : INFINITY;
    case PFX_RATE_RAMP:
        return solve_linear_rate(em->ramp_initial, em->ramp_delta, k);
    case PFX_RATE_CURVE: {
        const pfx_curve *c = &em->rate_curve;
        double before = c->v[0] * c->t[0];
        if (k <= before)
            return c->v[0] > 0 ? k / c->v[0] : INFINITY;
        double left = k - before;
        size_t i = 0;
        while (i + 1 < c->count && c->integral[i + 1] < left)
            i++;
        double slope = i + 1 < c->count ? (c->v[i + 1] - c->v[i]) / (c->t[i + 1] - c->t[i]) : 0;
        double s = solve_linear_rate(c->v[i], slope, left - c->integral[i]);
        return c->t[i] + s;
    }
    default:
        return INFINITY;
    }
}

/* The rate of one-second window w under RANDOM: mean + var * R, R uniform
 * in [-1, 1], drawn from a generator keyed by the window, so any window's
 * rate is known without visiting the earlier ones. */
static double window_rate(const pfx_schedule *s, const pfx_emitter *em, uint64_t w) {
    pfx_rng r = s->period_rng;
    pfx_rng_advance(&r, 2 * w);
    double rate = em->rate + em->rate_var * (2 * pfx_rng_unit(&r) - 1);
    return rate > 0 ? rate : 0;
}

/* Emitter time of the start of the schedule's current period. */
static double period_start(const pfx_schedule *s, const pfx_emitter *em) {
    return em->loop ? (double)s->period * em->duration : 0;
}

/* Computes s->next: the emitter time (within the period) of continuous
 * birth j + 1, or INFINITY past the period or the duration. */
static void find_next(pfx_schedule *s, const pfx_emitter *em) {
    double k = (double)(s->j + 1), t;
    switch (em->rate_kind) {
    case PFX_RATE_INTERVAL:
        return; /* s->next is advanced by pop */
    case PFX_RATE_RANDOM: {
        /* Windows past the effect's end (or the period) are never needed:
         * a rate near zero must not walk a billion empty seconds. */
        double limit = fmin(em->duration, em->horizon);
        if (em->rate + em->rate_var <= 0)
            limit = 0;
        for (;;) {
            if ((double)s->window >= limit) {
                t = INFINITY;
                break;
            }
            double r = window_rate(s, em, s->window);
            if (s->window_base + r >= k && r > 0) {
                t = (double)s->window + (k - s->window_base) / r;
                break;
            }
            s->window_base += r;
            s->window++;
        }
        break;
    }
    default:
        t = inverse_integral(em, k);
    }
    s->next = t <= em->duration ? t : INFINITY;
}

/* The next burst event, merged across bursts by time (ties: file order):
 * its time and count. Each event draws its count and probability (fixed
 * draws, in time order); an event that does not fire is passed over. Cycles
 * past the period (or the duration) are never visited. */
static void find_burst(pfx_schedule *s, const pfx_emitter *em) {
    s->burst_left = 0;
    s->burst_time = INFINITY;
    for (;;) {
        size_t best = em->burst_count;
        double best_t = INFINITY;
        for (size_t i = 0; i < em->burst_count; i++) {
            const pfx_burst *b = &em->bursts[i];
            if (s->cycle[i] >= b->cycles)
                continue;
            double t = b->time + b->interval * s->cycle[i];
            if (!(t <= em->duration)) {
                s->cycle[i] = b->cycles; /* later cycles are later still */
                continue;
            }
            if (t < best_t)
                best_t = t, best = i;
        }
        if (best == em->burst_count)
            return;
        const pfx_burst *b = &em->bursts[best];
        double count = pfx_sample_value(&b->count, &s->rng);
        double u = pfx_rng_unit(&s->rng);
        s->cycle[best]++;
        if (u < b->probability && count >= 1) {
            s->burst_time = best_t;
            s->burst_left = (uint64_t)floor(count);
            return;
        }
    }
}

static void start_period(pfx_schedule *s, const pfx_emitter *em) {
    s->rng = s->period_rng;
    pfx_rng_advance(&s->rng, 1u << 20); /* clear of the window-rate draws */
    s->j = 0;
    s->window = 0;
    s->window_base = 0;
    memset(s->cycle, 0, sizeof s->cycle);
    if (em->rate_kind == PFX_RATE_INTERVAL) {
        double first = pfx_sample_value(&em->interval, &s->rng);
        s->next = first <= em->duration ? first : INFINITY;
    } else {
        find_next(s, em);
    }
    find_burst(s, em);
}

void pfx_schedule_init(pfx_schedule *s, const pfx_emitter *em, uint64_t seed, uint64_t stream) {
    *s = (pfx_schedule){0};
    pfx_rng_seed(&s->period_rng, seed, stream ^ 0x5bd1e9955bd1e995ULL);
    start_period(s, em);
}

double pfx_schedule_peek(const pfx_schedule *s, const pfx_emitter *em) {
    /* fmin(next, burst) without the libm call: neither is NaN, and on a
     * tie both give the second (glibc's fmin is minsd) */
    const double burst = s->burst_left ? s->burst_time : INFINITY;
    double tau = s->next < burst ? s->next : burst;
    if (tau == INFINITY)
        return INFINITY;
    return em->start + period_start(s, em) + tau;
}

void pfx_schedule_pop(pfx_schedule *s, const pfx_emitter *em) {
    /* Continuous births first when a burst falls at the same instant. */
    if (s->burst_left && s->burst_time < s->next) {
        if (--s->burst_left == 0) {
            find_burst(s, em);
        }
    } else {
        s->j++;
        if (em->rate_kind == PFX_RATE_INTERVAL) {
            double next = s->next + pfx_sample_value(&em->interval, &s->rng);
            s->next = next <= em->duration ? next : INFINITY;
        } else {
            find_next(s, em);
        }
    }
    if (em->loop && s->next == INFINITY && !s->burst_left) {
        s->period++;
        start_period(s, em);
    }
}

uint32_t pfx_schedule_take(pfx_schedule *s, const pfx_emitter *em, double t, uint32_t max,
                           double *times) {
    const uint64_t period = s->period;
    uint32_t n = 0;
    while (n < max && s->period == period) {
        if (s->burst_left > 1 && s->burst_time < s->next) {
            /* A burst event's births but its last: one time, and popping
             * them only counts down (pfx_schedule_pop). */
            const double at = em->start + period_start(s, em) + s->burst_time;
            if (!(at <= t))
                break;
            uint64_t k = s->burst_left - 1;
            k = k < max - n ? k : max - n;
            for (uint64_t c = 0; c < k; c++)
                times[n++] = at;
            s->burst_left -= k;
            continue;
        }
        const double at = pfx_schedule_peek(s, em);
        if (!(at <= t))
            break;
        pfx_schedule_pop(s, em);
        times[n++] = at;
    }
    return n;
}

uint64_t pfx_schedule_skip_before(pfx_schedule *s, const pfx_emitter *em, double t) {
    if (em->rate_kind == PFX_RATE_INTERVAL)
        return 0;
    double tau = t - em->start - period_start(s, em);
    if (em->loop)
        tau = fmin(tau, em->duration);
    if (tau <= s->next)
        return 0;
    /* Births k with Lambda^-1(k) < tau: k < Lambda(tau). For the Reeves
     * windows the integral is known window by window. */
    double lambda;
    if (em->rate_kind == PFX_RATE_RANDOM) {
        double limit = fmin(fmin(em->duration, em->horizon), tau);
        while ((double)(s->window + 1) <= limit) {
            s->window_base += window_rate(s, em, s->window);
            s->window++;
        }
        lambda = s->window_base + window_rate(s, em, s->window) * (tau - (double)s->window);
    } else {
        lambda = pfx_emitter_births_by(em, tau);
    }
    double count = ceil(lambda) - 1;
    if (count <= (double)s->j)
        return 0;
    uint64_t skipped = (uint64_t)count - s->j;
    s->j = (uint64_t)count;
    find_next(s, em);
    if (em->loop && s->next == INFINITY && !s->burst_left) { /* as pop: the next period */
        s->period++;
        start_period(s, em);
    }
    return skipped;
}

uint64_t pfx_schedule_drop_until(pfx_schedule *s, const pfx_emitter *em, double t) {
    uint64_t dropped = 0;
    const uint64_t period = s->period;
    for (; s->period == period;) {
        double next = pfx_schedule_peek(s, em);
        if (!(next <= t))
            return dropped;
        if (s->burst_left && s->burst_time < s->next) {
            /* The whole rest of a burst event at once. */
            dropped += s->burst_left;
            s->burst_left = 1;
            pfx_schedule_pop(s, em);
            continue;
        }
        uint64_t skipped = pfx_schedule_skip_before(s, em, nextafter(t, INFINITY));
        if (skipped) {
            dropped += skipped;
            continue;
        }
        pfx_schedule_pop(s, em);
        dropped++;
    }
    return dropped; /* a new period: its draws start over (see sim.c) */
}
