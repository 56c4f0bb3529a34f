/* Opening a file for reading only when it is a regular one. A FIFO without
 * a writer blocks a plain open(), and a device such as /dev/zero never ends,
 * so every file pfx hashes or copies from a directory it does not own (a
 * manifest's outputs, a slice's frames) is opened through here. */
#ifndef PFX_BASE_REGULAR_FILE_H
#define PFX_BASE_REGULAR_FILE_H

#include <stdbool.h>

/* The errno of a file that is not a regular one. open() itself returns
 * ENODEV only for a device special file without a device, which is not a
 * regular file either, so the two never need telling apart. */
#define PFX_ENOTREG ENODEV

/* Opens path read-only without blocking (a FIFO's open returns at once),
 * checks with fstat that it is a regular file, and returns the descriptor,
 * blocking again, for the caller to close. follow_links false: a symbolic
 * link as the last component is refused too (O_NOFOLLOW), for directories
 * that are input rather than trust. -1 with errno set, PFX_ENOTREG for a
 * FIFO, a device, a directory, a socket or a refused link. */
int pfx_open_regular(const char *path, bool follow_links);

/* strerror(errnum), but "not a regular file" for PFX_ENOTREG. */
const char *pfx_file_strerror(int errnum);

#endif
