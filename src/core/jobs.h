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

/* The calling thread, and the threads it starts from then on (they inherit
 * it), a low priority: nice PS_THREAD_LOW_NICE, or its own where that is
 * nicer. Beside a thread that must not wait for them, they take little of
 * a core it wants and all of one it leaves idle. For good: unprivileged, a
 * thread cannot raise it again, so such a thread ends with its work. Not
 * the idle class (SCHED_IDLE): beside two busy loops, the default box's
 * first float checkpoint came at 2.5-2.8 s in two runs of three with its
 * first round on it, at 0.13-0.15 s at nice 10 or at the normal priority. */
#define PS_THREAD_LOW_NICE 10
void ps_thread_low_priority(void);

#endif
