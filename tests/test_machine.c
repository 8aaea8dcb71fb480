/* test_machine.c: what photosplat-bench measures of its machine
 * (app/machine.h): every figure there and plausible, the line that says it,
 * and a scene that does not load refused as any other. */
#include "test.h"

#include <string.h>

#include "app/machine.h"

static void measures_every_figure(void **state)
{
    (void)state;
    ps_machine m;
    ps_error err;
    assert_int_equal(ps_machine_measure("tests/data/good/diffuse-box.scn", &m, &err), PS_OK);
    assert_true(m.cores >= 1);
    /* One core traces thousands of a closed box's paths a second at least
     * (1-2 M here; the sanitizer build a few times fewer). */
    assert_true(m.paths_per_second > 1e4 && isfinite(m.paths_per_second));
#ifdef __linux__
    assert_true(m.load >= 0.0);
    /* A MiB written once takes more than nothing and less than a second. */
    assert_true(m.fresh_ms_per_mib > 0.0 && m.fresh_ms_per_mib < 1e3);
    assert_true(m.fault_us > 0.0 && m.fault_us < 1e6);
#endif
    char line[512];
    ps_machine_describe(&m, "diffuse-box", line, sizeof line);
    assert_non_null(strstr(line, "M photon paths a second (diffuse-box)"));
    assert_non_null(strstr(line, " cores"));
    /* The processor's name where the system gives one, and says so where not. */
    const char *cpu = m.cpu[0] ? m.cpu : "processor unknown";
    assert_int_equal(strncmp(line, cpu, strlen(cpu)), 0);
#ifdef __linux__
    assert_non_null(strstr(line, "ms a MiB (2 MiB pages)"));
    assert_non_null(strstr(line, "us a 4 KiB page"));
#endif
}

/* Unknown figures are said as such, not printed as zeros or garbage. */
static void describes_what_is_unknown(void **state)
{
    (void)state;
    ps_machine m;
    memset(&m, 0, sizeof m);
    m.cores = 2;
    m.load = -1.0;
    m.paths_per_second = 1.5e6;
    char line[512];
    ps_machine_describe(&m, "box", line, sizeof line);
    assert_string_equal(line, "processor unknown, 2 cores; one core traces 1.50 M photon paths a second (box)");
}

static void refuses_a_missing_scene(void **state)
{
    (void)state;
    ps_machine m;
    ps_error err;
    assert_int_not_equal(ps_machine_measure("tests/data/good/none.scn", &m, &err), PS_OK);
    assert_non_null(strstr(err.msg, "none.scn"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(measures_every_figure),
        cmocka_unit_test(describes_what_is_unknown),
        cmocka_unit_test(refuses_a_missing_scene),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
