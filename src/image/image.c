/* image.c: image allocation, the sRGB transfer function, tone mapping, and format sniffing. */
#include "image/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/memory.h"
#include "image/exr_io.h"

/* IEC 61966-2-1 constants. The encode threshold 0.0031308 and the decode
 * threshold 0.04045 are the standard's; they meet at 0.0031308·12.92 =
 * 0.04044994, a hair away from 0.04045, which is the standard's own rounding. */
#define SRGB_LINEAR_LIMIT 0.0031308
#define SRGB_ENCODED_LIMIT 0.04045
#define SRGB_LINEAR_SLOPE 12.92
#define SRGB_SCALE 1.055
#define SRGB_OFFSET 0.055
#define SRGB_GAMMA 2.4

/* The largest 8-bit code. */
#define CODE_MAX 255.0

/* 8 bytes: the PNG signature's length, enough to tell PNG from PFM. */
#define SNIFF_BYTES 8

ps_status ps_image_check_size(int64_t w, int64_t h, ps_error *err)
{
    if (w < 1 || h < 1)
        return ps_error_set(err, PS_ERR_LIMIT, "image is %lldx%lld; both sides must be at least 1", (long long)w,
                            (long long)h);
    if (w > PS_IMAGE_MAX_SIDE || h > PS_IMAGE_MAX_SIDE)
        return ps_error_set(err, PS_ERR_LIMIT, "image is %lldx%lld, larger than the %dx%d limit", (long long)w,
                            (long long)h, PS_IMAGE_MAX_SIDE, PS_IMAGE_MAX_SIDE);
    /* Both sides are at most 2^16 here, so the product fits in int64_t. */
    if (w * h > PS_IMAGE_MAX_PIXELS)
        return ps_error_set(err, PS_ERR_LIMIT, "image is %lldx%lld, more than the limit of %d pixels", (long long)w,
                            (long long)h, PS_IMAGE_MAX_PIXELS);
    /* On a 32-bit machine 2^28 pixels of 12 bytes do not fit in size_t. */
    if ((uint64_t)(w * h) > SIZE_MAX / (3 * sizeof(float)))
        return ps_error_set(err, PS_ERR_LIMIT, "image is %lldx%lld, too large for this machine's address space",
                            (long long)w, (long long)h);
    char what[64];
    snprintf(what, sizeof what, "image is %lldx%lld: it", (long long)w, (long long)h);
    return ps_memory_check((uint64_t)(w * h) * PS_IMAGE_PLAN_PIXEL_BYTES, NULL, what, err);
}

ps_status ps_image_create(int w, int h, ps_image *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    ps_status st = ps_image_check_size(w, h, err);
    if (st != PS_OK)
        return st;
    size_t n = (size_t)w * (size_t)h * 3;
    float *rgb = calloc(n, sizeof *rgb);
    if (!rgb)
        return ps_error_set(err, PS_ERR_NOMEM, "image is %dx%d: out of memory for %zu bytes", w, h, n * sizeof *rgb);
    out->width = w;
    out->height = h;
    out->rgb = rgb;
    return PS_OK;
}

void ps_image_destroy(ps_image *img)
{
    if (!img)
        return;
    free(img->rgb);
    memset(img, 0, sizeof *img);
}

/* Computed in double and rounded once, so that decode(encode(x)) is as close
 * to x as a float can be and all 256 codes survive a round trip. */
float ps_srgb_encode(float linear)
{
    double x = linear;
    if (x <= SRGB_LINEAR_LIMIT)
        return (float)(x * SRGB_LINEAR_SLOPE);
    if (x > SRGB_LINEAR_LIMIT)
        return (float)(SRGB_SCALE * pow(x, 1.0 / SRGB_GAMMA) - SRGB_OFFSET);
    return linear; /* NaN */
}

float ps_srgb_decode(float encoded)
{
    double c = encoded;
    if (c <= SRGB_ENCODED_LIMIT)
        return (float)(c / SRGB_LINEAR_SLOPE);
    if (c > SRGB_ENCODED_LIMIT)
        return (float)pow((c + SRGB_OFFSET) / SRGB_SCALE, SRGB_GAMMA);
    return encoded; /* NaN */
}

uint8_t ps_tonemap_8bit(float linear, float exposure)
{
    double v = (double)linear * (double)exposure;
    /* !(v > 0) is true for NaN as well as for v <= 0. */
    if (!(v > 0.0))
        return 0;
    if (v >= 1.0)
        return (uint8_t)CODE_MAX;
    double code = CODE_MAX * (double)ps_srgb_encode((float)v);
    /* code is in [0, 255]: adding one half and truncating rounds to nearest. */
    return (uint8_t)(code + 0.5);
}

void ps_image_srgb_to_linear(ps_image *img)
{
    size_t n = (size_t)img->width * (size_t)img->height * 3;
    for (size_t i = 0; i < n; i++)
        img->rgb[i] = ps_srgb_decode(img->rgb[i]);
}

ps_status ps_image_read(const char *path, ps_image *out, ps_image_format *format, ps_error *err)
{
    static const unsigned char png_magic[SNIFF_BYTES] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    memset(out, 0, sizeof *out);
    FILE *fp = ps_open_input(path, err);
    if (!fp)
        return err ? err->status : PS_ERR_IO;
    unsigned char head[SNIFF_BYTES];
    size_t got = fread(head, 1, sizeof head, fp);
    int bad = ferror(fp);
    fclose(fp);
    if (bad)
        return ps_error_set(err, PS_ERR_IO, "%s: read failed", path);
    if (got == 0)
        return ps_error_set(err, PS_ERR_FORMAT, "%s: empty file, not an image", path);
    /* A PFM starts "PF" or "Pf" and a whitespace character; the PFM reader
     * checks the rest. */
    if (got >= 3 && head[0] == 'P' && (head[1] == 'F' || head[1] == 'f') &&
        strchr(" \t\n\v\f\r", head[2]) && head[2] != '\0') {
        if (format)
            *format = PS_IMAGE_PFM;
        return ps_pfm_read(path, out, err);
    }
    if (got == SNIFF_BYTES && memcmp(head, png_magic, SNIFF_BYTES) == 0) {
        if (format)
            *format = PS_IMAGE_PNG;
        return ps_png_read(path, out, err);
    }
    /* OpenEXR's magic number, 20000630 little-endian. */
    if (got >= 4 && head[0] == 0x76 && head[1] == 0x2f && head[2] == 0x31 && head[3] == 0x01) {
        if (format)
            *format = PS_IMAGE_EXR;
        return ps_exr_read(path, out, err);
    }
    return ps_error_set(err, PS_ERR_FORMAT, "%s: not a PNG, PFM or OpenEXR image", path);
}
