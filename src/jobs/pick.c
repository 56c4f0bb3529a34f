/* Pick: the emitters whose sprites cover a pixel of a frame, found from
 * the frame's sprites (centre and size projected by the camera), not by
 * drawing each emitter alone: one simulation to the frame, no GL. */
#include "jobs/pick.h"

#include <stdlib.h>
#include <string.h>

#include "render/sprites.h"

bool pfx_pick(const pfx_effect *e, long k, int x, int y, bool *hit, pfx_diags *d) {
    memset(hit, 0, e->emitter_count * sizeof *hit);
    pfx_sim *sim = pfx_sim_create(e, d), *view = pfx_sim_create(e, d);
    pfx_sprite *sprites = malloc((pfx_sprites_capacity(e) + 1) * sizeof *sprites);
    bool ok = sim && view && sprites;
    if (!ok)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for %zu particles",
                       pfx_sprites_capacity(e));
    const pfx_sim *state = ok ? pfx_sim_frame(sim, view, k) : NULL;
    ok = ok && !sim->failed && !view->failed;
    size_t n = ok ? pfx_sprites_build(state, sprites) : 0;
    /* The pixel's centre, with y up from the bottom as the camera projects. */
    const double px = x + 0.5, py = e->height - (y + 0.5);
    for (size_t i = 0; i < n; i++) {
        const pfx_sprite *s = &sprites[i];
        const double p[3] = {s->x, s->y, s->z};
        double at[2], w;
        if (!pfx_camera_project(&e->camera, e->width, e->height, p, at, &w))
            continue;
        double extent = s->length > s->size ? s->length : s->size;
        double r = 0.5 * extent * pfx_camera_pixels_per_metre(&e->camera, e->height, p);
        if (r < 0.5 * PFX_MIN_FOOTPRINT_PX)
            r = 0.5 * PFX_MIN_FOOTPRINT_PX;
        double dx = px - at[0], dy = py - at[1];
        size_t m = (size_t)s->material;
        if (dx * dx + dy * dy <= r * r && m < e->emitter_count)
            hit[m] = true;
    }
    free(sprites);
    pfx_sim_destroy(view);
    pfx_sim_destroy(sim);
    return ok;
}
