/* falsecolor.c: lux, the logarithmic colour scale and the legend (falsecolor.h). */
#include "image/falsecolor.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "core/photometry.h"
#include "image/glyphs.h"

/* The automatic scale's percentile histogram: bins of 1/100 decade over
 * [1e-30, 1e30] lux, so no copy of the image is sorted. */
#define HIST_LO (-30)
#define HIST_BINS_PER_DECADE 100
#define HIST_BINS (60 * HIST_BINS_PER_DECADE)
/* The legend's colours (sRGB) and the percentile the scale starts at. */
#define LEGEND_BACKGROUND 0.12f
#define LOW_PERCENTILE 0.01

void ps_lux_from_irradiance(const ps_image *irr, float *lux)
{
    for (int y = 0; y < irr->height; y++)
        for (int x = 0; x < irr->width; x++) {
            const float *p = ps_image_at(irr, x, y);
            lux[(size_t)y * (size_t)irr->width + (size_t)x] = (float)ps_photometric(ps_rgb_make(p[0], p[1], p[2]));
        }
}

ps_lux_scale ps_lux_scale_auto(const float *lux, size_t count)
{
    static const ps_lux_scale none = {1.0, 10.0};
    unsigned hist[HIST_BINS];
    memset(hist, 0, sizeof hist);
    size_t positive = 0;
    double max = 0.0;
    for (size_t k = 0; k < count; k++) {
        double v = lux[k];
        if (!(v > 0.0) || !isfinite(v))
            continue;
        max = fmax(max, v);
        double b = floor((log10(v) - HIST_LO) * HIST_BINS_PER_DECADE);
        hist[b < 0 ? 0 : b >= HIST_BINS ? HIST_BINS - 1 : (size_t)b]++;
        positive++;
    }
    if (positive == 0)
        return none;
    size_t want = (size_t)(LOW_PERCENTILE * (double)positive), seen = 0;
    int bin = 0;
    while (bin < HIST_BINS - 1 && seen + hist[bin] <= want)
        seen += hist[bin++];
    double low = pow(10.0, HIST_LO + (double)bin / HIST_BINS_PER_DECADE);
    double top = ceil(log10(max) - 1e-9), bottom = floor(log10(low) + 1e-9);
    double decades = fmin(fmax(top - bottom, 1.0), PS_FALSECOLOR_MAX_DECADES);
    ps_lux_scale s = {pow(10.0, top - decades), pow(10.0, top)};
    return s;
}

void ps_lux_color(double v, ps_lux_scale s, float rgb[3])
{
    static const float stops[6][3] = {{0.10f, 0.00f, 0.40f}, {0.00f, 0.25f, 1.00f}, {0.00f, 0.85f, 0.90f},
                                      {0.20f, 0.85f, 0.10f}, {1.00f, 0.90f, 0.00f}, {1.00f, 0.10f, 0.00f}};
    if (!(v > 0.0)) {
        rgb[0] = rgb[1] = rgb[2] = 0.0f;
        return;
    }
    double t = (log10(v) - log10(s.lo)) / (log10(s.hi) - log10(s.lo));
    t = fmin(fmax(t, 0.0), 1.0) * 5.0;
    int i = t >= 5.0 ? 4 : (int)t;
    float f = (float)(t - i);
    for (int c = 0; c < 3; c++)
        rgb[c] = stops[i][c] + f * (stops[i + 1][c] - stops[i][c]);
}

int ps_falsecolor_legend_width(int height) { return PS_FALSECOLOR_LEGEND_W * (height >= 480 ? 2 : 1); }

static void put(ps_image *img, int x, int y, const float srgb[3])
{
    if (x < 0 || y < 0 || x >= img->width || y >= img->height)
        return;
    float *p = ps_image_at(img, x, y);
    for (int c = 0; c < 3; c++)
        p[c] = ps_srgb_decode(srgb[c]);
}

/* Text with its top-left at (x, y), glyphs scaled by g. */
static void text(ps_image *img, int x, int y, int g, const char *s, const float srgb[3])
{
    for (; *s; s++, x += PS_GLYPH_CELL_W * g) {
        const unsigned char *rows = ps_glyph((unsigned char)*s);
        for (int r = 0; r < PS_GLYPH_H; r++)
            for (int c = 0; c < PS_GLYPH_W; c++)
                if (rows[r] & (1u << (PS_GLYPH_W - 1 - c)))
                    for (int dy = 0; dy < g; dy++)
                        for (int dx = 0; dx < g; dx++)
                            put(img, x + c * g + dx, y + r * g + dy, srgb);
    }
}

ps_status ps_falsecolor_image(const float *lux, int width, int height, ps_lux_scale s, ps_image *out, ps_error *err)
{
    int lw = ps_falsecolor_legend_width(height), g = lw / PS_FALSECOLOR_LEGEND_W;
    if (!(s.lo > 0.0 && s.hi > s.lo))
        return ps_error_set(err, PS_ERR_RANGE, "false colour: the scale %g..%g lx is empty", s.lo, s.hi);
    ps_status st = ps_image_create(width + lw, height, out, err);
    if (st != PS_OK)
        return st;
    float rgb[3];
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            ps_lux_color(lux[(size_t)y * (size_t)width + (size_t)x], s, rgb);
            put(out, x, y, rgb);
        }
    const float back[3] = {LEGEND_BACKGROUND, LEGEND_BACKGROUND, LEGEND_BACKGROUND}, white[3] = {1, 1, 1};
    for (int y = 0; y < height; y++)
        for (int x = width; x < width + lw; x++)
            put(out, x, y, back);
    /* The bar: hi at its top, lo at its bottom, log-spaced; a title above. */
    int x0 = width + 4 * g, bar_w = 10 * g, top = 13 * g, bottom = height - 6 * g;
    text(out, x0, 2 * g, g, "lux", white);
    if (bottom - top < 8)
        return PS_OK; /* too small for a bar: the title alone */
    double llo = log10(s.lo), lhi = log10(s.hi);
    for (int y = top; y <= bottom; y++) {
        double t = 1.0 - (double)(y - top) / (bottom - top);
        ps_lux_color(pow(10.0, llo + t * (lhi - llo)), s, rgb);
        for (int x = x0; x < x0 + bar_w; x++)
            put(out, x, y, rgb);
    }
    /* Ticks and labels at each decade, and at 2 and 5 times it when the
     * decades are far enough apart for their labels. */
    double per_decade = (bottom - top) / (lhi - llo);
    bool minor = per_decade >= 3.0 * PS_GLYPH_CELL_H * g;
    int last_label = -1000;
    for (int k = (int)floor(lhi + 1e-9); k >= (int)ceil(llo - 1e-9); k--) {
        static const double steps[3] = {5.0, 2.0, 1.0};
        for (int m = 0; m < 3; m++) {
            if (m < 2 && !minor)
                continue;
            double v = steps[m] * pow(10.0, k), lv = log10(v);
            if (lv > lhi + 1e-9 || lv < llo - 1e-9)
                continue;
            int y = (int)lround(top + (lhi - lv) * per_decade);
            for (int x = x0 + bar_w; x < x0 + bar_w + 3 * g; x++)
                for (int dy = 0; dy < g; dy++)
                    put(out, x, y + dy, white);
            int ty = y - (PS_GLYPH_H * g) / 2;
            if (ty - last_label < PS_GLYPH_CELL_H * g)
                continue; /* its label would overlap the one above */
            char label[32];
            snprintf(label, sizeof label, "%g", v);
            text(out, x0 + bar_w + 5 * g, ty, g, label, white);
            last_label = ty;
        }
    }
    return PS_OK;
}

ps_status ps_falsecolor_write(const float *lux, int width, int height, const char *path, ps_error *err)
{
    ps_image img;
    ps_status st = ps_falsecolor_image(lux, width, height, ps_lux_scale_auto(lux, (size_t)width * (size_t)height),
                                       &img, err);
    if (st != PS_OK)
        return st;
    st = ps_png_write(&img, path, 1.0f, err);
    ps_image_destroy(&img);
    return st;
}
