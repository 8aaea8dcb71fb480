/* number.h: strict text-to-number conversion shared by every parser. */
#ifndef PS_CORE_NUMBER_H
#define PS_CORE_NUMBER_H

#include <stdbool.h>
#include <stdint.h>

/* The whole of s must be the number (no trailing junk); NaN, infinities and
 * values that overflow a double are refused. */
bool ps_parse_double(const char *s, double *out);
/* A decimal integer that fits in int64_t, the whole of s. */
bool ps_parse_int64(const char *s, int64_t *out);

#endif
