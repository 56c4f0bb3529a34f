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
}

bool pfx_atlas_job_run(const char *dir, const char *stem, long first, long last, double fps,
                       bool loop, pfx_atlas_layout *l, pfx_manifest *m, pfx_diags *d) {
    long n = last - first + 1;
    uint8_t **frames = calloc((size_t)n, sizeof *frames);
    char **names = calloc((size_t)n, sizeof *names);
    uint8_t *sheet = NULL;
    bool ok = frames && names;
    if (!ok)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
    char path[4400], png[4400], json[4400];
    for (long k = 0; ok && k < n; k++) {
        int w, h;
        names[k] = malloc(300);
        if (!names[k]) {
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
            ok = false;
            break;
        }
        snprintf(names[k], 300, "%s_%04ld.png", stem, first + k);
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        frames[k] = pfx_png_read(path, &w, &h);
        if (!frames[k]) {
            pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read the frame '%s' for the atlas",
                           path);
            ok = false;
        } else if (k == 0) {
            l->frame_w = w;
            l->frame_h = h;
            if ((long long)w * h * 4 * n > PFX_ATLAS_MAX_BYTES) {
                pfx_diag_error(d, PFX_RULE_MEMORY_BOUND,
                               "an atlas of %ld frames of %dx%d would hold %lld MiB of frames, "
                               "over the %lld MiB bound",
                               n, w, h, (long long)w * h * 4 * n >> 20, PFX_ATLAS_MAX_BYTES >> 20);
                ok = false;
            }
        } else if (w != l->frame_w || h != l->frame_h) {
            pfx_diag_error(d, PFX_RULE_INVALID_FILE,
                           "'%s' is %dx%d, not %dx%d like the frames before it", path, w, h,
                           l->frame_w, l->frame_h);
            ok = false;
        }
    }
    l->frames = (int)n;
    l->crop_w = 0;
    if (ok && l->crop)
        pfx_atlas_find_crop(l, frames, (int)n);
    ok = ok && pfx_atlas_layout_resolve(l, d);
    if (ok && !(sheet = pfx_atlas_compose(l, frames))) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for an atlas of %dx%d", l->width,
                       l->height);
        ok = false;
    }
    char image[300];
    snprintf(image, sizeof image, "%s_atlas.png", stem);
    snprintf(png, sizeof png, "%s/%s", dir, image);
    snprintf(json, sizeof json, "%s/%s_atlas.json", dir, stem);
    ok = ok && pfx_png_write(png, sheet, l->width, l->height, d);
    /* --motion-vectors: their sheet in the same layout, before the JSON
     * that names it. */
    char mv_image[300] = "", mv_png[4400];
    snprintf(mv_png, sizeof mv_png, "%s/%s_mv_atlas.png", dir, stem);
    if (ok && l->motion &&
        !pfx_mv_atlas_write(dir, stem, first, last, l, mv_image, sizeof mv_image, d)) {
        remove(png);
        ok = false;
    }
    l->motion_image = mv_image;
    if (ok && !pfx_atlas_write_json(json, l, image, (const char *const *)names, fps, loop, d)) {
        remove(png); /* both or neither */
        if (l->motion)
            remove(mv_png);
        ok = false;
    }
    l->motion_image = NULL;
    if (ok && m) {
        char name[320];
        snprintf(name, sizeof name, "%s_atlas.json", stem);
        ok = pfx_manifest_add_output(m, dir, image, d) &&
             pfx_manifest_add_output(m, dir, name, d) &&
             (!l->motion || pfx_manifest_add_output(m, dir, mv_image, d));
    }
    for (long k = 0; frames && k < n; k++)
        free(frames[k]);
    for (long k = 0; names && k < n; k++)
        free(names[k]);
    free(frames);
    free(names);
    free(sheet);
    return ok;
}
