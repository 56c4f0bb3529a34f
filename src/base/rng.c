/* Stream selection and jump-ahead for the per-emitter PCG32 generators (the
 * generator itself is inline in rng.h): FNV-1a over the emitter's name, finished with the
 * splitmix64 mixer so similar names give unrelated streams. */
#include "base/rng.h"

#include "base/clones.h"
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

/* pfx_rng_units in chunks of CHUNK outputs: the states of a chunk from
 * those JUMP outputs before (each a multiply-add, JUMP apart, so a vector
 * of them at once), then their outputs, then the units of pairs. */
#define JUMP 16
#define CHUNK 256

/* The affine map of `steps` steps of the generator of increment inc:
 * state -> state * mult + plus. */
static void jump_of(uint64_t inc, int steps, uint64_t *mult, uint64_t *plus) {
    uint64_t m = 1, p = 0;
    for (int i = 0; i < steps; i++) {
        m *= 6364136223846793005ULL;
        p = p * 6364136223846793005ULL + inc;
    }
    *mult = m, *plus = p;
}

PFX_CLONES
void pfx_rng_units(pfx_rng *r, double *restrict out, size_t n) {
    uint64_t st[CHUNK], mult, plus;
    uint32_t o[CHUNK];
    pfx_rng g = *r;
    for (int j = 0; j < JUMP; j++)
        st[j] = g.state, pfx_rng_next(&g);
    jump_of(r->inc, JUMP, &mult, &plus);
    for (size_t done = 0; done < n;) {
        const size_t units = n - done < CHUNK / 2 ? n - done : CHUNK / 2, outs = 2 * units;
        for (size_t j = JUMP; j < outs; j++)
            st[j] = st[j - JUMP] * mult + plus;
        for (size_t j = 0; j < outs; j++) {
            /* pfx_rng_next's output of the state before its step */
            const uint64_t old = st[j];
            const uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
            const uint32_t rot = (uint32_t)(old >> 59u);
            o[j] = (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
        }
        for (size_t m = 0; m < units; m++) {
            /* pfx_rng_unit's 27 + 26 bits; each below 2^27, exact as int32 */
            const int32_t hi = (int32_t)(o[2 * m] >> 5), lo = (int32_t)(o[2 * m + 1] >> 6);
            out[done + m] = ((double)hi * 67108864.0 + (double)lo) * (1.0 / 9007199254740992.0);
        }
        done += units;
        for (int j = 0; j < JUMP; j++) /* the next chunk's first states */
            st[j] = st[CHUNK - JUMP + j] * mult + plus;
    }
    pfx_rng_advance(r, 2 * (uint64_t)n);
}
