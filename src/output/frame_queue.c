/* The encoder pool of output/frame_queue.h. The renderer hands over float
 * frames; each encoder converts its frame (PNG) and encodes it, so the
 * conversion, the largest part of a frame's work after drawing, runs on
 * every core instead of the drawing thread. It writes through
 * output/png_write.h and output/exr_write.h; it knows no file format. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "output/frame_queue.h"

#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/resource.h>
#endif

#include "base/workers.h"
#include "model/kinds.h"
#include "output/atomic_file.h"
#include "output/exr_write.h"
#include "output/png_write.h"

static const char *const format_names[] = {
#define PFX_FRAME_FORMAT_NAME(kind, name) name,
    PFX_FRAME_FORMATS(PFX_FRAME_FORMAT_NAME)
#undef PFX_FRAME_FORMAT_NAME
        NULL};

const char *pfx_frame_format_name(pfx_frame_format f) {
    return f >= 0 && f < PFX_FRAME_FORMAT_COUNT ? format_names[f] : "?";
}

bool pfx_frame_format_parse(const char *name, pfx_frame_format *f) {
    int i = pfx_kind_find(format_names, name);
    if (i >= 0)
        *f = (pfx_frame_format)i;
    return i >= 0;
}

/* A pool of encoder threads over a ring of 2 x threads slots. The caller
 * fills slot `tail` (free whenever slot[tail].state is FREE) and submits it;
 * each encoder takes the oldest READY slot, converts, encodes and writes it
 * without the lock, and frees it. When slot `tail` is not free, the caller
 * takes the oldest READY slot the same way. Nobody gets a slot back until
 * whoever took it has set it FREE under the lock, so pixels are never
 * shared. Each frame is its own file and the conversion is a pure function
 * of the frame, so frames may finish in any order and the bytes of every
 * file are the same for any number of encoders, whoever encodes it. */
enum slot_state { SLOT_FREE, SLOT_FILLING, SLOT_READY, SLOT_ENCODING };

typedef struct frame_slot {
    pfx_float_image image;
    float *pixels; /* the slot's own buffer, which image.pixels must name */
    char *path;
    long seq; /* submission number: encoders take the lowest READY */
    enum slot_state state;
} frame_slot;

struct pfx_frame_queue {
    int width, height;
    pfx_frame_format format;
    pfx_tone tone;
    double fps; /* EXR frames record it; 0: not known */
    int threads, slot_count;
    frame_slot *slots;
    uint8_t **rgba; /* PNG: one 8-bit frame per encoder, and the caller's
                       last, to convert into */
    int rgba_taken; /* encoders that have taken theirs, under the lock */
    pthread_mutex_t lock;
    pthread_cond_t work_ready; /* encoders wait: a READY slot or stop */
    pthread_cond_t slot_free;  /* the caller waits: slot tail FREE */
    int tail;                  /* the next slot the caller fills */
    long submitted;
    bool stop;
    bool hold; /* tests: encoders take nothing until it is cleared or stop */
    bool failed;
    long failed_seq;   /* the failed frame's number; the earliest one's error
                          is the one kept */
    char *written;     /* a frame written (under the lock), whose
                          directory finish syncs once */
    pfx_diags failure; /* the first failure, under the lock; handed over by finish */
    pthread_t *thread;
    int started;
};

/* The oldest READY slot, or -1. Called under the lock. */
static int oldest_ready(const pfx_frame_queue *q) {
    int best = -1;
    for (int i = 0; i < q->slot_count; i++)
        if (q->slots[i].state == SLOT_READY && (best < 0 || q->slots[i].seq < q->slots[best].seq))
            best = i;
    return best;
}

/* Converts and writes one frame; false with the reason in error. */
static bool encode(const pfx_frame_queue *q, const frame_slot *sl, uint8_t *rgba,
                   pfx_diags *error) {
    const pfx_float_image *img = &sl->image;
    if (img->pixels != sl->pixels || img->width != q->width || img->height != q->height) {
        pfx_diag_error(error, PFX_RULE_WRITE_FAILED,
                       "cannot write '%s': the frame is not the queue's", sl->path);
        return false;
    }
    if (q->format == PFX_FRAME_EXR)
        return pfx_exr_write(sl->path, img, q->tone.exposure, q->fps, false, error);
    pfx_float_image_to_rgba8(img, &q->tone, rgba);
    return pfx_png_write_nosync(sl->path, rgba, q->width, q->height, error);
}

/* Encodes the READY slot `slot` on the calling thread: called and returns
 * under the lock, which it lets go while it works. */
static void encode_slot(pfx_frame_queue *q, int slot, uint8_t *rgba, pfx_diags *error) {
    frame_slot *sl = &q->slots[slot];
    sl->state = SLOT_ENCODING;
    /* After an error, the frames after the failed one are dropped. */
    bool skip = (q->failed && sl->seq > q->failed_seq) || sl->path == NULL;
    pthread_mutex_unlock(&q->lock);

    bool ok = skip || encode(q, sl, rgba, error);

    pthread_mutex_lock(&q->lock);
    if (ok && !skip) {
        free(q->written);
        q->written = sl->path;
    } else {
        free(sl->path);
    }
    sl->path = NULL;
    /* Encoders and the caller may fail out of order; the error kept is the
     * earliest frame's, whichever thread met it first. */
    if (!ok && (!q->failed || sl->seq < q->failed_seq)) {
        pfx_diags_free(&q->failure);
        pfx_diags_init_runtime(&q->failure);
        pfx_diags_append(&q->failure, error);
        q->failed = true;
        q->failed_seq = sl->seq;
    }
    pfx_diags_free(error);
    sl->state = SLOT_FREE;
    pthread_cond_broadcast(&q->slot_free);
}

/* Encoders give way to drawing: each lowers its own priority by
 * PFX_ENCODER_NICE (Linux keeps a nice value per thread; capped at 19), so
 * that the scheduler hands a core to llvmpipe's rasterisers, whose frame
 * is what everything waits for, and runs the encoders in the time drawing
 * leaves. An encoder that falls behind cannot starve the render, even on
 * a busy machine: when every frame is queued, the caller encodes the
 * oldest one itself, at its own priority (pfx_frame_queue_buffer).
 * Paired whole renders of fire at 512x512 on 2 cores (farm-bench, median
 * of 12 pairs) took 4.6 % less wall time; the nice alone, without the
 * caller's help, measured 8.8 % in another such run. */
#define PFX_ENCODER_NICE 10

static void give_way_to_drawing(void) {
#if defined(__linux__)
    /* "who" 0 is the calling thread: Linux keeps the value per thread
     * (setpriority(2), BUGS). */
    errno = 0;
    const int nice = getpriority(PRIO_PROCESS, 0);
    if (errno == 0 && nice < 19)
        (void)setpriority(PRIO_PROCESS, 0,
                          nice + PFX_ENCODER_NICE < 19 ? nice + PFX_ENCODER_NICE : 19);
#endif
}

static void *encoder_main(void *arg) {
    pfx_frame_queue *q = arg;
    give_way_to_drawing();
    pfx_diags error;
    pfx_diags_init_runtime(&error);
    pthread_mutex_lock(&q->lock);
    uint8_t *rgba = q->rgba ? q->rgba[q->rgba_taken++] : NULL;
    for (;;) {
        int slot;
        while (((slot = oldest_ready(q)) < 0 || q->hold) && !q->stop)
            pthread_cond_wait(&q->work_ready, &q->lock);
        if (slot < 0)
            break; /* stop, and everything submitted is taken */
        encode_slot(q, slot, rgba, &error);
    }
    pthread_mutex_unlock(&q->lock);
    return NULL;
}

static void queue_free(pfx_frame_queue *q) {
    for (int i = 0; q->slots && i < q->slot_count; i++) {
        free(q->slots[i].pixels);
        free(q->slots[i].path);
    }
    for (int i = 0; q->rgba && i <= q->threads; i++)
        free(q->rgba[i]);
    free(q->rgba);
    free(q->slots);
    free(q->thread);
    free(q->written);
    free(q);
}

/* Stops and joins the encoders started so far. */
static void stop_encoders(pfx_frame_queue *q) {
    pthread_mutex_lock(&q->lock);
    q->stop = true;
    pthread_cond_broadcast(&q->work_ready);
    pthread_mutex_unlock(&q->lock);
    for (int i = 0; i < q->started; i++)
        pthread_join(q->thread[i], NULL);
    q->started = 0;
}

int pfx_frame_encoder_count(int wanted) {
    int n = wanted > 0 ? wanted : pfx_workers_cores();
    return n < 1 ? 1 : n > PFX_FRAME_MAX_ENCODERS ? PFX_FRAME_MAX_ENCODERS : n;
}

double pfx_frame_queue_bytes(int width, int height, int encoders, pfx_frame_format f) {
    const double pixels = (double)width * (double)height;
    const double n = pfx_frame_encoder_count(encoders);
    /* Per encoder: PNG's 8-bit frame, or the EXR file built in memory (at
     * most 8 bytes a pixel, output/exr_write.c). */
    return 2 * n * pixels * 4 * sizeof(float) + n * pfx_frame_queue_caller_bytes(width, height, f);
}

double pfx_frame_queue_caller_bytes(int width, int height, pfx_frame_format f) {
    return (double)width * (double)height * (f == PFX_FRAME_PNG ? 4 : 8);
}

/* The slots' float frames and, for PNG, the encoders' 8-bit ones. */
static bool allocate_frames(pfx_frame_queue *q) {
    q->slots = calloc((size_t)q->slot_count, sizeof *q->slots);
    q->thread = calloc((size_t)q->threads, sizeof *q->thread);
    if (q->format == PFX_FRAME_PNG)
        q->rgba = calloc((size_t)q->threads + 1, sizeof *q->rgba);
    bool ok = q->slots && q->thread && (q->format != PFX_FRAME_PNG || q->rgba);
    const size_t pixels = (size_t)q->width * (size_t)q->height;
    for (int i = 0; ok && i < q->slot_count; i++)
        ok = (q->slots[i].pixels = malloc(pixels * 4 * sizeof(float))) != NULL;
    for (int i = 0; ok && q->rgba && i <= q->threads; i++)
        ok = (q->rgba[i] = malloc(pixels * 4)) != NULL;
    return ok;
}

pfx_frame_queue *pfx_frame_queue_create(int width, int height, int threads, pfx_frame_format format,
                                        const pfx_tone *tone) {
    if (width <= 0 || height <= 0 || width > 1000000 || height > 1000000 ||
        (size_t)width > SIZE_MAX / 4 / sizeof(float) / (size_t)height ||
        (format != PFX_FRAME_PNG && format != PFX_FRAME_EXR))
        return NULL;
    pfx_frame_queue *q = calloc(1, sizeof *q);
    if (q == NULL)
        return NULL;
    q->width = width;
    q->height = height;
    q->format = format;
    q->tone = *tone;
    q->threads = pfx_frame_encoder_count(threads < 1 ? 1 : threads);
    q->slot_count = 2 * q->threads;
    if (!allocate_frames(q) || pthread_mutex_init(&q->lock, NULL) != 0) {
        queue_free(q);
        return NULL;
    }
    pfx_diags_init_runtime(&q->failure);
    if (pthread_cond_init(&q->work_ready, NULL) != 0)
        goto fail_lock;
    if (pthread_cond_init(&q->slot_free, NULL) != 0)
        goto fail_work_ready;
    for (; q->started < q->threads; q->started++)
        if (pthread_create(&q->thread[q->started], NULL, encoder_main, q) != 0)
            break;
    if (q->started == 0)
        goto fail_slot_free;
    return q; /* fewer encoders than asked for when threads ran out */

fail_slot_free:
    pthread_cond_destroy(&q->slot_free);
fail_work_ready:
    pthread_cond_destroy(&q->work_ready);
fail_lock:
    pthread_mutex_destroy(&q->lock);
    pfx_diags_free(&q->failure);
    queue_free(q);
    return NULL;
}

/* While every frame is queued or being encoded, the caller encodes the
 * oldest queued one itself (with the last 8-bit frame), rather than wait
 * for encoders that a busy machine may be giving little time. */
pfx_float_image *pfx_frame_queue_buffer(pfx_frame_queue *q) {
    pthread_mutex_lock(&q->lock);
    frame_slot *sl = &q->slots[q->tail];
    while (sl->state != SLOT_FREE && sl->state != SLOT_FILLING) {
        const int oldest = oldest_ready(q);
        if (oldest < 0) {
            pthread_cond_wait(&q->slot_free, &q->lock);
            continue;
        }
        pfx_diags error;
        pfx_diags_init_runtime(&error);
        encode_slot(q, oldest, q->rgba ? q->rgba[q->threads] : NULL, &error);
    }
    sl->state = SLOT_FILLING;
    pthread_mutex_unlock(&q->lock);
    sl->image = (pfx_float_image){.width = q->width, .height = q->height, .pixels = sl->pixels};
    return &sl->image;
}

void pfx_frame_queue_set_fps(pfx_frame_queue *q, double fps) { q->fps = fps; }

void pfx_frame_queue_submit(pfx_frame_queue *q, const char *path) {
    /* Copied outside the lock; a failed copy becomes the queue's error. */
    char *copy = strdup(path);
    pthread_mutex_lock(&q->lock);
    frame_slot *sl = &q->slots[q->tail];
    if (sl->state != SLOT_FILLING) {
        /* Contract broken by the caller: nothing was rendered to submit. */
        if (!q->failed) {
            q->failed = true;
            q->failed_seq = q->submitted;
            pfx_diag_error(&q->failure, PFX_RULE_WRITE_FAILED,
                           "cannot write '%s': frame submitted without a buffer", path);
        }
        pthread_mutex_unlock(&q->lock);
        free(copy);
        return;
    }
    if (copy == NULL && !q->failed) {
        q->failed = true;
        q->failed_seq = q->submitted;
        pfx_diag_error(&q->failure, PFX_RULE_OUT_OF_MEMORY, "cannot write '%s': out of memory",
                       path);
    }
    sl->path = copy;
    sl->seq = q->submitted++;
    sl->state = SLOT_READY;
    q->tail = (q->tail + 1) % q->slot_count;
    pthread_cond_signal(&q->work_ready);
    pthread_mutex_unlock(&q->lock);
}

void pfx_frame_queue_hold_encoders(pfx_frame_queue *q, bool hold) {
    pthread_mutex_lock(&q->lock);
    q->hold = hold;
    pthread_cond_broadcast(&q->work_ready);
    pthread_mutex_unlock(&q->lock);
}

bool pfx_frame_queue_failed(pfx_frame_queue *q) {
    pthread_mutex_lock(&q->lock);
    bool failed = q->failed;
    pthread_mutex_unlock(&q->lock);
    return failed;
}

bool pfx_frame_queue_finish(pfx_frame_queue *q, pfx_diags *d) {
    if (q == NULL)
        return true;
    stop_encoders(q); /* encoders drain every READY slot before they stop */

    /* Each frame was synced before its rename; their names are synced
     * here, once for the directory. */
    if (!q->failed && q->written && !pfx_atomic_sync_dir(q->written, &q->failure))
        q->failed = true;
    bool ok = !q->failed;
    if (d)
        pfx_diags_append(d, &q->failure);
    pfx_diags_free(&q->failure);
    pthread_cond_destroy(&q->slot_free);
    pthread_cond_destroy(&q->work_ready);
    pthread_mutex_destroy(&q->lock);
    queue_free(q);
    return ok;
}
