/* rng.c: per-index generators and the Halton radical inverse. */
#include "core/rng.h"

#include <assert.h>

uint64_t ps_hash64(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

ps_rng ps_rng_make(uint64_t seed, uint32_t stream, uint64_t index)
{
    /* Hash all three so that (seed, index) and (seed, index + 1) start far apart
     * in state space and on different LCG increments. */
    uint64_t h = ps_hash64(seed ^ ps_hash64(((uint64_t)stream << 32) ^ 0x5851f42d4c957f2dULL));
    uint64_t k = ps_hash64(h ^ ps_hash64(index));
    ps_rng r;
    r.inc = (ps_hash64(k ^ 0xda3e39cb94b95bdbULL) << 1) | 1u;
    r.state = 0;
    (void)ps_rng_u32(&r);
    r.state += k;
    (void)ps_rng_u32(&r);
    return r;
}

uint32_t ps_rng_below(ps_rng *r, uint32_t n)
{
    assert(n > 0);
    uint64_t m = (uint64_t)ps_rng_u32(r) * n;
    uint32_t low = (uint32_t)m;
    if (low < n) {
        uint32_t threshold = (uint32_t)(-n) % n;
        while (low < threshold) {
            m = (uint64_t)ps_rng_u32(r) * n;
            low = (uint32_t)m;
        }
    }
    return (uint32_t)(m >> 32);
}

static const unsigned primes[PS_HALTON_MAX_DIM] = {
    2,  3,  5,  7,  11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53,
    59, 61, 67, 71, 73, 79, 83, 89, 97, 101, 103, 107, 109, 113, 127, 131};

unsigned ps_halton_prime(unsigned dim)
{
    assert(dim < PS_HALTON_MAX_DIM);
    return primes[dim];
}

/* The radical inverse's loop, inlined into each case of ps_radical_inverse
 * so that for the first primes (the photon emission's Halton dimensions) the
 * division by the base is one by a constant, which the compiler turns into a
 * multiplication: the same integers, so the same result, several times faster. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline double radical_inverse(unsigned base, uint64_t index)
{
    /* Accumulate the reversed digits as an integer and scale once at the end,
     * which is exact. Stop before the integer would overflow: the digits left
     * then lie below double precision of the result anyway. */
    const double inv_base = 1.0 / base;
    const uint64_t limit = UINT64_MAX / base - base;
    uint64_t reversed = 0;
    double inv_base_n = 1.0;
    while (index && reversed < limit) {
        uint64_t next = index / base;
        uint64_t digit = index - next * base;
        reversed = reversed * base + digit;
        inv_base_n *= inv_base;
        index = next;
    }
    double v = (double)reversed * inv_base_n;
    /* Rounding can reach 1.0 for huge indices; the sequence promises [0, 1). */
    return v < 1.0 ? v : 0x1.fffffffffffffp-1;
}

double ps_radical_inverse(unsigned base, uint64_t index)
{
    assert(base >= 2);
    switch (base) {
    case 2: return radical_inverse(2, index);
    case 3: return radical_inverse(3, index);
    case 5: return radical_inverse(5, index);
    case 7: return radical_inverse(7, index);
    case 11: return radical_inverse(11, index);
    case 13: return radical_inverse(13, index);
    default: return radical_inverse(base, index);
    }
}
