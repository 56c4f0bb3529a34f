/* SHA-256 through nettle's sha256_* (base/sha256.h): files are read in
 * 64 KiB blocks, so a large output costs no memory. */
#include "base/sha256.h"

#include <errno.h>
#include <nettle/sha2.h>
#include <stdio.h>

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

bool pfx_sha256_file(const char *path, char hex[PFX_SHA256_HEX]) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    struct sha256_ctx ctx;
    sha256_init(&ctx);
    static _Thread_local uint8_t buf[1 << 16];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        sha256_update(&ctx, n, buf);
    bool ok = !ferror(f);
    int err = errno;
    fclose(f);
    if (!ok) {
        errno = err ? err : EIO;
        return false;
    }
    to_hex(&ctx, hex);
    return true;
}

void pfx_sha256_bytes(const void *data, size_t n, char hex[PFX_SHA256_HEX]) {
    struct sha256_ctx ctx;
    sha256_init(&ctx);
    sha256_update(&ctx, n, data);
    to_hex(&ctx, hex);
}
