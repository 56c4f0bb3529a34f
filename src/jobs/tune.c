/* The ladder of jobs/tune.h: the file's bytes, read once, compiled once
 * per setting through pfx_load_bytes with --set sim.integrator/sim.rate/
 * sim.substeps appended to the user's (the file's own setting is the
 * effect already loaded), simulated to a fixed set of frames, and each
 * frame's particles compared by (emitter, birth id) with the reference's.
 * It writes nothing; jobs/tune_report.c does. */
#include "jobs/tune.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "model/kill_rules.h"
#include "sim/sim.h"

/* A particle of a compared frame: its emitter and birth id as one key (ids
 * are exact in time, so the same particle has the same key at any rate). */
typedef struct tune_point {
    uint64_t key;
    double p[3];
} tune_point;

/* The particles of one compared frame, sorted by key. */
typedef struct tune_frame {
    tune_point *pts;
    size_t n;
} tune_frame;

/* What one run is measured against, and its scratch. */
typedef struct tune_ctx {
    const pfx_tune_request *req;
    pfx_tune_result *res;
    long frames[PFX_TUNE_MAX_FRAMES];
    int nframes;
    tune_frame ref[PFX_TUNE_MAX_FRAMES]; /* the reference's particles */
    tune_point *scratch;                 /* one frame of the run being compared */
    size_t scratch_cap;
    double *err_m, *err_px; /* every compared particle-frame's error */
    size_t nerr, cap_m, cap_px;
    uint64_t *fate_keys; /* keys alive in one run and not the other */
    size_t nfate, fate_cap;
    const pfx_camera *cam;
    int width, height;
    FILE *log;
} tune_ctx;

/* The highest sim.rate the format takes (compile/compiler.h). */
#define TUNE_MAX_RATE 100000.0

/* The most particle-frames the reference may hold (32 bytes each). */
#define TUNE_MAX_POINTS (8u << 20)

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_key(const void *a, const void *b) {
    uint64_t x = ((const tune_point *)a)->key, y = ((const tune_point *)b)->key;
    return x < y ? -1 : x > y;
}

static int by_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static int by_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Grows *p (of *cap elements of `size` bytes) to hold at least `need`. */
static bool grow(void **p, size_t *cap, size_t need, size_t size) {
    if (need <= *cap)
        return true;
    size_t n = *cap ? *cap : 1024;
    while (n < need)
        n *= 2;
    void *q = realloc(*p, n * size);
    if (!q)
        return false;
    *p = q;
    *cap = n;
    return true;
}

/* The live particles of state s into ctx->scratch, sorted by key. */
static bool gather(tune_ctx *c, const pfx_sim *s, size_t *n) {
    size_t total = 0;
    for (size_t i = 0; i < s->effect->emitter_count; i++)
        total += s->pools[i].count;
    if (!grow((void **)&c->scratch, &c->scratch_cap, total + 1, sizeof *c->scratch))
        return false;
    size_t k = 0;
    for (size_t i = 0; i < s->effect->emitter_count; i++) {
        const pfx_pool *p = &s->pools[i];
        for (uint32_t j = 0; j < p->count; j++)
            c->scratch[k++] =
                (tune_point){((uint64_t)i << 32) | p->id[j], {p->px[j], p->py[j], p->pz[j]}};
    }
    qsort(c->scratch, k, sizeof *c->scratch, by_key);
    *n = k;
    return true;
}

static bool add_fate(tune_ctx *c, uint64_t key) {
    if (!grow((void **)&c->fate_keys, &c->fate_cap, c->nfate + 1, sizeof *c->fate_keys))
        return false;
    c->fate_keys[c->nfate++] = key;
    return true;
}

/* The screen distance of a and b in pixels: NAN (counted in metres only)
 * when neither lands on the image, or either is not in front of the
 * camera; each point is first clamped to a margin of one image size
 * around it, so a point grazing the camera's plane cannot make an error
 * of millions of pixels out of a few centimetres. */
static double screen_error(const tune_ctx *c, const double a[3], const double b[3]) {
    double pa[2], pb[2], da, db;
    if (!pfx_camera_project(c->cam, c->width, c->height, a, pa, &da) ||
        !pfx_camera_project(c->cam, c->width, c->height, b, pb, &db))
        return NAN;
    const double w = c->width, h = c->height;
    bool on_a = pa[0] >= 0 && pa[0] <= w && pa[1] >= 0 && pa[1] <= h;
    bool on_b = pb[0] >= 0 && pb[0] <= w && pb[1] >= 0 && pb[1] <= h;
    if (!on_a && !on_b)
        return NAN;
    for (int k = 0; k < 2; k++) {
        double lo = -(k ? h : w), hi = 2 * (k ? h : w);
        pa[k] = fmin(fmax(pa[k], lo), hi);
        pb[k] = fmin(fmax(pb[k], lo), hi);
    }
    return hypot(pa[0] - pb[0], pa[1] - pb[1]);
}

/* b, of the emitter in key's high half, moved by whole sizes of that
 * emitter's wrapping box (bounds: wrap) to the copy nearest a, into out:
 * a particle that wraps on one step in one run and on the next in the
 * other is a box size from its twin but has not strayed that far
 * (snow_box: 391 px), so the error is the shortest displacement in the
 * box. Without wrapping bounds, b itself. */
static void nearest_image(const pfx_effect *e, uint64_t key, const double a[3], const double b[3],
                          double out[3]) {
    const pfx_kill_rules *k = e->emitters[key >> 32].kill;
    for (int i = 0; i < 3; i++) {
        out[i] = b[i];
        if (k && k->bounds == PFX_BOUNDS_WRAP) {
            const double size = 2 * k->bounds_half[i];
            out[i] -= size * round((b[i] - a[i]) / size);
        }
    }
}

/* Compares scratch[0..n) with reference frame f of effect e: a merge of
 * two sorted lists; a key in one only is a particle whose fate differs. */
static bool compare_frame(tune_ctx *c, const pfx_effect *e, int f, size_t n) {
    const tune_frame *r = &c->ref[f];
    size_t i = 0, j = 0;
    if (!grow((void **)&c->err_m, &c->cap_m, c->nerr + n, sizeof *c->err_m) ||
        !grow((void **)&c->err_px, &c->cap_px, c->nerr + n, sizeof *c->err_px))
        return false;
    while (i < r->n || j < n) {
        if (j == n || (i < r->n && r->pts[i].key < c->scratch[j].key)) {
            if (!add_fate(c, r->pts[i++].key))
                return false;
        } else if (i == r->n || c->scratch[j].key < r->pts[i].key) {
            if (!add_fate(c, c->scratch[j++].key))
                return false;
        } else {
            const double *a = r->pts[i].p;
            double b[3];
            nearest_image(e, r->pts[i].key, a, c->scratch[j].p, b);
            double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                            (a[2] - b[2]) * (a[2] - b[2]));
            c->err_m[c->nerr] = isfinite(d) ? d : INFINITY;
            c->err_px[c->nerr] = screen_error(c, a, b);
            c->nerr++;
            i++, j++;
        }
    }
    return true;
}

/* The value below which 99 % of v[0..n) lie (NANs dropped); sorts v. */
static double p99(double *v, size_t n, double *max) {
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (!isnan(v[i]))
            v[k++] = v[i];
    *max = 0;
    if (!k)
        return 0;
    qsort(v, k, sizeof *v, by_double);
    *max = v[k - 1];
    return v[(size_t)floor(0.99 * (double)(k - 1))];
}

/* The user's --set and ours after them, into a fresh options struct. */
typedef struct tune_sets {
    const char *v[PFX_MAX_SETS + 3];
    char buf[3][64];
    pfx_compile_options opt;
} tune_sets;

static void make_sets(const pfx_tune_request *r, const pfx_tune_run *run, tune_sets *s) {
    s->opt = *r->compile;
    size_t n = 0;
    for (size_t i = 0; i < r->compile->set_count; i++)
        s->v[n++] = r->compile->sets[i];
    if (!run->current) {
        snprintf(s->buf[0], sizeof s->buf[0], "sim.integrator=%s",
                 pfx_integrator_name(run->integrator));
        snprintf(s->buf[1], sizeof s->buf[1], "sim.rate=%.17g", run->rate);
        s->v[n++] = s->buf[0];
        s->v[n++] = s->buf[1];
        if (run->substeps > 0) {
            snprintf(s->buf[2], sizeof s->buf[2], "sim.substeps=%d", run->substeps);
            s->v[n++] = s->buf[2];
        }
    }
    s->opt.sets = s->v;
    s->opt.set_count = n;
}

/* The first stability warning of any emitter of e, into why; false when
 * none predicts trouble. */
static bool predicted(const pfx_effect *e, char *why, size_t size) {
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_motion *m = e->emitters[i].motion;
        pfx_stability_warning w;
        if (m && pfx_motion_check_stability(m, &w, 1)) {
            snprintf(why, size, "emitter '%.60s': %.180s", e->emitters[i].name, w.message);
            return true;
        }
    }
    return false;
}

/* Simulates e to every compared frame. With `record`, keeps each frame as
 * the reference; with `compare`, compares each with it. Returns the wall
 * time spent simulating (comparison excluded), or a negative value when
 * memory ran out; *blew: the state went non-finite or exploded. */
static double simulate(tune_ctx *c, const pfx_effect *e, bool record, bool compare,
                       double *particle_steps, bool *blew) {
    pfx_diags quiet;
    pfx_diags_init_runtime(&quiet);
    pfx_sim *s = pfx_sim_create(e, &quiet), *view = pfx_sim_create(e, &quiet);
    double spent = -1, steps_done = 0;
    uint64_t last_step = 0;
    *blew = false;
    if (!s || !view)
        goto done;
    spent = 0;
    for (int f = 0; f < c->nframes; f++) {
        double t0 = now_s();
        const pfx_sim *st = pfx_sim_frame(s, view, c->frames[f]);
        spent += now_s() - t0;
        if (s->failed || view->failed) {
            *blew = true;
            break;
        }
        /* Particle-steps: the live count times the steps (each of its
         * substeps) taken since the last compared frame. */
        for (size_t i = 0; i < e->emitter_count; i++) {
            const pfx_motion *m = e->emitters[i].motion;
            int sub = m && m->choice.steps > 0 ? m->choice.steps : 1;
            steps_done += (double)st->pools[i].count * (double)(s->step - last_step) * sub;
        }
        last_step = s->step;
        if (!record && !compare)
            continue;
        size_t n;
        if (!gather(c, st, &n)) {
            spent = -1;
            break;
        }
        if (record) {
            tune_frame *r = &c->ref[f];
            r->pts = malloc((n + 1) * sizeof *r->pts);
            if (!r->pts) {
                spent = -1;
                break;
            }
            memcpy(r->pts, c->scratch, n * sizeof *r->pts);
            r->n = n;
        }
        if (compare && !compare_frame(c, e, f, n)) {
            spent = -1;
            break;
        }
    }
done:
    *particle_steps = steps_done;
    pfx_sim_destroy(view);
    pfx_sim_destroy(s);
    pfx_diags_free(&quiet);
    return spent;
}

/* The effect of one run: the file's own setting is the effect loaded;
 * another compiles the same bytes with its --set into l (*own: the caller
 * frees l). NULL when it does not compile so. */
static const pfx_effect *run_effect(const pfx_tune_request *r, const pfx_tune_run *run,
                                    pfx_loaded *l, bool *own) {
    *own = !run->current;
    if (run->current)
        return r->loaded->effect;
    tune_sets sets;
    make_sets(r, run, &sets);
    return pfx_load_bytes(l, r->path, r->loaded->source, r->loaded->source_len, &sets.opt);
}

/* Compiles, simulates, compares and times one run into `run`. False only
 * when memory ran out; a setting that does not compile is a row saying so. */
static bool measure(tune_ctx *c, pfx_tune_run *run, bool record) {
    pfx_loaded l;
    bool own;
    const pfx_effect *e = run_effect(c->req, run, &l, &own);
    if (!e) {
        run->compiled = false;
        snprintf(run->why, sizeof run->why, "does not compile with this setting");
        if (own)
            pfx_loaded_free(&l);
        return true;
    }
    run->compiled = true;
    if (run->current) {
        run->integrator = e->integrator;
        run->rate = e->sim_rate;
        run->substeps = e->substeps;
    }
    char why[256] = "";
    bool warned = predicted(e, why, sizeof why);
    c->nerr = c->nfate = 0;
    bool blew;
    double steps, best = simulate(c, e, record, !record, &steps, &blew);
    if (best < 0) {
        if (own)
            pfx_loaded_free(&l);
        return false;
    }
    run->particle_steps = steps;
    run->repeats = 1;
    /* Best of several: a cheap run is timed again (noise is largest
     * there); an expensive one is already well above the timer's noise. */
    for (int k = 1; !blew && k < (best < 0.02 ? 3 : best < 0.2 ? 2 : 1); k++) {
        bool b2;
        double s2, t = simulate(c, e, false, false, &s2, &b2);
        if (t >= 0 && t < best)
            best = t;
        run->repeats++;
    }
    run->seconds_per_s = best / c->res->sim_seconds;
    if (blew) {
        run->blew_up = true;
        snprintf(run->why, sizeof run->why, "the state went non-finite or exploded; %s",
                 warned ? why : "no stability rule predicted it");
    } else if (!record) {
        run->compared = c->nerr;
        run->err_p99_m = p99(c->err_m, c->nerr, &run->err_max_m);
        run->err_p99_px = p99(c->err_px, c->nerr, &run->err_max_px);
        if (c->nfate)
            qsort(c->fate_keys, c->nfate, sizeof *c->fate_keys, by_u64);
        uint64_t fates = 0;
        for (size_t i = 0; i < c->nfate; i++)
            fates += i == 0 || c->fate_keys[i] != c->fate_keys[i - 1];
        run->fates = fates;
        /* Huge: further off than ten image widths span at the emitters'
         * depth (in metres: a point near the camera's plane makes any
         * screen distance huge). */
        double huge_m = 10.0 * (c->width > c->height ? c->width : c->height) * c->res->m_per_px;
        if (!isfinite(run->err_max_m) || run->err_max_m > huge_m) {
            run->blew_up = true;
            snprintf(run->why, sizeof run->why, "error beyond 10 image widths (%.3g m); %s", huge_m,
                     warned ? why : "no stability rule predicted it");
        }
    }
    if (own)
        pfx_loaded_free(&l);
    return true;
}

static pfx_tune_run *add_run(pfx_tune_result *res, pfx_integrator in, double rate, int sub) {
    if (!grow((void **)&res->runs, &res->cap, res->count + 1, sizeof *res->runs))
        return NULL;
    pfx_tune_run *r = &res->runs[res->count++];
    *r = (pfx_tune_run){.integrator = in, .rate = rate, .substeps = sub};
    return r;
}

/* The row already run for this setting, or -1. */
static long find_run(const pfx_tune_result *res, pfx_integrator in, double rate, int sub) {
    for (size_t i = 0; i < res->count; i++) {
        const pfx_tune_run *r = &res->runs[i];
        if (r->integrator == in && fabs(r->rate - rate) <= 1e-9 * rate && r->substeps == sub)
            return (long)i;
    }
    return -1;
}

static bool within(const pfx_tune_result *res, const pfx_tune_run *r, bool px) {
    return r->compiled && !r->blew_up && !r->reference &&
           (px ? r->err_max_px <= res->tol_px : r->err_max_m <= res->tol_m);
}

/* The frames compared: all of [first, last] when they are few, else
 * PFX_TUNE_MAX_FRAMES spread evenly with both ends. */
static void choose_frames(tune_ctx *c) {
    long span = c->req->last - c->req->first;
    c->nframes = span + 1 <= PFX_TUNE_MAX_FRAMES ? (int)span + 1 : PFX_TUNE_MAX_FRAMES;
    for (int i = 0; i < c->nframes; i++)
        c->frames[i] = c->nframes == 1
                           ? c->req->first
                           : c->req->first + (long)llround((double)span * i / (c->nframes - 1));
}

/* The typical depth of the effect: the emitters' median scale on screen,
 * as metres per pixel. */
static double metres_per_pixel(const pfx_effect *e) {
    double v[64];
    size_t n = 0;
    for (size_t i = 0; i < e->emitter_count && n < 64; i++) {
        emitter_pose p;
        pfx_emitter_pose_at(&e->emitters[i], 0, &p);
        double ppm = pfx_camera_pixels_per_metre(&e->camera, e->height, p.position);
        if (ppm > 0)
            v[n++] = 1 / ppm;
    }
    if (!n)
        return pfx_camera_pixels_per_metre(&e->camera, e->height, e->camera.target) > 0
                   ? 1 / pfx_camera_pixels_per_metre(&e->camera, e->height, e->camera.target)
                   : 1;
    qsort(v, n, sizeof *v, by_double);
    return v[n / 2];
}

/* The order integrators are tried: the cheap specialised ones first, so
 * that a good setting is known early and dearer runs can be skipped. */
static const pfx_integrator ladder_order[] = {
    PFX_INTEGRATOR_AUTO,       PFX_INTEGRATOR_EXACT,    PFX_INTEGRATOR_BORIS, PFX_INTEGRATOR_VERLET,
    PFX_INTEGRATOR_SYMPLECTIC, PFX_INTEGRATOR_MIDPOINT, PFX_INTEGRATOR_EULER, PFX_INTEGRATOR_RK4};

/* True when a run of `in` at `work` steps (rate x substeps) a second
 * cannot beat the cheapest run within tolerance: its cost predicted from
 * the integrator's dearest stable run so far, scaled by the steps and
 * halved (fixed costs per frame do not scale), is still above it. */
static bool cannot_win(const pfx_tune_result *res, pfx_integrator in, double work) {
    if (res->recommended < 0)
        return false;
    const double best = res->runs[res->recommended].seconds_per_s;
    for (size_t i = 0; i < res->count; i++) {
        const pfx_tune_run *r = &res->runs[i];
        if (r->integrator != in || !r->compiled || r->blew_up || r->reference || r->current)
            continue;
        double w = r->rate * (r->substeps > 0 ? r->substeps : 1);
        if (w < work && 0.5 * r->seconds_per_s * work / w > best)
            return true;
    }
    return false;
}

/* One integrator's rungs, coarsest first. Stops refining once a run is
 * converged (within a tenth of the tolerance, or twice the reference's own
 * uncertainty: finer ones can only cost more, or measure nothing), or
 * once a run costs three times the cheapest run within tolerance so far
 * (finer ones cost more still and cannot win), and skips a run whose
 * predicted cost already loses (cannot_win). At the file's rate it also
 * tries 2 and 4 substeps when one step was not within tolerance. */
static bool run_integrator(tune_ctx *c, pfx_integrator in, double base_rate, bool px) {
    pfx_tune_result *res = c->res;
    const int subs_default = in == PFX_INTEGRATOR_AUTO ? 0 : 1;
    for (int j = PFX_TUNE_RATE_LO; j <= PFX_TUNE_RATE_HI; j++) {
        double rate = base_rate * ldexp(1.0, j);
        if (rate < 1 || rate > TUNE_MAX_RATE)
            continue;
        for (int sub = subs_default;
             sub <= (j == 0 && in != PFX_INTEGRATOR_AUTO ? 4 : subs_default);
             sub = sub ? sub * 2 : 1) {
            long at = find_run(res, in, rate, sub);
            if (at < 0 && cannot_win(res, in, rate * (sub ? sub : 1)))
                return true;
            if (at < 0) {
                pfx_tune_run *r = add_run(res, in, rate, sub);
                if (!r || !measure(c, r, false))
                    return false;
                at = (long)res->count - 1;
                if (c->log)
                    fprintf(c->log, "pfx: tune: %s at %g steps/s x %d: %s\n",
                            pfx_integrator_name(in), rate, sub,
                            !r->compiled ? "does not compile"
                            : r->blew_up ? "blew up"
                                         : "done");
            }
            const pfx_tune_run *r = &res->runs[at];
            if (!r->compiled)
                return true; /* no rate makes it apply */
            if (within(res, r, px))
                break; /* more substeps at this rate cannot win */
            if (sub == 0)
                break;
        }
        /* Keep the cheapest within tolerance up to date as runs come in. */
        for (size_t i = 0; i < res->count; i++)
            if (within(res, &res->runs[i], px) &&
                (res->recommended < 0 ||
                 res->runs[i].seconds_per_s < res->runs[res->recommended].seconds_per_s))
                res->recommended = (long)i;
        long at = find_run(res, in, rate, subs_default);
        const pfx_tune_run *r = at >= 0 ? &res->runs[at] : NULL;
        /* Converged: within a tenth of the tolerance, or within twice
         * what the reference itself is good to (its two finest runs'
         * difference), below which a finer run measures nothing. */
        const pfx_tune_run *chk = &res->runs[res->check];
        if (r && r->compiled && !r->blew_up &&
            (px ? r->err_max_px <= fmax(0.1 * res->tol_px, 2 * chk->err_max_px)
                : r->err_max_m <= fmax(0.1 * res->tol_m, 2 * chk->err_max_m)))
            break;
        if (r && res->recommended >= 0 && !r->blew_up &&
            r->seconds_per_s > 3 * res->runs[res->recommended].seconds_per_s)
            break;
    }
    return true;
}

/* Per integrator: the lowest rate it ran stably at, when a lower one blew
 * up: the rate below which it fails on this effect. */
static void find_failures(pfx_tune_result *res) {
    for (int in = 0; in < PFX_INTEGRATOR_COUNT; in++) {
        double lowest_bad = 0, lowest_good = INFINITY;
        const char *why = "";
        for (size_t i = 0; i < res->count; i++) {
            const pfx_tune_run *r = &res->runs[i];
            if ((int)r->integrator != in || !r->compiled || r->reference)
                continue;
            if (r->blew_up && r->rate > lowest_bad) {
                lowest_bad = r->rate;
                why = r->why;
            } else if (!r->blew_up && r->rate < lowest_good)
                lowest_good = r->rate;
        }
        if (lowest_bad > 0 && isfinite(lowest_good))
            snprintf(res->fails_below[in], sizeof res->fails_below[in],
                     "fails below %g steps/s (blew up at %g: %.120s)", lowest_good, lowest_bad,
                     why);
        else if (lowest_bad > 0)
            snprintf(res->fails_below[in], sizeof res->fails_below[in],
                     "fails at every rate tried, up to %g steps/s", lowest_bad);
    }
}

static void free_ctx(tune_ctx *c) {
    for (int f = 0; f < c->nframes; f++)
        free(c->ref[f].pts);
    free(c->scratch);
    free(c->err_m);
    free(c->err_px);
    free(c->fate_keys);
}

bool pfx_tune_run_ladder(const pfx_tune_request *r, pfx_tune_result *res, FILE *log, pfx_diags *d) {
    memset(res, 0, sizeof *res);
    res->recommended = -1;
    tune_ctx c = {.req = r, .res = res, .log = log};
    choose_frames(&c);
    const pfx_effect *e = r->loaded->effect;
    bool ok = false;
    c.cam = &e->camera;
    c.width = e->width;
    c.height = e->height;
    res->m_per_px = metres_per_pixel(e);
    res->tol_px = r->tolerance_px ? r->tolerance : r->tolerance / res->m_per_px;
    res->tol_m = r->tolerance_px ? r->tolerance * res->m_per_px : r->tolerance;
    res->sim_seconds = pfx_sim_frame_time(e, c.frames[c.nframes - 1]);
    if (!(res->sim_seconds > 0))
        res->sim_seconds = 1 / e->fps;
    res->frames_compared = c.nframes;
    const double base = e->sim_rate;
    /* The reference: rk4 at the finest rate; the check beside it at half
     * that rate. */
    pfx_tune_run *ref = add_run(res, PFX_INTEGRATOR_RK4,
                                fmin(base * ldexp(1.0, PFX_TUNE_RATE_HI), TUNE_MAX_RATE), 1);
    if (!ref)
        goto oom;
    ref->reference = true;
    const double ref_rate = ref->rate;
    if (!measure(&c, ref, true))
        goto oom;
    if (!ref->compiled || ref->blew_up) {
        pfx_diag_error(d, PFX_RULE_SIMULATION_DIVERGED,
                       "cannot tune '%s': its reference run (rk4 at %g steps/s) %s", r->path,
                       ref->rate, ref->compiled ? "blew up" : "does not compile");
        goto done;
    }
    size_t points = 0;
    for (int f = 0; f < c.nframes; f++)
        points += c.ref[f].n;
    if (points > TUNE_MAX_POINTS) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE,
                       "cannot tune '%s': %zu particle-frames to compare, more than %u; give a "
                       "shorter --frames range",
                       r->path, points, TUNE_MAX_POINTS);
        goto done;
    }
    pfx_tune_run *cur = add_run(res, e->integrator, e->sim_rate, e->substeps);
    if (!cur)
        goto oom;
    cur->current = true;
    res->current = res->count - 1;
    if (!measure(&c, cur, false))
        goto oom;
    pfx_tune_run *chk = add_run(res, PFX_INTEGRATOR_RK4, 0.5 * ref_rate, 1);
    if (!chk || !measure(&c, chk, false))
        goto oom;
    res->reference = 0;
    res->check = res->count - 1;
    res->converged = chk->compiled && !chk->blew_up &&
                     (r->tolerance_px ? chk->err_max_px <= 0.1 * res->tol_px
                                      : chk->err_max_m <= 0.1 * res->tol_m);
    if (within(res, &res->runs[res->current], r->tolerance_px))
        res->recommended = (long)res->current;
    for (size_t k = 0; k < sizeof ladder_order / sizeof ladder_order[0]; k++)
        if (!run_integrator(&c, ladder_order[k], base, r->tolerance_px))
            goto oom;
    for (size_t i = 0; i < res->count; i++)
        if (within(res, &res->runs[i], r->tolerance_px) &&
            (res->recommended < 0 ||
             res->runs[i].seconds_per_s < res->runs[res->recommended].seconds_per_s))
            res->recommended = (long)i;
    find_failures(res);
    ok = true;
    goto done;
oom:
    pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
done:
    free_ctx(&c);
    return ok;
}

void pfx_tune_result_free(pfx_tune_result *res) {
    free(res->runs);
    memset(res, 0, sizeof *res);
}

bool pfx_tune_parse_tolerance(const char *text, double *value, bool *px) {
    char *end;
    double v = strtod(text, &end);
    if (end == text || !(v > 0) || !isfinite(v))
        return false;
    static const struct {
        const char *unit;
        double scale;
        bool px;
    } units[] = {{"px", 1, true}, {"m", 1, false}, {"cm", 1e-2, false}, {"mm", 1e-3, false}};
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
        if (!strcmp(end, units[i].unit)) {
            *value = v * units[i].scale;
            *px = units[i].px;
            return true;
        }
    return false;
}
