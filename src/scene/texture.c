/* texture.c: map_Kd textures (texture.h). */
#include "scene/texture.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/memory.h"
#include "image/image.h"

struct ps_texture {
    atomic_int refs;
    int width, height;
    float *rgb;
    char *path;
};

static bool ends_with(const char *s, const char *end)
{
    size_t n = strlen(s), m = strlen(end);
    if (n < m)
        return false;
    for (size_t i = 0; i < m; i++)
        if ((s[n - m + i] | 32) != end[i])
            return false;
    return true;
}

ps_status ps_texture_load(const char *path, uint64_t planned_bytes, ps_texture **out, ps_error *err)
{
    *out = NULL;
    ps_image img = {0, 0, NULL};
    ps_status st;
    if (ends_with(path, ".png"))
        st = ps_png_read(path, &img, err);
    else if (ends_with(path, ".jpg") || ends_with(path, ".jpeg"))
        st = ps_jpeg_read(path, &img, err);
    else
        return ps_error_set(err, PS_ERR_FORMAT, "%s: not a PNG or JPEG file (by its name)", path);
    if (st != PS_OK)
        return st;
    uint64_t bytes = (uint64_t)img.width * (uint64_t)img.height * PS_TEXTURE_PLAN_TEXEL_BYTES;
    char what[64];
    snprintf(what, sizeof what, "its textures (%dx%d more)", img.width, img.height);
    if ((st = ps_memory_check(planned_bytes + bytes, path, what, err)) != PS_OK) {
        ps_image_destroy(&img);
        return st;
    }
    ps_image_srgb_to_linear(&img);
    ps_texture *t = calloc(1, sizeof *t);
    if (!t || !(t->path = strdup(path))) {
        free(t);
        ps_image_destroy(&img);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    }
    atomic_init(&t->refs, 1);
    t->width = img.width;
    t->height = img.height;
    t->rgb = img.rgb; /* taken over */
    *out = t;
    return PS_OK;
}

ps_texture *ps_texture_ref(ps_texture *t)
{
    atomic_fetch_add_explicit(&t->refs, 1, memory_order_relaxed);
    return t;
}

void ps_texture_unref(ps_texture *t)
{
    if (!t || atomic_fetch_sub_explicit(&t->refs, 1, memory_order_acq_rel) != 1)
        return;
    free(t->rgb);
    free(t->path);
    free(t);
}

int ps_texture_width(const ps_texture *t) { return t->width; }
int ps_texture_height(const ps_texture *t) { return t->height; }
const char *ps_texture_path(const ps_texture *t) { return t->path; }
const float *ps_texture_texels(const ps_texture *t) { return t->rgb; }
uint64_t ps_texture_bytes(const ps_texture *t)
{
    return (uint64_t)t->width * (uint64_t)t->height * PS_TEXTURE_PLAN_TEXEL_BYTES;
}

/* x mod n in [0, n) for any integer x. */
static int wrap(long long x, int n)
{
    long long m = x % n;
    return (int)(m < 0 ? m + n : m);
}

ps_rgb ps_texture_sample(const ps_texture *t, double u, double v)
{
    if (!isfinite(u) || !isfinite(v))
        u = v = 0.0;
    /* Texel centres at (i + 0.5) / width; image row 0 is v = 1. Only the
     * fractional part matters (repeat), taken first so huge u stay exact. */
    double fx = (u - floor(u)) * t->width - 0.5;
    double fy = (1.0 - (v - floor(v))) * t->height - 0.5;
    double x0 = floor(fx), y0 = floor(fy);
    double ax = fx - x0, ay = fy - y0;
    int xa = wrap((long long)x0, t->width), xb = wrap((long long)x0 + 1, t->width);
    int ya = wrap((long long)y0, t->height), yb = wrap((long long)y0 + 1, t->height);
    const float *p00 = t->rgb + 3 * ((size_t)ya * (size_t)t->width + (size_t)xa);
    const float *p10 = t->rgb + 3 * ((size_t)ya * (size_t)t->width + (size_t)xb);
    const float *p01 = t->rgb + 3 * ((size_t)yb * (size_t)t->width + (size_t)xa);
    const float *p11 = t->rgb + 3 * ((size_t)yb * (size_t)t->width + (size_t)xb);
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = (1 - ay) * ((1 - ax) * p00[k] + ax * p10[k]) + ay * ((1 - ax) * p01[k] + ax * p11[k]);
    return ps_rgb_make(c[0], c[1], c[2]);
}
