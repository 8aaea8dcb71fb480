/* test_mesh.c: the preview's triangle arrays (preview/mesh.h): every edge of a
 * subdivided triangle within max_edge, the split the least that achieves it
 * (and capped at PS_MESH_MAX_SPLIT), areas preserved (quads exactly, spheres
 * within the tessellation's sagitta), unit normals on the winding's side
 * (flat for quads, interpolated from an OBJ's flipped vertex normals),
 * consistent winding, and ranges that tile the vertices by object and
 * material. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "preview/mesh.h"
#include "scene/scene.h"
#include "scene/tessellate.h"

/* Positions and normals are floats: 2^-24 relative, times a few. */
#define FLOAT_TOL 1e-6
#define EDGE_SLACK 1e-9

/* A floor and a ceiling of 2 x 2 (normals +y and -y), a tilted
 * parallelogram, a sphere and an OBJ of two triangles in two materials whose
 * vertex normals point against the winding. */
static const char *const ROOM = "camera eye 0 1 5 target 0 0.5 0\n"
                                "light point position 0 1.5 0 power 10 10 10\n"
                                "material white diffuse albedo 0.7 0.7 0.7\n"
                                "material red diffuse albedo 0.7 0.2 0.2\n"
                                "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                                "quad corner 0.3 0.2 -0.8 edge1 1.5 0.5 0 edge2 0.2 0 1.3 material red\n"
                                "sphere center -0.5 0.6 0.2 radius 0.5 material red\n"
                                "quad corner -1 2 -1 edge1 2 0 0 edge2 0 0 2\n"
                                "mesh two.obj\n";

enum { FLOOR, TILTED, SPHERE, CEILING, MESH, OBJECTS };

static const ps_vec3 SPHERE_CENTRE = {-0.5, 0.6, 0.2};
#define SPHERE_RADIUS 0.5

static ps_scene *load(const char *text)
{
    FILE *fp = fopen(test_path("two.mtl"), "wb");
    assert_non_null(fp);
    fputs("newmtl a\nKd 0.5 0.5 0.5\nnewmtl b\nKd 0.2 0.3 0.4\n", fp);
    fclose(fp);
    fp = fopen(test_path("two.obj"), "wb");
    assert_non_null(fp);
    /* Face 1 winds toward +z with normals (0, 0, -1) and (0.6, 0, -0.8):
     * both are flipped to the winding's side; face 2 likewise. */
    fputs("mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 -1\nvn 0.6 0 -0.8\n"
          "usemtl a\nf 1//1 2//2 3//1\nusemtl b\nf 2//1 4//1 3//1\n",
          fp);
    fclose(fp);
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path(""));
    ps_scene *s = NULL;
    ps_error err;
    if (ps_scene_load_text(text, "mesh.scn", dir, NULL, &s, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    return s;
}

static ps_vec3 get3(const float *a, size_t v) { return ps_v3(a[3 * v], a[3 * v + 1], a[3 * v + 2]); }

static ps_vec3 tri_cross(const ps_preview_mesh *m, size_t t)
{
    ps_vec3 p0 = get3(m->positions, 3 * t), p1 = get3(m->positions, 3 * t + 1), p2 = get3(m->positions, 3 * t + 2);
    return ps_v3_cross(ps_v3_sub(p1, p0), ps_v3_sub(p2, p0));
}

static double longest_edge(const ps_preview_mesh *m, size_t t)
{
    ps_vec3 p0 = get3(m->positions, 3 * t), p1 = get3(m->positions, 3 * t + 1), p2 = get3(m->positions, 3 * t + 2);
    return fmax(ps_v3_len(ps_v3_sub(p1, p0)), fmax(ps_v3_len(ps_v3_sub(p2, p1)), ps_v3_len(ps_v3_sub(p0, p2))));
}

static ps_preview_mesh build(const ps_scene *s, double max_edge)
{
    ps_mesh_options o = ps_mesh_default_options(s);
    o.max_edge = max_edge;
    ps_preview_mesh m;
    ps_error err;
    if (ps_preview_mesh_build(s, &o, &m, &err) != PS_OK)
        fail_msg("mesh: %s", err.msg);
    return m;
}

/* Ranges tile [0, vertex_count) in order, each non-empty and a whole number
 * of triangles, no two neighbours with the same (object, material); returns
 * the first range of object `obj` (and its number of ranges in *n). */
static size_t check_ranges(const ps_preview_mesh *m, uint32_t obj, size_t *n)
{
    assert_int_equal(m->vertex_count % 3, 0);
    size_t next = 0, first = SIZE_MAX;
    *n = 0;
    for (size_t r = 0; r < m->range_count; r++) {
        const ps_mesh_range *g = &m->ranges[r];
        assert_int_equal(g->first, next);
        assert_true(g->count > 0);
        assert_int_equal(g->count % 3, 0);
        next += g->count;
        if (r > 0)
            assert_true(g->object != m->ranges[r - 1].object || g->material != m->ranges[r - 1].material);
        if (r > 0)
            assert_true(g->object >= m->ranges[r - 1].object);
        if (g->object == obj) {
            if (first == SIZE_MAX)
                first = r;
            (*n)++;
        }
    }
    assert_int_equal(next, m->vertex_count);
    return first;
}

/* Vertices of object obj: [*lo, *hi). */
static void object_span(const ps_preview_mesh *m, uint32_t obj, size_t *lo, size_t *hi)
{
    size_t n, r = check_ranges(m, obj, &n);
    assert_true(n > 0);
    *lo = m->ranges[r].first;
    *hi = m->ranges[r + n - 1].first + m->ranges[r + n - 1].count;
}

static double span_area(const ps_preview_mesh *m, size_t lo, size_t hi)
{
    double area = 0.0;
    for (size_t t = lo / 3; t < hi / 3; t++)
        area += 0.5 * ps_v3_len(tri_cross(m, t));
    return area;
}

static void room(void **state)
{
    (void)state;
    ps_scene *s = load(ROOM);
    size_t nobj, nmat, ntri;
    const ps_object *objects = ps_scene_objects(s, &nobj);
    const ps_material *mats = ps_scene_materials(s, &nmat);
    const ps_triangle *tris = ps_scene_triangles(s, &ntri);
    const ps_vec3 *spos = ps_scene_positions(s, NULL);
    assert_int_equal(nobj, OBJECTS);
    assert_int_equal(objects[SPHERE].type, PS_OBJ_SPHERE);
    const double max_edge = 0.1;
    ps_preview_mesh m = build(s, max_edge);

    /* Ranges: one per quad and sphere, two for the OBJ's two materials, in
     * object order, with the objects' materials. */
    assert_int_equal(m.range_count, 6);
    size_t n;
    for (uint32_t o = 0; o < OBJECTS; o++) {
        size_t r = check_ranges(&m, o, &n);
        assert_int_equal(n, o == MESH ? 2 : 1);
        assert_int_equal(m.ranges[r].object, o);
        if (o != MESH)
            assert_int_equal(m.ranges[r].material, objects[o].material);
    }
    /* Shared vertices: each names itself or an earlier vertex of its range
     * with the same position and normal bits, which names itself; no two
     * distinct ones are equal (a flat subdivided quad shares down to its
     * grid's points: fewer than half its vertices are distinct). */
    for (size_t r = 0; r < m.range_count; r++) {
        const ps_mesh_range *rg = &m.ranges[r];
        size_t distinct = 0;
        for (size_t v = rg->first; v < rg->first + rg->count; v++) {
            uint32_t u = m.shared[v];
            assert_true(u >= rg->first && u <= v);
            assert_int_equal(m.shared[u], u);
            assert_memory_equal(m.positions + 3 * u, m.positions + 3 * v, 3 * sizeof(float));
            assert_memory_equal(m.normals + 3 * u, m.normals + 3 * v, 3 * sizeof(float));
            distinct += u == v;
        }
        for (size_t a = rg->first; a < rg->first + rg->count && rg->count < 4000; a++)
            for (size_t b = a + 1; b < rg->first + rg->count; b++)
                if (m.shared[a] == a && m.shared[b] == b)
                    assert_true(memcmp(m.positions + 3 * a, m.positions + 3 * b, 3 * sizeof(float)) != 0 ||
                                memcmp(m.normals + 3 * a, m.normals + 3 * b, 3 * sizeof(float)) != 0);
        if (r == FLOOR)
            assert_true(distinct > 0 && 2 * distinct < rg->count);
    }
    assert_string_equal(mats[m.ranges[FLOOR].material].name, "white");
    assert_string_equal(mats[m.ranges[TILTED].material].name, "red");
    assert_string_equal(mats[m.ranges[SPHERE].material].name, "red");
    assert_string_equal(mats[m.ranges[CEILING].material].name, "(default)");
    assert_string_equal(mats[m.ranges[4].material].name, "two.obj/a");
    assert_string_equal(mats[m.ranges[5].material].name, "two.obj/b");

    /* Every vertex normal unit; every triangle wound about its normals. */
    for (size_t v = 0; v < m.vertex_count; v++) {
        ps_vec3 nv = get3(m.normals, v);
        assert_near(ps_v3_len(nv), 1.0, FLOAT_TOL);
        assert_true(ps_v3_dot(tri_cross(&m, v / 3), nv) > 0.0);
    }

    /* Subdivided objects: edges within max_edge, with the least split that
     * achieves it (one split fewer would not), area kept. */
    for (uint32_t o = 0; o < OBJECTS; o++) {
        if (o == SPHERE)
            continue;
        size_t lo, hi;
        object_span(&m, o, &lo, &hi);
        double area = 0.0;
        size_t at = lo;
        for (uint32_t t = objects[o].first_triangle; t < objects[o].first_triangle + objects[o].triangle_count; t++) {
            area += ps_scene_triangle_area(s, t);
            ps_vec3 p0 = spos[tris[t].v[0]], p1 = spos[tris[t].v[1]], p2 = spos[tris[t].v[2]];
            double longest = fmax(ps_v3_len(ps_v3_sub(p1, p0)),
                                  fmax(ps_v3_len(ps_v3_sub(p2, p1)), ps_v3_len(ps_v3_sub(p0, p2))));
            size_t split = (size_t)ceil(longest / max_edge);
            assert_true(split > 1);
            double worst = 0.0;
            for (size_t k = 0; k < split * split; k++)
                worst = fmax(worst, longest_edge(&m, at / 3 + k));
            assert_true(worst <= max_edge + EDGE_SLACK);
            assert_true(worst * split / (split - 1) > max_edge);
            /* Similar triangles: the longest edge over split. */
            assert_near(worst, longest / split, FLOAT_TOL);
            at += 3 * split * split;
        }
        assert_int_equal(at, hi);
        double got = span_area(&m, lo, hi);
        if (o == FLOOR || o == CEILING)
            assert_near(got, 4.0, 1e-9); /* axis-aligned: float positions exact on the boundary */
        else
            assert_near(got, area, FLOAT_TOL * area);
    }

    /* Quads are flat: every normal is edge1 x edge2's direction. */
    static const struct {
        int obj;
        ps_vec3 normal;
    } flat[] = {{FLOOR, {0, 1, 0}}, {CEILING, {0, -1, 0}}, {TILTED, {0.65, -1.95, -0.1}}};
    for (size_t i = 0; i < sizeof flat / sizeof flat[0]; i++) {
        size_t lo, hi;
        object_span(&m, (uint32_t)flat[i].obj, &lo, &hi);
        ps_vec3 want = ps_v3_norm(flat[i].normal);
        for (size_t v = lo; v < hi; v++)
            assert_near(ps_v3_len(ps_v3_sub(get3(m.normals, v), want)), 0.0, FLOAT_TOL);
    }

    /* The OBJ's normals: the flipped vertex normals interpolated at each
     * vertex's barycentric position, renormalised. Face 1 is (0,0,0),
     * (1,0,0), (0,1,0) with flipped normals n0 = n2 = (0,0,1), n1 = (-0.6,0,0.8). */
    {
        size_t lo, hi;
        object_span(&m, MESH, &lo, &hi);
        assert_near(span_area(&m, lo, hi), 1.0, FLOAT_TOL);
        const ps_mesh_range *a = &m.ranges[4], *b = &m.ranges[5];
        int tilted_seen = 0;
        for (size_t v = a->first; v < a->first + a->count; v++) {
            ps_vec3 p = get3(m.positions, v);
            assert_near(p.z, 0.0, 0.0);
            double w1 = p.x, w2 = p.y, w0 = 1.0 - w1 - w2;
            assert_true(w0 >= -FLOAT_TOL && w1 >= -FLOAT_TOL && w2 >= -FLOAT_TOL);
            ps_vec3 want = ps_v3_norm(ps_v3(-0.6 * w1, 0.0, w0 + 0.8 * w1 + w2));
            assert_near(ps_v3_len(ps_v3_sub(get3(m.normals, v), want)), 0.0, FLOAT_TOL);
            tilted_seen += w1 > 0.99;
        }
        assert_true(tilted_seen > 0); /* the corner with the tilted normal itself */
        for (size_t v = b->first; v < b->first + b->count; v++)
            assert_near(ps_v3_len(ps_v3_sub(get3(m.normals, v), ps_v3(0, 0, 1))), 0.0, FLOAT_TOL);
    }

    /* The sphere: the tessellation as it is (max_edge does not cut it), all
     * vertices on the sphere with radial normals, triangles within the
     * sagitta tolerance, area a little under 4 pi r^2. */
    {
        size_t lo, hi;
        object_span(&m, SPHERE, &lo, &hi);
        ps_trimesh tm;
        ps_error err;
        assert_int_equal(ps_sphere_tessellate(SPHERE_CENTRE, SPHERE_RADIUS, PS_SPHERE_DEFAULT_TOLERANCE, &tm, &err),
                         PS_OK);
        assert_int_equal(hi - lo, 3 * (size_t)tm.triangle_count);
        for (size_t t = 0; t < tm.triangle_count; t++)
            for (int k = 0; k < 3; k++) {
                size_t v = lo + 3 * t + (size_t)k;
                ps_vec3 want = tm.positions[tm.indices[3 * t + (size_t)k]];
                assert_near(ps_v3_len(ps_v3_sub(get3(m.positions, v), want)), 0.0, FLOAT_TOL);
            }
        ps_trimesh_free(&tm);
        double r = SPHERE_RADIUS;
        for (size_t v = lo; v < hi; v++) {
            ps_vec3 d = ps_v3_sub(get3(m.positions, v), SPHERE_CENTRE);
            assert_near(ps_v3_len(d), r, FLOAT_TOL);
            assert_near(ps_v3_len(ps_v3_sub(get3(m.normals, v), ps_v3_scale(d, 1.0 / r))), 0.0, 4.0 * FLOAT_TOL);
        }
        for (size_t t = lo / 3; t < hi / 3; t++) {
            /* The triangle's deepest point: its centroid and edge midpoints
             * bound it well enough on so fine a mesh. */
            ps_vec3 p0 = get3(m.positions, 3 * t), p1 = get3(m.positions, 3 * t + 1), p2 = get3(m.positions, 3 * t + 2);
            ps_vec3 c = ps_v3_scale(ps_v3_add(ps_v3_add(p0, p1), p2), 1.0 / 3.0);
            assert_true(ps_v3_len(ps_v3_sub(c, SPHERE_CENTRE)) >= r * (1.0 - PS_SPHERE_DEFAULT_TOLERANCE) - FLOAT_TOL);
            assert_true(longest_edge(&m, t) < 0.1 * r);
        }
        double area = span_area(&m, lo, hi), full = 4.0 * PS_PI * r * r;
        assert_true(area < full);
        assert_true(area > 0.99 * full);
    }
    ps_preview_mesh_free(&m);
    assert_null(m.positions);
    assert_int_equal(m.vertex_count, 0);
    ps_scene_destroy(s);
}

/* A huge max_edge leaves each triangle whole; a tiny one stops at
 * PS_MESH_MAX_SPLIT^2 a triangle; zero, negative or NaN mean 1. */
static void split_limits(void **state)
{
    (void)state;
    ps_scene *s = load(ROOM);
    size_t nobj;
    const ps_object *objects = ps_scene_objects(s, &nobj);
    ps_preview_mesh whole = build(s, 1e9);
    size_t lo, hi;
    for (uint32_t o = 0; o < OBJECTS; o++) {
        if (o == SPHERE)
            continue;
        object_span(&whole, o, &lo, &hi);
        assert_int_equal(hi - lo, 3 * (size_t)objects[o].triangle_count);
        assert_int_equal(hi - lo, 6); /* quads and the OBJ: two triangles each */
    }
    /* Whole triangles are the scene's, corner for corner. */
    object_span(&whole, TILTED, &lo, &hi);
    const ps_vec3 *spos = ps_scene_positions(s, NULL);
    const ps_triangle *tris = ps_scene_triangles(s, NULL);
    for (size_t k = 0; k < 6; k++) {
        ps_vec3 want = spos[tris[objects[TILTED].first_triangle + k / 3].v[k % 3]];
        assert_near(ps_v3_len(ps_v3_sub(get3(whole.positions, lo + k), want)), 0.0, FLOAT_TOL);
    }
    ps_preview_mesh_free(&whole);

    /* max_edge 1: the floor's diagonal 2 sqrt 2 needs 3. */
    ps_preview_mesh one = build(s, 1.0);
    object_span(&one, FLOOR, &lo, &hi);
    assert_int_equal(hi - lo, 2 * 3 * 3 * 3);
    static const double odd[] = {0.0, -1.0, NAN};
    for (size_t i = 0; i < sizeof odd / sizeof odd[0]; i++) {
        ps_preview_mesh m = build(s, odd[i]);
        assert_int_equal(m.vertex_count, one.vertex_count);
        assert_memory_equal(m.positions, one.positions, 3 * m.vertex_count * sizeof(float));
        ps_preview_mesh_free(&m);
    }
    ps_preview_mesh_free(&one);
    ps_scene_destroy(s);

    /* Tiny: capped. One quad only, to keep it small (2 * 256^2 triangles). */
    s = load("camera eye 0 1 5 target 0 0 0\nlight point position 0 3 0 power 1 1 1\n"
             "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0\n");
    ps_preview_mesh tiny = build(s, 1e-6);
    assert_int_equal(tiny.range_count, 1);
    assert_int_equal(tiny.vertex_count, 2 * 3 * (size_t)PS_MESH_MAX_SPLIT * PS_MESH_MAX_SPLIT);
    double worst = 0.0, area = 0.0;
    for (size_t t = 0; t < tiny.vertex_count / 3; t++) {
        worst = fmax(worst, longest_edge(&tiny, t));
        area += 0.5 * ps_v3_len(tri_cross(&tiny, t));
    }
    assert_near(worst, 2.0 * sqrt(2.0) / PS_MESH_MAX_SPLIT, FLOAT_TOL);
    assert_near(area, 4.0, 1e-9);
    ps_preview_mesh_free(&tiny);
    ps_scene_destroy(s);
}

static void defaults_and_errors(void **state)
{
    (void)state;
    ps_scene *s = load(ROOM);
    ps_mesh_options o = ps_mesh_default_options(s);
    double diag = ps_v3_len(ps_aabb_diag(ps_scene_bounds(s)));
    assert_true(diag > 2.0);
    assert_near(o.max_edge, diag / 64.0, 1e-15 * diag);
    assert_near(o.sphere_tolerance, PS_SPHERE_DEFAULT_TOLERANCE, 0.0);

    /* A tolerance the tessellator refuses: its error, and nothing built. */
    o.sphere_tolerance = 0.0;
    ps_preview_mesh m;
    ps_error err;
    assert_int_equal(ps_preview_mesh_build(s, &o, &m, &err), PS_ERR_RANGE);
    assert_int_equal(err.status, PS_ERR_RANGE);
    assert_non_null(strstr(err.msg, "tolerance"));
    assert_null(m.positions);
    assert_null(m.ranges);
    assert_int_equal(m.vertex_count, 0);
    assert_int_equal(m.range_count, 0);
    ps_preview_mesh_free(&m);
    ps_scene_destroy(s);

    /* Freeing a zeroed mesh (twice) and NULL. */
    ps_preview_mesh z;
    memset(&z, 0, sizeof z);
    ps_preview_mesh_free(&z);
    ps_preview_mesh_free(&z);
    ps_preview_mesh_free(NULL);
}

/* Ten spheres are 98 000 triangles, 14.6 MiB planned: refused under a 4 MiB
 * budget before anything is allocated, built under 16 MiB. */
static void memory_budget(void **state)
{
    (void)state;
    char text[2048];
    int n = snprintf(text, sizeof text, "camera eye 0 0 30 target 0 0 0\nlight point position 0 9 0 power 1 1 1\n");
    for (int i = 0; i < 10; i++)
        n += snprintf(text + n, sizeof text - (size_t)n, "sphere center %d 0 0 radius 0.4\n", i);
    ps_scene *s;
    ps_error err;
    if (ps_scene_load_text(text, "spheres.scn", "", NULL, &s, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_mesh_options o = ps_mesh_default_options(s);
    ps_preview_mesh m;
    setenv("PS_MEMORY_LIMIT", "4M", 1);
    assert_int_equal(ps_preview_mesh_build(s, &o, &m, &err), PS_ERR_LIMIT);
    assert_string_equal(err.msg, "spheres.scn: the preview mesh of 98000 triangles would need 15 MiB, more than the "
                                 "memory budget of 4 MiB (set by PS_MEMORY_LIMIT)");
    assert_null(m.positions);
    setenv("PS_MEMORY_LIMIT", "16M", 1);
    assert_int_equal(ps_preview_mesh_build(s, &o, &m, &err), PS_OK);
    assert_int_equal(m.vertex_count, 3 * 98000);
    unsetenv("PS_MEMORY_LIMIT");
    ps_preview_mesh_free(&m);
    ps_scene_destroy(s);
}

/* The moving camera's lit mesh (ps_mesh_moving_options): edges twice as
 * long, so each flat face split the least that keeps them within that
 * (ceil(n / 2) for n, about a quarter of the vertices), the same surfaces
 * (each object's area, its ranges' objects and materials, in order) and the
 * sphere exactly the fine mesh's, vertex for vertex: the depth prepass draws
 * that tessellation, and a coarser one would lie behind it. Counted before
 * building, as built. */
static void moving_mesh(void **state)
{
    (void)state;
    ps_scene *s = load(ROOM);
    ps_mesh_options fine_o = ps_mesh_default_options(s), moving_o = ps_mesh_moving_options(&fine_o);
    assert_near(moving_o.max_edge, PS_MESH_MOVING_EDGE_SCALE * fine_o.max_edge, 0.0);
    assert_near(moving_o.sphere_tolerance, fine_o.sphere_tolerance, 0.0);
    ps_preview_mesh fine = build(s, fine_o.max_edge), moving = build(s, moving_o.max_edge);
    assert_int_equal(ps_preview_mesh_vertex_count(s, &fine_o), fine.vertex_count);
    assert_int_equal(ps_preview_mesh_vertex_count(s, &moving_o), moving.vertex_count);
    printf("moving mesh: %zu vertices of the fine mesh's %zu\n", moving.vertex_count, fine.vertex_count);
    for (uint32_t obj = 0; obj < OBJECTS; obj++) {
        size_t flo, fhi, mlo, mhi;
        object_span(&fine, obj, &flo, &fhi);
        object_span(&moving, obj, &mlo, &mhi);
        double fa = span_area(&fine, flo, fhi), ma = span_area(&moving, mlo, mhi);
        assert_near(ma, fa, FLOAT_TOL * fa);
        for (size_t t = mlo / 3; t < mhi / 3; t++)
            assert_true(longest_edge(&moving, t) <= moving_o.max_edge * (1.0 + EDGE_SLACK));
        if (obj == SPHERE) {
            assert_int_equal(mhi - mlo, fhi - flo);
            assert_memory_equal(moving.positions + 3 * mlo, fine.positions + 3 * flo, 3 * sizeof(float) * (fhi - flo));
        }
    }
    /* The floor (2 x 2, its diagonal 2.83 the longest edge): n x n pieces
     * each side at the fine edge, ceil(n / 2) at the moving one. */
    size_t flo, fhi, mlo, mhi;
    object_span(&fine, FLOOR, &flo, &fhi);
    object_span(&moving, FLOOR, &mlo, &mhi);
    size_t n = (size_t)ceil(sqrt(8.0) / fine_o.max_edge), half = (n + 1) / 2;
    assert_int_equal(fhi - flo, 2 * 3 * n * n);
    assert_int_equal(mhi - mlo, 2 * 3 * half * half);
    assert_int_equal(moving.range_count, fine.range_count);
    for (size_t r = 0; r < fine.range_count; r++) {
        assert_int_equal(moving.ranges[r].object, fine.ranges[r].object);
        assert_int_equal(moving.ranges[r].material, fine.ranges[r].material);
    }
    ps_preview_mesh_free(&fine);
    ps_preview_mesh_free(&moving);
    ps_scene_destroy(s);
}

/* Tiles (ps_mesh_make_tiles): each range's triangles, every one once and
 * as its three vertices in order, in tiles that follow one another; each
 * tile's bounds hold its vertices; a flat range is cut on its two long axes
 * only, into about triangles / per tiles; a small range is one tile. */
static int cmp_triple(const void *a, const void *b)
{
    const uint32_t *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

static void tiles(void **state)
{
    (void)state;
    ps_scene *s = load(ROOM);
    ps_preview_mesh m = build(s, 0.05);
    const size_t per = 64;
    ps_mesh_tiling t;
    ps_error err;
    assert_int_equal(ps_mesh_make_tiles(&m, per, &t, &err), PS_OK);
    assert_int_equal(t.range_count, m.range_count);
    size_t next = 0;
    for (size_t r = 0; r < m.range_count; r++) {
        const ps_mesh_range *g = &m.ranges[r];
        size_t tris = g->count / 3, first = t.range_tiles[r], end = t.range_tiles[r + 1];
        assert_true(end > first);
        uint32_t *want = malloc(g->count * sizeof *want), *got = malloc(g->count * sizeof *got);
        assert_non_null(want);
        assert_non_null(got);
        for (size_t j = 0; j < g->count; j++)
            want[j] = m.shared ? m.shared[g->first + j] : (uint32_t)(g->first + j);
        size_t n = 0;
        for (size_t x = first; x < end; x++) {
            const ps_mesh_tile *tile = &t.tiles[x];
            assert_int_equal(tile->first, next); /* one after another */
            assert_true(tile->count > 0 && tile->count % 3 == 0);
            next += tile->count;
            for (size_t j = tile->first; j < tile->first + tile->count; j++) {
                ps_vec3 p = get3(m.positions, t.indices[j]);
                assert_true(p.x >= tile->bounds.lo.x && p.x <= tile->bounds.hi.x);
                assert_true(p.y >= tile->bounds.lo.y && p.y <= tile->bounds.hi.y);
                assert_true(p.z >= tile->bounds.lo.z && p.z <= tile->bounds.hi.z);
                got[n++] = t.indices[j];
            }
        }
        assert_int_equal(n, g->count);
        qsort(want, tris, 3 * sizeof *want, cmp_triple);
        qsort(got, tris, 3 * sizeof *got, cmp_triple);
        assert_memory_equal(want, got, g->count * sizeof *got);
        free(want);
        free(got);
        if (tris <= per)
            assert_int_equal(end - first, 1);
        if (g->object == FLOOR) {
            /* y = 0 throughout: no cut across it, about tris / per tiles */
            printf("floor: %zu triangles in %zu tiles of at most %zu asked\n", tris, end - first, per);
            assert_true(end - first >= tris / per / 2 && end - first <= 2 * tris / per);
            for (size_t x = first; x < end; x++)
                assert_true(t.tiles[x].bounds.lo.y == 0.0 && t.tiles[x].bounds.hi.y == 0.0);
        }
    }
    ps_mesh_tiling_free(&t);
    ps_mesh_tiling_free(&t); /* zeroed: again is harmless */
    ps_preview_mesh_free(&m);
    ps_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(room),
        cmocka_unit_test(split_limits),
        cmocka_unit_test(defaults_and_errors),
        cmocka_unit_test(memory_budget),
        cmocka_unit_test(moving_mesh),
        cmocka_unit_test(tiles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
