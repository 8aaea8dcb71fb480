/* specular_points.h: two sets of the specular layer's per-pixel points
 * (preview/specular.h) the same bytes, for the tests that trace them two
 * ways (test_specular, test_session). Include after test.h. */
#ifndef PS_TESTS_SPECULAR_POINTS_H
#define PS_TESTS_SPECULAR_POINTS_H

#include <string.h>

#include "preview/specular.h"

/* Both ready, more than `min_count` points, and the same bytes. */
static void assert_points_equal(ps_specular_points a, ps_specular_points b, size_t min_count)
{
    assert_true(a.ready && b.ready);
    assert_int_equal(a.count, b.count);
    assert_true(a.count > min_count);
    assert_memory_equal(a.xy, b.xy, 2 * a.count * sizeof(float));
    assert_memory_equal(a.dirs, b.dirs, 3 * a.count * sizeof(float));
    assert_memory_equal(a.weights, b.weights, 3 * a.count * sizeof(float));
    assert_memory_equal(a.cube, b.cube, a.count * sizeof(int));
}

#endif
