/* clock.c: the monotonic clock (clock.h). */
#include "core/clock.h"

#include <time.h>

static double seconds_of(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double ps_now_seconds(void) { return seconds_of(CLOCK_MONOTONIC); }
double ps_thread_cpu_seconds(void) { return seconds_of(CLOCK_THREAD_CPUTIME_ID); }
double ps_process_cpu_seconds(void) { return seconds_of(CLOCK_PROCESS_CPUTIME_ID); }
