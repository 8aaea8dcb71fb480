/* specular_glossy.c: glossy lobes in the specular layer (specular_glossy.h). */
#include "preview/specular_glossy.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

bool ps_glossy_wants(const ps_material *m) { return m->type == PS_MAT_GLOSSY && ps_rgb_max(m->specular) > 0.0; }

bool ps_specular_wants(const ps_material *m) { return ps_material_is_specular(m) || ps_glossy_wants(m); }

double ps_glossy_lobe_exponent(const ps_material *m) { return m->exponent + 1.0; }

int ps_glossy_level_size(double m, int base_size)
{
    /* The lobe's full width at half maximum: cos^m(a) = 1/2. A face spans
     * pi / 2. */
    double width = 2.0 * acos(pow(0.5, 1.0 / fmax(m, 1e-3)));
    double want = PS_GLOSSY_TEXELS_PER_WIDTH * 0.5 * PS_PI / width;
    int size = PS_GLOSSY_MIN_LEVEL;
    while (size < want && size < PS_GLOSSY_MAX_LEVEL)
        size *= 2;
    return size < base_size ? size : base_size;
}

bool ps_glossy_any(const ps_specular *sp, const ps_preview_mesh *mesh, const ps_material *materials)
{
    const ps_specular_range *r = ps_specular_ranges(sp);
    for (size_t i = 0; i < ps_specular_range_count(sp); i++)
        if (ps_glossy_wants(&materials[mesh->ranges[r[i].range].material]))
            return true;
    return false;
}

void ps_glossy_diffuse_materials(const ps_material *materials, size_t n, ps_material *out)
{
    for (size_t i = 0; i < n; i++) {
        out[i] = materials[i];
        if (ps_glossy_wants(&out[i]))
            out[i].specular = ps_rgb_gray(0.0);
    }
}

ps_status ps_glossy_splat_materials(const ps_specular *sp, const ps_preview_mesh *mesh, const ps_material *materials,
                                    size_t n, bool layer_on, ps_material **store, const ps_material **out,
                                    ps_error *err)
{
    *out = materials;
    if (!layer_on || !sp || !ps_glossy_any(sp, mesh, materials))
        return PS_OK;
    ps_material *m = realloc(*store, (n ? n : 1) * sizeof *m);
    if (!m)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for %zu materials", n);
    *store = m;
    ps_glossy_diffuse_materials(materials, n, m);
    *out = m;
    return PS_OK;
}

int ps_glossy_trace_point(const ps_world *world, const ps_material *materials, const ps_material *m, ps_vec3 eye,
                          ps_vec3 p, ps_vec3 n, ps_vec3 centre, ps_specular_term out[PS_SPECULAR_TERMS],
                          double *dropped)
{
    /* The mirror direction's path is a perfect mirror's. */
    ps_material mirror;
    memset(&mirror, 0, sizeof mirror);
    mirror.type = PS_MAT_MIRROR;
    mirror.reflectance = ps_rgb_gray(1.0);
    int k = ps_specular_trace_point(world, materials, &mirror, eye, p, n, centre, out, dropped);
    ps_vec3 d = ps_v3_sub(p, eye);
    double len = ps_v3_len(d);
    double nl = ps_v3_len(n);
    /* n . r = -(d . n) on the side the eye sees. */
    double cos_r = len > 0.0 && nl > 0.0 ? fabs(ps_v3_dot(d, n)) / (len * nl) : 0.0;
    ps_rgb w = ps_rgb_scale(m->specular, cos_r);
    for (int i = 0; i < k; i++)
        out[i].weight = ps_rgb_mul(out[i].weight, w);
    return k;
}

/* GL's cube faces: the major axis and how sc, tc map onto the others. */
ps_vec3 ps_cube_dir(int face, double s, double t)
{
    double sc = 2.0 * s - 1.0, tc = 2.0 * t - 1.0;
    ps_vec3 d;
    switch (face) {
    case 0: d = ps_v3(1.0, -tc, -sc); break;
    case 1: d = ps_v3(-1.0, -tc, sc); break;
    case 2: d = ps_v3(sc, 1.0, tc); break;
    case 3: d = ps_v3(sc, -1.0, -tc); break;
    case 4: d = ps_v3(sc, -tc, 1.0); break;
    default: d = ps_v3(-sc, -tc, -1.0); break;
    }
    return ps_v3_norm(d);
}

/* A face's texels in TILES x TILES tiles: a tile wholly outside an output
 * texel's lobe (past its floor) is skipped whole, so that a face of a lobe
 * reaching 31 degrees (e + 1 = 61) visits a tenth of the cube, not all. */
#define TILES 8
/* cos^m tabulated over [floor_cos, 1] at this many intervals, linearly
 * interpolated (the error is below 10^-7 of the peak at m = 1000). */
#define LOBE_TABLE 4096

struct ps_glossy_filter {
    int in_size, out_size;
    double m, floor_cos;
    /* The level's texels: unit directions and solid angles (6 out_size^2),
     * and the kept input averaged to them (rgb). */
    float *dir, *omega, *kept;
    /* Per tile (6 TILES^2): its centre's direction, and the cosine below
     * which an output direction's lobe cannot reach the tile (the lobe's
     * floor angle plus the tile's own angular radius). */
    float tile_dir[6 * TILES * TILES][3], tile_cos[6 * TILES * TILES];
    float lobe[LOBE_TABLE + 2];
};

static float lobe_at(const ps_glossy_filter *f, float c)
{
    float x = (c - (float)f->floor_cos) / (float)(1.0 - f->floor_cos) * LOBE_TABLE;
    int i = (int)x;
    if (i >= LOBE_TABLE)
        return f->lobe[LOBE_TABLE];
    return f->lobe[i] + (x - (float)i) * (f->lobe[i + 1] - f->lobe[i]);
}

ps_status ps_glossy_filter_create(int in_size, int out_size, double m, ps_glossy_filter **out, ps_error *err)
{
    *out = NULL;
    if (in_size <= 0 || out_size <= 0 || out_size > in_size || !(m > 0.0))
        return ps_error_set(err, PS_ERR_RANGE, "glossy level: sizes %d -> %d, exponent %g", in_size, out_size, m);
    ps_glossy_filter *f = calloc(1, sizeof *f);
    size_t n = 6 * (size_t)out_size * (size_t)out_size;
    if (f) {
        f->dir = malloc(3 * n * sizeof *f->dir);
        f->omega = malloc(n * sizeof *f->omega);
        f->kept = calloc(3 * n, sizeof *f->kept);
    }
    if (!f || !f->dir || !f->omega || !f->kept) {
        ps_glossy_filter_destroy(f);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for a glossy level of %d^2", out_size);
    }
    f->in_size = in_size, f->out_size = out_size, f->m = m;
    /* cos^m = floor: past it the terms are left out. */
    f->floor_cos = exp(log(PS_GLOSSY_LOBE_FLOOR) / m);
    int b = out_size;
    for (int face = 0; face < 6; face++)
        for (int j = 0; j < b; j++)
            for (int i = 0; i < b; i++) {
                size_t k = ((size_t)face * b + j) * b + i;
                ps_vec3 d = ps_cube_dir(face, (i + 0.5) / b, (j + 0.5) / b);
                f->dir[3 * k] = (float)d.x, f->dir[3 * k + 1] = (float)d.y, f->dir[3 * k + 2] = (float)d.z;
                /* A texel of side 2 / b on the unit-distance face plane at
                 * (u, v) subtends (2 / b)^2 / (1 + u^2 + v^2)^(3/2). */
                double u = 2.0 * (i + 0.5) / b - 1.0, v = 2.0 * (j + 0.5) / b - 1.0;
                f->omega[k] = (float)(4.0 / ((double)b * b) / pow(1.0 + u * u + v * v, 1.5));
            }
    for (int i = 0; i <= LOBE_TABLE + 1; i++)
        f->lobe[i] = (float)pow(fmin(1.0, f->floor_cos + (1.0 - f->floor_cos) * i / LOBE_TABLE), m);
    double floor_angle = acos(fmin(1.0, f->floor_cos));
    for (int face = 0; face < 6; face++)
        for (int tj = 0; tj < TILES; tj++)
            for (int ti = 0; ti < TILES; ti++) {
                int t = (face * TILES + tj) * TILES + ti;
                ps_vec3 c = ps_cube_dir(face, (ti + 0.5) / TILES, (tj + 0.5) / TILES);
                double radius = 0.0;
                for (int k = 0; k < 4; k++) {
                    ps_vec3 e = ps_cube_dir(face, (double)(ti + (k & 1)) / TILES, (double)(tj + (k >> 1)) / TILES);
                    radius = fmax(radius, acos(fmin(1.0, ps_v3_dot(c, e))));
                }
                f->tile_dir[t][0] = (float)c.x, f->tile_dir[t][1] = (float)c.y, f->tile_dir[t][2] = (float)c.z;
                /* A little slack for the floats' rounding. */
                f->tile_cos[t] = (float)cos(fmin(PS_PI, floor_angle + radius + 1e-3));
            }
    *out = f;
    return PS_OK;
}

void ps_glossy_filter_destroy(ps_glossy_filter *f)
{
    if (!f)
        return;
    free(f->dir);
    free(f->omega);
    free(f->kept);
    free(f);
}

int ps_glossy_filter_out_size(const ps_glossy_filter *f) { return f->out_size; }
double ps_glossy_filter_exponent(const ps_glossy_filter *f) { return f->m; }

/* Each input texel is split bilinearly over the four level texels about it
 * (a tent, clamped at the face's edges), and each level texel is its share's
 * weighted mean: a bright texel keeps its centroid, where a box average would
 * move it to the level texel's centre (half a level texel: 9.5 % of the
 * lobe's peak off the brute force in test_specular_glossy, 32 -> 16). */
void ps_glossy_filter_set_face(ps_glossy_filter *f, int face, const float *rgba)
{
    int a = f->in_size, b = f->out_size;
    float *dst = f->kept + 3 * (size_t)face * b * b;
    size_t n = (size_t)b * b;
    double *acc = calloc(4 * n, sizeof *acc);
    if (!acc)
        return; /* the level keeps this face as it was */
    for (int y = 0; y < a; y++) {
        double fy = (y + 0.5) * b / a - 0.5;
        int j0 = (int)floor(fy);
        double ty = fy - j0;
        for (int x = 0; x < a; x++) {
            double fx = (x + 0.5) * b / a - 0.5;
            int i0 = (int)floor(fx);
            double tx = fx - i0;
            const float *src = rgba + 4 * ((size_t)y * a + x);
            for (int dj = 0; dj < 2; dj++)
                for (int di = 0; di < 2; di++) {
                    double w = (di ? tx : 1.0 - tx) * (dj ? ty : 1.0 - ty);
                    if (w <= 0.0)
                        continue;
                    int i = i0 + di, j = j0 + dj;
                    i = i < 0 ? 0 : i >= b ? b - 1 : i;
                    j = j < 0 ? 0 : j >= b ? b - 1 : j;
                    double *t = acc + 4 * ((size_t)j * b + i);
                    t[0] += w * src[0], t[1] += w * src[1], t[2] += w * src[2], t[3] += w;
                }
        }
    }
    for (size_t k = 0; k < n; k++)
        for (int c = 0; c < 3; c++)
            dst[3 * k + c] = (float)(acc[4 * k + 3] > 0.0 ? acc[4 * k + c] / acc[4 * k + 3] : 0.0);
    free(acc);
}

void ps_glossy_filter_face(const ps_glossy_filter *f, int face, float *rgba)
{
    int b = f->out_size;
    const float fc = (float)f->floor_cos;
    for (int j = 0; j < b; j++)
        for (int i = 0; i < b; i++) {
            size_t o = ((size_t)face * b + j) * b + i;
            float ox = f->dir[3 * o], oy = f->dir[3 * o + 1], oz = f->dir[3 * o + 2];
            double sum[3] = {0, 0, 0}, wsum = 0.0;
            for (int t = 0; t < 6 * TILES * TILES; t++) {
                if (ox * f->tile_dir[t][0] + oy * f->tile_dir[t][1] + oz * f->tile_dir[t][2] < f->tile_cos[t])
                    continue;
                int tf = t / (TILES * TILES), ti = t % TILES, tj = t / TILES % TILES;
                int x0 = ti * b / TILES, x1 = (ti + 1) * b / TILES, y0 = tj * b / TILES, y1 = (tj + 1) * b / TILES;
                for (int y = y0; y < y1; y++)
                    for (int x = x0; x < x1; x++) {
                        size_t k = ((size_t)tf * b + y) * b + x;
                        float c = ox * f->dir[3 * k] + oy * f->dir[3 * k + 1] + oz * f->dir[3 * k + 2];
                        if (c <= fc)
                            continue;
                        double w = f->omega[k] * lobe_at(f, c);
                        wsum += w;
                        sum[0] += w * f->kept[3 * k];
                        sum[1] += w * f->kept[3 * k + 1];
                        sum[2] += w * f->kept[3 * k + 2];
                    }
            }
            float *t = rgba + 4 * ((size_t)j * b + i);
            for (int c = 0; c < 3; c++)
                t[c] = (float)(wsum > 0.0 ? sum[c] / wsum : 0.0);
            t[3] = 1.0f;
        }
}

uint64_t ps_specular_plan_bytes(int cube_size, int width, int height)
{
    /* RGBA16F, two a cube: the one shown and the one being rendered (gl_specular.c). */
    uint64_t cube = 2 * 6 * (uint64_t)cube_size * (uint64_t)cube_size * 4 * 2;
    uint64_t level = 6 * (uint64_t)PS_GLOSSY_MAX_LEVEL * PS_GLOSSY_MAX_LEVEL;
    /* A level: the texture (RGBA16F), the kept texels, directions and solid
     * angles (7 floats), one face's upload (RGBA floats), and one read-back
     * face of the cube (RGBA floats). */
    uint64_t glossy = level * (4 * 2 + 7 * 4) + level / 6 * 4 * 4 + (uint64_t)cube_size * cube_size * 4 * 4;
    return PS_SPECULAR_MAX_CUBES * (cube + glossy) + (uint64_t)width * (uint64_t)height * 4 * 4;
}
