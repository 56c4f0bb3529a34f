/* Output files that appear whole or not at all. Each is written to a
 * temporary name in its own directory, flushed to the disk (fsync) and
 * renamed into place; a failed write, a full disk, a file-size limit or a
 * signal removes the temporary. Every file render, bake and assemble write
 * (frames, caches, manifests, atlases, previews, depfiles) goes through
 * here, so the temporary names, the errors and the durability are the same
 * for every format. */
#ifndef PFX_ATOMIC_FILE_H
#define PFX_ATOMIC_FILE_H

#include <stdbool.h>
#include <stdio.h>

#include "base/diag.h"

typedef struct pfx_atomic_file pfx_atomic_file;

/* Creates the temporary file for `path` (".<name>.tmp-<pid>-<n>" in the
 * same directory, its name cut short to fit the directory's NAME_MAX
 * whenever the final name fits). Returns NULL with "cannot write 'path':
 * <errno text>" in d. Thread-safe. */
pfx_atomic_file *pfx_atomic_open(const char *path, pfx_diags *d);
/* The stream to write to. A writer that sees a write fail calls
 * pfx_atomic_failed with its errno, or leaves ferror set. */
FILE *pfx_atomic_stream(pfx_atomic_file *a);
void pfx_atomic_failed(pfx_atomic_file *a, int errnum);
/* Flushes, fsyncs, closes and renames into place; on any failure removes
 * the temporary and reports "cannot write 'path': <errno text>" into d.
 * Frees a. sync_dir: also fsync the directory, so the new name itself
 * survives a power loss (once after a batch of files is enough). */
bool pfx_atomic_commit(pfx_atomic_file *a, bool sync_dir, pfx_diags *d);
/* Closes and removes the temporary without a message (the caller failed
 * for its own reason), and frees a. NULL is a no-op. */
void pfx_atomic_abort(pfx_atomic_file *a);
/* Files that appear together or not at all (an atlas sheet, its
 * motion-vector sheet and the JSON naming them), so that a failure in the
 * last leaves the previous set whole: each is written through
 * pfx_atomic_open_in, whose pfx_atomic_commit flushes and syncs it but
 * leaves it at its temporary name; pfx_atomic_group_commit then renames
 * them all, in the order they were committed, and syncs the directory
 * once (they share one). A signal removes the temporaries until then.
 * At most 8 files a group. */
typedef struct pfx_atomic_group pfx_atomic_group;
/* NULL with "out of memory" in d. */
pfx_atomic_group *pfx_atomic_group_create(pfx_diags *d);
/* pfx_atomic_open for a file of group g (NULL: of none). */
pfx_atomic_file *pfx_atomic_open_in(pfx_atomic_group *g, const char *path, pfx_diags *d);
/* Renames every file committed into g into place, reporting into d the
 * first that cannot be (the files after it are removed); frees g. */
bool pfx_atomic_group_commit(pfx_atomic_group *g, pfx_diags *d);
/* Removes every temporary committed into g, and frees g. NULL: no-op. */
void pfx_atomic_group_abort(pfx_atomic_group *g);
/* Puts a hard link to `from` at `path`: links it to a temporary name as
 * pfx_atomic_open names it (removed by a signal like any temporary) and
 * renames that into place. Returns 1 when linked; 0 when no link could be
 * made (another file system, or one without hard links), with nothing
 * reported or left behind, so the caller may copy through pfx_atomic_open
 * instead; -1 when the rename failed, reported in d. Thread-safe. */
int pfx_atomic_link(const char *from, const char *path, pfx_diags *d);
/* fsyncs the directory that holds path; false with the errno in d. */
bool pfx_atomic_sync_dir(const char *path, pfx_diags *d);

/* For main(), before any thread starts: SIGINT, SIGTERM and SIGHUP remove
 * every temporary file still open and end the process by the same signal
 * (exit status 130, 143 and 129 in the shell); SIGXFSZ is ignored, so a
 * write past `ulimit -f` fails with EFBIG and is reported like a full
 * disk. Returns false when the signal thread cannot start (the process
 * keeps the default dispositions then). */
bool pfx_atomic_guard_signals(void);
/* A long-running command (`pfx preview`) that stops cleanly on its own:
 * the first SIGINT, SIGTERM or SIGHUP calls hook (on the signal thread)
 * instead of ending the process; a second one ends it as above. NULL:
 * none. */
void pfx_atomic_set_stop_hook(void (*hook)(int sig));

#endif
