/* jobs/atlas_job.h: frames from disk -> output/atlas.c -> PNG and JSON. */
#include "jobs/atlas_job.h"

#include <stdio.h>
#include <stdlib.h>

#include "jobs/motion_job.h"
#include "output/png_write.h"

void pfx_atlas_job_describe(const pfx_atlas_layout *l, pfx_manifest *m) {
    char grid[64] = "auto";
    if (l->columns || l->rows)
        snprintf(grid, sizeof grid, "%dx%d", l->columns, l->rows);
    pfx_manifest_set_string(m, "atlas", grid);
    pfx_manifest_set_number(m, "atlas_padding", l->padding);
    pfx_manifest_set_number(m, "atlas_extrude", l->extrude);
    pfx_manifest_set_number(m, "atlas_crop", l->crop);
    if (l->pot) /* the defaults keep the keys they had */
        pfx_manifest_set_number(m, "atlas_pot", 1);
    if (l->json_array)
        pfx_manifest_set_string(m, "atlas_json", "array");
}

/* One atlas job: the frames STEM_FFFF.png for FFFF = first, first + step,
 * ... up to last, read from DIR, with their file names (for the JSON). */
typedef struct atlas_job {
    const char *dir, *stem;
    long first, last, step, n;
    uint8_t **frames;
    char **names;
    pfx_atlas_layout *l;
    pfx_diags *d;
} atlas_job;

/* Whether n frames of w x h stay within PFX_ATLAS_MAX_BYTES; says so in d
 * when not. */
static bool frames_fit(const atlas_job *j, int w, int h) {
    if ((long long)w * h * 4 * j->n <= PFX_ATLAS_MAX_BYTES)
        return true;
    pfx_diag_error(j->d, PFX_RULE_MEMORY_BOUND,
                   "an atlas of %ld frames of %dx%d would hold %lld MiB of frames, over the %lld "
                   "MiB bound",
                   j->n, w, h, (long long)w * h * 4 * j->n >> 20, PFX_ATLAS_MAX_BYTES >> 20);
    return false;
}

/* Reads every frame, all of one size (l's when given, else the first's,
 * which sets it); stops at the first that cannot be read or does not
 * match, or when the frames together would pass the memory bound (checked
 * before any frame is read when the size is given, else at the first). */
static bool read_frames(atlas_job *j) {
    pfx_atlas_layout *l = j->l;
    char path[4400];
    /* A size given is checked before any frame is read. */
    if (l->frame_w > 0 && !frames_fit(j, l->frame_w, l->frame_h))
        return false;
    for (long k = 0; k < j->n; k++) {
        int w, h;
        j->names[k] = malloc(300);
        if (!j->names[k]) {
            pfx_diag_error(j->d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
            return false;
        }
        snprintf(j->names[k], 300, "%s_%04ld.png", j->stem, j->first + k * j->step);
        snprintf(path, sizeof path, "%s/%s", j->dir, j->names[k]);
        /* The size known (given, or the first frame's) is checked on the
         * header, before a frame that claims to be huge is decoded. */
        j->frames[k] = pfx_png_read_sized(path, l->frame_w, l->frame_h, &w, &h);
        if (!j->frames[k] && w > 0 && l->frame_w > 0 && (w != l->frame_w || h != l->frame_h)) {
            pfx_diag_error(j->d, PFX_RULE_INVALID_FILE,
                           "'%s' is %dx%d, not %dx%d like the render's frames; it is not read",
                           path, w, h, l->frame_w, l->frame_h);
            return false;
        }
        if (!j->frames[k]) {
            pfx_diag_error(j->d, PFX_RULE_READ_FAILED, "cannot read the frame '%s' for the atlas",
                           path);
            return false;
        } else if (k == 0) {
            l->frame_w = w;
            l->frame_h = h;
            if (!frames_fit(j, w, h))
                return false;
        }
    }
    return true;
}

/* Writes DIR/STEM_atlas.png, the motion-vector sheet when asked and the
 * JSON that names them, then adds them to the manifest m (when given).
 * They appear together (one atomic group, renamed at the end: the JSON
 * last, so it never names a missing image): a failure in any leaves the
 * previous set as it was, and none of the new. */
static bool write_outputs(const atlas_job *j, const uint8_t *sheet, double fps, bool loop,
                          pfx_manifest *m) {
    pfx_atlas_layout *l = j->l;
    const char *dir = j->dir, *stem = j->stem;
    char png[4400], json[4400];
    char image[300], mv_image[300] = "";
    snprintf(image, sizeof image, "%s_atlas.png", stem);
    snprintf(png, sizeof png, "%s/%s", dir, image);
    snprintf(json, sizeof json, "%s/%s_atlas.json", dir, stem);
    pfx_atomic_group *g = pfx_atomic_group_create(j->d);
    bool ok = g && pfx_png_write_in(g, png, sheet, l->width, l->height, j->d);
    /* --motion-vectors: their sheet in the same layout. */
    ok = ok && (!l->motion || pfx_mv_atlas_write(g, dir, stem, j->first, j->last, l, mv_image,
                                                 sizeof mv_image, j->d));
    l->motion_image = mv_image;
    ok = ok &&
         pfx_atlas_write_json(g, json, l, image, (const char *const *)j->names, fps, loop, j->d);
    l->motion_image = NULL;
    if (ok)
        ok = pfx_atomic_group_commit(g, j->d);
    else
        pfx_atomic_group_abort(g);
    if (ok && m) {
        char name[320];
        snprintf(name, sizeof name, "%s_atlas.json", stem);
        ok = pfx_manifest_add_output(m, dir, image, j->d) &&
             pfx_manifest_add_output(m, dir, name, j->d) &&
             (!l->motion || pfx_manifest_add_output(m, dir, mv_image, j->d));
    }
    return ok;
}

bool pfx_atlas_job_run(const char *dir, const char *stem, long first, long last, long step,
                       double fps, bool loop, pfx_atlas_layout *l, pfx_manifest *m, pfx_diags *d) {
    long n = (last - first) / step + 1;
    atlas_job j = {.dir = dir,
                   .stem = stem,
                   .first = first,
                   .last = last,
                   .step = step,
                   .n = n,
                   .l = l,
                   .d = d};
    /* Every step-th frame of the effect plays at fps / step, so that the
     * sheet lasts as long as the effect. */
    fps /= (double)step;
    j.frames = calloc((size_t)n, sizeof *j.frames);
    j.names = calloc((size_t)n, sizeof *j.names);
    uint8_t *sheet = NULL;
    bool ok = j.frames && j.names;
    if (!ok)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
    ok = ok && read_frames(&j);
    l->frames = (int)n;
    l->crop_w = 0;
    if (ok && l->crop)
        pfx_atlas_find_crop(l, j.frames, (int)n);
    ok = ok && pfx_atlas_layout_resolve(l, d);
    if (ok && !(sheet = pfx_atlas_compose(l, j.frames))) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for an atlas of %dx%d", l->width,
                       l->height);
        ok = false;
    }
    ok = ok && write_outputs(&j, sheet, fps, loop, m);
    for (long k = 0; j.frames && k < n; k++)
        free(j.frames[k]);
    for (long k = 0; j.names && k < n; k++)
        free(j.names[k]);
    free(j.frames);
    free(j.names);
    free(sheet);
    return ok;
}
