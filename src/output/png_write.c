/* PNG files through libpng: atomic 8-bit RGBA writes (temporary file in the
 * same directory, renamed into place), a reader for tests, and a queue whose
 * single writer thread encodes one frame while the caller renders the next.
 * It does not colour-manage: pixels are written and read as they are. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "output/png_write.h"

#include "base/cleanup.h"

#include "base/diag.h"

#include <errno.h>
#include <png.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
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

/* Thread-safe strerror: the queue writes from its own thread. */
static const char *pfx_errno_text(int errnum, char *buf, size_t size) {
    if (strerror_r(errnum, buf, size) != 0)
        snprintf(buf, size, "error %d", errnum);
    return buf;
}

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

/* "<dir>/.<name>.tmp-<pid>-<n>": same directory so rename() is atomic; the
 * counter keeps two threads of one process writing the same path apart. */
static char *pfx_temp_name(const char *path) {
    static atomic_uint counter;
    unsigned n = atomic_fetch_add(&counter, 1u);
    const char *slash = strrchr(path, '/');
    int dir_len = slash != NULL ? (int)(slash - path + 1) : 0;
    const char *name = path + dir_len;
    long pid = (long)getpid();
    int len = snprintf(NULL, 0, "%.*s.%s.tmp-%ld-%u", dir_len, path, name, pid, n);
    if (len < 0)
        return NULL;
    char *temp = malloc((size_t)len + 1);
    if (temp != NULL)
        snprintf(temp, (size_t)len + 1, "%.*s.%s.tmp-%ld-%u", dir_len, path, name, pid, n);
    return temp;
}

bool pfx_png_write(const char *path, const uint8_t *rgba, int width, int height, pfx_diags *d) {
    char why[128];
    if (path == NULL || path[0] == '\0' || path[strlen(path) - 1] == '/') {
        pfx_diag_error(d, "cannot write '%s': not a file name", path ? path : "");
        return false;
    }
    /* PNG allows up to 2^31-1 but libpng's default limit is 1000000. */
    if (rgba == NULL || width <= 0 || height <= 0 || width > 1000000 || height > 1000000) {
        pfx_diag_error(d, "cannot write '%s': invalid image size %dx%d", path, width, height);
        return false;
    }
    char *temp = pfx_temp_name(path);
    if (temp == NULL) {
        pfx_diag_error(d, "cannot write '%s': out of memory", path);
        return false;
    }
    /* Watched before it exists, so that a signal at any moment after
     * finds it (base/cleanup.h). */
    int watch = pfx_cleanup_watch(temp);
    /* "x": fail rather than follow or truncate something already there. */
    FILE *file = fopen(temp, "wbx");
    if (file == NULL) {
        pfx_cleanup_forget(watch);
        pfx_diag_error(d, "cannot write '%s': %s", path, pfx_errno_text(errno, why, sizeof why));
        free(temp);
        return false;
    }
    pfx_png_ctx ctx = {.message = "", .write_errno = 0, .file = file};
    bool ok = pfx_png_encode(&ctx, rgba, width, height);
    if (!ok) {
        if (ctx.write_errno != 0)
            pfx_diag_error(d, "cannot write '%s': %s", path,
                           pfx_errno_text(ctx.write_errno, why, sizeof why));
        else
            pfx_diag_error(d, "cannot encode '%s': %s", path, ctx.message);
        fclose(file);
    } else {
        /* Buffered data can fail to land only at fflush or fclose. */
        int failed_errno = 0;
        if (fflush(file) != 0 || ferror(file))
            failed_errno = errno != 0 ? errno : EIO;
        if (fclose(file) != 0 && failed_errno == 0)
            failed_errno = errno != 0 ? errno : EIO;
        if (failed_errno != 0) {
            pfx_diag_error(d, "cannot write '%s': %s", path,
                           pfx_errno_text(failed_errno, why, sizeof why));
            ok = false;
        } else if (rename(temp, path) != 0) {
            /* The temporary's name means nothing to the user; the path does. */
            pfx_diag_error(d, "cannot write '%s': %s", path,
                           pfx_errno_text(errno, why, sizeof why));
            ok = false;
        }
    }
    if (!ok)
        unlink(temp);
    pfx_cleanup_forget(watch);
    free(temp);
    return ok;
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

/* Two slots used as a ring: slots head .. head+pending-1 (mod 2) are queued
 * or being written, in submission order; the caller renders into slot
 * (head + pending) % 2, which is free whenever pending < 2. The writer reads
 * a slot's pixels without the lock: the caller cannot get that slot back
 * until the writer has decremented pending under the lock. */
struct pfx_png_queue {
    int width, height;
    uint8_t *pixels[2];
    char *path[2];
    pthread_mutex_t lock;
    pthread_cond_t work_ready; /* the writer waits: pending > 0 or stop */
    pthread_cond_t slot_free;  /* the caller waits: pending < 2 */
    int head;
    int pending;
    bool caller_has_slot; /* pfx_png_queue_buffer called, submit not yet */
    bool stop;
    bool failed;
    pfx_diags failure; /* the first failure, under the lock; handed over by finish */
    pthread_t thread;
};

static void *pfx_png_queue_main(void *arg) {
    pfx_png_queue *q = arg;
    pfx_diags error;
    pfx_diags_init_runtime(&error);
    pthread_mutex_lock(&q->lock);
    for (;;) {
        while (q->pending == 0 && !q->stop)
            pthread_cond_wait(&q->work_ready, &q->lock);
        if (q->pending == 0)
            break; /* stop, and everything submitted is written */
        int slot = q->head;
        char *path = q->path[slot];
        q->path[slot] = NULL;
        bool skip = q->failed || path == NULL;
        pthread_mutex_unlock(&q->lock);

        /* After the first error, later frames are dropped, not written. */
        bool ok = skip || pfx_png_write(path, q->pixels[slot], q->width, q->height, &error);
        free(path);

        pthread_mutex_lock(&q->lock);
        if (!ok && !q->failed) {
            q->failed = true;
            pfx_diags_append(&q->failure, &error);
        }
        pfx_diags_free(&error);
        q->head = (q->head + 1) % 2;
        q->pending--;
        pthread_cond_signal(&q->slot_free);
    }
    pthread_mutex_unlock(&q->lock);
    return NULL;
}

pfx_png_queue *pfx_png_queue_create(int width, int height) {
    if (width <= 0 || height <= 0 || width > 1000000 || height > 1000000 ||
        (size_t)width > SIZE_MAX / 4 / (size_t)height)
        return NULL;
    pfx_png_queue *q = calloc(1, sizeof *q);
    if (q == NULL)
        return NULL;
    q->width = width;
    q->height = height;
    size_t size = (size_t)width * (size_t)height * 4;
    q->pixels[0] = malloc(size);
    q->pixels[1] = malloc(size);
    if (q->pixels[0] == NULL || q->pixels[1] == NULL)
        goto fail_pixels;
    if (pthread_mutex_init(&q->lock, NULL) != 0)
        goto fail_pixels;
    if (pthread_cond_init(&q->work_ready, NULL) != 0)
        goto fail_lock;
    if (pthread_cond_init(&q->slot_free, NULL) != 0)
        goto fail_work_ready;
    if (pthread_create(&q->thread, NULL, pfx_png_queue_main, q) != 0)
        goto fail_slot_free;
    return q;

fail_slot_free:
    pthread_cond_destroy(&q->slot_free);
fail_work_ready:
    pthread_cond_destroy(&q->work_ready);
fail_lock:
    pthread_mutex_destroy(&q->lock);
fail_pixels:
    free(q->pixels[0]);
    free(q->pixels[1]);
    free(q);
    return NULL;
}

uint8_t *pfx_png_queue_buffer(pfx_png_queue *q) {
    pthread_mutex_lock(&q->lock);
    while (q->pending == 2)
        pthread_cond_wait(&q->slot_free, &q->lock);
    q->caller_has_slot = true;
    uint8_t *pixels = q->pixels[(q->head + q->pending) % 2];
    pthread_mutex_unlock(&q->lock);
    return pixels;
}

void pfx_png_queue_submit(pfx_png_queue *q, const char *path) {
    /* Copied outside the lock; a failed copy becomes the queue's error. */
    char *copy = strdup(path);
    pthread_mutex_lock(&q->lock);
    if (!q->caller_has_slot) {
        /* Contract broken by the caller: nothing was rendered to submit. */
        if (!q->failed) {
            q->failed = true;
            pfx_diag_error(&q->failure, "cannot write '%s': frame submitted without a buffer",
                           path);
        }
        pthread_mutex_unlock(&q->lock);
        free(copy);
        return;
    }
    if (copy == NULL && !q->failed) {
        q->failed = true;
        pfx_diag_error(&q->failure, "cannot write '%s': out of memory", path);
    }
    q->path[(q->head + q->pending) % 2] = copy;
    q->pending++;
    q->caller_has_slot = false;
    pthread_cond_signal(&q->work_ready);
    pthread_mutex_unlock(&q->lock);
}

bool pfx_png_queue_failed(pfx_png_queue *q) {
    pthread_mutex_lock(&q->lock);
    bool failed = q->failed;
    pthread_mutex_unlock(&q->lock);
    return failed;
}

bool pfx_png_queue_finish(pfx_png_queue *q, pfx_diags *d) {
    if (q == NULL)
        return true;
    pthread_mutex_lock(&q->lock);
    q->stop = true;
    pthread_cond_signal(&q->work_ready);
    pthread_mutex_unlock(&q->lock);
    pthread_join(q->thread, NULL);

    bool ok = !q->failed;
    if (d)
        pfx_diags_append(d, &q->failure);
    pfx_diags_free(&q->failure);
    pthread_cond_destroy(&q->slot_free);
    pthread_cond_destroy(&q->work_ready);
    pthread_mutex_destroy(&q->lock);
    free(q->path[0]);
    free(q->path[1]);
    free(q->pixels[0]);
    free(q->pixels[1]);
    free(q);
    return ok;
}
