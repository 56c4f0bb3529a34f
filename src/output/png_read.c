/* PNG textures: libpng's progressive-free reader with its transforms
 * expanding every colour type and depth to RGBA of 8 or 16 bits. No
 * colour management: texels are read as they are, like frames are
 * written. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "output/png_read.h"

#include <errno.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct {
    char message[200];
} read_ctx;

static void on_error(png_structp png, png_const_charp message) {
    read_ctx *ctx = png_get_error_ptr(png);
    if (!ctx->message[0])
        snprintf(ctx->message, sizeof ctx->message, "%s", message);
    png_longjmp(png, 1);
}

static void on_warning(png_structp png, png_const_charp message) {
    (void)png, (void)message; /* benign; never printed */
}

/* Straight -> premultiplied, rounding to nearest, in place. */
static void premultiply8(uint8_t *p, size_t texels) {
    for (size_t i = 0; i < texels; i++, p += 4) {
        unsigned a = p[3];
        for (int c = 0; c < 3; c++)
            p[c] = (uint8_t)((p[c] * a + 127) / 255);
    }
}

static void premultiply16(uint16_t *p, size_t texels) {
    for (size_t i = 0; i < texels; i++, p += 4) {
        uint64_t a = p[3];
        for (int c = 0; c < 3; c++)
            p[c] = (uint16_t)((p[c] * a + 32767) / 65535);
    }
}

/* The file, opened only when it is a regular file within the size limit
 * (a FIFO would block fopen, a device could be endless). */
static FILE *open_texture(const char *path, const char *name, const pfx_diag_at *at) {
    struct stat st;
    if (stat(path, &st) != 0) {
        pfx_diag_error_at(at, PFX_RULE_MISSING_FILE, "cannot open '%s': %s", name, strerror(errno));
        return NULL;
    }
    if (!S_ISREG(st.st_mode)) {
        pfx_diag_error_at(at, PFX_RULE_INVALID_FILE, "texture '%s' is not a regular file", name);
        return NULL;
    }
    if ((unsigned long long)st.st_size > PFX_TEXTURE_MAX_FILE_BYTES) {
        pfx_diag_error_at(at, PFX_RULE_TOO_LARGE,
                          "texture '%s' is %.1f MiB; at most %u MiB is read", name,
                          (double)st.st_size / (1 << 20), PFX_TEXTURE_MAX_FILE_BYTES >> 20);
        return NULL;
    }
    FILE *f = fopen(path, "rb");
    if (!f)
        pfx_diag_error_at(at, PFX_RULE_MISSING_FILE, "cannot open '%s': %s", name, strerror(errno));
    return f;
}

/* After the header: expand palette, grey and low depths to RGBA, keep 16
 * bits, swap 16-bit samples to host order. Returns the bit depth. */
static int set_transforms(png_structp png, png_infop info) {
    int depth = png_get_bit_depth(png, info), type = png_get_color_type(png, info);
    if (type == PNG_COLOR_TYPE_PALETTE)
        png_set_palette_to_rgb(png);
    if (type == PNG_COLOR_TYPE_GRAY && depth < 8)
        png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS))
        png_set_tRNS_to_alpha(png);
    if (type == PNG_COLOR_TYPE_GRAY || type == PNG_COLOR_TYPE_GRAY_ALPHA)
        png_set_gray_to_rgb(png);
    if (!(type & PNG_COLOR_MASK_ALPHA) && !png_get_valid(png, info, PNG_INFO_tRNS))
        png_set_add_alpha(png, depth == 16 ? 0xffff : 0xff, PNG_FILLER_AFTER);
    if (depth == 16) {
        const uint16_t probe = 1;
        uint8_t first;
        memcpy(&first, &probe, 1);
        if (first) /* little-endian host: PNG stores big-endian */
            png_set_swap(png);
    }
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    return depth == 16 ? 16 : 8;
}

bool pfx_png_read_texture(const char *path, const char *name, bool premultiply, pfx_arena *a,
                          pfx_image *out, const pfx_diag_at *at) {
    FILE *f = open_texture(path, name, at);
    if (!f)
        return false;
    read_ctx ctx = {""};
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &ctx, on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    /* volatile: assigned after setjmp and read after a longjmp */
    png_bytep *volatile rows = NULL;
    volatile bool ok = false;
    uint8_t sig[8];
    if (!info) {
        pfx_diag_error_at(at, PFX_RULE_OUT_OF_MEMORY, "out of memory reading '%s'", name);
        goto done;
    }
    if (fread(sig, 1, 8, f) != 8 || png_sig_cmp(sig, 0, 8)) {
        pfx_diag_error_at(at, PFX_RULE_INVALID_FILE, "texture '%s' is not a PNG file", name);
        goto done;
    }
    if (setjmp(png_jmpbuf(png))) {
        /* libpng's stdio reader says "Read Error" when fread comes up short */
        if (!strcmp(ctx.message, "Read Error"))
            pfx_diag_error_at(at, PFX_RULE_INVALID_FILE,
                              "texture '%s' is truncated: the file ends inside its image data",
                              name);
        else
            pfx_diag_error_at(at, PFX_RULE_INVALID_FILE, "texture '%s' is corrupt: %s", name,
                              ctx.message[0] ? ctx.message : "libpng failed");
        goto done;
    }
    png_init_io(png, f);
    png_set_sig_bytes(png, 8);
    /* libpng's own limit is far above ours, so an oversized image reaches
     * the plain message below (its IHDR check would say "Invalid IHDR data"). */
    png_set_user_limits(png, 1u << 24, 1u << 24);
    png_read_info(png, info);
    png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    if (w > PFX_TEXTURE_MAX_SIDE || h > PFX_TEXTURE_MAX_SIDE) {
        pfx_diag_error_at(at, PFX_RULE_TOO_LARGE, "texture '%s' is %ux%u; at most %dx%d is read",
                          name, (unsigned)w, (unsigned)h, PFX_TEXTURE_MAX_SIDE,
                          PFX_TEXTURE_MAX_SIDE);
        goto done;
    }
    int bits = set_transforms(png, info);
    size_t row_bytes = (size_t)w * 4 * (size_t)(bits / 8);
    if (row_bytes * h > PFX_TEXTURE_MAX_BYTES) {
        pfx_diag_error_at(at, PFX_RULE_TOO_LARGE,
                          "texture '%s' (%ux%u, %d-bit) takes %.0f MiB decoded; at most %d MiB",
                          name, (unsigned)w, (unsigned)h, bits, (double)(row_bytes * h) / 1048576.0,
                          (int)(PFX_TEXTURE_MAX_BYTES >> 20));
        goto done;
    }
    uint8_t *pixels = pfx_arena_alloc(a, row_bytes * h);
    rows = malloc(h * sizeof *rows);
    if (!pixels || !rows || png_get_rowbytes(png, info) != row_bytes) {
        pfx_diag_error_at(at, PFX_RULE_OUT_OF_MEMORY, "out of memory reading '%s' (%ux%u)", name,
                          (unsigned)w, (unsigned)h);
        goto done;
    }
    for (png_uint_32 y = 0; y < h; y++)
        rows[y] = pixels + y * row_bytes;
    png_read_image(png, rows);
    png_read_end(png, NULL);
    if (premultiply && bits == 8)
        premultiply8(pixels, (size_t)w * h);
    else if (premultiply)
        premultiply16((uint16_t *)(void *)pixels, (size_t)w * h);
    *out = (pfx_image){.path = name,
                       .file = NULL,
                       .width = (int)w,
                       .height = (int)h,
                       .bits = bits,
                       .pixels = pixels};
    ok = true;
done:
    png_destroy_read_struct(&png, info ? &info : NULL, NULL);
    free(rows);
    fclose(f);
    return ok;
}
