/* light_profile.c: lat-long tables of a light's relative intensity (light_profile.h). */
#include "preview/light_profile.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "core/sampling.h"

/* A mesh light's faces are summed by normal: its intensity towards d is
 * sum A_f max(0, n_f . d) / (pi A). Faces are gathered into buckets of similar
 * normal (a NORMAL_BINS x NORMAL_BINS/2 lat-long grid), each with its summed
 * area and area-weighted mean normal, so that a mesh of many faces costs no
 * more than this many. A preview approximation: faces of a bucket differ in
 * normal by up to a bin's width. */
#define NORMAL_BINS 32

typedef struct bucket {
    ps_vec3 n; /* area-weighted sum of normals */
    double area;
} bucket;

typedef struct profile_source {
    const ps_scene *scene;
    const ps_light *l;
    bucket *buckets; /* mesh lights */
    int bucket_count;
    double mesh_area;
} profile_source;

/* Intensity per watt of power, 1/sr, towards unit world direction d. */
static double intensity(const profile_source *src, ps_vec3 d)
{
    const ps_light *l = src->l;
    switch (l->type) {
    case PS_LIGHT_POINT:
    case PS_LIGHT_SPHERE:
        return 1.0 / (4.0 * PS_PI);
    case PS_LIGHT_SPOT:
        return ps_v3_dot(d, l->direction) >= l->cos_angle ? 1.0 / ps_cone_solid_angle(l->cos_angle) : 0.0;
    case PS_LIGHT_QUAD:
    case PS_LIGHT_DISC:
        return fmax(0.0, ps_v3_dot(d, l->direction)) * PS_INV_PI;
    case PS_LIGHT_MESH: {
        double sum = 0.0;
        for (int b = 0; b < src->bucket_count; b++)
            if (src->buckets[b].area > 0.0)
                sum += src->buckets[b].area * fmax(0.0, ps_v3_dot(d, src->buckets[b].n));
        return src->mesh_area > 0.0 ? sum / (PS_PI * src->mesh_area) : 0.0;
    }
    case PS_LIGHT_IES:
        return ps_light_ies_density(src->scene, l, d);
    }
    return 0.0;
}

/* The frame the table is laid out in: an ies light's own; otherwise the
 * light's axis (down for lights without one) with horizontal 0 built as the
 * scene parser builds an ies light's (world +x made perpendicular). */
static void frame(const ps_light *l, ps_vec3 *axis, ps_vec3 *a0, ps_vec3 *a90)
{
    if (l->type == PS_LIGHT_IES) {
        *axis = l->direction;
        *a0 = l->axis0;
        *a90 = l->axis90;
        return;
    }
    bool has_axis = l->type == PS_LIGHT_SPOT || l->type == PS_LIGHT_QUAD || l->type == PS_LIGHT_DISC;
    *axis = has_axis ? l->direction : ps_v3(0, -1, 0);
    ps_vec3 ref = fabs(axis->x) > 0.999 ? ps_v3(0, 0, 1) : ps_v3(1, 0, 0);
    *a0 = ps_v3_norm(ps_v3_sub(ref, ps_v3_scale(*axis, ps_v3_dot(ref, *axis))));
    *a90 = ps_v3_cross(*a0, *axis);
}

static bool gather_mesh(profile_source *src)
{
    const ps_light *l = src->l;
    src->bucket_count = NORMAL_BINS * NORMAL_BINS / 2;
    src->buckets = calloc((size_t)src->bucket_count, sizeof *src->buckets);
    if (!src->buckets)
        return false;
    size_t ne;
    const uint32_t *em = ps_scene_emitters(src->scene, &ne);
    for (uint32_t k = 0; k < l->emitter_count; k++) {
        uint32_t t = em[l->first_emitter + k];
        double a = ps_scene_triangle_area(src->scene, t);
        ps_vec3 n = ps_scene_triangle_normal(src->scene, t);
        double th = acos(fmin(1.0, fmax(-1.0, n.y))), ph = atan2(n.z, n.x) + PS_PI;
        int bj = (int)(th / PS_PI * (NORMAL_BINS / 2)), bi = (int)(ph / (2 * PS_PI) * NORMAL_BINS);
        bj = bj < 0 ? 0 : bj >= NORMAL_BINS / 2 ? NORMAL_BINS / 2 - 1 : bj;
        bi = bi < 0 ? 0 : bi >= NORMAL_BINS ? NORMAL_BINS - 1 : bi;
        bucket *b = &src->buckets[bj * NORMAL_BINS + bi];
        b->n = ps_v3_add(b->n, ps_v3_scale(n, a));
        b->area += a;
        src->mesh_area += a;
    }
    for (int b = 0; b < src->bucket_count; b++)
        if (src->buckets[b].area > 0.0) {
            double len = ps_v3_len(src->buckets[b].n);
            src->buckets[b].n = len > 0.0 ? ps_v3_scale(src->buckets[b].n, 1.0 / len) : ps_v3(0, 0, 0);
        }
    return true;
}

ps_status ps_light_profile_make(const ps_scene *s, size_t light, int height, ps_light_profile *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    size_t n;
    const ps_light *lights = ps_scene_lights(s, &n);
    if (light >= n)
        return ps_error_set(err, PS_ERR_RANGE, "%s: light %zu does not exist (the scene has %zu)", ps_scene_path(s),
                            light, n);
    if (height < 1 || height > PS_LIGHT_PROFILE_MAX_HEIGHT)
        return ps_error_set(err, PS_ERR_RANGE, "light profile: height %d is outside [1, %d]", height,
                            PS_LIGHT_PROFILE_MAX_HEIGHT);
    profile_source src = {s, &lights[light], NULL, 0, 0.0};
    if (src.l->type == PS_LIGHT_MESH && !gather_mesh(&src))
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for a light profile", ps_scene_path(s));
    int w = 2 * height;
    out->texels = malloc((size_t)w * (size_t)height * sizeof *out->texels);
    if (!out->texels) {
        free(src.buckets);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for a light profile", ps_scene_path(s));
    }
    out->width = w;
    out->height = height;
    frame(src.l, &out->axis, &out->axis0, &out->axis90);
    /* Each texel's solid-angle mean from SS x SS sub-samples weighted by sin(theta). */
    const int ss = PS_LIGHT_PROFILE_SUPERSAMPLE;
    double peak = 0.0;
    for (int j = 0; j < height; j++)
        for (int i = 0; i < w; i++) {
            double sum = 0.0, weight = 0.0;
            for (int b = 0; b < ss; b++) {
                double th = (j + (b + 0.5) / ss) * PS_PI / height, st = sin(th), ct = cos(th);
                for (int a = 0; a < ss; a++) {
                    double ph = (i + (a + 0.5) / ss) * 2.0 * PS_PI / w;
                    ps_vec3 d = ps_v3_add(ps_v3_scale(out->axis, ct),
                                          ps_v3_scale(ps_v3_add(ps_v3_scale(out->axis0, cos(ph)),
                                                                ps_v3_scale(out->axis90, sin(ph))),
                                                      st));
                    sum += intensity(&src, d) * st;
                    weight += st;
                }
            }
            double mean = weight > 0.0 ? sum / weight : 0.0;
            out->texels[(size_t)j * (size_t)w + (size_t)i] = (float)mean;
            peak = fmax(peak, mean);
        }
    free(src.buckets);
    /* The largest texel (stored rounded to float) becomes exactly 1. */
    float top = 0.0f;
    for (size_t k = 0; k < (size_t)w * (size_t)height; k++)
        top = fmaxf(top, out->texels[k]);
    for (size_t k = 0; k < (size_t)w * (size_t)height; k++)
        out->texels[k] = top > 0.0f ? (out->texels[k] == top ? 1.0f : (float)((double)out->texels[k] / peak)) : 0.0f;
    out->peak = peak;
    return PS_OK;
}

void ps_light_profile_free(ps_light_profile *p)
{
    if (!p)
        return;
    free(p->texels);
    memset(p, 0, sizeof *p);
}

float ps_light_profile_lookup(const ps_light_profile *p, ps_vec3 d)
{
    double z = ps_v3_dot(d, p->axis), x = ps_v3_dot(d, p->axis0), y = ps_v3_dot(d, p->axis90);
    double th = atan2(sqrt(x * x + y * y), z), ph = atan2(y, x);
    if (ph < 0.0)
        ph += 2.0 * PS_PI;
    int j = (int)(th / PS_PI * p->height), i = (int)(ph / (2.0 * PS_PI) * p->width);
    j = j < 0 ? 0 : j >= p->height ? p->height - 1 : j;
    i = i < 0 ? 0 : i >= p->width ? p->width - 1 : i;
    return p->texels[(size_t)j * (size_t)p->width + (size_t)i];
}

double ps_light_profile_texel_solid_angle(const ps_light_profile *p, int j)
{
    double t0 = j * PS_PI / p->height, t1 = (j + 1) * PS_PI / p->height;
    return (cos(t0) - cos(t1)) * 2.0 * PS_PI / p->width;
}

void ps_light_profile_to_u8(const ps_light_profile *p, uint8_t *out)
{
    for (size_t k = 0; k < (size_t)p->width * (size_t)p->height; k++) {
        double v = p->texels[k] * 255.0 + 0.5;
        out[k] = (uint8_t)(v < 0.0 ? 0 : v > 255.0 ? 255 : v);
    }
}
