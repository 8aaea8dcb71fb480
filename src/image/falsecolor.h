/* falsecolor.h: illuminance images for lighting designers: lux from an
 * irradiance image, and the false-colour picture with its labelled
 * logarithmic legend (as Radiance's falsecolor or DIALux's isolux views).
 * GL-free: the reference renderer, photosplat-snap and the window share it. */
#ifndef PS_IMAGE_FALSECOLOR_H
#define PS_IMAGE_FALSECOLOR_H

#include <stddef.h>

#include "core/status.h"
#include "image/image.h"

/* The legend strip to the right of the picture: width in pixels at glyph
 * scale 1 (twice that at scale 2, for pictures at least 480 tall). */
#define PS_FALSECOLOR_LEGEND_W 72
/* The legend spans at most this many decades; lower values share its bottom colour. */
#define PS_FALSECOLOR_MAX_DECADES 6

/* lux[y * width + x] = 683 Y of irradiance pixel (x, y) (core/photometry.h). */
void ps_lux_from_irradiance(const ps_image *irradiance, float *lux);

/* A logarithmic colour scale from lo to hi lux (0 < lo < hi). */
typedef struct ps_lux_scale {
    double lo, hi;
} ps_lux_scale;

/* Whole decades around the image: hi = 10^ceil(log10(max)), lo = 10^floor(log10
 * of the 1st percentile of the positive values)), at least 1 and at most
 * PS_FALSECOLOR_MAX_DECADES decades. All zero: 1 to 10 lx. */
ps_lux_scale ps_lux_scale_auto(const float *lux, size_t count);

/* The colour (sRGB-encoded, each in [0, 1]) that lux value v gets: a ramp
 * from dark blue through cyan, green and yellow to red over log10(v) in
 * [log10 lo, log10 hi], clamped at both ends; 0 lux (or less) is black. */
void ps_lux_color(double v, ps_lux_scale s, float rgb[3]);

/* The picture: width + legend wide, height tall (legend from
 * ps_falsecolor_legend_width), as a linear image that ps_png_write at
 * exposure 1 writes with exactly the sRGB colours above. Labels name each
 * decade ("100 lx") and, with room, the 2 and 5 between. */
int ps_falsecolor_legend_width(int height);
ps_status ps_falsecolor_image(const float *lux, int width, int height, ps_lux_scale s, ps_image *out, ps_error *err);

/* ps_falsecolor_image on the automatic scale, written as a PNG. */
ps_status ps_falsecolor_write(const float *lux, int width, int height, const char *path, ps_error *err);

#endif
