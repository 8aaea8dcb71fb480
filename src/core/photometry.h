/* photometry.h: the one conversion between radiometric and photometric units.
 *
 * photosplat's radiometric values are linear RGB in watts (flux), W/sr
 * (intensity), W/m^2 (irradiance). Their photometric counterparts (lumens,
 * candela, lux) are 683 lm/W times the luminance Y of the RGB triple, with
 * Y = 0.2126 R + 0.7152 G + 0.0722 B (the Rec. 709 / sRGB primaries' Y row).
 * Every conversion, in both directions, goes through these functions: a
 * colour sets the chromaticity, the photometric value sets Y. */
#ifndef PS_CORE_PHOTOMETRY_H
#define PS_CORE_PHOTOMETRY_H

#include "core/vec.h"

/* The luminous efficacy that defines the conversion, lm/W. */
#define PS_LUMENS_PER_WATT 683.0

static inline double ps_rgb_luminance(ps_rgb c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

/* Radiometric -> photometric: W -> lm, W/sr -> cd, W/m^2 -> lx. */
static inline double ps_photometric(ps_rgb radiometric) { return PS_LUMENS_PER_WATT * ps_rgb_luminance(radiometric); }

/* Photometric -> radiometric: the RGB of chromaticity `color` (any scale,
 * luminance > 0) whose photometric value is `value`. */
static inline ps_rgb ps_radiometric(double value, ps_rgb color)
{
    return ps_rgb_scale(color, value / (PS_LUMENS_PER_WATT * ps_rgb_luminance(color)));
}

#endif
