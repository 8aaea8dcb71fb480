/* test_options.c: the preview's options (app/options.h) read through the
 * enums' own name tables (and those tables: NULL-terminated, each name() the
 * table's entry): every name of every table sets its value in the
 * typed field, and a name outside a table is refused with the table's names. */
#include "test.h"

#include <string.h>

#include "app/options.h"
#include "photon/estimate.h"
#include "preview/splat.h"

/* Parses `--opt value` into o; PS_OK and err's message as they come. */
static ps_status parse(ps_preview_options *o, const char *opt, const char *value, ps_error *err)
{
    char *argv[] = {"prog", (char *)opt, (char *)value, NULL};
    ps_cli cli = ps_cli_begin("prog", 3, argv);
    ps_status st = PS_OK;
    ps_error_clear(err);
    assert_true(ps_cli_next(&cli));
    assert_true(ps_preview_option(&cli, "prog", o, &st, err));
    assert_false(ps_cli_next(&cli)); /* the value was consumed */
    return st;
}

/* A table's names, NULL after exactly count of them, each its own name(). */
static void check_table(const char *const *names, int count, const char *(*name_of)(int))
{
    for (int k = 0; k < count; k++) {
        assert_non_null(names[k]);
        assert_string_equal(name_of(k), names[k]);
    }
    assert_null(names[count]);
    assert_string_equal(name_of(count), "?");
}

static const char *kernel_of(int k) { return ps_kernel_name((ps_kernel)k); }
static const char *splat_of(int k) { return ps_splat_mode_name((ps_splat_mode)k); }
static const char *precision_of(int k) { return ps_precision_name((ps_precision)k); }
static const char *depth_of(int k) { return ps_color_depth_name((ps_color_depth)k); }
static const char *schedule_of(int k) { return ps_radius_schedule_name((ps_radius_schedule)k); }
static const char *map_of(int k) { return ps_map_name((ps_map_kind)k); }

static void tables(void **state)
{
    (void)state;
    check_table(ps_kernel_names, PS_KERNEL_COUNT, kernel_of);
    check_table(ps_splat_mode_names, PS_SPLAT_MODE_COUNT, splat_of);
    check_table(ps_precision_names, PS_PRECISION_COUNT, precision_of);
    check_table(ps_color_depth_names, PS_COLOR_DEPTH_COUNT, depth_of);
    check_table(ps_radius_schedule_names, PS_RADIUS_SCHEDULE_COUNT, schedule_of);
    check_table(ps_map_names, PS_MAP_COUNT, map_of);
    /* The contract's spellings (command lines and scripts depend on them). */
    assert_string_equal(ps_kernel_names[PS_KERNEL_CONE], "cone");
    assert_string_equal(ps_kernel_names[PS_KERNEL_EPANECHNIKOV], "epanechnikov");
    assert_string_equal(ps_splat_mode_names[PS_SPLAT_SPRITES], "sprites");
    assert_string_equal(ps_precision_names[PS_PRECISION_COUNTER], "counter");
    assert_string_equal(ps_color_depth_names[PS_COLOR_DEPTH_8], "8");
    assert_string_equal(ps_color_depth_names[PS_COLOR_DEPTH_FLOAT], "float");
    assert_string_equal(ps_radius_schedule_names[PS_RADIUS_PROGRESSIVE], "progressive");
    assert_string_equal(ps_map_names[PS_MAP_GLOBAL], "global");
}

static void defaults(void **state)
{
    (void)state;
    ps_preview_options o;
    ps_preview_options_init(&o, false);
    assert_int_equal(o.splat, PS_SPLAT_TRIANGLES);
    assert_int_equal(o.kernel, PS_KERNEL_CONE);
    assert_int_equal(o.color_depth, PS_COLOR_DEPTH_8);
    assert_int_equal(o.precision, PS_PRECISION_DIFFUSION);
    assert_int_equal(o.radius_schedule, PS_RADIUS_FIXED);
    assert_true(o.shadows && o.stencil_clip);
    ps_preview_options_init(&o, true);
    assert_int_equal(o.color_depth, PS_COLOR_DEPTH_FLOAT);
}

/* Every name of every table parses to its own value. */
static void round_trip(void **state)
{
    (void)state;
    ps_preview_options o;
    ps_preview_options_init(&o, false);
    ps_error err;
    for (int k = 0; k < PS_KERNEL_COUNT; k++) {
        assert_int_equal(parse(&o, "--kernel", ps_kernel_names[k], &err), PS_OK);
        assert_int_equal(o.kernel, k);
    }
    for (int k = 0; k < PS_SPLAT_MODE_COUNT; k++) {
        assert_int_equal(parse(&o, "--splat", ps_splat_mode_names[k], &err), PS_OK);
        assert_int_equal(o.splat, k);
    }
    for (int k = 0; k < PS_PRECISION_COUNT; k++) {
        assert_int_equal(parse(&o, "--precision", ps_precision_names[k], &err), PS_OK);
        assert_int_equal(o.precision, k);
    }
    for (int k = 0; k < PS_COLOR_DEPTH_COUNT; k++) {
        assert_int_equal(parse(&o, "--color-depth", ps_color_depth_names[k], &err), PS_OK);
        assert_int_equal(o.color_depth, k);
    }
    for (int k = 0; k < PS_RADIUS_SCHEDULE_COUNT; k++) {
        assert_int_equal(parse(&o, "--radius-schedule", ps_radius_schedule_names[k], &err), PS_OK);
        assert_int_equal(o.radius_schedule, k);
    }
    assert_int_equal(parse(&o, "--shadows", "off", &err), PS_OK);
    assert_false(o.shadows);
    assert_int_equal(parse(&o, "--stencil-clip", "off", &err), PS_OK);
    assert_false(o.stencil_clip);
    assert_true(o.shadows == false && o.kernel == PS_KERNEL_EPANECHNIKOV); /* earlier fields kept */
    assert_int_equal(parse(&o, "--shadows", "on", &err), PS_OK);
    assert_true(o.shadows);
}

static void refusals(void **state)
{
    (void)state;
    ps_preview_options o;
    ps_preview_options_init(&o, false);
    ps_error err;
    assert_int_equal(parse(&o, "--kernel", "cubic", &err), PS_ERR_PARSE);
    assert_string_equal(err.msg, "prog: option --kernel: 'cubic' is not one of box|cone|gauss|epanechnikov");
    assert_int_equal(o.kernel, PS_KERNEL_CONE); /* unchanged */
    assert_int_equal(parse(&o, "--color-depth", "16", &err), PS_ERR_PARSE);
    assert_string_equal(err.msg, "prog: option --color-depth: '16' is not one of 8|float");
    assert_int_equal(o.color_depth, PS_COLOR_DEPTH_8);
    assert_int_equal(parse(&o, "--radius-schedule", "adaptive", &err), PS_ERR_PARSE);
    assert_string_equal(err.msg, "prog: option --radius-schedule: 'adaptive' is not one of fixed|progressive");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(tables),
        cmocka_unit_test(defaults),
        cmocka_unit_test(round_trip),
        cmocka_unit_test(refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
