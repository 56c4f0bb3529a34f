/* The string map of strmap.h: linear probing in a table at most half full,
 * doubled when it would pass that. Deletion is not needed (a parse only
 * adds), so there are no tombstones. */
#include "base/strmap.h"

#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>
#include <unistd.h>

#define ROTL(x, b) (uint64_t)(((x) << (b)) | ((x) >> (64 - (b))))
#define SIPROUND                                                                                   \
    do {                                                                                           \
        v0 += v1;                                                                                  \
        v1 = ROTL(v1, 13);                                                                         \
        v1 ^= v0;                                                                                  \
        v0 = ROTL(v0, 32);                                                                         \
        v2 += v3;                                                                                  \
        v3 = ROTL(v3, 16);                                                                         \
        v3 ^= v2;                                                                                  \
        v0 += v3;                                                                                  \
        v3 = ROTL(v3, 21);                                                                         \
        v3 ^= v0;                                                                                  \
        v2 += v1;                                                                                  \
        v1 = ROTL(v1, 17);                                                                         \
        v1 ^= v2;                                                                                  \
        v2 = ROTL(v2, 32);                                                                         \
    } while (0)

uint64_t pfx_siphash(uint64_t k0, uint64_t k1, const void *data, size_t n) {
    const unsigned char *in = data;
    uint64_t v0 = 0x736f6d6570736575ULL ^ k0, v1 = 0x646f72616e646f6dULL ^ k1;
    uint64_t v2 = 0x6c7967656e657261ULL ^ k0, v3 = 0x7465646279746573ULL ^ k1;
    const unsigned char *end = in + (n - n % 8);
    for (; in != end; in += 8) {
        uint64_t m = 0;
        for (int i = 0; i < 8; i++)
            m |= (uint64_t)in[i] << (8 * i);
        v3 ^= m;
        SIPROUND;
        SIPROUND;
        v0 ^= m;
    }
    uint64_t b = (uint64_t)n << 56;
    for (size_t i = 0; i < n % 8; i++)
        b |= (uint64_t)in[i] << (8 * i);
    v3 ^= b;
    SIPROUND;
    SIPROUND;
    v0 ^= b;
    v2 ^= 0xff;
    SIPROUND;
    SIPROUND;
    SIPROUND;
    SIPROUND;
    return v0 ^ v1 ^ v2 ^ v3;
}

void pfx_strmap_init(pfx_strmap *m) {
    memset(m, 0, sizeof *m);
    uint64_t k[2];
    if (getrandom(k, sizeof k, GRND_NONBLOCK) != (ssize_t)sizeof k) {
        /* No entropy yet (early boot): the clock and the address still
         * differ from run to run. */
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        k[0] = (uint64_t)ts.tv_nsec * 0x9e3779b97f4a7c15ULL ^ (uint64_t)(uintptr_t)m;
        k[1] = (uint64_t)ts.tv_sec ^ (uint64_t)getpid() << 32;
    }
    m->k0 = k[0];
    m->k1 = k[1];
}

void pfx_strmap_free(pfx_strmap *m) {
    free(m->slots);
    m->slots = NULL;
    m->cap = m->count = 0;
}

static pfx_strmap_slot *probe(pfx_strmap_slot *slots, size_t cap, const char *key, size_t len,
                              uint64_t hash) {
    for (size_t i = hash & (cap - 1);; i = (i + 1) & (cap - 1)) {
        pfx_strmap_slot *s = &slots[i];
        if (!s->key || (s->hash == hash && s->len == len && !memcmp(s->key, key, len)))
            return s;
    }
}

static bool grow(pfx_strmap *m) {
    size_t cap = m->cap ? 2 * m->cap : 16;
    pfx_strmap_slot *slots = calloc(cap, sizeof *slots);
    if (!slots)
        return false;
    for (size_t i = 0; i < m->cap; i++)
        if (m->slots[i].key)
            *probe(slots, cap, m->slots[i].key, m->slots[i].len, m->slots[i].hash) = m->slots[i];
    free(m->slots);
    m->slots = slots;
    m->cap = cap;
    return true;
}

size_t *pfx_strmap_add(pfx_strmap *m, const char *key, size_t len, size_t value, bool *found) {
    if (2 * (m->count + 1) > m->cap && !grow(m))
        return NULL;
    uint64_t hash = pfx_siphash(m->k0, m->k1, key, len);
    pfx_strmap_slot *s = probe(m->slots, m->cap, key, len, hash);
    *found = s->key != NULL;
    if (!*found) {
        *s = (pfx_strmap_slot){key, len, hash, value};
        m->count++;
    }
    return &s->value;
}

const size_t *pfx_strmap_get(const pfx_strmap *m, const char *key, size_t len) {
    if (!m->cap)
        return NULL;
    const pfx_strmap_slot *s =
        probe(m->slots, m->cap, key, len, pfx_siphash(m->k0, m->k1, key, len));
    return s->key ? &s->value : NULL;
}
