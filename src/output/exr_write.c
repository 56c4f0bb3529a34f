/* EXR frames through OpenEXR's Core C library. The file is built in memory
 * (Core seeks back to write the chunk offset table, which a stream cannot
 * follow) and then written through the atomic writer in one piece. Pixels
 * become half floats with Imath's float-to-half (round to nearest even,
 * as every OpenEXR reader expects); nothing in the file depends on the
 * time or the thread, so the same frame gives the same bytes. */
#include "output/exr_write.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Imath's C conversion without its lookup table, which lives in libImath:
 * only the Core library is linked. */
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>
#include <openexr.h>

#include "output/atomic_file.h"

/* Compression, measured on frame 60 of effects/fire.yaml at 1920x1080
 * (OpenEXR 3.1.5, Debian 12 x86-64; sizes exact, times too noisy on the
 * shared 2-core machine to rank, all within 1.5x of each other):
 *   ZIP, 16 lines a chunk, level 4   720 KB   <- chosen
 *   ZIPS, 1 line a chunk             861 KB
 *   PIZ, 32 lines (wavelet)          887 KB
 *   RLE                             1327 KB
 *   none                           16.6 MB
 * All are lossless. ZIP is the smallest here: a particle frame is mostly
 * one flat background, which deflate takes in long runs, while PIZ's
 * wavelet pays on grainy photographic plates. It is also the kind every
 * compositor (Nuke, Houdini, Resolve) reads, and the usual choice for
 * multi-line reads of rendered elements. */
#define PFX_EXR_COMPRESSION EXR_COMPRESSION_ZIP
/* zlib's level (OpenEXR's own default), fixed so the bytes do not follow a
 * library default that may change. */
#define PFX_EXR_ZIP_LEVEL 4

/* The file as Core writes it: bytes at offsets, grown as needed. */
typedef struct sink {
    uint8_t *data;
    size_t size, cap;
    bool out_of_memory;
    char message[256]; /* Core's first error, or empty */
} sink;

static int64_t sink_write(exr_const_context_t ctxt, void *user, const void *buffer, uint64_t sz,
                          uint64_t offset, exr_stream_error_func_ptr_t error_cb) {
    (void)ctxt;
    (void)error_cb;
    sink *s = user;
    if (offset > SIZE_MAX / 2 || sz > SIZE_MAX / 2 - offset)
        return -1;
    size_t end = (size_t)(offset + sz);
    if (end > s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 1 << 16;
        while (cap < end)
            cap *= 2;
        uint8_t *grown = realloc(s->data, cap);
        if (!grown) {
            s->out_of_memory = true;
            return -1;
        }
        s->data = grown;
        s->cap = cap;
    }
    if (offset > s->size) /* a gap Core fills later: zero until then */
        memset(s->data + s->size, 0, (size_t)offset - s->size);
    memcpy(s->data + offset, buffer, (size_t)sz);
    s->size = end > s->size ? end : s->size;
    return (int64_t)sz;
}

/* Core reports through a callback; keep the first message, print nothing. */
static void on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg) {
    void *user = NULL;
    if (exr_get_user_data(ctxt, &user) == EXR_ERR_SUCCESS && user) {
        sink *s = user;
        if (!s->message[0])
            snprintf(s->message, sizeof s->message, "%s",
                     msg ? msg : exr_get_default_error_message(code));
    }
}

/* Row y (from the top) of img as half RGBA: colour x gain, alpha as is. */
static void half_row(const pfx_float_image *img, int y, float gain, uint16_t *out) {
    uint16_t bg[4];
    for (int c = 0; c < 4; c++)
        bg[c] = imath_float_to_half(c < 3 ? img->clear[c] * gain : img->clear[c]);
    const int gl_y = img->height - 1 - y;
    const bool in = img->x1 > img->x0 && gl_y >= img->y0 && gl_y < img->y1;
    const int from = in ? img->x0 : img->width, to = in ? img->x1 : img->width;
    for (int x = 0; x < from; x++)
        memcpy(out + 4 * x, bg, sizeof bg);
    if (in) {
        const float *src = img->pixels + (size_t)(gl_y - img->y0) * (size_t)(img->x1 - img->x0) * 4;
        for (int x = from; x < to; x++, src += 4) {
            uint32_t bits[4]; /* most of a particle frame is untouched: +0 */
            memcpy(bits, src, sizeof bits);
            if ((bits[0] | bits[1] | bits[2] | bits[3]) == 0) {
                memset(out + 4 * x, 0, 4 * sizeof *out);
                continue;
            }
            for (int c = 0; c < 4; c++)
                out[4 * x + c] = imath_float_to_half(c < 3 ? src[c] * gain : src[c]);
        }
    }
    for (int x = to; x < img->width; x++)
        memcpy(out + 4 * x, bg, sizeof bg);
}

/* fps as the rational framesPerSecond: n/1 when whole; the NTSC rates
 * (23.976, 29.97, 59.94 ...: N x 1000/1001 within 0.0005) as N000/1001,
 * the way editors and compositors write them; otherwise to a thousandth,
 * in lowest terms (12.5: 25/2). */
static exr_attr_rational_t fps_rational(double fps) {
    long whole = lround(fps), ntsc = lround(fps * 1.001);
    if (fabs(fps - (double)whole) < 1e-9)
        return (exr_attr_rational_t){(int32_t)whole, 1};
    if (fabs(fps - (double)ntsc * 1000.0 / 1001.0) < 5e-4)
        return (exr_attr_rational_t){(int32_t)(ntsc * 1000), 1001};
    long num = lround(fps * 1000.0), den = 1000, a = num, b = den;
    while (b) {
        long t = a % b;
        a = b;
        b = t;
    }
    return (exr_attr_rational_t){(int32_t)(num / a), (uint32_t)(den / a)};
}

/* The header: one scanline part, R G B A half, in Rec. 709 primaries with
 * a D65 white (pfx renders linear sRGB/Rec. 709 colour), at fps when
 * fps > 0. */
static exr_result_t write_header(exr_context_t ctx, const pfx_float_image *img, double fps,
                                 int *part) {
    static const exr_attr_chromaticities_t rec709 = {0.64f, 0.33f, 0.30f,   0.60f,
                                                     0.15f, 0.06f, 0.3127f, 0.3290f};
    exr_result_t rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, *part, img->width, img->height,
                                                 PFX_EXR_COMPRESSION);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_set_zip_compression_level(ctx, *part, PFX_EXR_ZIP_LEVEL);
    static const char *const names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4 && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctx, *part, names[c], EXR_PIXEL_HALF, EXR_PERCEPTUALLY_LOGARITHMIC, 1,
                             1);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_attr_set_chromaticities(ctx, *part, "chromaticities", &rec709);
    if (rv == EXR_ERR_SUCCESS && fps > 0) {
        const exr_attr_rational_t rate = fps_rational(fps);
        rv = exr_attr_set_rational(ctx, *part, "framesPerSecond", &rate);
    }
    return rv == EXR_ERR_SUCCESS ? exr_write_header(ctx) : rv;
}

/* Every chunk of scanlines, top to bottom, from a half RGBA buffer of one
 * chunk's rows. Core orders channels by name (A, B, G, R): each points at
 * its own offset in the interleaved pixel. */
static exr_result_t write_chunks(exr_context_t ctx, int part, const pfx_float_image *img,
                                 float gain, uint16_t *halves, int lines) {
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool started = false;
    exr_result_t rv = EXR_ERR_SUCCESS;
    static const char order[] = "RGBA"; /* the channels' places in a pixel */
    const int32_t line_stride = img->width * 4 * (int32_t)sizeof *halves;
    for (int y0 = 0; y0 < img->height && rv == EXR_ERR_SUCCESS; y0 += lines) {
        exr_chunk_info_t chunk;
        rv = exr_write_scanline_chunk_info(ctx, part, y0, &chunk);
        if (rv != EXR_ERR_SUCCESS)
            break;
        for (int y = 0; y < chunk.height; y++)
            half_row(img, y0 + y, gain, halves + (size_t)y * (size_t)img->width * 4);
        rv = started ? exr_encoding_update(ctx, part, &chunk, &enc)
                     : exr_encoding_initialize(ctx, part, &chunk, &enc);
        if (rv != EXR_ERR_SUCCESS)
            break;
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            const char *at = strchr(order, ch->channel_name[0]);
            ch->user_data_type = EXR_PIXEL_HALF;
            ch->user_bytes_per_element = 2;
            ch->user_pixel_stride = 4 * (int32_t)sizeof *halves;
            ch->user_line_stride = line_stride;
            ch->encode_from_ptr = (const uint8_t *)(halves + (at - order));
        }
        if (!started)
            rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        started = true;
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(ctx, part, &enc);
    }
    if (started)
        exr_encoding_destroy(ctx, &enc);
    return rv;
}

/* The whole file into s; false with s->message set. */
static bool encode(const char *path, const pfx_float_image *img, float gain, double fps, sink *s) {
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = s;
    init.write_fn = sink_write;
    init.error_handler_fn = on_error;
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    int part = 0, lines = 0;
    if (rv == EXR_ERR_SUCCESS)
        rv = write_header(ctx, img, fps, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    uint16_t *halves = NULL;
    if (rv == EXR_ERR_SUCCESS &&
        !(halves = malloc((size_t)lines * (size_t)img->width * 4 * sizeof *halves)))
        rv = EXR_ERR_OUT_OF_MEMORY;
    if (rv == EXR_ERR_SUCCESS)
        rv = write_chunks(ctx, part, img, gain, halves, lines);
    free(halves);
    exr_result_t done = ctx ? exr_finish(&ctx) : EXR_ERR_SUCCESS;
    if (rv == EXR_ERR_SUCCESS)
        rv = done;
    if (rv != EXR_ERR_SUCCESS && !s->message[0])
        snprintf(s->message, sizeof s->message, "%s",
                 s->out_of_memory ? "out of memory" : exr_get_default_error_message(rv));
    return rv == EXR_ERR_SUCCESS;
}

bool pfx_exr_write(const char *path, const pfx_float_image *img, double exposure, double fps,
                   bool sync_dir, pfx_diags *d) {
    if (path == NULL || path[0] == '\0' || path[strlen(path) - 1] == '/') {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write '%s': not a file name",
                       path ? path : "");
        return false;
    }
    if (img == NULL || img->width <= 0 || img->height <= 0 || img->width > 1000000 ||
        img->height > 1000000) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot write '%s': invalid image size", path);
        return false;
    }
    /* Room for the file at its largest (Core stores a chunk raw when
     * compression would grow it): 8 bytes a pixel, a few per chunk, the
     * header. Pages never written cost no memory. */
    sink s = {0};
    s.cap = (size_t)img->width * (size_t)img->height * 8 + (size_t)img->height * 16 + (1 << 16);
    if (!(s.data = malloc(s.cap))) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "cannot encode '%s': out of memory", path);
        return false;
    }
    if (!encode(path, img, (float)exp2(exposure), fps, &s)) {
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot encode '%s': %s", path, s.message);
        free(s.data);
        return false;
    }
    pfx_atomic_file *a = pfx_atomic_open(path, d);
    if (a == NULL) {
        free(s.data);
        return false;
    }
    if (fwrite(s.data, 1, s.size, pfx_atomic_stream(a)) != s.size)
        pfx_atomic_failed(a, errno != 0 ? errno : EIO);
    free(s.data);
    return pfx_atomic_commit(a, sync_dir, d);
}
