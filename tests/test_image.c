/* test_image.c: image allocation, sRGB and tone mapping, PNG and PFM files, and their failures. */
#include "test.h"

#include <dirent.h>
#include <float.h>
#include <png.h>
#include <signal.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "image/image.h"

/* ---- helpers ------------------------------------------------------------------ */

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(data, 1, n, fp), n);
    assert_int_equal(fclose(fp), 0);
}

/* Reads a whole small file; the caller frees. */
static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    size_t cap = 1 << 20;
    unsigned char *buf = malloc(cap);
    assert_non_null(buf);
    *n = fread(buf, 1, cap, fp);
    assert_true(*n < cap);
    fclose(fp);
    return buf;
}

static bool exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Entries of a directory other than . and .. (to find stray temporary files). */
static int dir_entries(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            n++;
    closedir(d);
    return n;
}

/* The error contract: a failure status, one line, naming the file. */
static void assert_error_names(ps_status st, const ps_error *err, const char *path)
{
    assert_int_not_equal(st, PS_OK);
    assert_int_equal(err->status, st);
    if (!strstr(err->msg, path))
        fail_msg("message '%s' does not name '%s'", err->msg, path);
    assert_null(strchr(err->msg, '\n'));
    assert_true(strlen(err->msg) > strlen(path) + 2);
}

static void assert_zeroed(const ps_image *img)
{
    assert_int_equal(img->width, 0);
    assert_int_equal(img->height, 0);
    assert_null(img->rgb);
}

static uint32_t float_bits(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

/* A tiny PNG writer through libpng, independent of ps_png_write, to produce
 * every colour type and bit depth the reader must accept. `rows` holds h rows
 * of packed samples exactly as PNG stores them (big-endian 16-bit). */
typedef struct raw_png {
    int w, h, depth, color, interlace;
    const unsigned char *rows;
    const png_color *palette;
    int npalette;
    const unsigned char *trns;
    int ntrns;
} raw_png;

static void write_raw_png(const char *path, const raw_png *p)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    assert_non_null(info);
    if (setjmp(png_jmpbuf(png)))
        fail_msg("test PNG writer failed for %s", path);
    png_init_io(png, fp);
    png_set_IHDR(png, info, (png_uint_32)p->w, (png_uint_32)p->h, p->depth, p->color, p->interlace,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (p->palette)
        png_set_PLTE(png, info, p->palette, p->npalette);
    if (p->trns)
        png_set_tRNS(png, info, p->trns, p->ntrns, NULL);
    png_write_info(png, info);
    size_t rowbytes = png_get_rowbytes(png, info);
    png_bytep *rowp = malloc(sizeof *rowp * (size_t)p->h);
    assert_non_null(rowp);
    for (int y = 0; y < p->h; y++)
        rowp[y] = (png_bytep)(p->rows + (size_t)y * rowbytes);
    png_write_image(png, rowp);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    free(rowp);
    assert_int_equal(fclose(fp), 0);
}

/* Reads path as PNG and checks every pixel is (v[i], v[i], v[i]) for gray
 * expectations or v[3i..3i+2], exactly. */
static void expect_png(const char *path, int w, int h, const float *expect, bool gray)
{
    ps_image img;
    ps_error err;
    ps_status st = ps_png_read(path, &img, &err);
    if (st != PS_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(img.width, w);
    assert_int_equal(img.height, h);
    for (int i = 0; i < w * h; i++)
        for (int c = 0; c < 3; c++) {
            float e = gray ? expect[i] : expect[3 * i + c];
            if (img.rgb[3 * i + c] != e)
                fail_msg("%s: pixel %d channel %d is %.9g, expected %.9g", path, i, c, (double)img.rgb[3 * i + c],
                         (double)e);
        }
    ps_image_destroy(&img);
}

/* Big-endian CRC-32 of PNG chunks (the zlib polynomial), for hand-made headers. */
static uint32_t crc32_png(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
}

static void put_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* A PNG signature, a valid IHDR claiming w x h RGB 8-bit, and the start of an
 * IDAT chunk (where libpng's header reading stops), then nothing. */
static void write_png_header_only(const char *path, uint32_t w, uint32_t h)
{
    unsigned char f[8 + 25 + 8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char *c = f + 8;
    put_be32(c, 13);
    memcpy(c + 4, "IHDR", 4);
    put_be32(c + 8, w);
    put_be32(c + 12, h);
    c[16] = 8; /* bit depth */
    c[17] = 2; /* RGB */
    c[18] = c[19] = c[20] = 0;
    put_be32(c + 21, crc32_png(c + 4, 17));
    put_be32(c + 25, 100);
    memcpy(c + 29, "IDAT", 4);
    write_bytes(path, f, sizeof f);
}

/* A deterministic pseudo-random image that does not compress (for write
 * failures that must happen while writing). */
static void fill_noise(ps_image *img)
{
    uint32_t s = 12345;
    for (size_t i = 0; i < (size_t)img->width * img->height * 3; i++) {
        s = s * 1664525u + 1013904223u;
        img->rgb[i] = (float)(s >> 8) / 16777216.0f;
    }
}

/* ---- sRGB and tone mapping ------------------------------------------------------- */

static void srgb_known_values(void **state)
{
    (void)state;
    assert_true(ps_srgb_encode(0.0f) == 0.0f);
    assert_true(ps_srgb_encode(1.0f) == 1.0f);
    assert_true(ps_srgb_decode(0.0f) == 0.0f);
    assert_true(ps_srgb_decode(1.0f) == 1.0f);
    /* The knee: 0.0031308 · 12.92 = 0.04044994 */
    assert_near(ps_srgb_encode(0.0031308f), 0.04045, 1e-6);
    assert_near(ps_srgb_decode(0.04045f), 0.0031308, 1e-7);
    /* Linear segment: 0.001 · 12.92 */
    assert_near(ps_srgb_encode(0.001f), 0.01292, 1e-8);
    /* 1.055 · 0.5^(1/2.4) − 0.055 = 0.735356983 */
    assert_near(ps_srgb_encode(0.5f), 0.735356983, 1e-6);
    /* ((0.5 + 0.055)/1.055)^2.4 = 0.214041140 */
    assert_near(ps_srgb_decode(0.5f), 0.214041140, 1e-6);
    /* 18% grey encodes to about 0.4614 (the familiar 118/255) */
    assert_near(ps_srgb_encode(0.18f), 0.461356, 1e-5);
    /* Not clamped: negative values use the linear segment. */
    assert_near(ps_srgb_encode(-0.01f), -0.1292, 1e-7);
    assert_true(isnan(ps_srgb_encode(NAN)));
    assert_true(isnan(ps_srgb_decode(NAN)));
    /* decode(encode(x)) = x to float precision over many decades. */
    for (double x = 1e-6; x <= 1.0; x *= 1.07) {
        float y = ps_srgb_decode(ps_srgb_encode((float)x));
        assert_near(y, (float)x, 4e-7 * x);
    }
    /* Monotonic across the knee. */
    float prev = -1.0f;
    for (int i = 0; i <= 2000; i++) {
        float v = ps_srgb_encode((float)i / 2000.0f * 0.01f);
        assert_true(v > prev);
        prev = v;
    }
}

static void tonemap_values(void **state)
{
    (void)state;
    assert_int_equal(ps_tonemap_8bit(0.0f, 1.0f), 0);
    assert_int_equal(ps_tonemap_8bit(1.0f, 1.0f), 255);
    /* Clamped above and below. */
    assert_int_equal(ps_tonemap_8bit(2.0f, 1.0f), 255);
    assert_int_equal(ps_tonemap_8bit(-1.0f, 1.0f), 0);
    assert_int_equal(ps_tonemap_8bit(INFINITY, 1.0f), 255);
    assert_int_equal(ps_tonemap_8bit(-INFINITY, 1.0f), 0);
    /* NaN, and inf·0 = NaN, give black. */
    assert_int_equal(ps_tonemap_8bit(NAN, 1.0f), 0);
    assert_int_equal(ps_tonemap_8bit(INFINITY, 0.0f), 0);
    /* 255 · 0.735357 = 187.52 -> 188 */
    assert_int_equal(ps_tonemap_8bit(0.5f, 1.0f), 188);
    /* Exposure multiplies before encoding: 0.25·2 = 0.5, 1·0.5 = 0.5 */
    assert_int_equal(ps_tonemap_8bit(0.25f, 2.0f), 188);
    assert_int_equal(ps_tonemap_8bit(1.0f, 0.5f), 188);
    assert_int_equal(ps_tonemap_8bit(0.6f, 4.0f), 255);
    /* 255 · 0.01292 = 3.29 -> 3 */
    assert_int_equal(ps_tonemap_8bit(0.001f, 1.0f), 3);
    /* 255 · 0.461356 = 117.65 -> 118 */
    assert_int_equal(ps_tonemap_8bit(0.18f, 1.0f), 118);
    /* Every code survives decode then tonemap. */
    for (int c = 0; c < 256; c++)
        assert_int_equal(ps_tonemap_8bit(ps_srgb_decode((float)c / 255.0f), 1.0f), c);
    /* Rounding to nearest: half a code below code 1 (linear 0.5/255/12.92) */
    assert_int_equal(ps_tonemap_8bit(0.49f / 255.0f / 12.92f, 1.0f), 0);
    assert_int_equal(ps_tonemap_8bit(0.51f / 255.0f / 12.92f, 1.0f), 1);
}

static void srgb_to_linear_in_place(void **state)
{
    (void)state;
    ps_image img;
    assert_int_equal(ps_image_create(2, 1, &img, NULL), PS_OK);
    for (int i = 0; i < 6; i++)
        img.rgb[i] = (float)i / 5.0f;
    ps_image_srgb_to_linear(&img);
    for (int i = 0; i < 6; i++)
        assert_true(img.rgb[i] == ps_srgb_decode((float)i / 5.0f));
    ps_image_destroy(&img);
}

/* ---- the image type ------------------------------------------------------------- */

static void image_create_and_limits(void **state)
{
    (void)state;
    ps_image img;
    ps_error err;
    assert_int_equal(ps_image_create(3, 2, &img, &err), PS_OK);
    assert_int_equal(img.width, 3);
    assert_int_equal(img.height, 2);
    for (int i = 0; i < 18; i++)
        assert_true(img.rgb[i] == 0.0f);
    /* Accessor: row-major from the top, 3 floats a pixel. */
    assert_ptr_equal(ps_image_at(&img, 2, 1), img.rgb + 3 * (1 * 3 + 2));
    ps_image_destroy(&img);
    assert_zeroed(&img);
    ps_image_destroy(&img); /* a zeroed struct is fine */
    ps_image_destroy(NULL);

    const int bad[][2] = {{0, 1}, {1, 0}, {-5, 3}, {PS_IMAGE_MAX_SIDE + 1, 1}, {1, PS_IMAGE_MAX_SIDE + 1},
                          /* sides within the limit, pixels not: refused before allocating 48 GiB */
                          {PS_IMAGE_MAX_SIDE, PS_IMAGE_MAX_SIDE},
                          {16385, 16384}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        img.width = 7; /* must be zeroed on failure */
        assert_int_equal(ps_image_create(bad[k][0], bad[k][1], &img, &err), PS_ERR_LIMIT);
        assert_zeroed(&img);
        assert_null(strchr(err.msg, '\n'));
    }
    assert_int_equal(ps_image_check_size(16384, 16384, NULL), PS_OK); /* exactly 2^28 */
    assert_int_equal(ps_image_check_size(INT64_MAX, INT64_MAX, NULL), PS_ERR_LIMIT);
    assert_int_equal(ps_image_create(PS_IMAGE_MAX_SIDE, 1, &img, NULL), PS_OK);
    ps_image_destroy(&img);
}

/* ---- PNG -------------------------------------------------------------------------- */

/* Linear values whose codes are known write exactly those codes, rows in order. */
static void png_round_trip_exact_codes(void **state)
{
    (void)state;
    enum { W = 4, H = 3 };
    ps_image img;
    assert_int_equal(ps_image_create(W, H, &img, NULL), PS_OK);
    unsigned char code[W * H * 3];
    for (int i = 0; i < W * H * 3; i++) {
        code[i] = (unsigned char)((i * 23 + 7) % 256);
        img.rgb[i] = ps_srgb_decode((float)code[i] / 255.0f);
    }
    /* Out-of-range values clamp; NaN is black. */
    img.rgb[0] = 7.5f, code[0] = 255;
    img.rgb[1] = -3.0f, code[1] = 0;
    img.rgb[2] = NAN, code[2] = 0;
    const char *path = test_path("round.png");
    ps_error err;
    ps_status st = ps_png_write(&img, path, 1.0f, &err);
    if (st != PS_OK)
        fail_msg("%s", err.msg);
    float expect[W * H * 3];
    for (int i = 0; i < W * H * 3; i++)
        expect[i] = (float)code[i] / 255.0f;
    expect_png(path, W, H, expect, false);

    /* The file says it is sRGB. */
    size_t n;
    unsigned char *bytes = slurp(path, &n);
    bool found = false;
    for (size_t i = 0; i + 4 <= n && !found; i++)
        found = memcmp(bytes + i, "sRGB", 4) == 0;
    free(bytes);
    assert_true(found);

    /* Exposure 4 on a quarter of 1 is white; on 1/8 it is 0.5 -> 188. */
    for (int i = 0; i < W * H * 3; i++)
        img.rgb[i] = i % 2 ? 0.25f : 0.125f;
    assert_int_equal(ps_png_write(&img, path, 4.0f, &err), PS_OK);
    for (int i = 0; i < W * H * 3; i++)
        expect[i] = i % 2 ? 1.0f : 188.0f / 255.0f;
    expect_png(path, W, H, expect, false);
    ps_image_destroy(&img);
}

static void png_read_gray_depths(void **state)
{
    (void)state;
    const char *path = test_path("gray.png");
    /* 8-bit gray 3x2 */
    const unsigned char g8[] = {0, 128, 255, 1, 2, 254};
    write_raw_png(path, &(raw_png){.w = 3, .h = 2, .depth = 8, .color = PNG_COLOR_TYPE_GRAY, .rows = g8});
    const float e8[] = {0, 128 / 255.0f, 1, 1 / 255.0f, 2 / 255.0f, 254 / 255.0f};
    expect_png(path, 3, 2, e8, true);
    /* 1-bit gray, 9 pixels wide: 1 0 1 1 0 0 0 1 | 1, rows padded to 2 bytes;
     * libpng scales bit 1 to 255. */
    const unsigned char g1[] = {0xb1, 0x80};
    write_raw_png(path, &(raw_png){.w = 9, .h = 1, .depth = 1, .color = PNG_COLOR_TYPE_GRAY, .rows = g1});
    const float e1[] = {1, 0, 1, 1, 0, 0, 0, 1, 1};
    expect_png(path, 9, 1, e1, true);
    /* 4-bit gray: samples 0x0, 0xf, 0x8, 0x1 -> code = 17·s (0, 255, 136, 17) */
    const unsigned char g4[] = {0x0f, 0x81};
    write_raw_png(path, &(raw_png){.w = 4, .h = 1, .depth = 4, .color = PNG_COLOR_TYPE_GRAY, .rows = g4});
    const float e4[] = {0, 1, 136 / 255.0f, 17 / 255.0f};
    expect_png(path, 4, 1, e4, true);
    /* 16-bit gray keeps 16-bit precision: 0x1234 / 65535, not 0x12 / 255. */
    const unsigned char g16[] = {0x12, 0x34, 0xff, 0xff, 0x00, 0x01};
    write_raw_png(path, &(raw_png){.w = 3, .h = 1, .depth = 16, .color = PNG_COLOR_TYPE_GRAY, .rows = g16});
    const float e16[] = {0x1234 / 65535.0f, 1, 1 / 65535.0f};
    expect_png(path, 3, 1, e16, true);
    /* Gray + alpha: alpha ignored (a transparent pixel keeps its gray). */
    const unsigned char ga[] = {200, 0, 50, 255};
    write_raw_png(path, &(raw_png){.w = 2, .h = 1, .depth = 8, .color = PNG_COLOR_TYPE_GRAY_ALPHA, .rows = ga});
    const float ea[] = {200 / 255.0f, 50 / 255.0f};
    expect_png(path, 2, 1, ea, true);
}

static void png_read_palette_and_rgba(void **state)
{
    (void)state;
    const char *path = test_path("pal.png");
    const png_color pal[3] = {{255, 0, 0}, {10, 20, 30}, {0, 0, 255}};
    const unsigned char trns[3] = {0, 128, 255};
    const float e[] = {10 / 255.0f, 20 / 255.0f, 30 / 255.0f, 1, 0, 0, 0, 0, 1, 10 / 255.0f, 20 / 255.0f, 30 / 255.0f};
    /* 8-bit palette with transparency (alpha then ignored), 2x2: indices 1 0 / 2 1 */
    const unsigned char p8[] = {1, 0, 2, 1};
    write_raw_png(path, &(raw_png){.w = 2, .h = 2, .depth = 8, .color = PNG_COLOR_TYPE_PALETTE, .rows = p8,
                                   .palette = pal, .npalette = 3, .trns = trns, .ntrns = 3});
    expect_png(path, 2, 2, e, false);
    /* 2-bit palette: 1 0 | 2 1 packed as 01 00 0000 and 10 01 0000 */
    const unsigned char p2[] = {0x40, 0x90};
    write_raw_png(path, &(raw_png){.w = 2, .h = 2, .depth = 2, .color = PNG_COLOR_TYPE_PALETTE, .rows = p2,
                                   .palette = pal, .npalette = 3});
    expect_png(path, 2, 2, e, false);

    /* RGBA 8: alpha dropped */
    const unsigned char rgba[] = {1, 2, 3, 0, 250, 251, 252, 128};
    write_raw_png(path, &(raw_png){.w = 2, .h = 1, .depth = 8, .color = PNG_COLOR_TYPE_RGBA, .rows = rgba});
    const float ergba[] = {1 / 255.0f, 2 / 255.0f, 3 / 255.0f, 250 / 255.0f, 251 / 255.0f, 252 / 255.0f};
    expect_png(path, 2, 1, ergba, false);
    /* RGB 16 and RGBA 16 */
    const unsigned char rgb16[] = {0x00, 0x00, 0x80, 0x00, 0xff, 0xff, 0xab, 0xcd, 0x00, 0x07, 0x10, 0x00};
    write_raw_png(path, &(raw_png){.w = 2, .h = 1, .depth = 16, .color = PNG_COLOR_TYPE_RGB, .rows = rgb16});
    const float e16[] = {0, 0x8000 / 65535.0f, 1, 0xabcd / 65535.0f, 7 / 65535.0f, 0x1000 / 65535.0f};
    expect_png(path, 2, 1, e16, false);
    const unsigned char rgba16[] = {0x00, 0x00, 0x80, 0x00, 0xff, 0xff, 0x12, 0x34,
                                    0xab, 0xcd, 0x00, 0x07, 0x10, 0x00, 0x00, 0x00};
    write_raw_png(path, &(raw_png){.w = 2, .h = 1, .depth = 16, .color = PNG_COLOR_TYPE_RGBA, .rows = rgba16});
    expect_png(path, 2, 1, e16, false);
}

static void png_read_interlaced(void **state)
{
    (void)state;
    enum { W = 11, H = 9 };
    unsigned char rows[W * H * 3];
    float e[W * H * 3];
    for (int i = 0; i < W * H * 3; i++) {
        rows[i] = (unsigned char)(i * 7 % 256);
        e[i] = (float)rows[i] / 255.0f;
    }
    const char *path = test_path("adam7.png");
    write_raw_png(path, &(raw_png){.w = W, .h = H, .depth = 8, .color = PNG_COLOR_TYPE_RGB,
                                   .interlace = PNG_INTERLACE_ADAM7, .rows = rows});
    expect_png(path, W, H, e, false);
}

static void png_malformed_inputs(void **state)
{
    (void)state;
    ps_image img;
    ps_error err;
    /* A valid file to damage. */
    ps_image src;
    assert_int_equal(ps_image_create(32, 32, &src, NULL), PS_OK);
    fill_noise(&src);
    const char *good_path = test_path("good.png");
    assert_int_equal(ps_png_write(&src, good_path, 1.0f, &err), PS_OK);
    ps_image_destroy(&src);
    size_t n;
    unsigned char *good = slurp(good_path, &n);
    assert_true(n > 200);

    struct {
        const char *name;
        size_t len;   /* bytes of `good` to keep (0: use data) */
        long flip;    /* index of a byte to invert, or -1 */
        const char *data;
        ps_status expect;
    } cases[] = {
        {"empty.png", 0, -1, "", PS_ERR_FORMAT},
        {"garbage.png", 0, -1, "this is not an image at all\n", PS_ERR_FORMAT},
        {"sigonly.png", 8, -1, NULL, PS_ERR_FORMAT},
        {"half.png", n / 2, -1, NULL, PS_ERR_FORMAT},
        {"noiend.png", n - 12, -1, NULL, PS_ERR_FORMAT},
        {"damaged.png", n, (long)n / 2, NULL, PS_ERR_FORMAT}, /* inside IDAT: bad compressed data */
        {"idatcrc.png", n, (long)n - 13, NULL, PS_ERR_FORMAT}, /* IDAT's CRC (IEND is the last 12 bytes) */
        {"ihdrcrc.png", n, 8 + 8 + 3, NULL, PS_ERR_FORMAT},    /* the width byte of IHDR */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const char *path = test_path(cases[k].name);
        if (cases[k].data) {
            write_bytes(path, cases[k].data, strlen(cases[k].data));
        } else {
            unsigned char *copy = malloc(n);
            assert_non_null(copy);
            memcpy(copy, good, n);
            if (cases[k].flip >= 0)
                copy[cases[k].flip] ^= 0xff;
            write_bytes(path, copy, cases[k].len);
            free(copy);
        }
        ps_status st = ps_png_read(path, &img, &err);
        assert_error_names(st, &err, path);
        assert_int_equal(st, cases[k].expect);
        assert_zeroed(&img);
        if (strstr(cases[k].name, "crc") && !strstr(err.msg, "CRC"))
            fail_msg("%s: expected a CRC error, got '%s'", cases[k].name, err.msg);
        if (strcmp(cases[k].name, "half.png") == 0 && !strstr(err.msg, "truncated"))
            fail_msg("%s: expected 'truncated', got '%s'", cases[k].name, err.msg);
    }
    free(good);

    /* Absurd sides: refused by the header check, before any allocation. */
    const char *wide = test_path("wide.png");
    write_png_header_only(wide, 100000, 1);
    assert_error_names(ps_png_read(wide, &img, &err), &err, wide);
    assert_int_equal(err.status, PS_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "exceeds user limit"));
    const char *huge = test_path("huge.png");
    write_png_header_only(huge, 0x7fffffff, 0x7fffffff);
    assert_error_names(ps_png_read(huge, &img, &err), &err, huge);
    /* Sides within the limit, pixels not: a valid header, too large. */
    const char *big = test_path("big.png");
    write_png_header_only(big, PS_IMAGE_MAX_SIDE, PS_IMAGE_MAX_SIDE);
    assert_error_names(ps_png_read(big, &img, &err), &err, big);
    assert_int_equal(err.status, PS_ERR_LIMIT);
    /* Width 0 is invalid PNG. */
    const char *zero = test_path("zero.png");
    write_png_header_only(zero, 0, 5);
    assert_error_names(ps_png_read(zero, &img, &err), &err, zero);
    assert_int_equal(err.status, PS_ERR_FORMAT);

    /* Not a file at all. */
    const char *dir = test_path("adir.png");
    mkdir(dir, 0777);
    assert_error_names(ps_png_read(dir, &img, &err), &err, dir);
    assert_int_equal(err.status, PS_ERR_IO);
    const char *missing = test_path("missing.png");
    assert_error_names(ps_png_read(missing, &img, &err), &err, missing);
    assert_int_equal(err.status, PS_ERR_IO);
    assert_zeroed(&img);
}

/* ---- PFM -------------------------------------------------------------------------- */

static void pfm_round_trip_bit_exact(void **state)
{
    (void)state;
    enum { W = 3, H = 2 };
    ps_image img;
    assert_int_equal(ps_image_create(W, H, &img, NULL), PS_OK);
    const float v[W * H * 3] = {0.5f,   -2.25f, 1e-30f,   1e30f, -1e30f, 0.0f,      -0.0f, 1e-40f /* denormal */,
                                3.4e38f, 1.0f,   0.1f,     0.2f,  0.3f,   FLT_MIN,   7.0f,  -7.0f,
                                INFINITY, NAN};
    memcpy(img.rgb, v, sizeof v);
    const char *path = test_path("round.pfm");
    ps_error err;
    ps_status st = ps_pfm_write(&img, path, &err);
    if (st != PS_OK)
        fail_msg("%s", err.msg);

    /* The file: the header, then the BOTTOM row first, little-endian. */
    size_t n;
    unsigned char *bytes = slurp(path, &n);
    static const char header[] = "PF\n3 2\n-1.0\n";
    size_t hl = sizeof header - 1;
    assert_int_equal(n, hl + W * H * 3 * 4);
    assert_memory_equal(bytes, header, hl);
    /* First sample: pixel (0, 1) red = 1.0f = 0x3f800000 */
    const unsigned char one_le[4] = {0x00, 0x00, 0x80, 0x3f};
    assert_memory_equal(bytes + hl, one_le, 4);
    free(bytes);

    ps_image back;
    st = ps_pfm_read(path, &back, &err);
    if (st != PS_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(back.width, W);
    assert_int_equal(back.height, H);
    for (int i = 0; i < W * H * 3; i++)
        assert_int_equal(float_bits(back.rgb[i]), float_bits(v[i]));
    ps_image_destroy(&back);
    ps_image_destroy(&img);
}

static void pfm_gray_big_endian_and_whitespace(void **state)
{
    (void)state;
    ps_image img;
    ps_error err;
    /* Pf, big-endian (scale +1), 2x2; any white space between tokens.
     * Rows bottom first: bottom = 1.0, 2.0; top = -0.5, 0.25. */
    const char hdr[] = "Pf \t\r\n 2\n\n2   1.0\n";
    const unsigned char data[] = {0x3f, 0x80, 0, 0, 0x40, 0x00, 0, 0, 0xbf, 0x00, 0, 0, 0x3e, 0x80, 0, 0};
    unsigned char file[sizeof hdr - 1 + sizeof data];
    memcpy(file, hdr, sizeof hdr - 1);
    memcpy(file + sizeof hdr - 1, data, sizeof data);
    const char *path = test_path("gray-be.pfm");
    write_bytes(path, file, sizeof file);
    ps_status st = ps_pfm_read(path, &img, &err);
    if (st != PS_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(img.width, 2);
    assert_int_equal(img.height, 2);
    const float expect[4] = {-0.5f, 0.25f, 1.0f, 2.0f}; /* top row first in memory */
    for (int i = 0; i < 4; i++)
        for (int c = 0; c < 3; c++)
            assert_true(img.rgb[3 * i + c] == expect[i]);
    ps_image_destroy(&img);

    /* PF big-endian with a scale magnitude other than 1: values as stored. */
    const char hdr2[] = "PF\n1 1\n4.5\n";
    const unsigned char d2[] = {0x3f, 0x80, 0, 0, 0x40, 0x00, 0, 0, 0xc0, 0x40, 0, 0};
    unsigned char f2[sizeof hdr2 - 1 + sizeof d2];
    memcpy(f2, hdr2, sizeof hdr2 - 1);
    memcpy(f2 + sizeof hdr2 - 1, d2, sizeof d2);
    write_bytes(path, f2, sizeof f2);
    assert_int_equal(ps_pfm_read(path, &img, &err), PS_OK);
    assert_true(img.rgb[0] == 1.0f && img.rgb[1] == 2.0f && img.rgb[2] == -3.0f);
    ps_image_destroy(&img);
}

static void pfm_malformed_inputs(void **state)
{
    (void)state;
    /* 4 bytes of data: one gray pixel. */
    static const char px4[] = "\x00\x00\x80\x3f";
    struct {
        const char *name, *header;
        int data_bytes; /* bytes of zeros to append */
        ps_status expect;
    } cases[] = {
        {"empty.pfm", "", 0, PS_ERR_FORMAT},
        {"magic.pfm", "PX\n1 1\n-1.0\n", 4, PS_ERR_FORMAT},
        {"ppm.pfm", "P6\n1 1\n255\n", 3, PS_ERR_FORMAT},
        {"magic-long.pfm", "PFF\n1 1\n-1.0\n", 12, PS_ERR_FORMAT},
        {"lead-space.pfm", " PF\n1 1\n-1.0\n", 12, PS_ERR_FORMAT},
        {"scale0.pfm", "Pf\n1 1\n0.0\n", 4, PS_ERR_FORMAT},
        {"scalenan.pfm", "Pf\n1 1\nnan\n", 4, PS_ERR_FORMAT},
        {"scalex.pfm", "Pf\n1 1\n-1.0x\n", 4, PS_ERR_FORMAT},
        {"width-abc.pfm", "Pf\nabc 1\n-1.0\n", 4, PS_ERR_FORMAT},
        {"width-0.pfm", "Pf\n0 1\n-1.0\n", 0, PS_ERR_FORMAT},
        {"height-neg.pfm", "Pf\n1 -1\n-1.0\n", 4, PS_ERR_FORMAT},
        {"width-float.pfm", "Pf\n1.5 1\n-1.0\n", 4, PS_ERR_FORMAT},
        {"width-huge.pfm", "Pf\n99999999999999999999999 1\n-1.0\n", 4, PS_ERR_FORMAT},
        {"absurd.pfm", "PF\n100000 100000\n-1.0\n", 12, PS_ERR_LIMIT},
        {"pixels.pfm", "PF\n20000 20000\n-1.0\n", 12, PS_ERR_LIMIT},
        {"header-only.pfm", "PF\n1 1\n-1.0\n", 0, PS_ERR_FORMAT},
        {"no-scale.pfm", "PF\n1 1\n", 0, PS_ERR_FORMAT},
        {"no-sep.pfm", "PF\n1 1\n-1.0", 0, PS_ERR_FORMAT},
        {"truncated.pfm", "PF\n2 2\n-1.0\n", 47, PS_ERR_FORMAT},
        {"trailing.pfm", "PF\n2 2\n-1.0\n", 49, PS_ERR_FORMAT},
        {"gray-as-rgb.pfm", "Pf\n2 2\n-1.0\n", 48, PS_ERR_FORMAT},
        {"long-token.pfm", "PF\n1 0000000000000000000000000000000000000000000000000000000000000000000001\n-1\n", 12,
         PS_ERR_FORMAT},
    };
    ps_image img;
    ps_error err;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const char *path = test_path(cases[k].name);
        size_t hl = strlen(cases[k].header);
        unsigned char *file = calloc(1, hl + (size_t)cases[k].data_bytes + 1);
        assert_non_null(file);
        memcpy(file, cases[k].header, hl);
        write_bytes(path, file, hl + (size_t)cases[k].data_bytes);
        free(file);
        ps_status st = ps_pfm_read(path, &img, &err);
        if (st == PS_OK)
            fail_msg("%s was accepted", cases[k].name);
        assert_error_names(st, &err, path);
        if (st != cases[k].expect)
            fail_msg("%s: status %d, expected %d (%s)", cases[k].name, st, cases[k].expect, err.msg);
        assert_zeroed(&img);
    }
    /* The one-pixel gray file the cases above damage is itself fine. */
    const char *ok = test_path("ok.pfm");
    char buf[32];
    memcpy(buf, "Pf\n1 1\n-1.0\n", 12);
    memcpy(buf + 12, px4, 4);
    write_bytes(ok, buf, 16);
    assert_int_equal(ps_pfm_read(ok, &img, &err), PS_OK);
    assert_true(img.rgb[0] == 1.0f && img.rgb[2] == 1.0f);
    ps_image_destroy(&img);

    const char *dir = test_path("adir.pfm");
    mkdir(dir, 0777);
    assert_error_names(ps_pfm_read(dir, &img, &err), &err, dir);
    const char *missing = test_path("missing.pfm");
    assert_error_names(ps_pfm_read(missing, &img, &err), &err, missing);
}

/* ---- format sniffing -------------------------------------------------------------- */

static void read_by_magic_not_name(void **state)
{
    (void)state;
    ps_image img, back;
    ps_error err;
    ps_image_format fmt;
    assert_int_equal(ps_image_create(2, 2, &img, NULL), PS_OK);
    img.rgb[0] = 1.0f;
    /* test_path returns a static buffer: keep copies of both names. */
    char png_named_pfm[1024], pfm_named_png[1024];
    snprintf(png_named_pfm, sizeof png_named_pfm, "%s", test_path("really-png.pfm"));
    snprintf(pfm_named_png, sizeof pfm_named_png, "%s", test_path("really-pfm.png"));
    assert_int_equal(ps_png_write(&img, png_named_pfm, 1.0f, &err), PS_OK);
    assert_int_equal(ps_pfm_write(&img, pfm_named_png, &err), PS_OK);
    assert_int_equal(ps_image_read(png_named_pfm, &back, &fmt, &err), PS_OK);
    assert_int_equal(fmt, PS_IMAGE_PNG);
    assert_true(back.rgb[0] == 1.0f && back.rgb[1] == 0.0f);
    ps_image_destroy(&back);
    assert_int_equal(ps_image_read(pfm_named_png, &back, &fmt, &err), PS_OK);
    assert_int_equal(fmt, PS_IMAGE_PFM);
    assert_true(back.rgb[0] == 1.0f && back.rgb[1] == 0.0f);
    ps_image_destroy(&back);
    ps_image_destroy(&img);

    const char *garbage = test_path("garbage.img");
    write_bytes(garbage, "GIF89a....", 10);
    assert_error_names(ps_image_read(garbage, &back, &fmt, &err), &err, garbage);
    assert_int_equal(err.status, PS_ERR_FORMAT);
    const char *empty = test_path("empty.img");
    write_bytes(empty, "", 0);
    assert_error_names(ps_image_read(empty, &back, NULL, &err), &err, empty);
    const char *tiny = test_path("tiny.img");
    write_bytes(tiny, "P", 1);
    assert_error_names(ps_image_read(tiny, &back, NULL, &err), &err, tiny);
    /* Starts like a PFM, is not one: the PFM reader's message. */
    const char *fake = test_path("fake.img");
    write_bytes(fake, "PF x\n", 5);
    assert_error_names(ps_image_read(fake, &back, NULL, &err), &err, fake);
    const char *dir = test_path("adir.img");
    mkdir(dir, 0777);
    assert_error_names(ps_image_read(dir, &back, NULL, &err), &err, dir);
    assert_zeroed(&back);
}

/* ---- write failures --------------------------------------------------------------- */

static void write_into_missing_directory(void **state)
{
    (void)state;
    ps_image img;
    ps_error err;
    assert_int_equal(ps_image_create(2, 2, &img, NULL), PS_OK);
    char path[1100];
    snprintf(path, sizeof path, "%s/out.png", test_path("no-such-dir"));
    assert_error_names(ps_png_write(&img, path, 1.0f, &err), &err, path);
    assert_false(exists(path));
    snprintf(path, sizeof path, "%s/out.pfm", test_path("no-such-dir"));
    assert_error_names(ps_pfm_write(&img, path, &err), &err, path);
    assert_false(exists(path));
    assert_false(exists(test_path("no-such-dir")));
    /* Writing over a directory is refused and leaves it a directory. */
    const char *dir = test_path("out-is-dir.png");
    mkdir(dir, 0777);
    assert_error_names(ps_png_write(&img, dir, 1.0f, &err), &err, dir);
    assert_error_names(ps_pfm_write(&img, dir, &err), &err, dir);
    /* No image to write. */
    ps_image none = {0, 0, NULL};
    const char *p = test_path("none.png");
    assert_error_names(ps_png_write(&none, p, 1.0f, &err), &err, p);
    assert_error_names(ps_pfm_write(&none, p, &err), &err, p);
    assert_false(exists(p));
    ps_image_destroy(&img);
}

/* A write that fails half way (the file size limit, like a full disk) leaves
 * neither the target nor a temporary file, and does not replace an older
 * file of the same name. */
static void failed_write_leaves_nothing(void **state)
{
    (void)state;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path("fsize"));
    assert_int_equal(mkdir(dir, 0777), 0);
    char png_path[1100], pfm_path[1100], old_path[1100];
    snprintf(png_path, sizeof png_path, "%s/big.png", dir);
    snprintf(pfm_path, sizeof pfm_path, "%s/big.pfm", dir);
    snprintf(old_path, sizeof old_path, "%s/old.pfm", dir);
    write_bytes(old_path, "old", 3);

    ps_image img;
    assert_int_equal(ps_image_create(256, 256, &img, NULL), PS_OK);
    fill_noise(&img);

    /* Writing past RLIMIT_FSIZE fails with EFBIG once SIGXFSZ is ignored. */
    struct rlimit saved, lim;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &saved), 0);
    void (*old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
    /* Nothing buffered may need writing to a log while the limit holds. */
    fflush(stdout);
    fflush(stderr);
    lim = saved;
    lim.rlim_cur = 20000;
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
    ps_error e1, e2, e3;
    ps_status s1 = ps_png_write(&img, png_path, 1.0f, &e1);
    ps_status s2 = ps_pfm_write(&img, pfm_path, &e2);
    ps_status s3 = ps_pfm_write(&img, old_path, &e3);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &saved), 0);
    signal(SIGXFSZ, old_handler);

    assert_error_names(s1, &e1, png_path);
    assert_error_names(s2, &e2, pfm_path);
    assert_error_names(s3, &e3, old_path);
    assert_int_equal(s1, PS_ERR_IO);
    assert_int_equal(s2, PS_ERR_IO);
    assert_false(exists(png_path));
    assert_false(exists(pfm_path));
    /* Only the old file remains, unchanged. */
    assert_int_equal(dir_entries(dir), 1);
    size_t n;
    unsigned char *old = slurp(old_path, &n);
    assert_int_equal(n, 3);
    assert_memory_equal(old, "old", 3);
    free(old);

    /* Without the limit the same writes succeed and replace the old file. */
    ps_error err;
    assert_int_equal(ps_pfm_write(&img, old_path, &err), PS_OK);
    ps_image back;
    assert_int_equal(ps_pfm_read(old_path, &back, &err), PS_OK);
    assert_memory_equal(back.rgb, img.rgb, sizeof(float) * 256 * 256 * 3);
    ps_image_destroy(&back);
    assert_int_equal(dir_entries(dir), 1);
    ps_image_destroy(&img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(srgb_known_values),
        cmocka_unit_test(tonemap_values),
        cmocka_unit_test(srgb_to_linear_in_place),
        cmocka_unit_test(image_create_and_limits),
        cmocka_unit_test(png_round_trip_exact_codes),
        cmocka_unit_test(png_read_gray_depths),
        cmocka_unit_test(png_read_palette_and_rgba),
        cmocka_unit_test(png_read_interlaced),
        cmocka_unit_test(png_malformed_inputs),
        cmocka_unit_test(pfm_round_trip_bit_exact),
        cmocka_unit_test(pfm_gray_big_endian_and_whitespace),
        cmocka_unit_test(pfm_malformed_inputs),
        cmocka_unit_test(read_by_magic_not_name),
        cmocka_unit_test(write_into_missing_directory),
        cmocka_unit_test(failed_write_leaves_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
