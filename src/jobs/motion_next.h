/* Where each sprite of a frame is one frame later, for --motion-vectors:
 * a simulation of its own run one frame ahead of the frames asked for,
 * its particles matched to the frame's by their stable id. */
#ifndef PFX_JOBS_MOTION_NEXT_H
#define PFX_JOBS_MOTION_NEXT_H

#include <stdbool.h>

#include "base/diag.h"
#include "model/effect.h"
#include "render/render.h"
#include "render/sprites.h"
#include "sim/sim.h"

typedef struct pfx_mv_next pfx_mv_next;

/* Allocates the simulation (and its view) and the id index once, sized
 * from the effect. NULL (with the reason in d) when out of memory; free
 * with pfx_mv_next_destroy. Simulation failures are reported into d. */
pfx_mv_next *pfx_mv_next_create(const pfx_effect *e, pfx_diags *d);
void pfx_mv_next_destroy(pfx_mv_next *n);
/* The bytes pfx_mv_next_create allocates for e, the simulation's pools
 * and spawn queues twice (the state and its view) and the id index (8
 * bytes a particle of every pool, and the sort's 16 bytes a particle of
 * the largest pool with its histogram): for the memory estimate. */
double pfx_mv_next_bytes(const pfx_effect *e);

/* Readies the ends of frame f's sprites, as feed (pointed at the frame's
 * state) gives them: simulates to the frame's time + 1 / fps, the
 * continuation of the simulation (a looping effect's last frame too, not
 * its wrap to frame 0), from time 0 in fixed steps, so the ends do not
 * depend on which frames a job renders. The feed must stay pointed at the
 * same state while the ends are read. False when the simulation failed. */
bool pfx_mv_next_frame(pfx_mv_next *n, const pfx_sprite_feed *feed, long f);

/* The ends of the frame's sprites (render.h): a particle still alive at
 * the next frame (same emitter, same id) ends where the simulation puts
 * it, whatever moved it (velocity, the vortex and other operators,
 * collisions); one that dies before then ends at its position plus its
 * velocity over 1 / fps. Weight 0 for emitters with motion_vectors:
 * false, else 1. Valid until the next pfx_mv_next_frame. */
pfx_sprite_ends pfx_mv_next_ends(const pfx_mv_next *n);

#endif
