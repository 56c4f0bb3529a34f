/* The emission keys of an emitter: how many particles it makes and when.
 * Every form is validated here and reduced to one pfx_rate_kind plus bursts;
 * the schedule (src/sim/schedule.c) turns them into exact birth times. */
#include "compile/compile_emission.h"

#include <math.h>
#include <string.h>

#define MAX_RATE 1e7      /* births per second, any form */
#define MIN_INTERVAL 1e-4 /* seconds: at most 10,000 births per second */
#define MAX_KEYS 256
#define MAX_BURST_COUNT 1e6
#define MAX_CYCLES 1000000

/* Reads `[{t: s, value: v}, ...]` keys with increasing t into out (arena). */
static bool read_curve(pfx_reader *r, const pfx_node *n, const char *what, double lo, double hi,
                       pfx_curve *out) {
    static const char *const key_names[] = {"t", "value", NULL};
    if (n->count == 0 || n->count > MAX_KEYS) {
        pfx_read_error(r, n, "'%s' as a curve needs 1 to %d keys {t, value}", what, MAX_KEYS);
        return false;
    }
    out->count = n->count;
    out->t = pfx_arena_alloc(r->arena, n->count * sizeof *out->t);
    out->v = pfx_arena_alloc(r->arena, n->count * sizeof *out->v);
    out->integral = pfx_arena_alloc(r->arena, n->count * sizeof *out->integral);
    if (!out->t || !out->v || !out->integral)
        return false;
    bool ok = true;
    for (size_t i = 0; i < n->count; i++) {
        const pfx_node *k = n->items[i];
        if (!pfx_read_map(r, k, what)) {
            ok = false;
            continue;
        }
        ok &= pfx_read_check_keys(r, k, key_names, "a curve key");
        const pfx_node *t = pfx_node_get(k, "t"), *v = pfx_node_get(k, "value");
        if (!t || !v) {
            pfx_read_error(r, k, "a curve key needs both 't' and 'value'");
            ok = false;
            continue;
        }
        if (!pfx_read_number(r, t, "t", &out->t[i]) || !pfx_read_number(r, v, what, &out->v[i])) {
            ok = false;
            continue;
        }
        if (i > 0 && out->t[i] <= out->t[i - 1]) {
            pfx_read_error(r, t, "curve keys must have increasing 't', got %g after %g", out->t[i],
                           out->t[i - 1]);
            ok = false;
        }
        ok &= pfx_check_above(r, t, "t", out->t[i], 0, false) &&
              pfx_check_above(r, v, what, out->v[i], lo, false) &&
              pfx_check_below(r, v, what, out->v[i], hi, false);
    }
    if (!ok)
        return false;
    /* Cumulative integral of the linear pieces, for rate curves. */
    out->integral[0] = 0;
    for (size_t i = 1; i < n->count; i++)
        out->integral[i] =
            out->integral[i - 1] + 0.5 * (out->v[i] + out->v[i - 1]) * (out->t[i] - out->t[i - 1]);
    return true;
}

static bool read_rate(pfx_reader *r, const pfx_node *n, pfx_emitter *em) {
    static const char *const random_keys[] = {"mean", "var", NULL};
    static const char *const ramp_keys[] = {"initial", "delta", NULL};
    if (n->kind == PFX_NODE_SCALAR) {
        em->rate_kind = PFX_RATE_CONSTANT;
        return pfx_read_number(r, n, "rate", &em->rate) &&
               pfx_check_above(r, n, "rate", em->rate, 0, false) &&
               pfx_check_below(r, n, "rate", em->rate, MAX_RATE, false);
    }
    if (n->kind == PFX_NODE_SEQ) {
        em->rate_kind = PFX_RATE_CURVE;
        return read_curve(r, n, "rate", 0, MAX_RATE, &em->rate_curve);
    }
    if (pfx_node_get(n, "initial") || pfx_node_get(n, "delta")) {
        em->rate_kind = PFX_RATE_RAMP;
        if (!pfx_read_check_keys(r, n, ramp_keys, "'rate'"))
            return false;
        const pfx_node *a = pfx_node_get(n, "initial"), *d = pfx_node_get(n, "delta");
        return (!a || (pfx_read_number(r, a, "initial", &em->ramp_initial) &&
                       pfx_check_above(r, a, "initial", em->ramp_initial, 0, false) &&
                       pfx_check_below(r, a, "initial", em->ramp_initial, MAX_RATE, false))) &&
               (!d || (pfx_read_number(r, d, "delta", &em->ramp_delta) &&
                       pfx_check_above(r, d, "delta", em->ramp_delta, -MAX_RATE, false) &&
                       pfx_check_below(r, d, "delta", em->ramp_delta, MAX_RATE, false)));
    }
    em->rate_kind = PFX_RATE_RANDOM;
    if (!pfx_read_check_keys(r, n, random_keys, "'rate'"))
        return false;
    const pfx_node *m = pfx_node_get(n, "mean"), *v = pfx_node_get(n, "var");
    if (!m) {
        pfx_read_error(r, n,
                       "'rate' must be a number, {mean, var}, {initial, delta} or a curve "
                       "[{t, value}, ...]");
        return false;
    }
    return pfx_read_number(r, m, "mean", &em->rate) &&
           pfx_check_above(r, m, "mean", em->rate, 0, false) &&
           pfx_check_below(r, m, "mean", em->rate, MAX_RATE, false) &&
           (!v || (pfx_read_number(r, v, "var", &em->rate_var) &&
                   pfx_check_above(r, v, "var", em->rate_var, 0, false) &&
                   pfx_check_below(r, v, "var", em->rate_var, MAX_RATE, false)));
}

static bool read_bursts(pfx_reader *r, const pfx_node *n, pfx_emitter *em) {
    static const char *const burst_keys[] = {"time",     "count",       "cycles",
                                             "interval", "probability", NULL};
    if (n->kind != PFX_NODE_SEQ || n->count > MAX_KEYS) {
        pfx_read_error(r, n,
                       "'bursts' must be a list of {time, count, cycles, interval, "
                       "probability}");
        return false;
    }
    em->bursts = pfx_arena_alloc(r->arena, (n->count + 1) * sizeof *em->bursts);
    if (!em->bursts)
        return false;
    bool ok = true;
    for (size_t i = 0; i < n->count; i++) {
        const pfx_node *b = n->items[i];
        pfx_burst *out = &em->bursts[em->burst_count++];
        *out = (pfx_burst){0, {.dist = PFX_DIST_CONST, .a = 10}, 1, 0, 1};
        if (!pfx_read_map(r, b, "bursts")) {
            ok = false;
            continue;
        }
        ok &= pfx_read_check_keys(r, b, burst_keys, "a burst");
        const pfx_node *v;
        double cycles = 1;
        if ((v = pfx_node_get(b, "time")))
            ok &= pfx_read_number(r, v, "time", &out->time) &&
                  pfx_check_above(r, v, "time", out->time, 0, false);
        if ((v = pfx_node_get(b, "count")))
            ok &=
                pfx_read_value(r, v, "count", &out->count) &&
                pfx_check_above(r, v, "count", pfx_value_min(&out->count), 0, false) &&
                pfx_check_below(r, v, "count", pfx_value_max(&out->count), MAX_BURST_COUNT, false);
        if ((v = pfx_node_get(b, "cycles"))) {
            ok &= pfx_read_number(r, v, "cycles", &cycles) &&
                  pfx_check_above(r, v, "cycles", cycles, 1, false) &&
                  pfx_check_below(r, v, "cycles", cycles, MAX_CYCLES, false);
            if (cycles != floor(cycles)) {
                pfx_read_error(r, v, "'cycles' must be a whole number, got %g", cycles);
                ok = false;
            }
        }
        out->cycles = (uint32_t)fmax(1, fmin(cycles, MAX_CYCLES));
        if ((v = pfx_node_get(b, "interval")))
            ok &= pfx_read_number(r, v, "interval", &out->interval) &&
                  pfx_check_above(r, v, "interval", out->interval, 0, false);
        if (out->cycles > 1 && out->interval <= 0) {
            pfx_read_error(r, b, "a burst with 'cycles' above 1 needs an 'interval' above 0");
            ok = false;
        }
        if ((v = pfx_node_get(b, "probability")))
            ok &= pfx_read_number(r, v, "probability", &out->probability) &&
                  pfx_check_above(r, v, "probability", out->probability, 0, false) &&
                  pfx_check_below(r, v, "probability", out->probability, 1, false);
        if (i > 0 && out->time < em->bursts[i - 1].time) {
            pfx_read_error(r, b, "bursts must be listed in order of 'time'");
            ok = false;
        }
    }
    return ok;
}

bool pfx_compile_emission(pfx_reader *r, const pfx_node *n, pfx_emitter *em) {
    int errors = r->d->errors;
    em->rate_kind = PFX_RATE_CONSTANT;
    em->rate = 10;
    em->duration = INFINITY;
    const pfx_node *rate = pfx_node_get(n, "rate"), *interval = pfx_node_get(n, "interval"),
                   *bursts = pfx_node_get(n, "bursts"), *v;
    if (rate && interval) {
        pfx_read_error(r, interval, "an emitter takes either 'rate' or 'interval', not both");
    } else if (interval) {
        em->rate_kind = PFX_RATE_INTERVAL;
        if (pfx_read_value(r, interval, "interval", &em->interval))
            pfx_check_above(r, interval, "interval", pfx_value_min(&em->interval), MIN_INTERVAL,
                            false);
    } else if (rate) {
        read_rate(r, rate, em);
    } else if (bursts) {
        em->rate = 0; /* bursts alone */
    }
    if (bursts)
        read_bursts(r, bursts, em);
    if ((v = pfx_node_get(n, "start")) && pfx_read_number(r, v, "start", &em->start))
        pfx_check_above(r, v, "start", em->start, 0, false);
    if ((v = pfx_node_get(n, "duration")) && pfx_read_number(r, v, "duration", &em->duration))
        pfx_check_above(r, v, "duration", em->duration, 0, true);
    if ((v = pfx_node_get(n, "loop"))) {
        if (v->kind != PFX_NODE_SCALAR || (strcmp(v->text, "true") && strcmp(v->text, "false")))
            pfx_read_error(r, v, "'loop' must be true or false");
        else
            em->loop = !strcmp(v->text, "true");
        if (em->loop && !isfinite(em->duration))
            pfx_read_error(r, v, "a looping emitter needs a 'duration' (its period)");
    }
    if (em->rate_kind == PFX_RATE_RAMP && em->ramp_delta > 0 && !isfinite(em->duration) && rate)
        pfx_read_error(r, rate, "a rate that grows without end needs the emitter's 'duration'");
    return r->d->errors == errors;
}

bool pfx_read_keys3(pfx_reader *r, const pfx_node *n, const char *what, double fixed[3],
                    pfx_keys3 *keys) {
    static const char *const key_names[] = {"t", "value", NULL};
    if (n->kind != PFX_NODE_SEQ || n->count == 0 || n->items[0]->kind != PFX_NODE_MAP)
        return pfx_read_numbers(r, n, what, fixed, 3);
    if (n->count > MAX_KEYS) {
        pfx_read_error(r, n, "'%s' has %zu keyframes; the most is %d", what, n->count, MAX_KEYS);
        return false;
    }
    keys->count = n->count;
    keys->t = pfx_arena_alloc(r->arena, n->count * sizeof *keys->t);
    keys->v = pfx_arena_alloc(r->arena, n->count * sizeof *keys->v);
    if (!keys->t || !keys->v)
        return false;
    bool ok = true;
    for (size_t i = 0; i < n->count; i++) {
        const pfx_node *k = n->items[i];
        if (!pfx_read_map(r, k, what)) {
            ok = false;
            continue;
        }
        ok &= pfx_read_check_keys(r, k, key_names, "a keyframe");
        const pfx_node *t = pfx_node_get(k, "t"), *v = pfx_node_get(k, "value");
        if (!t || !v) {
            pfx_read_error(r, k, "a keyframe needs both 't' and 'value'");
            ok = false;
            continue;
        }
        if (!pfx_read_number(r, t, "t", &keys->t[i]) ||
            !pfx_read_numbers(r, v, what, keys->v[i], 3)) {
            ok = false;
            continue;
        }
        if (i > 0 && keys->t[i] <= keys->t[i - 1]) {
            pfx_read_error(r, t, "keyframes must have increasing 't', got %g after %g", keys->t[i],
                           keys->t[i - 1]);
            ok = false;
        }
    }
    if (ok)
        memcpy(fixed, keys->v[0], sizeof(double[3]));
    return ok;
}
