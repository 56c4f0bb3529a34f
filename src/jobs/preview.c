/* jobs/preview.h: frames from disk -> output/webp.c or output/mp4.c (the
 * path's extension chooses), one frame in memory at a time. */
#include "jobs/preview.h"

#include <stdio.h>
#include <stdlib.h>

#include "output/mp4.h"
#include "output/png_write.h"
#include "output/webp.h"

/* One of the two writers, behind the three calls both have. */
typedef struct {
    pfx_webp *webp;
    pfx_mp4 *mp4;
} writer;

static bool writer_create(writer *w, int width, int height, double fps, const char *path,
                          pfx_diags *d) {
    if (pfx_mp4_path(path))
        return (w->mp4 = pfx_mp4_create(width, height, fps, path, d)) != NULL;
    return (w->webp = pfx_webp_create(width, height, fps, 100, d)) != NULL;
}

static bool writer_add(writer *w, const uint8_t *rgba, long k, pfx_diags *d) {
    return w->mp4 ? pfx_mp4_add(w->mp4, rgba, d) : pfx_webp_add(w->webp, rgba, k, d);
}

/* Writes (commit) or drops the file; false when anything failed. */
static bool writer_finish(writer *w, const char *path, long frames, bool commit, pfx_diags *d) {
    if (w->mp4)
        return pfx_mp4_finish(w->mp4, commit, d) && commit;
    if (w->webp)
        return pfx_webp_finish(w->webp, path, frames, commit, d) && commit;
    return false;
}

bool pfx_preview_run(const char *dir, const char *stem, long first, long last, double fps,
                     int width, int height, const char *path, pfx_diags *d) {
    writer w = {0};
    bool ok = true;
    for (long f = first; ok && f <= last; f++) {
        char frame[4400];
        int fw, fh;
        snprintf(frame, sizeof frame, "%s/%s_%04ld.png", dir, stem, f);
        uint8_t *rgba = pfx_png_read_sized(frame, width, height, &fw, &fh);
        if (!rgba && fw > 0 && (fw != width || fh != height)) {
            pfx_diag_error(d, PFX_RULE_INVALID_FILE,
                           "'%s' is %dx%d, not the %dx%d of the render; it is not read", frame, fw,
                           fh, width, height);
            ok = false;
            break;
        }
        if (!rgba) {
            pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read the frame '%s' for the preview",
                           frame);
            ok = false;
            break;
        }
        if (f == first)
            ok = writer_create(&w, width, height, fps, path, d);
        ok = ok && writer_add(&w, rgba, f - first, d);
        free(rgba);
    }
    return writer_finish(&w, path, last - first + 1, ok, d);
}
