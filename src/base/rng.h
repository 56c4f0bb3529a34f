/* PCG32 (O'Neill, 2014): a 64-bit LCG state with a permuted 32-bit output.
 * Small, fast, statistically strong, and its streams let every emitter own
 * an independent sequence derived from the effect's seed and its name. */
#ifndef PFX_RNG_H
#define PFX_RNG_H

#include <stddef.h>
#include <stdint.h>

typedef struct pfx_rng {
    uint64_t state, inc;
    uint64_t draws; /* outputs taken, so a caller can measure a fixed draw count */
} pfx_rng;

/* Seeds `r` for stream `stream` of seed `seed` (pcg32_srandom_r). */
static inline uint32_t pfx_rng_next(pfx_rng *r) {
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    r->draws++;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
}

static inline void pfx_rng_seed(pfx_rng *r, uint64_t seed, uint64_t stream) {
    r->state = 0;
    r->draws = 0;
    r->inc = (stream << 1u) | 1u;
    pfx_rng_next(r);
    r->state += seed;
    pfx_rng_next(r);
}

/* Uniform double in [0, 1) with 53 random bits (two draws). */
static inline double pfx_rng_unit(pfx_rng *r) {
    uint64_t hi = pfx_rng_next(r) >> 5, lo = pfx_rng_next(r) >> 6; /* 27 + 26 bits */
    return (double)(hi * 67108864.0 + lo) * (1.0 / 9007199254740992.0);
}

/* Uniform double in [a, b). */
static inline double pfx_rng_range(pfx_rng *r, double a, double b) {
    return a + (b - a) * pfx_rng_unit(r);
}

/* The splitmix64 finaliser: a bijective mix, for hashing keys (names,
 * lattice points, particle ids) into well-spread 64-bit values. */
static inline uint64_t pfx_mix64(uint64_t z) {
    z ^= z >> 30;
    z *= 0xbf58476d1ce4e5b9ULL;
    z ^= z >> 27;
    z *= 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* A uniform double in [0, 1) from the top 53 bits of a hash: a
 * counter-based draw, keyed by what it belongs to (a particle id and its
 * hit number, say) instead of by its place in a stream. */
static inline double pfx_unit_of_hash(uint64_t h) {
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/* Skips the next `delta` outputs in O(log delta) steps (Brown, "Random
 * number generation with arbitrary strides", 1994), as if pfx_rng_next had
 * been called delta times. */
void pfx_rng_advance(pfx_rng *r, uint64_t delta);

/* The next n units into out[0], ..., out[n - 1], exactly as n calls of
 * pfx_rng_unit would draw them, leaving r where they would. The outputs
 * are taken 16 at a time by generators jumped 0, 1, ..., 15 outputs ahead
 * and stepping 16 at once (one multiply-add each), so a long run costs
 * vector throughput rather than the chain of one multiply after another. */
void pfx_rng_units(pfx_rng *r, double *out, size_t n);

/* The stream of an emitter: a hash of its name, so adding, removing or
 * reordering other emitters never changes its particles. */
uint64_t pfx_rng_stream_for(const char *name);

#endif
