/* clock.h: the one clock every module times itself with: seconds on the
 * monotonic clock (never set back, unlike the wall clock), as a double. */
#ifndef PS_CORE_CLOCK_H
#define PS_CORE_CLOCK_H

/* Seconds since an arbitrary fixed point; only differences mean anything. */
double ps_now_seconds(void);

#endif
