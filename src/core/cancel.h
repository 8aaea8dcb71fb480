/* cancel.h: how long-running work is asked to stop early. The program owns
 * the flag (its SIGINT/SIGTERM handler raises it, src/app/interrupt.c); the
 * library only reads it, from worker threads, between units of work (tiles,
 * photon chunks), and then returns PS_ERR_INTERRUPTED.
 *
 * The flag is a C11 atomic int: threads other than the one that took the
 * signal read it, which a volatile sig_atomic_t does not make well defined,
 * and a signal handler may store to a lock-free atomic object (C11 7.14.1.1),
 * which the assertion below makes sure of. 0: not raised; otherwise the
 * number of the signal that raised it. */
#ifndef PS_CORE_CANCEL_H
#define PS_CORE_CANCEL_H

#include <stdatomic.h>

typedef atomic_int ps_cancel_flag;

_Static_assert(ATOMIC_INT_LOCK_FREE == 2, "a signal handler may only store to a lock-free atomic");

/* Whether work should stop: c is non-NULL and raised. Relaxed: the flag
 * carries no data with it, and a worker that sees it one chunk late only
 * stops one chunk later. */
static inline int ps_cancelled(const ps_cancel_flag *c)
{
    return c && atomic_load_explicit(c, memory_order_relaxed) != 0;
}

#endif
