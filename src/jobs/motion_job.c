/* jobs/motion_job.h: the scale pass, the frames, the sheet and the sidecar
 * of --motion-vectors; the drawing is render/motion_vectors.c's and the
 * encoding output/motion_vectors.c's. */
#include "jobs/motion_job.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "jobs/motion_next.h"
#include "output/png_write.h"
#include "render/sprites.h"
#include "sim/sim.h"

/* The scale's histogram: displacements from 2^-16 px (below it a sprite
 * counts as still, and is left out) to 2^24 px (above it in the last bin),
 * PFX_MV_BINS_PER_OCTAVE bins an octave, each holding the summed area of
 * its samples and the largest of them. Fixed size, whatever the effect. */
#define PFX_MV_BINS_PER_OCTAVE 1024
#define PFX_MV_LOW_LOG2 (-16)
#define PFX_MV_OCTAVES 40
#define PFX_MV_BINS (PFX_MV_OCTAVES * PFX_MV_BINS_PER_OCTAVE)

typedef struct mv_histogram {
    double area[PFX_MV_BINS];
    double most[PFX_MV_BINS];
    double total;
} mv_histogram;

static void histogram_add(mv_histogram *h, double v, double area) {
    if (!(v >= ldexp(1.0, PFX_MV_LOW_LOG2)) || !(area > 0) || !isfinite(v))
        return;
    double b = floor((log2(v) - PFX_MV_LOW_LOG2) * PFX_MV_BINS_PER_OCTAVE);
    size_t k = b < 0 ? 0 : b >= PFX_MV_BINS ? PFX_MV_BINS - 1 : (size_t)b;
    h->area[k] += area;
    h->most[k] = v > h->most[k] ? v : h->most[k];
    h->total += area;
}

/* The smallest sample v such that the samples up to v hold at least p of
 * the area, rounded up to the largest sample of its bin (so within a
 * factor 2^(1/1024), 0.07 %, above it); 0 when there is none. */
static double histogram_percentile(const mv_histogram *h, double p) {
    double below = 0;
    for (size_t k = 0; k < PFX_MV_BINS; k++) {
        below += h->area[k];
        if (h->area[k] > 0 && below >= p * h->total)
            return h->most[k];
    }
    return 0;
}

/* The pixels of the frame that sprite sp (of emitter em), centred at pixel
 * c, covers: its size, and its length when stretched along its
 * velocity, in pixels at that depth, each widened to the minimum
 * footprint, as an upright rectangle clipped to the frame. */
static double footprint_px(const pfx_effect *e, const pfx_emitter *em, const pfx_sprite *sp,
                           const double c[2]) {
    const double p[3] = {sp->x, sp->y, sp->z};
    double px_per_m = pfx_camera_pixels_per_metre(&e->camera, e->height, p);
    double sx = fmax(sp->size * px_per_m, PFX_MIN_FOOTPRINT_PX);
    double sy = em->look.align == PFX_ALIGN_VELOCITY
                    ? fmax(sp->length * px_per_m, PFX_MIN_FOOTPRINT_PX)
                    : sx;
    double x = fmin(c[0] + 0.5 * sx, e->width) - fmax(c[0] - 0.5 * sx, 0);
    double y = fmin(c[1] + 0.5 * sy, e->height) - fmax(c[1] - 0.5 * sy, 0);
    return x > 0 && y > 0 ? x * y : 0;
}

/* Adds the n sprites (and their ends) of a frame to h: each sprite's
 * max(|dx|, |dy|) in pixels, weighted by its footprint. A sprite left out
 * of the pass (weight 0) or whose centre or end is behind the camera adds
 * nothing, as it draws nothing in the pass. */
static void add_sprites(const pfx_effect *e, const pfx_sprite *sprites, const float *ends, size_t n,
                        mv_histogram *h) {
    for (size_t i = 0; i < n; i++, ends += 4) {
        const pfx_sprite *sp = &sprites[i];
        const double p[3] = {sp->x, sp->y, sp->z}, q[3] = {ends[0], ends[1], ends[2]};
        double a[2], b[2], wa, wb;
        if (!(ends[3] > 0) || !pfx_camera_project(&e->camera, e->width, e->height, p, a, &wa) ||
            !pfx_camera_project(&e->camera, e->width, e->height, q, b, &wb))
            continue;
        const pfx_emitter *em = &e->emitters[(size_t)sp->material];
        histogram_add(h, fmax(fabs(b[0] - a[0]), fabs(b[1] - a[1])), footprint_px(e, em, sp, a));
    }
}

/* The sprites and their ends are made a chunk at a time, as the renderer
 * makes them: the pass holds no array of a frame's sprites. */
bool pfx_mv_sequence_max(const pfx_effect *e, double *max_px, pfx_diags *d) {
    pfx_sim *sim = pfx_sim_create(e, d), *view = pfx_sim_create(e, d);
    pfx_mv_next *next = pfx_mv_next_create(e, d);
    pfx_sprite *sprites = malloc(PFX_RENDER_CHUNK * sizeof *sprites);
    float *ends = malloc(PFX_RENDER_CHUNK * 4 * sizeof *ends);
    mv_histogram *h = calloc(1, sizeof *h);
    pfx_sprite_feed feed = {NULL, NULL, NULL};
    bool ok = sim && view && next && sprites && ends && h && pfx_sprite_feed_init(&feed, e);
    if (!ok && next) /* else pfx_mv_next_create said so */
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for %zu particles",
                       pfx_sprites_capacity(e));
    const long frames = pfx_effect_frame_count(e);
    for (long f = 0; ok && f < frames; f++) {
        const pfx_sim *state = pfx_sim_frame(sim, view, f);
        if (sim->failed || view->failed)
            break;
        const pfx_sprite_source src = pfx_sprite_feed_source(&feed, state);
        if (!(ok = pfx_mv_next_frame(next, &feed, f)))
            break;
        const pfx_sprite_ends at = pfx_mv_next_ends(next);
        for (size_t first = 0; first < src.count; first += PFX_RENDER_CHUNK) {
            size_t n = src.count - first < PFX_RENDER_CHUNK ? src.count - first : PFX_RENDER_CHUNK;
            src.make(src.ctx, first, n, NULL, sprites);
            at.make(at.ctx, first, n, ends);
            add_sprites(e, sprites, ends, n, h);
        }
    }
    ok = ok && !sim->failed && !view->failed;
    double scale = h ? histogram_percentile(h, PFX_MV_PERCENTILE / 100.0) : 0;
    pfx_sim_destroy(sim);
    pfx_sim_destroy(view);
    pfx_mv_next_destroy(next);
    pfx_sprite_feed_free(&feed);
    free(sprites);
    free(ends);
    free(h);
    *max_px = scale > 0 && isfinite(scale) ? scale : 1.0;
    return ok;
}

bool pfx_mv_frame_init(pfx_mv_frame *b, const pfx_effect *e, pfx_diags *d) {
    const size_t n = (size_t)e->width * (size_t)e->height;
    b->mv = malloc(n * 3 * sizeof *b->mv);
    b->samples = malloc(n * 4 * sizeof *b->samples);
    if (!b->mv || !b->samples) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for motion vectors at %dx%d",
                       e->width, e->height);
        return false;
    }
    return (b->next = pfx_mv_next_create(e, d)) != NULL;
}

void pfx_mv_frame_free(pfx_mv_frame *b) {
    free(b->mv);
    free(b->samples);
    pfx_mv_next_destroy(b->next);
    b->mv = NULL;
    b->samples = NULL;
    b->next = NULL;
}

bool pfx_mv_frame_write(pfx_mv_frame *b, pfx_renderer *r, const pfx_effect *e,
                        const pfx_render_settings *s, const pfx_sprite_source *src,
                        const pfx_sprite_feed *feed, long f, const pfx_mv_meta *m, const char *path,
                        pfx_diags *d) {
    if (!pfx_mv_next_frame(b->next, feed, f))
        return false; /* the simulation reported into d */
    const pfx_sprite_ends ends = pfx_mv_next_ends(b->next);
    if (!pfx_renderer_motion_vectors(r, &e->camera, s, src, &ends, b->mv, d))
        return false;
    pfx_mv_encode(b->mv, e->width, e->height, m, b->samples);
    return pfx_png_write16(path, b->samples, e->width, e->height, false, d);
}

bool pfx_mv_frame_path(const char *dir, const char *stem, long frame, char *out, size_t size) {
    int n = snprintf(out, size, "%s/%s_mv_%04ld.png", dir, stem, frame);
    return n > 0 && (size_t)n < size;
}

bool pfx_mv_add_outputs(pfx_manifest *mf, const char *dir, const char *stem, long first, long last,
                        pfx_diags *d) {
    for (long f = first; f <= last; f++) {
        char name[320];
        snprintf(name, sizeof name, "%s_mv_%04ld.png", stem, f);
        if (!pfx_manifest_add_output(mf, dir, name, d))
            return false;
    }
    return true;
}

bool pfx_mv_atlas_write(pfx_atomic_group *g, const char *dir, const char *stem, long first,
                        long last, const pfx_atlas_layout *l, char *image, size_t image_size,
                        pfx_diags *d) {
    const long n = last - first + 1;
    uint16_t **frames = calloc((size_t)n, sizeof *frames);
    uint16_t *sheet = NULL;
    bool ok = frames != NULL;
    if (!ok)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
    char path[4400];
    for (long k = 0; ok && k < n; k++) {
        int w, h;
        pfx_mv_frame_path(dir, stem, first + k, path, sizeof path);
        frames[k] = pfx_png_read16(path, &w, &h);
        if (!frames[k]) {
            pfx_diag_error(d, PFX_RULE_READ_FAILED,
                           "cannot read the motion vectors '%s' for the atlas", path);
            ok = false;
        } else if (w != l->frame_w || h != l->frame_h) {
            pfx_diag_error(d, PFX_RULE_INVALID_FILE,
                           "'%s' is %dx%d, not %dx%d like the colour frames", path, w, h,
                           l->frame_w, l->frame_h);
            ok = false;
        }
    }
    if (ok && !(sheet = pfx_mv_atlas_compose(l, frames))) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for an atlas of %dx%d", l->width,
                       l->height);
        ok = false;
    }
    snprintf(image, image_size, "%s_mv_atlas.png", stem);
    snprintf(path, sizeof path, "%s/%s", dir, image);
    ok = ok && pfx_png_write16_in(g, path, sheet, l->width, l->height, d);
    for (long k = 0; frames && k < n; k++)
        free(frames[k]);
    free(frames);
    free(sheet);
    return ok;
}

bool pfx_mv_sidecar_run(const char *dir, const char *stem, long first, long last,
                        const pfx_mv_meta *m, pfx_manifest *mf, pfx_diags *d) {
    /* A slice's sidecar would describe its part under the name of the
     * whole, and slices may share a directory: the scale goes into its
     * manifest instead, and assemble writes the sidecar of the whole. */
    if (mf && pfx_manifest_set_slice_number(mf, PFX_MV_SLICE_SCALE, m->max_px))
        return true;
    char path[4400], pattern[300], name[300];
    snprintf(pattern, sizeof pattern, "%s_mv_%%04d.png", stem);
    snprintf(name, sizeof name, "%s_mv.json", stem);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return pfx_mv_write_sidecar(path, m, pattern, first, last, d) &&
           (!mf || pfx_manifest_add_output(mf, dir, name, d));
}

void pfx_mv_describe(const pfx_mv_meta *m, pfx_manifest *mf) {
    pfx_manifest_set_number(mf, "motion_vectors", 1);
    pfx_manifest_set_number(mf, "mv_max", m->max_given ? m->max_px : 0);
    pfx_manifest_set_number(mf, "mv_flip_y", m->flip_y);
}

bool pfx_mv_assembled(const pfx_manifest *all, pfx_manifest *const *slices,
                      const char *const *names, size_t n, pfx_mv_meta *m, pfx_diags *d) {
    const double given = pfx_manifest_get_number(all, "mv_max", 0);
    *m = (pfx_mv_meta){.max_given = given > 0,
                       .flip_y = pfx_manifest_get_number(all, "mv_flip_y", 0) != 0,
                       .fps = pfx_manifest_get_number(all, "fps", 30)};
    for (size_t i = 0; i < n; i++) {
        const double s = pfx_manifest_slice_number(slices[i], PFX_MV_SLICE_SCALE, 0);
        if (!(s > 0)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "'%s' does not record the scale of its motion vectors", names[i]);
            return false;
        }
        /* Every slice finds the scale over the whole effect (or is given
         * it), so the slices of one render agree to the bit. */
        if (i > 0 && s != m->max_px) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "'%s' encodes its motion vectors with a scale of %.17g px, '%s' with "
                           "%.17g px",
                           names[i], s, names[0], m->max_px);
            return false;
        }
        m->max_px = s;
    }
    return true;
}
