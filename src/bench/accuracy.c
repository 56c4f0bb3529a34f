/* `pfx bench accuracy`: every integrator on problems with exact solutions,
 * over dt = T/2^j, the largest error over the run (and at the end time)
 * against cost (force evaluations per simulated second, and measured ns
 * per particle-step in the float kernel, best of several), plus stability
 * limits measured by bisection. Writes CSV and SVG. It judges nothing: the
 * tests assert; this shows. */
#include "bench/accuracy.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "bench/accuracy_problems.h"
#include "output/atomic_file.h"
#include "output/svg_chart.h"

#define TWO_PI 6.283185307179586
#define G 9.81
#define J_MIN 2
#define J_MAX 14
#define NJ (J_MAX - J_MIN + 1)
#define TIMING_PARTICLES 4096

static const pfx_integrator integrators[] = {
    PFX_INTEGRATOR_EULER,  PFX_INTEGRATOR_SYMPLECTIC, PFX_INTEGRATOR_MIDPOINT, PFX_INTEGRATOR_RK4,
    PFX_INTEGRATOR_VERLET, PFX_INTEGRATOR_EXACT,      PFX_INTEGRATOR_BORIS,    PFX_INTEGRATOR_AUTO};
static const char *const colors[] = {"#d62728", "#ff7f0e", "#2ca02c", "#1f77b4",
                                     "#9467bd", "#000000", "#17becf", "#8c564b"};
/* A marker each, so that a line under another still shows (exact and
 * boris never share a panel); X is kept for unstable steps. */
static const pfx_mark marks[] = {PFX_MARK_DOT,     PFX_MARK_SQUARE, PFX_MARK_TRIANGLE,
                                 PFX_MARK_DIAMOND, PFX_MARK_RING,   PFX_MARK_PLUS,
                                 PFX_MARK_PLUS,    PFX_MARK_RING};
/* auto's default tolerance, m of position error per simulated second */
#define AUTO_TOLERANCE 1e-3
/* Runs of the timing, the best kept: one sample is noise on a busy machine */
#define TIMING_RUNS 5
#define NINT (sizeof integrators / sizeof integrators[0])
#define NPROB pfx_acc_problem_count
#define problems pfx_acc_problems

static pfx_motion_force *add(pfx_motion *m, pfx_motion_kind kind) {
    pfx_motion_force *f = &m->forces[m->force_count++];
    memset(f, 0, sizeof *f);
    f->kind = kind;
    f->name = "f";
    return f;
}

static void pool_of(pfx_acc_state *s, pfx_motion_pool_d *p) {
    *p = (pfx_motion_pool_d){
        .count = 1, .px = &s->x, .py = &s->y, .pz = &s->z, .vx = &s->u, .vy = &s->v, .vz = &s->w};
}

/* ns per particle-step: TIMING_PARTICLES copies of the problem's start
 * state in the float kernel, stepped at the given dt. */
static double time_float(const pfx_acc_problem *pr, pfx_integrator integ, double dt, float *buf) {
    pfx_motion m;
    pfx_acc_state s;
    memset(&m, 0, sizeof m);
    m.integrator = integ;
    pr->setup(&m, &s);
    pfx_motion_plan plan;
    pfx_motion_plan_prepare(&plan, &m, dt);
    const size_t n = TIMING_PARTICLES;
    float *c[6];
    double init[6] = {s.x, s.y, s.z, s.u, s.v, s.w};
    for (int k = 0; k < 6; k++) {
        c[k] = buf + k * n;
        for (size_t i = 0; i < n; i++)
            c[k][i] = (float)(init[k] * (1 + 1e-4 * (double)i / n));
    }
    pfx_motion_pool_f pool = {
        .count = n, .px = c[0], .py = c[1], .pz = c[2], .vx = c[3], .vy = c[4], .vz = c[5]};
    struct timespec a, b;
    int steps = 0;
    double elapsed = 0;
    clock_gettime(CLOCK_MONOTONIC, &a);
    do { /* at least 20 ms and 16 steps */
        for (int r = 0; r < 16; r++, steps++)
            pfx_motion_step_f(&plan, &pool, steps * dt);
        clock_gettime(CLOCK_MONOTONIC, &b);
        elapsed = (double)(b.tv_sec - a.tv_sec) * 1e9 + (double)(b.tv_nsec - a.tv_nsec);
    } while (elapsed < 2e7);
    return elapsed / ((double)steps * (double)n);
}

/* Largest unstable rate among the warnings, for the label; 0 if stable. */
static double unstable_rate(const pfx_motion *m, const char **what, bool *always) {
    *always = false;
    pfx_stability_warning w[8];
    size_t n = pfx_motion_check_stability(m, w, 8);
    for (size_t i = 0; i < n && i < 8; i++) {
        if (w[i].kind == PFX_STABILITY_UNSTABLE) {
            const pfx_motion_force *f = w[i].force >= 0 ? &m->forces[w[i].force] : NULL;
            *what = f && f->kind == PFX_MOTION_DRAG ? "k*dt" : "omega*dt";
            *always = w[i].limit == 0;
            return w[i].number;
        }
        if (w[i].kind == PFX_STABILITY_DRIFT && w[i].number > 0) {
            const pfx_motion_force *f = &m->forces[w[i].force];
            *what = "Omega*dt";
            *always = true;
            return fabs(f->charge) / (f->mass > 0 ? f->mass : 1) *
                   sqrt(f->field[0] * f->field[0] + f->field[1] * f->field[1] +
                        f->field[2] * f->field[2]) *
                   m->choice.dt / m->choice.steps;
        }
    }
    return 0;
}

/* ---- Stability limits, measured ---- */

static bool grows(pfx_integrator integ, int oscillator, double z) {
    pfx_motion m;
    memset(&m, 0, sizeof m);
    m.integrator = integ;
    m.substeps = 1;
    pfx_acc_state s = {0, 0, 0, 0, 0, 0};
    if (oscillator) {
        add(&m, PFX_MOTION_SPRING)->k = 1; /* omega = 1, so omega*h = h = z */
        s.x = 1;
    } else {
        add(&m, PFX_MOTION_DRAG)->k = 1;
        s.u = 1;
    }
    pfx_motion_plan plan;
    pfx_motion_plan_prepare(&plan, &m, z);
    pfx_motion_pool_d p;
    pool_of(&s, &p);
    for (int i = 0; i < 20000; i++) {
        pfx_motion_step_d(&plan, &p, i * z);
        /* bounded orbits near omega h = 2 reach 1/sqrt(1 - (omega h)^2/4) */
        double a = oscillator ? fmax(fabs(s.x), fabs(s.u)) : fabs(s.u);
        if (!(a < (oscillator ? 1e3 : 1.5)))
            return true;
    }
    return false;
}

double pfx_bench_stability_limit(pfx_integrator integ, int oscillator) {
    double lo = 1e-3, hi = 1e3;
    if (!grows(integ, oscillator, hi))
        return INFINITY;
    if (grows(integ, oscillator, lo))
        return 0;
    for (int i = 0; i < 60; i++) { /* geometric bisection */
        double mid = sqrt(lo * hi);
        if (grows(integ, oscillator, mid))
            hi = mid;
        else
            lo = mid;
    }
    return lo;
}

/* ---- Output ---- */

/* One point of the sweep. err[0] is the model run (double, born on the
 * grid); err[1 + mode] the emitted run of each pfx_birth_mode (float,
 * through pfx_sim; NAN where the step rate is not one an effect may ask). */
#define NRUN (1 + PFX_BIRTH_MODE_COUNT)
typedef struct result {
    double dt, cost, ns, rate;
    double err[NRUN], max_rate[NRUN], max_err[NRUN]; /* max_err: the largest over the run */
    bool always;                                     /* unstable at any dt (no stability region) */
    int steps;
    const char *rate_name;
} result;

static const char *run_name(int run) {
    return run == 0 ? "model (double, born on the grid)" : pfx_birth_mode_name(run - 1);
}

/* DIR/NAME as an atomic file (whole or absent, like every file pfx
 * writes), or NULL with why not on log. */
static pfx_atomic_file *open_output(const char *dir, const char *name, FILE *log) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    pfx_atomic_file *a = pfx_atomic_open(path, &d);
    pfx_diags_print(&d, log, false);
    pfx_diags_free(&d);
    return a;
}

/* Renames the file into place; 0, or 1 with why not on log. */
static int close_output(pfx_atomic_file *a, FILE *log) {
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    bool ok = pfx_atomic_commit(a, true, &d);
    pfx_diags_print(&d, log, false);
    pfx_diags_free(&d);
    return ok ? 0 : 1;
}

static int write_csv(const char *dir, result (*res)[NINT][NJ], FILE *log) {
    pfx_atomic_file *a = open_output(dir, "work-precision.csv", log);
    if (!a)
        return 1;
    FILE *f = pfx_atomic_stream(a);
    fprintf(f, "problem,integrator,run,dt,substeps,evals_per_s,error,max_error_per_s,"
               "ns_per_particle_step,unstable_rate_name,unstable_rate,max_error\n");
    for (size_t p = 0; p < NPROB; p++)
        for (size_t i = 0; i < NINT; i++) {
            if (!pfx_acc_applies(&problems[p], integrators[i]))
                continue;
            for (int run = 0; run < NRUN; run++)
                for (int j = 0; j < NJ; j++) {
                    const result *r = &res[p][i][j];
                    if (isnan(r->err[run]))
                        continue;
                    fprintf(f, "\"%s\",%s,\"%s\",%.9g,%d,%.6g,%.6g,%.6g,%.3f,%s,%.4g,%.6g\n",
                            problems[p].name, pfx_integrator_name(integrators[i]), run_name(run),
                            r->dt, r->steps, r->cost, r->err[run], r->max_rate[run], r->ns,
                            r->rate > 0 ? r->rate_name : "", r->rate, r->max_err[run]);
                }
        }
    return close_output(a, log);
}

/* The cost axis of problem p's panel: whole decades around every
 * integrator's cost, so the panels share a look. */
static void cost_range(size_t p, result (*res)[NINT][NJ], pfx_chart *c) {
    c->x0 = INFINITY, c->x1 = 0;
    for (size_t i = 0; i < NINT; i++)
        for (int j = 0; j < NJ; j++)
            if (pfx_acc_applies(&problems[p], integrators[i])) {
                c->x0 = fmin(c->x0, res[p][i][j].cost);
                c->x1 = fmax(c->x1, res[p][i][j].cost);
            }
    c->x0 = pow(10, floor(log10(c->x0)));
    c->x1 = pow(10, ceil(log10(c->x1)));
}

/* Integrator i's line on problem p's panel: its marker per stable dt, a
 * cross per unstable one, and a line of text, stacked at the panel's top
 * (row *rows, counted up) so that no two print over each other, with the
 * rate that makes the smallest unstable dt unstable (or that no dt is
 * stable). The error is the largest over the run, not only at age T (an
 * orbit can be far off mid-way and back on track at T). */
static void plot_integrator(FILE *f, const pfx_chart *c, size_t p, size_t i, int run,
                            result (*res)[NINT][NJ], int *rows) {
    double x[NJ], y[NJ];
    bool skip[NJ];
    for (int j = 0; j < NJ; j++) {
        x[j] = res[p][i][j].cost;
        y[j] = fmax(fmin(res[p][i][j].max_err[run], 1e3), c->y0);
        skip[j] = isnan(res[p][i][j].max_err[run]);
    }
    pfx_chart_line(f, c, NJ, x, y, skip, colors[i], integrators[i] == PFX_INTEGRATOR_AUTO);
    int labelled = 0, unstable = 0;
    for (int j = 0; j < NJ; j++)
        unstable += res[p][i][j].rate > 0;
    for (int j = NJ - 1; j >= 0; j--) { /* smallest unstable dt first */
        const result *r = &res[p][i][j];
        if (skip[j])
            continue;
        if (r->rate > 0) {
            pfx_chart_mark(f, c, x[j], y[j], PFX_MARK_CROSS, colors[i]);
            if (!labelled++) {
                char lab[80];
                if (r->always && unstable == NJ)
                    snprintf(lab, sizeof lab, "%s: unstable at every dt",
                             pfx_integrator_name(integrators[i]));
                else
                    snprintf(lab, sizeof lab, "%s: X from %s=%.2g",
                             pfx_integrator_name(integrators[i]), r->rate_name, r->rate);
                pfx_svg_text(f, c->left + c->width - 6, c->top + 14 + 12 * (*rows)++, 10, "end",
                             colors[i], lab);
            }
        } else {
            pfx_chart_mark(f, c, x[j], y[j], marks[i], colors[i]);
        }
    }
}

/* Reference slopes and auto's tolerance on a panel: error falls as
 * cost^-p for a method of order p (cost ~ 1/dt), drawn as grey segments
 * over two decades from the panel's top left, each labelled with its
 * order; and the error auto promises over a run of T seconds (its default
 * tolerance, in m per simulated second, times T), dashed across. */
static void reference_lines(FILE *f, const pfx_chart *c, double T) {
    static const int orders[] = {1, 2, 4};
    const double xa = c->x0 * 1.5, ya = 10;
    for (int k = 0; k < 3; k++) {
        double xb = xa * 100, yb = ya * pow(100, -orders[k]);
        if (yb < c->y0) { /* stop at the floor */
            xb = xa * pow(ya / c->y0, 1.0 / orders[k]);
            yb = c->y0;
        }
        pfx_chart_segment(f, c, xa, ya, xb, yb, "#999", false);
        char lab[16];
        snprintf(lab, sizeof lab, "order %d", orders[k]);
        pfx_svg_text(f, pfx_chart_px(c, xb) + 3, pfx_chart_py(c, yb) + 3, 9, "start", "#777", lab);
    }
    const double tol = AUTO_TOLERANCE * T;
    if (tol > c->y0 && tol < c->y1) {
        pfx_chart_segment(f, c, c->x0, tol, c->x1, tol, "#555", true);
        char lab[64];
        snprintf(lab, sizeof lab, "auto's tolerance: %g m/s x T = %.3g m", AUTO_TOLERANCE, tol);
        pfx_svg_text(f, c->left + 4, pfx_chart_py(c, tol) - 3, 9, "start", "#555", lab);
    }
}

/* Two integrators whose points coincide at every step (the same scheme
 * under two names, or auto choosing one of them at its own substeps) draw
 * one line over the other: a note at the panel's foot says so. */
static void note_coinciding(FILE *f, const pfx_chart *c, size_t p, int run,
                            result (*res)[NINT][NJ]) {
    int notes = 0;
    for (size_t a = 0; a < NINT; a++)
        for (size_t b = a + 1; b < NINT; b++) {
            if (!pfx_acc_applies(&problems[p], integrators[a]) ||
                !pfx_acc_applies(&problems[p], integrators[b]))
                continue;
            bool same = true;
            for (int j = 0; j < NJ && same; j++) {
                const result *ra = &res[p][a][j], *rb = &res[p][b][j];
                double ea = ra->max_err[run], eb = rb->max_err[run];
                if (isnan(ea) && isnan(eb))
                    continue;
                same = ra->cost == rb->cost && fabs(ea - eb) <= 1e-3 * fmax(fabs(ea), fabs(eb));
            }
            if (!same)
                continue;
            char lab[80];
            snprintf(lab, sizeof lab, "%s lies under %s (the same points)",
                     pfx_integrator_name(integrators[a]), pfx_integrator_name(integrators[b]));
            pfx_svg_text(f, c->left + c->width - 6, c->top + c->height - 8 - 12 * notes++, 10,
                         "end", "#333", lab);
        }
}

/* The chart of one run kind: file `name`, errors max_err[run], one panel
 * per problem in a grid of two columns. */
static int write_work_precision(const char *dir, const char *name, int run, result (*res)[NINT][NJ],
                                FILE *log) {
    pfx_atomic_file *a = open_output(dir, name, log);
    if (!a)
        return 1;
    FILE *f = pfx_atomic_stream(a);
    const int cols = 2, pw = 400, ph = 260, mx = 80, my = 70;
    const int W = cols * (pw + mx) + 160, H = (int)((NPROB + cols - 1) / cols) * (ph + my) + 90;
    pfx_svg_begin(f, W, H);
    char title[160];
    snprintf(title, sizeof title,
             "Work-precision, %s: largest position error over the run vs force evaluations per "
             "simulated second",
             run_name(run));
    pfx_svg_text(f, W / 2.0, 24, 16, "middle", "#000", title);
    pfx_svg_text(
        f, W / 2.0, 42, 11, "middle", "#555",
        run ? "through emission: an effect compiled and simulated by pfx (float state); "
              "dt = T/2^j where 1 <= 1/dt; X = outside the stability region; errors below 1e-9 "
              "drawn at 1e-9"
            : "dt = T/2^j; X = outside the stability region (labelled with its k*dt or "
              "omega*dt); errors below 1e-15 drawn at 1e-15");
    for (size_t p = 0; p < NPROB; p++) {
        pfx_chart c = {.left = mx + (double)(p % cols) * (pw + mx),
                       .top = 80 + (double)(p / cols) * (ph + my),
                       .width = pw,
                       .height = ph,
                       .log_x = true,
                       .log_y = true,
                       .y0 = run ? 1e-9 : 1e-15,
                       .y1 = 1e3};
        cost_range(p, res, &c);
        pfx_chart_axes(f, &c, problems[p].name, "force evaluations per simulated second",
                       "largest position error (m)");
        reference_lines(f, &c, problems[p].T);
        int rows = 0;
        for (size_t i = 0; i < NINT; i++)
            if (pfx_acc_applies(&problems[p], integrators[i]))
                plot_integrator(f, &c, p, i, run, res, &rows);
        note_coinciding(f, &c, p, run, res);
    }
    const char *labels[NINT];
    for (size_t i = 0; i < NINT; i++)
        labels[i] = pfx_integrator_name(integrators[i]);
    pfx_svg_legend_marked(f, W - 130, 90, (int)NINT, labels, (const char *const *)colors, marks);
    pfx_svg_end(f);
    return close_output(a, log);
}

/* The integrators whose stability limits are charted; boris shares exact's
 * row (the last one's label says so). */
static const pfx_integrator stab_integrators[] = {
    PFX_INTEGRATOR_EULER, PFX_INTEGRATOR_SYMPLECTIC, PFX_INTEGRATOR_MIDPOINT,
    PFX_INTEGRATOR_RK4,   PFX_INTEGRATOR_VERLET,     PFX_INTEGRATOR_EXACT};
enum { NS = sizeof stab_integrators / sizeof stab_integrators[0] };

static int write_stability_csv(const char *dir, double meas[NS][2], double theo[NS][2], FILE *log) {
    pfx_atomic_file *a = open_output(dir, "stability.csv", log);
    if (!a)
        return 1;
    FILE *f = pfx_atomic_stream(a);
    fprintf(f, "integrator,decay_kdt_measured,decay_kdt_theory,oscillator_wdt_measured,"
               "oscillator_wdt_theory\n");
    for (int i = 0; i < NS; i++)
        fprintf(f, "%s,%.6g,%.6g,%.6g,%.6g\n", pfx_integrator_name(stab_integrators[i]), meas[i][0],
                theo[i][0], meas[i][1], theo[i][1]);
    return close_output(a, log);
}

/* Row i of a stability panel: the measured limit m as a bar (clipped at
 * the axis end, its label then inside it), the theory t as a tick. */
static void stability_row(FILE *f, const pfx_chart *c, int i, double m, double t) {
    double yb = NS - i - 0.8, yt = NS - i - 0.2;
    const char *col = colors[i];
    pfx_chart_rect(f, c, 0, yb, fmin(m, 4), yt, col);
    char lab[64];
    if (isinf(m))
        snprintf(lab, sizeof lab, "stable at any step");
    else if (t == 0)
        snprintf(lab, sizeof lab, "%.3g (theory 0: grows at any step)", m);
    else
        snprintf(lab, sizeof lab, "%.4g (theory %.4g)", m, t);
    double lx = pfx_chart_px(c, fmin(m, 4)) + 4;
    if (isinf(m) || m > 3)
        lx = pfx_chart_px(c, 0) + 4;
    pfx_svg_text(f, lx, pfx_chart_py(c, 0.5 * (yb + yt)) + 4, 10, "start",
                 isinf(m) || m > 3 ? "#fff" : "#000", lab);
    if (!isinf(t)) {
        double x = pfx_chart_px(c, t);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#000\" "
                "stroke-width=\"2.5\"/>\n",
                x, pfx_chart_py(c, yb) + 3, x, pfx_chart_py(c, yt) - 3);
    }
    pfx_svg_text(f, c->left - 6, pfx_chart_py(c, 0.5 * (yb + yt)) + 4, 11, "end", "#000",
                 i == NS - 1 ? "exact/boris" : pfx_integrator_name(stab_integrators[i]));
}

static int write_stability_svg(const char *dir, double meas[NS][2], double theo[NS][2], FILE *log) {
    pfx_atomic_file *a = open_output(dir, "stability.svg", log);
    if (!a)
        return 1;
    FILE *f = pfx_atomic_stream(a);
    const int W = 900, H = 360;
    pfx_svg_begin(f, W, H);
    pfx_svg_text(f, W / 2.0, 24, 16, "middle", "#000",
                 "Largest stable step: measured by bisection (bar) vs theory (black tick)");
    pfx_svg_text(f, W / 2.0, 42, 11, "middle", "#555",
                 "20,000 steps of one particle in double; theory 0 = unstable at any step (the "
                 "measured bar is where growth shows within 20,000 steps)");
    const char *titles[2] = {"decay v' = -k v: largest k*dt",
                             "oscillator x'' = -w^2 x: largest omega*dt"};
    for (int o = 0; o < 2; o++) {
        pfx_chart c = {.left = 110 + o * 440,
                       .top = 80,
                       .width = 320,
                       .height = 230,
                       .x0 = 0,
                       .x1 = 4,
                       .y0 = 0,
                       .y1 = NS,
                       .no_y_ticks = true};
        pfx_chart_axes(f, &c, titles[o], o ? "omega*dt" : "k*dt", NULL);
        for (int i = 0; i < NS; i++)
            stability_row(f, &c, i, meas[i][o], theo[i][o]);
    }
    pfx_svg_end(f);
    return close_output(a, log);
}

/* The measured stability limits (decay k*dt, oscillator omega*dt) of each
 * integrator beside their theory, logged and written as CSV and SVG. */
static int write_stability(const char *dir, FILE *log) {
    double meas[NS][2], theo[NS][2];
    for (int i = 0; i < NS; i++)
        for (int o = 0; o < 2; o++) {
            const pfx_integrator integ = stab_integrators[i];
            meas[i][o] = pfx_bench_stability_limit(integ, o);
            pfx_scheme s = pfx_integrator_scheme(integ);
            theo[i][o] = o ? pfx_stability_oscillator_limit(s) : pfx_stability_decay_limit(s);
            fprintf(log, "  stability %-10s %s: measured %.5g, theory %.5g\n",
                    pfx_integrator_name(integ), o ? "omega*dt" : "k*dt    ", meas[i][o],
                    theo[i][o]);
        }
    int rc = write_stability_csv(dir, meas, theo, log);
    return rc ? rc : write_stability_svg(dir, meas, theo, log);
}

int pfx_bench_accuracy(const char *out_dir, FILE *log) {
    if (mkdir(out_dir, 0777) != 0 && errno != EEXIST) {
        fprintf(log, "pfx: cannot create '%s': %s\n", out_dir, strerror(errno));
        return 1;
    }
    result(*res)[NINT][NJ] = calloc(NPROB, sizeof *res);
    float *buf = malloc(6 * TIMING_PARTICLES * sizeof *buf);
    if (!res || !buf) {
        free(res);
        free(buf);
        fprintf(log, "pfx: out of memory\n");
        return 1;
    }
    for (size_t p = 0; p < NPROB; p++) {
        const pfx_acc_problem *pr = &problems[p];
        for (size_t i = 0; i < NINT; i++) {
            if (!pfx_acc_applies(pr, integrators[i]))
                continue;
            for (int j = 0; j < NJ; j++) {
                pfx_motion m;
                long steps = 1L << (J_MIN + j);
                result *r = &res[p][i][j];
                pfx_acc_result mr = pfx_acc_run_model(pr, integrators[i], steps, &m);
                r->err[0] = mr.error, r->max_rate[0] = mr.max_rate, r->max_err[0] = mr.max_error;
                for (int b = 0; b < PFX_BIRTH_MODE_COUNT; b++) {
                    double rate = (double)steps / pr->T;
                    r->err[1 + b] = r->max_rate[1 + b] = r->max_err[1 + b] = NAN;
                    if (rate < 1 || rate > 1e5)
                        continue;
                    pfx_acc_result er =
                        pfx_acc_run_emitted(pr, integrators[i], steps, (pfx_birth_mode)b);
                    r->err[1 + b] = er.error, r->max_rate[1 + b] = er.max_rate;
                    r->max_err[1 + b] = er.max_error;
                }
                r->dt = pr->T / (double)steps;
                r->steps = m.choice.steps;
                r->cost = pfx_motion_evals_per_step(&m) / r->dt;
                r->rate = unstable_rate(&m, &r->rate_name, &r->always);
            }
            /* time at the middle of the sweep: the kernel cost per substep
             * does not depend on dt; the best of several runs, since other
             * work on the machine only ever adds time */
            double ns = INFINITY;
            for (int k = 0; k < TIMING_RUNS; k++)
                ns = fmin(ns, time_float(pr, integrators[i], pr->T / 256, buf));
            for (int j = 0; j < NJ; j++)
                res[p][i][j].ns = ns;
            fprintf(log,
                    "  %-30s %-10s error at dt=T/256: %.3g (model), %.3g / %.3g / %.3g (emitted "
                    "at 0 / off grid / on a step end), %.1f ns/particle-step\n",
                    pr->name, pfx_integrator_name(integrators[i]), res[p][i][6].err[0],
                    res[p][i][6].err[1], res[p][i][6].err[2], res[p][i][6].err[3], ns);
        }
    }
    int rc = write_csv(out_dir, res, log);
    if (rc == 0)
        rc = write_work_precision(out_dir, "work-precision.svg", 0, res, log);
    if (rc == 0)
        rc = write_work_precision(out_dir, "work-precision-emitted.svg", 1 + PFX_BIRTH_OFF_GRID,
                                  res, log);
    if (rc == 0)
        rc = write_stability(out_dir, log);
    free(res);
    free(buf);
    return rc;
}
