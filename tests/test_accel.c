/* test_accel.c: the ray accelerator: the octree against the brute-force
 * oracle (same primitive, same t) on random and adversarial rays,
 * watertightness on closed meshes, analytic sphere distances at three scales,
 * degenerate inputs, scale invariance and scene building; the AVX2 traversal
 * against the scalar one (bit for bit); the nearest-geometry query against
 * closed forms and its own oracle. */
#include "test.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "accel/accel_internal.h" /* white box: the root cube, to aim rays at cell planes */
#include "core/rng.h"
#include "scene/scene.h"
#include "scene/tessellate.h"

/* Octree and oracle run the same primitive code, so t agrees exactly; this
 * is the tolerance the issue allows. */
#define T_REL_TOL 1e-9

/* ---- a growable triangle soup ------------------------------------------------ */

typedef struct soup {
    ps_vec3 *pos;
    size_t npos, cap_pos;
    uint32_t *idx;
    size_t ntri, cap_tri;
    ps_vec3 centers[64];
    double radii[64];
    size_t nsph;
} soup;

static uint32_t soup_vertex(soup *s, ps_vec3 p)
{
    if (s->npos == s->cap_pos) {
        s->cap_pos = s->cap_pos ? 2 * s->cap_pos : 1024;
        s->pos = realloc(s->pos, sizeof *s->pos * s->cap_pos);
        assert_non_null(s->pos);
    }
    s->pos[s->npos] = p;
    return (uint32_t)s->npos++;
}

static void soup_tri(soup *s, uint32_t a, uint32_t b, uint32_t c)
{
    if (s->ntri == s->cap_tri) {
        s->cap_tri = s->cap_tri ? 2 * s->cap_tri : 1024;
        s->idx = realloc(s->idx, sizeof *s->idx * 3 * s->cap_tri);
        assert_non_null(s->idx);
    }
    s->idx[3 * s->ntri] = a;
    s->idx[3 * s->ntri + 1] = b;
    s->idx[3 * s->ntri + 2] = c;
    s->ntri++;
}

static void soup_tri_p(soup *s, ps_vec3 a, ps_vec3 b, ps_vec3 c)
{
    uint32_t i = soup_vertex(s, a), j = soup_vertex(s, b), k = soup_vertex(s, c);
    soup_tri(s, i, j, k);
}

static void soup_sphere(soup *s, ps_vec3 c, double r)
{
    assert_true(s->nsph < 64);
    s->centers[s->nsph] = c;
    s->radii[s->nsph++] = r;
}

static void soup_mesh(soup *s, const ps_trimesh *m)
{
    uint32_t base = (uint32_t)s->npos;
    for (uint32_t v = 0; v < m->vertex_count; v++)
        soup_vertex(s, m->positions[v]);
    for (uint32_t t = 0; t < m->triangle_count; t++)
        soup_tri(s, base + m->indices[3 * t], base + m->indices[3 * t + 1], base + m->indices[3 * t + 2]);
}

static void soup_free(soup *s)
{
    free(s->pos);
    free(s->idx);
    memset(s, 0, sizeof *s);
}

static ps_accel_input soup_input(const soup *s)
{
    ps_accel_input in = {s->pos, s->npos, s->idx, s->ntri, s->centers, s->radii, s->nsph};
    return in;
}

static ps_accel *build_with(const soup *s, ps_accel_kind kind, int max_depth, int leaf_prims, bool no_simd)
{
    ps_accel_input in = soup_input(s);
    ps_accel_options opt = {kind, max_depth, leaf_prims, no_simd};
    ps_accel *a = NULL;
    ps_error err;
    if (ps_accel_build(&in, &opt, &a, &err) != PS_OK)
        fail_msg("build: %s", err.msg);
    return a;
}

static ps_accel *build(const soup *s, ps_accel_kind kind, int max_depth, int leaf_prims)
{
    return build_with(s, kind, max_depth, leaf_prims, false);
}

static ps_vec3 soup_tri_vertex(const soup *s, size_t t, int k) { return s->pos[s->idx[3 * t + (size_t)k]]; }

/* ---- random numbers --------------------------------------------------------------- */

static double uni(ps_rng *r, double lo, double hi) { return lo + (hi - lo) * ps_rng_uniform(r); }

static ps_vec3 rand_box(ps_rng *r, double lo, double hi) { return ps_v3(uni(r, lo, hi), uni(r, lo, hi), uni(r, lo, hi)); }

static ps_vec3 rand_dir(ps_rng *r)
{
    for (;;) {
        ps_vec3 v = rand_box(r, -1, 1);
        double l2 = ps_v3_len2(v);
        if (l2 > 1e-4 && l2 <= 1)
            return ps_v3_scale(v, 1 / sqrt(l2));
    }
}

/* ---- comparing the octree with the oracle ------------------------------------------ */

typedef struct ray_case {
    ps_ray r;
    double tmin, tmax;
} ray_case;

/* The octree (a) and the oracle must agree exactly: hit or miss, primitive,
 * t and barycentrics; occluded must agree with intersect. Returns hits. */
static size_t check_against_brute(const ps_accel *a, const ray_case *rays, size_t n)
{
    size_t hits = 0;
    for (size_t i = 0; i < n; i++) {
        ps_hit h1 = {0}, h2 = {0};
        const ray_case *c = &rays[i];
        bool f1 = ps_accel_intersect(a, c->r, c->tmin, c->tmax, &h1);
        bool f2 = ps_accel_intersect_brute(a, c->r, c->tmin, c->tmax, &h2);
        bool occ = ps_accel_occluded(a, c->r, c->tmin, c->tmax);
        if (f1 != f2 || (f1 && (h1.prim != h2.prim || !(fabs(h1.t - h2.t) <= T_REL_TOL * fabs(h2.t)) ||
                                fabs(h1.b1 - h2.b1) > 1e-9 || fabs(h1.b2 - h2.b2) > 1e-9)))
            fail_msg("ray %zu o=(%.17g %.17g %.17g) d=(%.17g %.17g %.17g) [%g, %g]: octree %d prim %u t %.17g, "
                     "brute %d prim %u t %.17g",
                     i, c->r.o.x, c->r.o.y, c->r.o.z, c->r.d.x, c->r.d.y, c->r.d.z, c->tmin, c->tmax, f1,
                     (unsigned)h1.prim, h1.t, f2, (unsigned)h2.prim, h2.t);
        if (occ != f1)
            fail_msg("ray %zu: occluded %d but intersect %d", i, occ, f1);
        if (f1) {
            hits++;
            assert_true(h1.t > c->tmin && h1.t < c->tmax);
            /* Nothing is hit before the nearest hit. */
            assert_false(ps_accel_occluded(a, c->r, c->tmin, h1.t));
        }
    }
    return hits;
}

/* ---- the random soup of test 1 ---------------------------------------------------- */

/* Random triangles of sizes from 3 mm to 50 cm in [-1, 1]^3, a bumpy grid and
 * a closed sphere mesh (shared edges), spheres, and triangles lying exactly in
 * the root's split planes (where the tree must file them on both sides). */
static void make_soup(soup *s, ps_rng *rng)
{
    memset(s, 0, sizeof *s);
    for (int t = 0; t < 3000; t++) {
        ps_vec3 c = rand_box(rng, -1, 1);
        double size = pow(10.0, uni(rng, -2.5, -0.3));
        soup_tri_p(s, ps_v3_madd(c, rand_dir(rng), size), ps_v3_madd(c, rand_dir(rng), size),
                   ps_v3_madd(c, rand_dir(rng), size));
    }
    /* A 24 x 24 grid of quads, vertices shared. */
    enum { GRID = 24 };
    uint32_t base = (uint32_t)s->npos;
    for (int i = 0; i <= GRID; i++)
        for (int j = 0; j <= GRID; j++) {
            double x = -0.8 + 1.6 * i / GRID, z = -0.8 + 1.6 * j / GRID;
            soup_vertex(s, ps_v3(x, -0.3 + 0.1 * sin(5 * x) * cos(4 * z), z));
        }
    for (int i = 0; i < GRID; i++)
        for (int j = 0; j < GRID; j++) {
            uint32_t v00 = base + (uint32_t)(i * (GRID + 1) + j), v01 = v00 + 1, v10 = v00 + GRID + 1, v11 = v10 + 1;
            soup_tri(s, v00, v10, v11);
            soup_tri(s, v00, v11, v01);
        }
    ps_trimesh m;
    ps_error err;
    assert_int_equal(ps_sphere_tessellate(ps_v3(0.3, -0.2, 0.4), 0.3, 0.02, &m, &err), PS_OK);
    soup_mesh(s, &m);
    ps_trimesh_free(&m);
    for (int k = 0; k < 12; k++)
        soup_sphere(s, rand_box(rng, -0.9, 0.9), pow(10.0, uni(rng, -2, -0.7)));
    /* Bounds: make sure they reach +-1.05 in every axis so that the planes added below stay inside. */
    soup_tri_p(s, ps_v3(-1.05, -1.05, -1.05), ps_v3(-1.0, -1.05, -1.05), ps_v3(-1.05, -1.0, -1.05));
    soup_tri_p(s, ps_v3(1.05, 1.05, 1.05), ps_v3(1.0, 1.05, 1.05), ps_v3(1.05, 1.0, 1.05));
}

/* Split planes of the first levels along each axis: root_lo + side * k / 2^level. */
static double cell_plane(const ps_accel *a, int axis, ps_rng *rng)
{
    int level = 1 + (int)ps_rng_below(rng, 4);
    uint32_t k = ps_rng_below(rng, (1u << level) + 1);
    return ps_v3_get(a->root_lo, axis) + a->root_side * k / (double)(1u << level);
}

/* Triangles exactly in the first split planes, squares with a shared diagonal. */
static void add_plane_triangles(soup *s, const ps_accel *a)
{
    for (int axis = 0; axis < 3; axis++) {
        double mid = ps_v3_get(a->root_lo, axis) + 0.5 * a->root_side;
        double q = ps_v3_get(a->root_lo, axis) + 0.25 * a->root_side;
        double planes[2] = {mid, q};
        for (int k = 0; k < 2; k++) {
            double c[3][4];
            double u0 = -0.6, u1 = 0.4;
            int ua = (axis + 1) % 3, va = (axis + 2) % 3;
            ps_vec3 p[4];
            double uv[4][2] = {{u0, u0}, {u1, u0}, {u1, u1}, {u0, u1}};
            for (int v = 0; v < 4; v++) {
                c[axis][v] = planes[k];
                c[ua][v] = uv[v][0];
                c[va][v] = uv[v][1];
                p[v] = ps_v3(c[0][v], c[1][v], c[2][v]);
            }
            uint32_t i0 = soup_vertex(s, p[0]), i1 = soup_vertex(s, p[1]), i2 = soup_vertex(s, p[2]),
                     i3 = soup_vertex(s, p[3]);
            soup_tri(s, i0, i1, i2);
            soup_tri(s, i0, i2, i3);
        }
    }
}

enum { RAY_COUNT = 24000 };

/* Random and adversarial rays over the soup (see test 1). */
static size_t make_rays(const soup *s, const ps_accel *a, ps_rng *rng, ray_case *rays)
{
    size_t n = 0;
    double eps = ps_accel_epsilon(a);
    /* Step 1: random origins inside and outside the root, random directions of random length. */
    for (int i = 0; i < 8000; i++) {
        ps_vec3 d = ps_v3_scale(rand_dir(rng), pow(10.0, uni(rng, -3, 3)));
        rays[n++] = (ray_case){{rand_box(rng, -1.6, 1.6), d}, 0.0, INFINITY};
    }
    /* Step 2: aimed exactly at vertices, with finite tmax past them. */
    for (int i = 0; i < 3000; i++) {
        ps_vec3 o = rand_box(rng, -1.5, 1.5);
        ps_vec3 v = s->pos[s->idx[ps_rng_below(rng, (uint32_t)(3 * s->ntri))]];
        rays[n++] = (ray_case){{o, ps_v3_sub(v, o)}, 0.0, i % 2 ? INFINITY : 2.0};
    }
    /* Step 3: at edge midpoints (shared edges of the grid and the sphere mesh among them). */
    for (int i = 0; i < 3000; i++) {
        size_t t = 3000 + ps_rng_below(rng, (uint32_t)(s->ntri - 3000));
        int k = (int)ps_rng_below(rng, 3);
        ps_vec3 m = ps_v3_scale(ps_v3_add(soup_tri_vertex(s, t, k), soup_tri_vertex(s, t, (k + 1) % 3)), 0.5);
        ps_vec3 o = rand_box(rng, -1.5, 1.5);
        rays[n++] = (ray_case){{o, ps_v3_sub(m, o)}, 0.0, INFINITY};
    }
    /* Step 4: in the plane of a triangle, from outside it toward its centroid. */
    for (int i = 0; i < 1500; i++) {
        size_t t = ps_rng_below(rng, (uint32_t)s->ntri);
        ps_vec3 p0 = soup_tri_vertex(s, t, 0), e0 = ps_v3_sub(soup_tri_vertex(s, t, 1), p0),
                e1 = ps_v3_sub(soup_tri_vertex(s, t, 2), p0);
        ps_vec3 o = ps_v3_madd(ps_v3_madd(p0, e0, uni(rng, -2, -0.5)), e1, uni(rng, -2, 3));
        ps_vec3 c = ps_v3_madd(ps_v3_madd(p0, e0, 1.0 / 3), e1, 1.0 / 3);
        rays[n++] = (ray_case){{o, ps_v3_sub(c, o)}, 0.0, INFINITY};
    }
    /* Step 5: axis-parallel rays, and rays with one zero component. */
    for (int i = 0; i < 3000; i++) {
        ps_vec3 d = ps_v3(0, 0, 0);
        int axis = (int)ps_rng_below(rng, 3);
        double sign = ps_rng_below(rng, 2) ? 1.0 : -1.0;
        if (i % 3 == 0) {
            d = rand_dir(rng);
            d = axis == 0 ? ps_v3(0, d.y, d.z) : axis == 1 ? ps_v3(d.x, 0, d.z) : ps_v3(d.x, d.y, 0);
        } else {
            d = axis == 0 ? ps_v3(sign, 0, 0) : axis == 1 ? ps_v3(0, sign, 0) : ps_v3(0, 0, sign);
        }
        rays[n++] = (ray_case){{rand_box(rng, -1.2, 1.2), d}, 0.0, INFINITY};
    }
    /* Step 6: origins exactly on cell planes (one, two or three coordinates),
     * random or axis-parallel directions, some lying in the plane. */
    for (int i = 0; i < 3000; i++) {
        double o[3] = {uni(rng, -1.2, 1.2), uni(rng, -1.2, 1.2), uni(rng, -1.2, 1.2)};
        int planes = 1 + (int)ps_rng_below(rng, 3);
        for (int k = 0; k < planes; k++) {
            int axis = (int)ps_rng_below(rng, 3);
            o[axis] = cell_plane(a, axis, rng);
        }
        ps_vec3 d = rand_dir(rng);
        int axis = (int)ps_rng_below(rng, 3);
        if (i % 3 == 1) /* lying in a plane through the origin */
            d = axis == 0 ? ps_v3(0, d.y, d.z) : axis == 1 ? ps_v3(d.x, 0, d.z) : ps_v3(d.x, d.y, 0);
        else if (i % 3 == 2)
            d = axis == 0 ? ps_v3(-1, 0, 0) : axis == 1 ? ps_v3(0, 1, 0) : ps_v3(0, 0, -1);
        rays[n++] = (ray_case){{ps_v3(o[0], o[1], o[2]), d}, 0.0, INFINITY};
    }
    /* Step 7: rays leaving a surface: from a vertex, with tmin = epsilon; and
     * random limits (tmax between hits). */
    for (int i = 0; i < 1500; i++) {
        ps_vec3 v = s->pos[s->idx[ps_rng_below(rng, (uint32_t)(3 * s->ntri))]];
        rays[n++] = (ray_case){{v, rand_dir(rng)}, eps, INFINITY};
    }
    while (n < RAY_COUNT) {
        double t0 = uni(rng, 0, 1), t1 = t0 + uni(rng, 0, 2);
        rays[n++] = (ray_case){{rand_box(rng, -1.3, 1.3), rand_dir(rng)}, t0, t1};
    }
    return n;
}

/* 1 and 6: the octree (default, shallow, fine-leaved) equals the oracle on
 * every ray, and occluded agrees with intersect. */
static void octree_matches_brute_force(void **state)
{
    (void)state;
    ps_rng rng = ps_rng_make(1, PS_STREAM_TEST, 0);
    soup s;
    make_soup(&s, &rng);
    /* The root depends only on the bounds, which the plane triangles stay inside. */
    ps_accel *probe = build(&s, PS_ACCEL_OCTREE, 0, 0);
    add_plane_triangles(&s, probe);
    ps_accel *a = build(&s, PS_ACCEL_OCTREE, 0, 0);
    assert_true(a->root_side == probe->root_side && a->root_lo.x == probe->root_lo.x);
    ps_accel_destroy(probe);

    ps_accel_stats st;
    ps_accel_get_stats(a, &st);
    assert_int_equal(st.kind, PS_ACCEL_OCTREE);
    assert_true(st.nodes > 100 && st.leaves > 50 && st.max_depth_reached >= 3);
    /* The cost model keeps duplication bounded (triangles up to half the
     * scene wide are filed in many cells; an exploding tree would make
     * hundreds of references each). */
    assert_true(st.prim_refs < 16 * (s.ntri + s.nsph));
    assert_int_equal(ps_accel_prim_count(a), s.ntri + s.nsph);
    assert_int_equal(ps_accel_triangle_count(a), s.ntri);

    ray_case *rays = malloc(sizeof *rays * RAY_COUNT);
    size_t n = make_rays(&s, a, &rng, rays);
    assert_true(n >= 20000);
    size_t hits = check_against_brute(a, rays, n);
    /* A real mixture of hits and misses. */
    assert_true(hits > n / 3 && hits < n - n / 20);

    /* Other shapes of tree must give the very same answers. */
    ps_accel *shallow = build(&s, PS_ACCEL_OCTREE, 2, 0);
    ps_accel *fine = build(&s, PS_ACCEL_OCTREE, 0, 1);
    ps_accel_get_stats(shallow, &st);
    assert_true(st.max_depth_reached <= 2);
    assert_int_equal(check_against_brute(shallow, rays, n / 4), check_against_brute(a, rays, n / 4));
    assert_int_equal(check_against_brute(fine, rays, n / 4), check_against_brute(a, rays, n / 4));
    ps_accel_destroy(shallow);
    ps_accel_destroy(fine);
    free(rays);
    ps_accel_destroy(a);
    soup_free(&s);
}

/* ---- 2: watertightness ------------------------------------------------------------ */

/* Rays from interior points (inside(p) says which) in random directions, and
 * aimed exactly at every vertex and every edge midpoint, must all hit, at a
 * point inside the mesh's box; aimed rays exactly where they aimed (t = 1,
 * the mesh being convex). Returns the number of rays. */
static size_t check_closed(const soup *s, ps_vec3 inner_lo, ps_vec3 inner_hi, ps_rng *rng, int random_rays)
{
    ps_accel *a = build(s, PS_ACCEL_OCTREE, 0, 0);
    ps_aabb box = ps_accel_bounds(a);
    double slack = 1e-9 * ps_aabb_extent(box);
    box.lo = ps_v3_sub(box.lo, ps_v3(slack, slack, slack));
    box.hi = ps_v3_add(box.hi, ps_v3(slack, slack, slack));
    size_t rays = 0;
    for (size_t i = 0; i < 3 * s->ntri + (size_t)random_rays; i++) {
        ps_vec3 o = ps_v3(uni(rng, inner_lo.x, inner_hi.x), uni(rng, inner_lo.y, inner_hi.y),
                          uni(rng, inner_lo.z, inner_hi.z));
        for (int aim = 0; aim < 2; aim++) {
            ps_vec3 target;
            bool aimed = true;
            if (i >= 3 * s->ntri) {
                if (aim)
                    break;
                target = ps_v3_add(o, rand_dir(rng));
                aimed = false;
            } else if (aim == 0) {
                target = soup_tri_vertex(s, i / 3, (int)(i % 3));
            } else {
                size_t t = i / 3;
                int k = (int)(i % 3);
                target = ps_v3_scale(ps_v3_add(soup_tri_vertex(s, t, k), soup_tri_vertex(s, t, (k + 1) % 3)), 0.5);
            }
            ps_ray r = {o, ps_v3_sub(target, o)};
            ps_hit h;
            rays++;
            if (!ps_accel_intersect(a, r, 0.0, INFINITY, &h))
                fail_msg("ray %zu (aim %d) from (%.17g %.17g %.17g) to (%.17g %.17g %.17g) escaped", i, aim, o.x, o.y,
                         o.z, target.x, target.y, target.z);
            assert_true(ps_aabb_contains(box, ps_ray_at(r, h.t)));
            if (aimed)
                assert_near(h.t, 1.0, 1e-9);
        }
    }
    ps_accel_destroy(a);
    return rays;
}

/* A cube of side 2*half around c, each face an n x n grid of quads; the
 * shared vertices are computed from integer grid coordinates, so every face
 * meeting at an edge sees the same numbers. */
static void make_cube(soup *s, ps_vec3 c, double half, int n)
{
    memset(s, 0, sizeof *s);
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            int ua = (axis + 1) % 3, va = (axis + 2) % 3;
            uint32_t base = (uint32_t)s->npos;
            for (int i = 0; i <= n; i++)
                for (int j = 0; j <= n; j++) {
                    double q[3];
                    q[axis] = side ? 1.0 : -1.0;
                    q[ua] = -1.0 + 2.0 * i / n;
                    q[va] = -1.0 + 2.0 * j / n;
                    soup_vertex(s, ps_v3(c.x + half * q[0], c.y + half * q[1], c.z + half * q[2]));
                }
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) {
                    uint32_t v00 = base + (uint32_t)(i * (n + 1) + j), v01 = v00 + 1, v10 = v00 + (uint32_t)n + 1,
                             v11 = v10 + 1;
                    /* Alternate the diagonal so that both orientations of shared diagonals occur. */
                    if ((i + j) % 2) {
                        soup_tri(s, v00, v10, v11);
                        soup_tri(s, v00, v11, v01);
                    } else {
                        soup_tri(s, v00, v10, v01);
                        soup_tri(s, v10, v11, v01);
                    }
                }
        }
}

static void watertight_closed_meshes(void **state)
{
    (void)state;
    ps_rng rng = ps_rng_make(2, PS_STREAM_TEST, 0);
    size_t rays = 0;

    /* The tessellated sphere: interior points well inside the inscribed mesh. */
    ps_trimesh m;
    ps_error err;
    ps_vec3 c = ps_v3(0.35, 0.4, 0.2);
    double r = 0.4;
    assert_int_equal(ps_sphere_tessellate(c, r, PS_SPHERE_DEFAULT_TOLERANCE, &m, &err), PS_OK);
    soup s;
    memset(&s, 0, sizeof s);
    soup_mesh(&s, &m);
    ps_trimesh_free(&m);
    double inner = 0.5 * r;
    rays += check_closed(&s, ps_v3(c.x - inner, c.y - inner, c.z - inner), ps_v3(c.x + inner, c.y + inner, c.z + inner),
                         &rng, 20000);
    soup_free(&s);

    /* A subdivided cube at the origin, and a small one far from it. */
    make_cube(&s, ps_v3(0, 0, 0), 1.0, 40);
    rays += check_closed(&s, ps_v3(-0.95, -0.95, -0.95), ps_v3(0.95, 0.95, 0.95), &rng, 20000);
    soup_free(&s);
    ps_vec3 far = ps_v3(1e3, -2e3, 5e2);
    double half = 1e-1;
    make_cube(&s, far, half, 12);
    rays += check_closed(&s, ps_v3_sub(far, ps_v3(0.9 * half, 0.9 * half, 0.9 * half)),
                         ps_v3_add(far, ps_v3(0.9 * half, 0.9 * half, 0.9 * half)), &rng, 5000);
    soup_free(&s);
    assert_true(rays >= 100000);
}

/* ---- 3: spheres ---------------------------------------------------------------- */

/* One sphere of radius r at c (an octree over it and a few triangles far
 * away, so the tree has cells): analytic distances, relative to r. */
static void check_sphere_at_scale(ps_vec3 c, double r)
{
    soup s;
    memset(&s, 0, sizeof s);
    soup_sphere(&s, c, r);
    for (int k = 0; k < 20; k++) {
        ps_vec3 p = ps_v3_add(c, ps_v3(8 * r, 0.4 * r * k, 0.5 * r)); /* clear of the rays below */
        soup_tri_p(&s, p, ps_v3_add(p, ps_v3(0, 0.3 * r, 0)), ps_v3_add(p, ps_v3(0, 0, 0.3 * r)));
    }
    ps_accel *a = build(&s, PS_ACCEL_OCTREE, 0, 1);
    double eps = ps_accel_epsilon(a);
    uint32_t sphere_id = (uint32_t)s.ntri;
    ps_hit h;
    const double tol = 1e-12;

    /* Through the centre from distance 3r: t = 3r - r, in units of |d|. */
    ps_vec3 o = ps_v3_add(c, ps_v3(0, 0, 3 * r));
    assert_true(ps_accel_intersect(a, (ps_ray){o, ps_v3(0, 0, -1)}, 0, INFINITY, &h));
    assert_int_equal(h.prim, sphere_id);
    assert_near(h.t / r, 2.0, tol);
    assert_near(h.b1, 0.0, 0);
    /* A direction of length 4r: t counts in |d|. */
    assert_true(ps_accel_intersect(a, (ps_ray){o, ps_v3(0, 0, -4 * r)}, 0, INFINITY, &h));
    assert_near(h.t, 0.5, tol);
    /* From the centre: t = r; from inside off-centre, the far root. */
    assert_true(ps_accel_intersect(a, (ps_ray){c, ps_v3(0.6, 0.8, 0)}, 0, INFINITY, &h));
    assert_near(h.t / r, 1.0, tol);
    assert_true(ps_accel_intersect(a, (ps_ray){ps_v3_add(c, ps_v3(0.5 * r, 0, 0)), ps_v3(-1, 0, 0)}, 0, INFINITY, &h));
    assert_near(h.t / r, 1.5, tol);
    /* Tangent-ish: impact parameter just inside hits near the tangent point, just outside misses. */
    for (int sgn = -1; sgn <= 1; sgn += 2) {
        double b = r * (1 + sgn * 1e-6);
        ps_ray ray = {ps_v3_add(c, ps_v3(-3 * r, b, 0)), ps_v3(1, 0, 0)};
        bool hit = ps_accel_intersect(a, ray, 0, INFINITY, &h);
        assert_int_equal(hit, sgn < 0);
        if (hit)
            assert_near(h.t / r, 3.0 - sqrt(1 - (1 - 1e-6) * (1 - 1e-6)), 1e-9);
    }
    /* Leaving the surface (a relative 1e-12 off it, either side) with tmin =
     * epsilon: outward misses, inward (into glass) finds the far side at 2r. */
    ps_vec3 n = ps_v3_norm(ps_v3(1, 2, 3));
    for (int side = -1; side <= 1; side += 2) {
        ps_vec3 p = ps_v3_madd(c, n, r * (1 + side * 1e-12));
        assert_false(ps_accel_intersect(a, (ps_ray){p, n}, eps, INFINITY, &h));
        assert_true(ps_accel_intersect(a, (ps_ray){p, ps_v3_neg(n)}, eps, INFINITY, &h));
        assert_int_equal(h.prim, sphere_id);
        assert_near(h.t / r, 2.0, 1e-9);
    }
    /* An epsilon scaled like the scene: an offset of eps from the surface never self-hits. */
    assert_true(eps < 1e-6 * r);
    ps_accel_destroy(a);
    soup_free(&s);
}

static void spheres_analytic(void **state)
{
    (void)state;
    check_sphere_at_scale(ps_v3(0, 0, 0), 1.0);
    check_sphere_at_scale(ps_v3(0.35, 0.4, 0.2), 0.4);
    check_sphere_at_scale(ps_v3(1e-3, -2e-3, 0), 1e-3);
    check_sphere_at_scale(ps_v3(1e3, 2e3, -1e3), 1e3);
    /* Brute force (AUTO on a tiny scene) answers the same. */
    soup s;
    memset(&s, 0, sizeof s);
    soup_sphere(&s, ps_v3(0, 0, 0), 2.0);
    ps_accel *a = build(&s, PS_ACCEL_AUTO, 0, 0);
    ps_accel_stats st;
    ps_accel_get_stats(a, &st);
    assert_int_equal(st.kind, PS_ACCEL_BRUTE);
    ps_hit h;
    assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(0, 5, 0), ps_v3(0, -1, 0)}, 0, INFINITY, &h));
    assert_near(h.t, 3.0, 1e-12);
    assert_int_equal(h.prim, 0);
    ps_accel_destroy(a);
    soup_free(&s);
}

/* ---- 4: degenerate inputs ---------------------------------------------------------- */

static void empty_and_invalid_input(void **state)
{
    (void)state;
    ps_accel_input in = {0};
    ps_accel *a = NULL;
    ps_error err;
    for (int kind = PS_ACCEL_AUTO; kind <= PS_ACCEL_BRUTE; kind++) {
        ps_accel_options opt = {(ps_accel_kind)kind, 0, 0, false};
        assert_int_equal(ps_accel_build(&in, &opt, &a, &err), PS_OK);
        ps_hit h;
        assert_false(ps_accel_intersect(a, (ps_ray){ps_v3(0, 0, 0), ps_v3(1, 0, 0)}, 0, INFINITY, &h));
        assert_false(ps_accel_occluded(a, (ps_ray){ps_v3(0, 0, 0), ps_v3(1, 0, 0)}, 0, INFINITY));
        assert_false(ps_accel_intersect_brute(a, (ps_ray){ps_v3(0, 0, 0), ps_v3(1, 0, 0)}, 0, INFINITY, &h));
        assert_true(ps_aabb_is_empty(ps_accel_bounds(a)));
        assert_near(ps_accel_epsilon(a), PS_RAY_EPSILON_MIN, 0);
        assert_int_equal(ps_accel_prim_count(a), 0);
        ps_accel_destroy(a);
    }
    ps_accel_destroy(NULL);

    /* Refusals: each one message, no accelerator. */
    ps_vec3 pos[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    uint32_t bad_idx[3] = {0, 1, 3};
    in = (ps_accel_input){pos, 3, bad_idx, 1, NULL, NULL, 0};
    assert_int_equal(ps_accel_build(&in, NULL, &a, &err), PS_ERR_RANGE);
    assert_null(a);
    assert_non_null(strstr(err.msg, "out of range"));
    uint32_t idx[3] = {0, 1, 2};
    pos[1].y = NAN;
    in = (ps_accel_input){pos, 3, idx, 1, NULL, NULL, 0};
    assert_int_equal(ps_accel_build(&in, NULL, &a, &err), PS_ERR_RANGE);
    pos[1].y = 0;
    ps_vec3 c = {0, 0, 0};
    double r = -1;
    in = (ps_accel_input){pos, 3, idx, 1, &c, &r, 1};
    assert_int_equal(ps_accel_build(&in, NULL, &a, &err), PS_ERR_RANGE);
    in = (ps_accel_input){NULL, 0, NULL, 1, NULL, NULL, 0};
    assert_int_equal(ps_accel_build(&in, NULL, &a, &err), PS_ERR_RANGE);
    ps_accel_options opt = {PS_ACCEL_OCTREE, -1, 0, false};
    in = (ps_accel_input){pos, 3, idx, 1, NULL, NULL, 0};
    assert_int_equal(ps_accel_build(&in, &opt, &a, &err), PS_ERR_RANGE);
}

static void one_triangle_limits_and_bad_rays(void **state)
{
    (void)state;
    soup s;
    memset(&s, 0, sizeof s);
    soup_tri_p(&s, ps_v3(0, 0, 0), ps_v3(1, 0, 0), ps_v3(0, 1, 0));
    for (int kind = PS_ACCEL_OCTREE; kind <= PS_ACCEL_BRUTE; kind++) {
        ps_accel *a = build(&s, (ps_accel_kind)kind, 0, 0);
        ps_ray down = {ps_v3(0.2, 0.3, 1), ps_v3(0, 0, -1)};
        ps_hit h;
        assert_true(ps_accel_intersect(a, down, 0, INFINITY, &h));
        assert_near(h.t, 1.0, 1e-15);
        assert_int_equal(h.prim, 0);
        assert_near(h.b1, 0.2, 1e-15);
        assert_near(h.b2, 0.3, 1e-15);
        /* Two-sided: from below too. */
        assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(0.2, 0.3, -2), ps_v3(0, 0, 0.5)}, 0, INFINITY, &h));
        assert_near(h.t, 4.0, 1e-15);
        /* (tmin, tmax) is open at both ends. */
        assert_false(ps_accel_intersect(a, down, 0, 0.5, &h));
        assert_false(ps_accel_intersect(a, down, 0, 1.0, &h));
        assert_false(ps_accel_intersect(a, down, 1.0, INFINITY, &h));
        assert_false(ps_accel_occluded(a, down, 0, 1.0));
        assert_true(ps_accel_intersect(a, down, 0.999, 1.001, &h));
        assert_true(ps_accel_occluded(a, down, 0.999, 1.001));
        assert_false(ps_accel_intersect(a, down, 2, 1, &h));
        /* Bad rays and limits never hit. */
        assert_false(ps_accel_intersect(a, (ps_ray){ps_v3(0.2, 0.3, NAN), ps_v3(0, 0, -1)}, 0, INFINITY, &h));
        assert_false(ps_accel_intersect(a, (ps_ray){ps_v3(0.2, 0.3, 1), ps_v3(0, NAN, -1)}, 0, INFINITY, &h));
        assert_false(ps_accel_intersect(a, (ps_ray){ps_v3(0.2, 0.3, 1), ps_v3(0, 0, -INFINITY)}, 0, INFINITY, &h));
        assert_false(ps_accel_intersect(a, (ps_ray){ps_v3(0.2, 0.3, 1), ps_v3(0, 0, 0)}, 0, INFINITY, &h));
        assert_false(ps_accel_intersect(a, down, NAN, INFINITY, &h));
        assert_false(ps_accel_intersect(a, down, 0, NAN, &h));
        assert_false(ps_accel_occluded(a, (ps_ray){ps_v3(0.2, 0.3, 1), ps_v3(0, 0, 0)}, 0, INFINITY));
        /* Directions of extreme length still work (t in units of |d|). */
        assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(0.2, 0.3, 1), ps_v3(0, 0, -1e-200)}, 0, INFINITY, &h));
        assert_near(h.t * 1e-200, 1.0, 1e-12);
        assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(0.2, 0.3, 1), ps_v3(0, 1e-300, -1e200)}, 0, INFINITY, &h));
        assert_near(h.t * 1e200, 1.0, 1e-12);
        /* A ray in the triangle's plane does not hit it. */
        assert_false(ps_accel_intersect(a, (ps_ray){ps_v3(-1, 0.2, 0), ps_v3(1, 0, 0)}, 0, INFINITY, &h));
        ps_accel_destroy(a);
    }
    soup_free(&s);
}

static void degenerate_triangles_never_hit(void **state)
{
    (void)state;
    soup s;
    memset(&s, 0, sizeof s);
    soup_tri_p(&s, ps_v3(0, 0, 0), ps_v3(0, 0, 0), ps_v3(0, 1, 0));           /* two vertices coincide */
    soup_tri_p(&s, ps_v3(0, 0, 0), ps_v3(1, 1, 1), ps_v3(2, 2, 2));           /* collinear */
    soup_tri_p(&s, ps_v3(0.5, 0.5, 0.5), ps_v3(0.5, 0.5, 0.5), ps_v3(0.5, 0.5, 0.5)); /* a point */
    soup_tri_p(&s, ps_v3(0.1, 0.3, 0.7), ps_v3(0.2, 0.6, 1.4), ps_v3(0.3, 0.9, 2.1)); /* collinear up to rounding */
    soup_sphere(&s, ps_v3(0.5, 0.5, 0.5), 0.0);                               /* a sphere of radius 0 */
    soup_tri_p(&s, ps_v3(5, 0, 0), ps_v3(6, 0, 0), ps_v3(5, 1, 0));           /* one real triangle, id 4 */
    ps_rng rng = ps_rng_make(3, PS_STREAM_TEST, 0);
    for (int kind = PS_ACCEL_OCTREE; kind <= PS_ACCEL_BRUTE; kind++) {
        ps_accel *a = build(&s, (ps_accel_kind)kind, 0, 0);
        for (int i = 0; i < 4000; i++) {
            /* Aim at a vertex or a point along a degenerate triangle's extent. */
            size_t t = ps_rng_below(&rng, 4);
            ps_vec3 target = ps_v3_lerp(soup_tri_vertex(&s, t, 0), soup_tri_vertex(&s, t, 2), uni(&rng, 0, 1));
            ps_vec3 o = rand_box(&rng, -3, 3);
            ps_hit h;
            ps_ray r = {o, ps_v3_sub(target, o)};
            if (ps_accel_intersect(a, r, 0, INFINITY, &h))
                assert_int_equal(h.prim, 4);
            assert_int_equal(ps_accel_occluded(a, r, 0, INFINITY), ps_accel_intersect(a, r, 0, INFINITY, &h));
        }
        ps_hit h;
        assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(5.25, 0.25, 1), ps_v3(0, 0, -1)}, 0, INFINITY, &h));
        assert_int_equal(h.prim, 4);
        ps_accel_destroy(a);
    }
    soup_free(&s);
}

/* Flat scenes (zero thickness on one axis), a cluster of primitives at one
 * point, and a flat scene far from the origin: all trees build small and
 * agree with the oracle. */
static void flat_and_clustered_scenes(void **state)
{
    (void)state;
    ps_rng rng = ps_rng_make(4, PS_STREAM_TEST, 0);
    for (int variant = 0; variant < 3; variant++) {
        soup s;
        memset(&s, 0, sizeof s);
        ps_vec3 offset = variant == 2 ? ps_v3(1e4, 1e4, -1e4) : ps_v3(0, 0, 0);
        double scale = variant == 2 ? 1e-4 : 1.0;
        if (variant != 1) {
            /* A 30 x 30 grid in the plane y = 0.25 (scaled and moved in variant 2). */
            enum { N = 30 };
            uint32_t base = (uint32_t)s.npos;
            for (int i = 0; i <= N; i++)
                for (int j = 0; j <= N; j++)
                    soup_vertex(&s, ps_v3_add(offset, ps_v3_scale(ps_v3(-1 + 2.0 * i / N, 0.25, -1 + 2.0 * j / N), scale)));
            for (int i = 0; i < N; i++)
                for (int j = 0; j < N; j++) {
                    uint32_t v = base + (uint32_t)(i * (N + 1) + j);
                    soup_tri(&s, v, v + N + 1, v + N + 2);
                    soup_tri(&s, v, v + N + 2, v + 1);
                }
        } else {
            /* 200 tiny triangles and 5 spheres all at one point. */
            for (int k = 0; k < 200; k++) {
                ps_vec3 p = ps_v3(0.3, 0.3, 0.3);
                soup_tri_p(&s, p, ps_v3_madd(p, rand_dir(&rng), 1e-9), ps_v3_madd(p, rand_dir(&rng), 1e-9));
            }
            for (int k = 0; k < 5; k++)
                soup_sphere(&s, ps_v3(0.3, 0.3, 0.3), 1e-9 * (k + 1));
        }
        ps_accel *a = build(&s, PS_ACCEL_OCTREE, 0, 0);
        ps_accel_stats st;
        ps_accel_get_stats(a, &st);
        /* A flat scene lying on every level's split plane would double its references per level. */
        if (!(st.prim_refs <= 10 * (s.ntri + s.nsph) && st.nodes < 40 * (s.ntri + s.nsph)))
            fail_msg("variant %d: %zu refs, %zu nodes for %zu primitives", variant, st.prim_refs, st.nodes, s.ntri + s.nsph);
        ray_case *rays = malloc(sizeof *rays * 3000);
        ps_vec3 c = variant == 1 ? ps_v3(0.3, 0.3, 0.3) : ps_v3_add(offset, ps_v3_scale(ps_v3(0.3, 0.25, 0.3), scale));
        for (int i = 0; i < 3000; i++) {
            ps_vec3 o = ps_v3_add(c, ps_v3_scale(rand_box(&rng, -1.5, 1.5), scale));
            ps_vec3 d = i % 4 == 0 ? ps_v3(uni(&rng, -1, 1), 0, uni(&rng, -1, 1)) /* in the plane */
                                   : ps_v3_sub(ps_v3_add(c, ps_v3_scale(rand_box(&rng, -1, 1), variant == 1 ? 1e-9 : scale)), o);
            if (i % 8 == 1 || i % 8 == 4)
                o.y = c.y; /* on the plane itself (and, for i % 8 == 4, lying in it) */
            rays[i] = (ray_case){{o, d}, 0.0, INFINITY};
        }
        size_t hits = check_against_brute(a, rays, 3000);
        assert_true(hits > 500);
        free(rays);
        ps_accel_destroy(a);
        soup_free(&s);
    }
}

/* ---- 5: scale invariance ----------------------------------------------------------- */

static void scale_invariance(void **state)
{
    (void)state;
    const double scales[2] = {1e-3, 1e3};
    enum { RAYS = 5000 };
    ps_rng rng = ps_rng_make(5, PS_STREAM_TEST, 0);
    soup base;
    memset(&base, 0, sizeof base);
    for (int t = 0; t < 1500; t++) {
        ps_vec3 c = rand_box(&rng, -1, 1);
        double size = pow(10.0, uni(&rng, -2, -0.5));
        soup_tri_p(&base, ps_v3_madd(c, rand_dir(&rng), size), ps_v3_madd(c, rand_dir(&rng), size),
                   ps_v3_madd(c, rand_dir(&rng), size));
    }
    for (int k = 0; k < 8; k++)
        soup_sphere(&base, rand_box(&rng, -0.8, 0.8), uni(&rng, 0.02, 0.2));
    ps_ray *rays = malloc(sizeof *rays * RAYS);
    for (int i = 0; i < RAYS; i++)
        rays[i] = (ps_ray){rand_box(&rng, -1.5, 1.5), rand_dir(&rng)};
    ps_accel *a1 = build(&base, PS_ACCEL_OCTREE, 0, 0);
    for (int k = 0; k < 2; k++) {
        double f = scales[k];
        soup s = base;
        s.pos = malloc(sizeof *s.pos * base.npos);
        s.idx = malloc(sizeof *s.idx * 3 * base.ntri);
        memcpy(s.idx, base.idx, sizeof *s.idx * 3 * base.ntri);
        for (size_t v = 0; v < base.npos; v++)
            s.pos[v] = ps_v3_scale(base.pos[v], f);
        for (size_t j = 0; j < base.nsph; j++) {
            s.centers[j] = ps_v3_scale(base.centers[j], f);
            s.radii[j] = base.radii[j] * f;
        }
        ps_accel *a2 = build(&s, PS_ACCEL_OCTREE, 0, 0);
        assert_near(ps_accel_epsilon(a2) / ps_accel_epsilon(a1), f, 1e-12 * f);
        size_t hits = 0;
        for (int i = 0; i < RAYS; i++) {
            ps_hit h1, h2;
            ps_ray r2 = {ps_v3_scale(rays[i].o, f), rays[i].d};
            bool f1 = ps_accel_intersect(a1, rays[i], ps_accel_epsilon(a1), INFINITY, &h1);
            bool f2 = ps_accel_intersect(a2, r2, ps_accel_epsilon(a2), INFINITY, &h2);
            assert_int_equal(f1, f2);
            if (!f1)
                continue;
            hits++;
            assert_int_equal(h1.prim, h2.prim);
            /* The same direction over a scaled scene: t scales by f. */
            assert_near(h2.t / f, h1.t, 1e-9 * h1.t);
        }
        if (hits < RAYS / 5)
            fail_msg("%zu hits", hits);
        ps_accel_destroy(a2);
        free(s.pos);
        free(s.idx);
    }
    ps_accel_destroy(a1);
    free(rays);
    soup_free(&base);
}

/* ---- 7, 8: scenes ------------------------------------------------------------------ */

static void build_scene_maps_spheres(void **state)
{
    (void)state;
    const char *text = "camera eye 0 1 5 target 0 1 0\n"
                       "light point position 0 3 0 power 10 10 10\n"
                       "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0\n"
                       "sphere center 0.5 0.5 0 radius 0.25\n"
                       "quad corner -1 2 -1 edge1 2 0 0 edge2 0 0 2\n"
                       "sphere center -0.5 0.5 0 radius 0.3\n";
    ps_scene *sc = NULL;
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &sc, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_accel *a = NULL;
    uint32_t *map = NULL;
    assert_int_equal(ps_accel_build_scene(sc, NULL, &a, &map, &err), PS_OK);
    assert_non_null(map);
    assert_int_equal(ps_accel_triangle_count(a), 4);
    assert_int_equal(ps_accel_prim_count(a), 6);
    assert_int_equal(map[0], 1);
    assert_int_equal(map[1], 3);
    ps_hit h;
    /* Down onto each sphere; then past them onto the floor (triangles 0 and 1). */
    assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(0.5, 1.5, 0), ps_v3(0, -1, 0)}, 0, INFINITY, &h));
    assert_int_equal(h.prim, 4);
    assert_near(h.t, 0.75, 1e-12);
    assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(-0.5, 1.5, 0), ps_v3(0, -1, 0)}, 0, INFINITY, &h));
    assert_int_equal(h.prim, 5);
    assert_near(h.t, 0.7, 1e-12);
    assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(0.9, 1.5, 0.9), ps_v3(0, -1, 0)}, 0, INFINITY, &h));
    assert_true(h.prim < 2);
    assert_near(h.t, 1.5, 1e-12);
    /* Up to the ceiling (triangles 2 and 3). */
    assert_true(ps_accel_intersect(a, (ps_ray){ps_v3(0.9, 1.5, 0.9), ps_v3(0, 1, 0)}, 0, INFINITY, &h));
    assert_true(h.prim == 2 || h.prim == 3);
    /* The epsilon scales with the scene's extent (2 here). */
    assert_near(ps_accel_epsilon(a), PS_RAY_EPSILON_REL * 2, 1e-25);
    free(map);
    ps_accel_destroy(a);
    /* No sphere_objects wanted: fine too. */
    assert_int_equal(ps_accel_build_scene(sc, NULL, &a, NULL, &err), PS_OK);
    ps_accel_destroy(a);
    ps_scene_destroy(sc);
}

static void forced_octree_on_default_scene(void **state)
{
    (void)state;
    ps_scene *sc = NULL;
    ps_error err;
    if (ps_scene_load("data/scenes/cornell-caustic.scn", NULL, &sc, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_accel *brute_acc = NULL, *tree = NULL, *fine = NULL;
    assert_int_equal(ps_accel_build_scene(sc, NULL, &brute_acc, NULL, &err), PS_OK);
    ps_accel_options opt = {PS_ACCEL_OCTREE, 0, 0, false};
    assert_int_equal(ps_accel_build_scene(sc, &opt, &tree, NULL, &err), PS_OK);
    opt.leaf_prims = 1;
    assert_int_equal(ps_accel_build_scene(sc, &opt, &fine, NULL, &err), PS_OK);
    ps_accel_stats st;
    ps_accel_get_stats(brute_acc, &st);
    assert_int_equal(st.kind, PS_ACCEL_BRUTE); /* 12 primitives: AUTO does not build a tree */
    assert_int_equal(st.nodes, 0);
    ps_accel_get_stats(tree, &st);
    assert_int_equal(st.kind, PS_ACCEL_OCTREE);
    assert_true(st.nodes > 1);
    ps_accel_get_stats(fine, &st);
    assert_true(st.nodes >= 9 && st.leaves >= 8 && st.max_depth_reached >= 1 && st.bytes > 0 && st.build_seconds >= 0);

    ps_rng rng = ps_rng_make(6, PS_STREAM_TEST, 0);
    enum { RAYS = 5000 };
    ray_case *rays = malloc(sizeof *rays * RAYS);
    for (int i = 0; i < RAYS; i++)
        rays[i] = (ray_case){{rand_box(&rng, -0.99, 0.99), rand_dir(&rng)}, 0.0, INFINITY};
    for (int i = 0; i < RAYS; i += 7)
        rays[i].r.o.y += 1.0; /* inside the box, which spans y in [0, 2] */
    size_t hits = check_against_brute(tree, rays, RAYS);
    assert_int_equal(check_against_brute(fine, rays, RAYS), hits);
    assert_int_equal(check_against_brute(brute_acc, rays, RAYS), hits);
    /* Open toward +z only: most rays from inside hit something. */
    assert_true(hits > RAYS / 2);
    free(rays);
    ps_accel_destroy(brute_acc);
    ps_accel_destroy(tree);
    ps_accel_destroy(fine);
    ps_scene_destroy(sc);
}


/* ---- SIMD traversal --------------------------------------------------------------- */

static bool same_hit_bits(const ps_hit *h1, const ps_hit *h2)
{
    return h1->prim == h2->prim && memcmp(&h1->t, &h2->t, sizeof h1->t) == 0 &&
           memcmp(&h1->b1, &h2->b1, sizeof h1->b1) == 0 && memcmp(&h1->b2, &h2->b2, sizeof h1->b2) == 0;
}

/* a and b answer every ray with the same bits; returns the hits. */
static size_t same_bits_on_rays(const ps_accel *a, const ps_accel *b, const ray_case *rays, size_t n)
{
    size_t hits = 0;
    for (size_t i = 0; i < n; i++) {
        ps_hit h1 = {0}, h2 = {0};
        const ray_case *c = &rays[i];
        bool f1 = ps_accel_intersect(a, c->r, c->tmin, c->tmax, &h1);
        bool f2 = ps_accel_intersect(b, c->r, c->tmin, c->tmax, &h2);
        if (f1 != f2 || (f1 && !same_hit_bits(&h1, &h2)))
            fail_msg("ray %zu: avx2 %d prim %u t %.17g b %.17g %.17g, scalar %d prim %u t %.17g b %.17g %.17g", i, f1,
                     (unsigned)h1.prim, h1.t, h1.b1, h1.b2, f2, (unsigned)h2.prim, h2.t, h2.b1, h2.b2);
        assert_true(ps_accel_occluded(a, c->r, c->tmin, c->tmax) == f2);
        hits += f1;
    }
    return hits;
}

/* The AVX2 traversal (where the processor has it) against the scalar one on
 * test 1's rays and the default scene's: the very same bits (t, prim,
 * barycentrics), since each vector lane makes the scalar test's operations. */
static void simd_matches_scalar_bit_for_bit(void **state)
{
    (void)state;
    ps_rng rng = ps_rng_make(1, PS_STREAM_TEST, 0);
    soup s;
    make_soup(&s, &rng);
    ps_accel *probe = build(&s, PS_ACCEL_OCTREE, 0, 0);
    add_plane_triangles(&s, probe);
    ps_accel_destroy(probe);
    ps_accel *vec = build_with(&s, PS_ACCEL_OCTREE, 0, 0, false);
    ps_accel *sca = build_with(&s, PS_ACCEL_OCTREE, 0, 0, true);
    assert_false(sca->simd);
    if (!vec->simd) {
        ps_accel_destroy(vec);
        ps_accel_destroy(sca);
        soup_free(&s);
        skip(); /* no AVX2 here: the scalar traversal is the only one */
    }
    /* Same tree either way: only the traversal differs. */
    assert_int_equal(vec->node_count, sca->node_count);
    assert_int_equal(vec->ref_count, sca->ref_count);
    /* Every leaf lists its triangles before its spheres (the AVX2 leaf loop relies on it). */
    for (size_t k = 0; k < vec->node_count; k++) {
        accel_node nd = vec->nodes[k];
        if (nd.count & ACCEL_NODE_INTERIOR)
            continue;
        for (uint32_t j = 1; j < nd.count; j++)
            assert_false(vec->refs[nd.index + j - 1] >= vec->tri_count && vec->refs[nd.index + j] < vec->tri_count);
    }
    ray_case *rays = malloc(sizeof *rays * RAY_COUNT);
    size_t n = make_rays(&s, vec, &rng, rays);
    assert_true(same_bits_on_rays(vec, sca, rays, n) > n / 3);
    /* A brute-force accelerator's query (AVX2) against its scalar oracle, on a part of the rays. */
    ps_accel *bvec = build_with(&s, PS_ACCEL_BRUTE, 0, 0, false);
    assert_true(bvec->simd);
    for (size_t i = 0; i < n; i += 20) {
        ps_hit h1 = {0}, h2 = {0};
        const ray_case *c = &rays[i];
        bool f1 = ps_accel_intersect(bvec, c->r, c->tmin, c->tmax, &h1);
        bool f2 = ps_accel_intersect_brute(bvec, c->r, c->tmin, c->tmax, &h2);
        if (f1 != f2 || (f1 && !same_hit_bits(&h1, &h2)))
            fail_msg("ray %zu: brute avx2 %d prim %u t %.17g, scalar %d prim %u t %.17g", i, f1, (unsigned)h1.prim, h1.t,
                     f2, (unsigned)h2.prim, h2.t);
        assert_true(ps_accel_occluded(bvec, c->r, c->tmin, c->tmax) == f2);
    }
    free(rays);
    ps_accel_destroy(bvec);
    ps_accel_destroy(vec);
    ps_accel_destroy(sca);
    soup_free(&s);
}

/* ---- nearest geometry ------------------------------------------------------------- */

/* Closed forms on one triangle and one sphere: the face, an edge, a vertex;
 * outside and inside the sphere; max_dist inclusive. */
static void nearest_closed_forms(void **state)
{
    (void)state;
    soup s;
    memset(&s, 0, sizeof s);
    /* The triangle (0,0,0) (2,0,0) (0,2,0) in z = 0; the sphere r = 1 at (10, 0, 0). */
    soup_tri_p(&s, ps_v3(0, 0, 0), ps_v3(2, 0, 0), ps_v3(0, 2, 0));
    soup_sphere(&s, ps_v3(10, 0, 0), 1.0);
    for (int kind = PS_ACCEL_OCTREE; kind <= PS_ACCEL_BRUTE; kind++) {
        ps_accel *a = build(&s, (ps_accel_kind)kind, 0, 0);
        ps_nearest n;
        /* Above the face: straight down. */
        assert_true(ps_accel_nearest(a, ps_v3(0.5, 0.5, 3.0), INFINITY, &n));
        assert_int_equal(n.prim, 0);
        assert_true(n.distance == 3.0 && n.point.x == 0.5 && n.point.y == 0.5 && n.point.z == 0.0);
        /* Beyond the hypotenuse x + y = 2: to its midpoint (1, 1, 0). */
        assert_true(ps_accel_nearest(a, ps_v3(2, 2, 0), INFINITY, &n));
        assert_near(n.distance, sqrt(2.0), 1e-15);
        assert_near(n.point.x, 1.0, 1e-15);
        assert_near(n.point.y, 1.0, 1e-15);
        /* Beyond the vertex at the origin. */
        assert_true(ps_accel_nearest(a, ps_v3(-3, -4, 0), INFINITY, &n));
        assert_true(n.distance == 5.0 && n.point.x == 0.0 && n.point.y == 0.0);
        /* Near the sphere, outside and inside: | |p - c| - r |. */
        assert_true(ps_accel_nearest(a, ps_v3(10, 3, 0), INFINITY, &n));
        assert_int_equal(n.prim, 1);
        assert_true(n.distance == 2.0 && n.point.y == 1.0);
        assert_true(ps_accel_nearest(a, ps_v3(10.25, 0, 0), INFINITY, &n));
        assert_int_equal(n.prim, 1);
        assert_true(n.distance == 0.75);
        assert_true(ps_accel_nearest_distance(a, ps_v3(10, 0, 0)) == 1.0); /* the centre */
        /* On the geometry: 0. */
        assert_true(ps_accel_nearest_distance(a, ps_v3(1, 0.5, 0)) == 0.0);
        /* max_dist: inclusive, and nothing beyond it. */
        assert_true(ps_accel_nearest(a, ps_v3(0.5, 0.5, 3.0), 3.0, &n) && n.distance == 3.0);
        assert_false(ps_accel_nearest(a, ps_v3(0.5, 0.5, 3.0), 2.999, &n));
        assert_false(ps_accel_nearest(a, ps_v3(NAN, 0, 0), INFINITY, &n));
        assert_false(ps_accel_nearest(a, ps_v3(0, 0, 0), -1.0, &n));
        ps_accel_destroy(a);
    }
    /* No geometry: nothing is near. */
    soup empty;
    memset(&empty, 0, sizeof empty);
    ps_accel *a = build(&empty, PS_ACCEL_OCTREE, 0, 0);
    assert_true(ps_accel_nearest_distance(a, ps_v3(0, 0, 0)) == INFINITY);
    ps_accel_destroy(a);
    soup_free(&s);
}

/* The octree's nearest against the oracle's on test 1's soup: points inside,
 * around and far outside it, on vertices and just off them, with and without
 * a max_dist: the same primitive, distance and point, bit for bit. */
static void nearest_matches_brute_force(void **state)
{
    (void)state;
    ps_rng rng = ps_rng_make(9, PS_STREAM_TEST, 0);
    soup s;
    make_soup(&s, &rng);
    ps_accel *a = build(&s, PS_ACCEL_OCTREE, 0, 0);
    ps_accel *fine = build(&s, PS_ACCEL_OCTREE, 0, 1);
    size_t zero = 0;
    for (int i = 0; i < 6000; i++) {
        ps_vec3 p;
        double max_dist = INFINITY;
        switch (i % 5) {
        case 0: p = rand_box(&rng, -1.2, 1.2); break;
        case 1: p = rand_box(&rng, -40, 40); break;
        case 2: p = s.pos[s.idx[ps_rng_below(&rng, (uint32_t)(3 * s.ntri))]]; break;
        case 3:
            p = ps_v3_madd(s.pos[s.idx[ps_rng_below(&rng, (uint32_t)(3 * s.ntri))]], rand_dir(&rng), 1e-6);
            break;
        default:
            p = rand_box(&rng, -1.2, 1.2);
            max_dist = uni(&rng, 0.0, 0.1);
            break;
        }
        ps_nearest n1, n2, n3;
        bool f1 = ps_accel_nearest(a, p, max_dist, &n1), f2 = ps_accel_nearest_brute(a, p, max_dist, &n2);
        bool f3 = ps_accel_nearest(fine, p, max_dist, &n3);
        if (f1 != f2 || (f1 && (n1.prim != n2.prim || n1.distance != n2.distance || n1.point.x != n2.point.x ||
                                n1.point.y != n2.point.y || n1.point.z != n2.point.z)))
            fail_msg("point %d (%.17g %.17g %.17g): octree %d prim %u d %.17g, brute %d prim %u d %.17g", i, p.x, p.y,
                     p.z, f1, (unsigned)n1.prim, n1.distance, f2, (unsigned)n2.prim, n2.distance);
        assert_true(f3 == f1 && (!f1 || (n3.prim == n1.prim && n3.distance == n1.distance)));
        if (i % 5 != 4)
            assert_true(f1);
        if (f1) {
            assert_true(n1.distance <= max_dist);
            /* The point lies that far from p. */
            assert_near(ps_v3_len(ps_v3_sub(n1.point, p)), n1.distance, 1e-12 * (1.0 + n1.distance));
            zero += n1.distance == 0.0;
        }
    }
    assert_true(zero >= 1000); /* the points on vertices */
    ps_accel_destroy(a);
    ps_accel_destroy(fine);
    soup_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(octree_matches_brute_force),
        cmocka_unit_test(watertight_closed_meshes),
        cmocka_unit_test(spheres_analytic),
        cmocka_unit_test(empty_and_invalid_input),
        cmocka_unit_test(one_triangle_limits_and_bad_rays),
        cmocka_unit_test(degenerate_triangles_never_hit),
        cmocka_unit_test(flat_and_clustered_scenes),
        cmocka_unit_test(scale_invariance),
        cmocka_unit_test(build_scene_maps_spheres),
        cmocka_unit_test(forced_octree_on_default_scene),
        cmocka_unit_test(simd_matches_scalar_bit_for_bit),
        cmocka_unit_test(nearest_closed_forms),
        cmocka_unit_test(nearest_matches_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
