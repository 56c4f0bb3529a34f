/* Waiting for files to change, with inotify: what the live session and
 * `pfx watch` recompile on. Directories are watched, not files, since
 * editors save by renaming a new file over the old one. */
#ifndef PFX_JOBS_FILE_WATCH_H
#define PFX_JOBS_FILE_WATCH_H

#include <stdbool.h>

#include "base/diag.h"
#include "model/effect.h"

typedef struct pfx_file_watch pfx_file_watch;

/* NULL, with the reason in d, when inotify or a pipe is not available.
 * Free with pfx_file_watch_destroy. */
pfx_file_watch *pfx_file_watch_create(pfx_diags *d);
void pfx_file_watch_destroy(pfx_file_watch *w);
/* Forgets the files watched so far (a new list follows). */
void pfx_file_watch_reset(pfx_file_watch *w);
/* Watches path (its directory, for its name) from now on; at most 256
 * files, the rest ignored. */
void pfx_file_watch_add(pfx_file_watch *w, const char *path);
/* Watches e's file and every file it read (pfx_effect_each_input). */
void pfx_file_watch_add_effect(pfx_file_watch *w, const pfx_effect *e);
/* Blocks until a watched file changes, then until events have settled for
 * 15 ms (a save in several steps counts once): true. False once
 * pfx_file_watch_stop was called. Reset and add may be called from other
 * threads meanwhile. */
bool pfx_file_watch_wait(pfx_file_watch *w);
/* Makes wait return false, now and from then on; async-signal-safe. */
void pfx_file_watch_stop(pfx_file_watch *w);

#endif
