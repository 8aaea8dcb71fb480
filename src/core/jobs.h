/* jobs.h: a count of independent jobs run on a few threads, dealt
 * round-robin (job j on thread j mod threads). What a job computes must not
 * depend on which thread runs it: callers that gather results write them
 * into per-job slots and join them in job order, so the bytes are the same
 * for any thread count. */
#ifndef PS_CORE_JOBS_H
#define PS_CORE_JOBS_H

#include <stddef.h>

/* Threads a run uses at most. */
#define PS_JOBS_MAX_THREADS 64

typedef void (*ps_job_fn)(void *ctx, size_t job);

/* Jobs 0..count-1 on up to `threads` threads (values below 1 run on one),
 * the calling thread among them. Where a thread cannot be started its share
 * runs on the caller. Returns when every job has run. */
void ps_run_jobs(size_t count, int threads, ps_job_fn fn, void *ctx);

#endif
