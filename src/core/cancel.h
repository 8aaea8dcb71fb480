/* cancel.h: how long-running work is asked to stop early. The program owns
 * the flag (its SIGINT/SIGTERM handler raises it, src/app/interrupt.c); the
 * library only reads it, between units of work (tiles, photon chunks), and
 * then returns PS_ERR_INTERRUPTED. sig_atomic_t is what a handler may set. */
#ifndef PS_CORE_CANCEL_H
#define PS_CORE_CANCEL_H

#include <signal.h>

typedef volatile sig_atomic_t ps_cancel_flag;

/* Whether work should stop: c is non-NULL and raised. */
static inline int ps_cancelled(const ps_cancel_flag *c) { return c && *c != 0; }

#endif
