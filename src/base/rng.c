/* Stream selection and jump-ahead for the per-emitter PCG32 generators (the
 * generator itself is inline in rng.h): FNV-1a over the emitter's name, finished with the
 * splitmix64 mixer so similar names give unrelated streams. */
#include "base/rng.h"

#include "base/hash.h"

uint64_t pfx_rng_stream_for(const char *name) {
    return pfx_mix64(pfx_fnv1a_str(PFX_FNV_OFFSET, name));
}

void pfx_rng_advance(pfx_rng *r, uint64_t delta) {
    uint64_t mult = 6364136223846793005ULL, plus = r->inc;
    uint64_t acc_mult = 1, acc_plus = 0;
    r->draws += delta;
    while (delta > 0) {
        if (delta & 1) {
            acc_mult *= mult;
            acc_plus = acc_plus * mult + plus;
        }
        plus = (mult + 1) * plus;
        mult *= mult;
        delta /= 2;
    }
    r->state = acc_mult * r->state + acc_plus;
}
