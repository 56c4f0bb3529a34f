/* The speed benchmark. It reports figures, it does not judge them: each
 * figure stands next to a reference measured in the same run on the same
 * machine, so the ratio means something where absolute speeds do not. */
#include "bench/speed.h"

#include "bench/looks.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

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
 * constant 2 s lifetime), feeling gravity plus `extra` (YAML lines of forces
 * and deflectors), compiled like any effect. */
static pfx_effect *fountain(pfx_loaded *l, double n, const char *forces, const char *emitter) {
    char text[2048];
    snprintf(text, sizeof text,
             "pfx: 1\nseed: 1\nforces:\n  gravity: { type: gravity }\n%s"
             "emitters:\n  bench:\n    shape: { type: sphere, radius: 0.1 }\n"
             "    rate: %.17g\n    spread: 30\n    speed: [2, 4]\n    lifetime: 2\n%s",
             forces, n / 2, emitter);
    memset(l, 0, sizeof *l);
    size_t len = strlen(text);
    l->source = strdup(text);
    pfx_diags_init(&l->diags, "bench.yaml", l->source, len);
    pfx_compile_options opt = {.max_particles = (uint64_t)(4 * n + 100)};
    if (l->source && pfx_parse(l->source, len, &l->doc, &l->diags))
        l->effect = pfx_compile(l->doc.root, "bench.yaml", &opt, &l->arena, &l->diags);
    if (!l->effect)
        pfx_diags_print(&l->diags, stderr, false);
    return l->effect;
}

/* Particle-steps per second of one emitter in steady state, stepping for
 * about 0.4 s of wall time (at least 5 steps), so a slow force set cannot
 * make the benchmark run for minutes. */
static double steps_per_second(const pfx_effect *e) {
    pfx_sim *s = pfx_sim_create(e, NULL);
    if (!s)
        return 0;
    for (int i = 0; i < 250; i++) /* past one lifetime: steady state */
        pfx_sim_step(s);
    int steps = 0;
    double work = 0, t0 = now(), elapsed = 0;
    while (steps < 5 || elapsed < 0.4) {
        work += s->pools[0].count;
        pfx_sim_step(s);
        steps++;
        elapsed = now() - t0;
    }
    pfx_sim_destroy(s);
    return work / elapsed;
}

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

static void bench_sim(FILE *out) {
    fprintf(out, "simulation: gravity-only fountain, exact constant-acceleration kernel\n");
    fprintf(out, "  %10s %16s %16s %8s\n", "particles", "pfx steps/s", "roofline/s", "ratio");
    const double sizes[] = {1e4, 1e5, 1e6};
    double roof_1e5 = 0;
    for (int k = 0; k < 3; k++) {
        pfx_loaded l;
        if (!fountain(&l, sizes[k], "", "")) {
            pfx_loaded_free(&l);
            return;
        }
        double rate = steps_per_second(l.effect);
        double roof = roofline((size_t)sizes[k]);
        if (k == 1)
            roof_1e5 = roof;
        fprintf(out, "  %10.0f %16.4g %16.4g %7.0f%%\n", sizes[k], rate, roof, 100 * rate / roof);
        pfx_loaded_free(&l);
    }
    /* Each force (with gravity) and deflectors at 10^5 particles: what a
     * scene pays for what it uses, against the same roofline. */
    static const struct {
        const char *name, *forces, *emitter;
    } cases[] = {
        {"gravity only", "", ""},
        {"+ linear drag (exact)", "  air: { type: drag, k: 0.5, wind: [1, 0, 0] }\n", ""},
        {"+ quadratic drag", "  air: { type: drag, k: 0, c: 0.2 }\n", ""},
        {"+ attractor",
         "  well: { type: attractor, center: [0, 2, 0], strength: 2, softening: 0.2 }\n", ""},
        {"+ vortex", "  twist: { type: vortex, axis: [0, 1, 0], strength: 90, radius: 2 }\n", ""},
        {"+ magnetic (boris)", "  b: { type: magnetic, field: [0, 0, 1] }\n", "    charge: 0.5\n"},
        {"+ spiral", "  sp: { type: spiral, axis: [0, 1, 0], rate: 90 }\n", ""},
        {"+ spring", "  s: { type: spring, k: 4, zeta: 0.2 }\n", ""},
        {"+ turbulence (2 octaves)",
         "  t: { type: turbulence, strength: 1, scale: 1, octaves: 2 }\n", ""},
        {"+ speed limit", "  lim: { type: speed_limit, max: 3 }\n", ""},
        {"+ deflector (plane)",
         "deflectors:\n  ground: { type: plane, resilience: 0.5, friction: 0.1 }\n", ""},
        {"+ deflectors (plane, sphere, box)",
         "deflectors:\n  ground: { type: plane, resilience: 0.5 }\n"
         "  ball: { type: sphere, center: [0.5, 1, 0], radius: 0.3 }\n"
         "  crate: { type: box, center: [-0.6, 0.5, 0], size: [0.4, 0.4, 0.4] }\n",
         ""},
    };
    const double n = 1e5;
    double roof = roof_1e5; /* the same reference as the 10^5 row above */
    fprintf(out, "per force at 10^5 particles (roofline %.4g steps/s):\n", roof);
    fprintf(out, "  %-34s %14s %8s  %s\n", "force set", "steps/s", "ratio", "integrator");
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        pfx_loaded l;
        char forces[1024];
        /* Deflector cases add a top-level key after the forces. */
        snprintf(forces, sizeof forces, "%s", cases[k].forces);
        if (!fountain(&l, n, forces, cases[k].emitter)) {
            pfx_loaded_free(&l);
            continue;
        }
        const pfx_emitter *em = &l.effect->emitters[0];
        double rate = steps_per_second(l.effect);
        char why[64];
        snprintf(why, sizeof why, "%s",
                 em->motion ? pfx_integrator_name(em->motion->choice.chosen) : "exact (gravity)");
        fprintf(out, "  %-34s %14.4g %7.0f%%  %s\n", cases[k].name, rate, 100 * rate / roof, why);
        pfx_loaded_free(&l);
    }
}

static bool bench_render(FILE *out, const char *fire_path, pfx_renderer *r, pfx_diags *d) {
    pfx_loaded l;
    pfx_compile_options opt = {.width = 512, .height = 512};
    pfx_effect *e = pfx_load(&l, fire_path, &opt);
    if (!e) {
        pfx_diags_append(d, &l.diags);
        pfx_loaded_free(&l);
        return false;
    }
    char dir[] = "/tmp/pfx-bench-XXXXXX";
    pfx_render_job job = {.effect = e,
                          .renderer = r,
                          .dir = dir,
                          .stem = "f",
                          .first = 0,
                          .last = pfx_effect_frame_count(e) - 1};
    if (!mkdtemp(dir)) {
        pfx_diag_error(d, "cannot create '%s': %s", dir, strerror(errno));
        pfx_loaded_free(&l);
        return false;
    }
    double t0 = now();
    bool ok = pfx_render_job_run(&job, d);
    double full_fps = (double)job.frames_done / (now() - t0);
    char path[600];
    for (long f = 0; f < job.frames_done; f++) {
        snprintf(path, sizeof path, "%s/f_%04ld.png", dir, f);
        unlink(path);
    }
    rmdir(dir);
    if (ok) {
        /* The raw reference draws the last frame's sprites (the steady
         * state), as many of them as the render drew on average. */
        long frames = job.frames_done;
        size_t mean = frames ? job.sprites_drawn / (size_t)frames : 0;
        double raw_fps = pfx_renderer_bench_raw(r, &e->camera, job.sprites, mean, (int)frames);
        fprintf(out,
                "rendering: %s at 512x512 through %s, %ld frames, %zu sprites a frame on average\n",
                fire_path, pfx_renderer_name(r), frames, mean);
        fprintf(out, "  %-44s %8.1f frames/s\n", "pfx render (sim, sprites, draw, PNG overlapped)",
                full_fps);
        char raw[64];
        snprintf(raw, sizeof raw, "raw %s (upload, one draw, readback)", pfx_renderer_name(r));
        fprintf(out, "  %-44s %8.1f frames/s\n", raw, raw_fps);
        fprintf(out, "  %-44s %7.0f%%\n", "ratio", 100 * full_fps / raw_fps);
    }
    pfx_render_job_free(&job);
    pfx_loaded_free(&l);
    return ok;
}

bool pfx_bench_speed(FILE *out, const char *fire_path, pfx_renderer_kind renderer, pfx_diags *d) {
    pfx_renderer *r = pfx_renderer_create(renderer, 512, 512, d);
    if (!r)
        return false;
    bench_sim(out);
    bool ok = bench_render(out, fire_path, r, d) && pfx_bench_looks(out, r, 512, 512, d);
    pfx_renderer_destroy(r);
    return ok;
}
