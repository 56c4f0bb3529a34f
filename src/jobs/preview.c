/* jobs/preview.h: frames from disk -> output/webp.c or output/mp4.c (the
 * path's extension chooses), one frame in memory at a time. Premultiplied
 * frames are made straight first, since WebP stores straight alpha and the
 * MP4 writer composites straight alpha over black. */
#include "jobs/preview.h"

#include <stdint.h>
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

/* --preview-quality Q to x264's CRF: linear, Q 100 is CRF 0 (the best)
 * and Q 0 CRF 51 (the worst); no Q keeps the default CRF 18 (Q 65 is
 * CRF 18 too, rounded). */
static int crf_of(int quality) { return quality < 0 ? 18 : (int)((100 - quality) * 51 + 50) / 100; }

static bool writer_create(writer *w, int width, int height, double fps, const pfx_preview *p,
                          pfx_diags *d) {
    if (pfx_mp4_path(p->path))
        return (w->mp4 = pfx_mp4_create(width, height, fps, crf_of(p->quality), p->path, d)) !=
               NULL;
    return (w->webp = pfx_webp_create(width, height, fps, p->quality, d)) != NULL;
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

bool pfx_preview_check(const pfx_preview *p, int width, int height, pfx_diags *d) {
    if (pfx_mp4_path(p->path) || (width <= PFX_WEBP_MAX_SIDE && height <= PFX_WEBP_MAX_SIDE))
        return true; /* x264 takes every size pfx renders (16384 a side); odd ones are padded */
    pfx_diag_error(d, PFX_RULE_TOO_LARGE,
                   "cannot write '%s': WebP frames are at most %d pixels a side, and these are "
                   "%dx%d; use a smaller --size or --preview OUT.mp4",
                   p->path, PFX_WEBP_MAX_SIDE, width, height);
    return false;
}

/* Premultiplied to straight RGBA in place. A pixel of added light (colour
 * brighter than its alpha, as additive sprites make) cannot be straight
 * with its own alpha, so its alpha is raised to its brightest channel:
 * over black it then shows exactly the light the frame holds, and over
 * anything else it hides a little more of what is behind. */
static void to_straight(uint8_t *rgba, size_t pixels) {
    for (size_t i = 0; i < pixels; i++, rgba += 4) {
        int a = rgba[3];
        for (int c = 0; c < 3; c++)
            a = rgba[c] > a ? rgba[c] : a;
        for (int c = 0; c < 3 && a; c++)
            rgba[c] = (uint8_t)((rgba[c] * 255 + a / 2) / a);
        rgba[3] = (uint8_t)a;
    }
}

bool pfx_preview_run(const char *dir, const char *stem, long first, long last, long step,
                     double fps, int width, int height, const pfx_preview *p, pfx_diags *d) {
    /* Every step-th frame plays at fps / step: the preview lasts as long as
     * the effect. */
    fps /= (double)step;
    const char *path = p->path;
    writer w = {0};
    bool ok = true;
    for (long f = first; ok && f <= last; f += step) {
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
            ok = pfx_preview_check(p, width, height, d) &&
                 writer_create(&w, width, height, fps, p, d);
        if (ok && p->premultiplied)
            to_straight(rgba, (size_t)fw * (size_t)fh);
        ok = ok && writer_add(&w, rgba, (f - first) / step, d);
        free(rgba);
    }
    return writer_finish(&w, path, (last - first) / step + 1, ok, d);
}
