/* test_rng.c: the per-index random stream and the Halton radical inverse. */
#include "test.h"

#include <math.h>
#include <string.h>

#include "core/rng.h"

/* The same (seed, stream, index) gives the same numbers, whatever was drawn
 * before or by whom: the property that keeps photons stable across threads. */
static void same_arguments_same_sequence(void **state)
{
    (void)state;
    for (uint64_t i = 0; i < 1000; i++) {
        ps_rng a = ps_rng_make(42, PS_STREAM_CAUSTIC, i);
        ps_rng b = ps_rng_make(42, PS_STREAM_CAUSTIC, i);
        for (int k = 0; k < 16; k++)
            assert_int_equal(ps_rng_u32(&a), ps_rng_u32(&b));
    }
}

/* Order of creation does not matter: make index 7 after 1000 others, or first. */
static void independent_of_order(void **state)
{
    (void)state;
    ps_rng first = ps_rng_make(1, PS_STREAM_GLOBAL, 7);
    double expect[8];
    for (int k = 0; k < 8; k++)
        expect[k] = ps_rng_uniform(&first);
    for (uint64_t i = 0; i < 1000; i++) {
        ps_rng other = ps_rng_make(1, PS_STREAM_GLOBAL, 999 - i);
        (void)ps_rng_u32(&other);
    }
    ps_rng again = ps_rng_make(1, PS_STREAM_GLOBAL, 7);
    for (int k = 0; k < 8; k++)
        assert_true(ps_rng_uniform(&again) == expect[k]);
}

/* Pinned values: a change to the generator changes every photon path, which
 * must be a deliberate act (golden images depend on it). */
static void pinned_values(void **state)
{
    (void)state;
    static const uint32_t want[4] = {4042492362u, 3889865537u, 1569220716u, 2228797737u};
    ps_rng r = ps_rng_make(0, PS_STREAM_TEST, 0);
    for (int k = 0; k < 4; k++)
        assert_int_equal(ps_rng_u32(&r), want[k]);
    ps_rng q = ps_rng_make(42, PS_STREAM_CAUSTIC, 123456789);
    assert_true(ps_rng_uniform(&q) == 0.093254380767664902);
    /* Seed, stream and index each change the sequence. */
    ps_rng s = ps_rng_make(1, PS_STREAM_TEST, 0), t = ps_rng_make(0, PS_STREAM_CAUSTIC, 0),
           u = ps_rng_make(0, PS_STREAM_TEST, 1);
    assert_true(ps_rng_u32(&s) != want[0]);
    assert_true(ps_rng_u32(&t) != want[0]);
    assert_true(ps_rng_u32(&u) != want[0]);
}

/* Neighbouring indices are not correlated: the mean of the first number over
 * consecutive indices and the correlation of index i with i+1 are near their
 * expected values (0.5 and 0), to several standard errors. */
static void neighbours_uncorrelated(void **state)
{
    (void)state;
    enum { N = 200000 };
    double sum = 0, sum_xy = 0, prev = 0;
    for (uint64_t i = 0; i < N; i++) {
        ps_rng r = ps_rng_make(3, PS_STREAM_CAUSTIC, i);
        double x = ps_rng_uniform(&r);
        assert_true(x >= 0.0 && x < 1.0);
        sum += x;
        if (i)
            sum_xy += (x - 0.5) * (prev - 0.5);
        prev = x;
    }
    double mean = sum / N, corr = sum_xy / (N - 1) / (1.0 / 12.0);
    /* sigma of the mean = sqrt(1/12/N) ~ 6.5e-4; of the correlation ~ 1/sqrt(N) ~ 2.2e-3 */
    assert_true(fabs(mean - 0.5) < 0.003);
    assert_true(fabs(corr) < 0.011);
}

/* Uniformity of a long stream: chi-square over 64 bins. */
static void uniform_histogram(void **state)
{
    (void)state;
    enum { BINS = 64, N = 640000 };
    unsigned hist[BINS];
    memset(hist, 0, sizeof hist);
    ps_rng r = ps_rng_make(9, PS_STREAM_TEST, 5);
    for (int k = 0; k < N; k++)
        hist[(int)(ps_rng_uniform(&r) * BINS)]++;
    double chi2 = 0, e = (double)N / BINS;
    for (int b = 0; b < BINS; b++)
        chi2 += (hist[b] - e) * (hist[b] - e) / e;
    /* 63 degrees of freedom: the 99.99th percentile is about 118. */
    assert_true(chi2 < 118.0);
}

static void below_is_in_range_and_unbiased(void **state)
{
    (void)state;
    ps_rng r = ps_rng_make(5, PS_STREAM_TEST, 1);
    unsigned count[3] = {0, 0, 0};
    for (int k = 0; k < 300000; k++) {
        uint32_t v = ps_rng_below(&r, 3);
        assert_true(v < 3);
        count[v]++;
    }
    for (int k = 0; k < 3; k++)
        assert_true(fabs(count[k] / 300000.0 - 1.0 / 3.0) < 0.004);
    assert_int_equal(ps_rng_below(&r, 1), 0);
}

static void radical_inverse_known_values(void **state)
{
    (void)state;
    /* Base 2: 1 -> .1b, 2 -> .01b, 3 -> .11b, 6 = 110b -> .011b */
    assert_true(ps_radical_inverse(2, 0) == 0.0);
    assert_true(ps_radical_inverse(2, 1) == 0.5);
    assert_true(ps_radical_inverse(2, 2) == 0.25);
    assert_true(ps_radical_inverse(2, 3) == 0.75);
    assert_true(ps_radical_inverse(2, 6) == 0.375);
    /* Base 3: 1 -> 1/3, 2 -> 2/3, 3 = 10_3 -> 1/9, 5 = 12_3 -> 2/3 + 1/9... reversed: .21_3 = 2/3 + 1/9 */
    assert_true(fabs(ps_radical_inverse(3, 1) - 1.0 / 3.0) < 1e-15);
    assert_true(fabs(ps_radical_inverse(3, 2) - 2.0 / 3.0) < 1e-15);
    assert_true(fabs(ps_radical_inverse(3, 3) - 1.0 / 9.0) < 1e-15);
    assert_true(fabs(ps_radical_inverse(3, 5) - (2.0 / 3.0 + 1.0 / 9.0)) < 1e-15);
    assert_int_equal(ps_halton_prime(0), 2);
    assert_int_equal(ps_halton_prime(4), 11);
    assert_true(fabs(ps_halton(2, 4) - 4.0 / 5.0) < 1e-15);
}

/* Huge indices stay in [0, 1) and the first 2^k points of base 2 are a
 * stratification: each of the 2^k intervals holds exactly one. */
static void radical_inverse_range_and_strata(void **state)
{
    (void)state;
    assert_true(ps_radical_inverse(2, UINT64_MAX) < 1.0);
    assert_true(ps_radical_inverse(131, UINT64_MAX) < 1.0);
    assert_true(ps_radical_inverse(3, UINT64_MAX - 1) >= 0.0);
    enum { K = 1024 };
    unsigned char seen[K];
    memset(seen, 0, sizeof seen);
    for (uint64_t i = 0; i < K; i++) {
        double v = ps_radical_inverse(2, i);
        int bin = (int)(v * K);
        assert_int_equal(seen[bin], 0);
        seen[bin] = 1;
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(same_arguments_same_sequence),
        cmocka_unit_test(independent_of_order),
        cmocka_unit_test(pinned_values),
        cmocka_unit_test(neighbours_uncorrelated),
        cmocka_unit_test(uniform_histogram),
        cmocka_unit_test(below_is_in_range_and_unbiased),
        cmocka_unit_test(radical_inverse_known_values),
        cmocka_unit_test(radical_inverse_range_and_strata),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
