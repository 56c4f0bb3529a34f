/* Stream selection for the per-emitter PCG32 generators (the generator itself
 * is inline in rng.h): FNV-1a over the emitter's name, finished with the
 * splitmix64 mixer so similar names give unrelated streams. */
#include "sim/rng.h"

uint64_t pfx_rng_stream_for(const char *name) {
    uint64_t h = 1469598103934665603ULL;
    for (const unsigned char *p = (const unsigned char *)name; *p; p++) {
        h ^= *p;
        h *= 1099511628211ULL;
    }
    h ^= h >> 30;
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 27;
    h *= 0x94d049bb133111ebULL;
    h ^= h >> 31;
    return h;
}
