/* array.h: overflow-checked growth of plain C arrays. */
#ifndef PS_CORE_ARRAY_H
#define PS_CORE_ARRAY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/memory.h"

/* Makes room for at least `need` elements of `elem` bytes in *p (capacity in
 * *cap, grown geometrically). False, with *p untouched, when the size would
 * overflow or the allocation fails: callers report PS_ERR_NOMEM and keep a
 * valid structure, never a half-grown one. `large`: for arrays that grow
 * large and are written soon after, grown by ps_memory_large_realloc
 * (core/memory.h) and freed with ps_memory_large_free(p, cap * elem). */
static inline bool ps_array_reserve_as(void **p, size_t *cap, size_t need, size_t elem, bool large)
{
    if (need <= *cap)
        return true;
    size_t n = *cap ? *cap : 16;
    while (n < need) {
        if (n > SIZE_MAX / 2)
            return false;
        n *= 2;
    }
    if (elem && n > SIZE_MAX / elem)
        return false;
    void *q = large ? ps_memory_large_realloc(*p, *cap * elem, n * elem) : realloc(*p, n * elem);
    if (!q)
        return false;
    *p = q;
    *cap = n;
    return true;
}

static inline bool ps_array_reserve(void **p, size_t *cap, size_t need, size_t elem)
{
    return ps_array_reserve_as(p, cap, need, elem, false);
}

/* ps_array_reserve for a typed pointer: PS_RESERVE(arr, cap, need). */
#define PS_RESERVE(ptr, cap, need) ps_array_reserve((void **)&(ptr), &(cap), (need), sizeof *(ptr))
/* ... and ps_array_reserve_as: PS_RESERVE_AS(arr, cap, need, large). */
#define PS_RESERVE_AS(ptr, cap, need, large) ps_array_reserve_as((void **)&(ptr), &(cap), (need), sizeof *(ptr), (large))

#endif
