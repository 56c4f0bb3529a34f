/* When an emitter's particles are born: the continuous rate (constant,
 * curve, Reeves ramp, Reeves mean +- var, or random intervals), bursts, the
 * emitter's start, duration and loop. A schedule yields birth times in
 * increasing order, exactly, independent of the simulation step. */
#ifndef PFX_SCHEDULE_H
#define PFX_SCHEDULE_H

#include <stdint.h>

#include "base/rng.h"
#include "model/effect.h"

#define PFX_MAX_BURSTS 256

/* Plain values only, so a simulation view copies it with the emitter. */
typedef struct pfx_schedule {
    uint64_t period; /* loop periods completed (0 when not looping) */
    uint64_t j;      /* continuous births so far in this period */
    double next;     /* emitter time of the next continuous birth in the period */
    /* RANDOM: the current one-second window and the count integral at its start */
    uint64_t window;
    double window_base;
    /* bursts: each burst's next cycle; the current event's births left */
    uint32_t cycle[PFX_MAX_BURSTS];
    uint64_t burst_left;
    double burst_time;
    pfx_rng rng;        /* intervals, random rates, burst counts and probabilities */
    pfx_rng period_rng; /* rng at the start of the period (loops repeat it) */
} pfx_schedule;

/* Starts the schedule of emitter em (stream: the emitter's). */
void pfx_schedule_init(pfx_schedule *s, const pfx_emitter *em, uint64_t seed, uint64_t stream);

/* Effect time of the next birth, or INFINITY when there is none. */
double pfx_schedule_peek(const pfx_schedule *s, const pfx_emitter *em);
/* Consumes the birth pfx_schedule_peek returned. */
void pfx_schedule_pop(pfx_schedule *s, const pfx_emitter *em);

/* Takes the births due up to effect time t, at most max, in order, their
 * times into times[]: as pfx_schedule_peek and pfx_schedule_pop one by
 * one (a burst event's births at once), stopping after the birth that
 * ends a loop period (the next period's draws start over). Returns how
 * many it took. */
uint32_t pfx_schedule_take(pfx_schedule *s, const pfx_emitter *em, double t, uint32_t max,
                           double *times);

/* Drops every birth due up to effect time t (a full pool, or births already
 * dead), without visiting each where the schedule allows, stopping at the
 * end of a loop period; returns how many births that was. */
uint64_t pfx_schedule_drop_until(pfx_schedule *s, const pfx_emitter *em, double t);

/* Skips, without visiting each, the births before effect time t where the
 * schedule allows it (continuous rates with a closed-form count); returns
 * how many were skipped. Births it cannot skip are left to peek and pop. */
uint64_t pfx_schedule_skip_before(pfx_schedule *s, const pfx_emitter *em, double t);

#endif
