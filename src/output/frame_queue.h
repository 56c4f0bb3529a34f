/* Background encoders for frame sequences: the renderer fills one float
 * frame while a pool of encoder threads converts and writes the frames
 * before it, each as a PNG (converted to 8-bit as the tone says) or an EXR
 * (half float, as rendered). The conversion runs here, on the encoders,
 * so that it overlaps drawing and uses every core. */
#ifndef PFX_FRAME_QUEUE_H
#define PFX_FRAME_QUEUE_H

#include <stdbool.h>

#include "base/diag.h"
#include "render/image.h"

/* The file formats of a frame sequence, one row each: the kind and the
 * word --format and the file extension use. */
#define PFX_FRAME_FORMATS(X)                                                                       \
    X(PFX_FRAME_PNG, "png")                                                                        \
    X(PFX_FRAME_EXR, "exr")

typedef enum pfx_frame_format {
#define PFX_FRAME_FORMAT_ENUM(kind, name) kind,
    PFX_FRAME_FORMATS(PFX_FRAME_FORMAT_ENUM)
#undef PFX_FRAME_FORMAT_ENUM
        PFX_FRAME_FORMAT_COUNT
} pfx_frame_format;

/* The format's word and extension ("exr"); a static string. */
const char *pfx_frame_format_name(pfx_frame_format f);
/* The format named `name`, exactly as in the table; false if there is none. */
bool pfx_frame_format_parse(const char *name, pfx_frame_format *f);

typedef struct pfx_frame_queue pfx_frame_queue;

/* The most encoder threads a queue starts. */
#define PFX_FRAME_MAX_ENCODERS 64

/* How many encoders a queue for `wanted` threads starts: wanted, or one per
 * online core when it is 0, within 1 .. PFX_FRAME_MAX_ENCODERS. The memory
 * estimate and the render both ask here. */
int pfx_frame_encoder_count(int wanted);

/* The bytes a queue of `encoders` threads holds for width x height frames:
 * 2 x encoders float frames (16 bytes a pixel, four times an 8-bit one)
 * and per encoder, for PNG the 8-bit frame it converts into (4 bytes a
 * pixel), for EXR the file it builds in memory (at most 8). */
double pfx_frame_queue_bytes(int width, int height, int encoders, pfx_frame_format f);
/* And the caller's own, for the frames it encodes while every frame is
 * queued (pfx_frame_queue_buffer): what one encoder converts into. */
double pfx_frame_queue_caller_bytes(int width, int height, pfx_frame_format f);

/* Creates a queue for frames of width x height written as `format` with
 * `threads` encoders (1 to PFX_FRAME_MAX_ENCODERS; 2 x threads float frame
 * buffers), converting PNG frames with `tone` (copied; EXR takes its
 * exposure alone), and starts them. The caller owns it and ends it with
 * pfx_frame_queue_finish. NULL if the size is invalid or memory or a
 * thread is unavailable. */
pfx_frame_queue *pfx_frame_queue_create(int width, int height, int threads, pfx_frame_format format,
                                        const pfx_tone *tone);
/* The frame rate EXR frames record (framesPerSecond); call before the
 * first submit (the submit's lock hands it to the encoders). */
void pfx_frame_queue_set_fps(pfx_frame_queue *q, double fps);
/* A frame to render the next frame into: its pixels have room for width x
 * height x 4 floats; the caller fills every field (as
 * pfx_renderer_draw_float does). While every frame is queued or being
 * encoded, the caller encodes the oldest queued one itself, or waits when
 * none is left to take. */
pfx_float_image *pfx_frame_queue_buffer(pfx_frame_queue *q);
/* Hands the frame last returned by pfx_frame_queue_buffer to the encoders
 * to be written to `path` (copied). Encoders take frames in submission
 * order; each file's bytes do not depend on the number of encoders. After
 * a failure the frames after the failed one are not written. */
void pfx_frame_queue_submit(pfx_frame_queue *q, const char *path);
/* For tests: while hold is true the encoder threads take no frame, so the
 * caller encodes every frame that pfx_frame_queue_buffer must free, and
 * finish lets them take the rest. */
void pfx_frame_queue_hold_encoders(pfx_frame_queue *q, bool hold);
/* True once a frame has failed; later frames are dropped, so the caller
 * may stop rendering early. The error itself comes from finish. */
bool pfx_frame_queue_failed(pfx_frame_queue *q);
/* Waits for every submitted frame, syncs their directory (each frame was
 * synced before its rename), stops the threads and frees the queue.
 * Returns false with the error of the earliest frame that failed added to
 * d (may be NULL). */
bool pfx_frame_queue_finish(pfx_frame_queue *q, pfx_diags *d);

#endif
