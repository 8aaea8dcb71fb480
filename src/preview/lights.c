/* lights.c: the scene's lights as GL point lights and visible emitters (lights.h). */
#include "preview/lights.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/memory.h"
#include "core/sampling.h"

const ps_vec3 ps_cube_face_axes[PS_CUBE_FACES] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

/* The largest angle between a cube face's axis and a direction it covers
 * (its corners): acos(1 / sqrt(3)). */
#define CUBE_FACE_RADIUS_DEG 54.7356103172

unsigned ps_preview_light_faces(const ps_preview_light *v)
{
    if (ps_v3_len2(v->dir) == 0.0 || v->cutoff_deg >= 180.0)
        return (1u << PS_CUBE_FACES) - 1;
    unsigned mask = 0;
    for (int f = 0; f < PS_CUBE_FACES; f++) {
        double angle = acos(fmax(-1.0, fmin(1.0, ps_v3_dot(ps_cube_face_axes[f], v->dir)))) * 180.0 / PS_PI;
        if (angle < v->cutoff_deg + CUBE_FACE_RADIUS_DEG)
            mask |= 1u << f;
    }
    return mask;
}

/* Squared distance from p to the triangle abc: the closest point lies in the
 * face, on an edge or at a corner, told apart by barycentric signs
 * (Ericson, Real-Time Collision Detection, 5.1.5). */
static double point_triangle_dist2(ps_vec3 p, ps_vec3 a, ps_vec3 b, ps_vec3 c)
{
    ps_vec3 ab = ps_v3_sub(b, a), ac = ps_v3_sub(c, a), ap = ps_v3_sub(p, a);
    double d1 = ps_v3_dot(ab, ap), d2 = ps_v3_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0)
        return ps_v3_len2(ap);
    ps_vec3 bp = ps_v3_sub(p, b);
    double d3 = ps_v3_dot(ab, bp), d4 = ps_v3_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3)
        return ps_v3_len2(bp);
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
        return ps_v3_len2(ps_v3_sub(p, ps_v3_madd(a, ab, d1 / (d1 - d3))));
    ps_vec3 cp = ps_v3_sub(p, c);
    double d5 = ps_v3_dot(ab, cp), d6 = ps_v3_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6)
        return ps_v3_len2(cp);
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
        return ps_v3_len2(ps_v3_sub(p, ps_v3_madd(a, ac, d2 / (d2 - d6))));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
        return ps_v3_len2(ps_v3_sub(p, ps_v3_madd(b, ps_v3_sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    double denom = va + vb + vc;
    if (!(denom > 0.0)) /* a degenerate triangle: its corners are near enough */
        return fmin(ps_v3_len2(ap), fmin(ps_v3_len2(bp), ps_v3_len2(cp)));
    double v = vb / denom, w = vc / denom;
    return ps_v3_len2(ps_v3_sub(p, ps_v3_madd(ps_v3_madd(a, ab, v), ac, w)));
}

double ps_preview_mesh_distance(const ps_preview_mesh *m, ps_vec3 p)
{
    double best = HUGE_VAL;
    for (size_t i = 0; i + 2 < m->vertex_count; i += 3) {
        const float *q = m->positions + 3 * i;
        ps_vec3 a = ps_v3(q[0], q[1], q[2]), b = ps_v3(q[3], q[4], q[5]), c = ps_v3(q[6], q[7], q[8]);
        best = fmin(best, point_triangle_dist2(p, a, b, c));
    }
    return sqrt(best);
}

/* ---- building ------------------------------------------------------------ */

typedef struct builder {
    const ps_scene *scene;
    ps_preview_lights *out;
    size_t cap;
    int area_side;
} builder;

static bool push_light(builder *b, ps_preview_light v)
{
    ps_preview_lights *l = b->out;
    if (l->count == b->cap) {
        size_t n = b->cap ? 2 * b->cap : 16;
        ps_preview_light *p = realloc(l->lights, n * sizeof *p);
        if (!p)
            return false;
        l->lights = p;
        b->cap = n;
    }
    v.faces = ps_preview_light_faces(&v);
    l->lights[l->count++] = v;
    return true;
}

static ps_preview_light point_light(uint32_t light, ps_vec3 pos, ps_rgb intensity)
{
    ps_preview_light v = {pos, {0, 0, 0}, 180.0, 0.0, intensity, 0, 0.0, light, -1};
    return v;
}

ps_vec3 ps_cube_texel_direction(int f, int size, int i, int j)
{
    /* GL 4.5 8.13: face f's (sc, tc) from the major axis; inverted here. */
    double sc = 2.0 * (i + 0.5) / size - 1.0, tc = 2.0 * (j + 0.5) / size - 1.0;
    switch (f) {
    case 0: return ps_v3(1.0, -tc, -sc);
    case 1: return ps_v3(-1.0, -tc, sc);
    case 2: return ps_v3(sc, 1.0, tc);
    case 3: return ps_v3(sc, -1.0, -tc);
    case 4: return ps_v3(sc, -tc, 1.0);
    default: return ps_v3(-sc, -tc, -1.0);
    }
}

/* An IES luminaire: a point light of intensity P d_max whose distribution
 * GL draws from a cube table (lights.h); the shadow cube keeps only the faces
 * the table lights. A table of all zeros (refused by the parser) or no room
 * for it leaves the light out, with *ok saying which. */
static bool add_ies_light(builder *b, uint32_t light, const ps_light *L)
{
    ps_preview_lights *l = b->out;
    const int size = PS_PREVIEW_PROFILE_SIZE;
    size_t n = (size_t)PS_CUBE_FACES * size * size;
    double *dens = malloc(n * sizeof *dens);
    ps_preview_profile *grown = realloc(l->profiles, (l->profile_count + 1) * sizeof *grown);
    if (grown)
        l->profiles = grown;
    uint16_t *texels = malloc(n * sizeof *texels);
    if (!dens || !grown || !texels) {
        free(dens), free(texels);
        return false;
    }
    double peak = 0.0;
    for (int f = 0; f < PS_CUBE_FACES; f++)
        for (int j = 0; j < size; j++)
            for (int i = 0; i < size; i++) {
                size_t k = ((size_t)f * size + (size_t)j) * size + (size_t)i;
                dens[k] = ps_light_ies_density(b->scene, L, ps_v3_norm(ps_cube_texel_direction(f, size, i, j)));
                peak = fmax(peak, dens[k]);
            }
    unsigned faces = 0;
    for (size_t k = 0; k < n; k++) {
        texels[k] = peak > 0.0 ? (uint16_t)lround(65535.0 * dens[k] / peak) : 0;
        if (texels[k])
            faces |= 1u << (k / ((size_t)size * size));
    }
    free(dens);
    l->profiles[l->profile_count].size = size;
    l->profiles[l->profile_count].texels = texels;
    ps_preview_light v = point_light(light, L->position, ps_rgb_scale(L->power, peak));
    v.profile = (int)l->profile_count++;
    if (!push_light(b, v))
        return false;
    l->lights[l->count - 1].faces = faces; /* what the table lights, not the whole cube */
    return true;
}

/* The virtual point lights of an area light: a grid of strata's centres over
 * the area, each a cosine emitter of power / (pi * count). */
static bool add_area_light(builder *b, uint32_t light, const ps_light *L)
{
    const int side = b->area_side;
    const int count = side * side;
    ps_rgb each = ps_rgb_scale(L->power, PS_INV_PI / count);
    if (L->type == PS_LIGHT_SPHERE) /* outside it, a Lambertian sphere lights like a point at its centre */
        return push_light(b, point_light(light, L->position, ps_rgb_scale(L->power, 0.25 * PS_INV_PI)));
    size_t ntri = 0, nem = 0;
    const ps_triangle *tris = ps_scene_triangles(b->scene, &ntri);
    const ps_vec3 *pos = ps_scene_positions(b->scene, &ntri);
    const uint32_t *emitters = ps_scene_emitters(b->scene, &nem);
    double total_area = 0.0;
    if (L->type == PS_LIGHT_MESH)
        for (uint32_t k = 0; k < L->emitter_count; k++)
            total_area += ps_scene_triangle_area(b->scene, emitters[L->first_emitter + k]);
    for (int j = 0; j < side; j++)
        for (int i = 0; i < side; i++) {
            double u = (i + 0.5) / side, w = (j + 0.5) / side;
            ps_preview_light v = {{0, 0, 0}, L->direction, 90.0, 1.0, each, 0, 0.0, light, -1};
            if (L->type == PS_LIGHT_QUAD) {
                v.pos = ps_v3_add(L->position, ps_v3_add(ps_v3_scale(L->edge1, u), ps_v3_scale(L->edge2, w)));
            } else if (L->type == PS_LIGHT_DISC) {
                double x, y;
                ps_sample_disc(u, w, &x, &y);
                ps_vec3 a, c;
                ps_v3_basis(L->direction, &a, &c);
                v.pos = ps_v3_add(L->position, ps_v3_add(ps_v3_scale(a, x * L->radius), ps_v3_scale(c, y * L->radius)));
            } else { /* a mesh light: the face at area fraction (j * side + i + 0.5) / count */
                double target = (j * side + i + 0.5) / count * total_area, run = 0.0;
                uint32_t t = emitters[L->first_emitter];
                for (uint32_t k = 0; k < L->emitter_count; k++) {
                    t = emitters[L->first_emitter + k];
                    run += ps_scene_triangle_area(b->scene, t);
                    if (run >= target)
                        break;
                }
                const ps_triangle *tri = &tris[t];
                v.pos = ps_v3_scale(ps_v3_add(ps_v3_add(pos[tri->v[0]], pos[tri->v[1]]), pos[tri->v[2]]), 1.0 / 3.0);
                v.dir = ps_scene_triangle_normal(b->scene, t);
            }
            if (!push_light(b, v))
                return false;
        }
    return true;
}

void ps_preview_lights_free(ps_preview_lights *l)
{
    for (size_t i = 0; i < l->emitter_count; i++)
        ps_trimesh_free(&l->emitters[i].sphere);
    free(l->emitters);
    for (size_t i = 0; i < l->profile_count; i++)
        free(l->profiles[i].texels);
    free(l->profiles);
    free(l->lights);
    memset(l, 0, sizeof *l);
}

static ps_status fail(ps_preview_lights *out, const ps_scene *s, ps_error *err)
{
    ps_preview_lights_free(out);
    return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for GL lights", ps_scene_path(s));
}

ps_status ps_preview_lights_build(const ps_scene *s, const ps_accel *accel, const ps_preview_mesh *coarse,
                                  int shadow_size, int area_side, ps_preview_lights *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    out->shadow_size = shadow_size > 0 ? shadow_size : 0;
    int side = area_side < 1 ? 1 : area_side > PS_PREVIEW_AREA_SIDE ? PS_PREVIEW_AREA_SIDE : area_side;
    builder b = {s, out, 0, side};
    size_t n;
    const ps_light *lights = ps_scene_lights(s, &n);
    size_t emitters = 0, spheres = 0;
    for (size_t l = 0; l < n; l++) {
        const ps_light *L = &lights[l];
        bool ok;
        if (L->type == PS_LIGHT_POINT) {
            ok = push_light(&b, point_light((uint32_t)l, L->position, ps_rgb_scale(L->power, 0.25 * PS_INV_PI)));
        } else if (L->type == PS_LIGHT_SPOT) {
            double solid = 2.0 * PS_PI * (1.0 - L->cos_angle);
            ps_preview_light v = {L->position, L->direction, L->angle_deg, 0.0, ps_rgb_scale(L->power, 1.0 / solid),
                                  0, 0.0, (uint32_t)l, -1};
            ok = push_light(&b, v);
        } else if (L->type == PS_LIGHT_IES) {
            ok = add_ies_light(&b, (uint32_t)l, L);
        } else {
            ok = add_area_light(&b, (uint32_t)l, L);
        }
        if (!ok)
            return fail(out, s, err);
        emitters += L->type == PS_LIGHT_QUAD || L->type == PS_LIGHT_DISC || L->type == PS_LIGHT_SPHERE;
        spheres += L->type == PS_LIGHT_SPHERE;
    }
    /* Shadow maps (a depth texture per lit cube face of every GL light) and
     * sphere-light meshes: thousands of lights would not fit, so they are
     * refused here rather than failing inside the GL driver. */
    for (size_t i = 0; shadow_size > 0 && i < out->count; i++)
        for (unsigned m = out->lights[i].faces; m; m &= m - 1)
            out->shadow_faces++;
    uint64_t texels = (uint64_t)shadow_size * (uint64_t)shadow_size;
    uint64_t bytes = ps_memory_mul(out->shadow_faces, ps_memory_mul(texels, PS_SHADOW_TEXEL_BYTES)) +
                     ps_memory_mul(spheres, ps_memory_mul(ps_sphere_triangle_count(PS_SPHERE_DEFAULT_TOLERANCE),
                                                          PS_SPHERE_TRIANGLE_BYTES));
    char what[128];
    snprintf(what, sizeof what, "%zu lights (%zu GL lights, %llu shadow maps of %dx%d)", n, out->count,
             (unsigned long long)out->shadow_faces, shadow_size, shadow_size);
    ps_status st = ps_memory_check(bytes, ps_scene_path(s), what, err);
    if (st != PS_OK) {
        ps_preview_lights_free(out);
        return st;
    }
    /* Near planes: what a depth-only pass could draw nearest the light. */
    ps_aabb bounds = ps_scene_bounds(s);
    double diag = ps_v3_len(ps_aabb_diag(bounds));
    if (!(diag > 0.0) || !isfinite(diag))
        diag = 1.0;
    double floor_near = fmax(PS_SHADOW_NEAR_FRACTION * diag, 1e-300);
    for (size_t i = 0; i < out->count; i++) {
        ps_vec3 p = out->lights[i].pos;
        double z = PS_SHADOW_NEAR_SHARE * (accel ? ps_accel_nearest_distance(accel, p) : ps_preview_mesh_distance(coarse, p));
        out->lights[i].shadow_near = isfinite(z) ? fmax(z, floor_near) : floor_near; /* no geometry at all */
    }
    out->emitters = emitters ? calloc(emitters, sizeof *out->emitters) : NULL;
    if (emitters && !out->emitters)
        return fail(out, s, err);
    for (size_t l = 0; l < n; l++) {
        const ps_light *L = &lights[l];
        if (L->type != PS_LIGHT_QUAD && L->type != PS_LIGHT_DISC && L->type != PS_LIGHT_SPHERE)
            continue;
        ps_preview_emitter *e = &out->emitters[out->emitter_count];
        e->type = L->type;
        e->position = L->position;
        e->edge1 = L->edge1;
        e->edge2 = L->edge2;
        e->normal = L->direction;
        e->radius = L->radius;
        e->radiance = L->radiance;
        if (L->type == PS_LIGHT_SPHERE) {
            st = ps_sphere_tessellate(L->position, L->radius, PS_SPHERE_DEFAULT_TOLERANCE, &e->sphere, err);
            if (st != PS_OK) {
                ps_preview_lights_free(out);
                return st;
            }
        }
        out->emitter_count++;
    }
    return PS_OK;
}
