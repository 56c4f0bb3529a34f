/* `pfx bench`: simulation and rendering speed, each next to a reference
 * measured in the same run. */
#ifndef PFX_BENCH_SPEED_H
#define PFX_BENCH_SPEED_H

#include <stdbool.h>
#include <stdio.h>

#include "base/diag.h"

#include "render/render.h"

/* Measures and prints, as text or (json) as one JSON object: the machine
 * (cores; memory bandwidth by the STREAM triad on all cores); the
 * gravity-only simulation at 10^4 to 10^7 live particles on one thread and
 * on every core, next to the bandwidth limit (bandwidth / the 60 bytes a
 * particle-step moves) and, for one thread, a minimal SoA kernel doing the
 * same arithmetic (the roofline); each force and deflector set at 10^5
 * particles on one thread; births per second of the point, sphere and cone
 * shapes on one and two threads; and frames per second of rendering
 * `fire_path`, then a built-in scene of some 15000 sprites, each
 * at 512x512 and 1920x1080 (sim + sprites + draw + readback + PNG, the
 * frame loop of `pfx render` itself, jobs/render_job.h) next to raw drawing
 * of the same sprites, through the `renderer` kind, which it names.
 * Returns false with the failure in d (a renderer that cannot start fails
 * before anything is measured). */
/* The sections of the report, one row each: the bit and the name `pfx
 * bench NAME...` gives; none named: all. The machine line is always
 * there. */
#define PFX_BENCH_SECTIONS(X)                                                                      \
    X(PFX_BENCH_SIM, 1u << 0, "sim")                                                               \
    X(PFX_BENCH_FORCES, 1u << 1, "forces")                                                         \
    X(PFX_BENCH_SORT, 1u << 2, "sort")                                                             \
    X(PFX_BENCH_RENDER, 1u << 3, "render")                                                         \
    X(PFX_BENCH_LOOKS, 1u << 4, "looks")                                                           \
    X(PFX_BENCH_EMISSION, 1u << 5, "emission")
enum {
#define PFX_BENCH_BIT(id, bit, name) id = bit,
    PFX_BENCH_SECTIONS(PFX_BENCH_BIT)
#undef PFX_BENCH_BIT
        PFX_BENCH_ALL = (1u << 6) - 1
};
/* The section's bit for its name, or 0 when there is none; names, a
 * NULL-ended list of them for suggestions. */
unsigned pfx_bench_section(const char *name);
extern const char *const pfx_bench_section_names[];

bool pfx_bench_speed(FILE *out, const char *fire_path, pfx_renderer_kind renderer, bool json,
                     unsigned sections, pfx_diags *d);

#endif
