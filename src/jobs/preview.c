/* jobs/preview.h: frames from disk -> output/webp.c, one frame in memory at
 * a time. */
#include "jobs/preview.h"

#include <stdio.h>
#include <stdlib.h>

#include "output/png_write.h"
#include "output/webp.h"

bool pfx_preview_run(const char *dir, const char *stem, long first, long last, double fps,
                     const char *path, pfx_diags *d) {
    pfx_webp *w = NULL;
    int width = 0, height = 0;
    bool ok = true;
    for (long f = first; ok && f <= last; f++) {
        char frame[4400];
        int fw, fh;
        snprintf(frame, sizeof frame, "%s/%s_%04ld.png", dir, stem, f);
        uint8_t *rgba = pfx_png_read(frame, &fw, &fh);
        if (!rgba) {
            pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read the frame '%s' for the preview",
                           frame);
            ok = false;
            break;
        }
        if (!w) {
            width = fw, height = fh;
            ok = (w = pfx_webp_create(width, height, fps, 100, d)) != NULL;
        } else if (fw != width || fh != height) {
            pfx_diag_error(d, PFX_RULE_INVALID_FILE,
                           "'%s' is %dx%d, not %dx%d like the frames before it", frame, fw, fh,
                           width, height);
            ok = false;
        }
        ok = ok && pfx_webp_add(w, rgba, f - first, d);
        free(rgba);
    }
    return w ? pfx_webp_finish(w, path, last - first + 1, ok, d) && ok : false;
}
