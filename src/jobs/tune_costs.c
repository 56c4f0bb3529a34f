/* What else a scene pays for (jobs/tune.h): one run of the file's own
 * setting over every frame of the range, watching each particle through
 * the camera, and the ladder's runs, turned into findings with their
 * savings. It changes nothing and writes nothing. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jobs/tune.h"
#include "sim/sim.h"

/* What the watch counts per emitter. */
typedef struct emitter_watch {
    uint32_t peak;               /* most alive at a frame */
    double frames, wasted;       /* particle-frames, and those off screen or invisible */
    double largest_px;           /* the largest sprite on screen, px across */
    bool colour_set, one_colour; /* every sprite of it the same colour */
    float colour[3];
} emitter_watch;

static void add_cost(pfx_tune_result *res, double saving, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void add_cost(pfx_tune_result *res, double saving, const char *fmt, ...) {
    if (res->cost_count == sizeof res->costs / sizeof res->costs[0])
        return;
    pfx_tune_cost *c = &res->costs[res->cost_count++];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->text, sizeof c->text, fmt, ap);
    va_end(ap);
    c->saving = saving;
}

/* One frame's particles of emitter i into w: on screen or not, visible or
 * not (alpha under 1/255, or under a tenth of a pixel across), their size
 * on screen and colour. */
static void watch_pool(const pfx_effect *e, size_t i, const pfx_pool *p, emitter_watch *w) {
    const pfx_emitter *em = &e->emitters[i];
    if (p->count > w->peak)
        w->peak = p->count;
    for (uint32_t j = 0; j < p->count; j++) {
        const double pos[3] = {p->px[j], p->py[j], p->pz[j]};
        double px[2], depth;
        float rgba[4];
        pfx_particle_color(em, p, j, rgba);
        double across =
            pfx_particle_size(em, p, j) * pfx_camera_pixels_per_metre(&e->camera, e->height, pos);
        bool seen = pfx_camera_project(&e->camera, e->width, e->height, pos, px, &depth) &&
                    px[0] > -across && px[0] < e->width + across && px[1] > -across &&
                    px[1] < e->height + across;
        bool visible = rgba[3] >= 1.0f / 255 && across >= 0.1;
        w->frames++;
        w->wasted += !(seen && visible);
        if (seen && across > w->largest_px)
            w->largest_px = across;
        if (!w->colour_set) {
            memcpy(w->colour, rgba, sizeof w->colour);
            w->colour_set = w->one_colour = true;
        } else if (memcmp(w->colour, rgba, sizeof w->colour)) {
            w->one_colour = false;
        }
    }
}

/* The findings from the watch. */
static void findings(const pfx_effect *e, const emitter_watch *w, pfx_tune_result *res) {
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        if (em->capacity > 2 * (w[i].peak + 1))
            add_cost(res, 1 - (double)w[i].peak / em->capacity,
                     "emitter '%s': a pool of %u particles, at most %u alive at a frame: its "
                     "memory is sized for the worst case of rate x lifetime",
                     em->name, em->capacity, w[i].peak);
        if (w[i].frames > 0 && w[i].wasted > 0.5 * w[i].frames)
            add_cost(res, w[i].wasted / w[i].frames,
                     "emitter '%s': %.0f%% of its particle-frames are off screen or invisible "
                     "(a kill rule, bounds or a shorter lifetime would spare them)",
                     em->name, 100 * w[i].wasted / w[i].frames);
        const pfx_image *t = em->look.texture;
        if (t && w[i].largest_px > 0) {
            int cols = em->look.flipbook.cols > 0 ? em->look.flipbook.cols : 1;
            int rows = em->look.flipbook.rows > 0 ? em->look.flipbook.rows : 1;
            double cell = fmax((double)t->width / cols, (double)t->height / rows);
            double need = pow(2, ceil(log2(fmax(w[i].largest_px, 1))));
            if (cell > 2 * need)
                add_cost(res, 1 - (need / cell) * (need / cell),
                         "emitter '%s': texture '%s' has %gpx cells, its sprites are at most "
                         "%.0f px on screen (%gpx would do)",
                         em->name, t->path, cell, w[i].largest_px, need);
        }
    }
    /* The depth sort runs when an emitter blends alpha; compositing
     * sprites of one colour gives the same pixel in any order, so it
     * buys nothing when every alpha sprite shares one colour, unlit and
     * untextured. */
    bool any = false, same = true;
    const float *first = NULL;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        if (em->blend != PFX_BLEND_ALPHA || em->look.draw != PFX_DRAW_SPRITE || !w[i].colour_set)
            continue;
        any = true;
        same = same && w[i].one_colour && !em->look.texture && !em->look.lit;
        if (same && first && memcmp(first, w[i].colour, 3 * sizeof *first))
            same = false;
        first = w[i].colour;
    }
    if (any && same)
        add_cost(res, 1,
                 "a depth sort of every frame's sprites that changes no pixel: every "
                 "alpha-blended sprite has one colour, and layers of one colour composite the "
                 "same in any order");
}

/* Steps per frame beyond need: the file's rate against the cheapest run
 * within the tolerance. */
static void step_finding(const pfx_effect *e, pfx_tune_result *res) {
    if (res->recommended < 0 || (size_t)res->recommended == res->current)
        return;
    const pfx_tune_run *cur = &res->runs[res->current], *rec = &res->runs[res->recommended];
    if (cur->blew_up || rec->particle_steps >= cur->particle_steps)
        return;
    add_cost(res, 1 - rec->particle_steps / cur->particle_steps,
             "%.3g steps a frame (%g steps/s at %g fps) where %.3g keep the error within "
             "tolerance: %.4g particle-steps where %.4g do",
             cur->rate / e->fps, cur->rate, e->fps, rec->rate / e->fps, cur->particle_steps,
             rec->particle_steps);
}

bool pfx_tune_scene_costs(const pfx_tune_request *r, pfx_tune_result *res, pfx_diags *d) {
    const pfx_effect *e = r->loaded->effect;
    bool ok = false;
    pfx_diags quiet;
    pfx_diags_init_runtime(&quiet);
    pfx_sim *s = NULL, *view = NULL;
    emitter_watch *w = NULL;
    s = pfx_sim_create(e, &quiet);
    view = pfx_sim_create(e, &quiet);
    w = calloc(e->emitter_count + 1, sizeof *w);
    if (!s || !view || !w) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    step_finding(e, res);
    for (long f = r->first; f <= r->last; f++) {
        const pfx_sim *st = pfx_sim_frame(s, view, f);
        if (s->failed || view->failed)
            break;
        for (size_t i = 0; i < e->emitter_count; i++)
            watch_pool(e, i, &st->pools[i], &w[i]);
    }
    findings(e, w, res);
    ok = true;
done:
    free(w);
    pfx_sim_destroy(view);
    pfx_sim_destroy(s);
    pfx_diags_free(&quiet);
    return ok;
}
