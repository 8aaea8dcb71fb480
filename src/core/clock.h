/* clock.h: the clocks every module and benchmark times itself with: seconds
 * on the monotonic clock (never set back, unlike the wall clock), and
 * processor time, as doubles. */
#ifndef PS_CORE_CLOCK_H
#define PS_CORE_CLOCK_H

/* Seconds since an arbitrary fixed point; only differences mean anything. */
double ps_now_seconds(void);

/* Processor time, for benchmarks on a shared machine: what the work cost,
 * whatever else shared the cores meanwhile. The calling thread's, and all of
 * the process's threads together. */
double ps_thread_cpu_seconds(void);
double ps_process_cpu_seconds(void);

#endif
