/* test_obj.c: OBJ/MTL loading: edge cases with exact results and located errors,
 * and the MTL → material mapping and mesh transforms as the scene applies them. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "scene/obj.h"
#include "scene/scene.h"

/* Writes `text` to a scratch file and returns its path (static buffer). */
static const char *write_file(const char *name, const char *text, size_t len)
{
    const char *path = test_path(name);
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(text, 1, len, fp), len);
    fclose(fp);
    return path;
}

static const char *write_text(const char *name, const char *text) { return write_file(name, text, strlen(text)); }

/* Loads and expects failure with status st and a message holding `want`. */
static void expect_error(const char *path, ps_status st, const char *want)
{
    ps_obj_mesh m;
    ps_error err;
    warn_log log = {0, ""};
    ps_warn_sink sink = {log_warning, &log};
    ps_status got = ps_obj_load(path, &m, &sink, &err);
    if (got != st || !strstr(err.msg, want))
        fail_msg("%s: status %d '%s', expected %d with '%s'", path, got, err.msg, st, want);
    assert_null(strchr(err.msg, '\n'));
    assert_int_equal(m.triangle_count, 0);
    assert_null(m.positions);
}

static const char quad_obj[] = "# a unit quad and a pentagon\n"
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                               "vn 0 0 1\n"
                               "f 1//1 2//1 3//1 4//1\n"
                               "v 2 0 0\nv 3 0 0\nv 3.5 1 0\nv 2.5 2 0\nv 1.5 1 0\n"
                               "f -5 -4 -3 -2 -1\n";

static void polygons_become_fans(void **state)
{
    (void)state;
    ps_obj_mesh m;
    ps_error err;
    assert_int_equal(ps_obj_load(write_text("quad.obj", quad_obj), &m, NULL, &err), PS_OK);
    assert_int_equal(m.position_count, 9);
    assert_int_equal(m.normal_count, 1);
    assert_int_equal(m.triangle_count, 2 + 3); /* quad: 2, pentagon: 3 */
    /* Fan around the first corner: (0,1,2), (0,2,3). */
    int32_t want[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; k++)
        assert_int_equal(m.tri_v[k], want[k]);
    assert_int_equal(m.tri_n[0], 0);
    /* Relative indices -5..-1 after 9 vertices are 4..8. */
    assert_int_equal(m.tri_v[6], 4);
    assert_int_equal(m.tri_v[8], 6);
    assert_int_equal(m.tri_n[6], -1);
    assert_int_equal(m.tri_mat[0], -1);
    ps_obj_free(&m);
    ps_obj_free(&m); /* freeing twice is harmless: free zeroes */
}

static void malformed_files(void **state)
{
    (void)state;
    expect_error("tests/data/no-such.obj", PS_ERR_IO, "tests/data/no-such.obj: cannot open");
    expect_error("tests/data", PS_ERR_IO, "is a directory");
    expect_error(write_text("empty.obj", ""), PS_ERR_PARSE, "empty.obj: no faces");
    expect_error(write_text("prose.obj", "Dear reader,\nthis is not a mesh.\n"), PS_ERR_PARSE, "no faces");
    static const char junk[] = {'\x89', 'P', 'N', 'G', '\0', '\x01', 'f', ' ', '1', '\n'};
    expect_error(write_file("junk.obj", junk, sizeof junk), PS_ERR_PARSE, "binary data");
    expect_error(write_text("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), PS_ERR_RANGE,
                 "range.obj:4: face vertex index 4 is out of range (3 defined so far)");
    /* A face may only use vertices defined above it. */
    expect_error(write_text("ahead.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"), PS_ERR_RANGE, "ahead.obj:3:");
    expect_error(write_text("negrange.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 -2 -1\n"), PS_ERR_RANGE,
                 "negrange.obj:4: face vertex index -4 is out of range");
    expect_error(write_text("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), PS_ERR_PARSE,
                 "zero.obj:4: face vertex index '0' is not a non-zero integer");
    expect_error(write_text("normrange.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n"),
                 PS_ERR_RANGE, "normrange.obj:5: face normal index 2 is out of range");
    expect_error(write_text("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), PS_ERR_PARSE,
                 "nan.obj:2: 'v': 'nan' is not a finite number");
    expect_error(write_text("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n"), PS_ERR_PARSE,
                 "inf.obj:3: 'v': '1e999' is not a finite number");
    /* Found by fuzzing: tinyobjloader read this as infinite; magnitudes above 1e30 are refused. */
    expect_error(write_text("huge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 1e300 1\nf 1//1 2//1 3//1\n"), PS_ERR_RANGE,
                 "huge.obj:4: 'vn': '1e300' is out of range");
    expect_error(write_text("infn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 -inf 1\nf 1//1 2//1 3//1\n"), PS_ERR_PARSE,
                 "infn.obj:4: 'vn'");
    expect_error(write_text("short.obj", "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), PS_ERR_PARSE,
                 "short.obj:1: 'v' needs 3 to 6 numbers, got 2");
    expect_error(write_text("corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3/4 2 3\n"), PS_ERR_PARSE,
                 "corner.obj:4: malformed face corner");
    /* 256 corners overflow tinyobjloader's per-face count: refused, not corrupted. */
    char big[8192] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
    for (int k = 0; k < 256; k++)
        strcat(big, k % 3 == 0 ? " 1" : k % 3 == 1 ? " 2" : " 3");
    strcat(big, "\n");
    expect_error(write_text("big.obj", big), PS_ERR_LIMIT, "big.obj:4: face has 256 vertices");
}

static void degenerate_faces_warn(void **state)
{
    (void)state;
    ps_obj_mesh m;
    ps_error err;
    warn_log log = {0, ""};
    ps_warn_sink sink = {log_warning, &log};
    const char *path = write_text("degen.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\n");
    assert_int_equal(ps_obj_load(path, &m, &sink, &err), PS_OK);
    assert_int_equal(m.triangle_count, 1);
    assert_int_equal(log.count, 1);
    assert_non_null(strstr(log.last, "degen.obj:4: face with 2 vertices ignored"));
    ps_obj_free(&m);
}

static void missing_mtl_and_undefined_usemtl(void **state)
{
    (void)state;
    ps_obj_mesh m;
    ps_error err;
    warn_log log = {0, ""};
    ps_warn_sink sink = {log_warning, &log};
    const char *path =
        write_text("nomtl.obj", "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl shiny\nf 1 2 3\n");
    assert_int_equal(ps_obj_load(path, &m, &sink, &err), PS_OK);
    assert_int_equal(log.count, 2); /* the missing library, then the undefined name */
    assert_non_null(strstr(log.last, "nomtl.obj:5: usemtl 'shiny' is not defined"));
    assert_int_equal(m.tri_mat[0], -1);
    ps_obj_free(&m);
}

static void mtl_errors_are_located(void **state)
{
    (void)state;
    write_text("bad.mtl", "newmtl a\nKd 0.5 0.5 0.5\nnewmtl b\nKd nan 0 0\n");
    expect_error(write_text("badmtl.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), PS_ERR_PARSE,
                 "bad.mtl:4: 'Kd': 'nan' is not a finite number");
    write_text("neg.mtl", "newmtl a\nKs 0.5 -0.5 0.5\n");
    expect_error(write_text("negmtl.obj", "mtllib neg.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), PS_ERR_RANGE,
                 "neg.mtl:2: 'Ks' components must not be negative");
    write_text("illum.mtl", "newmtl a\nillum 42\n");
    expect_error(write_text("illum.obj", "mtllib illum.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), PS_ERR_PARSE,
                 "illum.mtl:2: illum needs one integer from 0 to 10");
}

/* The contract's MTL mapping, through a scene: mirror (illum 3/5, reflectance
 * Ks), dielectric (illum 4/6/7, ior Ni), glossy (Ks > 0), diffuse, and
 * emitters (Ke > 0) as area lights of flux pi * area * Ke. */
static void mtl_mapping_and_emitters(void **state)
{
    (void)state;
    write_text("mats.mtl", "newmtl matte\nKd 0.5 0.4 0.3\n"
                           "newmtl shiny\nKd 0.6 0.6 0.6\nKs 0.6 0.2 0.2\nNs 50\nillum 2\n"
                           "newmtl chrome\nKs 0.9 0.9 0.9\nillum 3\n"
                           "newmtl water\nNi 1.33\nillum 7\n"
                           "newmtl glassnoni\nillum 4\n"
                           "newmtl lamp\nKd 0 0 0\nKe 2 3 4\n");
    write_text("mats.obj", "mtllib mats.mtl\n"
                           "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                           "usemtl matte\nf 1 2 3\nusemtl shiny\nf 1 3 4\nusemtl chrome\nf 1 2 3\n"
                           "usemtl water\nf 1 2 3\nusemtl glassnoni\nf 1 2 3\n"
                           "usemtl lamp\nf 1 2 3 4\n");
    const char *scene = "camera eye 0 0 5 target 0 0 0\nmesh mats.obj\n";
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path(""));
    ps_scene *s;
    ps_error err;
    warn_log log = {0, ""};
    ps_scene_load_options opts = {{log_warning, &log}};
    if (ps_scene_load_text(scene, "mats.scn", dir, &opts, &s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    size_t nmat, nlight, ntri;
    const ps_material *m = ps_scene_materials(s, &nmat);
    const ps_triangle *t = ps_scene_triangles(s, &ntri);
    assert_int_equal(ntri, 7);
    const ps_material *matte = &m[t[0].material], *shiny = &m[t[1].material], *chrome = &m[t[2].material],
                      *water = &m[t[3].material], *noni = &m[t[4].material], *lamp = &m[t[5].material];
    assert_string_equal(matte->name, "mats.obj/matte");
    assert_int_equal(matte->type, PS_MAT_DIFFUSE);
    assert_near(matte->albedo.b, 0.3, 1e-6);
    /* Kd + Ks = 1.2 in red: scaled by 1/1.2 with a warning. */
    assert_int_equal(shiny->type, PS_MAT_GLOSSY);
    assert_near(shiny->albedo.r, 0.5, 1e-6);
    assert_near(shiny->specular.r, 0.5, 1e-6);
    assert_near(shiny->exponent, 50, 1e-6);
    assert_int_equal(chrome->type, PS_MAT_MIRROR);
    assert_near(chrome->reflectance.g, 0.9, 1e-6);
    assert_int_equal(water->type, PS_MAT_DIELECTRIC);
    assert_near(water->ior, 1.33, 1e-6);
    assert_int_equal(noni->type, PS_MAT_DIELECTRIC);
    assert_near(noni->ior, 1.5, 0); /* no Ni: glass, with a warning, not tinyobjloader's 1.0 */
    assert_near(lamp->emission.b, 4, 1e-6);
    assert_int_equal(log.count, 2);
    const ps_light *l = ps_scene_lights(s, &nlight);
    assert_int_equal(nlight, 1);
    assert_int_equal(l[0].type, PS_LIGHT_MESH);
    assert_int_equal(l[0].emitter_count, 2); /* the lamp quad's two triangles */
    assert_near(l[0].area, 1.0, 1e-12);
    assert_near(l[0].power.r, PS_PI * 2.0, 1e-5);
    assert_near(l[0].power.b, PS_PI * 4.0, 1e-5);
    size_t nobj;
    assert_true(ps_scene_objects(s, &nobj)[0].specular);
    ps_scene_destroy(s);

    /* A material override replaces the MTL entirely: no emitters, so no light. */
    const char *over = "camera eye 0 0 5 target 0 0 0\nmaterial w diffuse albedo 1 1 1\nmesh mats.obj material w\n";
    assert_int_equal(ps_scene_load_text(over, "over.scn", dir, &opts, &s, &err), PS_ERR_PARSE);
    assert_non_null(strstr(err.msg, "over.scn:3: the scene has no light"));
}

/* Transforms apply in the order written, normals follow the inverse
 * transpose, and a mirroring scale keeps geometric normals outward. */
static void mesh_transforms(void **state)
{
    (void)state;
    write_text("one.obj", "v 1 0 0\nv 0 1 0\nv 0 0 0\nvn 0 0 1\nvn 1 1 0\nf 1//1 2//1 3//2\n");
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path(""));
    ps_scene *s;
    ps_error err;
    const char *text = "camera eye 0 0 5 target 0 0 0\nlight point position 0 0 3 power 1 1 1\n"
                       "mesh one.obj scale 2 rotate 0 1 0 90 translate 1 0 0\n"
                       "mesh one.obj scale -1 1 1\n"
                       "mesh one.obj scale 1 4 1\n";
    if (ps_scene_load_text(text, "xf.scn", dir, NULL, &s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    size_t n;
    const ps_vec3 *p = ps_scene_positions(s, &n);
    const ps_vec3 *nn = ps_scene_normals(s, NULL);
    const ps_triangle *t = ps_scene_triangles(s, NULL);
    assert_int_equal(n, 9);
    /* (1,0,0): scale -> (2,0,0); +90 deg about y -> (0,0,-2); translate -> (1,0,-2). */
    assert_near(p[0].x, 1, 1e-12);
    assert_near(p[0].y, 0, 1e-12);
    assert_near(p[0].z, -2, 1e-12);
    /* (0,0,1) about y by 90 deg -> (1,0,0). */
    assert_near(nn[0].x, 1, 1e-12);
    assert_near(nn[0].z, 0, 1e-12);
    /* The mirrored copy: original winding (1,0,0),(0,1,0),(0,0,0) faces +z;
     * after x -> -x it still faces +z, because two corners were swapped. */
    ps_vec3 g = ps_scene_triangle_normal(s, 1);
    assert_near(g.z, 1, 1e-12);
    /* The first copy's face normal +z turned by 90 deg about y is +x. */
    assert_near(ps_scene_triangle_normal(s, 0).x, 1, 1e-12);
    assert_int_equal(t[1].v[0], 3); /* first corner kept */
    assert_int_equal(t[1].v[1], 5); /* second and third swapped */
    assert_near(nn[t[1].n[0]].z, 1, 1e-12);
    /* vn (1,1,0)/sqrt2 under x -> -x becomes (-1,1,0)/sqrt2. */
    assert_near(nn[3].x, -sqrt(0.5), 1e-12);
    assert_near(nn[3].y, sqrt(0.5), 1e-12);
    /* Non-uniform scale (1,4,1): the normal of the plane x + y = c becomes
     * (4,1,0)/sqrt17, perpendicular to the stretched tangent (1,-4,0). */
    assert_near(nn[5].x, 4 / sqrt(17.0), 1e-12);
    assert_near(nn[5].y, 1 / sqrt(17.0), 1e-12);
    ps_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(polygons_become_fans),
        cmocka_unit_test(malformed_files),
        cmocka_unit_test(degenerate_faces_warn),
        cmocka_unit_test(missing_mtl_and_undefined_usemtl),
        cmocka_unit_test(mtl_errors_are_located),
        cmocka_unit_test(mtl_mapping_and_emitters),
        cmocka_unit_test(mesh_transforms),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
