/* libFuzzer target: what compiles runs. Any bytes are loaded as in
 * fuzz_load.c with a budget of 500 particles; an effect that compiles is
 * simulated to its first three frames (when they are at most 2,000 steps
 * and, by pfx info's estimate, substeps included, 2e7 particle-steps away:
 * a stiff field may ask for hundreds of substeps, which is slow but not a
 * bug, and libFuzzer would report it as a timeout) and each frame is turned into sprites and drawn
 * at 32x32 by one renderer made at the first input. The simulation asserts its invariants instead
 * of reporting, so any sanitizer report or abort here is a bug of the compiler (it let bad input
 * through) or of the stage itself. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "jobs/estimate.h"
#include "jobs/load.h"
#include "render/render.h"
#include "render/sprites.h"
#include "sim/sim.h"

#define MAX_STEPS 2000.0
#define MAX_PARTICLE_STEPS 2e7
#define FRAMES 3

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static pfx_renderer *renderer(void) {
    static pfx_renderer *r;
    static bool tried;
    if (!tried) {
        pfx_diags d;
        pfx_diags_init_runtime(&d);
        tried = true;
        r = pfx_renderer_create(PFX_RENDERER_AUTO, 32, 32, &d);
        if (!r)
            fprintf(stderr, "fuzz_sim: no renderer: simulating only\n");
        pfx_diags_free(&d);
    }
    return r;
}

static void run(const pfx_effect *e) {
    long frames = pfx_effect_frame_count(e);
    if (frames > FRAMES)
        frames = FRAMES;
    if (pfx_sim_frame_time(e, frames - 1) * e->sim_rate > MAX_STEPS)
        return;
    pfx_estimate est;
    pfx_estimate_run(e, 0, frames - 1, 0, &est);
    if (est.work > MAX_PARTICLE_STEPS)
        return;
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    pfx_sim *sim = pfx_sim_create(e, &d), *view = pfx_sim_create(e, &d);
    pfx_sprite *sprites = malloc((pfx_sprites_capacity(e) + 1) * sizeof *sprites);
    pfx_renderer *r = renderer();
    static uint8_t rgba[32 * 32 * 4];
    /* The effect's looks (textures, flipbooks, light), as pfx render sets them. */
    pfx_material *materials = malloc((e->emitter_count + 1) * sizeof *materials);
    const pfx_render_settings settings = pfx_sprites_settings(e);
    if (materials)
        pfx_sprites_materials(e, materials);
    if (r && (!materials || !pfx_renderer_set_materials(r, materials, e->emitter_count, &d)))
        r = NULL;
    for (long f = 0; sim && view && sprites && f < frames; f++) {
        const pfx_sim *state = pfx_sim_frame(sim, view, f);
        if (sim->failed || view->failed)
            break;
        size_t n = pfx_sprites_build(state, sprites);
        if (r)
            pfx_renderer_draw_frame(r, &e->camera, &settings, sprites, n, pfx_sprites_need_sort(e),
                                    (pfx_ribbons){NULL, 0}, rgba, &d);
    }
    free(sprites);
    free(materials);
    pfx_sim_destroy(view);
    pfx_sim_destroy(sim);
    pfx_diags_free(&d);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    pfx_loaded l;
    pfx_compile_options opt = {.max_particles = 500};
    const pfx_effect *e = pfx_load_bytes(&l, "/nonexistent/fuzz.yaml", data, size, &opt);
    if (e)
        run(e);
    pfx_loaded_free(&l);
    return 0;
}
