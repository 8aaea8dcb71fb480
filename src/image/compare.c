/* compare.c: RMSE, relMSE, PSNR and means between two images, optionally masked. */
#include "image/compare.h"

#include <math.h>
#include <string.h>

/* A running sum with Kahan-Babuska (Neumaier) compensation: the error stays
 * about one rounding of the total however many terms (up to 3·2^28) are
 * added, where a plain double sum drifts by up to terms·eps. */
typedef struct ksum {
    double sum, comp;
} ksum;

static void ksum_add(ksum *k, double v)
{
    double t = k->sum + v;
    if (fabs(k->sum) >= fabs(v))
        k->comp += (k->sum - t) + v;
    else
        k->comp += (v - t) + k->sum;
    k->sum = t;
}

static double ksum_value(const ksum *k) { return k->sum + k->comp; }

static const char *or_default(const char *name, const char *fallback) { return name ? name : fallback; }

static int mask_selects(const ps_image *mask, int x, int y)
{
    if (!mask)
        return 1;
    const float *m = ps_image_at(mask, x, y);
    /* NaN compares false: a NaN mask pixel is not selected. */
    return ((double)m[0] + m[1] + m[2]) / 3.0 >= PS_MASK_THRESHOLD;
}

static int finite3(const float *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

ps_status ps_image_compare(const ps_image *a, const ps_image *b, const ps_image *mask, const ps_compare_names *names,
                           ps_compare_result *out, ps_error *err)
{
    const char *na = or_default(names ? names->a : NULL, "A");
    const char *nb = or_default(names ? names->b : NULL, "B");
    const char *nm = or_default(names ? names->mask : NULL, "mask");
    memset(out, 0, sizeof *out);
    if (!a->rgb || a->width < 1 || a->height < 1)
        return ps_error_set(err, PS_ERR_RANGE, "%s: empty image", na);
    if (!b->rgb || b->width < 1 || b->height < 1)
        return ps_error_set(err, PS_ERR_RANGE, "%s: empty image", nb);
    if (a->width != b->width || a->height != b->height)
        return ps_error_set(err, PS_ERR_RANGE, "%s: is %dx%d but %s is %dx%d", nb, b->width, b->height, na, a->width,
                            a->height);
    if (mask && (mask->width != a->width || mask->height != a->height || !mask->rgb))
        return ps_error_set(err, PS_ERR_RANGE, "%s: mask is %dx%d but the images are %dx%d", nm, mask->width,
                            mask->height, a->width, a->height);

    ksum sq = {0, 0}, rel = {0, 0}, sa = {0, 0}, sb = {0, 0};
    size_t pixels = 0;
    for (int y = 0; y < a->height; y++) {
        for (int x = 0; x < a->width; x++) {
            if (!mask_selects(mask, x, y))
                continue;
            const float *pa = ps_image_at(a, x, y), *pb = ps_image_at(b, x, y);
            if (!finite3(pa))
                return ps_error_set(err, PS_ERR_RANGE, "%s: pixel (%d, %d) is not finite (%g %g %g)", na, x, y,
                                    (double)pa[0], (double)pa[1], (double)pa[2]);
            if (!finite3(pb))
                return ps_error_set(err, PS_ERR_RANGE, "%s: pixel (%d, %d) is not finite (%g %g %g)", nb, x, y,
                                    (double)pb[0], (double)pb[1], (double)pb[2]);
            for (int c = 0; c < 3; c++) {
                double va = pa[c], vb = pb[c], d = va - vb;
                ksum_add(&sq, d * d);
                ksum_add(&rel, d * d / (vb * vb + PS_RELMSE_EPSILON));
                ksum_add(&sa, va);
                ksum_add(&sb, vb);
            }
            pixels++;
        }
    }
    if (pixels == 0)
        return ps_error_set(err, PS_ERR_RANGE, "%s: mask selects no pixel (white means a channel mean >= %g)", nm,
                            PS_MASK_THRESHOLD);

    double n = (double)pixels * 3.0;
    double mse = ksum_value(&sq) / n;
    out->samples = pixels * 3;
    out->rmse = sqrt(mse);
    out->relmse = ksum_value(&rel) / n;
    out->psnr = mse > 0.0 ? 10.0 * log10(PS_PSNR_PEAK * PS_PSNR_PEAK / mse) : INFINITY;
    out->mean_a = ksum_value(&sa) / n;
    out->mean_b = ksum_value(&sb) / n;
    return PS_OK;
}
