/* test_compare.c: RMSE, relMSE, PSNR and means on small images with answers worked by hand. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "image/compare.h"
#include "image/image.h"

/* A w x h image filled with (r, g, b). */
static ps_image filled(int w, int h, float r, float g, float b)
{
    ps_image img;
    assert_int_equal(ps_image_create(w, h, &img, NULL), PS_OK);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float *p = ps_image_at(&img, x, y);
            p[0] = r, p[1] = g, p[2] = b;
        }
    return img;
}

static void set_pixel(ps_image *img, int x, int y, float r, float g, float b)
{
    float *p = ps_image_at(img, x, y);
    p[0] = r, p[1] = g, p[2] = b;
}

static ps_compare_result compare_ok(const ps_image *a, const ps_image *b, const ps_image *mask)
{
    ps_compare_result r;
    ps_error err;
    if (ps_image_compare(a, b, mask, NULL, &r, &err) != PS_OK)
        fail_msg("%s", err.msg);
    return r;
}

static void assert_one_line_naming(const ps_error *err, const char *name)
{
    if (!strstr(err->msg, name))
        fail_msg("message '%s' does not name '%s'", err->msg, name);
    assert_null(strchr(err->msg, '\n'));
}

static void uniform_difference(void **state)
{
    (void)state;
    ps_image a = filled(4, 3, 0.5f, 0.5f, 0.5f), b = filled(4, 3, 0.25f, 0.25f, 0.25f);
    ps_compare_result r = compare_ok(&a, &b, NULL);
    /* Every sample differs by 0.25: mse = 0.0625, rmse = 0.25;
     * relmse = 0.0625 / (0.25² + 0.01) = 0.0625 / 0.0725 = 0.862068966;
     * psnr = 10·log10(1 / 0.0625) = 12.0411998 dB; 4·3·3 = 36 samples. */
    assert_near(r.rmse, 0.25, 1e-15);
    assert_near(r.relmse, 0.0625 / 0.0725, 1e-15);
    assert_near(r.psnr, 12.041199826559248, 1e-12);
    assert_near(r.mean_a, 0.5, 1e-15);
    assert_near(r.mean_b, 0.25, 1e-15);
    assert_int_equal(r.samples, 36);

    /* B is the reference: swapping changes relMSE only.
     * relmse = 0.0625 / (0.5² + 0.01) = 0.0625 / 0.26 = 0.240384615 */
    r = compare_ok(&b, &a, NULL);
    assert_near(r.rmse, 0.25, 1e-15);
    assert_near(r.relmse, 0.0625 / 0.26, 1e-15);
    assert_near(r.psnr, 12.041199826559248, 1e-12);
    assert_near(r.mean_a, 0.25, 1e-15);
    assert_near(r.mean_b, 0.5, 1e-15);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
}

static void single_pixel_channel(void **state)
{
    (void)state;
    ps_image a = filled(2, 2, 0, 0, 0), b = filled(2, 2, 0, 0, 0);
    ps_image_at(&a, 1, 0)[0] = 0.6f;
    ps_compare_result r = compare_ok(&a, &b, NULL);
    /* One of 12 samples differs by 0.6 (as a float: 0.6f):
     * mse = 0.36/12 = 0.03, rmse = 0.173205; relmse = (0.36/0.01)/12 = 3;
     * psnr = 10·log10(1/0.03) = 15.2287875; mean_a = 0.6/12 = 0.05. */
    double d = 0.6f;
    assert_near(r.rmse, sqrt(d * d / 12), 1e-15);
    assert_near(r.rmse, 0.173205, 1e-6);
    assert_near(r.relmse, d * d / 0.01 / 12, 1e-12);
    assert_near(r.relmse, 3.0, 1e-6);
    assert_near(r.psnr, 10 * log10(12 / (d * d)), 1e-12);
    assert_near(r.psnr, 15.2287875, 1e-6);
    assert_near(r.mean_a, d / 12, 1e-15);
    assert_near(r.mean_b, 0, 0);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
}

static void identical_images(void **state)
{
    (void)state;
    ps_image a = filled(3, 5, 0.1f, 20.0f, -3.0f), b = filled(3, 5, 0.1f, 20.0f, -3.0f);
    ps_compare_result r = compare_ok(&a, &b, NULL);
    assert_true(r.rmse == 0.0);
    assert_true(r.relmse == 0.0);
    assert_true(isinf(r.psnr) && r.psnr > 0);
    /* (0.1f + 20 - 3) / 3 */
    assert_near(r.mean_a, ((double)0.1f + 20.0 - 3.0) / 3.0, 1e-14);
    assert_near(r.mean_b, r.mean_a, 0);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
}

static void mask_selects_pixels(void **state)
{
    (void)state;
    /* A = [0.5, 0.5], B = [0.25, 0.5]: only the left pixel differs. */
    ps_image a = filled(2, 1, 0.5f, 0.5f, 0.5f), b = filled(2, 1, 0.5f, 0.5f, 0.5f);
    set_pixel(&b, 0, 0, 0.25f, 0.25f, 0.25f);
    /* No mask: mse = 3·0.0625/6 = 0.03125, rmse = 0.1767767 */
    ps_compare_result r = compare_ok(&a, &b, NULL);
    assert_near(r.rmse, sqrt(0.03125), 1e-15);
    assert_near(r.mean_b, 0.375, 1e-15);
    assert_int_equal(r.samples, 6);
    /* Left pixel white: as the uniform case, rmse 0.25, means 0.5 and 0.25. */
    ps_image m = filled(2, 1, 1, 1, 1);
    set_pixel(&m, 1, 0, 0, 0, 0);
    r = compare_ok(&a, &b, &m);
    assert_near(r.rmse, 0.25, 1e-15);
    assert_near(r.mean_a, 0.5, 1e-15);
    assert_near(r.mean_b, 0.25, 1e-15);
    assert_int_equal(r.samples, 3);
    /* Right pixel white: identical there. */
    set_pixel(&m, 0, 0, 0, 0, 0);
    set_pixel(&m, 1, 0, 1, 1, 1);
    r = compare_ok(&a, &b, &m);
    assert_true(r.rmse == 0.0 && isinf(r.psnr));
    assert_near(r.mean_b, 0.5, 1e-15);
    /* The threshold is the channel mean >= 0.5: (1, 0, 0.5) is selected, 0.49 gray is not. */
    set_pixel(&m, 0, 0, 1.0f, 0.0f, 0.5f);
    set_pixel(&m, 1, 0, 0.49f, 0.49f, 0.49f);
    r = compare_ok(&a, &b, &m);
    assert_near(r.rmse, 0.25, 1e-15);
    assert_int_equal(r.samples, 3);
    /* A NaN mask pixel is not selected. */
    set_pixel(&m, 1, 0, NAN, 1, 1);
    r = compare_ok(&a, &b, &m);
    assert_int_equal(r.samples, 3);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
    ps_image_destroy(&m);
}

static void half_of_a_larger_image(void **state)
{
    (void)state;
    /* 8x8, A = 1 everywhere, B = 0 in the top half and 1 in the bottom half;
     * mask selects the left half. Selected: 4x8 pixels, half of them differ
     * by 1: mse = 0.5, relmse = 0.5·(1/0.01) = 50, psnr = 10·log10(2) = 3.0103. */
    ps_image a = filled(8, 8, 1, 1, 1), b = filled(8, 8, 1, 1, 1), m = filled(8, 8, 0, 0, 0);
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            if (y < 4)
                set_pixel(&b, x, y, 0, 0, 0);
            if (x < 4)
                set_pixel(&m, x, y, 1, 1, 1);
        }
    ps_compare_result r = compare_ok(&a, &b, &m);
    assert_int_equal(r.samples, 4 * 8 * 3);
    assert_near(r.rmse, sqrt(0.5), 1e-15);
    assert_near(r.relmse, 50.0, 1e-12);
    assert_near(r.psnr, 10 * log10(2.0), 1e-12);
    assert_near(r.mean_a, 1.0, 1e-15);
    assert_near(r.mean_b, 0.5, 1e-15);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
    ps_image_destroy(&m);
}

static void size_mismatch(void **state)
{
    (void)state;
    ps_image a = filled(4, 3, 0, 0, 0), b = filled(3, 4, 0, 0, 0), m = filled(4, 4, 1, 1, 1);
    ps_compare_result r;
    ps_error err;
    ps_compare_names names = {"a.png", "b.pfm", "mask.png"};
    assert_int_equal(ps_image_compare(&a, &b, NULL, &names, &r, &err), PS_ERR_RANGE);
    assert_one_line_naming(&err, "a.png");
    assert_one_line_naming(&err, "b.pfm");
    assert_one_line_naming(&err, "4x3");
    assert_one_line_naming(&err, "3x4");
    /* Default names when none are given. */
    assert_int_equal(ps_image_compare(&a, &b, NULL, NULL, &r, &err), PS_ERR_RANGE);
    assert_one_line_naming(&err, "B: is 3x4 but A is 4x3");
    /* The mask must match too. */
    assert_int_equal(ps_image_compare(&a, &a, &m, &names, &r, &err), PS_ERR_RANGE);
    assert_one_line_naming(&err, "mask.png");
    assert_one_line_naming(&err, "4x4");
    ps_image_destroy(&a);
    ps_image_destroy(&b);
    ps_image_destroy(&m);
}

static void empty_mask(void **state)
{
    (void)state;
    ps_image a = filled(3, 3, 0.5f, 0.5f, 0.5f), m = filled(3, 3, 0.2f, 0.2f, 0.2f);
    ps_compare_result r;
    ps_error err;
    ps_compare_names names = {"a.png", "b.png", "m.png"};
    assert_int_equal(ps_image_compare(&a, &a, &m, &names, &r, &err), PS_ERR_RANGE);
    assert_one_line_naming(&err, "m.png");
    assert_one_line_naming(&err, "no pixel");
    /* An empty image is refused, not divided by zero. */
    ps_image none = {0, 0, NULL};
    assert_int_equal(ps_image_compare(&none, &a, NULL, &names, &r, &err), PS_ERR_RANGE);
    assert_one_line_naming(&err, "a.png");
    ps_image_destroy(&a);
    ps_image_destroy(&m);
}

static void non_finite_pixels(void **state)
{
    (void)state;
    ps_image a = filled(4, 3, 0.5f, 0.5f, 0.5f), b = filled(4, 3, 0.5f, 0.5f, 0.5f);
    ps_compare_names names = {"a.pfm", "b.pfm", "m.png"};
    ps_compare_result r;
    ps_error err;
    ps_image_at(&a, 2, 1)[1] = NAN;
    assert_int_equal(ps_image_compare(&a, &b, NULL, &names, &r, &err), PS_ERR_RANGE);
    assert_one_line_naming(&err, "a.pfm: pixel (2, 1)");
    assert_one_line_naming(&err, "not finite");
    /* In the reference too, and infinities count. */
    ps_image_at(&a, 2, 1)[1] = 0.5f;
    ps_image_at(&b, 3, 2)[2] = -INFINITY;
    assert_int_equal(ps_image_compare(&a, &b, NULL, &names, &r, &err), PS_ERR_RANGE);
    assert_one_line_naming(&err, "b.pfm: pixel (3, 2)");
    /* A masked-out non-finite pixel is not looked at. */
    ps_image m = filled(4, 3, 1, 1, 1);
    set_pixel(&m, 3, 2, 0, 0, 0);
    r = compare_ok(&a, &b, &m);
    assert_true(r.rmse == 0.0);
    assert_int_equal(r.samples, 11 * 3);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
    ps_image_destroy(&m);
}

/* Sums keep double precision on a large image: 2048x2048 samples of 0.1f
 * average to exactly (double)0.1f, to about 1e-16 relative (a float
 * accumulator would be off by 1e-3). Large finite values do not overflow. */
static void large_image_precision(void **state)
{
    (void)state;
    ps_image a = filled(2048, 2048, 0.1f, 0.1f, 0.1f), b = filled(2048, 2048, 0, 0, 0);
    ps_compare_result r = compare_ok(&a, &b, NULL);
    assert_near(r.mean_a, (double)0.1f, 1e-16);
    assert_near(r.rmse, (double)0.1f, 1e-16);
    assert_near(r.relmse, (double)0.1f * 0.1f / 0.01, 1e-13);
    ps_image_destroy(&a);
    ps_image_destroy(&b);

    ps_image big = filled(2, 2, 3e38f, -3e38f, 1), neg = filled(2, 2, -3e38f, 3e38f, 1);
    r = compare_ok(&big, &neg, NULL);
    assert_true(isfinite(r.rmse) && isfinite(r.relmse));
    /* Two of three channels differ by 2·3e38f: rmse = sqrt(2/3)·6e38. */
    double d = 2.0 * (double)3e38f;
    assert_near(r.rmse, sqrt(2.0 / 3.0) * d, d * 1e-14);
    ps_image_destroy(&big);
    ps_image_destroy(&neg);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(uniform_difference),
        cmocka_unit_test(single_pixel_channel),
        cmocka_unit_test(identical_images),
        cmocka_unit_test(mask_selects_pixels),
        cmocka_unit_test(half_of_a_larger_image),
        cmocka_unit_test(size_mismatch),
        cmocka_unit_test(empty_mask),
        cmocka_unit_test(non_finite_pixels),
        cmocka_unit_test(large_image_precision),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
