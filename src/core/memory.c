/* memory.c: the memory budget (see memory.h). */
#include "core/memory.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

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
