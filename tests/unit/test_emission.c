/* Emission and life (issue 3) through the compiler and the simulation:
 * bursts at exact times and counts, rate curves that integrate to their
 * count, Reeves mean +- var windows, intervals, level of detail, moving
 * emitters spreading births along their path, sub-emitter counts and
 * inheritance, and a seamless loop whose state repeats. Every expectation
 * is a formula, not a number pfx printed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim/schedule.h"
#include "sim/sim.h"
#include "test.h"
#include "test_compile.h"

static pfx_sim *run(const pfx_effect *e, double t) {
    pfx_sim *s = pfx_sim_create(e, NULL);
    CHECK(s != NULL);
    if (s)
        pfx_sim_run_to(s, t);
    return s;
}

/* Bursts: count particles at time + c * interval, each exactly as old as
 * its burst. */
static void test_bursts(void) {
    compiled c;
    if (!compile_text(&c, "pfx: 1\nsim: { rate: 60 }\nemitters:\n  b:\n    rate: 0\n"
                          "    bursts: [{time: 0.51, count: 7, cycles: 3, interval: 0.25}]\n"
                          "    lifetime: 10\n    speed: 0\n"))
        return;
    pfx_sim *s = run(c.e, 1.5);
    const pfx_pool *p = &s->pools[0];
    CHECK(p->count == 21);
    int per_burst[3] = {0, 0, 0};
    for (uint32_t j = 0; j < p->count; j++) {
        /* The burst a particle came from is its age's: 1.5 - 0.51 - 0.25 c. */
        int cyc = (int)lround((1.5 - 0.51 - pfx_particle_age(p, j)) / 0.25);
        CHECK(cyc >= 0 && cyc < 3);
        if (cyc < 0 || cyc > 2)
            continue;
        per_burst[cyc]++;
        CHECK_NEAR(pfx_particle_age(p, j), 1.5 - (0.51 + 0.25 * cyc), 1e-5);
    }
    CHECK(per_burst[0] == 7 && per_burst[1] == 7 && per_burst[2] == 7);
    pfx_sim_destroy(s);
    compiled_free(&c);
}

/* A rate curve from 0 to 100/s over 2 s: births by tau are floor(25 tau^2),
 * its integral, exactly (births are where the integral crosses k). */
static void test_rate_curve(void) {
    compiled c;
    if (!compile_text(&c,
                      "pfx: 1\nemitters:\n  r:\n    rate: [{t: 0, value: 0}, {t: 2, value: 100}]\n"
                      "    lifetime: 100\n"))
        return;
    const double taus[] = {0.3, 0.9, 1.4, 2.0, 2.5, 3.1};
    for (size_t k = 0; k < sizeof taus / sizeof *taus; k++) {
        pfx_sim *s = run(c.e, taus[k]);
        double tau = s->time, want = tau <= 2 ? 25 * tau * tau : 100 + 100 * (tau - 2);
        CHECK(s->emitters[0].born == (uint64_t)floor(want + 1e-9));
        pfx_sim_destroy(s);
    }
    compiled_free(&c);
}

/* Reeves mean +- var: every whole second has its own count in
 * [mean - var, mean + var] (+-1 for the window edges), and the counts
 * average to the mean within 4 standard errors (var / sqrt(3) each). */
static void test_reeves_windows(void) {
    compiled c;
    if (!compile_text(&c, "pfx: 1\nduration: 300\nsim: { rate: 20 }\nemitters:\n  r:\n"
                          "    rate: { mean: 100, var: 40 }\n    lifetime: 0.01\n"))
        return;
    pfx_sim *s = pfx_sim_create(c.e, NULL);
    const int windows = 300;
    uint64_t before = 0;
    double sum = 0;
    bool in_range = true;
    for (int w = 1; w <= windows; w++) {
        pfx_sim_run_to(s, w);
        double n = (double)(s->emitters[0].born - before);
        before = s->emitters[0].born;
        in_range &= n >= 60 - 1 && n <= 140 + 1;
        sum += n;
    }
    CHECK(in_range);
    double mean = sum / windows, se = 40 / sqrt(3.0) / sqrt((double)windows);
    fprintf(stderr, "  reeves: mean %.2f per second, expected 100 +- %.2f (4 se)\n", mean, 4 * se);
    CHECK_NEAR(mean, 100, 4 * se);
    pfx_sim_destroy(s);
    compiled_free(&c);
}

/* interval: a constant interval 0.1 s gives floor(t / 0.1) births. */
static void test_interval(void) {
    compiled c;
    if (!compile_text(&c, "pfx: 1\nemitters:\n  i:\n    interval: 0.1\n    lifetime: 100\n"))
        return;
    pfx_sim *s = run(c.e, 2.05);
    CHECK(s->emitters[0].born == 20);
    pfx_sim_destroy(s);
    compiled_free(&c);
}

/* Level of detail: the rate is per_pixel x the projected area, so moving
 * the emitter sqrt(2) times farther halves the rate. */
static void test_lod(void) {
    compiled a, b;
    const char *fmt = "pfx: 1\ncamera: { position: [0, 0, 0], target: [0, 0, -1], fov: 40 }\n"
                      "emitters:\n  l:\n    shape: { type: sphere, radius: 0.5 }\n"
                      "    position: [0, 0, %.17g]\n    lod: { per_pixel: 0.01 }\n";
    char ta[512], tb[512];
    snprintf(ta, sizeof ta, fmt, -10.0);
    snprintf(tb, sizeof tb, fmt, -10.0 * sqrt(2.0));
    if (!compile_text(&a, ta) || !compile_text(&b, tb))
        return;
    CHECK_NEAR(b.e->emitters[0].lod_area / a.e->emitters[0].lod_area, 0.5, 1e-9);
    CHECK_NEAR(b.e->emitters[0].rate / a.e->emitters[0].rate, 0.5, 1e-9);
    pfx_sim *sa = run(a.e, 20), *sb = run(b.e, 20);
    double ra = (double)sa->emitters[0].born, rb = (double)sb->emitters[0].born;
    CHECK(fabs(rb - 0.5 * ra) <= 1.0);
    pfx_sim_destroy(sa);
    pfx_sim_destroy(sb);
    compiled_free(&a);
    compiled_free(&b);
}

/* A moving emitter spreads its births along its path: at 120 births/s and
 * 30 steps/s, a point moving at 12 m/s leaves particles 0.1 m apart, not in
 * clumps of 4 per step. */
static void test_moving_emitter(void) {
    compiled c;
    if (!compile_text(&c, "pfx: 1\nsim: { rate: 30 }\nforces: {}\nemitters:\n  m:\n"
                          "    position: [{t: 0, value: [0, 0, 0]}, {t: 10, value: [120, 0, 0]}]\n"
                          "    rate: 120\n    speed: 0\n    lifetime: 100\n"))
        return;
    pfx_sim *s = run(c.e, 1.0);
    const pfx_pool *p = &s->pools[0];
    CHECK(p->count == 120);
    for (uint32_t j = 0; j < p->count; j++)
        CHECK_NEAR(p->px[j], 12.0 * (p->id[j] + 1) / 120.0, 1e-4);
    pfx_sim_destroy(s);
    compiled_free(&c);
}

/* Sub-emitters: every parent death makes `count` children at the death
 * place (a child with speed 0 and no force stays there), with the parent's
 * colour when inherited. */
static void test_sub_emitters(void) {
    compiled c;
    if (!compile_text(&c, "pfx: 1\nforces: {}\nemitters:\n  parent:\n    rate: 4\n"
                          "    speed: 2\n    lifetime: 0.5\n    color: \"#ff8000\"\n"
                          "    on_death: { emit: child, count: 6, inherit: [color] }\n"
                          "  child:\n    speed: 0\n    lifetime: 100\n"))
        return;
    pfx_sim *s = run(c.e, 3.1);
    /* Parent k (k = 1, 2, ...) is born at k/4 and dies at k/4 + 0.5 at
     * height 2 * 0.5 = 1 (direction +Y, no force). */
    uint64_t deaths = (uint64_t)floor((3.1 - 0.5) * 4);
    const pfx_pool *ch = &s->pools[1];
    fprintf(stderr, "  %llu deaths, %u children\n", (unsigned long long)deaths, ch->count);
    CHECK(ch->count == 6 * deaths);
    for (uint32_t j = 0; j < ch->count; j++) {
        CHECK_NEAR(ch->py[j], 1.0, 1e-5);
        float col[4];
        pfx_particle_color(&c.e->emitters[1], ch, j, col);
        CHECK_NEAR(col[0], 1.0, 1e-6);
        CHECK_NEAR(col[1], 128.0 / 255, 1e-6);
        CHECK_NEAR(col[2], 0.0, 1e-6);
    }
    pfx_sim_destroy(s);
    compiled_free(&c);
}

/* A cycle without depth is refused; with depth it is bounded. */
static void test_cycle_depth(void) {
    compiled c;
    memset(&c, 0, sizeof c);
    const char *bad = "pfx: 1\nemitters:\n  a:\n    on_death: { emit: a, count: 2 }\n";
    size_t len = strlen(bad);
    pfx_diags_init(&c.diags, "inline.yaml", bad, len);
    CHECK(pfx_parse(bad, len, &c.doc, &c.diags));
    CHECK(pfx_compile(c.doc.root, "inline.yaml", NULL, &c.arena, &c.diags) == NULL);
    compiled_free(&c);
    if (!compile_text(&c, "pfx: 1\nforces: {}\nemitters:\n  a:\n    rate: 1\n    lifetime: 0.1\n"
                          "    on_death: { emit: a, count: 2, depth: 3 }\n"))
        return;
    /* One root birth at t = 1 dies at 1.1 -> 2 children die at 1.2 -> 4 at
     * 1.3 -> 8 at 1.4 (generation 3: no more). */
    pfx_sim *s = run(c.e, 1.45);
    fprintf(stderr, "  %llu births\n", (unsigned long long)s->emitters[0].born);
    CHECK(s->emitters[0].born == 1 + 2 + 4 + 8);
    pfx_sim_destroy(s);
    compiled_free(&c);
}

/* Sorted (x, y, z, age) of every live particle. */
static double *snapshot(const pfx_sim *s, size_t *n) {
    const pfx_pool *p = &s->pools[0];
    double *v = malloc((p->count + 1) * 4 * sizeof *v);
    for (uint32_t j = 0; j < p->count; j++) {
        v[4 * j] = pfx_particle_age(p, j);
        v[4 * j + 1] = p->px[j];
        v[4 * j + 2] = p->py[j];
        v[4 * j + 3] = p->pz[j];
    }
    *n = p->count;
    return v;
}

static int by_age(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Seamless loop: the state at T + P equals the state at T (the same draws
 * every period), and frame N = P fps is frame 0. Without `loop` the same
 * effect differs after a period, so the test can fail. */
static void test_loop(void) {
    const char *text = "pfx: 1\nloop: %s\nduration: 2\nfps: 30\nemitters:\n  f:\n"
                       "    shape: { type: sphere, radius: 0.3 }\n    rate: 50\n"
                       "    speed: [0.5, 1.5]\n    spread: 30\n    lifetime: [0.5, 1.5]\n";
    for (int looping = 1; looping >= 0; looping--) {
        char t[512];
        snprintf(t, sizeof t, text, looping ? "true" : "false");
        compiled c;
        if (!compile_text(&c, t))
            return;
        double T = looping ? c.e->loop_start : 4.0;
        if (looping) {
            CHECK(c.e->loop_frames == 60);
            CHECK(c.e->loop_start >= 1.5);
            CHECK(pfx_sim_frame_time(c.e, 60) == pfx_sim_frame_time(c.e, 0));
        }
        pfx_sim *a = run(c.e, T), *b = run(c.e, T + 2.0);
        size_t na, nb;
        double *va = snapshot(a, &na), *vb = snapshot(b, &nb);
        qsort(va, na, 4 * sizeof *va, by_age);
        qsort(vb, nb, 4 * sizeof *vb, by_age);
        double worst = na == nb ? 0 : INFINITY;
        for (size_t k = 0; k < 4 * na && na == nb; k++)
            worst = fmax(worst, fabs(va[k] - vb[k]));
        fprintf(stderr, "  loop %s: %zu vs %zu particles, worst difference %.3g\n",
                looping ? "on" : "off", na, nb, worst);
        if (looping)
            CHECK(na == nb && worst < 1e-4);
        else
            CHECK(!(na == nb && worst < 1e-4));
        free(va);
        free(vb);
        pfx_sim_destroy(a);
        pfx_sim_destroy(b);
        compiled_free(&c);
    }
}

/* Sprite angle: angle0 + spin * age for a constant spin; for a spin curve
 * from 0 to 360 deg/s over life the turn is lifetime * 180 u^2 (its
 * integral), within the table's resolution. */
static void test_spin(void) {
    compiled c;
    if (!compile_text(&c, "pfx: 1\nforces: {}\nemitters:\n  s:\n    rate: 10\n"
                          "    lifetime: 2\n    angle: 30\n    spin: 90\n    sprite: square\n"
                          "  t:\n    rate: 10\n    lifetime: 2\n"
                          "    spin: [{at: 0, value: 0}, {at: 1, value: 360}]\n"))
        return;
    pfx_sim *s = run(c.e, 1.5);
    const pfx_pool *p = &s->pools[0], *q = &s->pools[1];
    CHECK(p->count > 0 && q->count > 0);
    for (uint32_t j = 0; j < p->count; j++)
        CHECK_NEAR(pfx_particle_angle(&c.e->emitters[0], p, j),
                   (30 + 90 * (double)pfx_particle_age(p, j)) * M_PI / 180, 1e-5);
    for (uint32_t j = 0; j < q->count; j++) {
        double u = pfx_particle_age(q, j) / 2.0;
        /* Nearest-entry lookup: u is off by up to half a table step. */
        double want = 2.0 * 180 * u * u, slack = 2.0 * 360 * 0.5 / 255 + 0.01;
        CHECK_NEAR(pfx_particle_angle(&c.e->emitters[1], q, j) * 180 / M_PI, want, slack);
    }
    pfx_sim_destroy(s);
    compiled_free(&c);
}

/* pfx_schedule_take (a block of births at once, a burst event's births
 * together) takes the births peek and pop give one by one, in order, with
 * the same times to the bit, stopping after the birth that ends a loop
 * period, and leaves the schedule as they leave it: bursts of every kind
 * (overlapping, cycled, probable, random counts) beside a rate, looping
 * with bursts inside a step, and a rate curve, taken up to 1 to 64 at a
 * time against steps of a few sizes. */
static void test_schedule_take(void) {
    static const char *const emitters[] = {
        "    rate: 37\n    bursts: [{time: 0.1, count: 200, cycles: 3, interval: 0.3},"
        " {time: 0.1, count: [5, 90]}, {time: 0.45, count: 70, probability: 0.5, cycles: 4,"
        " interval: 0.05}]\n    duration: 2\n",
        "    rate: 300\n    bursts: [{time: 0, count: 130}, {time: 0.2, count: 65}]\n"
        "    duration: 0.25\n    loop: true\n",
        "    rate: [{t: 0, value: 0}, {t: 1, value: 500}]\n    duration: 2\n",
    };
    for (size_t e = 0; e < sizeof emitters / sizeof *emitters; e++) {
        char text[512];
        snprintf(text, sizeof text, "pfx: 1\nemitters:\n  b:\n%s    lifetime: 1\n", emitters[e]);
        compiled c;
        if (!compile_text(&c, text))
            continue;
        const pfx_emitter *em = &c.e->emitters[0];
        static pfx_schedule one, many;
        pfx_schedule_init(&one, em, 5, 6);
        many = one;
        bool same = true;
        int births = 0;
        uint32_t max = 1;
        for (double t1 = 0.013; t1 < 1.7 && same; t1 += 0.0071 * (1 + (births & 3))) {
            for (;;) {
                double times[64];
                const uint64_t period = one.period;
                uint32_t n = 0;
                while (n < max && one.period == period) {
                    const double at = pfx_schedule_peek(&one, em);
                    if (!(at <= t1))
                        break;
                    pfx_schedule_pop(&one, em);
                    times[n++] = at;
                }
                double got[64];
                const uint32_t m = pfx_schedule_take(&many, em, t1, max, got);
                same &= m == n && !memcmp(got, times, n * sizeof *times) &&
                        !memcmp(&one, &many, sizeof one);
                births += (int)n;
                max = max % 64 + 1;
                if (!n || !same)
                    break;
            }
        }
        if (!same)
            fprintf(stderr, "  emitter %zu: take and peek/pop part after %d births\n", e, births);
        CHECK(same);
        CHECK(births > 300);
        compiled_free(&c);
    }
}

int main(void) {
    RUN(test_bursts);
    RUN(test_schedule_take);
    RUN(test_rate_curve);
    RUN(test_reeves_windows);
    RUN(test_interval);
    RUN(test_lod);
    RUN(test_moving_emitter);
    RUN(test_sub_emitters);
    RUN(test_cycle_depth);
    RUN(test_loop);
    RUN(test_spin);
    return TEST_EXIT();
}
