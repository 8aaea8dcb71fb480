/* test_photon_map.c: the photon map's parallel arrays (photon/photon_map.h):
 * one capacity for all three, grown geometrically from 16, with the bytes
 * figure following it; appends keep every entry and add the counters; a
 * request that cannot be met leaves the map as it was; the text dump. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "photon/photon_map.h"

/* Photon k of a test: at (k, 2k, -k) with power k + 1 in each channel. */
static ps_photon test_photon(size_t k)
{
    double x = (double)k;
    return ps_photon_pack(ps_v3(x, 2 * x, -x), ps_rgb_gray(x + 1), ps_v3(0, -1, 0), ps_v3(0, 1, 0), 0.5);
}

static void one_capacity_grows(void **state)
{
    (void)state;
    ps_photon_map m;
    ps_photon_map_init(&m, PS_MAP_GLOBAL);
    assert_int_equal(m.count, 0);
    assert_int_equal(m.cap, 0);
    assert_int_equal(ps_photon_map_bytes(&m), 0);
    assert_int_equal(PS_PHOTON_MAP_BYTES, 26); /* 20-byte record, 2-byte material, 4-byte object */
    assert_true(ps_photon_map_push(&m, test_photon(0), 3, 7));
    assert_int_equal(m.cap, 16);
    assert_int_equal(ps_photon_map_bytes(&m), 16 * 26);
    for (size_t k = 1; k < 17; k++)
        assert_true(ps_photon_map_push(&m, test_photon(k), (uint16_t)(k + 3), (uint32_t)(k + 7)));
    assert_int_equal(m.count, 17);
    assert_int_equal(m.cap, 32);
    assert_int_equal(ps_photon_map_bytes(&m), 32 * 26);
    assert_true(ps_photon_map_reserve(&m, 1000));
    assert_int_equal(m.cap, 1024);
    assert_int_equal(ps_photon_map_bytes(&m), 26624);
    assert_true(ps_photon_map_reserve(&m, 10)); /* never shrinks */
    assert_int_equal(m.cap, 1024);
    for (size_t k = 0; k < 17; k++) {
        ps_photon p = test_photon(k);
        assert_memory_equal(&m.photons[k], &p, sizeof p);
        assert_int_equal(m.materials[k], k + 3);
        assert_int_equal(m.objects[k], k + 7);
    }
    /* Counters are the tracer's: pushing does not touch them. */
    assert_int_equal(m.counters.stored, 0);
    /* A size that overflows is refused, the map unchanged. */
    assert_false(ps_photon_map_reserve(&m, SIZE_MAX));
    assert_int_equal(m.count, 17);
    assert_int_equal(m.cap, 1024);
    ps_photon_map_free(&m);
    assert_int_equal(m.kind, PS_MAP_GLOBAL);
    /* Exact: a map filled once holds no unused capacity; growing on from
     * there doubles the exact size. */
    assert_true(ps_photon_map_reserve_exact(&m, 100));
    assert_int_equal(m.cap, 100);
    assert_int_equal(ps_photon_map_bytes(&m), 2600);
    assert_true(ps_photon_map_reserve_exact(&m, 50)); /* never shrinks */
    assert_int_equal(m.cap, 100);
    assert_true(ps_photon_map_reserve(&m, 101));
    assert_int_equal(m.cap, 200);
    ps_photon_map_free(&m);
    assert_int_equal(m.cap, 0);
    assert_null(m.photons);
}

static void append_and_power(void **state)
{
    (void)state;
    ps_photon_map a, b;
    ps_photon_map_init(&a, PS_MAP_CAUSTIC);
    ps_photon_map_init(&b, PS_MAP_CAUSTIC);
    for (size_t k = 0; k < 5; k++)
        assert_true(ps_photon_map_push(&a, test_photon(k), 1, 2));
    for (size_t k = 5; k < 40; k++)
        assert_true(ps_photon_map_push(&b, test_photon(k), 4, (uint32_t)k));
    a.counters.emitted = 10, a.counters.stored = 5, a.counters.rays = 30;
    b.counters.emitted = 70, b.counters.stored = 35, b.counters.rays = 200, b.counters.empty = 3;
    assert_true(ps_photon_map_append(&a, &b));
    assert_int_equal(a.count, 40);
    assert_int_equal(a.cap, 64);
    assert_int_equal(a.counters.emitted, 80);
    assert_int_equal(a.counters.stored, 40);
    assert_int_equal(a.counters.rays, 230);
    assert_int_equal(a.counters.empty, 3);
    for (size_t k = 0; k < 40; k++) {
        ps_photon p = test_photon(k);
        assert_memory_equal(&a.photons[k], &p, sizeof p);
        assert_int_equal(a.materials[k], k < 5 ? 1 : 4);
        assert_int_equal(a.objects[k], k < 5 ? 2 : k);
    }
    /* Powers 1..40 per channel, each within RGBE's 1/256 of its value. */
    ps_rgb sum = ps_photon_map_power(&a);
    assert_near(sum.g, 40.0 * 41.0 / 2.0, 820.0 / 256.0);
    ps_photon_map_free(&a);
    ps_photon_map_free(&b);
}

static void text_dump(void **state)
{
    (void)state;
    ps_photon_map m;
    ps_photon_map_init(&m, PS_MAP_CAUSTIC);
    assert_true(ps_photon_map_push(&m, test_photon(1), 0, 0));
    const char *path = test_path("dump.txt");
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    ps_photon_map_write_text(f, &m);
    fclose(f);
    char line[256] = "";
    f = fopen(path, "r");
    assert_non_null(fgets(line, sizeof line, f));
    fclose(f);
    assert_string_equal(line, "caustic 1 2 -1 2 2 2 0.000000 -1.000000 0.000000 0.000000 1.000000 0.000000\n");
    ps_photon_map_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(one_capacity_grows),
        cmocka_unit_test(append_and_power),
        cmocka_unit_test(text_dump),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
