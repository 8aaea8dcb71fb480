/* hash.h: a hash of a few 32-bit words, for open-addressing tables keyed by
 * exact bits (vertices that must be equal bit for bit). FNV-1a's constants,
 * with a shift that mixes high bits into the low ones the tables index by. */
#ifndef PS_CORE_HASH_H
#define PS_CORE_HASH_H

#include <stddef.h>
#include <stdint.h>

static inline uint64_t ps_hash_words(const uint32_t *w, size_t n, uint64_t seed)
{
    uint64_t h = 1469598103934665603ull ^ seed;
    for (size_t i = 0; i < n; i++) {
        h ^= w[i];
        h *= 1099511628211ull;
        h ^= h >> 29;
    }
    return h;
}

#endif
