/* memory.h: the memory budget every large allocation is checked against
 * before it is made, so that a photon count or image size that would not fit
 * is refused with a message instead of ending in a failed allocation midway
 * or the kernel's out-of-memory killer (Linux overcommits: malloc succeeds and
 * the pages fail later). */
#ifndef PS_CORE_MEMORY_H
#define PS_CORE_MEMORY_H

#include <stdint.h>

#include "core/status.h"

/* The budget is this fraction of physical memory: the rest is for the
 * system, the GL driver and what the estimates below leave out. */
#define PS_MEMORY_FRACTION 0.75
/* An environment variable that sets the budget in bytes instead (a number
 * with an optional K, M or G suffix, powers of 1024). Tests use it to check
 * the refusals without allocating gigabytes. */
#define PS_MEMORY_LIMIT_ENV "PS_MEMORY_LIMIT"

/* The budget in bytes: PS_MEMORY_LIMIT_ENV when set and valid, else
 * PS_MEMORY_FRACTION of physical memory (UINT64_MAX when that is unknown).
 * Read from the environment on each call: no state is kept. */
uint64_t ps_memory_budget(void);

/* Parses a PS_MEMORY_LIMIT_ENV value ("512M"); false when it is not a
 * positive size. */
int ps_memory_parse_size(const char *text, uint64_t *out);

/* a * b, saturating at UINT64_MAX (estimates must not wrap to small). */
uint64_t ps_memory_mul(uint64_t a, uint64_t b);

/* PS_OK when `bytes` fit in the budget; otherwise PS_ERR_LIMIT with the
 * one-line message "WHO: WHAT needs N GiB, more than the memory budget of
 * M GiB (...)". `who` names the program or file (NULL: no "WHO: "), `what`
 * the thing. */
ps_status ps_memory_check(uint64_t bytes, const char *who, const char *what, ps_error *err);

/* For long sessions (the window, snap --script): blocks from this size up
 * are mapped on their own and unmapped when freed, whatever their history.
 * glibc raises that threshold to the size of each large block freed (up to
 * 32 MiB), after which a session's maps, repair tables and splat arrays came
 * from the heap and stayed there: `make soak`'s resident memory grew 10-15
 * MiB over 187 s (limit 12.5) with the repair's arrays of 2026-12-03, 1.4
 * MiB with the threshold fixed, at the cost of first-touch faults on each
 * new large block (a move's update 0.017-0.038 -> 0.029-0.049 s at 10^6 photons).
 * Elsewhere (no glibc) nothing. */
#define PS_MEMORY_MAP_THRESHOLD (128 * 1024)
void ps_memory_map_large_blocks(void);

#endif
