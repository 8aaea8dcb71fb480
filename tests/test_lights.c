/* test_lights.c: the scene's lights as GL point lights (preview/lights.h),
 * GL-free: every light's virtual lights carry its flux (4 pi I for a point, pi I
 * for a cosine emitter, the cone's solid angle times I for a spot), the cube
 * faces a light can reach, the shadow cubes' near planes, and the emitters the
 * eye sees. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "preview/lights.h"
#include "photon/world.h"
#include "preview/mesh.h"
#include "scene/scene.h"

typedef struct lit {
    ps_scene *scene;
    ps_preview_mesh coarse;
    ps_preview_lights lights;
} lit;

static lit lit_make(const char *text)
{
    lit l;
    memset(&l, 0, sizeof l);
    ps_error err;
    if (ps_scene_load_text(text, "lights.scn", "", NULL, &l.scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_mesh_options mo = ps_mesh_default_options(l.scene);
    mo.max_edge = HUGE_VAL;
    if (ps_preview_mesh_build(l.scene, &mo, &l.coarse, &err) != PS_OK)
        fail_msg("mesh: %s", err.msg);
    if (ps_preview_lights_build(l.scene, NULL, &l.coarse, PS_SHADOW_SIZE_DEFAULT, PS_PREVIEW_AREA_SIDE, &l.lights, &err) != PS_OK)
        fail_msg("lights: %s", err.msg);
    return l;
}

static void lit_free(lit *l)
{
    ps_preview_lights_free(&l->lights);
    ps_preview_mesh_free(&l->coarse);
    ps_scene_destroy(l->scene);
}

/* The flux a GL light emits: 4 pi I omnidirectional, pi I as a cosine
 * emitter, 2 pi (1 - cos cutoff) I as a constant cone. */
static double flux(const ps_preview_light *v)
{
    if (v->cutoff_deg >= 180.0)
        return 4.0 * PS_PI * v->intensity.g;
    if (v->exponent == 1.0)
        return PS_PI * v->intensity.g;
    return 2.0 * PS_PI * (1.0 - cos(v->cutoff_deg * PS_PI / 180.0)) * v->intensity.g;
}

#define FLOOR "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
#define CAMERA "camera eye 0 1 4 target 0 1 0 up 0 1 0 fov 40\n"
#define WHITE CAMERA "material white diffuse albedo 0.5 0.5 0.5\n"

static void point_light_is_one_omnidirectional_light(void **state)
{
    (void)state;
    lit l = lit_make(WHITE FLOOR "light point position 0 1.5 0 power 40 40 40\n");
    assert_int_equal(l.lights.count, 1);
    const ps_preview_light *v = &l.lights.lights[0];
    assert_near(v->intensity.g, 40.0 / (4.0 * PS_PI), 1e-12);
    assert_near(flux(v), 40.0, 1e-9);
    assert_int_equal(v->faces, 0x3f);
    /* The floor is 1.5 below: the near plane at half of it. */
    assert_near(v->shadow_near, PS_SHADOW_NEAR_SHARE * 1.5, 1e-6);
    assert_int_equal(l.lights.emitter_count, 0); /* point lights are invisible */
    assert_int_equal(l.lights.shadow_faces, 6);
    lit_free(&l);
}

static void spot_light_reaches_one_face(void **state)
{
    (void)state;
    lit l = lit_make(WHITE FLOOR "light spot position 0 1.5 0 direction 0 -1 0 angle 30 power 10 10 10\n");
    const ps_preview_light *v = &l.lights.lights[0];
    assert_true(ps_preview_light_is_spot(v));
    assert_near(v->intensity.g, 10.0 / (2.0 * PS_PI * (1.0 - cos(PS_PI / 6.0))), 1e-9);
    assert_near(flux(v), 10.0, 1e-9);
    /* 30 degrees about -y: only the -y face (bit 3). A side face's axis is
     * 90 degrees from the spot's, beyond 30 + 54.7 (a face's reach). */
    assert_int_equal(v->faces, 1u << 3);
    lit_free(&l);
}

static void wide_spot_reaches_five_faces(void **state)
{
    (void)state;
    lit l = lit_make(WHITE FLOOR "light spot position 0 1.5 0 direction 0 -1 0 angle 60 power 10 10 10\n");
    /* 60 + 54.7 > 90: the four side faces too, not +y (180 degrees away). */
    assert_int_equal(l.lights.lights[0].faces, 0x3f & ~(1u << 2));
    lit_free(&l);
}

static void area_light_is_sixteen_cosine_emitters(void **state)
{
    (void)state;
    lit l = lit_make(WHITE FLOOR "light quad corner -0.25 1.9 -0.25 edge1 0.5 0 0 edge2 0 0 0.5 power 30 30 30\n");
    assert_int_equal(l.lights.count, PS_PREVIEW_AREA_SAMPLES);
    double total = 0.0;
    for (size_t i = 0; i < l.lights.count; i++) {
        const ps_preview_light *v = &l.lights.lights[i];
        assert_false(ps_preview_light_is_spot(v));
        assert_near(v->exponent, 1.0, 0.0);
        assert_near(v->cutoff_deg, 90.0, 0.0);
        /* edge1 x edge2 = (0.5,0,0) x (0,0,0.5) points down. */
        assert_near(v->dir.y, -1.0, 1e-12);
        /* A stratum's centre: inside the quad, on its plane. */
        assert_near(v->pos.y, 1.9, 1e-12);
        assert_true(fabs(v->pos.x) < 0.25 && fabs(v->pos.z) < 0.25);
        /* A downward cosine emitter lights 5 faces, never +y. */
        assert_int_equal(v->faces, 0x3f & ~(1u << 2));
        total += flux(v);
    }
    assert_near(total, 30.0, 1e-9);
    /* Strata centres: x and z at -0.1875, -0.0625, 0.0625, 0.1875. */
    assert_near(l.lights.lights[0].pos.x, -0.1875, 1e-12);
    assert_near(l.lights.lights[5].pos.z, -0.0625, 1e-12);
    assert_int_equal(l.lights.emitter_count, 1);
    const ps_preview_emitter *e = &l.lights.emitters[0];
    assert_int_equal(e->type, PS_LIGHT_QUAD);
    assert_near(e->radiance.g, 30.0 / (PS_PI * 0.25), 1e-9);
    assert_int_equal(l.lights.shadow_faces, 5 * PS_PREVIEW_AREA_SAMPLES);
    lit_free(&l);
}

/* Fewer strata, the same flux: 1 and 2 x 2 virtual lights (the progressive
 * first pictures) carry the area light's power as the 16 do. */
static void coarser_area_lights_keep_the_flux(void **state)
{
    (void)state;
    ps_scene *scene;
    ps_error err;
    assert_int_equal(ps_scene_load_text(WHITE FLOOR "light quad corner -0.25 1.9 -0.25 edge1 0.5 0 0 edge2 0 0 0.5 "
                                                    "power 30 30 30\n",
                                        "area.scn", "", NULL, &scene, &err),
                     PS_OK);
    ps_preview_mesh coarse;
    ps_mesh_options mo = ps_mesh_default_options(scene);
    assert_int_equal(ps_preview_mesh_build(scene, &mo, &coarse, &err), PS_OK);
    for (int side = 1; side <= PS_PREVIEW_AREA_SIDE; side *= 2) {
        ps_preview_lights l;
        assert_int_equal(ps_preview_lights_build(scene, NULL, &coarse, 0, side, &l, &err), PS_OK);
        assert_int_equal(l.count, (size_t)(side * side));
        double total = 0.0;
        for (size_t i = 0; i < l.count; i++)
            total += flux(&l.lights[i]);
        assert_near(total, 30.0, 1e-9);
        if (side == 1) /* the one stratum's centre: the quad's */
            assert_true(fabs(l.lights[0].pos.x) < 1e-12 && fabs(l.lights[0].pos.z) < 1e-12);
        ps_preview_lights_free(&l);
    }
    ps_preview_mesh_free(&coarse);
    ps_scene_destroy(scene);
}

static void disc_and_sphere_lights(void **state)
{
    (void)state;
    lit l = lit_make(WHITE FLOOR "light disc center 0 1.9 0 normal 0 -1 0 radius 0.2 power 20 20 20\n"
                                 "light sphere center 0.5 1 0 radius 0.1 power 8 8 8\n");
    assert_int_equal(l.lights.count, PS_PREVIEW_AREA_SAMPLES + 1);
    double disc = 0.0;
    for (size_t i = 0; i < PS_PREVIEW_AREA_SAMPLES; i++) {
        const ps_preview_light *v = &l.lights.lights[i];
        assert_int_equal(v->light, 0);
        double r = hypot(v->pos.x, v->pos.z);
        assert_true(r < 0.2);
        disc += flux(v);
    }
    assert_near(disc, 20.0, 1e-9);
    /* Outside it, a Lambertian sphere lights like a point at its centre. */
    const ps_preview_light *s = &l.lights.lights[PS_PREVIEW_AREA_SAMPLES];
    assert_int_equal(s->light, 1);
    assert_near(flux(s), 8.0, 1e-9);
    assert_near(s->pos.x, 0.5, 0.0);
    assert_near(s->shadow_near, PS_SHADOW_NEAR_SHARE * 1.0, 1e-6);
    /* Both are seen: the disc, and the sphere with its tessellation. */
    assert_int_equal(l.lights.emitter_count, 2);
    assert_int_equal(l.lights.emitters[1].type, PS_LIGHT_SPHERE);
    assert_true(l.lights.emitters[1].sphere.triangle_count > 0);
    lit_free(&l);
}

/* With no geometry the near plane falls back to a share of the scene's size. */
static void near_plane_without_geometry(void **state)
{
    (void)state;
    lit l = lit_make(CAMERA "light point position 0 1 0 power 1 1 1\nlight point position 2 1 0 power 1 1 1\n");
    double diag = ps_v3_len(ps_aabb_diag(ps_scene_bounds(l.scene)));
    assert_near(l.lights.lights[0].shadow_near, PS_SHADOW_NEAR_FRACTION * diag, 1e-15);
    assert_true(isinf(ps_preview_mesh_distance(&l.coarse, ps_v3(0, 0, 0))));
    lit_free(&l);
}

/* Near planes from the ray accelerator: the exact sphere's distance, at most
 * its tessellation's (which lies inside it), the same as brute force for flat
 * geometry. */
static void near_plane_from_the_accelerator(void **state)
{
    (void)state;
    lit l = lit_make(WHITE FLOOR "sphere center 0 0.5 0 radius 0.3 material white\n"
                                 "light point position 0 1.5 0 power 1 1 1\n"
                                 "light point position 1.5 0.6 0.9 power 1 1 1\n");
    ps_world *w;
    ps_error err;
    assert_int_equal(ps_world_create(l.scene, NULL, &w, &err), PS_OK);
    ps_preview_lights fast;
    assert_int_equal(ps_preview_lights_build(l.scene, ps_world_accel(w), &l.coarse, 0, PS_PREVIEW_AREA_SIDE, &fast, &err), PS_OK);
    /* Over the sphere: 1.5 - (0.5 + 0.3) = 0.7 to its top. */
    assert_near(fast.lights[0].shadow_near, PS_SHADOW_NEAR_SHARE * 0.7, 1e-9);
    assert_true(fast.lights[0].shadow_near <= l.lights.lights[0].shadow_near + 1e-6); /* float vertices */
    assert_true(l.lights.lights[0].shadow_near - fast.lights[0].shadow_near < 0.01);
    /* Past the floor's edge (x = 1), 0.6 above it: its edge, sqrt(0.5^2 + 0.6^2)
     * away, nearer than the sphere, either way. */
    assert_near(fast.lights[1].shadow_near, PS_SHADOW_NEAR_SHARE * sqrt(0.61), 1e-9);
    assert_near(l.lights.lights[1].shadow_near, PS_SHADOW_NEAR_SHARE * sqrt(0.61), 1e-6);
    ps_preview_lights_free(&fast);
    ps_world_destroy(w);
    lit_free(&l);
}

/* The brute-force distance against hand-worked points of one triangle. */
static void mesh_distance(void **state)
{
    (void)state;
    float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    ps_preview_mesh m;
    memset(&m, 0, sizeof m);
    m.positions = pos;
    m.vertex_count = 3;
    assert_near(ps_preview_mesh_distance(&m, ps_v3(0.2, 0.2, 0.5)), 0.5, 1e-12);  /* over the face */
    assert_near(ps_preview_mesh_distance(&m, ps_v3(-1, 0, 0)), 1.0, 1e-12);       /* past a corner */
    assert_near(ps_preview_mesh_distance(&m, ps_v3(0.5, -2, 0)), 2.0, 1e-12);     /* past an edge */
    assert_near(ps_preview_mesh_distance(&m, ps_v3(1, 1, 0)), sqrt(0.5), 1e-12);  /* past the hypotenuse */
}

/* Shadow maps that would not fit are refused before anything is made. */
static void shadow_maps_planned_against_the_budget(void **state)
{
    (void)state;
    ps_scene *scene;
    ps_error err;
    assert_int_equal(ps_scene_load_text(WHITE FLOOR "light point position 0 1 0 power 1 1 1\n", "big.scn", "", NULL,
                                        &scene, &err),
                     PS_OK);
    ps_preview_mesh coarse;
    ps_mesh_options mo = ps_mesh_default_options(scene);
    assert_int_equal(ps_preview_mesh_build(scene, &mo, &coarse, &err), PS_OK);
    ps_preview_lights l;
    /* Six faces of 2^20 texels a side, 4 bytes each: 2^43 bytes. */
    assert_int_equal(ps_preview_lights_build(scene, NULL, &coarse, 1 << 20, PS_PREVIEW_AREA_SIDE, &l, &err), PS_ERR_LIMIT);
    assert_non_null(strstr(err.msg, "big.scn"));
    assert_non_null(strstr(err.msg, "shadow maps"));
    assert_int_equal(l.count, 0);
    ps_preview_lights_free(&l);
    ps_preview_mesh_free(&coarse);
    ps_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(point_light_is_one_omnidirectional_light),
        cmocka_unit_test(spot_light_reaches_one_face),
        cmocka_unit_test(wide_spot_reaches_five_faces),
        cmocka_unit_test(area_light_is_sixteen_cosine_emitters),
        cmocka_unit_test(coarser_area_lights_keep_the_flux),
        cmocka_unit_test(disc_and_sphere_lights),
        cmocka_unit_test(near_plane_without_geometry),
        cmocka_unit_test(near_plane_from_the_accelerator),
        cmocka_unit_test(mesh_distance),
        cmocka_unit_test(shadow_maps_planned_against_the_budget),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
