/* pfx tune: one effect run under a ladder of simulation settings
 * (integrator x sim rate x substeps), each run compared particle by
 * particle and frame by frame with a converged reference, timed, and
 * checked for blow-ups (jobs/tune.c); the report of those runs as CSV,
 * JSON, an SVG and PNG work-precision chart and a text summary
 * (jobs/tune_report.c). The file is read once (the request's `loaded`);
 * every other setting compiles those bytes through jobs/load.h with --set
 * overrides, so a run is exactly what `pfx render --set ...` would
 * simulate, and saving the file during a tune changes none of its runs. */
#ifndef PFX_JOBS_TUNE_H
#define PFX_JOBS_TUNE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "compile/compile.h"
#include "jobs/load.h"
#include "model/motion.h"

/* The rates of the ladder: the file's rate x 2^j, j = -3..3. */
#define PFX_TUNE_RATE_LO (-3)
#define PFX_TUNE_RATE_HI 3
/* At most this many frames of the range are compared (evenly spread, the
 * first and last included): enough to catch an error anywhere in a life,
 * and it bounds the reference's memory. */
#define PFX_TUNE_MAX_FRAMES 64

/* What a tune is asked: the effect, its --set, the frames and the
 * tolerance (a screen error in pixels, or a distance in metres). */
typedef struct pfx_tune_request {
    const char *path;
    const pfx_loaded *loaded;           /* path loaded with `compile` (its effect not NULL) */
    const pfx_compile_options *compile; /* the user's options, --set included */
    long first, last;                   /* resolved frame range */
    double tolerance;                   /* > 0 */
    bool tolerance_px;                  /* tolerance in pixels, else metres */
} pfx_tune_request;

/* One run of the ladder. */
typedef struct pfx_tune_run {
    pfx_integrator integrator;
    double rate;                   /* sim.rate, steps per second */
    int substeps;                  /* sim.substeps given; 0: the effect's own (auto's choice) */
    bool current;                  /* the file's own setting (with the user's --set) */
    bool reference;                /* the reference every run is compared with */
    bool compiled;                 /* false: the effect does not compile this way (why) */
    bool blew_up;                  /* non-finite, exploding or huge: no error figures */
    char why[256];                 /* blew_up: the rule that predicted it, or that none did */
    double err_max_m, err_p99_m;   /* position error against the reference */
    double err_max_px, err_p99_px; /* the same on screen */
    uint64_t fates;                /* particles alive in one run and not in the other */
    uint64_t compared;             /* particle-frames compared */
    double seconds_per_s;          /* best measured wall time per simulated second */
    double particle_steps;         /* live particles x substeps, summed over the steps */
    int repeats;                   /* timings taken (best of these) */
} pfx_tune_run;

/* One finding of "what else the scene pays for". */
typedef struct pfx_tune_cost {
    char text[320];
    double saving; /* the fraction of that part's work or memory saved, 0..1 */
} pfx_tune_cost;

typedef struct pfx_tune_result {
    pfx_tune_run *runs;
    size_t count, cap;
    size_t current, reference, check; /* indices; check: the second-finest run */
    long recommended;                 /* index of the cheapest run within tolerance; -1: none */
    bool converged;                   /* reference and check agree far below the tolerance */
    double tol_m, tol_px;             /* the tolerance both ways */
    double m_per_px;                  /* metres a pixel spans at the emitters' typical depth */
    double depth;                     /* that depth (1 for ortho) */
    double sim_seconds;               /* simulated time per run */
    long frames_compared;
    pfx_tune_cost costs[16];
    size_t cost_count;
    char fails_below[PFX_INTEGRATOR_COUNT][200]; /* per integrator: "" or where it fails */
} pfx_tune_result;

/* Runs the ladder for r. Progress goes to `log` unless NULL. Returns false
 * with the reason in d when the reference cannot run or out of memory; a run that fails to compile
 * or blows up is a row, not a failure. Free res with pfx_tune_result_free. */
bool pfx_tune_run_ladder(const pfx_tune_request *r, pfx_tune_result *res, FILE *log, pfx_diags *d);
void pfx_tune_result_free(pfx_tune_result *res);

/* After the ladder: what else the scene pays for (jobs/tune_costs.c),
 * into res->costs: steps a frame beyond need, pools far above the peak
 * alive, particle-frames off screen or invisible, a depth sort that
 * changes no pixel, textures larger than their sprites on screen. One
 * more run of the file's setting over every frame of the range. False
 * with the reason in d. */
bool pfx_tune_scene_costs(const pfx_tune_request *r, pfx_tune_result *res, pfx_diags *d);

/* Writes DIR/tune.csv, tune.json, tune.svg and tune.png (each whole or
 * absent) and prints the summary on out. False with the reason in d. */
bool pfx_tune_report(const pfx_tune_request *r, const pfx_tune_result *res, const char *dir,
                     FILE *out, pfx_diags *d);

/* Parses a tolerance: NUMBER followed by px, m, mm or cm. False when the
 * text is none of those or the number is not > 0. */
bool pfx_tune_parse_tolerance(const char *text, double *value, bool *px);

#endif
