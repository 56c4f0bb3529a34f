/* PFX_CLONES, for the hot loops of the simulation and the frame conversion. */
#ifndef PFX_BASE_CLONES_H
#define PFX_BASE_CLONES_H

/* PFX_CLONES: on x86-64, an AVX2 copy of a function beside the baseline
 * one, picked when the program loads. Both run the same operations in the
 * same order (lane-wise arithmetic, no FMA: the build has
 * -ffp-contract=off and the clone does not enable FMA), so they give the
 * same bits; wider vectors only do more lanes at once. */
/* Not with clang (14 here): it emits a clone's callers against a symbol
 * that only its own translation unit resolves, so calls from other files
 * fail to link. */
#if defined(__x86_64__) && defined(__has_attribute) && !defined(PFX_NO_CLONES) &&                  \
    !defined(__clang__)
#if __has_attribute(target_clones)
#define PFX_CLONES __attribute__((target_clones("avx2", "default")))
#endif
#endif
#ifndef PFX_CLONES
#define PFX_CLONES
#endif

#endif
