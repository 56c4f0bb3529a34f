/* PFX_CLONES, for the hot loops of the simulation and the frame conversion. */
#ifndef PFX_BASE_CLONES_H
#define PFX_BASE_CLONES_H

/* PFX_CLONES: on x86-64, AVX-512 and AVX2 copies of a function beside the
 * baseline one, the widest the processor has picked when the program
 * loads. All run the same operations in the same order (lane-wise
 * arithmetic, no FMA: the build has -ffp-contract=off and no clone enables
 * FMA), so they give the same bits; wider vectors only do more lanes at
 * once. AVX-512's 32 vector registers also hold the vortex's and the
 * attractor's constants without spilling them: 16 % and 8 % less time a
 * particle step there. */
/* Not with clang (14 here): it emits a clone's callers against a symbol
 * that only its own translation unit resolves, so calls from other files
 * fail to link. */
#if defined(__x86_64__) && defined(__has_attribute) && !defined(PFX_NO_CLONES) &&                  \
    !defined(__clang__)
#if __has_attribute(target_clones)
#define PFX_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#endif
#endif
#ifndef PFX_CLONES
#define PFX_CLONES
#endif

#endif
