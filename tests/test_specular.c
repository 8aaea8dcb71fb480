/* test_specular.c: the specular layer's lookups (preview/specular.h), no GL:
 * Fresnel weights at normal incidence, energy kept through a glass sphere,
 * the distance-corrected lookup of a planar mirror in closed form, the
 * lookups of the default scene's mesh, lookups re-aimed from another
 * centre against fresh ones, and the per-pixel paths of the pixels near the
 * triangles against those of every pixel of their boxes. */
#include "test.h"

#include <math.h>
#include <string.h>

#include "photon/world.h"
#include "preview/mesh.h"
#include "preview/specular.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "specular_points.h"

typedef struct rig {
    ps_scene *scene;
    ps_world *world;
    const ps_material *mats;
} rig;

static rig rig_make(const char *text)
{
    rig r;
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &r.scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    assert_int_equal(ps_world_create(r.scene, NULL, &r.world, &err), PS_OK);
    size_t n;
    r.mats = ps_scene_materials(r.scene, &n);
    return r;
}

static void rig_free(rig *r)
{
    ps_world_destroy(r->world);
    ps_scene_destroy(r->scene);
}

static const ps_material *material(const rig *r, const char *name)
{
    size_t n;
    const ps_material *m = ps_scene_materials(r->scene, &n);
    for (size_t i = 0; i < n; i++)
        if (strcmp(m[i].name, name) == 0)
            return &m[i];
    fail_msg("no material %s", name);
    return NULL;
}

/* A single glass interface (a dielectric quad) seen head on: reflectance
 * ((n - 1) / (n + 1))^2 = 0.04 back toward the eye, 0.96 through. */
static void normal_incidence_reflects_4_percent(void **state)
{
    (void)state;
    rig r = rig_make("camera eye 0 0 2 target 0 0 0 up 0 1 0 fov 40\n"
                     "material glass dielectric ior 1.5\n"
                     "quad corner -1 -1 0 edge1 2 0 0 edge2 0 2 0 material glass\n"
                     "light point position 0 0 1 power 1 1 1\n");
    ps_specular_term t[PS_SPECULAR_TERMS];
    double dropped;
    int k = ps_specular_trace_point(r.world, r.mats, material(&r, "glass"), ps_v3(0, 0, 2), ps_v3(0, 0, 0),
                                    ps_v3(0, 0, 1), ps_v3(0, 0, 0), t, &dropped);
    assert_int_equal(k, 2);
    assert_near(dropped, 0.0, 0.0);
    /* The heavier first: through (toward -z), then back (toward +z). */
    assert_near(t[0].weight.r, 0.96, 1e-12);
    assert_true(t[0].dir.z < 0.0 && fabs(t[0].dir.x) < 1e-9 * fabs(t[0].dir.z));
    assert_near(t[1].weight.g, 0.04, 1e-12);
    assert_true(t[1].dir.z > 0.0);
    rig_free(&r);
}

/* A clear glass sphere alone: every path leaves it, so the kept terms and
 * the paths cut short add up to exactly 1 wherever the eye looks (Fresnel
 * splits, total internal reflection reflects all), and what is cut short
 * (paths under PS_SPECULAR_MIN_WEIGHT) is under 0.1 %, under 1 % at
 * grazing incidence, where every split is nearly even. */
static void glass_sphere_keeps_energy(void **state)
{
    (void)state;
    rig r = rig_make("camera eye 0 0 3 target 0 0 0 up 0 1 0 fov 40\n"
                     "material glass dielectric ior 1.5\n"
                     "sphere center 0 0 0 radius 0.5 material glass\n"
                     "light point position 0 2 0 power 1 1 1\n");
    const ps_material *glass = material(&r, "glass");
    ps_vec3 eye = ps_v3(0, 0, 3);
    for (int i = 0; i <= 20; i++) {
        double a = 1.35 * i / 20.0; /* from the pole facing the eye to near its silhouette (1.40) */
        ps_vec3 n = ps_v3(sin(a), 0.0, cos(a));
        ps_vec3 p = ps_v3_scale(n, 0.5);
        ps_specular_term t[PS_SPECULAR_TERMS];
        double dropped;
        int k = ps_specular_trace_point(r.world, r.mats, glass, eye, p, n, ps_v3(0, 0, 0), t, &dropped);
        if (k < 2)
            fail_msg("angle %g: %d terms", a, k);
        double sum = dropped;
        for (int j = 0; j < k; j++)
            sum += t[j].weight.r;
        assert_near(sum, 1.0, 1e-9);
        if (!(dropped < (a <= 1.2 ? 1e-3 : 1e-2)))
            fail_msg("angle %g: %g cut short", a, dropped);
    }
    rig_free(&r);
}

/* A planar mirror facing a wall: the lookup goes from the cube's centre to
 * the very point of the wall the reflected ray reaches (not along the
 * reflected direction, as a plain reflection map would). */
static void mirror_lookup_is_distance_corrected(void **state)
{
    (void)state;
    rig r = rig_make("camera eye 0 0 0.5 target 0 0 0 up 0 1 0 fov 40\n"
                     "material white diffuse albedo 0.5 0.5 0.5\n"
                     "material mirror mirror reflectance 0.9 0.8 0.7\n"
                     "quad corner -1 -1 0 edge1 2 0 0 edge2 0 2 0 material mirror\n"
                     "quad corner -3 -3 1 edge1 0 6 0 edge2 6 0 0 material white\n" /* z = 1, facing -z */
                     "light point position 0 0 0.8 power 1 1 1\n");
    ps_vec3 eye = ps_v3(0, 0, 0.5), p = ps_v3(0.3, 0.2, 0.0), centre = ps_v3(0.1, -0.1, 0.0);
    ps_specular_term t[PS_SPECULAR_TERMS];
    double dropped;
    int k = ps_specular_trace_point(r.world, r.mats, material(&r, "mirror"), eye, p, ps_v3(0, 0, 1), centre, t,
                                    &dropped);
    assert_int_equal(k, 1);
    ps_vec3 d = ps_v3_norm(ps_v3_sub(p, eye));
    ps_vec3 dr = ps_v3(d.x, d.y, -d.z);
    ps_vec3 hit = ps_v3_add(p, ps_v3_scale(dr, 1.0 / dr.z)); /* z = 1 */
    /* Scaled by the eye's distance over the path's (specular.c: exact
     * interpolation over a planar mirror's triangles). */
    double first = ps_v3_len(ps_v3_sub(p, eye)), length = first + ps_v3_len(ps_v3_sub(hit, p));
    ps_vec3 want = ps_v3_scale(ps_v3_sub(hit, centre), first / length);
    assert_near(t[0].dir.x, want.x, 1e-6);
    assert_near(t[0].dir.y, want.y, 1e-6);
    assert_near(t[0].dir.z, want.z, 1e-6);
    assert_near(t[0].weight.r, 0.9, 1e-12);
    assert_near(t[0].weight.b, 0.7, 1e-12);
    rig_free(&r);
}

/* The default scene, its world, its fine mesh and two lookup sets over it. */
typedef struct default_rig {
    ps_scene *scene;
    ps_world *world;
    ps_preview_mesh mesh;
    ps_specular *a, *b;
} default_rig;

/* In place: the lookup sets keep the mesh's address. */
static void default_rig_make(default_rig *d)
{
    ps_error err;
    assert_int_equal(ps_scene_load("data/scenes/cornell-caustic.scn", NULL, &d->scene, &err), PS_OK);
    assert_int_equal(ps_world_create(d->scene, NULL, &d->world, &err), PS_OK);
    ps_mesh_options mo = ps_mesh_default_options(d->scene);
    assert_int_equal(ps_preview_mesh_build(d->scene, &mo, &d->mesh, &err), PS_OK);
    size_t nm;
    assert_int_equal(ps_specular_create(&d->mesh, ps_scene_materials(d->scene, &nm), &d->a, &err), PS_OK);
    assert_int_equal(ps_specular_create(&d->mesh, ps_scene_materials(d->scene, &nm), &d->b, &err), PS_OK);
}

static void default_rig_free(default_rig *d)
{
    ps_specular_destroy(d->a);
    ps_specular_destroy(d->b);
    ps_preview_mesh_free(&d->mesh);
    ps_world_destroy(d->world);
    ps_scene_destroy(d->scene);
}

/* The default scene's fine mesh: its two spheres, one cube each at their
 * centres; every vertex facing the eye gets lookups whose weights add up to
 * at most 1 (clear glass and a perfect mirror inside a box, nothing leaves
 * the scene but through its open front), and lookups traced in pieces equal
 * those traced at once. */
static void default_scene_lookups(void **state)
{
    (void)state;
    default_rig d;
    default_rig_make(&d);
    ps_specular *a = d.a, *b = d.b;
    assert_int_equal(ps_specular_range_count(a), 2);
    assert_int_equal(ps_specular_cube_count(a), 2);
    ps_vec3 c0 = ps_specular_cube_centre(a, 0), c1 = ps_specular_cube_centre(a, 1);
    assert_true(ps_v3_len(ps_v3_sub(c0, ps_v3(0.35, 0.4, 0.2))) < 1e-3);
    assert_true(ps_v3_len(ps_v3_sub(c1, ps_v3(-0.45, 0.35, -0.4))) < 1e-3);
    ps_vec3 eye = ps_camera_frame_make(ps_scene_camera(d.scene), 64, 64).eye;
    assert_int_equal(ps_specular_update(a, d.world, eye, 0), 0);
    size_t left = ps_specular_update(b, d.world, eye, 1000), calls = 1;
    while (left > 0) {
        size_t before = left;
        left = ps_specular_update(b, d.world, eye, 1000);
        assert_true(left < before);
        calls++;
    }
    assert_true(calls > 2);
    const ps_specular_range *R = ps_specular_ranges(a);
    size_t n = R[1].offset + d.mesh.ranges[R[1].range].count, facing = 0;
    for (int k = 0; k < PS_SPECULAR_TERMS; k++) {
        assert_memory_equal(ps_specular_dirs(a, k), ps_specular_dirs(b, k), 3 * n * sizeof(float));
        assert_memory_equal(ps_specular_weights(a, k), ps_specular_weights(b, k), 3 * n * sizeof(float));
    }
    for (size_t i = 0; i < 2; i++) {
        const ps_mesh_range *rg = &d.mesh.ranges[R[i].range];
        for (size_t v = 0; v < rg->count; v++) {
            const float *p = d.mesh.positions + 3 * (rg->first + v), *nn = d.mesh.normals + 3 * (rg->first + v);
            ps_vec3 to_eye = ps_v3_sub(eye, ps_v3(p[0], p[1], p[2]));
            if (ps_v3_dot(to_eye, ps_v3(nn[0], nn[1], nn[2])) <= 0.0)
                continue;
            facing++;
            double sum = 0.0;
            for (int k = 0; k < PS_SPECULAR_TERMS; k++)
                sum += ps_specular_weights(a, k)[3 * (R[i].offset + v)];
            assert_true(sum > 0.5 && sum <= 1.0 + 1e-6);
        }
    }
    assert_true(facing > 1000);
    default_rig_free(&d);
}

/* The default scene's mirror sphere (cube 0) looked up from another centre,
 * as after an edit moved it, until its new map is shown: its lookups and
 * per-pixel points are re-aimed, nothing traced again (the points stay
 * ready), and then equal, byte for byte, those traced afresh from the
 * cube's own centre; the per-pixel points are the same bytes on 1 and 3
 * threads. */
static void reaimed_lookups_equal_fresh_ones(void **state)
{
    (void)state;
    default_rig d;
    default_rig_make(&d);
    ps_specular *moved = d.a, *fresh = d.b;
    ps_specular_set_threads(fresh, 3);
    ps_vec3 centre = ps_specular_cube_centre(moved, 0), old = ps_v3_add(centre, ps_v3(-0.1, 0.0, 0.0));
    assert_true(ps_specular_set_lookup_centre(moved, 0, old));
    assert_false(ps_specular_set_lookup_centre(moved, 0, old));
    ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(d.scene), 96, 96);
    assert_int_equal(ps_specular_update(moved, d.world, cam.eye, 0), 0);
    assert_int_equal(ps_specular_update(fresh, d.world, cam.eye, 0), 0);
    assert_int_equal(ps_specular_update_pixels(moved, d.world, &cam, 0, 0.0), 0);
    assert_true(ps_specular_pixel_rays_left(fresh, &cam) > 4096);
    size_t left = ps_specular_update_pixels(fresh, d.world, &cam, 4096, 0.0);
    while (left > 0)
        left = ps_specular_update_pixels(fresh, d.world, &cam, 4096, 0.0);
    assert_int_equal(ps_specular_pixel_rays_left(fresh, &cam), 0);
    const ps_specular_range *R = ps_specular_ranges(moved);
    size_t n = R[1].offset + d.mesh.ranges[R[1].range].count;
    /* From the other centre the mirror's lookups differ (the test can fail). */
    assert_memory_not_equal(ps_specular_dirs(moved, 0), ps_specular_dirs(fresh, 0), 3 * n * sizeof(float));
    ps_specular_points pm = ps_specular_pixel_points(moved), pf = ps_specular_pixel_points(fresh);
    assert_int_equal(pm.count, pf.count);
    assert_memory_not_equal(pm.dirs, pf.dirs, 3 * pm.count * sizeof(float));
    (void)ps_specular_take_changed(moved);
    assert_true(ps_specular_set_lookup_centre(moved, 0, centre));
    assert_true(ps_specular_take_changed(moved));
    assert_true(ps_specular_pixel_points(moved).ready);
    for (int k = 0; k < PS_SPECULAR_TERMS; k++) {
        assert_memory_equal(ps_specular_dirs(moved, k), ps_specular_dirs(fresh, k), 3 * n * sizeof(float));
        assert_memory_equal(ps_specular_weights(moved, k), ps_specular_weights(fresh, k), 3 * n * sizeof(float));
    }
    assert_points_equal(ps_specular_pixel_points(moved), ps_specular_pixel_points(fresh), 1000);
    default_rig_free(&d);
}

/* Only pixels near a range's triangles are traced: the same points, byte
 * for byte, as tracing every pixel of each range's box (the ring's box holds
 * 4x the pixels its triangles cover), from the scene's camera, zoomed in on
 * a chord near a silhouette until it spans four view heights, and looking
 * at it from its range's cube centre (triangles behind the eye give their
 * box's whole rectangle); and the scene's view at 32x26, where the spheres
 * and the ring have more than PIXEL_TRIANGLES_MAX (16) triangles a pixel of
 * their boxes and trace the boxes. (It fails when the
 * second half of each range's triangles is left out; it passes with the
 * triangles' rectangles no wider than their corners: none of these views
 * needs their margins.) */
static void pixels_near_triangles_hold_every_point(void **state)
{
    (void)state;
    const char *scenes[] = {"data/scenes/ring-caustic.scn", "data/scenes/cornell-caustic.scn",
                            "data/scenes/design-room.scn"};
    for (int sc = 0; sc < 3; sc++) {
        ps_error err;
        ps_scene *scene;
        ps_world *world;
        ps_preview_mesh mesh;
        assert_int_equal(ps_scene_load(scenes[sc], NULL, &scene, &err), PS_OK);
        assert_int_equal(ps_world_create(scene, NULL, &world, &err), PS_OK);
        ps_mesh_options mo = ps_mesh_default_options(scene);
        assert_int_equal(ps_preview_mesh_build(scene, &mo, &mesh, &err), PS_OK);
        size_t nm;
        ps_specular *near, *boxes;
        assert_int_equal(ps_specular_create(&mesh, ps_scene_materials(scene, &nm), &near, &err), PS_OK);
        assert_int_equal(ps_specular_create(&mesh, ps_scene_materials(scene, &nm), &boxes, &err), PS_OK);
        ps_specular_set_pixel_boxes(boxes, true);
        ps_specular_set_threads(near, 2);
        /* The first mirror or glass range (glossy ones trace no pixel),
         * its triangle seen most nearly edge on: that one's first edge's
         * midpoint, near the silhouette, and length. */
        const ps_material *mats = ps_scene_materials(scene, &nm);
        const ps_specular_range *first = ps_specular_ranges(near);
        while (mats[mesh.ranges[first->range].material].type == PS_MAT_GLOSSY)
            first++;
        const ps_mesh_range *rg = &mesh.ranges[first->range];
        ps_vec3 eye = ps_scene_camera(scene)->eye, edge = eye;
        double best = HUGE_VAL, chord = 0.0;
        for (size_t t = rg->first; t + 2 < rg->first + rg->count; t += 3) {
            ps_vec3 q[3];
            for (int k = 0; k < 3; k++)
                q[k] = ps_v3(mesh.positions[3 * (t + k)], mesh.positions[3 * (t + k) + 1],
                             mesh.positions[3 * (t + k) + 2]);
            ps_vec3 n = ps_v3_norm(ps_v3_cross(ps_v3_sub(q[1], q[0]), ps_v3_sub(q[2], q[0])));
            /* Edge on, its first edge long (not a sliver at a pole). */
            double c = fabs(ps_v3_dot(n, ps_v3_norm(ps_v3_sub(q[0], eye)))) / ps_v3_len(ps_v3_sub(q[1], q[0]));
            if (c < best)
                best = c, edge = ps_v3_scale(ps_v3_add(q[0], q[1]), 0.5), chord = ps_v3_len(ps_v3_sub(q[1], q[0]));
        }
        for (int v = 0; v < 4; v++) {
            ps_camera c = *ps_scene_camera(scene);
            if (v == 1) { /* zoomed in on it, the view a quarter of the chord high */
                c.target = edge;
                c.fov_deg = 2.0 * atan(0.125 * chord / ps_v3_len(ps_v3_sub(edge, eye))) * 180.0 / PS_PI;
            }
            if (v == 2) { /* from the range's cube centre, looking at it */
                c.eye = ps_specular_cube_centre(near, first->cube);
                c.target = edge;
            }
            ps_camera_frame cam = v == 3 ? ps_camera_frame_make(&c, 32, 26) : ps_camera_frame_make(&c, 97, 80);
            for (int k = 0; k < 2; k++) {
                ps_specular *sp = k ? boxes : near;
                assert_int_equal(ps_specular_update(sp, world, cam.eye, 0), 0);
                assert_int_equal(ps_specular_update_pixels(sp, world, &cam, 0, 0.0), 0);
            }
            print_message("%s, camera %d: %zu points\n", scenes[sc], v, ps_specular_pixel_points(near).count);
            assert_points_equal(ps_specular_pixel_points(near), ps_specular_pixel_points(boxes), 100);
        }
        ps_specular_destroy(near);
        ps_specular_destroy(boxes);
        ps_preview_mesh_free(&mesh);
        ps_world_destroy(world);
        ps_scene_destroy(scene);
    }
}

/* The triangles a term lights (ps_specular_weighted_triangles): any corner
 * with any channel above 0 keeps the triangle whole (GL interpolates the
 * weight from it across the triangle), a NaN too (never hidden); all-zero
 * ones are left out; a partial last triangle is ignored. */
static void weighted_triangles(void **state)
{
    (void)state;
    float w[3 * 13];
    memset(w, 0, sizeof w);
    w[3 * 2 + 2] = 0.5f;   /* triangle 0: its last corner's blue */
    w[3 * 6 + 0] = 1e-30f; /* triangle 2: its first corner, a tiny red */
    w[3 * 10 + 1] = NAN;   /* triangle 3: its second corner */
    w[3 * 12] = 1.0f;      /* the 13th vertex: no triangle */
    unsigned idx[13];
    size_t n = ps_specular_weighted_triangles(w, 13, idx);
    const unsigned want[9] = {0, 1, 2, 6, 7, 8, 9, 10, 11};
    assert_int_equal(n, 9);
    assert_memory_equal(idx, want, sizeof want);
    memset(w, 0, sizeof w);
    assert_int_equal(ps_specular_weighted_triangles(w, 12, idx), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(normal_incidence_reflects_4_percent),
        cmocka_unit_test(glass_sphere_keeps_energy),
        cmocka_unit_test(mirror_lookup_is_distance_corrected),
        cmocka_unit_test(default_scene_lookups),
        cmocka_unit_test(reaimed_lookups_equal_fresh_ones),
        cmocka_unit_test(pixels_near_triangles_hold_every_point),
        cmocka_unit_test(weighted_triangles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
