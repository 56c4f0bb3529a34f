/* SHA-256 of files and bytes, from nettle (not written by hand): the
 * content hashes of manifests and the bake key. Digests are 64 lowercase
 * hex digits. */
#ifndef PFX_BASE_SHA256_H
#define PFX_BASE_SHA256_H

#include <stdbool.h>
#include <stddef.h>

#define PFX_SHA256_HEX 65 /* 64 digits and the NUL */

/* The digest of the file at path into hex. False with errno set when it
 * cannot be opened or read, PFX_ENOTREG (base/regular_file.h) when it is
 * not a regular file: a FIFO or /dev/zero would never end. */
bool pfx_sha256_file(const char *path, char hex[PFX_SHA256_HEX]);

/* The digest of what is left to read of fd (not closed). False with errno
 * set on a read error. */
bool pfx_sha256_fd(int fd, char hex[PFX_SHA256_HEX]);

/* The digest of n bytes at data into hex. */
void pfx_sha256_bytes(const void *data, size_t n, char hex[PFX_SHA256_HEX]);

#endif
