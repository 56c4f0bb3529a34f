/* The string map of base/strmap.h: SipHash-2-4 against the test vectors of
 * its paper (appendix A), and the map's contract (first add wins unless the
 * caller overwrites, keys with NUL bytes, growth past many keys). */
#include "test.h"

#include "base/strmap.h"

static void siphash_vectors(void) {
    /* Key 00 01 .. 0f; the messages 00 01 .. (n - 1). */
    uint64_t k0 = 0x0706050403020100ULL, k1 = 0x0f0e0d0c0b0a0908ULL;
    unsigned char msg[16];
    for (int i = 0; i < 16; i++)
        msg[i] = (unsigned char)i;
    CHECK(pfx_siphash(k0, k1, msg, 0) == 0x726fdb47dd0e0e31ULL);
    CHECK(pfx_siphash(k0, k1, msg, 1) == 0x74f839c593dc67fdULL);
    CHECK(pfx_siphash(k0, k1, msg, 8) == 0x93f5f5799a932462ULL);
    CHECK(pfx_siphash(k0, k1, msg, 15) == 0xa129ca6149be45e5ULL);
}

static void first_add_wins(void) {
    pfx_strmap m;
    pfx_strmap_init(&m);
    bool found;
    size_t *v = pfx_strmap_add(&m, "rate", 4, 7, &found);
    CHECK(v && !found && *v == 7);
    v = pfx_strmap_add(&m, "rate", 4, 9, &found);
    CHECK(v && found && *v == 7);
    *v = 11;
    const size_t *g = pfx_strmap_get(&m, "rate", 4);
    CHECK(g && *g == 11);
    CHECK(!pfx_strmap_get(&m, "rat", 3));
    /* Keys are byte strings: "a\0b" and "a\0c" differ, "a" is neither. */
    pfx_strmap_add(&m, "a\0b", 3, 1, &found);
    CHECK(!found);
    pfx_strmap_add(&m, "a\0c", 3, 2, &found);
    CHECK(!found);
    CHECK(!pfx_strmap_get(&m, "a", 1));
    g = pfx_strmap_get(&m, "a\0c", 3);
    CHECK(g && *g == 2);
    pfx_strmap_free(&m);
}

static void many_keys(void) {
    enum { N = 100000 };
    static char names[N][8];
    pfx_strmap m;
    pfx_strmap_init(&m);
    bool found, ok = true;
    for (size_t i = 0; i < N; i++) {
        snprintf(names[i], sizeof names[i], "k%zu", i);
        size_t *v = pfx_strmap_add(&m, names[i], strlen(names[i]), i, &found);
        ok &= v && !found;
    }
    CHECK(ok);
    CHECK(m.count == N && m.cap >= 2 * N);
    for (size_t i = 0; i < N; i++) {
        const size_t *g = pfx_strmap_get(&m, names[i], strlen(names[i]));
        ok &= g && *g == i;
    }
    CHECK(ok);
    pfx_strmap_free(&m);
}

int main(void) {
    RUN(siphash_vectors);
    RUN(first_add_wins);
    RUN(many_keys);
    return TEST_EXIT();
}
