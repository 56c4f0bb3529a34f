/* The speed benchmark. It reports figures, it does not judge them: each
 * figure stands next to a reference measured in the same run on the same
 * machine, so the ratio means something where absolute speeds do not. */
#include "bench/speed.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "compile/compile.h"
#include "output/png_write.h"
#include "render/render.h"
#include "render/sprites.h"
#include "sim/sim.h"

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A gravity-only fountain whose steady live count is about n: rate n / L with
 * a constant lifetime L. */
static void make_fountain(pfx_effect *e, pfx_emitter *em, double n) {
    memset(e, 0, sizeof *e);
    memset(em, 0, sizeof *em);
    e->duration = 10;
    e->fps = 30;
    e->sim_rate = 120;
    e->emitter_count = 1;
    e->emitters = em;
    e->max_particles = (uint64_t)(2 * n + 10);
    em->name = "bench";
    em->shape.type = PFX_SHAPE_SPHERE;
    em->shape.radius = 0.1;
    for (int i = 0; i < 9; i += 4)
        em->rotation[i] = 1;
    em->rate_kind = PFX_RATE_CONSTANT;
    em->rate = n / 2.0;
    em->duration = INFINITY;
    em->direction[1] = 1;
    em->spread_deg = 30;
    em->speed = (pfx_value){.dist = PFX_DIST_UNIFORM, .a = 2, .b = 4};
    em->lifetime = pfx_value_const(2);
    em->max_lifetime = 2;
    em->size_start = em->size_end = pfx_value_const(0.05);
    em->size_same = true;
    em->gravity_scale = pfx_value_const(1);
    em->accel[1] = -9.81;
    em->capacity = (uint32_t)(floor(em->rate * 2) + 1);
}

/* The roofline: the same per-particle arithmetic as the gravity kernel on
 * dense arrays, with nothing else (no deaths, no births). */
static double roofline(size_t n, int steps) {
    float *col = malloc(7 * n * sizeof *col);
    if (!col)
        return 0;
    float *px = col, *py = px + n, *pz = py + n, *vx = pz + n, *vy = vx + n, *vz = vy + n,
          *age = vz + n;
    for (size_t i = 0; i < 7 * n; i++)
        col[i] = (float)(i % 97) * 0.01f;
    const float dt = 1.0f / 120, hy = -9.81f * 0.5f * dt * dt, ky = -9.81f * dt;
    double t0 = now();
    for (int s = 0; s < steps; s++) {
        for (size_t i = 0; i < n; i++) {
            px[i] += vx[i] * dt;
            py[i] += vy[i] * dt + hy;
            pz[i] += vz[i] * dt;
            vy[i] += ky;
            age[i] += dt;
        }
        /* Keep the compiler from collapsing the steps. */
        __asm__ volatile("" : : "r"(col) : "memory");
    }
    double rate = (double)n * steps / (now() - t0);
    free(col);
    return rate;
}

static void bench_sim(FILE *out) {
    fprintf(out, "simulation: gravity-only fountain, exact constant-acceleration kernel\n");
    fprintf(out, "  %10s %16s %16s %8s\n", "particles", "pfx steps/s", "roofline/s", "ratio");
    const double sizes[] = {1e4, 1e5, 1e6};
    for (int k = 0; k < 3; k++) {
        pfx_effect e;
        pfx_emitter em;
        make_fountain(&e, &em, sizes[k]);
        pfx_sim *s = pfx_sim_create(&e);
        if (!s)
            return;
        for (int i = 0; i < 250; i++) /* past one lifetime: steady state */
            pfx_sim_step(s);
        int steps = (int)fmax(20, 2e8 / sizes[k]);
        double work = 0, t0 = now();
        for (int i = 0; i < steps; i++) {
            work += s->pools[0].count;
            pfx_sim_step(s);
        }
        double pfx_rate = work / (now() - t0);
        double roof = roofline((size_t)sizes[k], steps);
        fprintf(out, "  %10.0f %16.4g %16.4g %7.0f%%\n", sizes[k], pfx_rate, roof,
                100 * pfx_rate / roof);
        pfx_sim_destroy(s);
    }
}

static int bench_render(FILE *out, const char *fire_path) {
    pfx_loaded l;
    pfx_compile_options opt = {.width = 512, .height = 512};
    pfx_effect *e = pfx_load(&l, fire_path, &opt);
    if (!e) {
        pfx_diags_print(&l.diags, stderr, false);
        pfx_loaded_free(&l);
        return 1;
    }
    char err[512] = "", dir[] = "/tmp/pfx-bench-XXXXXX", path[600];
    pfx_sim *sim = pfx_sim_create(e), *view = pfx_sim_create(e);
    pfx_sprite *sprites = malloc((pfx_sprites_capacity(e) + 1) * sizeof *sprites);
    pfx_renderer *r = pfx_renderer_create(512, 512, err, sizeof err);
    pfx_png_queue *q = pfx_png_queue_create(512, 512);
    int status = 1;
    if (!sim || !view || !sprites || !r || !q || !mkdtemp(dir))
        goto done;
    long frames = pfx_effect_frame_count(e);
    size_t sprite_total = 0;
    double t0 = now();
    for (long f = 0; f < frames; f++) {
        const pfx_sim *state = pfx_sim_frame(sim, view, f);
        size_t n = pfx_sprites_build(state, sprites);
        sprite_total += n;
        uint8_t *px = pfx_png_queue_buffer(q);
        if (!pfx_renderer_draw(r, &e->camera, e->background, sprites, n, pfx_sprites_need_sort(e),
                               px, err, sizeof err))
            goto done;
        snprintf(path, sizeof path, "%s/f_%04ld.png", dir, f);
        pfx_png_queue_submit(q, path);
    }
    bool ok = pfx_png_queue_finish(q, err, sizeof err);
    q = NULL;
    double full_fps = (double)frames / (now() - t0);
    for (long f = 0; f < frames; f++) {
        snprintf(path, sizeof path, "%s/f_%04ld.png", dir, f);
        unlink(path);
    }
    rmdir(dir);
    if (!ok)
        goto done;
    /* The raw reference draws the last frame's sprites (the steady state),
     * as many of them as the render drew on average. */
    size_t mean = frames ? sprite_total / (size_t)frames : 0;
    double raw_fps = pfx_renderer_bench_raw(r, &e->camera, sprites, mean, (int)frames);
    fprintf(out, "rendering: %s at 512x512, %ld frames, %zu sprites a frame on average\n",
            fire_path, frames, mean);
    fprintf(out, "  %-44s %8.1f frames/s\n", "pfx render (sim, sprites, draw, PNG overlapped)",
            full_fps);
    fprintf(out, "  %-44s %8.1f frames/s\n", "raw OSMesa (upload, one draw, readback)", raw_fps);
    fprintf(out, "  %-44s %7.0f%%\n", "ratio", 100 * full_fps / raw_fps);
    status = 0;
done:
    if (status && err[0])
        fprintf(stderr, "pfx: %s\n", err);
    if (q)
        pfx_png_queue_finish(q, err, sizeof err);
    pfx_renderer_destroy(r);
    free(sprites);
    pfx_sim_destroy(view);
    pfx_sim_destroy(sim);
    pfx_loaded_free(&l);
    return status;
}

int pfx_bench_speed(FILE *out, const char *fire_path) {
    bench_sim(out);
    return bench_render(out, fire_path);
}
