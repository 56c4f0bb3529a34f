/* The live session (ARCHITECTURE.md): one effect file held open for a
 * front end (`pfx preview`). It keeps the last good compiled effect with
 * its version, the diagnostics of the latest attempt, and a cache of
 * rendered frames, rendered by one worker thread through the same frame
 * loop `pfx render` runs (jobs/render_job.c), the frame under the
 * playhead first. A watcher thread recompiles on every change of the file
 * or of what it reads (textures, meshes). It knows no protocol. */
#ifndef PFX_JOBS_SESSION_H
#define PFX_JOBS_SESSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/diag.h"
#include "compile/compile.h"
#include "render/render.h"

typedef struct pfx_session pfx_session;

typedef struct pfx_session_options {
    const char *path;            /* the effect file (kept, not copied) */
    pfx_compile_options compile; /* as `pfx render` takes them (--size, --seed, ...) */
    pfx_renderer_kind renderer;
    size_t cache_bytes;  /* the frame cache's cap in PNG bytes; 0: from the estimate */
    uint64_t max_memory; /* --max-memory: a version estimated to need more is refused */
} pfx_session_options;

/* Loads the file once and starts the render worker and the file watcher.
 * A file that does not compile still makes a session (with no frames until
 * a good save); NULL, with the reason in d, when a thread, the renderer or
 * the scratch directory cannot start. Free with pfx_session_destroy. */
pfx_session *pfx_session_create(const pfx_session_options *o, pfx_diags *d);
/* Stops and joins every thread, frees every model and frame. NULL: no-op. */
void pfx_session_destroy(pfx_session *s);

/* Reads and compiles the file now (the watcher calls it on a change). A
 * failure (or a render estimated over max_memory, as `pfx render` refuses
 * it) keeps the last good model and replaces the diagnostics; success
 * raises the version and cancels the stale renders at once. Returns true
 * when the version was raised. */
bool pfx_session_reload(pfx_session *s);

/* The news counter: raised by each reload (good or bad) and by nothing
 * else. Blocks until it differs from `seen` or timeout_ms passes (or the
 * session stops), and returns it. */
unsigned pfx_session_wait(pfx_session *s, unsigned seen, int timeout_ms);
/* Wakes every waiter (pfx_session_wait returns at once from now on). */
void pfx_session_stop(pfx_session *s);

/* The state as JSON text (malloc'd, the caller frees it): file, version,
 * news, frames, fps, size [w, h], diagnostics [{line, column, severity,
 * rule, message}], diagnostics_text (as `pfx validate` prints them),
 * emitters [{name, line, start, end, loop, bursts [s...], spawns [{event,
 * emitter}]}], the per-frame stats rendered so far and the frame cache
 * {frames, bytes, cap}. NULL when out of memory. */
char *pfx_session_state_json(pfx_session *s);

/* Frame k of the current version as the PNG file `pfx render --frames k`
 * writes (malloc'd into *png, *len bytes; the caller frees it), rendering
 * it first if it is not cached and moving the playhead there; `ahead` (a
 * look-ahead) leaves the playhead where it is while the worker renders
 * this version, so it never cancels the playhead's frame. Waits at
 * most timeout_ms. Returns 1 with the frame, 0 when there is no good model
 * or k is outside it, -1 on a timeout or a render failure. *version is the
 * version the frame belongs to. */
int pfx_session_frame(pfx_session *s, long k, bool ahead, int timeout_ms, void **png, size_t *len,
                      unsigned *version);

/* The emitters whose sprites cover pixel (x right, y down) of frame k as
 * JSON text [{emitter, line}] (malloc'd), in emitter order; NULL when
 * there is no good model, k or the pixel is outside, or memory ran out. */
char *pfx_session_pick_json(pfx_session *s, long k, int x, int y);

#endif
