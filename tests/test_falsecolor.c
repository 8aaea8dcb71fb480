/* test_falsecolor.c: lux from irradiance (683 Y), the automatic log scale,
 * the colour ramp, the false-colour picture's legend (bar and labels), the
 * one-channel PFM and OpenEXR files read back. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "image/exr_io.h"
#include "image/falsecolor.h"
#include "image/glyphs.h"
#include "image/image.h"

static void lux_is_683_y(void **state)
{
    (void)state;
    ps_image irr;
    assert_int_equal(ps_image_create(2, 1, &irr, NULL), PS_OK);
    float *p = ps_image_at(&irr, 0, 0);
    p[0] = 1, p[1] = 0, p[2] = 0;
    p = ps_image_at(&irr, 1, 0);
    p[0] = 2, p[1] = 1, p[2] = 3;
    float lux[2];
    ps_lux_from_irradiance(&irr, lux);
    assert_near(lux[0], 683 * 0.2126, 1e-4);
    assert_near(lux[1], 683 * (2 * 0.2126 + 0.7152 + 3 * 0.0722), 1e-3);
    ps_image_destroy(&irr);
}

static void automatic_scale(void **state)
{
    (void)state;
    float v[1000];
    for (int k = 0; k < 1000; k++)
        v[k] = (float)(3.0 + k * 0.4); /* 3 .. 402.6 lx */
    ps_lux_scale s = ps_lux_scale_auto(v, 1000);
    assert_near(s.lo, 1.0, 1e-9);
    assert_near(s.hi, 1000.0, 1e-9);
    /* A few dark pixels (under 1 %) do not stretch it; zeros never count. */
    v[0] = 1e-6f;
    v[1] = 0.0f;
    s = ps_lux_scale_auto(v, 1000);
    assert_near(s.lo, 1.0, 1e-9);
    /* Many decades are cut to PS_FALSECOLOR_MAX_DECADES below the top. */
    for (int k = 0; k < 500; k++)
        v[k] = 1e-9f;
    s = ps_lux_scale_auto(v, 1000);
    assert_near(s.hi / s.lo, 1e6, 1e-3);
    float zero[4] = {0, 0, 0, 0};
    s = ps_lux_scale_auto(zero, 4);
    assert_true(s.lo == 1.0 && s.hi == 10.0);
}

static void ramp(void **state)
{
    (void)state;
    ps_lux_scale s = {1.0, 1e5};
    float a[3], b[3];
    ps_lux_color(0.0, s, a);
    assert_true(a[0] == 0 && a[1] == 0 && a[2] == 0);
    ps_lux_color(1.0, s, a);
    ps_lux_color(0.01, s, b); /* below the scale: its bottom colour */
    assert_memory_equal(a, b, sizeof a);
    ps_lux_color(1e5, s, a);
    assert_near(a[0], 1.0, 1e-6); /* red on top */
    assert_true(a[2] < 0.01);
    ps_lux_color(1.0, s, a);
    assert_true(a[2] > a[0] && a[2] > a[1]); /* blue at the bottom */
    /* The middle of the scale (316 lx, t = 0.5) lies between cyan and green. */
    ps_lux_color(pow(10.0, 2.5), s, a);
    assert_true(a[1] > 0.8f && a[0] < 0.2f);
}

/* The picture: the image part keeps each pixel's ramp colour; the legend's
 * bar shows the scale's colours top (hi) to bottom (lo); labels are drawn
 * in white glyphs beside it; 8-bit PNG codes equal the ramp's sRGB. */
static void picture_and_legend(void **state)
{
    (void)state;
    int w = 40, h = 200;
    float *lux = malloc((size_t)w * h * sizeof *lux);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            lux[y * w + x] = (float)pow(10.0, 3.0 * (h - 1 - y) / (h - 1)); /* 1 .. 1000 lx, top bright */
    ps_lux_scale s = ps_lux_scale_auto(lux, (size_t)w * h);
    assert_near(s.lo, 1, 1e-9);
    assert_near(s.hi, 1000, 1e-9);
    ps_image img;
    ps_error err;
    assert_int_equal(ps_falsecolor_image(lux, w, h, s, &img, &err), PS_OK);
    int lw = ps_falsecolor_legend_width(h);
    assert_int_equal(img.width, w + lw);
    assert_int_equal(img.height, h);
    float want[3];
    ps_lux_color(lux[10 * w + 5], s, want);
    assert_near(ps_image_at(&img, 5, 10)[1], ps_srgb_decode(want[1]), 1e-6);
    /* The bar: its top row is hi's colour, its bottom row lo's. */
    int x_bar = w + 4 + 2, top = 13, bottom = h - 6;
    ps_lux_color(s.hi, s, want);
    assert_near(ps_image_at(&img, x_bar, top)[0], ps_srgb_decode(want[0]), 1e-6);
    ps_lux_color(s.lo, s, want);
    assert_near(ps_image_at(&img, x_bar, bottom)[2], ps_srgb_decode(want[2]), 1e-6);
    /* Labels: white pixels right of the ticks, on rows near each decade. */
    int labels = 0;
    for (int k = 0; k <= 3; k++) {
        int y = (int)lround(top + (3 - k) * (bottom - top) / 3.0), white = 0;
        for (int yy = y - 3; yy <= y + 3; yy++)
            for (int x = w + 4 + 10 + 5; x < w + lw; x++)
                white += yy >= 0 && yy < h && ps_image_at(&img, x, yy)[0] == 1.0f;
        labels += white > 5;
    }
    assert_int_equal(labels, 4);
    /* The "1000" label spells its digits: the '1' glyph's column of pixels. */
    const unsigned char *one = ps_glyph('1');
    assert_true(one[1] != 0);
    /* Written and read back, codes as the ramp's. */
    const char *png = test_path("fc.png");
    assert_int_equal(ps_falsecolor_write(lux, w, h, png, &err), PS_OK);
    ps_image back;
    assert_int_equal(ps_png_read(png, &back, &err), PS_OK);
    ps_lux_color(lux[100 * w + 7], s, want);
    assert_near(ps_image_at(&back, 7, 100)[1], want[1], 0.5 / 255 + 1e-6);
    ps_image_destroy(&back);
    ps_image_destroy(&img);
    free(lux);
}

static void gray_files(void **state)
{
    (void)state;
    float v[6] = {0.5f, 1e-3f, 1234.5f, 0.0f, 7.0f, 65504.0f};
    ps_error err;
    const char *names[2] = {"lux.pfm", "lux.exr"};
    for (int k = 0; k < 2; k++) {
        const char *path = test_path(names[k]);
        assert_int_equal(ps_gray_write(v, 3, 2, path, &err), PS_OK);
        ps_image img;
        if (k == 0) {
            ps_image_format fmt;
            assert_int_equal(ps_image_read(path, &img, &fmt, &err), PS_OK);
            assert_int_equal(fmt, PS_IMAGE_PFM);
        } else {
            assert_int_equal(ps_exr_read(path, &img, &err), PS_OK);
        }
        assert_int_equal(img.width, 3);
        assert_int_equal(img.height, 2);
        for (int y = 0; y < 2; y++)
            for (int x = 0; x < 3; x++)
                for (int c = 0; c < 3; c++)
                    assert_true(ps_image_at(&img, x, y)[c] == v[y * 3 + x]);
        ps_image_destroy(&img);
    }
    FILE *f = fopen(test_path("lux.pfm"), "rb");
    char magic[3] = {0};
    assert_int_equal(fread(magic, 1, 2, f), 2);
    fclose(f);
    assert_string_equal(magic, "Pf");
}

/* RGB EXR, float exactly and half within its precision; a directory is refused. */
static void exr_rgb(void **state)
{
    (void)state;
    ps_image img;
    assert_int_equal(ps_image_create(37, 21, &img, NULL), PS_OK); /* more rows than one ZIP chunk (16) */
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            float *p = ps_image_at(&img, x, y);
            p[0] = (float)(x * 0.25 + y);
            p[1] = (float)(1.0 / (1 + x + y));
            p[2] = (float)(x * y * 3.5);
        }
    ps_error err;
    char path[1024], half[1024]; /* test_path's buffer is static */
    snprintf(path, sizeof path, "%s", test_path("rgb.exr"));
    snprintf(half, sizeof half, "%s", test_path("half.exr"));
    assert_int_equal(ps_hdr_write(&img, path, &err), PS_OK);
    assert_int_equal(ps_exr_write(&img, half, PS_EXR_HALF, &err), PS_OK);
    ps_image back, hb;
    assert_int_equal(ps_exr_read(path, &back, &err), PS_OK);
    assert_int_equal(ps_exr_read(half, &hb, &err), PS_OK);
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++)
            for (int c = 0; c < 3; c++) {
                float a = ps_image_at(&img, x, y)[c];
                if (ps_image_at(&back, x, y)[c] != a)
                    fail_msg("(%d, %d, %d): %.9g read back, %.9g written", x, y, c, ps_image_at(&back, x, y)[c], a);
                assert_near(ps_image_at(&hb, x, y)[c], a, fabs(a) / 1024.0 + 1e-7);
            }
    FILE *f = fopen(path, "rb");
    unsigned char magic[4];
    assert_int_equal(fread(magic, 1, 4, f), 4);
    fclose(f);
    assert_true(magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01);
    /* ps_image_read (photosplat-compare's reader) tells EXR by its magic. */
    ps_image_format fmt;
    ps_image sniffed;
    assert_int_equal(ps_image_read(path, &sniffed, &fmt, &err), PS_OK);
    assert_int_equal(fmt, PS_IMAGE_EXR);
    assert_true(ps_image_at(&sniffed, 5, 7)[2] == ps_image_at(&img, 5, 7)[2]);
    ps_image_destroy(&sniffed);
    /* A .pfm name is a PFM. */
    assert_int_equal(ps_hdr_write(&img, test_path("rgb.pfm"), &err), PS_OK);
    ps_image p2;
    assert_int_equal(ps_image_read(test_path("rgb.pfm"), &p2, &fmt, &err), PS_OK);
    assert_int_equal(fmt, PS_IMAGE_PFM);
    ps_image_destroy(&p2);
    /* Failures leave nothing: a directory as the target, or a missing one. */
    assert_int_not_equal(ps_exr_write(&img, "build", PS_EXR_FLOAT, &err), PS_OK);
    assert_int_not_equal(ps_exr_write(&img, "build/no/such/dir/x.exr", PS_EXR_FLOAT, &err), PS_OK);
    assert_int_not_equal(ps_exr_read(test_path("rgb.pfm"), &p2, &err), PS_OK);
    assert_int_not_equal(ps_exr_read("build", &p2, &err), PS_OK);
    ps_image_destroy(&back);
    ps_image_destroy(&hb);
    ps_image_destroy(&img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(lux_is_683_y),      cmocka_unit_test(automatic_scale), cmocka_unit_test(ramp),
        cmocka_unit_test(picture_and_legend), cmocka_unit_test(gray_files),     cmocka_unit_test(exr_rgb),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
