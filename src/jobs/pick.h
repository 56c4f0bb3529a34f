/* Pick: which emitters made a pixel of a frame, for `pfx preview`. */
#ifndef PFX_JOBS_PICK_H
#define PFX_JOBS_PICK_H

#include <stdbool.h>

#include "base/diag.h"
#include "model/effect.h"

/* Simulates e to frame k and sets hit[i] (room for e->emitter_count) when
 * a sprite of emitter i covers pixel (x right, y down) of the frame, as
 * the renderer would draw it: a disc around the sprite's projected centre
 * whose diameter is its on-screen width (size, or an align-velocity
 * streak's length when longer), widened to PFX_MIN_FOOTPRINT_PX as the
 * renderer widens thin sprites. Ribbons are not picked. Computed from the
 * frame's sprites, not by drawing. False, with the reason in d, when the
 * simulation cannot be created or fails. */
bool pfx_pick(const pfx_effect *e, long k, int x, int y, bool *hit, pfx_diags *d);

#endif
