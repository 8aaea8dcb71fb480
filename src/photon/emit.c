/* emit.c: light sampling, bounding spheres and caustic cones. */
#include "photon/emit.h"

#include <math.h>
#include <stdlib.h>

#include "core/sampling.h"
#include "scene/ies.h"

/* Directions within this of a full sphere are sampled as the light's own
 * distribution: a caustic cone that wide gains nothing and only adds variance. */
#define FULL_CAUSTIC_CONE_COS (-1.0 + 1e-12)

typedef struct light_data {
    ps_vec3 center;
    double radius;
    uint32_t first_face, face_count; /* mesh lights: range in cdf / faces */
} light_data;

struct ps_light_sampler {
    const ps_scene *scene;
    light_data *lights;
    uint32_t *faces; /* mesh light faces (triangle indices), all lights concatenated */
    double *cdf;     /* per face: cumulative area within its light, last = 1 */
};

static ps_vec3 light_normal(const ps_light *L) { return L->direction; }

ps_status ps_light_sampler_create(const ps_scene *s, ps_light_sampler **out, ps_error *err)
{
    *out = NULL;
    size_t nl, ne, ntri, npos;
    const ps_light *lights = ps_scene_lights(s, &nl);
    const uint32_t *emitters = ps_scene_emitters(s, &ne);
    const ps_triangle *tris = ps_scene_triangles(s, &ntri);
    const ps_vec3 *pos = ps_scene_positions(s, &npos);
    ps_light_sampler *ls = calloc(1, sizeof *ls);
    if (ls) {
        ls->lights = calloc(nl ? nl : 1, sizeof *ls->lights);
        ls->faces = calloc(ne ? ne : 1, sizeof *ls->faces);
        ls->cdf = calloc(ne ? ne : 1, sizeof *ls->cdf);
    }
    if (!ls || !ls->lights || !ls->faces || !ls->cdf) {
        ps_light_sampler_destroy(ls);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the light tables", ps_scene_path(s));
    }
    ls->scene = s;
    for (size_t l = 0; l < nl; l++) {
        const ps_light *L = &lights[l];
        light_data *d = &ls->lights[l];
        switch (L->type) {
        case PS_LIGHT_POINT:
        case PS_LIGHT_SPOT:
        case PS_LIGHT_IES:
            d->center = L->position;
            d->radius = 0.0;
            break;
        case PS_LIGHT_QUAD: {
            ps_vec3 half1 = ps_v3_scale(L->edge1, 0.5), half2 = ps_v3_scale(L->edge2, 0.5);
            d->center = ps_v3_add(L->position, ps_v3_add(half1, half2));
            d->radius = fmax(ps_v3_len(ps_v3_add(half1, half2)), ps_v3_len(ps_v3_sub(half1, half2)));
            break;
        }
        case PS_LIGHT_DISC:
        case PS_LIGHT_SPHERE:
            d->center = L->position;
            d->radius = L->radius;
            break;
        case PS_LIGHT_MESH: {
            d->first_face = L->first_emitter;
            d->face_count = L->emitter_count;
            ps_aabb box = ps_aabb_empty();
            double total = 0.0;
            for (uint32_t k = 0; k < L->emitter_count; k++) {
                uint32_t t = emitters[L->first_emitter + k];
                ls->faces[L->first_emitter + k] = t;
                total += ps_scene_triangle_area(s, t);
                ls->cdf[L->first_emitter + k] = total;
                for (int v = 0; v < 3; v++)
                    box = ps_aabb_point(box, pos[tris[t].v[v]]);
            }
            for (uint32_t k = 0; k < L->emitter_count; k++)
                ls->cdf[L->first_emitter + k] = total > 0.0 ? ls->cdf[L->first_emitter + k] / total : 1.0;
            if (L->emitter_count)
                ls->cdf[L->first_emitter + L->emitter_count - 1] = 1.0;
            d->center = ps_aabb_center(box);
            double r2 = 0.0;
            for (uint32_t k = 0; k < L->emitter_count; k++)
                for (int v = 0; v < 3; v++)
                    r2 = fmax(r2, ps_v3_len2(ps_v3_sub(pos[tris[emitters[L->first_emitter + k]].v[v]], d->center)));
            d->radius = sqrt(r2);
            break;
        }
        }
    }
    *out = ls;
    return PS_OK;
}

void ps_light_sampler_destroy(ps_light_sampler *ls)
{
    if (!ls)
        return;
    free(ls->lights);
    free(ls->faces);
    free(ls->cdf);
    free(ls);
}

static const ps_light *light_at(const ps_light_sampler *ls, uint32_t l)
{
    size_t n;
    return &ps_scene_lights(ls->scene, &n)[l];
}

void ps_light_bounding_sphere(const ps_light_sampler *ls, uint32_t l, ps_vec3 *center, double *radius)
{
    *center = ls->lights[l].center;
    *radius = ls->lights[l].radius;
}

bool ps_light_caustic_cone(const ps_light_sampler *ls, uint32_t l, ps_vec3 center, double radius,
                           ps_caustic_cone *out)
{
    const ps_light *L = light_at(ls, l);
    const light_data *d = &ls->lights[l];
    double rho = radius + d->radius;
    ps_vec3 to = ps_v3_sub(center, d->center);
    double dist = ps_v3_len(to);
    if (dist <= rho) {
        /* The light is inside the widened sphere: every direction may hit it. */
        out->axis = ps_v3(0.0, 0.0, 1.0);
        out->cos_half = -1.0;
    } else {
        out->axis = ps_v3_scale(to, 1.0 / dist);
        double sin_half = rho / dist;
        out->cos_half = sqrt(fmax(0.0, 1.0 - sin_half * sin_half));
    }
    switch (L->type) {
    case PS_LIGHT_SPOT:
        if (out->cos_half > -1.0) {
            double between = acos(fmin(1.0, fmax(-1.0, ps_v3_dot(out->axis, L->direction))));
            if (between >= acos(L->cos_angle) + acos(out->cos_half))
                return false; /* the caustic cone and the spot's cone do not overlap */
        }
        return true;
    case PS_LIGHT_QUAD:
    case PS_LIGHT_DISC:
        /* Every point of the light lies in its plane and emits to one side. */
        return ps_v3_dot(ps_v3_sub(center, d->center), light_normal(L)) + radius > 0.0;
    default:
        return true;
    }
}

double ps_light_caustic_cone_share(const ps_light_sampler *ls, uint32_t l, const ps_caustic_cone *caustic)
{
    const ps_light *L = light_at(ls, l);
    if (caustic->cos_half <= FULL_CAUSTIC_CONE_COS)
        return 1.0;
    double omega = ps_cone_solid_angle(caustic->cos_half);
    switch (L->type) {
    case PS_LIGHT_POINT:
    case PS_LIGHT_SPHERE:
        return fmin(1.0, omega / (4.0 * PS_PI));
    case PS_LIGHT_SPOT:
        return fmin(1.0, omega / ps_cone_solid_angle(L->cos_angle));
    case PS_LIGHT_IES: /* the table's density along the axis, times the cone */
        return fmin(1.0, omega * ps_light_ies_density(ls->scene, L, caustic->axis));
    default: /* one-sided Lambertian: about omega / pi near the normal */
        return fmin(1.0, omega * PS_INV_PI);
    }
}

/* A point on area light l and the normal there, from u[0], u[1]. */
static void sample_area(const ps_light_sampler *ls, const ps_light *L, uint32_t l, double u0, double u1, ps_vec3 *p,
                        ps_vec3 *n)
{
    switch (L->type) {
    case PS_LIGHT_QUAD:
        *p = ps_v3_add(L->position, ps_v3_add(ps_v3_scale(L->edge1, u0), ps_v3_scale(L->edge2, u1)));
        *n = light_normal(L);
        return;
    case PS_LIGHT_DISC: {
        double x, y;
        ps_vec3 t, b;
        ps_sample_disc(u0, u1, &x, &y);
        ps_v3_basis(light_normal(L), &t, &b);
        *p = ps_v3_add(L->position, ps_v3_add(ps_v3_scale(t, x * L->radius), ps_v3_scale(b, y * L->radius)));
        *n = light_normal(L);
        return;
    }
    case PS_LIGHT_SPHERE:
        *n = ps_sample_sphere(u0, u1);
        *p = ps_v3_madd(L->position, *n, L->radius);
        return;
    default: { /* mesh: a face by area, then a point on it; u0 is reused within the face */
        const light_data *d = &ls->lights[l];
        const double *cdf = ls->cdf + d->first_face;
        uint32_t lo = 0, hi = d->face_count - 1;
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (cdf[mid] > u0)
                hi = mid;
            else
                lo = mid + 1;
        }
        double below = lo ? cdf[lo - 1] : 0.0, width = cdf[lo] - below;
        double v0 = width > 0.0 ? fmin(fmax((u0 - below) / width, 0.0), 0x1.fffffffffffffp-1) : 0.5;
        uint32_t tri = ls->faces[d->first_face + lo];
        size_t nt, np;
        const ps_triangle *T = &ps_scene_triangles(ls->scene, &nt)[tri];
        const ps_vec3 *pos = ps_scene_positions(ls->scene, &np);
        double b1, b2;
        ps_sample_triangle(v0, u1, &b1, &b2);
        ps_vec3 a = pos[T->v[0]], e1 = ps_v3_sub(pos[T->v[1]], a), e2 = ps_v3_sub(pos[T->v[2]], a);
        *p = ps_v3_add(a, ps_v3_add(ps_v3_scale(e1, b1), ps_v3_scale(e2, b2)));
        *n = ps_scene_triangle_normal(ls->scene, tri);
        return;
    }
    }
}

void ps_light_sample_point(const ps_light_sampler *ls, uint32_t l, double u0, double u1, ps_vec3 *p, ps_vec3 *n)
{
    sample_area(ls, light_at(ls, l), l, u0, u1, p, n);
}

/* An IES luminaire's photon direction. Without a cone: exactly the file's
 * distribution (ps_ies_sample inverts its bilinear table), so every photon
 * carries the same flux, power / N. Inside a caustic cone: uniform there and
 * weighted by the table's density, weight = density * cone solid angle, whose
 * mean over the cone is the fraction of the flux it holds. u[0], u[2], u[3]
 * pick the direction (u[1] is the point on the light: none). */
static bool emit_ies(const ps_light_sampler *ls, const ps_light *L, const ps_caustic_cone *cone, const double u[4],
                     ps_vec3 *dir, double *weight)
{
    if (cone) {
        *dir = ps_sample_cone(u[2], u[3], cone->axis, cone->cos_half);
        *weight = ps_light_ies_density(ls->scene, L, *dir) * ps_cone_solid_angle(cone->cos_half);
        return *weight > 0.0;
    }
    double theta, phi;
    ps_ies_sample(ps_scene_ies_profile(ls->scene, L->profile), u[0], u[2], u[3], &theta, &phi);
    *dir = ps_v3_norm(ps_light_ies_direction(L, theta, phi));
    *weight = 1.0;
    return true;
}

bool ps_light_emit(const ps_light_sampler *ls, uint32_t l, const ps_caustic_cone *caustic, const double u[4],
                   ps_emission *out)
{
    const ps_light *L = light_at(ls, l);
    if (caustic && caustic->cos_half <= FULL_CAUSTIC_CONE_COS)
        caustic = NULL; /* the whole sphere: the light's own distribution is the better sampler */
    double weight = 1.0;
    ps_vec3 origin, dir, normal = ps_v3(0.0, 0.0, 0.0);

    switch (L->type) {
    case PS_LIGHT_POINT:
        origin = L->position;
        if (caustic) {
            dir = ps_sample_cone(u[2], u[3], caustic->axis, caustic->cos_half);
            weight = ps_cone_solid_angle(caustic->cos_half) / (4.0 * PS_PI);
        } else {
            dir = ps_sample_sphere(u[2], u[3]);
        }
        break;
    case PS_LIGHT_SPOT: {
        origin = L->position;
        double spot_omega = ps_cone_solid_angle(L->cos_angle);
        if (caustic && ps_cone_solid_angle(caustic->cos_half) < spot_omega) {
            /* Sample the narrower of the caustic cone and the spot's cone,
             * reject what the other one excludes. */
            dir = ps_sample_cone(u[2], u[3], caustic->axis, caustic->cos_half);
            if (ps_v3_dot(dir, L->direction) < L->cos_angle)
                return false;
            weight = ps_cone_solid_angle(caustic->cos_half) / spot_omega;
        } else {
            dir = ps_sample_cone(u[2], u[3], L->direction, L->cos_angle);
            if (caustic && ps_v3_dot(dir, caustic->axis) < caustic->cos_half)
                return false;
        }
        break;
    }
    case PS_LIGHT_IES:
        origin = L->position;
        if (!emit_ies(ls, L, caustic, u, &dir, &weight))
            return false;
        break;
    default: {
        sample_area(ls, L, l, u[0], u[1], &origin, &normal);
        if (caustic) {
            /* Uniform in the caustic cone, weighted by the Lambertian cosine: power
             * L_e cos A omega = flux * cos * omega / pi, with L_e = flux / (pi A). */
            dir = ps_sample_cone(u[2], u[3], caustic->axis, caustic->cos_half);
            double c = ps_v3_dot(dir, normal);
            if (c <= 0.0)
                return false;
            weight = c * ps_cone_solid_angle(caustic->cos_half) * PS_INV_PI;
        } else {
            dir = ps_sample_cosine(u[2], u[3], normal);
        }
        break;
    }
    }
    out->ray = ps_ray_make(origin, dir);
    out->power = ps_rgb_scale(L->power, weight);
    out->weight = weight;
    out->normal = normal;
    return true;
}
