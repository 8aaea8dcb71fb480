/* test.h: what every test file includes: cmocka and small helpers. */
#ifndef PS_TESTS_TEST_H
#define PS_TESTS_TEST_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

/* |a - b| <= tol, printing both values when it fails. */
#define assert_near(a, b, tol)                                                                                   \
    do {                                                                                                         \
        double a_ = (a), b_ = (b), t_ = (tol);                                                                   \
        if (!(fabs(a_ - b_) <= t_))                                                                              \
            fail_msg("%s = %.17g, expected %s = %.17g within %g", #a, a_, #b, b_, t_);                           \
    } while (0)

/* A scratch directory for files a test writes; created once per process,
 * under build/ so it never litters the source tree. Returns a path joined with
 * name in a static buffer (tests are single-threaded). */
static inline const char *test_path(const char *name)
{
    static char dir[256], buf[1024];
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "build/test-tmp/%ld", (long)getpid());
        mkdir("build", 0777);
        mkdir("build/test-tmp", 0777);
        mkdir(dir, 0777);
    }
    snprintf(buf, sizeof buf, "%s/%s", dir, name);
    return buf;
}

/* Records warnings (a ps_warn_sink's function) so tests can assert on them. */
typedef struct warn_log {
    int count;
    char last[1024];
} warn_log;

static inline void log_warning(void *user, const char *msg)
{
    warn_log *log = user;
    log->count++;
    snprintf(log->last, sizeof log->last, "%s", msg);
}

#endif
