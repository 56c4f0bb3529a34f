/* output/webp.h over libwebpmux. Lossless frames keep every colour exactly
 * (config.exact: even under alpha 0), so a preview can be checked pixel by
 * pixel against the PNGs it was made from. Lossy frames let the encoder
 * change what alpha 0 hides, which is most of what they save there. */
#include "output/webp.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <webp/encode.h>
#include <webp/mux.h>

#include "output/atomic_file.h"

struct pfx_webp {
    WebPAnimEncoder *enc;
    WebPConfig config;
    int width, height;
    double fps;
};

/* Frame k starts at round(1000 k / fps) ms. */
static int timestamp_ms(const pfx_webp *w, long k) { return (int)lround(1000.0 * k / w->fps); }

pfx_webp *pfx_webp_create(int width, int height, double fps, int quality, pfx_diags *d) {
    pfx_webp *w = calloc(1, sizeof *w);
    WebPAnimEncoderOptions options;
    if (!w || !WebPAnimEncoderOptionsInit(&options) || !WebPConfigInit(&w->config)) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot start the WebP encoder");
        free(w);
        return NULL;
    }
    options.anim_params.loop_count = 0; /* for ever */
    options.allow_mixed = 0;
    w->config.lossless = quality < 0;
    w->config.exact = quality < 0;
    w->config.quality = quality < 0 ? 75 : (float)quality; /* lossless: effort */
    w->width = width;
    w->height = height;
    w->fps = fps;
    w->enc = WebPValidateConfig(&w->config) ? WebPAnimEncoderNew(width, height, &options) : NULL;
    if (!w->enc) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot start the WebP encoder for %dx%d frames",
                       width, height);
        free(w);
        return NULL;
    }
    return w;
}

bool pfx_webp_add(pfx_webp *w, const uint8_t *rgba, long k, pfx_diags *d) {
    WebPPicture pic;
    if (!WebPPictureInit(&pic)) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot encode a WebP frame");
        return false;
    }
    pic.use_argb = 1;
    pic.width = w->width;
    pic.height = w->height;
    bool ok = WebPPictureImportRGBA(&pic, rgba, w->width * 4) &&
              WebPAnimEncoderAdd(w->enc, &pic, timestamp_ms(w, k), &w->config);
    if (!ok)
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot encode WebP frame %ld: %s", k,
                       WebPAnimEncoderGetError(w->enc));
    WebPPictureFree(&pic);
    return ok;
}

bool pfx_webp_finish(pfx_webp *w, const char *path, long frames, bool commit, pfx_diags *d) {
    bool ok = commit;
    WebPData data;
    WebPDataInit(&data);
    if (ok && (!WebPAnimEncoderAdd(w->enc, NULL, timestamp_ms(w, frames), NULL) ||
               !WebPAnimEncoderAssemble(w->enc, &data))) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot assemble '%s': %s", path,
                       WebPAnimEncoderGetError(w->enc));
        ok = false;
    }
    if (ok) {
        pfx_atomic_file *a = pfx_atomic_open(path, d);
        ok = a != NULL;
        if (a) {
            if (fwrite(data.bytes, 1, data.size, pfx_atomic_stream(a)) != data.size)
                pfx_atomic_failed(a, errno);
            ok = pfx_atomic_commit(a, true, d);
        }
    }
    WebPDataClear(&data);
    WebPAnimEncoderDelete(w->enc);
    free(w);
    return ok || !commit;
}
