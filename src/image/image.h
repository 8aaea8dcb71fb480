/* image.h: linear RGB float images, the exposure/sRGB pipeline, and PNG/PFM files. */
#ifndef PS_IMAGE_IMAGE_H
#define PS_IMAGE_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"

/* Largest width or height any reader or program accepts (a 64k-wide image is
 * already far beyond a preview renderer's needs; the limit bounds the damage a
 * corrupt or hostile header can do). */
#define PS_IMAGE_MAX_SIDE 65536
/* Largest pixel count: 2^28 pixels of 3 floats is 3 GiB, the most we ever
 * allocate for one image. */
#define PS_IMAGE_MAX_PIXELS (1 << 28)

/* An RGB float image, by value (like raylib's Image). Pixels are interleaved
 * r,g,b; row 0 is the TOP row; width*height*3 floats. What the floats mean
 * depends on where the image came from: linear radiance for renderers and PFM
 * files, sRGB-encoded values in [0,1] for ps_png_read (see there). A zeroed
 * struct is the empty image. */
typedef struct ps_image {
    int width, height;
    float *rgb;
} ps_image;

/* What one pixel is planned at against the memory budget (core/memory.h):
 * the float image, and a reader's decoded copy of up to 16-bit RGBA. */
#define PS_IMAGE_PLAN_PIXEL_BYTES (3 * sizeof(float) + 4 * sizeof(uint16_t))

/* PS_OK when a w x h image is within the limits below and the memory budget; otherwise PS_ERR_LIMIT
 * with a message without a file name ("image is WxH, ..."), which readers
 * prefix with theirs. Takes 64-bit sides so that readers can check header
 * values before narrowing them. */
ps_status ps_image_check_size(int64_t w, int64_t h, ps_error *err);
/* Allocates a zero-filled w x h image. Refuses sides outside [1,
 * PS_IMAGE_MAX_SIDE] and more than PS_IMAGE_MAX_PIXELS pixels with
 * PS_ERR_LIMIT, before allocating. On failure *out is zeroed. */
ps_status ps_image_create(int w, int h, ps_image *out, ps_error *err);
/* Frees the pixels and zeroes *img; accepts NULL and a zeroed struct. */
void ps_image_destroy(ps_image *img);

/* The 3 floats of pixel (x, y), y counted from the top. No bounds check. */
static inline float *ps_image_at(const ps_image *img, int x, int y)
{
    return img->rgb + 3 * ((size_t)y * (size_t)img->width + (size_t)x);
}

/* ---- exposure and sRGB ------------------------------------------------------ */

/* The sRGB transfer function (IEC 61966-2-1), exactly piecewise: 12.92·x up to
 * 0.0031308, 1.055·x^(1/2.4) − 0.055 above. Not clamped: values outside [0,1]
 * follow the same formulas (negative values use the linear segment); NaN stays
 * NaN. */
float ps_srgb_encode(float linear);
/* The inverse: c/12.92 up to 0.04045, ((c + 0.055)/1.055)^2.4 above. */
float ps_srgb_decode(float encoded);
/* The 8-bit code of a linear value: round(255 · encode(clamp(linear·exposure,
 * 0, 1))). NaN (also from inf·0) gives 0, +inf gives 255. */
uint8_t ps_tonemap_8bit(float linear, float exposure);
/* Decodes every value of img from sRGB to linear, in place (for comparing a
 * PNG with linear data). */
void ps_image_srgb_to_linear(ps_image *img);

/* ---- files ------------------------------------------------------------------
 * Readers check the input is a regular file, zero *out on failure, and report
 * malformed files as PS_ERR_FORMAT with one line "PATH: problem"; images over
 * the size limits are PS_ERR_LIMIT (a PNG whose side exceeds
 * PS_IMAGE_MAX_SIDE is refused by libpng itself, so it is PS_ERR_FORMAT).
 * Writers go through ps_outfile: a failed write leaves nothing under `path`. */

/* 8-bit RGB PNG with an sRGB chunk; each value goes through
 * ps_tonemap_8bit(v, exposure). */
ps_status ps_png_write(const ps_image *img, const char *path, float exposure, ps_error *err);
/* Any PNG (gray, gray+alpha, palette, RGB, RGBA; 1 to 16 bits; interlaced or
 * not). Alpha is ignored, gray is replicated to RGB, and out holds the values
 * as stored, scaled to [0,1] (code/255 or code/65535, 16-bit precision kept):
 * still sRGB-encoded, no gamma is applied. Callers decode if they need linear. */
ps_status ps_png_read(const char *path, ps_image *out, ps_error *err);
/* A baseline or progressive JPEG (gray or YCbCr; CMYK refused), as
 * ps_png_read: code/255, still sRGB-encoded (textures, jpeg_io.c). */
ps_status ps_jpeg_read(const char *path, ps_image *out, ps_error *err);

/* PFM: "PF\n<w> <h>\n-1.0\n", then rows bottom to top as little-endian 32-bit
 * floats, linear, no exposure (every value written as is, NaN included). */
ps_status ps_pfm_write(const ps_image *img, const char *path, ps_error *err);
/* The one-channel form, "Pf": width x height values, rows top first (an
 * illuminance image in lux). */
ps_status ps_pfm_write_gray(const float *values, int width, int height, const char *path, ps_error *err);
/* "PF" (RGB) and "Pf" (gray, replicated to RGB) with any whitespace between
 * header tokens; negative scale means little-endian, positive big-endian, zero
 * is an error. The scale's magnitude is not applied: values are returned as
 * stored (our writer always stores -1.0). A file shorter or longer than the
 * header says is an error. Non-finite values are returned as they are. */
ps_status ps_pfm_read(const char *path, ps_image *out, ps_error *err);

/* Which reader a file needs, told by its first bytes, not its name. */
typedef enum ps_image_format { PS_IMAGE_PNG, PS_IMAGE_PFM, PS_IMAGE_EXR } ps_image_format;

/* Reads a PNG, a PFM or an OpenEXR file (image/exr_io.h), whichever the file's magic says; anything else is
 * PS_ERR_FORMAT. format (may be NULL) receives which it was. */
ps_status ps_image_read(const char *path, ps_image *out, ps_image_format *format, ps_error *err);

#endif
