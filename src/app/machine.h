/* machine.h: what photosplat-bench measures of the machine it runs on, beside
 * its checkpoints, so that runs on different machines can be told apart.
 *
 * A checkpoint's seconds are the machine's as much as the code's. The build
 * whose full bench landed 41 of its 48 first checkpoints (0.05 s) on time on
 * one machine landed 5-15 of them in nine runs on another of the same kind
 * (2026-12-06). There bench_photon traced 1.29 M paths a processor-second
 * against the README's 1.9 M, and a first write to memory cost 3.0-3.4 ms a
 * 2 MiB page and 9.3 us a 4 KiB one, where memory freed a moment before
 * cost 0.12 ms a 2 MiB page: the machines are virtual, their host backs a
 * page only when it is first written and takes freed memory back within a
 * minute. The default box's first view (its shadow maps, llvmpipe's bins and
 * buffers) grew the process by 29-34 MiB, and under perf, zeroing those
 * pages was 0.036-0.041 s of it; the view took 0.046-0.076 s, and drawn a
 * second time in the same process 0.009-0.015 s. So the first checkpoints
 * there mostly measure first writes and llvmpipe's first use of each state,
 * which no pacing can move. Memory figures are of new memory when measured:
 * memory another process freed a moment before costs less (0.06-0.6 ms a
 * MiB right after a run). */
#ifndef PS_APP_MACHINE_H
#define PS_APP_MACHINE_H

#include <stddef.h>

#include "core/status.h"

typedef struct ps_machine {
    char cpu[128];           /* the processor's model name ("" unknown) */
    long cores;              /* online cores (ps_online_cores) */
    double load;             /* the 1-minute load average when measured (< 0: unknown) */
    double paths_per_second; /* the scene's photon paths traced a second on one thread */
    double fresh_ms_per_mib; /* first writes to memory never written, in 2 MiB pages where
                              * the kernel gives them: milliseconds a MiB (0: not measured) */
    double fault_us;         /* the first write to a 4 KiB page: microseconds (0: not measured) */
} ps_machine;

/* The memory written for fresh_ms_per_mib and for fault_us. */
#define PS_MACHINE_FRESH_BYTES ((size_t)32 * 1024 * 1024)
#define PS_MACHINE_FAULT_BYTES ((size_t)4 * 1024 * 1024)
/* The global photons traced for paths_per_second, best of PS_MACHINE_REPEATS
 * (a run that lost the processor says nothing of the machine). */
#define PS_MACHINE_PATHS 65536
#define PS_MACHINE_REPEATS 3

/* Measures the machine: memory first (before this process has freed any for
 * the kernel to give back), then photon paths of the scene at scene_path:
 * about 0.25 s on the machines above. PS_OK, or the scene's error. */
ps_status ps_machine_measure(const char *scene_path, ps_machine *out, ps_error *err);

/* One line for a reader: "AMD EPYC, 2 cores, load 0.14; one core traces
 * 1.40 M photon paths a second (cornell-caustic); first writes to new memory
 * cost 1.59 ms a MiB (2 MiB pages), 11.1 us a 4 KiB page". scene_name names
 * the scene traced. */
void ps_machine_describe(const ps_machine *m, const char *scene_name, char *buf, size_t size);

#endif
