/* memory.c: the memory budget (see memory.h). */
/* MAP_ANONYMOUS and MADV_HUGEPAGE are Linux's, past POSIX. */
#define _GNU_SOURCE
#include "core/memory.h"

#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <sys/mman.h>

#define BYTES_PER_MIB (1024.0 * 1024.0)
#define BYTES_PER_GIB (1024.0 * BYTES_PER_MIB)

void ps_memory_set_drawing_policy(void)
{
#ifdef __GLIBC__
    /* Setting either turns glibc's own adjustment of both off. */
    (void)mallopt(M_MMAP_THRESHOLD, PS_MEMORY_MAP_THRESHOLD);
    (void)mallopt(M_TRIM_THRESHOLD, PS_MEMORY_TRIM_THRESHOLD);
#endif
}

/* Not under ASan: mappings of our own would hide these arrays' bounds from it. */
#if defined(__linux__) && defined(MADV_HUGEPAGE) && !defined(__SANITIZE_ADDRESS__)
#define HAVE_LARGE_PAGES 1
#endif

/* glibc's default pad of a heap's growth (M_TOP_PAD), put back afterwards. */
#define GLIBC_TOP_PAD (128 * 1024)

void ps_memory_reserve_large_heap(size_t bytes)
{
#if defined(__GLIBC__) && defined(HAVE_LARGE_PAGES)
    uint64_t quarter = ps_memory_budget() / 4;
    if (bytes > quarter)
        bytes = (size_t)quarter;
    if (bytes > (size_t)INT_MAX - PS_MEMORY_TRIM_THRESHOLD) /* mallopt's int */
        bytes = (size_t)INT_MAX - PS_MEMORY_TRIM_THRESHOLD;
    (void)mallopt(M_MMAP_THRESHOLD, PS_MEMORY_HEAP_MAP_THRESHOLD);
    (void)mallopt(M_TRIM_THRESHOLD, (int)(bytes + PS_MEMORY_TRIM_THRESHOLD));
    /* A block larger than the heap's free top makes glibc grow the heap by
     * what it lacks and the pad (sbrk); freed, the block joins the top. */
    size_t top = mallinfo2().keepcost, want = top + PS_MEMORY_LARGE_PAGE;
    if (want >= PS_MEMORY_HEAP_MAP_THRESHOLD)
        want = PS_MEMORY_HEAP_MAP_THRESHOLD - PS_MEMORY_LARGE_PAGE; /* the top holds most of it already */
    (void)mallopt(M_TOP_PAD, (int)bytes);
    char *block = malloc(want);
    if (block) /* used, so that the compiler keeps the malloc and free it sees paired */
        *(volatile char *)block = 0;
    char *end = sbrk(0);
    (void)mallopt(M_TOP_PAD, GLIBC_TOP_PAD);
    /* Only the heap's end just grown (glibc may map a heap elsewhere when
     * sbrk fails: the block is then not below the break). */
    if (block && end != (char *)-1 && end > block && (size_t)(end - block) <= want + bytes + PS_MEMORY_LARGE_PAGE) {
        uintptr_t from = ((uintptr_t)block + PS_MEMORY_LARGE_PAGE - 1) & ~(uintptr_t)(PS_MEMORY_LARGE_PAGE - 1);
        uintptr_t to = (uintptr_t)end & ~(uintptr_t)(PS_MEMORY_LARGE_PAGE - 1);
        if (to > from)
            (void)madvise((void *)from, to - from, MADV_HUGEPAGE); /* advice: without it, small pages */
    }
    free(block);
#else
    (void)bytes;
    ps_memory_set_drawing_policy();
#endif
}

#ifdef HAVE_LARGE_PAGES

static size_t large_span(size_t bytes)
{
    return (bytes + PS_MEMORY_LARGE_PAGE - 1) / PS_MEMORY_LARGE_PAGE * PS_MEMORY_LARGE_PAGE;
}

/* span bytes (whole large pages) at a large page's boundary, advised: mapped
 * one page longer, the ends beside the boundary given back. */
static void *map_large(size_t span)
{
    if (span > SIZE_MAX - PS_MEMORY_LARGE_PAGE)
        return NULL;
    size_t over = span + PS_MEMORY_LARGE_PAGE;
    char *m = mmap(NULL, over, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED)
        return NULL;
    char *a = (char *)(((uintptr_t)m + PS_MEMORY_LARGE_PAGE - 1) & ~(uintptr_t)(PS_MEMORY_LARGE_PAGE - 1));
    if (a > m)
        munmap(m, (size_t)(a - m));
    if (m + over > a + span)
        munmap(a + span, (size_t)(m + over - (a + span)));
    (void)madvise(a, span, MADV_HUGEPAGE); /* advice: without it, small pages */
    return a;
}

void *ps_memory_large_realloc(void *p, size_t old_bytes, size_t new_bytes)
{
    if (new_bytes < PS_MEMORY_LARGE_MIN)
        return realloc(p, new_bytes);
    size_t span = large_span(new_bytes);
    if (old_bytes >= PS_MEMORY_LARGE_MIN && span <= large_span(old_bytes))
        return p;
    /* A new mapping and a copy: growing one in place (mremap) found the
     * addresses after it taken, mappings being placed downwards. */
    void *q = map_large(span);
    if (!q)
        return NULL;
    if (p)
        memcpy(q, p, old_bytes);
    ps_memory_large_free(p, old_bytes);
    return q;
}

void ps_memory_large_free(void *p, size_t bytes)
{
    if (!p)
        return;
    if (bytes >= PS_MEMORY_LARGE_MIN)
        munmap(p, large_span(bytes));
    else
        free(p);
}
#else
void *ps_memory_large_realloc(void *p, size_t old_bytes, size_t new_bytes)
{
    return p && new_bytes <= old_bytes ? p : realloc(p, new_bytes);
}

void ps_memory_large_free(void *p, size_t bytes)
{
    (void)bytes;
    free(p);
}
#endif

int ps_memory_parse_size(const char *text, uint64_t *out)
{
    if (!text || *text < '0' || *text > '9')
        return 0;
    char *end;
    unsigned long long v = strtoull(text, &end, 10);
    uint64_t unit = 1;
    switch (*end) {
    case 'k': case 'K': unit = 1ull << 10; end++; break;
    case 'm': case 'M': unit = 1ull << 20; end++; break;
    case 'g': case 'G': unit = 1ull << 30; end++; break;
    default: break;
    }
    if (*end != '\0' || v == 0)
        return 0;
    *out = ps_memory_mul(v, unit);
    return 1;
}

uint64_t ps_memory_mul(uint64_t a, uint64_t b)
{
    if (a != 0 && b > UINT64_MAX / a)
        return UINT64_MAX;
    return a * b;
}

uint64_t ps_memory_budget(void)
{
    uint64_t v;
    if (ps_memory_parse_size(getenv(PS_MEMORY_LIMIT_ENV), &v))
        return v;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0)
        return UINT64_MAX;
    return (uint64_t)((double)ps_memory_mul((uint64_t)pages, (uint64_t)page) * PS_MEMORY_FRACTION);
}

/* "1.5 GiB", or "64 MiB" below a GiB. */
static void format_size(uint64_t bytes, char *out, size_t n)
{
    if ((double)bytes >= BYTES_PER_GIB)
        snprintf(out, n, "%.1f GiB", (double)bytes / BYTES_PER_GIB);
    else
        snprintf(out, n, "%.0f MiB", (double)bytes / BYTES_PER_MIB);
}

ps_status ps_memory_check(uint64_t bytes, const char *who, const char *what, ps_error *err)
{
    uint64_t budget = ps_memory_budget(), v;
    if (bytes <= budget)
        return PS_OK;
    char need[32], have[32];
    format_size(bytes, need, sizeof need);
    format_size(budget, have, sizeof have);
    const char *sep = who ? ": " : "";
    who = who ? who : "";
    if (ps_memory_parse_size(getenv(PS_MEMORY_LIMIT_ENV), &v))
        return ps_error_set(err, PS_ERR_LIMIT, "%s%s%s would need %s, more than the memory budget of %s (set by %s)",
                            who, sep, what, need, have, PS_MEMORY_LIMIT_ENV);
    return ps_error_set(err, PS_ERR_LIMIT,
                        "%s%s%s would need %s, more than the memory budget of %s (%.0f %% of physical memory)", who,
                        sep, what, need, have, 100.0 * PS_MEMORY_FRACTION);
}
