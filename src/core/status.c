/* status.c: formatting of one-line errors and warnings. */
#include "core/status.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* Messages are printed as exactly one line, so a path or token that carries a
 * newline or other control character must not break it. */
static void flatten(char *s)
{
    for (; *s; s++)
        if ((unsigned char)*s < 0x20 || *s == 0x7f)
            *s = ' ';
}

ps_status ps_error_set(ps_error *err, ps_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        flatten(err->msg);
        err->status = status;
        err->line = 0;
    }
    return status;
}

ps_status ps_error_at(ps_error *err, ps_status status, const char *file, int line, const char *fmt, ...)
{
    if (err) {
        int n = snprintf(err->msg, sizeof err->msg, "%s:%d: ", file, line);
        if (n >= 0 && (size_t)n < sizeof err->msg) {
            va_list ap;
            va_start(ap, fmt);
            vsnprintf(err->msg + n, sizeof err->msg - (size_t)n, fmt, ap);
            va_end(ap);
        }
        flatten(err->msg);
        err->status = status;
        err->line = line;
    }
    return status;
}

void ps_error_clear(ps_error *err)
{
    if (err) {
        err->status = PS_OK;
        err->line = 0;
        err->msg[0] = '\0';
    }
}

const char *ps_status_name(ps_status status)
{
    switch (status) {
    case PS_OK: return "ok";
    case PS_ERR_IO: return "i/o error";
    case PS_ERR_PARSE: return "parse error";
    case PS_ERR_FORMAT: return "format error";
    case PS_ERR_RANGE: return "value out of range";
    case PS_ERR_LIMIT: return "too large";
    case PS_ERR_NOMEM: return "out of memory";
    case PS_ERR_INTERRUPTED: return "interrupted";
    }
    return "unknown error";
}

void ps_warn(const ps_warn_sink *sink, const char *fmt, ...)
{
    char msg[PS_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    flatten(msg);
    if (sink && sink->fn)
        sink->fn(sink->user, msg);
    else
        fprintf(stderr, "warning: %s\n", msg);
}
