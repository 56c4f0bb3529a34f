/* `pfx bench accuracy`: error against exact solutions, cost and measured
 * stability limits of every integrator, written as CSV and SVG charts. */
#ifndef PFX_BENCH_ACCURACY_H
#define PFX_BENCH_ACCURACY_H

#include <stdio.h>

#include "sim/motion.h"

/* Run every problem for every integrator over a sweep of dt, write
 * DIR/work-precision.csv/.svg and DIR/stability.csv/.svg (creating DIR).
 * Progress and failures go to log. Returns 0, or non-zero after printing
 * why. */
int pfx_bench_accuracy(const char *out_dir, FILE *log);

/* Largest stable k*h (oscillator = 0: v' = -k v) or omega*h (oscillator = 1:
 * x'' = -omega^2 x) of integrator, measured by bisection on the growth of
 * one particle stepped 20,000 times in double through pfx_motion_step_d. */
double pfx_bench_stability_limit(pfx_integrator integrator, int oscillator);

#endif
