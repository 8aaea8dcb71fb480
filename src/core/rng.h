/* rng.h: random numbers that are a pure function of (seed, stream, index).
 *
 * Thesis 4.1.3: photon i must take the same path whichever thread or batch traces
 * it, so that the picture does not flicker between frames and the photon set does
 * not depend on the thread count. A generator is therefore never shared: each
 * photon (or pixel sample) makes its own from (seed, stream, index) and draws
 * from it. Streams separate independent uses (photons of each map, eye samples)
 * so that they never reuse each other's numbers. */
#ifndef PS_CORE_RNG_H
#define PS_CORE_RNG_H

#include <stdint.h>

/* Named streams, so that no two consumers alias by accident. */
enum {
    PS_STREAM_CAUSTIC = 1, /* caustic-map photons */
    PS_STREAM_GLOBAL = 2,  /* global-map photons */
    PS_STREAM_PIXEL = 3,   /* eye rays of the reference renderer */
    PS_STREAM_TEST = 99    /* tests */
};

/* PCG32 (O'Neill 2014): 64-bit LCG state, xorshift-rotate output. The
 * increment (odd) is derived from the stream and index so that the sequences of
 * neighbouring indices are unrelated, not shifted copies of one another. */
typedef struct ps_rng {
    uint64_t state;
    uint64_t inc;
} ps_rng;

/* The generator for item `index` of `stream` under `seed`. Pure: equal
 * arguments give equal sequences on every platform. */
ps_rng ps_rng_make(uint64_t seed, uint32_t stream, uint64_t index);

/* A 64-bit mixing function (SplitMix64's finaliser), exposed for hashing. */
uint64_t ps_hash64(uint64_t x);

static inline uint32_t ps_rng_u32(ps_rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31u));
}

/* Uniform in [0, 1): 53 random bits, so never exactly 1. */
static inline double ps_rng_uniform(ps_rng *r)
{
    uint64_t hi = ps_rng_u32(r), lo = ps_rng_u32(r);
    uint64_t bits = ((hi << 32) | lo) >> 11;
    return (double)bits * (1.0 / 9007199254740992.0); /* 2^-53 */
}

/* Uniform integer in [0, n) without modulo bias (Lemire's method); n > 0. */
uint32_t ps_rng_below(ps_rng *r, uint32_t n);

/* Radical inverse of index in the given prime base: the Halton sequence's
 * coordinate for that base. Always in [0, 1). base >= 2. */
double ps_radical_inverse(unsigned base, uint64_t index);

/* The d-th prime (d = 0 gives 2), for Halton dimensions; d < PS_HALTON_MAX_DIM. */
#define PS_HALTON_MAX_DIM 32
unsigned ps_halton_prime(unsigned dim);

/* Halton point `index` in dimension `dim` (base = dim-th prime). */
static inline double ps_halton(unsigned dim, uint64_t index) { return ps_radical_inverse(ps_halton_prime(dim), index); }

#endif
