/* The speed benchmark. It reports figures, it does not judge them: each
 * figure stands next to a reference measured in the same run on the same
 * machine (a roofline kernel, the memory bandwidth, raw drawing), so the
 * ratio means something where absolute speeds do not. The same figures are
 * printed as text or as one JSON object (jansson). */
#include "bench/speed.h"

#include "bench/looks.h"
#include "bench/sort_speed.h"

#include <errno.h>
#include <jansson.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "base/workers.h"
#include "jobs/load.h"
#include "jobs/render_job.h"
#include "output/png_write.h"
#include "render/render.h"
#include "render/sprites.h"
#include "sim/sim.h"

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A fountain whose steady live count is about n (rate n / 2 with a
 * constant 2 s lifetime), or with `burst`, n particles born at time 0 that
 * all live BURST_LIFE seconds (so a timed step has no births or deaths; a
 * fall that long stays far inside the state check's limits, so the
 * kernel runs without it), feeling gravity
 * plus `forces` (YAML lines of forces and deflectors), compiled like any
 * effect and stepped on `threads` threads. `launch`: the emitter's shape,
 * spread and speed lines, NULL for the fountain's. */
#define BURST_LIFE 100.0
#define FOUNTAIN_LAUNCH                                                                            \
    "    shape: { type: sphere, radius: 0.1 }\n    spread: 30\n    speed: [2, 4]\n"

static pfx_effect *fountain(pfx_loaded *l, double n, const char *forces, const char *emitter,
                            const char *launch, bool burst, int threads) {
    char text[2048], rate[1024];
    if (burst) { /* bursts of at most 10^6 each (the format's limit) */
        size_t len = (size_t)snprintf(rate, sizeof rate, "bursts: [");
        for (double left = n; left > 0 && len < sizeof rate - 64; left -= 1e6)
            len += (size_t)snprintf(rate + len, sizeof rate - len, "%s{ time: 0, count: %.17g }",
                                    left < n ? ", " : "", left < 1e6 ? left : 1e6);
        snprintf(rate + len, sizeof rate - len, "]");
    } else
        snprintf(rate, sizeof rate, "rate: %.17g", n / 2);
    snprintf(text, sizeof text,
             "pfx: 1\nseed: 1\nforces:\n  gravity: { type: gravity }\n%s"
             "emitters:\n  bench:\n%s    %s\n    lifetime: %g\n%s",
             forces, launch ? launch : FOUNTAIN_LAUNCH, rate, burst ? BURST_LIFE : 2.0, emitter);
    memset(l, 0, sizeof *l);
    size_t len = strlen(text);
    l->source = strdup(text);
    pfx_diags_init(&l->diags, "bench.yaml", l->source, len);
    pfx_compile_options opt = {.max_particles = (uint64_t)(4 * n + 100), .threads = threads};
    if (l->source && pfx_parse(l->source, len, &l->doc, &l->diags))
        l->effect = pfx_compile(l->doc.root, "bench.yaml", &opt, &l->arena, &l->diags);
    if (!l->effect)
        pfx_diags_print(&l->diags, stderr, false);
    return l->effect;
}

/* A simulation timed in windows of about 0.15 s of wall time (at least 5
 * steps each), so a slow force set cannot make the benchmark run for
 * minutes. Its figure is the best window: a window another process on the
 * machine slowed down does not decide it (interference only ever adds
 * time; the reference rows are measured the same way). */
typedef struct timed_sim {
    pfx_sim *s;
    int left; /* steps it may still take */
} timed_sim;

/* Created and stepped `warm` steps, into steady state; false when out of
 * memory. A burst fountain (fountain()) is never stepped past its
 * lifetime: the count would fall to 0. */
static bool timed_start(timed_sim *t, const pfx_effect *e, int warm, bool burst) {
    t->s = pfx_sim_create(e, NULL);
    t->left = burst ? (int)(BURST_LIFE * e->sim_rate) - warm - 2 : INT_MAX;
    for (int i = 0; t->s && i < warm; i++)
        pfx_sim_step(t->s);
    return t->s != NULL;
}

/* One window: particle-steps per second (0 when no step is left). */
static double timed_window(timed_sim *t) {
    int steps = 0;
    double work = 0, t0 = now(), elapsed = 0;
    while ((steps < 5 || elapsed < 0.15) && steps < t->left) {
        work += t->s->pools[0].count;
        pfx_sim_step(t->s);
        steps++;
        elapsed = now() - t0;
    }
    t->left -= steps;
    return elapsed > 0 ? work / elapsed : 0;
}

/* ---- Memory bandwidth: the STREAM triad a = b + s c (McCalpin) ---- */

typedef struct triad_job {
    double *a, *b, *c;
    size_t n, blocks;
} triad_job;

static void triad_init(void *arg, size_t k) {
    triad_job *t = arg;
    size_t lo = t->n * k / t->blocks, hi = t->n * (k + 1) / t->blocks;
    for (size_t i = lo; i < hi; i++)
        t->a[i] = 0, t->b[i] = 1, t->c[i] = 2;
}

static void triad_block(void *arg, size_t k) {
    triad_job *t = arg;
    size_t lo = t->n * k / t->blocks, hi = t->n * (k + 1) / t->blocks;
    double *restrict a = t->a;
    const double *restrict b = t->b, *restrict c = t->c;
    for (size_t i = lo; i < hi; i++)
        a[i] = b[i] + 3.0 * c[i];
}

/* GB/s of the triad on every core over three arrays of 64 MiB (far larger
 * than the caches), counting 24 bytes an element as STREAM does; each
 * thread first touches the slice it runs. Best of five after a warm-up. */
static double triad_bandwidth(int cores) {
    const size_t n = (size_t)1 << 23;
    triad_job t = {malloc(n * sizeof(double)), malloc(n * sizeof(double)),
                   malloc(n * sizeof(double)), n, (size_t)cores};
    pfx_workers *w = pfx_workers_create(cores);
    double best = 0;
    if (t.a && t.b && t.c && w) {
        pfx_workers_run(w, t.blocks, triad_init, &t);
        for (int run = -1; run < 5; run++) {
            double t0 = now();
            pfx_workers_run(w, t.blocks, triad_block, &t);
            double gbs = 24.0 * (double)n / (now() - t0) / 1e9;
            if (run >= 0 && gbs > best)
                best = gbs;
        }
    }
    pfx_workers_destroy(w);
    free(t.a), free(t.b), free(t.c);
    return best;
}

/* Bytes the gravity-only step must move per particle with no births or
 * deaths: position and velocity read and written (6 floats, 48 bytes) and
 * the death scan's birth time (8) and lifetime (4). */
#define SIM_BYTES_PER_STEP 60.0

/* The roofline: exactly the per-particle arithmetic of the gravity kernel
 * (integrate_gravity in src/sim/sim.c: three position and three velocity
 * multiply-adds in float; the state check is proven unneeded for the
 * fountain at birth, as for most effects) on dense arrays, with nothing
 * else (no deaths, no births). The acceleration comes through a volatile so the
 * compiler cannot drop the zero components pfx itself computes. Best of
 * three runs of about 0.15 s each, after a warm-up pass. */
static double roofline(size_t n) {
    float *col = malloc(6 * n * sizeof *col);
    if (!col)
        return 0;
    float *px = col, *py = px + n, *pz = py + n, *vx = pz + n, *vy = vx + n, *vz = vy + n;
    for (size_t i = 0; i < 6 * n; i++)
        col[i] = (float)(i % 97) * 0.01f;
    volatile float g[3] = {0, -9.81f, 0};
    const float dt = 1.0f / 120, h = 0.5f * dt * dt;
    const float hx = g[0] * h, hy = g[1] * h, hz = g[2] * h;
    const float kx = g[0] * dt, ky = g[1] * dt, kz = g[2] * dt;
    double best = 0;
    for (int run = -1; run < 3; run++) {
        double t0 = now(), elapsed = 0;
        long steps = 0;
        while (steps < 3 || elapsed < 0.15) {
            for (size_t i = 0; i < n; i++) {
                px[i] += vx[i] * dt + hx;
                py[i] += vy[i] * dt + hy;
                pz[i] += vz[i] * dt + hz;
                vx[i] += kx;
                vy[i] += ky;
                vz[i] += kz;
            }
            /* Keep the compiler from collapsing the steps. */
            __asm__ volatile("" : : "r"(col) : "memory");
            steps++;
            elapsed = now() - t0;
        }
        double rate = (double)n * (double)steps / elapsed;
        if (run >= 0 && rate > best) /* run -1 warms the caches and the clock */
            best = rate;
    }
    free(col);
    return best;
}

/* The report as it is measured: printed as text at once, and gathered as
 * JSON (NULL members when out of memory, which jansson's setters ignore). */
typedef struct report {
    FILE *out;
    bool json;
    json_t *root, *sim, *forces, *render, *emission;
} report;

/* One size's rows: a burst fountain on each thread count, all created
 * first and then timed a window each in turn, three rounds, each row's
 * figure its best window. Taking turns puts the rows' windows moments
 * apart, under the same load, so a burst of other work on a shared machine
 * moves one window of every row rather than one row's figure, and the
 * thread scaling is a ratio of like with like (as the force rows are
 * measured beside gravity's). */
#define SIM_ROWS 3

static bool sim_rows(double n, const int *threads, int rows, double rate[SIM_ROWS]) {
    pfx_loaded l[SIM_ROWS];
    timed_sim t[SIM_ROWS] = {{NULL, 0}};
    bool ok = true;
    for (int c = 0; c < rows && ok; c++) {
        rate[c] = 0;
        ok = fountain(&l[c], n, "", "", NULL, true, threads[c]);
        if (!ok)
            rows = c + 1; /* l[c] is still freed below */
        else if (!timed_start(&t[c], l[c].effect, 1, true))
            fprintf(stderr, "pfx bench: out of memory for %.0f particles on %d threads\n", n,
                    threads[c]); /* its row reads 0 */
    }
    for (int window = 0; ok && window < 3; window++)
        for (int c = 0; c < rows; c++) {
            const double w = t[c].s ? timed_window(&t[c]) : 0;
            rate[c] = w > rate[c] ? w : rate[c];
        }
    for (int c = 0; c < rows; c++) {
        pfx_sim_destroy(t[c].s);
        pfx_loaded_free(&l[c]);
    }
    return ok;
}

static void bench_sim(report *r, int cores, double bandwidth) {
    FILE *out = r->json ? NULL : r->out;
    if (out) {
        fprintf(out,
                "simulation: gravity-only fountain, exact constant-acceleration kernel, n\n"
                "particles born at t = 0 (no births or deaths while timed), the thread counts'\n"
                "windows taken in turns; limit = bandwidth / %.0f bytes a particle-step\n",
                SIM_BYTES_PER_STEP);
        fprintf(out, "  %10s %7s %14s %14s %8s %14s %8s\n", "particles", "threads", "steps/s",
                "limit/s", "of limit", "roofline/s", "ratio");
    }
    const double sizes[] = {1e4, 1e5, 1e6, 1e7};
    const double limit = bandwidth * 1e9 / SIM_BYTES_PER_STEP;
    /* One thread, two (the scaling the issue asks of two cores) and every
     * core. */
    const int counts[SIM_ROWS] = {1, 2, cores};
    const int rows = cores > 2 ? 3 : cores;
    for (int k = 0; k < 4; k++) {
        double rate[SIM_ROWS];
        if (!sim_rows(sizes[k], counts, rows, rate))
            return;
        for (int c = 0; c < rows; c++) {
            json_array_append_new(r->sim, json_pack("{s:f, s:i, s:f, s:f}", "particles", sizes[k],
                                                    "threads", counts[c], "steps_per_s", rate[c],
                                                    "limit_steps_per_s", limit));
            if (!out)
                continue;
            fprintf(out, "  %10.0f %7d %14.4g %14.4g %7.0f%%", sizes[k], counts[c], rate[c], limit,
                    100 * rate[c] / limit);
            if (c == 0 && k < 3) { /* the roofline of one thread, in cache or not */
                double roof = roofline((size_t)sizes[k]);
                fprintf(out, " %14.4g %7.0f%%\n", roof, 100 * rate[c] / roof);
            } else {
                fprintf(out, " %14s %8s\n", "", "");
            }
        }
    }
}

static void bench_forces(report *r) {
    FILE *out = r->json ? NULL : r->out;
    /* Each force (with gravity) and deflectors at 10^5 particles, one
     * thread: what a scene pays for what it uses, against the gravity-only
     * row measured beside them. The fountain's ground is y = 0: the plane
     * cases bounce and slide on it; "resting" is born on it at rest, held
     * there by gravity (a resting state, no sweep); "no hits" touch nothing. */
    static const struct {
        const char *name, *forces, *emitter, *launch;
    } cases[] = {
        {"gravity only", "", "", NULL},
        {"+ linear drag (exact)", "  air: { type: drag, k: 0.5, wind: [1, 0, 0] }\n", "", NULL},
        {"+ quadratic drag", "  air: { type: drag, k: 0, c: 0.2 }\n", "", NULL},
        {"+ attractor",
         "  well: { type: attractor, center: [0, 2, 0], strength: 2, softening: 0.2 }\n", "", NULL},
        {"+ vortex", "  twist: { type: vortex, axis: [0, 1, 0], strength: 90, radius: 2 }\n", "",
         NULL},
        {"+ magnetic (boris)", "  b: { type: magnetic, field: [0, 0, 1] }\n", "    charge: 0.5\n",
         NULL},
        {"+ spiral", "  sp: { type: spiral, axis: [0, 1, 0], rate: 90 }\n", "", NULL},
        {"+ spring", "  s: { type: spring, k: 4, zeta: 0.2 }\n", "", NULL},
        {"+ turbulence (2 octaves)",
         "  t: { type: turbulence, strength: 1, scale: 1, octaves: 2 }\n", "", NULL},
        {"+ speed limit", "  lim: { type: speed_limit, max: 3 }\n", "", NULL},
        {"+ deflector (plane)",
         "deflectors:\n  ground: { type: plane, resilience: 0.5, friction: 0.1 }\n", "", NULL},
        {"+ deflector (plane), resting",
         "deflectors:\n  ground: { type: plane, resilience: 0.5, friction: 0.1 }\n", "",
         "    shape: { type: rect, size: [2, 2] }\n    speed: 0\n"},
        {"+ deflectors (plane, sphere, box)",
         "deflectors:\n  ground: { type: plane, resilience: 0.5 }\n"
         "  ball: { type: sphere, center: [0.5, 1, 0], radius: 0.3 }\n"
         "  crate: { type: box, center: [-0.6, 0.5, 0], size: [0.4, 0.4, 0.4] }\n",
         "", NULL},
        {"+ deflector (plane), no hits",
         "deflectors:\n  deep: { type: plane, point: [0, -100, 0] }\n", "", NULL},
        {"+ deflectors (3), no hits",
         "deflectors:\n  deep: { type: plane, point: [0, -100, 0] }\n"
         "  ball: { type: sphere, center: [50, 1, 0], radius: 0.3 }\n"
         "  crate: { type: box, center: [-60, 0.5, 0], size: [0.4, 0.4, 0.4] }\n",
         "", NULL},
    };
    const double n = 1e5;
    if (out) {
        fprintf(out, "per force at 10^5 particles, one thread (windows taken in turns with the "
                     "gravity-only fountain's):\n");
        fprintf(out, "  %-34s %14s %10s %9s  %s\n", "force set", "steps/s", "ns/step", "vs gravity",
                "integrator");
    }
    /* The gravity-only fountain runs beside every case, a window of it
     * before each of the case's, so that each ratio compares windows
     * measured moments apart, under the same load; its own row is its
     * first three windows. */
    pfx_loaded g;
    timed_sim ref = {NULL, 0};
    if (!fountain(&g, n, cases[0].forces, cases[0].emitter, NULL, false, 1) ||
        !timed_start(&ref, g.effect, 250, false)) { /* past one lifetime: steady */
        pfx_sim_destroy(ref.s);
        pfx_loaded_free(&g);
        return;
    }
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        pfx_loaded l;
        timed_sim t = {NULL, 0};
        const bool alone = k == 0;
        if (!alone &&
            (!fountain(&l, n, cases[k].forces, cases[k].emitter, cases[k].launch, false, 1) ||
             !timed_start(&t, l.effect, 250, false))) {
            pfx_sim_destroy(t.s);
            pfx_loaded_free(&l);
            continue;
        }
        double rate = 0, gravity = 0;
        for (int window = 0; window < 3; window++) {
            double w = timed_window(&ref);
            gravity = w > gravity ? w : gravity;
            w = alone ? gravity : timed_window(&t);
            rate = w > rate ? w : rate;
        }
        const pfx_emitter *em = &(alone ? g.effect : l.effect)->emitters[0];
        json_array_append_new(r->forces,
                              json_pack("{s:s, s:i, s:f, s:f}", "name", cases[k].name, "threads", 1,
                                        "steps_per_s", rate, "gravity_steps_per_s", gravity));
        if (out)
            fprintf(out, "  %-34s %14.4g %10.1f %8.0f%%  %s\n", cases[k].name, rate, 1e9 / rate,
                    100 * rate / gravity,
                    em->motion ? pfx_integrator_name(em->motion->choice.chosen)
                               : "exact (gravity)");
        if (!alone) {
            pfx_sim_destroy(t.s);
            pfx_loaded_free(&l);
        }
    }
    pfx_sim_destroy(ref.s);
    pfx_loaded_free(&g);
}

/* Births per second of each emitter shape: a burst of EMISSION_N
 * particles at t = 0, gravity only, the fountain's spread and speeds, the
 * one step that births them (drawing each one's position, direction and
 * attributes, and stepping it from its birth time to the step's end) timed
 * on its own, warm: a first untimed run touches the pool's pages, then the
 * simulation is reset and run again. Three rounds in which the rows take
 * turns, each row's figure its best (as sim_rows). */
#define EMISSION_N 1e6

static double time_births(const pfx_effect *e) {
    pfx_sim *s = pfx_sim_create(e, NULL);
    if (!s)
        return 0;
    while (s->pools[0].count == 0 && s->step < 4)
        pfx_sim_step(s);
    pfx_sim_reset(s);
    const double t0 = now();
    while (s->pools[0].count == 0 && s->step < 4)
        pfx_sim_step(s);
    const double elapsed = now() - t0, born = s->pools[0].count;
    pfx_sim_destroy(s);
    return elapsed > 0 ? born / elapsed : 0;
}

static void bench_emission(report *r, int cores) {
    FILE *out = r->json ? NULL : r->out;
    static const struct {
        const char *name, *launch;
    } shapes[] = {
        {"point", "    shape: { type: point }\n    spread: 30\n    speed: [2, 4]\n"},
        {"sphere", "    shape: { type: sphere, radius: 0.1 }\n    spread: 30\n    speed: [2, 4]\n"},
        {"cone", "    shape: { type: cone, radius: 0.1, height: 0.2 }\n    spread: 30\n"
                 "    speed: [2, 4]\n"},
    };
    enum { SHAPES = sizeof shapes / sizeof *shapes };
    const int counts[2] = {1, cores < 2 ? 1 : 2}, rows = cores < 2 ? 1 : 2;
    pfx_loaded l[SHAPES][2];
    double rate[SHAPES][2] = {{0}};
    bool ok[SHAPES][2];
    for (int k = 0; k < SHAPES; k++)
        for (int c = 0; c < rows; c++)
            ok[k][c] = fountain(&l[k][c], EMISSION_N, "", "", shapes[k].launch, true, counts[c]);
    for (int round = 0; round < 3; round++)
        for (int k = 0; k < SHAPES; k++)
            for (int c = 0; c < rows; c++) {
                const double w = ok[k][c] ? time_births(l[k][c].effect) : 0;
                rate[k][c] = w > rate[k][c] ? w : rate[k][c];
            }
    if (out) {
        fprintf(out,
                "emission: a burst of %.0f at t = 0 (spread 30, speed [2, 4], gravity), the "
                "step that births it, best of 3 rounds\n",
                EMISSION_N);
        fprintf(out, "  %-8s %7s %14s %14s\n", "shape", "threads", "births/s", "ns/birth");
    }
    for (int k = 0; k < SHAPES; k++)
        for (int c = 0; c < rows; c++) {
            json_array_append_new(r->emission,
                                  json_pack("{s:s, s:i, s:f}", "shape", shapes[k].name, "threads",
                                            counts[c], "births_per_s", rate[k][c]));
            if (out)
                fprintf(out, "  %-8s %7d %14.4g %14.1f\n", shapes[k].name, counts[c], rate[k][c],
                        rate[k][c] > 0 ? 1e9 / rate[k][c] : 0.0);
            pfx_loaded_free(&l[k][c]);
        }
}

/* One timed pfx render of the job's frames into a fresh temporary
 * directory (removed after): frames per second, or -1 (reported into d). */
static double time_render(pfx_render_job *job, pfx_diags *d) {
    char dir[] = "/tmp/pfx-bench-XXXXXX";
    if (!mkdtemp(dir)) {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create '%s': %s", dir, strerror(errno));
        return -1;
    }
    job->dir = dir;
    double t0 = now();
    bool ok = pfx_render_job_run(job, d);
    double fps = (double)job->frames_done / (now() - t0);
    char path[600];
    for (long f = job->first; f <= job->last; f++) {
        snprintf(path, sizeof path, "%s/f_%04ld.png", dir, f);
        unlink(path);
    }
    rmdir(dir);
    job->dir = NULL;
    return ok ? fps : -1;
}

static double median3(double a, double b, double c) {
    return a > b ? (b > c ? b : a > c ? c : a) : (a > c ? a : b > c ? c : b);
}

/* pfx render's frames per second against raw drawing of the same sprites,
 * both warm: an untimed render of the first frames compiles every shader
 * variant first (a one-time cost of some 0.1 s that raw drawing, run after
 * it, would not pay), then three rounds of a whole render and of raw
 * drawing alternate and each figure is the median of its three, so that a
 * burst of other work on the machine moves one round, not the ratio. */
static bool bench_render(report *rep, const char *scene, const char *fire_path, const char *shown,
                         pfx_renderer *r, int width, int height, pfx_diags *d) {
    FILE *out = rep->json ? NULL : rep->out;
    pfx_loaded l;
    pfx_compile_options opt = {.width = width, .height = height};
    pfx_effect *e = pfx_load(&l, fire_path, &opt);
    if (!e) {
        pfx_diags_append(d, &l.diags);
        pfx_loaded_free(&l);
        return false;
    }
    const long last = pfx_effect_frame_count(e) - 1;
    pfx_render_job job = {
        .effect = e, .renderer = r, .stem = "f", .first = 0, .last = last < 4 ? last : 4};
    bool ok = time_render(&job, d) > 0;
    pfx_render_job_free(&job);
    double full[3] = {0}, raw[3] = {0};
    long frames = 0;
    size_t mean = 0;
    for (int k = 0; k < 3 && ok; k++) {
        job = (pfx_render_job){.effect = e, .renderer = r, .stem = "f", .first = 0, .last = last};
        full[k] = time_render(&job, d);
        ok = full[k] > 0;
        /* The raw reference draws the last frame's sprites (the steady
         * state), as many of them as the render drew on average. */
        frames = job.frames_done;
        mean = frames ? job.sprites_drawn / (size_t)frames : 0;
        pfx_sprite *sprites = ok ? calloc(pfx_sprites_capacity(e) + 1, sizeof *sprites) : NULL;
        if (sprites) {
            pfx_sprites_build(pfx_sim_frame(job.sim, job.view, job.last), sprites);
            raw[k] = pfx_renderer_bench_raw(r, &e->camera, sprites, mean, (int)frames);
        }
        ok = ok && sprites && raw[k] > 0;
        free(sprites);
        pfx_render_job_free(&job);
    }
    if (ok) {
        const double full_fps = median3(full[0], full[1], full[2]);
        const double raw_fps = median3(raw[0], raw[1], raw[2]);
        json_array_append_new(rep->render,
                              json_pack("{s:s, s:i, s:i, s:I, s:f, s:f}", "scene", scene, "width",
                                        width, "height", height, "sprites", (json_int_t)mean,
                                        "pfx_fps", full_fps, "raw_fps", raw_fps));
        if (out) {
            fprintf(out,
                    "rendering: %s (%s) at %dx%d through %s, %ld frames, %zu sprites a frame on "
                    "average; warm, median of 3 rounds\n",
                    scene, shown, width, height, pfx_renderer_name(r), frames, mean);
            fprintf(out, "  %-44s %8.1f frames/s\n",
                    "pfx render (sim, sprites, draw, PNG overlapped)", full_fps);
            char name[64];
            snprintf(name, sizeof name, "raw %s (upload, one draw, readback)",
                     pfx_renderer_name(r));
            fprintf(out, "  %-44s %8.1f frames/s\n", name, raw_fps);
            fprintf(out, "  %-44s %7.0f%%\n", "ratio", 100 * full_fps / raw_fps);
        }
    }
    pfx_loaded_free(&l);
    return ok;
}

/* The heavy render scene: some 15000 small additive sprites in steady state
 * from the first frame (a 2.5 s life at 6000 a second, prewarmed), 30
 * frames; written to a temporary file for the loader. */
static const char heavy_scene[] =
    "pfx: 1\nduration: 1\nfps: 30\nseed: 3\nsim: { rate: 60, prewarm: 3 }\n"
    "camera: { position: [0, 1, 4], target: [0, 1, 0], fov: 40 }\n"
    "image: { background: transparent }\n"
    "forces:\n  g: { type: gravity, accel: [0, -0.5, 0] }\n"
    "emitters:\n  dust:\n    shape: { type: sphere, radius: 1 }\n    position: [0, 1, 0]\n"
    "    rate: 6000\n    speed: [0.05, 0.2]\n    spread: 180\n    lifetime: 2.5\n"
    "    size: 0.04\n    color: [\"#ffd08080\", \"#ff602000\"]\n    blend: add\n";

/* bench_render of the heavy scene, from a file in a fresh temporary
 * directory (removed after); false with the failure in d. */
static bool bench_render_heavy(report *rep, pfx_renderer *r, int width, int height, pfx_diags *d) {
    char dir[] = "/tmp/pfx-bench-XXXXXX", path[64];
    if (!mkdtemp(dir)) {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create '%s': %s", dir, strerror(errno));
        return false;
    }
    snprintf(path, sizeof path, "%s/heavy.yaml", dir);
    FILE *f = fopen(path, "w");
    bool written = f && fputs(heavy_scene, f) >= 0;
    if (f)
        written = fclose(f) == 0 && written;
    if (!written)
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write '%s'", path);
    const bool ok =
        written && bench_render(rep, "1e4 sprites", path, "built in", r, width, height, d);
    unlink(path);
    rmdir(dir);
    return ok;
}

const char *const pfx_bench_section_names[] = {
#define PFX_BENCH_NAME(id, bit, name) name,
    PFX_BENCH_SECTIONS(PFX_BENCH_NAME)
#undef PFX_BENCH_NAME
        NULL};

unsigned pfx_bench_section(const char *name) {
#define PFX_BENCH_MATCH(id, bit, text)                                                             \
    if (!strcmp(name, text))                                                                       \
        return bit;
    PFX_BENCH_SECTIONS(PFX_BENCH_MATCH)
#undef PFX_BENCH_MATCH
    return 0;
}

bool pfx_bench_speed(FILE *out, const char *fire_path, pfx_renderer_kind renderer, bool json,
                     unsigned sections, pfx_diags *d) {
    static const int sizes[2][2] = {{512, 512}, {1920, 1080}};
    pfx_renderer *r[2] = {NULL, NULL};
    for (int k = 0; k < 2; k++)
        if (!(r[k] = pfx_renderer_create(renderer, sizes[k][0], sizes[k][1], d))) {
            pfx_renderer_destroy(r[0]);
            return false;
        }
    report rep = {out, json, json_object(), json_array(), json_array(), json_array(), json_array()};
    const int cores = pfx_workers_cores();
    const double bandwidth = triad_bandwidth(cores);
    json_object_set_new(rep.root, "machine",
                        json_pack("{s:i, s:f}", "cores", cores, "bandwidth_gb_s", bandwidth));
    if (!json)
        fprintf(out, "machine: %d cores, memory bandwidth %.1f GB/s (STREAM triad, all cores)\n",
                cores, bandwidth);
    if (sections & PFX_BENCH_SIM)
        bench_sim(&rep, cores, bandwidth);
    if (sections & PFX_BENCH_FORCES)
        bench_forces(&rep);
    if (sections & PFX_BENCH_EMISSION)
        bench_emission(&rep, cores);
    json_t *sort = json_array();
    bool ok = true;
    if (sections & PFX_BENCH_SORT)
        ok = pfx_bench_sort(json ? NULL : out, r[0], cores, sort, d);
    /* The fire, then the heavy scene, each at both sizes beside raw
     * drawing in the same run. */
    for (int k = 0; k < 2 && ok && (sections & PFX_BENCH_RENDER); k++)
        ok = bench_render(&rep, "fire", fire_path, fire_path, r[k], sizes[k][0], sizes[k][1], d);
    for (int k = 0; k < 2 && ok && (sections & PFX_BENCH_RENDER); k++)
        ok = bench_render_heavy(&rep, r[k], sizes[k][0], sizes[k][1], d);
    /* The sprite looks' table is text only (not part of --json). */
    if (ok && !json && (sections & PFX_BENCH_LOOKS))
        ok = pfx_bench_looks(out, r[0], sizes[0][0], sizes[0][1], d);
    json_object_set(rep.root, "sim", rep.sim);
    json_object_set(rep.root, "forces", rep.forces);
    json_object_set(rep.root, "render", rep.render);
    json_object_set(rep.root, "emission", rep.emission);
    json_object_set_new(rep.root, "sort", sort);
    if (json && ok) {
        char *text =
            json_dumps(rep.root, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(6));
        if (text)
            fprintf(out, "%s\n", text);
        else
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        ok = text != NULL;
        free(text);
    }
    json_decref(rep.sim), json_decref(rep.forces), json_decref(rep.render);
    json_decref(rep.emission), json_decref(rep.root);
    pfx_renderer_destroy(r[1]);
    pfx_renderer_destroy(r[0]);
    return ok;
}
