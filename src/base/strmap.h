/* A map from byte strings to indices, for names a file picks (mapping keys,
 * YAML anchors): open addressing over a keyed hash, SipHash-2-4 (Aumasson
 * and Bernstein, "SipHash: a fast short-input PRF", 2012) keyed once per map
 * from getrandom(2), so no file can make its names collide on purpose and
 * every lookup stays O(1) expected. The map does not copy keys: they must
 * outlive it. */
#ifndef PFX_BASE_STRMAP_H
#define PFX_BASE_STRMAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct pfx_strmap_slot {
    const char *key; /* NULL: empty */
    size_t len;
    uint64_t hash;
    size_t value;
} pfx_strmap_slot;

typedef struct pfx_strmap {
    pfx_strmap_slot *slots;
    size_t cap, count; /* cap is 0 or a power of two, at least twice count */
    uint64_t k0, k1;   /* the SipHash key */
} pfx_strmap;

/* An empty map with a fresh key; allocates nothing until the first add. */
void pfx_strmap_init(pfx_strmap *m);
void pfx_strmap_free(pfx_strmap *m);

/* The value slot of key (len bytes, may hold NUL bytes): when the key is
 * there, *found is true and the slot holds its value (the caller may
 * overwrite it); otherwise the key is added with `value`. NULL when out of
 * memory. The pointer is valid until the next add. */
size_t *pfx_strmap_add(pfx_strmap *m, const char *key, size_t len, size_t value, bool *found);

/* The value of key, or NULL. */
const size_t *pfx_strmap_get(const pfx_strmap *m, const char *key, size_t len);

/* SipHash-2-4 of n bytes under the 128-bit key (k0, k1). */
uint64_t pfx_siphash(uint64_t k0, uint64_t k1, const void *data, size_t n);

#endif
