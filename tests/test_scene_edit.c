/* test_scene_edit.c: the scene editing API (lights moved, powers and spot
 * angles changed, objects translated, deep copies). The oracle is the loader:
 * an edited scene must equal, field for field, the scene whose file says the
 * new values; refused edits must leave every array byte-identical. */
#include "test.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"
#include "scene_same.h"

/* ---- helpers ------------------------------------------------------------------- */

/* The emissive OBJ (one emitting unit square facing down at y = 2 and one grey
 * triangle, with vertex normals), written once under build/test-tmp. */
static const char *lamp_dir(void)
{
    static char dir[1024];
    if (!dir[0]) {
        FILE *fp = fopen(test_path("lamp.obj"), "wb");
        assert_non_null(fp);
        fputs("mtllib lamp.mtl\n"
              "v -0.5 2 -0.5\nv 0.5 2 -0.5\nv 0.5 2 0.5\nv -0.5 2 0.5\n"
              "v 1 0 0\nv 2 0 0\nv 1 1 0\n"
              "vn 0 -1 0\nvn 0 0 1\n"
              "usemtl glow\nf 1//1 2//1 3//1 4//1\n"
              "usemtl body\nf 5//2 6//2 7//2\n",
              fp);
        fclose(fp);
        fp = fopen(test_path("lamp.mtl"), "wb");
        assert_non_null(fp);
        fputs("newmtl glow\nKd 0 0 0\nKe 2 2 2\nnewmtl body\nKd 0.5 0.5 0.5\n", fp);
        fclose(fp);
        snprintf(dir, sizeof dir, "%s", test_path(""));
        dir[strlen(dir) - 1] = '\0'; /* drop the trailing '/' */
    }
    return dir;
}

/* Loads text as "edit.scn" with OBJ paths relative to the lamp's directory. */
static ps_scene *load(const char *text)
{
    ps_scene *s = NULL;
    ps_error err;
    warn_log log = {0, ""};
    ps_scene_load_options opts = {{log_warning, &log}};
    if (ps_scene_load_text(text, "edit.scn", lamp_dir(), &opts, &s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    return s;
}

/* A floor quad (object 0), a sphere (object 1) and a point light (light 0) at
 * lines 2-4, then `extra` at line 5. */
static ps_scene *load_with(const char *extra)
{
    char text[2048];
    snprintf(text, sizeof text,
             "camera eye 0 1 3 target 0 1 0\n"
             "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0\n"
             "sphere center 0 0.5 0 radius 0.25\n"
             "light point position 0 1 0 power 1 1 1\n"
             "%s\n",
             extra);
    return load(text);
}

/* A byte copy of every observable array of a scene, to prove a refused edit
 * changed nothing. */
typedef struct snapshot {
    void *data[7];
    size_t bytes[7];
    ps_aabb bounds;
    ps_camera camera;
    ps_scene_defaults defaults;
} snapshot;

static void take(snapshot *sn, const ps_scene *s)
{
    size_t n[7];
    const void *src[7] = {
        ps_scene_materials(s, &n[0]), ps_scene_positions(s, &n[1]), ps_scene_normals(s, &n[2]),
        ps_scene_triangles(s, &n[3]), ps_scene_objects(s, &n[4]),   ps_scene_lights(s, &n[5]),
        ps_scene_emitters(s, &n[6]),
    };
    const size_t elem[7] = {sizeof(ps_material), sizeof(ps_vec3),  sizeof(ps_vec3), sizeof(ps_triangle),
                            sizeof(ps_object),   sizeof(ps_light), sizeof(uint32_t)};
    for (int i = 0; i < 7; i++) {
        sn->bytes[i] = n[i] * elem[i];
        sn->data[i] = malloc(sn->bytes[i] + 1);
        assert_non_null(sn->data[i]);
        if (sn->bytes[i])
            memcpy(sn->data[i], src[i], sn->bytes[i]);
    }
    sn->bounds = ps_scene_bounds(s);
    sn->camera = *ps_scene_camera(s);
    sn->defaults = *ps_scene_get_defaults(s);
}

static void assert_unchanged(const snapshot *sn, const ps_scene *s)
{
    snapshot now;
    take(&now, s);
    for (int i = 0; i < 7; i++) {
        assert_int_equal(now.bytes[i], sn->bytes[i]);
        if (sn->bytes[i])
            assert_memory_equal(now.data[i], sn->data[i], sn->bytes[i]);
        free(now.data[i]);
    }
    assert_memory_equal(&now.bounds, &sn->bounds, sizeof now.bounds);
    assert_memory_equal(&now.camera, &sn->camera, sizeof now.camera);
    assert_memory_equal(&now.defaults, &sn->defaults, sizeof now.defaults);
}

static void drop(snapshot *sn)
{
    for (int i = 0; i < 7; i++)
        free(sn->data[i]);
}

/* A refused edit: PS_ERR_RANGE, exactly this message, nothing changed. The
 * call names its error record `rerr`. */
#define assert_refused(s, call, expected)                                                                        \
    do {                                                                                                          \
        snapshot sn_;                                                                                             \
        take(&sn_, (s));                                                                                          \
        ps_error e_;                                                                                              \
        ps_error *rerr = &e_;                                                                                     \
        assert_int_equal((call), PS_ERR_RANGE);                                                                   \
        assert_int_equal(e_.status, PS_ERR_RANGE);                                                                \
        assert_string_equal(e_.msg, (expected));                                                                  \
        assert_unchanged(&sn_, (s));                                                                              \
        drop(&sn_);                                                                                               \
    } while (0)

static void ok(ps_status st, const ps_error *err)
{
    if (st != PS_OK)
        fail_msg("%s", err->msg);
    assert_int_equal(err->status, PS_OK);
    assert_string_equal(err->msg, "");
}

/* ---- moving lights ------------------------------------------------------------------ */

/* Each light type starts far up (y = 10) and moves into the room: the edited
 * scene equals the scene written with the new place, its bounds shrink back to
 * the rest of the scene, and the moved light's own numbers are as expected. */
static void move_each_light_type(void **state)
{
    (void)state;
    static const struct {
        const char *before, *after;
        ps_vec3 to;
    } cases[] = {
        {"light point position 0 10 0 power 1 2 3", "light point position 0.5 1.5 -0.5 power 1 2 3", {0.5, 1.5, -0.5}},
        {"light spot position 0 10 0 direction 1 -1 0 angle 45 power 5 5 5",
         "light spot position 0.5 1 0.5 direction 1 -1 0 angle 45 power 5 5 5", {0.5, 1, 0.5}},
        {"light quad corner 0 10 0 edge1 0.5 0 0 edge2 0 0 0.5 power 100 100 100",
         "light quad corner -0.25 1.75 -0.25 edge1 0.5 0 0 edge2 0 0 0.5 power 100 100 100", {-0.25, 1.75, -0.25}},
        {"light sphere center 0 10 0 radius 0.125 power 100 100 100",
         "light sphere center 0.5 1.5 0.5 radius 0.125 power 100 100 100", {0.5, 1.5, 0.5}},
        {"light disc center 0 10 0 normal 0 -1 1 radius 0.25 power 100 100 100",
         "light disc center 0 1.5 0 normal 0 -1 1 radius 0.25 power 100 100 100", {0, 1.5, 0}},
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        ps_scene *s = load_with(cases[c].before), *want = load_with(cases[c].after);
        const ps_light before = ps_scene_lights(s, NULL)[1];
        assert_true(ps_scene_bounds(s).hi.y >= 10.0);
        ps_error err;
        ok(ps_scene_set_light_position(s, 1, cases[c].to, &err), &err);
        assert_same_scene(s, want, SCENE_SAME_LINES);
        const ps_light *l = &ps_scene_lights(s, NULL)[1];
        assert_same_vec(l->position, cases[c].to);
        /* The shape travels unchanged: edges, normal, radius, area, radiance. */
        assert_same_vec(l->edge1, before.edge1);
        assert_same_vec(l->edge2, before.edge2);
        assert_same_vec(l->direction, before.direction);
        assert_same_double(l->radius, before.radius);
        assert_same_double(l->area, before.area);
        assert_same_rgb(l->radiance, before.radiance);
        /* The old place is forgotten: all that is left reaches y = 1.875 at most. */
        ps_aabb b = ps_scene_bounds(s);
        assert_true(b.hi.y < 2.0);
        assert_true(ps_aabb_contains(b, cases[c].to));
        ps_scene_destroy(s);
        ps_scene_destroy(want);
    }
}

/* The bounds are exactly the rest of the scene plus the light's new box. */
static void moved_light_bounds(void **state)
{
    (void)state;
    ps_scene *s = load_with("light quad corner 0 10 0 edge1 0.5 0 0 edge2 0 0 0.5 power 1 1 1");
    ps_error err;
    ok(ps_scene_set_light_position(s, 1, ps_v3(3, -2, 0.5), &err), &err);
    ps_aabb b = ps_scene_bounds(s);
    /* Floor x, z in [-1, 1] at y 0; sphere y in [0.25, 0.75]; point light at y 1;
     * quad light x in [3, 3.5], y -2, z in [0.5, 1]. */
    assert_near(b.lo.x, -1, 0);
    assert_near(b.hi.x, 3.5, 0);
    assert_near(b.lo.y, -2, 0);
    assert_near(b.hi.y, 1, 0);
    assert_near(b.lo.z, -1, 0);
    assert_near(b.hi.z, 1, 0);
    /* Moving the point light, the highest thing, lowers the top. */
    ok(ps_scene_set_light_position(s, 0, ps_v3(0, 0.5, 0), &err), &err);
    assert_near(ps_scene_bounds(s).hi.y, 0.75, 0);
    ps_scene_destroy(s);
}

static void move_light_errors(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text,
             "camera eye 0 1 3 target 0 1 0\n"
             "light quad corner 0 1 0 edge1 1 0 0 edge2 0 0 1 power 1 1 1\n"
             "\n"
             "mesh lamp.obj\n"
             "light sphere center 0 1 0 radius 1 power 1 1 1\n");
    ps_scene *s = load(text);
    assert_int_equal(ps_scene_lights(s, NULL)[1].type, PS_LIGHT_MESH);
    assert_refused(s, ps_scene_set_light_position(s, 3, ps_v3(0, 0, 0), rerr),
                   "edit.scn: light 3 does not exist (the scene has 3 lights)");
    assert_refused(s, ps_scene_set_light_position(s, (size_t)-1, ps_v3(0, 0, 0), rerr),
                   "edit.scn: light 18446744073709551615 does not exist (the scene has 3 lights)");
    assert_refused(s, ps_scene_set_light_position(s, 1, ps_v3(0, 0, 0), rerr),
                   "edit.scn:4: light 1 is an emissive mesh: move its object (object 0)");
    assert_refused(s, ps_scene_set_light_position(s, 2, ps_v3(0, NAN, 0), rerr),
                   "edit.scn:5: light 2: position (0 nan 0) is not finite");
    assert_refused(s, ps_scene_set_light_position(s, 2, ps_v3(0, 0, -INFINITY), rerr),
                   "edit.scn:5: light 2: position (0 0 -inf) is not finite");
    /* At the edge of range but finite, corners and radius included: accepted.
     * (The loader's limits on edges and radii, finite lengths and areas, keep
     * a finite reference point from taking a shape beyond DBL_MAX.) */
    ps_error e;
    ok(ps_scene_set_light_position(s, 0, ps_v3(-1.7e308, 0, 0), &e), &e);
    ok(ps_scene_set_light_position(s, 2, ps_v3(DBL_MAX, 0, 0), &e), &e);
    ps_aabb b = ps_scene_bounds(s);
    assert_true(ps_v3_isfinite(b.lo) && ps_v3_isfinite(b.hi));
    assert_near(b.hi.x, DBL_MAX, 0);
    assert_near(b.lo.x, -1.7e308, 0);
    /* err may be NULL. */
    assert_int_equal(ps_scene_set_light_position(s, 2, ps_v3(NAN, 0, 0), NULL), PS_ERR_RANGE);
    assert_int_equal(ps_scene_set_light_position(s, 2, ps_v3(0, 1, 0), NULL), PS_OK);
    ps_scene_destroy(s);
}

/* ---- power and spot angle --------------------------------------------------------- */

static void power_of_each_light_type(void **state)
{
    (void)state;
    static const char *before[] = {
        "light point position 0 1 0 power 1 2 3",
        "light spot position 0 1 0 direction 0 -1 0 angle 30 power 1 2 3",
        "light quad corner 0 1 0 edge1 0.5 0 0 edge2 0 0 0.25 power 1 2 3",
        "light sphere center 0 1 0 radius 0.125 power 1 2 3",
        "light disc center 0 1 0 normal 0 -1 0 radius 0.25 power 1 2 3",
    };
    static const char *after[] = {
        "light point position 0 1 0 power 40 0 0.5",
        "light spot position 0 1 0 direction 0 -1 0 angle 30 power 40 0 0.5",
        "light quad corner 0 1 0 edge1 0.5 0 0 edge2 0 0 0.25 power 40 0 0.5",
        "light sphere center 0 1 0 radius 0.125 power 40 0 0.5",
        "light disc center 0 1 0 normal 0 -1 0 radius 0.25 power 40 0 0.5",
    };
    for (size_t c = 0; c < 5; c++) {
        ps_scene *s = load_with(before[c]), *want = load_with(after[c]);
        ps_error err;
        ok(ps_scene_set_light_power(s, 1, ps_rgb_make(40, 0, 0.5), &err), &err);
        assert_same_scene(s, want, SCENE_SAME_LINES);
        const ps_light *l = &ps_scene_lights(s, NULL)[1];
        assert_near(l->power.r, 40, 0);
        if (l->area > 0.0) {
            assert_near(l->radiance.r, 40 / (PS_PI * l->area), 1e-12 * l->radiance.r);
            assert_near(l->radiance.g, 0, 0);
            assert_near(l->radiance.b, 0.5 / (PS_PI * l->area), 1e-12 * l->radiance.b);
        } else {
            assert_near(l->radiance.r, 0, 0);
        }
        ps_rgb total = ps_scene_total_power(s);
        assert_near(total.r, 41, 0);
        assert_near(total.g, 1, 0);
        assert_near(total.b, 1.5, 0);
        ps_scene_destroy(s);
        ps_scene_destroy(want);
    }
}

/* A mesh light's power is its faces' emission times pi * area: both change. */
static void power_of_mesh_light(void **state)
{
    (void)state;
    ps_scene *s = load("camera eye 0 1 3 target 0 1 0\nmesh lamp.obj\n");
    size_t n;
    const ps_light *l = ps_scene_lights(s, &n);
    assert_int_equal(n, 1);
    assert_int_equal(l->type, PS_LIGHT_MESH);
    assert_near(l->area, 1, 0);
    assert_near(l->power.r, 2 * PS_PI, 0);
    uint32_t m = ps_scene_triangles(s, NULL)[ps_scene_emitters(s, NULL)[l->first_emitter]].material;
    const ps_material *mat = &ps_scene_materials(s, NULL)[m];
    assert_string_equal(mat->name, "lamp.obj/glow");
    ps_error err;
    ok(ps_scene_set_light_power(s, 0, ps_rgb_make(PS_PI, 0, 3 * PS_PI), &err), &err);
    assert_near(l->power.r, PS_PI, 0);
    assert_near(l->power.b, 3 * PS_PI, 0);
    assert_near(l->radiance.r, 1, 1e-15);
    assert_near(l->radiance.g, 0, 0);
    assert_near(l->radiance.b, 3, 3e-15);
    assert_same_rgb(mat->emission, l->radiance);
    assert_near(ps_scene_total_power(s).b, 3 * PS_PI, 0);
    /* Zero power: a dark lamp, still a light. */
    ok(ps_scene_set_light_power(s, 0, ps_rgb_gray(0), &err), &err);
    assert_true(ps_rgb_is_black(mat->emission) && ps_rgb_is_black(l->radiance));
    ps_scene_destroy(s);
}

static void power_errors(void **state)
{
    (void)state;
    ps_scene *s = load_with("light quad corner 0 1 0 edge1 1e-77 0 0 edge2 0 0 1e-77 power 1 1 1");
    assert_refused(s, ps_scene_set_light_power(s, 2, ps_rgb_gray(1), rerr),
                   "edit.scn: light 2 does not exist (the scene has 2 lights)");
    assert_refused(s, ps_scene_set_light_power(s, 0, ps_rgb_make(1, -1, 0), rerr),
                   "edit.scn:4: light 0: power (1 -1 0) must not be negative");
    assert_refused(s, ps_scene_set_light_power(s, 0, ps_rgb_make(NAN, 1, 1), rerr),
                   "edit.scn:4: light 0: power (nan 1 1) is not finite");
    assert_refused(s, ps_scene_set_light_power(s, 1, ps_rgb_make(1, 1, INFINITY), rerr),
                   "edit.scn:5: light 1: power (1 1 inf) is not finite");
    /* An area of 1e-154: 1e300 W would be an infinite radiance. */
    assert_refused(s, ps_scene_set_light_power(s, 1, ps_rgb_gray(1e300), rerr),
                   "edit.scn:5: light 1: power (1e+300 1e+300 1e+300) is too large for its area 1e-154 (the "
                   "radiance would not be finite)");
    ps_error e;
    ok(ps_scene_set_light_power(s, 1, ps_rgb_gray(PS_SCENE_MAX_LIGHT_POWER), &e), &e);
    /* Past PS_SCENE_MAX_LIGHT_POWER a photon's RGBE power would clamp. */
    assert_refused(s, ps_scene_set_light_power(s, 1, ps_rgb_gray(1e150), rerr),
                   "edit.scn:5: light 1: power (1e+150 1e+150 1e+150) is above the 1e+30 W a light may have");
    ps_scene_destroy(s);
}

static void spot_angle(void **state)
{
    (void)state;
    ps_scene *s = load_with("light spot position 0 1 0 direction 0 -1 0 angle 30 power 1 1 1");
    ps_scene *want = load_with("light spot position 0 1 0 direction 0 -1 0 angle 60 power 1 1 1");
    ps_error err;
    ok(ps_scene_set_spot_angle(s, 1, 60, &err), &err);
    assert_same_scene(s, want, SCENE_SAME_LINES);
    const ps_light *l = &ps_scene_lights(s, NULL)[1];
    assert_near(l->angle_deg, 60, 0);
    assert_near(l->cos_angle, 0.5, 1e-15);
    ok(ps_scene_set_spot_angle(s, 1, 90, &err), &err);
    assert_near(l->cos_angle, 0, 1e-16);
    ok(ps_scene_set_spot_angle(s, 1, 1e-300, &err), &err);
    assert_near(l->cos_angle, 1, 0);
    assert_refused(s, ps_scene_set_spot_angle(s, 1, 95, rerr), "edit.scn:5: light 1: angle 95 is not in (0, 90]");
    assert_refused(s, ps_scene_set_spot_angle(s, 1, 0, rerr), "edit.scn:5: light 1: angle 0 is not in (0, 90]");
    assert_refused(s, ps_scene_set_spot_angle(s, 1, -30, rerr), "edit.scn:5: light 1: angle -30 is not in (0, 90]");
    assert_refused(s, ps_scene_set_spot_angle(s, 1, 90.000000000001, rerr),
                   "edit.scn:5: light 1: angle 90 is not in (0, 90]"); /* %g rounds; the check does not */
    assert_refused(s, ps_scene_set_spot_angle(s, 1, NAN, rerr), "edit.scn:5: light 1: angle nan is not in (0, 90]");
    assert_refused(s, ps_scene_set_spot_angle(s, 1, INFINITY, rerr),
                   "edit.scn:5: light 1: angle inf is not in (0, 90]");
    assert_refused(s, ps_scene_set_spot_angle(s, 0, 30, rerr),
                   "edit.scn:4: light 0 is a point light, not a spot: only spots have an angle");
    assert_refused(s, ps_scene_set_spot_angle(s, 7, 30, rerr),
                   "edit.scn: light 7 does not exist (the scene has 2 lights)");
    ps_scene_destroy(s);
    ps_scene_destroy(want);
}

/* ---- translating objects ------------------------------------------------------------ */

/* Vertices moved by exactly delta, the rest of the scene untouched, normals and
 * areas unchanged, and the result equal to loading the moved object. */
static void translate_quad_and_sphere(void **state)
{
    (void)state;
    ps_scene *s = load_with("light point position 0 3 0 power 1 1 1");
    ps_scene *want = load("camera eye 0 1 3 target 0 1 0\n"
                          "quad corner -0.5 -0.25 1 edge1 0 0 2 edge2 2 0 0\n"
                          "sphere center -2 0.5 0.125 radius 0.25\n"
                          "light point position 0 1 0 power 1 1 1\n"
                          "light point position 0 3 0 power 1 1 1\n");
    size_t npos;
    const ps_vec3 *p = ps_scene_positions(s, &npos);
    ps_vec3 before[4];
    memcpy(before, p, sizeof before);
    double area0 = ps_scene_triangle_area(s, 0), area1 = ps_scene_triangle_area(s, 1);
    ps_vec3 n0 = ps_scene_triangle_normal(s, 0);
    ps_aabb b0 = ps_scene_objects(s, NULL)[0].bounds;
    ps_vec3 d = ps_v3(0.5, -0.25, 2);
    ps_error err;
    ok(ps_scene_translate_object(s, 0, d, &err), &err);
    for (int v = 0; v < 4; v++) {
        ps_vec3 moved = ps_v3_add(before[v], d);
        assert_same_vec(p[v], moved);
    }
    assert_same_double(ps_scene_triangle_area(s, 0), area0);
    assert_same_double(ps_scene_triangle_area(s, 1), area1);
    ps_vec3 n1 = ps_scene_triangle_normal(s, 0);
    assert_same_vec(n0, n1);
    ps_aabb b1 = ps_scene_objects(s, NULL)[0].bounds;
    ps_vec3 lo = ps_v3_add(b0.lo, d), hi = ps_v3_add(b0.hi, d);
    assert_same_vec(b1.lo, lo);
    assert_same_vec(b1.hi, hi);
    ok(ps_scene_translate_object(s, 1, ps_v3(-2, 0, 0.125), &err), &err);
    const ps_object *sphere = &ps_scene_objects(s, NULL)[1];
    assert_near(sphere->center.x, -2, 0);
    assert_near(sphere->bounds.lo.x, -2.25, 0);
    assert_near(sphere->bounds.hi.z, 0.375, 0);
    assert_near(sphere->radius, 0.25, 0);
    assert_same_scene(s, want, SCENE_SAME_LINES);
    /* Scene bounds: the moved floor (z up to 3), the sphere (x down to -2.25),
     * the top light (y 3); the floor's old z = -1 is no longer needed. */
    ps_aabb b = ps_scene_bounds(s);
    assert_near(b.lo.x, -2.25, 0);
    assert_near(b.hi.x, 1.5, 0);
    assert_near(b.lo.y, -0.25, 0);
    assert_near(b.hi.y, 3, 0);
    assert_near(b.lo.z, -0.125, 0);
    assert_near(b.hi.z, 3, 0);
    ps_scene_destroy(s);
    ps_scene_destroy(want);
}

/* An OBJ mesh (tests/data/good/tri.obj) among other objects: only its own
 * vertices move. */
static void translate_obj_mesh(void **state)
{
    (void)state;
    ps_scene *s = load_with("mesh ../../../tests/data/good/tri.obj translate 0 0 1");
    ps_scene *want = load_with("mesh ../../../tests/data/good/tri.obj translate 0.25 -1 1.5");
    assert_int_equal(ps_scene_objects(s, NULL)[2].type, PS_OBJ_MESH);
    size_t npos;
    const ps_vec3 *p = ps_scene_positions(s, &npos);
    assert_int_equal(npos, 4 + 3); /* the floor's corners, then the triangle's */
    ps_vec3 before[7];
    memcpy(before, p, sizeof before);
    ps_error err;
    ok(ps_scene_translate_object(s, 2, ps_v3(0.25, -1, 0.5), &err), &err);
    assert_memory_equal(p, before, 4 * sizeof *p);
    for (int v = 4; v < 7; v++) {
        ps_vec3 moved = ps_v3_add(before[v], ps_v3(0.25, -1, 0.5));
        assert_same_vec(p[v], moved);
    }
    assert_near(ps_scene_triangle_area(s, 2), 0.5, 0);
    assert_same_scene(s, want, SCENE_SAME_LINES);
    assert_near(ps_scene_bounds(s).lo.y, -1, 0);
    ps_scene_destroy(s);
    ps_scene_destroy(want);
}

/* The emissive mesh's light travels with it: position (its box's centre),
 * area and power as the loader would give them; vertex normals unchanged. */
static void translate_emissive_mesh(void **state)
{
    (void)state;
    ps_scene *s = load("camera eye 0 1 3 target 0 1 0\nsphere center 0 0 0 radius 1\nmesh lamp.obj\n");
    ps_scene *want = load("camera eye 0 1 3 target 0 1 0\nsphere center 0 0 0 radius 1\n"
                          "mesh lamp.obj translate 1 0.5 -2\n");
    const ps_light *l = &ps_scene_lights(s, NULL)[0];
    assert_int_equal(l->type, PS_LIGHT_MESH);
    assert_int_equal(l->object, 1);
    assert_near(l->position.x, 0.75, 0); /* box x [-0.5, 2], y [0, 2], z [-0.5, 0.5] */
    assert_near(l->position.y, 1, 0);
    size_t nn;
    const ps_vec3 *normals = ps_scene_normals(s, &nn);
    assert_int_equal(nn, 2);
    ps_vec3 nbefore[2] = {normals[0], normals[1]};
    double area = l->area;
    ps_rgb power = l->power;
    ps_error err;
    ok(ps_scene_translate_object(s, 1, ps_v3(1, 0.5, -2), &err), &err);
    assert_near(l->position.x, 1.75, 0);
    assert_near(l->position.y, 1.5, 0);
    assert_near(l->position.z, -2, 0);
    assert_same_double(l->area, area);
    assert_same_rgb(l->power, power);
    assert_memory_equal(normals, nbefore, sizeof nbefore);
    assert_same_scene(s, want, SCENE_SAME_LINES);
    ps_aabb b = ps_scene_bounds(s);
    assert_near(b.hi.x, 3, 0);
    assert_near(b.hi.y, 2.5, 0);
    assert_near(b.lo.z, -2.5, 0);
    ps_scene_destroy(s);
    ps_scene_destroy(want);
}

/* Far from the origin the corners round, and so do the faces' areas: at
 * x = 2^52 the spacing of doubles is 1 on one side and 0.5 on the other, and
 * the lamp's square becomes 0.5 m wide. The light's area and power follow its
 * faces, exactly as the loader computes them for the mesh written there. */
static void translate_emissive_mesh_inexact(void **state)
{
    (void)state;
    ps_scene *s = load("camera eye 0 1 3 target 0 1 0\nmesh lamp.obj\n");
    ps_scene *want = load("camera eye 0 1 3 target 0 1 0\nmesh lamp.obj translate 4503599627370496 0 0\n");
    ps_error err;
    ok(ps_scene_translate_object(s, 0, ps_v3(4503599627370496.0, 0, 0), &err), &err);
    assert_same_scene(s, want, SCENE_SAME_LINES);
    const ps_light *l = &ps_scene_lights(s, NULL)[0];
    const uint32_t *em = ps_scene_emitters(s, NULL);
    double area = 0.0;
    for (uint32_t e = l->first_emitter; e < l->first_emitter + l->emitter_count; e++)
        area += ps_scene_triangle_area(s, em[e]);
    assert_same_double(l->area, area);
    assert_near(l->area, 0.5, 0); /* the case this test is for */
    assert_same_rgb(l->power, ps_rgb_scale(l->radiance, PS_PI * area));
    ps_scene_destroy(s);
    ps_scene_destroy(want);
}

static void translate_errors(void **state)
{
    (void)state;
    ps_scene *s = load("camera eye 0 1 3 target 0 1 0\n"
                       "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0\n"
                       "sphere center 0 0.5 0 radius 0.25\n"
                       "mesh ../../../tests/data/good/tri.obj\n"
                       "mesh lamp.obj\n"
                       "light point position 0 1 0 power 1 1 1\n");
    assert_refused(s, ps_scene_translate_object(s, 4, ps_v3(0, 0, 0), rerr),
                   "edit.scn: object 4 does not exist (the scene has 4 objects)");
    assert_refused(s, ps_scene_translate_object(s, 0, ps_v3(NAN, 0, 0), rerr),
                   "edit.scn:2: object 0: delta (nan 0 0) is not finite");
    assert_refused(s, ps_scene_translate_object(s, 1, ps_v3(0, -INFINITY, 0), rerr),
                   "edit.scn:3: object 1: delta (0 -inf 0) is not finite");
    /* 1e308 once stays in range (the far vertices land on 1e308 + 1 = 1e308);
     * twice overflows. */
    ps_error e;
    ok(ps_scene_translate_object(s, 1, ps_v3(1e308, 0, 0), &e), &e);
    assert_near(ps_scene_objects(s, NULL)[1].center.x, 1e308, 0);
    assert_refused(s, ps_scene_translate_object(s, 1, ps_v3(1e308, 0, 0), rerr),
                   "edit.scn:3: object 1: moving by (1e+308 0 0) takes it out of range");
    ok(ps_scene_translate_object(s, 2, ps_v3(0, 1e308, 0), &e), &e);
    assert_refused(s, ps_scene_translate_object(s, 2, ps_v3(0, 1e308, 0), rerr),
                   "edit.scn:4: object 2: moving by (0 1e+308 0) takes a vertex out of range");
    /* A quad 2 m wide at 1e20 m: its corners round together. */
    assert_refused(s, ps_scene_translate_object(s, 0, ps_v3(0, 0, 1e20), rerr),
                   "edit.scn:2: object 0: moving by (0 0 1e+20) would collapse it (coordinates too large for its "
                   "size)");
    /* So would the lamp's emitting square. */
    assert_refused(s, ps_scene_translate_object(s, 3, ps_v3(1e20, 0, 0), rerr),
                   "edit.scn:5: object 3: moving by (1e+20 0 0) would collapse the emitting faces of light 0 "
                   "(coordinates too large for their size)");
    /* The lamp's box centre would be (1.7e308 + 1.7e308) / 2: out of range even
     * though every vertex is finite (and the emitting square, level in y, keeps
     * its area). */
    assert_refused(s, ps_scene_translate_object(s, 3, ps_v3(0, 1.7e308, 0), rerr),
                   "edit.scn:5: object 3: moving by (0 1.7e+308 0) takes light 0 out of range");
    ps_scene_destroy(s);
}

/* ---- copies ---------------------------------------------------------------------------- */

static void clone_is_equal_and_deep(void **state)
{
    (void)state;
    ps_scene *s = load("camera eye 0 1 3 target 0 1 0 fov 50\n"
                       "image 64 32\n"
                       "material white diffuse albedo 0.75 0.75 0.75\n"
                       "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                       "sphere center 0 0.5 0 radius 0.25\n"
                       "mesh lamp.obj\n"
                       "light spot position 0 1 0 direction 0 -1 0 angle 30 power 1 1 1\n"
                       "light disc center 0 1.5 0 normal 0 -1 0 radius 0.25 power 3 3 3\n");
    ps_scene *c = NULL;
    ps_error err;
    ok(ps_scene_clone(s, &c, &err), &err);
    assert_non_null(c);
    assert_ptr_not_equal(c, s);
    snapshot orig, copy;
    take(&orig, s);
    take(&copy, c);
    for (int i = 0; i < 7; i++) {
        assert_int_equal(copy.bytes[i], orig.bytes[i]);
        if (orig.bytes[i])
            assert_memory_equal(copy.data[i], orig.data[i], orig.bytes[i]);
    }
    assert_memory_equal(&copy.bounds, &orig.bounds, sizeof orig.bounds);
    assert_memory_equal(&copy.camera, &orig.camera, sizeof orig.camera);
    assert_memory_equal(&copy.defaults, &orig.defaults, sizeof orig.defaults);
    assert_string_equal(ps_scene_path(c), ps_scene_path(s));
    assert_ptr_not_equal(ps_scene_path(c), ps_scene_path(s));
    assert_ptr_not_equal(ps_scene_positions(c, NULL), ps_scene_positions(s, NULL));
    assert_ptr_not_equal(ps_scene_lights(c, NULL), ps_scene_lights(s, NULL));
    assert_ptr_not_equal(ps_scene_materials(c, NULL), ps_scene_materials(s, NULL));
    drop(&copy);

    /* Every kind of edit on the copy leaves the original as it was. */
    ok(ps_scene_set_light_position(c, 1, ps_v3(5, 5, 5), &err), &err);
    ok(ps_scene_set_light_power(c, 2, ps_rgb_gray(9), &err), &err);
    ok(ps_scene_set_light_power(c, 0, ps_rgb_gray(9), &err), &err); /* the lamp: its material too */
    ok(ps_scene_set_spot_angle(c, 1, 10, &err), &err);
    ok(ps_scene_translate_object(c, 0, ps_v3(0, -1, 0), &err), &err);
    ok(ps_scene_translate_object(c, 1, ps_v3(0, -1, 0), &err), &err);
    ok(ps_scene_translate_object(c, 2, ps_v3(0, -1, 0), &err), &err);
    assert_unchanged(&orig, s);
    drop(&orig);

    /* The copy lives on its own (ASan would see a shared array here). */
    ps_scene_destroy(s);
    assert_near(ps_scene_lights(c, NULL)[1].position.x, 5, 0);
    assert_near(ps_scene_bounds(c).hi.x, 5, 0);
    ps_scene *cc = NULL;
    ok(ps_scene_clone(c, &cc, &err), &err);
    ps_scene_destroy(c);
    assert_near(ps_scene_lights(cc, NULL)[0].power.r, 9, 0);
    ps_scene_destroy(cc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(move_each_light_type),
        cmocka_unit_test(moved_light_bounds),
        cmocka_unit_test(move_light_errors),
        cmocka_unit_test(power_of_each_light_type),
        cmocka_unit_test(power_of_mesh_light),
        cmocka_unit_test(power_errors),
        cmocka_unit_test(spot_angle),
        cmocka_unit_test(translate_quad_and_sphere),
        cmocka_unit_test(translate_obj_mesh),
        cmocka_unit_test(translate_emissive_mesh),
        cmocka_unit_test(translate_emissive_mesh_inexact),
        cmocka_unit_test(translate_errors),
        cmocka_unit_test(clone_is_equal_and_deep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
