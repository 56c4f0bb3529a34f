/* Manifests: what a render or bake read and wrote, beside its outputs as
 * JSON (through jansson). The pfx version and results revision, the
 * command, the resolved settings, the SHA-256 of every input (the effect,
 * its meshes) and of every output, and a bake key: the SHA-256 of
 * everything that decides the outputs. A re-run whose key and outputs
 * match the previous manifest has nothing to do; files the previous
 * manifest listed and the new one does not are stale and removed. */
#ifndef PFX_JOBS_MANIFEST_H
#define PFX_JOBS_MANIFEST_H

#include <stdbool.h>
#include <stddef.h>

#include "base/diag.h"
#include "base/sha256.h"
#include "model/effect.h"

/* The revision of the bytes pfx writes for a given input and settings,
 * raised by every change that alters some output (a re-pinned state hash,
 * a frame that changed), so that a bake key recorded by an earlier build
 * of the same version never vouches for this one's outputs: it is part of
 * the key, and each manifest records it as "pfx_results".
 *   1  0.1.0 up to the newborns' substep levels
 *   2  a newborn's part of a step at the attractor's substep levels
 *   3  EXR chromaticities and framesPerSecond; the atlas JSON's uv and used;
 *      motion vectors from the next frame's positions, scaled by a percentile
 *   4  random turns and flipbook start cells by default; the split step's
 *      midpoint half kicks on forces of v; auto's substeps for quadratic
 *      drag and per particle about an unsoftened attractor; random
 *      deflector responses drawn per particle and hit; sub-emitter children
 *      keyed by their event (ids, counts, draws); vortex, spiral and
 *      speed_limit applied about each step (Strang splitting), the vortex
 *      at its midpoint where a region or inflow varies its rate; on_death
 *      and trail children from the parent's state at the event time, to
 *      second order; sphere, cone and spread sampling by fast_d.h's
 *      polynomial sincos and cube root (last bits of births)
 *   5  textured sprites and ribbons read the mip level pfx computes,
 *      blended across half-way, from mipmaps pfx makes; textures held as
 *      half floats (floats for 16-bit images), filtered in float */
#define PFX_RESULTS 5

typedef struct pfx_manifest pfx_manifest;

/* An empty manifest for `command` ("render", "bake"). NULL when out of
 * memory. Free with pfx_manifest_destroy. */
pfx_manifest *pfx_manifest_create(const char *command);
void pfx_manifest_destroy(pfx_manifest *m);

/* A resolved setting (part of the bake key). */
void pfx_manifest_set_string(pfx_manifest *m, const char *key, const char *value);
void pfx_manifest_set_number(pfx_manifest *m, const char *key, double value);
void pfx_manifest_set_range(pfx_manifest *m, const char *key, long first, long last);
/* A list of strings in their order: --set's PATH=VALUE words. */
void pfx_manifest_set_strings(pfx_manifest *m, const char *key, const char *const *values,
                              size_t n);

/* Hashes the input at path and lists it (part of the bake key); a second
 * call with the same path does nothing. False, with the reason in d, when
 * it cannot be read. */
bool pfx_manifest_add_input(pfx_manifest *m, const char *path, pfx_diags *d);
/* Lists the input at path with the SHA-256 (hex) of the bytes the run
 * read, where opening it again would not give them (a pipe); a second
 * call with the same path does nothing. */
void pfx_manifest_add_input_sha256(pfx_manifest *m, const char *path, const char *sha256);
/* The effect file and every file it read (meshes, textures, normal maps). */
bool pfx_manifest_add_effect(pfx_manifest *m, const pfx_effect *e, pfx_diags *d);
/* Calls fn with the path of the effect file, then of every file it read
 * (meshes, textures, normal maps, in emitter order, repeats included): the
 * manifest's inputs, and what the live session watches. */
void pfx_effect_each_input(const pfx_effect *e, void (*fn)(void *ctx, const char *path), void *ctx);
size_t pfx_manifest_input_count(const pfx_manifest *m);
const char *pfx_manifest_input(const pfx_manifest *m, size_t i);

/* The bake key over the version, the results revision, the command, the
 * settings and the inputs so far, as 64 hex digits (owned by m, valid
 * until the next change). */
const char *pfx_manifest_key(pfx_manifest *m);

/* Hashes dir/name and lists it as an output by its name (relative to the
 * manifest's directory). False, with the reason in d, when unreadable. */
bool pfx_manifest_add_output(pfx_manifest *m, const char *dir, const char *name, pfx_diags *d);
size_t pfx_manifest_output_count(const pfx_manifest *m);
const char *pfx_manifest_output(const pfx_manifest *m, size_t i, const char **sha256);

/* Hashes the preview at path (--preview: a path of its own, not a name in
 * the manifest's directory) and records it as the manifest's "preview"
 * {path, sha256}, so that a preview damaged or replaced since is not up to
 * date. False, with the reason in d, when unreadable. */
bool pfx_manifest_add_preview(pfx_manifest *m, const char *path, pfx_diags *d);

/* True when m records the preview at path with the SHA-256 the file has
 * now. */
bool pfx_manifest_preview_intact(const pfx_manifest *m, const char *path);
/* Records in now the preview as prev records it: for a preview that
 * pfx_manifest_preview_intact has just hashed, which is not read again. */
void pfx_manifest_keep_preview(pfx_manifest *now, const pfx_manifest *prev);

/* Writes m to path whole or not at all (a temporary renamed into place).
 * False with the reason in d. */
bool pfx_manifest_write(pfx_manifest *m, const char *path, pfx_diags *d);

/* The manifest at path, or NULL when there is none or it is not one of
 * pfx's (then nothing is trusted from it): not a regular file (never
 * opened for reading when a FIFO or a device), not JSON, another format,
 * or an input or output without a string path and sha256. */
pfx_manifest *pfx_manifest_read(const char *path);
/* The same for a manifest that must be there (a slice's): NULL with the
 * reason in d (the file's kind or errno, the JSON error at path:line:col,
 * or which member is wrong). */
pfx_manifest *pfx_manifest_load(const char *path, pfx_diags *d);
/* The key the manifest recorded, or NULL. */
const char *pfx_manifest_recorded_key(const pfx_manifest *m);

/* True when prev records `key` and every output it lists is in dir with
 * the recorded SHA-256, and so is its preview when its settings name one
 * (pfx_manifest_preview_intact): a re-run would write the same bytes. */
bool pfx_manifest_up_to_date(const pfx_manifest *prev, const char *key, const char *dir);

/* Whether name is one a manifest may list: a plain file name in the
 * manifest's directory (not empty, no '/' or '\\', no leading '.', no
 * control byte, at most 255 bytes). */
bool pfx_manifest_plain_name(const char *name);

/* Removes from dir each output prev lists and now does not, when the file
 * still has the hash pfx recorded (a file changed since, or never written
 * by pfx, or one that is an input of `now` by device and inode, such as a
 * frame of an earlier run used as this run's texture, is never touched: a
 * note says so). Names with a '/' or a leading '.' are ignored. Returns
 * how many were removed. */
size_t pfx_manifest_remove_stale(const pfx_manifest *prev, const pfx_manifest *now, const char *dir,
                                 pfx_diags *d);

/* A number setting, or `fallback` when m has none. */
double pfx_manifest_get_number(const pfx_manifest *m, const char *key, double fallback);

/* Marks m as slice `index` of `count` of the frames first..last (the
 * frames of all slices together). */
void pfx_manifest_set_slice(pfx_manifest *m, long index, long count, long first, long last);

/* A number that slice manifest m records for `pfx assemble` beside its
 * index, outside the settings and so outside the bake key (a value the run
 * found, not one it was given: --motion-vectors' scale). False, nothing
 * set, when m is not a slice's manifest. */
bool pfx_manifest_set_slice_number(pfx_manifest *m, const char *key, double value);
/* That number, or `fallback` when m records none. */
double pfx_manifest_slice_number(const pfx_manifest *m, const char *key, double fallback);

/* The one manifest of a render cut into slices: the slices' manifests
 * (named by `names` in messages) must be every slice of one render
 * exactly once: the same inputs, settings but for the frames, and count;
 * no output twice, each a plain name (pfx_manifest_plain_name) with its
 * SHA-256. The result has the settings of a single-process render
 * of all the frames (so the same bake key) and every output, sorted; its
 * frame range is in *first, *last. NULL with the reasons in d. */
pfx_manifest *pfx_manifest_assemble(pfx_manifest *const *parts, const char *const *names, size_t n,
                                    long *first, long *last, pfx_diags *d);

#endif
