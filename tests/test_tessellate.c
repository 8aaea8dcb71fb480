/* test_tessellate.c: the OpenGL sphere mesh: on the sphere, closed, outward,
 * and within its tolerance of the true surface. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "scene/tessellate.h"

typedef struct edge { uint32_t a, b; } edge;

static int edge_cmp(const void *x, const void *y)
{
    const edge *e = x, *f = y;
    if (e->a != f->a)
        return e->a < f->a ? -1 : 1;
    return e->b < f->b ? -1 : e->b > f->b;
}

static void check_sphere(ps_vec3 c, double r, double tol)
{
    ps_trimesh m;
    ps_error err;
    assert_int_equal(ps_sphere_tessellate(c, r, tol, &m, &err), PS_OK);
    for (uint32_t v = 0; v < m.vertex_count; v++) {
        assert_near(ps_v3_len(ps_v3_sub(m.positions[v], c)), r, 1e-12 * (r + ps_v3_len(c)));
        assert_near(ps_v3_len(m.normals[v]), 1, 1e-12);
        assert_near(ps_v3_dot(m.normals[v], ps_v3_norm(ps_v3_sub(m.positions[v], c))), 1, 1e-9);
    }
    /* Closed and consistently wound: each directed edge once, its reverse once. */
    edge *edges = malloc(sizeof *edges * 3 * m.triangle_count);
    double area = 0, max_depth = 0;
    for (uint32_t t = 0; t < m.triangle_count; t++) {
        const uint32_t *ix = &m.indices[3 * t];
        for (int k = 0; k < 3; k++) {
            assert_true(ix[k] < m.vertex_count);
            edges[3 * t + k] = (edge){ix[k], ix[(k + 1) % 3]};
        }
        ps_vec3 p0 = m.positions[ix[0]], p1 = m.positions[ix[1]], p2 = m.positions[ix[2]];
        ps_vec3 cr = ps_v3_cross(ps_v3_sub(p1, p0), ps_v3_sub(p2, p0));
        area += 0.5 * ps_v3_len(cr);
        ps_vec3 centroid = ps_v3_scale(ps_v3_add(ps_v3_add(p0, p1), p2), 1.0 / 3.0);
        /* outward: the face normal points away from the centre */
        assert_true(ps_v3_dot(cr, ps_v3_sub(centroid, c)) > 0);
        /* No point of the triangle is nearer the centre than its plane is, so
         * r minus the plane's distance bounds how deep any point lies. */
        double d = r - fabs(ps_v3_dot(ps_v3_sub(p0, c), ps_v3_norm(cr)));
        if (d > max_depth)
            max_depth = d;
    }
    qsort(edges, 3 * (size_t)m.triangle_count, sizeof *edges, edge_cmp);
    for (size_t k = 0; k < 3 * (size_t)m.triangle_count; k++) {
        if (k)
            assert_true(edge_cmp(&edges[k], &edges[k - 1]) != 0); /* no directed edge twice */
        edge rev = {edges[k].b, edges[k].a};
        assert_non_null(bsearch(&rev, edges, 3 * (size_t)m.triangle_count, sizeof *edges, edge_cmp));
    }
    free(edges);
    assert_true(max_depth <= tol * r);
    /* The inscribed mesh's area is below the sphere's, by at most ~2 tol. */
    double sphere = 4 * PS_PI * r * r;
    assert_true(area < sphere);
    assert_true(area > sphere * (1 - 2.5 * tol));
    ps_trimesh_free(&m);
}

static void default_tolerance(void **state)
{
    (void)state;
    check_sphere(ps_v3(0.35, 0.4, 0.2), 0.4, PS_SPHERE_DEFAULT_TOLERANCE);
}

static void coarse_fine_and_extreme_scales(void **state)
{
    (void)state;
    check_sphere(ps_v3(0, 0, 0), 1, 0.05);
    check_sphere(ps_v3(1e4, -2e4, 3e4), 1e4, 1e-2);
    check_sphere(ps_v3(1e-4, 0, 0), 1e-4, 1e-3);
    check_sphere(ps_v3(0, 0, 0), 1, 1e-4);
}

static void counts_and_refusals(void **state)
{
    (void)state;
    ps_trimesh m;
    ps_error err;
    assert_int_equal(ps_sphere_tessellate(ps_v3(0, 0, 0), 1, PS_SPHERE_DEFAULT_TOLERANCE, &m, &err), PS_OK);
    /* A preview sphere stays modest: a few thousand triangles. */
    assert_true(m.triangle_count > 1000 && m.triangle_count < 20000);
    ps_trimesh_free(&m);
    assert_int_equal(ps_sphere_tessellate(ps_v3(0, 0, 0), 0, 0.01, &m, &err), PS_ERR_RANGE);
    assert_int_equal(ps_sphere_tessellate(ps_v3(0, 0, 0), 1, 0, &m, &err), PS_ERR_RANGE);
    assert_int_equal(ps_sphere_tessellate(ps_v3(0, 0, 0), 1, NAN, &m, &err), PS_ERR_RANGE);
    assert_null(m.positions);
}

/* The count callers check against memory is the count the mesh has. */
static void count_before_building(void **state)
{
    (void)state;
    const double tolerances[] = {0.5, 0.1, 1e-3, 1e-5, 1e-9};
    for (size_t i = 0; i < sizeof tolerances / sizeof tolerances[0]; i++) {
        ps_trimesh m;
        ps_error err;
        assert_int_equal(ps_sphere_tessellate(ps_v3(0, 0, 0), 1.0, tolerances[i], &m, &err), PS_OK);
        assert_int_equal(ps_sphere_triangle_count(tolerances[i]), m.triangle_count);
        ps_trimesh_free(&m);
    }
    assert_int_equal(ps_sphere_triangle_count(PS_SPHERE_DEFAULT_TOLERANCE), 9800);
    assert_int_equal(ps_sphere_triangle_count(0.0), 0);
    assert_int_equal(ps_sphere_triangle_count(0.6), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(default_tolerance),
        cmocka_unit_test(coarse_fine_and_extreme_scales),
        cmocka_unit_test(counts_and_refusals),
        cmocka_unit_test(count_before_building),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
