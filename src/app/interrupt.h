/* interrupt.h: SIGINT and SIGTERM stop a long run cleanly. The handler only
 * raises a flag (the one piece of process state the programs keep); the
 * renderer and tracer read it between tiles and photon chunks and return
 * PS_ERR_INTERRUPTED, and the program says how far it got, writes nothing
 * and exits 128 + the signal's number (130 for SIGINT, 143 for SIGTERM), as
 * shells report a program killed by that signal. */
#ifndef PS_APP_INTERRUPT_H
#define PS_APP_INTERRUPT_H

#include "core/cancel.h"
#include "core/status.h"

/* Exit status base for a signal: 128 + its number (POSIX shells' convention). */
#define PS_EXIT_SIGNAL_BASE 128

/* Installs the handlers and returns the flag: 0 until a signal arrives, then
 * its number. A second signal ends the program at once (the handlers reset
 * after the first), so a stuck stage can still be stopped. Also ignores
 * SIGXFSZ and SIGPIPE, so that a write past a file-size limit or into a
 * closed pipe fails and is reported like any failed write (and the temporary
 * file is removed) instead of killing the program midway. */
const ps_cancel_flag *ps_interrupt_install(void);

/* The exit status for the signal that raised the flag (130 when none did). */
int ps_interrupt_exit_status(void);

/* Prints "PROG: MESSAGE; nothing written" (err's message says how far the
 * run got) on stderr and returns ps_interrupt_exit_status(). */
int ps_interrupt_fail(const char *prog, const ps_error *err);

#endif
