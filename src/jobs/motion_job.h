/* --motion-vectors around the frame loop: the scale chosen from the whole
 * sequence, each frame's motion-vector PNG, the sheet beside the colour
 * atlas, and the sidecar JSON when there is no atlas. */
#ifndef PFX_JOBS_MOTION_JOB_H
#define PFX_JOBS_MOTION_JOB_H

#include <stdbool.h>
#include <stddef.h>

#include "base/diag.h"
#include "jobs/manifest.h"
#include "model/effect.h"
#include "output/atlas.h"
#include "output/motion_vectors.h"
#include "render/render.h"
#include "render/sprites.h"

/* The scale of a render's motion vectors: the PFX_MV_PERCENTILE-th
 * percentile of the displacements to the next frame (jobs/motion_next.h),
 * max(|dx|, |dy|) in pixels, of the sprites drawn into the pass, each
 * weighted by the pixels its footprint covers in the frame, over every
 * frame of the effect, 0 .. frame count - 1: a pass of the simulation
 * without drawing. Still sprites (under 2^-16 px) are left out; the value
 * is rounded up to within 0.07 %. Every frame and every slice of a render
 * then shares one scale, so their bytes do not depend on the range
 * rendered. 1 when nothing moves. False (with the simulation's failure in
 * d) when the simulation fails. */
bool pfx_mv_sequence_max(const pfx_effect *e, double *max_px, pfx_diags *d);

/* Scratch for one renderer's motion-vector frames. */
typedef struct pfx_mv_frame {
    float *mv;                /* width x height x 3 floats from the renderer */
    uint16_t *samples;        /* width x height x 4 encoded samples */
    struct pfx_mv_next *next; /* the next frame's state */
} pfx_mv_frame;

/* Allocates the scratch; false (with the reason in d) when out of memory. */
bool pfx_mv_frame_init(pfx_mv_frame *b, const pfx_effect *e, pfx_diags *d);
void pfx_mv_frame_free(pfx_mv_frame *b);

/* Draws the motion vectors of frame f's sprites (src, made by feed) at the
 * effect's camera, to where each is at frame f + 1 (jobs/motion_next.h),
 * and writes them to `path` (the directory synced by the caller). False
 * with the reason in d. */
bool pfx_mv_frame_write(pfx_mv_frame *b, pfx_renderer *r, const pfx_effect *e,
                        const pfx_render_settings *s, const pfx_sprite_source *src,
                        const pfx_sprite_feed *feed, long f, const pfx_mv_meta *m, const char *path,
                        pfx_diags *d);

/* dir/stem_mv_NNNN.png; false when it does not fit in size. */
bool pfx_mv_frame_path(const char *dir, const char *stem, long frame, char *out, size_t size);

/* Lists dir/stem_mv_NNNN.png of first..last as outputs of mf. */
bool pfx_mv_add_outputs(pfx_manifest *mf, const char *dir, const char *stem, long first, long last,
                        pfx_diags *d);

/* The motion-vector sheet dir/stem_mv_atlas.png of frames first..last laid
 * out by l, resolved for the colour atlas (jobs/atlas_job.c calls it, so
 * the two line up), as a file of group g (output/atomic_file.h); `image`
 * gets its file name. False with the reason in d, nothing written. */
bool pfx_mv_atlas_write(pfx_atomic_group *g, const char *dir, const char *stem, long first,
                        long last, const pfx_atlas_layout *l, char *image, size_t image_size,
                        pfx_diags *d);

/* The key of a slice manifest's "slice" member holding the scale
 * (pfx_mv_meta.max_px) its motion-vector frames were encoded with. */
#define PFX_MV_SLICE_SCALE "mv_max_px"

/* Without an atlas: dir/stem_mv.json, listed in mf. When mf is a slice's
 * manifest (render --slice), only the scale is recorded in it, for `pfx
 * assemble` to write the sidecar of all the slices (pfx_mv_assembled). */
bool pfx_mv_sidecar_run(const char *dir, const char *stem, long first, long last,
                        const pfx_mv_meta *m, pfx_manifest *mf, pfx_diags *d);

/* The settings of m into mf (part of the bake key). */
void pfx_mv_describe(const pfx_mv_meta *m, pfx_manifest *mf);

/* The encoding of assembled slices: the settings of all (the assembled
 * manifest) and the scale each slice recorded, which must be the same in
 * every one of the n slice manifests (named in messages by names). False
 * with the reason in d. */
bool pfx_mv_assembled(const pfx_manifest *all, pfx_manifest *const *slices,
                      const char *const *names, size_t n, pfx_mv_meta *m, pfx_diags *d);

#endif
