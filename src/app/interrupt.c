/* interrupt.c: the SIGINT/SIGTERM flag (see interrupt.h). */
#include "app/interrupt.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>

/* The one piece of process state: a signal handler has nowhere else to put
 * what it saw. Written only by the handler (a lock-free atomic store, which a
 * handler may make); read by the workers through ps_cancelled. */
static ps_cancel_flag interrupted_by;

static void on_signal(int sig) { atomic_store_explicit(&interrupted_by, sig, memory_order_relaxed); }

const ps_cancel_flag *ps_interrupt_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sigemptyset(&sa.sa_mask);
    sa.sa_handler = on_signal;
    sa.sa_flags = SA_RESETHAND; /* a second signal: the default action, at once */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGXFSZ, SIG_IGN);
    signal(SIGPIPE, SIG_IGN);
    return &interrupted_by;
}

int ps_interrupt_exit_status(void)
{
    int sig = atomic_load_explicit(&interrupted_by, memory_order_relaxed);
    return PS_EXIT_SIGNAL_BASE + (sig ? sig : SIGINT);
}

int ps_interrupt_fail(const char *prog, const ps_error *err)
{
    fprintf(stderr, "%s: %s; nothing written\n", prog, err->msg[0] ? err->msg : "interrupted");
    return ps_interrupt_exit_status();
}
