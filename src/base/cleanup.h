/* Temporary files a signal must not leave behind: writers register the
 * hidden name they write to, and main.c's SIGINT and SIGTERM handler
 * removes every registered file before the process exits with 128 + the
 * signal. A fixed table (no malloc), filled and read with atomics, so the
 * handler is async-signal-safe and writers on any thread may use it. */
#ifndef PFX_BASE_CLEANUP_H
#define PFX_BASE_CLEANUP_H

/* Registers path (copied); returns the slot to pass to pfx_cleanup_forget,
 * or -1 when the table is full or the path too long (the file is then
 * simply not cleaned up). */
int pfx_cleanup_watch(const char *path);
/* The file at slot is renamed or removed: forget it. -1 does nothing. */
void pfx_cleanup_forget(int slot);
/* From a signal handler: unlinks every registered file. */
void pfx_cleanup_now(void);

#endif
