/* PNG files through libpng: atomic 8-bit RGBA writes (temporary file in the
 * same directory, renamed into place) whose IDAT libdeflate compresses,
 * and a reader for tests; the encoder threads of output/frame_queue.c call
 * the writer. It does not colour-manage: pixels are written and read as
 * they are. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "output/png_write.h"

#include "base/diag.h"
#include "base/regular_file.h"
#include "output/atomic_file.h"

#include <errno.h>
#include <libdeflate.h>
#include <png.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Compression: libpng writes the signature, IHDR and IEND; the IDAT
 * stream is the Up-filtered rows deflated in one call by libdeflate, at
 * PFX_PNG_DEFLATE_LEVEL. Thread CPU time per frame, median of 15
 * interleaved rounds (libpng 1.6.39, zlib 1.2.13, libdeflate 1.14, Debian
 * 12 x86-64, 2 busy cores), size against zlib's:
 *                            fire 512x512      smoke 512x512     fire 1920x1080
 *   zlib Z_RLE, filter up    5.8 ms  60 KB     7.8 ms  79 KB     34 ms  227 KB  (before)
 *   libdeflate 1, up         4.8 ms  +8 %      5.9 ms +11 %      34 ms  +12 %
 *   libdeflate 2, up         4.7 ms  +4 %      6.3 ms  +8 %      28 ms   +7 %
 *   libdeflate 3, up         4.9 ms  +2 %      6.7 ms  +4 %      29 ms   +4 %  <- chosen
 *   libdeflate 4, up         5.2 ms  +2 %      8.9 ms  -1 %      33 ms   +2 %
 *   libdeflate 6, up         9.4 ms  -2 %     17.0 ms  -1 %      48 ms   +1 %
 *   libdeflate 2, sub        4.8 ms +23 %      5.6 ms +15 %      30 ms  +21 %
 * Level 3 saves 14-15 % of the encoder's time for files at most 5 % larger;
 * level 2 saves a little more but comes near the 10 % the files may grow.
 * Earlier, with zlib: libpng's default (level 6, every filter chosen per
 * row) was 5.5 x slower than Z_RLE + up for 17 % smaller files. Up is the
 * filter: the transparent background leaves long runs of zero bytes under
 * it, and it is one subtraction a byte. */
#define PFX_PNG_DEFLATE_LEVEL 3
/* libdeflate 1.14's compressor at levels 2 to 6, measured (mallinfo2):
 * 668304 bytes; counted by the memory estimate. */
#define PFX_PNG_COMPRESSOR_BYTES ((size_t)700 * 1024)
/* IDAT chunks of at most this many bytes (a PNG chunk holds < 2^31). */
#define PFX_PNG_IDAT_MAX ((size_t)1 << 20)

/* Per-call libpng state: the handlers record messages here instead of
 * printing them, since libpng's defaults write to stderr. */
typedef struct {
    char message[256]; /* first error, or empty */
    int write_errno;   /* errno of a failed fwrite, 0 if none */
    FILE *file;
} pfx_png_ctx;

static void pfx_png_on_error(png_structp png, png_const_charp message) {
    pfx_png_ctx *ctx = png_get_error_ptr(png);
    if (ctx->message[0] == '\0')
        snprintf(ctx->message, sizeof ctx->message, "%s", message);
    png_longjmp(png, 1);
}

/* Warnings (e.g. a benign CRC oddity while reading) are not failures and
 * must not reach stderr; they are dropped. */
static void pfx_png_on_warning(png_structp png, png_const_charp message) {
    (void)png;
    (void)message;
}

/* Our own write function so a failed fwrite reports errno (e.g. "No space
 * left on device") rather than libpng's bare "Write Error". */
static void pfx_png_on_write(png_structp png, png_bytep data, size_t length) {
    pfx_png_ctx *ctx = png_get_io_ptr(png);
    if (fwrite(data, 1, length, ctx->file) != length) {
        ctx->write_errno = errno != 0 ? errno : EIO;
        png_error(png, "write failed");
    }
}

/* Nothing to do: pfx_png_write flushes once, after the last row. */
static void pfx_png_on_flush(png_structp png) { (void)png; }

/* The encoding thread's scratch, kept from frame to frame: the filtered
 * rows, room for their deflated stream, and a compressor. Allocating the
 * two buffers afresh for every frame cost page faults worth a fifth of the
 * time libdeflate saved (0.15 s of system time over 40 frames at
 * 1920x1080). Freed when the thread ends; the main thread's lives until
 * the process does. */
typedef struct idat_scratch {
    uint8_t *buf;
    size_t cap;
    struct libdeflate_compressor *c;
} idat_scratch;

static pthread_key_t scratch_key;
static pthread_once_t scratch_once = PTHREAD_ONCE_INIT;
static bool scratch_key_ok;

static void scratch_free(void *p) {
    idat_scratch *s = p;
    free(s->buf);
    libdeflate_free_compressor(s->c);
    free(s);
}

static void scratch_key_create(void) {
    scratch_key_ok = pthread_key_create(&scratch_key, scratch_free) == 0;
}

/* This thread's scratch with at least `bytes` of buffer, or NULL when out
 * of memory. */
static idat_scratch *thread_scratch(size_t bytes) {
    pthread_once(&scratch_once, scratch_key_create);
    if (!scratch_key_ok)
        return NULL;
    idat_scratch *s = pthread_getspecific(scratch_key);
    if (!s) {
        if (!(s = calloc(1, sizeof *s)))
            return NULL;
        if (!(s->c = libdeflate_alloc_compressor(PFX_PNG_DEFLATE_LEVEL)) ||
            pthread_setspecific(scratch_key, s) != 0) {
            scratch_free(s);
            return NULL;
        }
    }
    if (s->cap < bytes) {
        uint8_t *b = realloc(s->buf, bytes);
        if (!b)
            return NULL;
        s->buf = b, s->cap = bytes;
    }
    return s;
}

size_t pfx_png_encoder_scratch_bytes(int width, int height) {
    const size_t raw = ((size_t)width * 4 + 1) * (size_t)height;
    /* The filtered rows, and libdeflate's bound for their stream: the
     * input, 5 bytes per stored block of at most 10000 and a little more. */
    return 2 * raw + raw / 1000 + 1024 + PFX_PNG_COMPRESSOR_BYTES;
}

/* The zlib stream of the image's IDAT: each row behind its filter byte,
 * None for the first row and Up (the byte above subtracted) for the others,
 * deflated by libdeflate. Returns the stream (in this thread's scratch,
 * valid until its next call) and its size in *size, or NULL when out of
 * memory. */
static const uint8_t *pfx_png_idat(const uint8_t *rgba, int width, int height, size_t *size) {
    const size_t stride = (size_t)width * 4, raw = (stride + 1) * (size_t)height;
    idat_scratch *s = thread_scratch(0);
    const size_t bound = s ? libdeflate_zlib_compress_bound(s->c, raw) : 0;
    if (!s || !(s = thread_scratch(raw + bound)))
        return NULL;
    uint8_t *filtered = s->buf, *z = s->buf + raw;
    for (int y = 0; y < height; y++) {
        const uint8_t *row = rgba + (size_t)y * stride, *above = row - stride;
        uint8_t *out = filtered + (size_t)y * (stride + 1);
        out[0] = y ? 2 : 0; /* PNG filter types: 0 None, 2 Up */
        if (y == 0)
            memcpy(out + 1, row, stride);
        else
            for (size_t i = 0; i < stride; i++)
                out[1 + i] = (uint8_t)(row[i] - above[i]);
    }
    /* 0 only when the bound is too small, which libdeflate rules out. */
    *size = libdeflate_zlib_compress(s->c, filtered, raw, z, bound);
    return *size ? z : NULL;
}

/* The chunks of a PNG of `depth` bits a sample, RGBA, no interlace:
 * libpng writes the header, then `body` the image data and the end. The
 * one place that sets up libpng and catches its longjmp for both writers. */
typedef void (*png_body_fn)(png_structp png, png_infop info, const void *image, int width,
                            int height);

static bool png_encode_with(pfx_png_ctx *ctx, int width, int height, int depth, png_body_fn body,
                            const void *image) {
    png_structp png =
        png_create_write_struct(PNG_LIBPNG_VER_STRING, ctx, pfx_png_on_error, pfx_png_on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (info == NULL) {
        png_destroy_write_struct(&png, NULL);
        snprintf(ctx->message, sizeof ctx->message, "out of memory");
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_set_write_fn(png, ctx, pfx_png_on_write, pfx_png_on_flush);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, depth, PNG_COLOR_TYPE_RGBA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    body(png, info, image, width, height);
    png_destroy_write_struct(&png, &info);
    return true;
}

/* The 8-bit frames' IDAT, made by libdeflate (pfx_png_idat). */
typedef struct idat_stream {
    const uint8_t *bytes;
    size_t size;
} idat_stream;

static void write_idat(png_structp png, png_infop info, const void *image, int width, int height) {
    (void)width, (void)height;
    const idat_stream *idat = image;
    /* No tIME or text chunks: the same pixels must give the same bytes. */
    png_write_info(png, info);
    for (size_t at = 0; at < idat->size; at += PFX_PNG_IDAT_MAX)
        png_write_chunk(png, (png_const_bytep) "IDAT", idat->bytes + at,
                        idat->size - at < PFX_PNG_IDAT_MAX ? idat->size - at : PFX_PNG_IDAT_MAX);
    /* png_write_end would refuse: libpng did not see the IDAT go out. */
    png_write_chunk(png, (png_const_bytep) "IEND", NULL, 0);
}

static bool pfx_png_encode(pfx_png_ctx *ctx, const uint8_t *rgba, int width, int height) {
    idat_stream idat = {NULL, 0};
    idat.bytes = pfx_png_idat(rgba, width, height, &idat.size);
    if (!idat.bytes) {
        snprintf(ctx->message, sizeof ctx->message, "out of memory");
        return false;
    }
    return png_encode_with(ctx, width, height, 8, write_idat, &idat);
}

/* 16-bit RGBA rows through libpng's own deflate (motion vectors are
 * written only when asked), at the level and with the row filter of the
 * 8-bit frames. PNG stores samples big-endian; png_set_swap turns host
 * order into that on a little-endian machine. */
static void write_rows16(png_structp png, png_infop info, const void *image, int width,
                         int height) {
    const uint16_t *rgba = image;
    png_set_compression_level(png, PFX_PNG_DEFLATE_LEVEL);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
    png_write_info(png, info);
    const uint16_t one = 1;
    if (*(const uint8_t *)&one == 1)
        png_set_swap(png);
    size_t stride = (size_t)width * 4;
    for (int y = 0; y < height; y++)
        png_write_row(png, (png_const_bytep)(rgba + (size_t)y * stride));
    png_write_end(png, info);
}

static bool png_encode16(pfx_png_ctx *ctx, const uint16_t *rgba, int width, int height) {
    return png_encode_with(ctx, width, height, 16, write_rows16, rgba);
}

/* Encodes into an atomic file (output/atomic_file.h): whole or absent.
 * depth 8: rgba is uint8_t samples, 16: uint16_t in host order. sync_dir:
 * fsync the directory after the rename. g: a group the file joins (NULL:
 * none), which renames it later. */
static bool png_write_depth(pfx_atomic_group *g, const char *path, const void *rgba, int width,
                            int height, int depth, bool sync_dir, pfx_diags *d) {
    if (path == NULL || path[0] == '\0' || path[strlen(path) - 1] == '/') {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write '%s': not a file name",
                       path ? path : "");
        return false;
    }
    /* PNG allows up to 2^31-1 but libpng's default limit is 1000000. */
    if (rgba == NULL || width <= 0 || height <= 0 || width > 1000000 || height > 1000000) {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write '%s': invalid image size %dx%d",
                       path, width, height);
        return false;
    }
    pfx_atomic_file *a = pfx_atomic_open_in(g, path, d);
    if (a == NULL)
        return false;
    pfx_png_ctx ctx = {.message = "", .write_errno = 0, .file = pfx_atomic_stream(a)};
    if (!(depth == 16 ? png_encode16(&ctx, rgba, width, height)
                      : pfx_png_encode(&ctx, rgba, width, height))) {
        if (ctx.write_errno != 0) {
            pfx_atomic_failed(a, ctx.write_errno);
            return pfx_atomic_commit(a, false, d); /* reports the errno, removes the temporary */
        }
        pfx_diag_error(d, PFX_RULE_ENCODE_FAILED, "cannot encode '%s': %s", path, ctx.message);
        pfx_atomic_abort(a);
        return false;
    }
    return pfx_atomic_commit(a, sync_dir, d);
}

static bool png_write(const char *path, const uint8_t *rgba, int width, int height, bool sync_dir,
                      pfx_diags *d) {
    return png_write_depth(NULL, path, rgba, width, height, 8, sync_dir, d);
}

bool pfx_png_write(const char *path, const uint8_t *rgba, int width, int height, pfx_diags *d) {
    return png_write(path, rgba, width, height, true, d);
}

bool pfx_png_write_nosync(const char *path, const uint8_t *rgba, int width, int height,
                          pfx_diags *d) {
    return png_write(path, rgba, width, height, false, d);
}

bool pfx_png_write_in(pfx_atomic_group *g, const char *path, const uint8_t *rgba, int width,
                      int height, pfx_diags *d) {
    return png_write_depth(g, path, rgba, width, height, 8, false, d);
}

/* Transforms so that any PNG reads as RGBA of `bits` bits a sample:
 * palette, grey and tRNS expanded, 16-bit scaled down or 8-bit widened
 * (x 257), alpha added where there is none; 16-bit samples in host order. */
static void want_rgba(png_structp png, png_infop info, int bits) {
    int color = png_get_color_type(png, info);
    int depth = png_get_bit_depth(png, info);
    if (color == PNG_COLOR_TYPE_PALETTE)
        png_set_palette_to_rgb(png);
    if (color == PNG_COLOR_TYPE_GRAY && depth < 8)
        png_set_expand_gray_1_2_4_to_8(png);
    bool has_trns = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
    if (has_trns)
        png_set_tRNS_to_alpha(png);
    if (bits == 8 && depth == 16)
        png_set_scale_16(png);
    if (bits == 16)
        png_set_expand_16(png);
    if (color == PNG_COLOR_TYPE_GRAY || color == PNG_COLOR_TYPE_GRAY_ALPHA)
        png_set_gray_to_rgb(png);
    if (!has_trns && (color & PNG_COLOR_MASK_ALPHA) == 0)
        png_set_add_alpha(png, bits == 16 ? 0xffff : 0xff, PNG_FILLER_AFTER);
    const uint16_t one = 1;
    if (bits == 16 && *(const uint8_t *)&one == 1)
        png_set_swap(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
}

/* Any PNG as RGBA samples of `bits` (8 or 16) bits, top row first. Returns
 * a malloc'd buffer the caller frees, or NULL. Only a regular file is
 * opened (a FIFO would block). want_w > 0: only an image of want_w x
 * want_h, checked on the header before anything is allocated or decoded;
 * *width, *height hold the header's size then even when it differs. */
static void *png_read_depth(const char *path, int bits, int want_w, int want_h, int *width,
                            int *height) {
    if (width != NULL)
        *width = 0;
    if (height != NULL)
        *height = 0;
    int fd = pfx_open_regular(path, true);
    FILE *file = fd >= 0 ? fdopen(fd, "rb") : NULL;
    if (file == NULL) {
        if (fd >= 0)
            close(fd);
        return NULL;
    }
    pfx_png_ctx ctx = {.message = "", .write_errno = 0, .file = file};
    png_structp png =
        png_create_read_struct(PNG_LIBPNG_VER_STRING, &ctx, pfx_png_on_error, pfx_png_on_warning);
    png_infop info = png != NULL ? png_create_info_struct(png) : NULL;
    if (info == NULL) {
        png_destroy_read_struct(&png, NULL, NULL);
        fclose(file);
        return NULL;
    }
    /* Assigned after setjmp and needed after a longjmp, hence volatile. */
    png_bytep volatile pixels = NULL;
    png_bytep *volatile rows = NULL;
    if (setjmp(png_jmpbuf(png))) {
        free(rows);
        free(pixels);
        png_destroy_read_struct(&png, &info, NULL);
        fclose(file);
        return NULL;
    }
    png_init_io(png, file);
    png_read_info(png, info);
    png_uint_32 w = png_get_image_width(png, info);
    png_uint_32 h = png_get_image_height(png, info);
    if (width != NULL)
        *width = (int)w;
    if (height != NULL)
        *height = (int)h;
    if (want_w > 0 && (w != (png_uint_32)want_w || h != (png_uint_32)want_h))
        png_error(png, "not the size asked for");
    want_rgba(png, info, bits);
    size_t stride = (size_t)w * 4 * (size_t)(bits / 8);
    if (png_get_rowbytes(png, info) != stride)
        png_error(png, "not RGBA of the asked depth after transforms");
    /* Dimensions are at most libpng's limit of 1000000, so no overflow. */
    pixels = malloc(stride * h);
    rows = malloc(sizeof(png_bytep) * h);
    if (pixels == NULL || rows == NULL)
        png_error(png, "out of memory");
    for (png_uint_32 y = 0; y < h; y++)
        rows[y] = pixels + (size_t)y * stride;
    png_read_image(png, rows);
    png_read_end(png, NULL);
    void *result = pixels;
    free(rows);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(file);
    return result;
}

uint8_t *pfx_png_read(const char *path, int *width, int *height) {
    return png_read_depth(path, 8, 0, 0, width, height);
}

uint8_t *pfx_png_read_sized(const char *path, int width, int height, int *got_w, int *got_h) {
    return png_read_depth(path, 8, width, height, got_w, got_h);
}

bool pfx_png_write16(const char *path, const uint16_t *rgba, int width, int height, bool sync_dir,
                     pfx_diags *d) {
    return png_write_depth(NULL, path, rgba, width, height, 16, sync_dir, d);
}

bool pfx_png_write16_in(pfx_atomic_group *g, const char *path, const uint16_t *rgba, int width,
                        int height, pfx_diags *d) {
    return png_write_depth(g, path, rgba, width, height, 16, false, d);
}

uint16_t *pfx_png_read16(const char *path, int *width, int *height) {
    return png_read_depth(path, 16, 0, 0, width, height);
}
