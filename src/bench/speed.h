/* `pfx bench`: simulation and rendering speed, each next to a reference
 * measured in the same run. */
#ifndef PFX_BENCH_SPEED_H
#define PFX_BENCH_SPEED_H

#include <stdbool.h>
#include <stdio.h>

#include "base/diag.h"

#include "render/render.h"

/* Prints particle-steps per second of the gravity-only simulation at 10^4,
 * 10^5 and 10^6 live particles next to a minimal SoA kernel doing the same
 * arithmetic (the roofline), and frames per second of rendering `fire_path`
 * (sim + sprites + draw + readback + PNG) next to raw drawing of the same
 * sprites, both through the `renderer` kind, which it names. The render is
 * the frame loop of `pfx render` itself (jobs/render_job.h). Returns false
 * with the failure in d (a renderer that cannot start fails before anything
 * is measured). */
bool pfx_bench_speed(FILE *out, const char *fire_path, pfx_renderer_kind renderer, pfx_diags *d);

#endif
