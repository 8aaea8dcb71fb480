/* memory.h: the memory budget every large allocation is checked against
 * before it is made, so that a photon count or image size that would not fit
 * is refused with a message instead of ending in a failed allocation midway
 * or the kernel's out-of-memory killer (Linux overcommits: malloc succeeds and
 * the pages fail later). */
#ifndef PS_CORE_MEMORY_H
#define PS_CORE_MEMORY_H

#include <stddef.h>
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

/* The allocator's policy for the programs that draw (the window and snap),
 * two settings (glibc; elsewhere nothing):
 *
 * Blocks from PS_MEMORY_MAP_THRESHOLD up are mapped on their own and
 * unmapped when freed, whatever their history. glibc raises that threshold
 * to the size of each large block freed (up to 32 MiB), after which a
 * session's maps, repair tables and splat arrays came from the heap and
 * stayed there: `make soak`'s resident memory grew 10-15 MiB over 187 s
 * (limit 12.5) with the repair's arrays of 2026-12-03, 1.4 MiB with the
 * threshold fixed, at the cost of first-touch faults on each new large block
 * (a move's update 0.017-0.038 -> 0.029-0.049 s at 10^6 photons).
 *
 * Up to PS_MEMORY_TRIM_THRESHOLD of freed memory at the heap's top stays
 * with the process. Fixing the first setting fixes glibc's trim threshold
 * too, at 128 KiB, and llvmpipe frees the bins of every scene it draws
 * (blocks under the map threshold, from the heap): the heap's top went back
 * to the kernel after each draw and the next faulted it in again, zeroed.
 * The window orbiting over 1.25*10^6 photons at 512^2 (scripts/bench-window.sh
 * orbit, six runs each, alternating): a moving frame 47-83 ms, the full
 * picture 1.70-2.02 s after the stop; with 64 MiB kept 31-40 ms and
 * 1.20-1.48 s (4 MiB, set from outside: 34-36 ms, 1.6-1.8 s).
 * What is kept is reused by the next draw: `make soak` stays flat (-0.3 and
 * +3.7 MiB over 181 s) about 60 MiB higher (275-280 MiB at the end against
 * 214). At 16 MiB the kept top filled over the session and the soak failed,
 * +16.4 MiB. */
#define PS_MEMORY_MAP_THRESHOLD (128 * 1024)
#define PS_MEMORY_TRIM_THRESHOLD (64 * 1024 * 1024)
void ps_memory_set_drawing_policy(void);

/* photosplat-snap's allocator (glibc on Linux; elsewhere, and under ASan,
 * ps_memory_set_drawing_policy): the heap grown at once by `bytes` (at most
 * a quarter of the memory budget), advised for 2 MiB pages, and every block
 * under PS_MEMORY_HEAP_MAP_THRESHOLD (glibc's largest) served from it, so
 * that the first write to each 2 MiB is one page fault instead of 512:
 * llvmpipe's textures, shadow maps and bins, the splat arrays, the specular
 * layer's lookups. A 4 KiB page's fault costs about 10 us on these machines,
 * and the default box's first picture at 256^2 wrote some 40 MiB never
 * touched before: 10 700 faults, 0.22-0.25 s; from such a heap 390,
 * 0.12-0.18 s. What is never written stays virtual; freed memory goes back
 * to the kernel only past `bytes` + PS_MEMORY_TRIM_THRESHOLD at the heap's
 * top, so that the advised part stays the heap's. With 256 MiB the area
 * box's sixteen virtual lights' shadow cubes (16 x 5 faces of 4 MiB,
 * counted, not measured) faulted past it and took 0.83 s, 0.26 s within
 * 1 GiB. snap only (and not its 8-bit --time runs without checkpoints,
 * snap_main.c): a run of seconds may keep what it touched; the window keeps
 * ps_memory_set_drawing_policy, with which the soak finds its memory flat
 * (docs/soak.md). */
#define PS_MEMORY_HEAP_MAP_THRESHOLD (32 * 1024 * 1024)
#define PS_MEMORY_SNAP_HEAP ((size_t)1024 * 1024 * 1024)
void ps_memory_reserve_large_heap(size_t bytes);

/* The large page the kernel backs advised memory with (x86-64's 2 MiB
 * transparent huge page): snap's heap and large arrays are aligned to it, and
 * photosplat-bench times first writes in it (app/machine.h). */
#define PS_MEMORY_LARGE_PAGE ((size_t)2 * 1024 * 1024)

/* Large arrays that the kernel may back with 2 MiB pages (Linux's
 * transparent huge pages, which it gives to memory advised for them, as
 * here): the first write to each 2 MiB is one page fault instead of 512. A
 * fault costs about 10 us on these machines (4 MiB written the first time:
 * 10.6 ms in 4 KiB pages, 0.4 ms in 2 MiB ones), and a refresh that draws
 * more splats than any before writes them (108 bytes a triangle splat) into
 * pages never touched. From PS_MEMORY_LARGE_MIN bytes an array is a mapping
 * of its own, aligned to 2 MiB; below, malloc's (and always under ASan). */
#define PS_MEMORY_LARGE_MIN (4 * 1024 * 1024)

/* p (allocated by this function with old_bytes, or NULL with 0) grown to
 * new_bytes >= old_bytes, its contents kept; NULL (p untouched) when out of
 * memory. Freed only by ps_memory_large_free with the same byte count. */
void *ps_memory_large_realloc(void *p, size_t old_bytes, size_t new_bytes);
void ps_memory_large_free(void *p, size_t bytes);

#endif
