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

/* Reads `[{t: s, value: v}, ...]` keys with increasing t into out (arena),
 * with the integral at every key for the closed-form birth times. */
static bool read_curve(pfx_reader *r, const pfx_node *n, const char *what, double lo, double hi,
                       pfx_curve *out) {
    pfx_key_list_spec spec = {what, "t", MAX_KEYS, 1, true, 0, 1e9, lo, hi};
    size_t count = n->kind == PFX_NODE_SEQ ? n->count : 0;
    out->t = pfx_arena_alloc(r->arena, (count + 1) * sizeof *out->t);
    out->v = pfx_arena_alloc(r->arena, (count + 1) * sizeof *out->v);
    out->integral = pfx_arena_alloc(r->arena, (count + 1) * sizeof *out->integral);
    if (!out->t || !out->v || !out->integral || !pfx_read_key_list(r, n, &spec, out->t, out->v))
        return false;
    out->count = count;
    out->integral[0] = 0;
    for (size_t i = 1; i < count; i++)
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
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE,
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
    if (n->kind != PFX_NODE_SEQ) {
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE,
                       "'bursts' must be a list of {time, count, cycles, interval, "
                       "probability}");
        return false;
    }
    if (n->count > MAX_KEYS) {
        pfx_read_error(r, n, PFX_RULE_TOO_MANY, "an emitter has at most %d bursts, got %zu",
                       MAX_KEYS, n->count);
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
                pfx_read_error(r, v, PFX_RULE_NOT_INTEGER,
                               "'cycles' must be a whole number, got %g", cycles);
                ok = false;
            }
        }
        out->cycles = (uint32_t)fmax(1, fmin(cycles, MAX_CYCLES));
        if ((v = pfx_node_get(b, "interval")))
            ok &= pfx_read_number(r, v, "interval", &out->interval) &&
                  pfx_check_above(r, v, "interval", out->interval, 0, false);
        if (out->cycles > 1 && out->interval <= 0) {
            pfx_read_error(r, b, PFX_RULE_INCONSISTENT_VALUES,
                           "a burst with 'cycles' above 1 needs an 'interval' above 0");
            ok = false;
        }
        if ((v = pfx_node_get(b, "probability")))
            ok &= pfx_read_number(r, v, "probability", &out->probability) &&
                  pfx_check_above(r, v, "probability", out->probability, 0, false) &&
                  pfx_check_below(r, v, "probability", out->probability, 1, false);
        if (i > 0 && out->time < em->bursts[i - 1].time) {
            pfx_read_error(r, b, PFX_RULE_OUT_OF_ORDER, "bursts must be listed in order of 'time'");
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
        pfx_read_error(r, interval, PFX_RULE_CONFLICTING_KEYS,
                       "an emitter takes either 'rate' or 'interval', not both");
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
            pfx_read_error(r, v, PFX_RULE_WRONG_TYPE, "'loop' must be true or false");
        else
            em->loop = !strcmp(v->text, "true");
        if (em->loop && !isfinite(em->duration))
            pfx_read_error(r, v, PFX_RULE_MISSING_KEY,
                           "a looping emitter needs a 'duration' (its period)");
        else if (em->loop && em->duration < 1e-3)
            pfx_read_error(r, v, PFX_RULE_OUT_OF_RANGE,
                           "a looping emitter's 'duration' (its period) must be at least "
                           "0.001 s, got %g",
                           em->duration);
    }
    if (em->rate_kind == PFX_RATE_RAMP && em->ramp_delta > 0 && !isfinite(em->duration) && rate)
        pfx_read_error(r, rate, PFX_RULE_MISSING_KEY,
                       "a rate that grows without end needs the emitter's 'duration'");
    return r->d->errors == errors;
}

bool pfx_read_keys3(pfx_reader *r, const pfx_node *n, const char *what, double fixed[3],
                    pfx_keys3 *keys) {
    if (n->kind != PFX_NODE_SEQ || n->count == 0 || n->items[0]->kind != PFX_NODE_MAP)
        return pfx_read_numbers(r, n, what, fixed, 3);
    pfx_key_list_spec spec = {what, "t", MAX_KEYS, 3, true, -1e9, 1e9, 0, 0};
    keys->t = pfx_arena_alloc(r->arena, n->count * sizeof *keys->t);
    keys->v = pfx_arena_alloc(r->arena, n->count * sizeof *keys->v);
    if (!keys->t || !keys->v || !pfx_read_key_list(r, n, &spec, keys->t, &keys->v[0][0]))
        return false;
    keys->count = n->count;
    memcpy(fixed, keys->v[0], sizeof(double[3]));
    return true;
}
