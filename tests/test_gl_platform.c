/* test_gl_platform.c: photosplat-snap's context backend (platform_osmesa.c):
 * the buffer it opens and reads back, and llvmpipe's optimisation passes left
 * out (GALLIVM_PERF=nopt) unless the user chose GALLIVM_PERF. That the
 * pictures are the same bytes either way is cli_snap.sh's check. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "gl/gl_api.h"
#include "gl/platform.h"

#define PERF_ENV "GALLIVM_PERF"

static ps_platform *open_platform(int w, int h, bool float_buffer)
{
    ps_platform_config c = {w, h, float_buffer, "test"};
    ps_platform *p = NULL;
    ps_error err;
    if (ps_platform_open(&c, &p, &err) != PS_OK)
        fail_msg("platform: %s", err.msg);
    return p;
}

/* Mesa reads the variable once, at its first context; whatever it read, the
 * environment after each open is what a later one would read. */
static void fast_compiles_unless_the_user_chose(void **state)
{
    (void)state;
    unsetenv(PERF_ENV);
    ps_platform *p = open_platform(8, 8, false);
    const char *v = getenv(PERF_ENV);
    assert_non_null(v);
    assert_string_equal(v, "nopt");
    ps_platform_close(p);

    const char *chosen[] = {"", "brilinear", "nopt,rho_approx"};
    for (size_t i = 0; i < sizeof chosen / sizeof chosen[0]; i++) {
        setenv(PERF_ENV, chosen[i], 1);
        p = open_platform(8, 8, false);
        v = getenv(PERF_ENV);
        assert_non_null(v);
        assert_string_equal(v, chosen[i]);
        ps_platform_close(p);
    }
    unsetenv(PERF_ENV);
}

/* The size asked for, and a cleared float buffer read back as stored. */
static void float_buffer_read_as_stored(void **state)
{
    (void)state;
    ps_platform *p = open_platform(5, 3, true);
    int w = 0, h = 0;
    ps_platform_size(p, &w, &h);
    assert_int_equal(w, 5);
    assert_int_equal(h, 3);
    glClearColor(0.25f, 1.5f, 3.0f, 1.0f); /* above 1: a float buffer keeps it */
    glClear(GL_COLOR_BUFFER_BIT);
    ps_image img;
    ps_error err;
    if (ps_platform_read(p, &img, &err) != PS_OK)
        fail_msg("read: %s", err.msg);
    assert_int_equal(img.width, 5);
    assert_int_equal(img.height, 3);
    for (int i = 0; i < 5 * 3; i++) {
        assert_true(img.rgb[3 * i] == 0.25f);
        assert_true(img.rgb[3 * i + 1] == 1.5f);
        assert_true(img.rgb[3 * i + 2] == 3.0f);
    }
    ps_image_destroy(&img);
    ps_platform_close(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fast_compiles_unless_the_user_chose),
        cmocka_unit_test(float_buffer_read_as_stored),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
