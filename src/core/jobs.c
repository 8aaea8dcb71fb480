/* jobs.c: jobs on a few threads (jobs.h). */
#include "core/jobs.h"

#include <pthread.h>

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
