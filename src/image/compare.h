/* compare.h: error metrics between a test image and a reference (pure, no I/O). */
#ifndef PS_IMAGE_COMPARE_H
#define PS_IMAGE_COMPARE_H

#include <stddef.h>

#include "core/status.h"
#include "image/image.h"

/* relMSE's denominator is b² + PS_RELMSE_EPSILON (the contract's 0.01): it
 * keeps black reference pixels from dividing by zero. */
#define PS_RELMSE_EPSILON 0.01
/* PSNR's peak signal: 1.0, the white of an 8-bit PNG scaled to [0,1] and of
 * radiance at exposure 1. */
#define PS_PSNR_PEAK 1.0
/* A mask pixel is selected ("white") when the mean of its channels is at
 * least this. */
#define PS_MASK_THRESHOLD 0.5

/* Over the selected pixels and all 3 channels (samples = 3 × pixels), with
 * a the image under test and b the reference:
 *   rmse   = sqrt(mean (a−b)²)
 *   relmse = mean (a−b)² / (b² + PS_RELMSE_EPSILON)
 *   psnr   = 10·log10(PS_PSNR_PEAK² / mean (a−b)²) in dB; +INFINITY when equal
 *   mean_a, mean_b = mean of a, of b */
typedef struct ps_compare_result {
    double rmse, relmse, psnr, mean_a, mean_b;
    size_t samples;
} ps_compare_result;

/* How the images are named in messages (file names, usually). NULL, or a NULL
 * member, means "A", "B", "mask". */
typedef struct ps_compare_names {
    const char *a, *b, *mask;
} ps_compare_names;

/* Compares a with the reference b over the pixels mask selects (mask NULL:
 * all pixels). Errors, each one line "NAME: problem": sizes differ
 * (PS_ERR_RANGE), the mask selects no pixel (PS_ERR_RANGE), a selected pixel
 * of a or b is NaN or infinite (PS_ERR_RANGE, naming the pixel as x,y from the
 * top left). Masked-out pixels are not looked at. Sums are compensated
 * (Neumaier) in double, so 2^28-pixel images keep full precision. */
ps_status ps_image_compare(const ps_image *a, const ps_image *b, const ps_image *mask, const ps_compare_names *names,
                           ps_compare_result *out, ps_error *err);

#endif
