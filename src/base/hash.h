/* FNV-1a, 64 bits: the state hash the determinism tests pin and the hash
 * of names that picks random streams. Not for anything an attacker picks
 * (it is not collision-resistant); SHA-256 comes from a library. */
#ifndef PFX_BASE_HASH_H
#define PFX_BASE_HASH_H

#include <stddef.h>
#include <stdint.h>

#define PFX_FNV_OFFSET 1469598103934665603ULL
#define PFX_FNV_PRIME 1099511628211ULL

/* h folded with n bytes at data, a byte at a time. */
static inline uint64_t pfx_fnv1a(uint64_t h, const void *data, size_t n) {
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++) {
        h ^= b[i];
        h *= PFX_FNV_PRIME;
    }
    return h;
}

/* h folded with a whole 32-bit value at once (a count, not its bytes). */
static inline uint64_t pfx_fnv1a_u32(uint64_t h, uint32_t v) {
    h ^= v;
    return h * PFX_FNV_PRIME;
}

/* h folded with a NUL-terminated string's bytes. */
static inline uint64_t pfx_fnv1a_str(uint64_t h, const char *s) {
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        h ^= *p;
        h *= PFX_FNV_PRIME;
    }
    return h;
}

#endif
