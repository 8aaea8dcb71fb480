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
 * overflow or realloc fails: callers report PS_ERR_NOMEM and keep a valid
 * structure, never a half-grown one. */
static inline bool ps_array_reserve(void **p, size_t *cap, size_t need, size_t elem)
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
    void *q = realloc(*p, n * elem);
    if (!q)
        return false;
    *p = q;
    *cap = n;
    return true;
}

/* ps_array_reserve for a typed pointer: PS_RESERVE(arr, cap, need). */
#define PS_RESERVE(ptr, cap, need) ps_array_reserve((void **)&(ptr), &(cap), (need), sizeof *(ptr))

/* ps_array_reserve for arrays that grow large and are written soon after
 * (core/memory.h: ps_memory_large_realloc); freed with
 * ps_memory_large_free(p, cap * elem). */
static inline bool ps_array_reserve_large(void **p, size_t *cap, size_t need, size_t elem)
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
    void *q = ps_memory_large_realloc(*p, *cap * elem, n * elem);
    if (!q)
        return false;
    *p = q;
    *cap = n;
    return true;
}
#define PS_RESERVE_LARGE(ptr, cap, need) ps_array_reserve_large((void **)&(ptr), &(cap), (need), sizeof *(ptr))

#endif
