/* The report of a tune (jobs/tune.h): the runs as CSV and JSON, the
 * work-precision chart as SVG (output/svg_chart.h) and PNG
 * (output/chart_png.h), and the summary on stdout. It runs nothing. */
#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/json_text.h"
#include "jobs/tune.h"
#include "output/atomic_file.h"
#include "output/chart_png.h"
#include "output/json_file.h"
#include "output/svg_chart.h"

/* One colour per integrator, in enum order (auto first). */
static const char *const colours[] = {"#000000", "#d62728", "#ff7f0e", "#2ca02c",
                                      "#1f77b4", "#9467bd", "#8c564b", "#e377c2"};

static const char *status_word(const pfx_tune_run *r) {
    return !r->compiled ? "not-applicable" : r->blew_up ? "unstable" : "ok";
}

/* The cost axis: milliseconds of wall time per simulated second. */
static double cost_ms(const pfx_tune_run *r) { return 1e3 * r->seconds_per_s; }

static bool write_csv(const pfx_tune_result *res, const char *path, pfx_diags *d) {
    pfx_atomic_file *a = pfx_atomic_open(path, d);
    if (!a)
        return false;
    FILE *f = pfx_atomic_stream(a);
    fputs("integrator,rate,substeps,current,reference,recommended,status,err_max_m,err_p99_m,"
          "err_max_px,err_p99_px,fates,compared,seconds_per_sim_second,particle_steps,repeats,"
          "why\n",
          f);
    for (size_t i = 0; i < res->count; i++) {
        const pfx_tune_run *r = &res->runs[i];
        fprintf(f, "%s,%.17g,%d,%d,%d,%d,%s,%.9g,%.9g,%.9g,%.9g,%llu,%llu,%.9g,%.9g,%d,\"",
                pfx_integrator_name(r->integrator), r->rate, r->substeps, r->current, r->reference,
                (long)i == res->recommended, status_word(r), r->err_max_m, r->err_p99_m,
                r->err_max_px, r->err_p99_px, (unsigned long long)r->fates,
                (unsigned long long)r->compared, r->seconds_per_s, r->particle_steps, r->repeats);
        for (const char *p = r->why; *p; p++)
            fputs(*p == '"' ? "\"\"" : (char[]){*p, 0}, f);
        fputs("\"\n", f);
    }
    return pfx_atomic_commit(a, false, d);
}

static json_t *run_json(const pfx_tune_result *res, size_t i) {
    const pfx_tune_run *r = &res->runs[i];
    return json_pack("{s:s, s:f, s:i, s:b, s:b, s:b, s:s, s:f, s:f, s:f, s:f, s:I, s:I, s:f, "
                     "s:f, s:i, s:s}",
                     "integrator", pfx_integrator_name(r->integrator), "rate", r->rate, "substeps",
                     r->substeps, "current", r->current, "reference", r->reference, "recommended",
                     (long)i == res->recommended, "status", status_word(r), "err_max_m",
                     r->err_max_m, "err_p99_m", r->err_p99_m, "err_max_px", r->err_max_px,
                     "err_p99_px", r->err_p99_px, "fates", (json_int_t)r->fates, "compared",
                     (json_int_t)r->compared, "seconds_per_sim_second", r->seconds_per_s,
                     "particle_steps", r->particle_steps, "repeats", r->repeats, "why", r->why);
}

static bool write_json(const pfx_tune_request *q, const pfx_tune_result *res, const char *path,
                       pfx_diags *d) {
    json_t *runs = json_array(), *costs = json_array(), *fails = json_object();
    for (size_t i = 0; i < res->count; i++)
        json_array_append_new(runs, run_json(res, i));
    for (size_t i = 0; i < res->cost_count; i++)
        json_array_append_new(costs, json_pack("{s:s, s:f}", "finding", res->costs[i].text,
                                               "saving", res->costs[i].saving));
    for (int in = 0; in < PFX_INTEGRATOR_COUNT; in++)
        if (res->fails_below[in][0])
            json_object_set_new(fails, pfx_integrator_name((pfx_integrator)in),
                                json_string(res->fails_below[in]));
    json_t *root = json_pack(
        "{s:o, s:{s:f, s:f, s:s}, s:f, s:f, s:I, s:b, s:I, s:I, s:I, s:o, s:o, s:o}", "effect",
        pfx_json_bytes(q->path), "tolerance", "px", res->tol_px, "m", res->tol_m, "given_in",
        q->tolerance_px ? "px" : "m", "metres_per_pixel", res->m_per_px, "simulated_seconds",
        res->sim_seconds, "frames_compared", (json_int_t)res->frames_compared, "converged",
        res->converged, "current", (json_int_t)res->current, "reference",
        (json_int_t)res->reference, "recommended", (json_int_t)res->recommended, "runs", runs,
        "unstable", fails, "scene_costs", costs);
    bool ok = pfx_json_file_write(path, root, d);
    json_decref(root);
    return ok;
}

/* The chart's ranges: every plotted run inside, decades padded. */
static void chart_range(const pfx_tune_result *res, double tol_px, pfx_chart *c) {
    double xl = INFINITY, xh = 0, yl = tol_px, yh = tol_px;
    for (size_t i = 0; i < res->count; i++) {
        const pfx_tune_run *r = &res->runs[i];
        if (!r->compiled || r->reference)
            continue;
        xl = fmin(xl, cost_ms(r));
        xh = fmax(xh, cost_ms(r));
        if (!r->blew_up && r->err_max_px > 0) {
            yl = fmin(yl, r->err_max_px);
            yh = fmax(yh, r->err_max_px);
        }
    }
    if (!(xl < INFINITY) || !(xl > 0))
        xl = 1e-3, xh = fmax(xh, 1);
    c->x0 = pow(10, floor(log10(xl)));
    c->x1 = pow(10, ceil(log10(xh * 1.0001)));
    c->y0 = pow(10, floor(log10(fmax(yl, 1e-9 * tol_px))));
    c->y1 = pow(10, ceil(log10(yh * 1.0001)));
    if (c->y1 <= c->y0)
        c->y1 = c->y0 * 10;
    if (c->x1 <= c->x0)
        c->x1 = c->x0 * 10;
}

/* Plotted error: a run with no error at all sits on the bottom edge. */
static double shown_error(const pfx_chart *c, const pfx_tune_run *r) {
    return r->err_max_px > c->y0 ? r->err_max_px : c->y0;
}

/* idx[0 .. n) in order of cost (insertion sort, stable: n is small). */
static void by_cost(const pfx_tune_result *res, size_t *idx, size_t n) {
    for (size_t a = 1; a < n; a++)
        for (size_t b = a;
             b > 0 && res->runs[idx[b]].seconds_per_s < res->runs[idx[b - 1]].seconds_per_s; b--) {
            size_t t = idx[b];
            idx[b] = idx[b - 1];
            idx[b - 1] = t;
        }
}

/* The Pareto front: runs within no other run's reach (cheaper and more
 * accurate), in order of cost. Returns how many went into idx. */
static size_t pareto(const pfx_tune_result *res, size_t *idx) {
    size_t n = 0;
    for (size_t i = 0; i < res->count; i++) {
        const pfx_tune_run *r = &res->runs[i];
        if (!r->compiled || r->blew_up || r->reference)
            continue;
        bool dominated = false;
        for (size_t j = 0; j < res->count && !dominated; j++) {
            const pfx_tune_run *o = &res->runs[j];
            dominated = j != i && o->compiled && !o->blew_up && !o->reference &&
                        o->seconds_per_s <= r->seconds_per_s && o->err_max_px <= r->err_max_px &&
                        (o->seconds_per_s < r->seconds_per_s || o->err_max_px < r->err_max_px);
        }
        if (!dominated)
            idx[n++] = i;
    }
    by_cost(res, idx, n);
    return n;
}

/* The stable, plotted runs of integrator `in` into idx, in order of cost:
 * one line of the chart. Returns how many. */
static int integrator_runs(const pfx_tune_result *res, pfx_integrator in, size_t *idx) {
    int n = 0;
    for (size_t i = 0; i < res->count; i++) {
        const pfx_tune_run *r = &res->runs[i];
        if (r->integrator == in && r->compiled && !r->reference && !r->blew_up && !r->current)
            idx[n++] = i;
    }
    by_cost(res, idx, (size_t)n);
    return n;
}

/* Draws the chart on a canvas: the SVG writer or the PNG rasteriser take
 * the same calls (output/chart_png.h mirrors svg_chart.h). */
static bool write_svg(const pfx_tune_result *res, const char *path, pfx_diags *d) {
    pfx_atomic_file *a = pfx_atomic_open(path, d);
    if (!a)
        return false;
    FILE *f = pfx_atomic_stream(a);
    const int W = 860, H = 560;
    pfx_chart c = {
        .left = 80, .top = 50, .width = 560, .height = 440, .log_x = true, .log_y = true};
    chart_range(res, res->tol_px, &c);
    pfx_svg_begin(f, W, H);
    pfx_chart_axes(f, &c, "work-precision: error on screen against cost",
                   "cost: ms of wall time per simulated second", "largest position error, px");
    /* The tolerance line. */
    double tx[2] = {c.x0, c.x1}, ty[2] = {res->tol_px, res->tol_px};
    fprintf(f, "<g id=\"tolerance\">\n");
    pfx_chart_line(f, &c, 2, tx, ty, NULL, "#555555", true);
    char label[160];
    snprintf(label, sizeof label, "tolerance %.3g px", res->tol_px);
    pfx_svg_text(f, c.left + c.width - 4, pfx_chart_py(&c, res->tol_px) - 4, 10, "end", "#555555",
                 label);
    fprintf(f, "</g>\n");
    /* One line per integrator, its runs in order of rate. */
    const char *labels[PFX_INTEGRATOR_COUNT + 4], *lcolours[PFX_INTEGRATOR_COUNT + 4];
    int nl = 0;
    double *x = malloc((res->count + 1) * sizeof *x), *y = malloc((res->count + 1) * sizeof *y);
    size_t *idx = malloc((res->count + 1) * sizeof *idx);
    if (!x || !y || !idx) {
        free(x), free(y), free(idx);
        pfx_atomic_abort(a);
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return false;
    }
    for (int in = 0; in < PFX_INTEGRATOR_COUNT; in++) {
        int n = integrator_runs(res, (pfx_integrator)in, idx);
        if (!n)
            continue;
        fprintf(f, "<g class=\"integrator\" id=\"line-%s\">\n",
                pfx_integrator_name((pfx_integrator)in));
        for (int k = 0; k < n; k++) {
            x[k] = cost_ms(&res->runs[idx[k]]);
            y[k] = shown_error(&c, &res->runs[idx[k]]);
        }
        pfx_chart_line(f, &c, n, x, y, NULL, colours[in], false);
        for (int k = 0; k < n; k++)
            pfx_chart_mark(f, &c, x[k], y[k], PFX_MARK_DOT, colours[in]);
        fprintf(f, "</g>\n");
        labels[nl] = pfx_integrator_name((pfx_integrator)in);
        lcolours[nl++] = colours[in];
    }
    /* Unstable runs: crosses on the top edge. */
    fprintf(f, "<g id=\"unstable\">\n");
    for (size_t i = 0; i < res->count; i++)
        if (res->runs[i].compiled && res->runs[i].blew_up)
            pfx_chart_mark(f, &c, cost_ms(&res->runs[i]), c.y1, PFX_MARK_CROSS,
                           colours[res->runs[i].integrator]);
    fprintf(f, "</g>\n");
    /* The Pareto front, dashed. */
    size_t np = pareto(res, idx);
    for (size_t k = 0; k < np; k++) {
        x[k] = cost_ms(&res->runs[idx[k]]);
        y[k] = shown_error(&c, &res->runs[idx[k]]);
    }
    fprintf(f, "<g id=\"pareto\">\n");
    pfx_chart_line(f, &c, (int)np, x, y, NULL, "#999999", true);
    fprintf(f, "</g>\n");
    /* The file's setting and the recommendation. */
    const pfx_tune_run *cur = &res->runs[res->current];
    fprintf(f, "<g id=\"current\">\n");
    if (cur->compiled && !cur->blew_up) {
        pfx_chart_mark(f, &c, cost_ms(cur), shown_error(&c, cur), PFX_MARK_SQUARE, "#000000");
        pfx_svg_text(f, pfx_chart_px(&c, cost_ms(cur)) + 8,
                     pfx_chart_py(&c, shown_error(&c, cur)) - 6, 11, "start", "#000000",
                     "the file's setting");
    }
    fprintf(f, "</g>\n<g id=\"recommended\">\n");
    if (res->recommended >= 0) {
        const pfx_tune_run *r = &res->runs[res->recommended];
        pfx_chart_mark(f, &c, cost_ms(r), shown_error(&c, r), PFX_MARK_SQUARE, "#17becf");
        pfx_svg_text(f, pfx_chart_px(&c, cost_ms(r)) + 8, pfx_chart_py(&c, shown_error(&c, r)) + 14,
                     11, "start", "#17becf", "recommended");
    }
    fprintf(f, "</g>\n");
    labels[nl] = "Pareto front";
    lcolours[nl++] = "#999999";
    labels[nl] = "tolerance";
    lcolours[nl++] = "#555555";
    fprintf(f, "<g id=\"legend\">\n");
    pfx_svg_legend(f, c.left + c.width + 30, c.top + 10, nl, labels, lcolours);
    fprintf(f, "</g>\n");
    pfx_svg_end(f);
    free(x), free(y), free(idx);
    return pfx_atomic_commit(a, false, d);
}

/* The same chart as a PNG: lines and markers through output/chart_png.h
 * (no text: the SVG carries the labels). */
static bool write_png(const pfx_tune_result *res, const char *path, pfx_diags *d) {
    const int W = 860, H = 560;
    pfx_chart c = {
        .left = 80, .top = 50, .width = 560, .height = 440, .log_x = true, .log_y = true};
    chart_range(res, res->tol_px, &c);
    pfx_chart_png *p = pfx_chart_png_create(W, H);
    if (!p) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return false;
    }
    pfx_chart_png_axes(p, &c);
    pfx_chart_png_line(p, &c, c.x0, res->tol_px, c.x1, res->tol_px, 0x555555, true);
    size_t *idx = malloc((res->count + 1) * sizeof *idx);
    if (!idx) {
        pfx_chart_png_destroy(p);
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return false;
    }
    for (int in = 0; in < PFX_INTEGRATOR_COUNT; in++) {
        unsigned col = (unsigned)strtoul(colours[in] + 1, NULL, 16);
        int n = integrator_runs(res, (pfx_integrator)in, idx);
        for (int k = 0; k < n; k++) {
            const pfx_tune_run *r = &res->runs[idx[k]];
            pfx_chart_png_mark(p, &c, cost_ms(r), shown_error(&c, r), PFX_MARK_DOT, col);
            if (k > 0) {
                const pfx_tune_run *q = &res->runs[idx[k - 1]];
                pfx_chart_png_line(p, &c, cost_ms(q), shown_error(&c, q), cost_ms(r),
                                   shown_error(&c, r), col, false);
            }
        }
    }
    for (size_t i = 0; i < res->count; i++)
        if (res->runs[i].compiled && res->runs[i].blew_up && !res->runs[i].reference)
            pfx_chart_png_mark(p, &c, cost_ms(&res->runs[i]), c.y1, PFX_MARK_CROSS,
                               (unsigned)strtoul(colours[res->runs[i].integrator] + 1, NULL, 16));
    free(idx);
    const pfx_tune_run *cur = &res->runs[res->current];
    if (cur->compiled && !cur->blew_up)
        pfx_chart_png_mark(p, &c, cost_ms(cur), shown_error(&c, cur), PFX_MARK_SQUARE, 0x000000);
    if (res->recommended >= 0) {
        const pfx_tune_run *r = &res->runs[res->recommended];
        pfx_chart_png_mark(p, &c, cost_ms(r), shown_error(&c, r), PFX_MARK_SQUARE, 0x17becf);
    }
    bool ok = pfx_chart_png_write(p, path, d);
    pfx_chart_png_destroy(p);
    return ok;
}

static void describe(const pfx_tune_run *r, char *buf, size_t size) {
    if (r->substeps > 0)
        snprintf(buf, size, "%s at %g steps/s, %d substep%s", pfx_integrator_name(r->integrator),
                 r->rate, r->substeps, r->substeps == 1 ? "" : "s");
    else
        snprintf(buf, size, "%s at %g steps/s", pfx_integrator_name(r->integrator), r->rate);
}

static void print_summary(const pfx_tune_request *q, const pfx_tune_result *res, FILE *out) {
    char a[128], b[128];
    const pfx_tune_run *cur = &res->runs[res->current], *ref = &res->runs[res->reference],
                       *chk = &res->runs[res->check];
    fprintf(out, "tune '%s': tolerance %.3g px = %.3g m at the emitters' depth (%.3g m a pixel)\n",
            q->path, res->tol_px, res->tol_m, res->m_per_px);
    describe(ref, a, sizeof a);
    describe(chk, b, sizeof b);
    fprintf(out, "reference: %s; %s: %s differs from it by at most %.3g px (%.3g m)\n", a,
            res->converged ? "converged" : "NOT converged", b, chk->err_max_px, chk->err_max_m);
    describe(cur, a, sizeof a);
    if (cur->blew_up)
        fprintf(out, "current: %s: unstable: %s\n", a, cur->why);
    else
        fprintf(out,
                "current: %s: error %.3g px (99%%: %.3g px), %.3g m; %llu particles' fate "
                "differs; %.3g ms per simulated second, %.4g particle-steps\n",
                a, cur->err_max_px, cur->err_p99_px, cur->err_max_m, (unsigned long long)cur->fates,
                cost_ms(cur), cur->particle_steps);
    if (!res->converged)
        fprintf(out,
                "the reference did not converge: every error below is only good to about %.3g "
                "px, the difference of its two finest runs\n",
                chk->err_max_px);
    if (res->recommended < 0) {
        fputs("no setting tried is within the tolerance\n", out);
    } else if ((size_t)res->recommended == res->current) {
        fputs("cheapest within tolerance: the current setting\n", out);
    } else {
        const pfx_tune_run *r = &res->runs[res->recommended];
        describe(r, a, sizeof a);
        double saving = cur->blew_up ? 0 : 1 - r->seconds_per_s / cur->seconds_per_s;
        fprintf(out,
                "cheapest within tolerance: %s: error %.3g px, %.3g ms per simulated second "
                "(%.0f%% %s than the current)\n",
                a, r->err_max_px, cost_ms(r), fabs(100 * saving), saving >= 0 ? "less" : "more");
        fputs("change: sim: {", out);
        const char *sep = " ";
        if (r->integrator != cur->integrator) {
            fprintf(out, "%sintegrator: %s", sep, pfx_integrator_name(r->integrator));
            sep = ", ";
        }
        if (fabs(r->rate - cur->rate) > 1e-9 * r->rate) {
            fprintf(out, "%srate: %.17g", sep, r->rate);
            sep = ", ";
        }
        if (r->substeps != cur->substeps && r->substeps > 0)
            fprintf(out, "%ssubsteps: %d", sep, r->substeps);
        fputs(" }\n", out);
    }
    for (int in = 0; in < PFX_INTEGRATOR_COUNT; in++)
        if (res->fails_below[in][0])
            fprintf(out, "unstable: %s %s\n", pfx_integrator_name((pfx_integrator)in),
                    res->fails_below[in]);
    if (res->cost_count)
        fputs("the scene also pays for:\n", out);
    for (size_t i = 0; i < res->cost_count; i++)
        fprintf(out, "  - %s (saves %.0f%%)\n", res->costs[i].text, 100 * res->costs[i].saving);
}

bool pfx_tune_report(const pfx_tune_request *r, const pfx_tune_result *res, const char *dir,
                     FILE *out, pfx_diags *d) {
    char path[4200];
    snprintf(path, sizeof path, "%s/tune.csv", dir);
    if (!write_csv(res, path, d))
        return false;
    snprintf(path, sizeof path, "%s/tune.json", dir);
    if (!write_json(r, res, path, d))
        return false;
    snprintf(path, sizeof path, "%s/tune.svg", dir);
    if (!write_svg(res, path, d))
        return false;
    snprintf(path, sizeof path, "%s/tune.png", dir);
    if (!write_png(res, path, d))
        return false;
    print_summary(r, res, out);
    return true;
}
