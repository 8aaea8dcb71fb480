/* accel.c: building an accelerator (from arrays or a scene), the brute-force
 * oracle, and the queries that dispatch between it and the octree. */
#include <float.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/clock.h"
#include "accel/accel_internal.h"

/* A triangle whose doubled area is within this fraction of its longest edge
 * squared has no area beyond rounding (coincident or collinear vertices): it
 * is left out, so that it never reports a hit with a meaningless normal. */
#define DEGENERATE_REL (8.0 * DBL_EPSILON)

/* Outside octree_trace_avx2.c, whose code must not run before this says yes. */
bool ps_accel_cpu_has_avx2(void)
{
#if defined(__GNUC__) && defined(__x86_64__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2");
#else
    return false;
#endif
}

static bool triangle_degenerate(const accel_tri *t)
{
    ps_vec3 p0 = ps_v3(t->v[0], t->v[1], t->v[2]);
    ps_vec3 e0 = ps_v3_sub(ps_v3(t->v[3], t->v[4], t->v[5]), p0);
    ps_vec3 e1 = ps_v3_sub(ps_v3(t->v[6], t->v[7], t->v[8]), p0);
    ps_vec3 e2 = ps_v3_sub(e1, e0);
    double longest2 = fmax(ps_v3_len2(e0), fmax(ps_v3_len2(e1), ps_v3_len2(e2)));
    return !(ps_v3_len(ps_v3_cross(e0, e1)) > DEGENERATE_REL * longest2);
}

void ps_accel_destroy(ps_accel *a)
{
    if (!a)
        return;
    free(a->tris);
    free(a->tri_ids);
    free(a->spheres);
    free(a->sphere_ids);
    free(a->nodes);
    free(a->refs);
    free(a);
}

/* Checks the input and copies its hittable primitives into a. */
static ps_status copy_input(ps_accel *a, const ps_accel_input *in, ps_error *err)
{
    /* Step 1: shapes of the arrays. */
    if ((in->triangle_count && (!in->indices || !in->positions)) ||
        (in->sphere_count && (!in->sphere_centers || !in->sphere_radii)))
        return ps_error_set(err, PS_ERR_RANGE, "accel: input counts given without their arrays");
    /* Ids and counts are 32-bit; leave room for the "no hit" id. */
    if (in->triangle_count > UINT32_MAX - 1 || in->sphere_count > UINT32_MAX - 1 - in->triangle_count)
        return ps_error_set(err, PS_ERR_LIMIT, "accel: %zu triangles and %zu spheres are more than 2^32 primitives",
                            in->triangle_count, in->sphere_count);
    a->input_triangles = in->triangle_count;
    a->input_spheres = in->sphere_count;
    a->bounds = ps_aabb_empty();
    a->tris = malloc(sizeof *a->tris * (in->triangle_count ? in->triangle_count : 1));
    a->tri_ids = malloc(sizeof *a->tri_ids * (in->triangle_count ? in->triangle_count : 1));
    a->spheres = malloc(sizeof *a->spheres * (in->sphere_count ? in->sphere_count : 1));
    a->sphere_ids = malloc(sizeof *a->sphere_ids * (in->sphere_count ? in->sphere_count : 1));
    if (!a->tris || !a->tri_ids || !a->spheres || !a->sphere_ids)
        return ps_error_set(err, PS_ERR_NOMEM, "accel: out of memory for %zu triangles", in->triangle_count);

    /* Step 2: triangles: indices in range, positions finite, area non-zero. */
    for (size_t t = 0; t < in->triangle_count; t++) {
        accel_tri tri;
        for (int k = 0; k < 3; k++) {
            uint32_t v = in->indices[3 * t + (size_t)k];
            if (v >= in->position_count)
                return ps_error_set(err, PS_ERR_RANGE, "accel: triangle %zu: vertex index %u out of range (%zu positions)",
                                    t, (unsigned)v, in->position_count);
            ps_vec3 p = in->positions[v];
            if (!ps_v3_isfinite(p))
                return ps_error_set(err, PS_ERR_RANGE, "accel: triangle %zu: vertex %u is not finite", t, (unsigned)v);
            tri.v[3 * k] = p.x;
            tri.v[3 * k + 1] = p.y;
            tri.v[3 * k + 2] = p.z;
            a->bounds = ps_aabb_point(a->bounds, p);
        }
        if (triangle_degenerate(&tri))
            continue;
        a->tris[a->tri_count] = tri;
        a->tri_ids[a->tri_count++] = (uint32_t)t;
    }

    /* Step 3: spheres: finite, radius >= 0; radius 0 is kept out of the search. */
    for (size_t k = 0; k < in->sphere_count; k++) {
        ps_vec3 c = in->sphere_centers[k];
        double r = in->sphere_radii[k];
        if (!ps_v3_isfinite(c) || !isfinite(r) || r < 0.0)
            return ps_error_set(err, PS_ERR_RANGE, "accel: sphere %zu: centre or radius %g not valid", k, r);
        ps_vec3 rv = ps_v3(r, r, r);
        a->bounds = ps_aabb_union(a->bounds, (ps_aabb){ps_v3_sub(c, rv), ps_v3_add(c, rv)});
        if (!(r > 0.0))
            continue;
        accel_sphere *s = &a->spheres[a->sphere_count];
        s->c[0] = c.x;
        s->c[1] = c.y;
        s->c[2] = c.z;
        s->r = r;
        a->sphere_ids[a->sphere_count++] = (uint32_t)(in->triangle_count + k);
    }
    return PS_OK;
}

ps_status ps_accel_build(const ps_accel_input *in, const ps_accel_options *opt, ps_accel **out, ps_error *err)
{
    double start = ps_now_seconds();
    *out = NULL;
    ps_accel_options o = {PS_ACCEL_AUTO, 0, 0, false};
    if (opt)
        o = *opt;
    if (!in)
        return ps_error_set(err, PS_ERR_RANGE, "accel: no input");
    if (o.max_depth < 0 || o.leaf_prims < 0 || o.kind < PS_ACCEL_AUTO || o.kind > PS_ACCEL_BRUTE)
        return ps_error_set(err, PS_ERR_RANGE, "accel: options out of range (max_depth %d, leaf_prims %d)", o.max_depth,
                            o.leaf_prims);
    int max_depth = o.max_depth ? o.max_depth : PS_OCTREE_DEFAULT_MAX_DEPTH;
    if (max_depth > PS_OCTREE_MAX_DEPTH_LIMIT)
        max_depth = PS_OCTREE_MAX_DEPTH_LIMIT;
    int leaf_prims = o.leaf_prims ? o.leaf_prims : PS_OCTREE_DEFAULT_LEAF_PRIMS;

    ps_accel *a = calloc(1, sizeof *a);
    if (!a)
        return ps_error_set(err, PS_ERR_NOMEM, "accel: out of memory");
    ps_status st = copy_input(a, in, err);
    if (st != PS_OK) {
        ps_accel_destroy(a);
        return st;
    }
    double extent = ps_aabb_extent(a->bounds);
    a->epsilon = fmax(PS_RAY_EPSILON_REL * extent, PS_RAY_EPSILON_MIN);

    /* Tiny scenes: a tree would cost more than it saves. */
    ps_accel_kind kind = o.kind;
    if (kind == PS_ACCEL_AUTO)
        kind = in->triangle_count + in->sphere_count < PS_ACCEL_BRUTE_MAX_PRIMS ? PS_ACCEL_BRUTE : PS_ACCEL_OCTREE;
    a->kind = kind;
    a->simd = !o.no_simd && ps_accel_cpu_has_avx2();
    a->prefetch_leaves = (size_t)a->tri_count * sizeof *a->tris > ACCEL_PREFETCH_BYTES;
    if (kind == PS_ACCEL_OCTREE) {
        st = ps_accel_octree_build(a, max_depth, leaf_prims, err);
        if (st != PS_OK) {
            ps_accel_destroy(a);
            return st;
        }
    }
    a->stats.kind = kind;
    a->stats.simd = a->simd;
    a->stats.bytes = sizeof *a + a->tri_count * (sizeof *a->tris + sizeof *a->tri_ids) +
                     a->sphere_count * (sizeof *a->spheres + sizeof *a->sphere_ids) +
                     a->node_count * sizeof *a->nodes + a->ref_count * sizeof *a->refs;
    a->stats.build_seconds = ps_now_seconds() - start;
    *out = a;
    return PS_OK;
}

ps_status ps_accel_build_scene(const ps_scene *s, const ps_accel_options *opt, ps_accel **out,
                               uint32_t **sphere_objects, ps_error *err)
{
    *out = NULL;
    if (sphere_objects)
        *sphere_objects = NULL;
    size_t npos, ntri, nobj;
    const ps_vec3 *pos = ps_scene_positions(s, &npos);
    const ps_triangle *tri = ps_scene_triangles(s, &ntri);
    const ps_object *obj = ps_scene_objects(s, &nobj);

    /* Step 1: the triangle soup's indices, and the spheres in object order. */
    size_t nsph = 0;
    for (size_t i = 0; i < nobj; i++)
        nsph += obj[i].type == PS_OBJ_SPHERE;
    uint32_t *indices = malloc(sizeof *indices * 3 * (ntri ? ntri : 1));
    ps_vec3 *centers = malloc(sizeof *centers * (nsph ? nsph : 1));
    double *radii = malloc(sizeof *radii * (nsph ? nsph : 1));
    uint32_t *map = malloc(sizeof *map * (nsph ? nsph : 1));
    if (!indices || !centers || !radii || !map) {
        free(indices);
        free(centers);
        free(radii);
        free(map);
        return ps_error_set(err, PS_ERR_NOMEM, "accel: out of memory for the scene's %zu triangles", ntri);
    }
    for (size_t t = 0; t < ntri; t++)
        for (int k = 0; k < 3; k++)
            indices[3 * t + (size_t)k] = tri[t].v[k];
    size_t k = 0;
    for (size_t i = 0; i < nobj; i++) {
        if (obj[i].type != PS_OBJ_SPHERE)
            continue;
        centers[k] = obj[i].center;
        radii[k] = obj[i].radius;
        map[k++] = (uint32_t)i;
    }

    /* Step 2: build over them. */
    ps_accel_input in = {pos, npos, indices, ntri, centers, radii, nsph};
    ps_status st = ps_accel_build(&in, opt, out, err);
    free(indices);
    free(centers);
    free(radii);
    if (st != PS_OK || !sphere_objects || nsph == 0) {
        free(map);
        return st;
    }
    *sphere_objects = map;
    return PS_OK;
}

/* ---- queries ------------------------------------------------------------------ */

/* Every primitive in turn; specialised per dominant axis like the traversal,
 * so both run the same triangle code. */
static PS_ALWAYS_INLINE bool brute(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit,
                                   bool any, int kx, int ky, int kz)
{
    ps_hit best = {tmax, UINT32_MAX, 0.0, 0.0};
    bool found = false;
    for (uint32_t p = 0; p < a->tri_count; p++) {
        double b1 = 0.0, b2 = 0.0;
        double t = accel_tri_hit(&a->tris[p], r, kx, ky, kz, &b1, &b2);
        if (!accel_hit_better(t, a->tri_ids[p], &best, found, tmin))
            continue;
        if (any)
            return true;
        best = (ps_hit){t, a->tri_ids[p], b1, b2};
        found = true;
    }
    for (uint32_t k = 0; k < a->sphere_count; k++) {
        double t = accel_sphere_hit(&a->spheres[k], r, tmin);
        if (!accel_hit_better(t, a->sphere_ids[k], &best, found, tmin))
            continue;
        if (any)
            return true;
        best = (ps_hit){t, a->sphere_ids[k], 0.0, 0.0};
        found = true;
    }
    if (found && !any)
        *hit = best;
    return found;
}

static bool brute_dispatch(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit, bool any)
{
    switch (r->kz) {
    case 0:
        return brute(a, r, tmin, tmax, hit, any, 1, 2, 0);
    case 1:
        return brute(a, r, tmin, tmax, hit, any, 2, 0, 1);
    default:
        return brute(a, r, tmin, tmax, hit, any, 0, 1, 2);
    }
}

static bool query(const ps_accel *a, ps_ray ray, double tmin, double tmax, ps_hit *hit, bool any, bool force_brute)
{
    accel_ray r;
    /* NaN limits fail this comparison too. */
    if (!a || !(tmin < tmax) || !accel_ray_prepare(ray, &r, a->sphere_count > 0))
        return false;
    if (force_brute)
        return brute_dispatch(a, &r, tmin, tmax, hit, any);
    if (a->kind != PS_ACCEL_OCTREE)
        return a->simd ? ps_accel_brute_avx2(a, &r, tmin, tmax, hit, any) : brute_dispatch(a, &r, tmin, tmax, hit, any);
    if (a->simd)
        return ps_accel_octree_trace_avx2(a, &r, tmin, tmax, hit, any);
    return ps_accel_octree_trace(a, &r, tmin, tmax, hit, any);
}

bool ps_accel_intersect(const ps_accel *a, ps_ray r, double tmin, double tmax, ps_hit *hit)
{
    return query(a, r, tmin, tmax, hit, false, false);
}

bool ps_accel_occluded(const ps_accel *a, ps_ray r, double tmin, double tmax)
{
    return query(a, r, tmin, tmax, NULL, true, false);
}

bool ps_accel_intersect_brute(const ps_accel *a, ps_ray r, double tmin, double tmax, ps_hit *hit)
{
    return query(a, r, tmin, tmax, hit, false, true);
}

double ps_accel_epsilon(const ps_accel *a) { return a->epsilon; }
ps_aabb ps_accel_bounds(const ps_accel *a) { return a->bounds; }
size_t ps_accel_prim_count(const ps_accel *a) { return a->input_triangles + a->input_spheres; }
size_t ps_accel_triangle_count(const ps_accel *a) { return a->input_triangles; }

void ps_accel_get_stats(const ps_accel *a, ps_accel_stats *st) { *st = a->stats; }
