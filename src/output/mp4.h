/* MP4 previews (H.264, yuv420p) made by an ffmpeg executable found on the
 * PATH, never linked: pfx starts it with an argv array (no shell) and pipes
 * it raw RGB frames. Transparent pixels are composited over black, and an
 * odd width or height is padded with one black column or row, since
 * yuv420p needs even sizes. */
#ifndef PFX_OUTPUT_MP4_H
#define PFX_OUTPUT_MP4_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/diag.h"

typedef struct pfx_mp4 pfx_mp4;

/* True when path ends in ".mp4" (the extension that chooses this writer). */
bool pfx_mp4_path(const char *path);
/* Finds an executable ffmpeg on the PATH and puts its path in exe. False
 * with "cannot write 'path': ffmpeg not found on PATH (...)" in d: the
 * check main.c makes before anything is rendered. */
bool pfx_mp4_find_ffmpeg(const char *path, char *exe, size_t exe_size, pfx_diags *d);
/* Starts ffmpeg writing width x height frames at fps, x264 at crf (0..51,
 * lower is better), to a temporary beside path. NULL with the reason in d,
 * and nothing left on the disk. */
pfx_mp4 *pfx_mp4_create(int width, int height, double fps, int crf, const char *path, pfx_diags *d);
/* Sends one frame of 8-bit straight RGBA, top row first. False when
 * ffmpeg has stopped reading, with why (its exit status and the last
 * lines of its stderr) in d. */
bool pfx_mp4_add(pfx_mp4 *m, const uint8_t *rgba, pfx_diags *d);
/* Closes ffmpeg's input and waits for it. commit: renames its file into
 * place when it exited 0 (a failure is reported as by pfx_mp4_add);
 * otherwise stops ffmpeg and removes its file without a message. Frees m.
 * True when the file is in place, or, without commit, when nothing had
 * failed before. */
bool pfx_mp4_finish(pfx_mp4 *m, bool commit, pfx_diags *d);

#endif
