/* Slices: a frame range cut into N contiguous parts, one per process of a
 * job array (Slurm, Kubernetes Indexed Jobs, AWS Batch), each simulating
 * from t = 0 so that its frames are byte for byte those of one process. */
#ifndef PFX_JOBS_SLICE_H
#define PFX_JOBS_SLICE_H

#include <stdbool.h>

/* Slice `index` (0 <= index < count) of frames first..last: the frames
 * first + floor(index C / count) to first + floor((index + 1) C / count) - 1
 * of the C frames, so that slices differ by at most one frame and the last
 * ends at `last`. False, with *s_first > *s_last, when the slice is empty
 * (more slices than frames). */
bool pfx_slice_range(long first, long last, long index, long count, long *s_first, long *s_last);

/* The same cut of the frames first, first + step, ..., last (last - first
 * a multiple of step; step 1: pfx_slice_range): by their count, so that
 * each slice holds frames of the sequence and the slices together hold
 * each once. */
bool pfx_slice_range_step(long first, long last, long step, long index, long count, long *s_first,
                          long *s_last);

/* Reads a slice index from the environment variable `name`: a whole
 * number in [0, count). False when unset, empty or out of range. */
bool pfx_slice_index_from_env(const char *name, long count, long *index);

#endif
