/* jobs.c: jobs on a few threads (jobs.h). */
#define _GNU_SOURCE /* gettid: a thread's own nice value (Linux) */
#include "core/jobs.h"

#include <errno.h>
#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

typedef struct job_list {
    ps_job_fn fn;
    void *ctx;
    size_t first, step, count;
} job_list;

static void *job_thread(void *arg)
{
    const job_list *l = arg;
    for (size_t j = l->first; j < l->count; j += l->step)
        l->fn(l->ctx, j);
    return NULL;
}

void ps_run_jobs(size_t count, int threads, ps_job_fn fn, void *ctx)
{
    if (threads > PS_JOBS_MAX_THREADS)
        threads = PS_JOBS_MAX_THREADS;
    if ((size_t)threads > count)
        threads = (int)count;
    if (threads < 1)
        threads = 1;
    job_list lists[PS_JOBS_MAX_THREADS];
    pthread_t tid[PS_JOBS_MAX_THREADS];
    int started = 1; /* thread 0's share runs here */
    for (int t = 0; t < threads; t++)
        lists[t] = (job_list){fn, ctx, (size_t)t, (size_t)threads, count};
    while (started < threads && pthread_create(&tid[started], NULL, job_thread, &lists[started]) == 0)
        started++;
    for (int t = started; t < threads; t++) /* no threads to be had: their shares here */
        job_thread(&lists[t]);
    job_thread(&lists[0]);
    for (int t = 1; t < started; t++)
        pthread_join(tid[t], NULL);
}

void ps_thread_low_priority(void)
{
    /* Never higher than it was (a process started nicer stays so). */
    id_t self = (id_t)gettid();
    errno = 0;
    int was = getpriority(PRIO_PROCESS, self);
    if (errno == 0 && was < PS_THREAD_LOW_NICE)
        setpriority(PRIO_PROCESS, self, PS_THREAD_LOW_NICE);
}
