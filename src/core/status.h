/* status.h: status codes and the one-line error record every module reports through. */
#ifndef PS_CORE_STATUS_H
#define PS_CORE_STATUS_H

#include <stddef.h>

/* What went wrong, coarsely; the message says exactly what. Programs map any
 * status other than PS_OK caused by input to exit status 2. */
typedef enum ps_status {
    PS_OK = 0,
    PS_ERR_IO,     /* a file could not be opened, read or written */
    PS_ERR_PARSE,  /* text input is malformed (scene, OBJ, MTL, options) */
    PS_ERR_FORMAT, /* binary input is malformed or unsupported (PNG, PFM) */
    PS_ERR_RANGE,  /* a value is well formed but outside what it may be */
    PS_ERR_LIMIT,  /* input is valid but too large for this machine or program */
    PS_ERR_NOMEM,  /* an allocation failed */
    PS_ERR_INTERRUPTED /* the caller's cancel flag was raised (a signal): work stopped early */
} ps_status;

/* Long enough for a path plus a sentence; longer messages are truncated. */
#define PS_ERROR_MSG_MAX 1024

/* An error is one line: "file:line: problem" where a line exists, "file: problem"
 * otherwise. It never contains a newline (ps_error_set replaces them), so a
 * program can print it as the single line the contract promises. */
typedef struct ps_error {
    ps_status status;
    /* The line the message starts with ("file:line: problem"), set by
     * ps_error_at; 0 when the message names no line. A caller that needs to
     * know where a problem lies reads this, never the text. */
    int line;
    char msg[PS_ERROR_MSG_MAX];
} ps_error;

/* Records status and a printf-style message in err (err may be NULL) and returns
 * status, so that callers can write `return ps_error_set(err, ...)`. The
 * message names no line of its own (line 0). */
ps_status ps_error_set(ps_error *err, ps_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* The located form: "file:line: " and the printf-style message, with line
 * (> 0) kept in err->line. */
ps_status ps_error_at(ps_error *err, ps_status status, const char *file, int line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* Resets err to PS_OK with an empty message (err may be NULL). */
void ps_error_clear(ps_error *err);

/* A short English name for a status ("parse error"). */
const char *ps_status_name(ps_status status);

/* Where non-fatal diagnostics (a missing MTL, a clamped value) go. The message is
 * one line without a newline, in the same "file:line: problem" form. A NULL
 * function means: print "warning: <msg>" to stderr. */
typedef void (*ps_warn_fn)(void *user, const char *msg);

typedef struct ps_warn_sink {
    ps_warn_fn fn;
    void *user;
} ps_warn_sink;

void ps_warn(const ps_warn_sink *sink, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#endif
