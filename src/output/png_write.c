/* PNG files through libpng: atomic 8-bit RGBA writes (temporary file in the
 * same directory, renamed into place) and a reader for tests; the encoder
 * threads of output/frame_queue.c call the writer. It does not
 * colour-manage: pixels are written and read as they are. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "output/png_write.h"

#include "base/diag.h"
#include "output/atomic_file.h"

#include <errno.h>
#include <png.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

/* Compression, measured on a 512x512 frame of 150 soft particles, 78% fully
 * transparent (min of 15 runs, libpng 1.6.39, zlib 1.2.13, Debian 12 x86-64):
 *   Z_RLE + filter up          3.3 ms   98 KB   <- chosen
 *   Z_RLE + filter sub         3.3 ms   99 KB
 *   level 1 (Z_BEST_SPEED) up  4.1 ms  101 KB
 *   level 3 + filter up        5.2 ms   96 KB
 *   level 6 + all filters     18.2 ms   82 KB   (libpng default)
 * A denser frame (66% transparent) ranks the same: 3.9 ms vs 5.2 ms at level
 * 1. Run-length matching suits the long runs of zero bytes that transparent
 * background leaves after the up filter. The level is irrelevant under Z_RLE
 * but must be non-zero. */
#define PFX_PNG_ZLIB_LEVEL 1
#define PFX_PNG_ZLIB_STRATEGY Z_RLE
#define PFX_PNG_FILTERS PNG_FILTER_UP

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

/* Encodes into ctx->file. Nothing assigned before setjmp is modified after
 * it, so no local needs to be volatile. */
static bool pfx_png_encode(pfx_png_ctx *ctx, const uint8_t *rgba, int width, int height) {
    png_structp png =
        png_create_write_struct(PNG_LIBPNG_VER_STRING, ctx, pfx_png_on_error, pfx_png_on_warning);
    if (png == NULL) {
        snprintf(ctx->message, sizeof ctx->message, "out of memory");
        return false;
    }
    png_infop info = png_create_info_struct(png);
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
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_RGBA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, PFX_PNG_ZLIB_LEVEL);
    png_set_compression_strategy(png, PFX_PNG_ZLIB_STRATEGY);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PFX_PNG_FILTERS);
    /* No tIME or text chunks: the same pixels must give the same bytes. */
    png_write_info(png, info);
    size_t stride = (size_t)width * 4;
    for (int y = 0; y < height; y++)
        png_write_row(png, rgba + (size_t)y * stride);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return true;
}

/* Encodes into an atomic file (output/atomic_file.h): whole or absent.
 * sync_dir: fsync the directory after the rename. */
static bool png_write(const char *path, const uint8_t *rgba, int width, int height, bool sync_dir,
                      pfx_diags *d) {
    if (path == NULL || path[0] == '\0' || path[strlen(path) - 1] == '/') {
        pfx_diag_error(d, "cannot write '%s': not a file name", path ? path : "");
        return false;
    }
    /* PNG allows up to 2^31-1 but libpng's default limit is 1000000. */
    if (rgba == NULL || width <= 0 || height <= 0 || width > 1000000 || height > 1000000) {
        pfx_diag_error(d, "cannot write '%s': invalid image size %dx%d", path, width, height);
        return false;
    }
    pfx_atomic_file *a = pfx_atomic_open(path, d);
    if (a == NULL)
        return false;
    pfx_png_ctx ctx = {.message = "", .write_errno = 0, .file = pfx_atomic_stream(a)};
    if (!pfx_png_encode(&ctx, rgba, width, height)) {
        if (ctx.write_errno != 0) {
            pfx_atomic_failed(a, ctx.write_errno);
            return pfx_atomic_commit(a, false, d); /* reports the errno, removes the temporary */
        }
        pfx_diag_error(d, "cannot encode '%s': %s", path, ctx.message);
        pfx_atomic_abort(a);
        return false;
    }
    return pfx_atomic_commit(a, sync_dir, d);
}

bool pfx_png_write(const char *path, const uint8_t *rgba, int width, int height, pfx_diags *d) {
    return png_write(path, rgba, width, height, true, d);
}

bool pfx_png_write_nosync(const char *path, const uint8_t *rgba, int width, int height,
                          pfx_diags *d) {
    return png_write(path, rgba, width, height, false, d);
}

/* Applies the transforms that turn any PNG into 8-bit RGBA rows. */
static void pfx_png_want_rgba(png_structp png, png_infop info) {
    int color = png_get_color_type(png, info);
    int depth = png_get_bit_depth(png, info);
    if (color == PNG_COLOR_TYPE_PALETTE)
        png_set_palette_to_rgb(png);
    if (color == PNG_COLOR_TYPE_GRAY && depth < 8)
        png_set_expand_gray_1_2_4_to_8(png);
    bool has_trns = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
    if (has_trns)
        png_set_tRNS_to_alpha(png);
    if (depth == 16)
        png_set_scale_16(png);
    if (color == PNG_COLOR_TYPE_GRAY || color == PNG_COLOR_TYPE_GRAY_ALPHA)
        png_set_gray_to_rgb(png);
    if (!has_trns && (color & PNG_COLOR_MASK_ALPHA) == 0)
        png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
}

uint8_t *pfx_png_read(const char *path, int *width, int *height) {
    FILE *file = fopen(path, "rb");
    if (file == NULL)
        return NULL;
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
    uint8_t *volatile pixels = NULL;
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
    pfx_png_want_rgba(png, info);
    png_uint_32 w = png_get_image_width(png, info);
    png_uint_32 h = png_get_image_height(png, info);
    size_t stride = (size_t)w * 4;
    if (png_get_rowbytes(png, info) != stride)
        png_error(png, "not 8-bit RGBA after transforms");
    /* Dimensions are at most libpng's limit of 1000000, so no overflow. */
    pixels = malloc(stride * h);
    rows = malloc(sizeof(png_bytep) * h);
    if (pixels == NULL || rows == NULL)
        png_error(png, "out of memory");
    for (png_uint_32 y = 0; y < h; y++)
        rows[y] = pixels + (size_t)y * stride;
    png_read_image(png, rows);
    png_read_end(png, NULL);
    uint8_t *result = pixels;
    free(rows);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(file);
    if (width != NULL)
        *width = (int)w;
    if (height != NULL)
        *height = (int)h;
    return result;
}
