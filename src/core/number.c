/* number.c: strict number parsing. */
#include "core/number.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>

bool ps_parse_double(const char *s, double *out)
{
    char *end;
    double v = strtod(s, &end);
    /* strtod accepts "nan" and "inf" and returns ±HUGE_VAL on overflow: all are
     * refused by the isfinite test. Underflow to a denormal or zero is fine. */
    if (end == s || *end != '\0' || !isfinite(v))
        return false;
    *out = v;
    return true;
}

bool ps_parse_int64(const char *s, int64_t *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end != '\0' || errno == ERANGE)
        return false;
    *out = (int64_t)v;
    return true;
}
