/* SHA-256 through nettle's sha256_* (base/sha256.h): files are read in
 * 64 KiB blocks, so a large output costs no memory. */
#include "base/sha256.h"

#include <errno.h>
#include <nettle/sha2.h>
#include <unistd.h>

#include "base/regular_file.h"

static void to_hex(struct sha256_ctx *ctx, char hex[PFX_SHA256_HEX]) {
    static const char digits[] = "0123456789abcdef";
    uint8_t digest[SHA256_DIGEST_SIZE];
    sha256_digest(ctx, sizeof digest, digest);
    for (int i = 0; i < SHA256_DIGEST_SIZE; i++) {
        hex[2 * i] = digits[digest[i] >> 4];
        hex[2 * i + 1] = digits[digest[i] & 15];
    }
    hex[2 * SHA256_DIGEST_SIZE] = 0;
}

bool pfx_sha256_fd(int fd, char hex[PFX_SHA256_HEX]) {
    struct sha256_ctx ctx;
    sha256_init(&ctx);
    static _Thread_local uint8_t buf[1 << 16];
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) != 0) {
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return false;
        }
        sha256_update(&ctx, (size_t)n, buf);
    }
    to_hex(&ctx, hex);
    return true;
}

bool pfx_sha256_file(const char *path, char hex[PFX_SHA256_HEX]) {
    int fd = pfx_open_regular(path, true);
    if (fd < 0)
        return false;
    bool ok = pfx_sha256_fd(fd, hex);
    int err = errno;
    close(fd);
    errno = err;
    return ok;
}

void pfx_sha256_bytes(const void *data, size_t n, char hex[PFX_SHA256_HEX]) {
    struct sha256_ctx ctx;
    sha256_init(&ctx);
    sha256_update(&ctx, n, data);
    to_hex(&ctx, hex);
}
