/* test_gl_illuminance.c: the preview's illuminance (photosplat-snap
 * --illuminance, the window's false colour) in lux, against closed forms in
 * the spirit of CIE 171:2006: a point source of known candela over a plane,
 * E = I cos(theta) / d^2, whatever the plane's albedo; an IES luminaire the
 * same way from its table. Drawn through the session's illuminance mode into
 * float layers in an 8-bit context, as snap does. */
#include "test.h"
#include "analytic.h"

#include <GL/osmesa.h>
#include <stdlib.h>
#include <string.h>

#include "core/photometry.h"
#include "gl/gl_render.h"
#include "image/falsecolor.h"
#include "preview/session.h"
#include "scene/scene.h"

#define SIDE 48

/* The lux image of a scene's preview in illuminance mode (all layers). */
static float *preview_lux(const char *text, ps_scene **scene_out, ps_camera_frame *cam)
{
    ps_scene *scene;
    ps_error err;
    if (ps_scene_load_text(text, "lux.scn", "", NULL, &scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_session_settings set = ps_session_default_settings(scene);
    set.threads = 2;
    set.float_buffer = false; /* the 8-bit snapshot's session: the mode must not care */
    ps_session *s;
    if (ps_session_create(scene, &set, &s, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    OSMesaContext ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    assert_non_null(ctx);
    uint8_t *buffer = malloc(4 * SIDE * SIDE);
    assert_true(OSMesaMakeCurrent(ctx, buffer, GL_UNSIGNED_BYTE, SIDE, SIDE));
    assert_int_equal(ps_session_set_illuminance(s, true, &err), PS_OK);
    ps_gl_options go = {true, false, 0, false, false, OSMesaGetProcAddress};
    ps_gl_scene gs = ps_gl_scene_of(s);
    assert_true(gs.hide_emitters);
    ps_gl_renderer *gl;
    assert_int_equal(ps_gl_renderer_create(&gs, ps_session_kernel(s), &go, &gl, &err), PS_OK);
    ps_gl_layers *layers;
    assert_int_equal(ps_gl_layers_create(SIDE, SIDE, true, &layers, &err), PS_OK);
    *cam = ps_camera_frame_make(ps_scene_camera(scene), SIDE, SIDE);
    ps_session_frame f;
    assert_int_equal(ps_session_refresh(s, cam, &f, &err), PS_OK);
    assert_near(f.direct_exposure, 1.0, 0.0);
    ps_gl_layers_draw(layers, gl, cam, &f);
    double gains[PS_MAP_COUNT] = {f.map[0].gain, f.map[1].gain};
    ps_image img;
    assert_int_equal(ps_gl_layers_composite(layers, f.direct_gain, gains, &img, &err), PS_OK);
    for (size_t i = 0; i < 3 * (size_t)SIDE * SIDE; i++)
        img.rgb[i] *= (float)PS_PI;
    float *lux = malloc(sizeof(float) * SIDE * SIDE);
    ps_lux_from_irradiance(&img, lux);
    ps_image_destroy(&img);
    ps_gl_layers_destroy(layers);
    ps_gl_renderer_destroy(gl);
    OSMesaDestroyContext(ctx);
    free(buffer);
    ps_session_destroy(s);
    *scene_out = scene;
    return lux;
}

/* A 100 cd point source 1 m over a floor of albedo 0.3 (that it is not 1
 * must not matter), nothing else: E = 100 cos / d^2 lux, within 2 %. */
static void point_source_over_a_plane(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 50\n"
                       "material floor diffuse albedo 0.3 0.3 0.3\n"
                       "quad corner -2 0 2 edge1 4 0 0 edge2 0 0 -4 material floor\n"
                       "light point position 0.3 1 -0.2 candela 100\n"
                       "photons caustic 0 global 20000\n";
    ps_scene *scene;
    ps_camera_frame cam;
    float *lux = preview_lux(text, &scene, &cam);
    double worst = 0.0;
    int n = 0;
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            ps_vec3 q;
            if (!floor_point(&cam, x + 0.5, y + 0.5, &q) || fabs(q.x) > 1.9 || fabs(q.z) > 1.9)
                continue;
            double dx = q.x - 0.3, dz = q.z + 0.2, d2 = 1.0 + dx * dx + dz * dz;
            double expect = 100.0 / d2 * (1.0 / sqrt(d2));
            worst = fmax(worst, fabs(lux[y * SIDE + x] - expect) / expect);
            n++;
        }
    printf("point source, 100 cd: %d pixels, worst %.3f %% off E = I cos / d^2\n", n, 100 * worst);
    assert_true(n > 1000);
    assert_true(worst < 0.02);
    free(lux);
    ps_scene_destroy(scene);
}

/* The bundled batwing at 1200 lm over the same floor: E = I(w) cos / d^2
 * with I from the file's table rescaled to the lumens, within 2 % (away from
 * its nadir, where the synthetic table is not single-valued). */
static void ies_luminaire_over_a_plane(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 50\n"
                       "material floor diffuse albedo 0.7 0.7 0.7\n"
                       "quad corner -2 0 2 edge1 4 0 0 edge2 0 0 -4 material floor\n"
                       "light ies data/ies/batwing.ies position 0 1 0 lumens 1200\n"
                       "photons caustic 0 global 0\n";
    ps_scene *scene;
    ps_camera_frame cam;
    float *lux = preview_lux(text, &scene, &cam);
    size_t nl;
    const ps_light *L = &ps_scene_lights(scene, &nl)[0];
    double worst = 0.0;
    int n = 0;
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            ps_vec3 q;
            if (!floor_point(&cam, x + 0.5, y + 0.5, &q) || fabs(q.x) > 1.9 || fabs(q.z) > 1.9)
                continue;
            ps_vec3 to = ps_v3_sub(q, L->position);
            double d2 = ps_v3_len2(to);
            ps_vec3 w = ps_v3_scale(to, 1.0 / sqrt(d2));
            if (-w.y > cos(10.0 * PS_PI / 180.0))
                continue;
            /* 1200 lm spread as the table: I = 1200 * density candela. */
            double expect = 1200.0 * ps_light_ies_density(scene, L, w) * -w.y / d2;
            worst = fmax(worst, fabs(lux[y * SIDE + x] - expect) / expect);
            n++;
        }
    printf("IES batwing, 1200 lm: %d pixels, worst %.3f %% off its table's I cos / d^2\n", n, 100 * worst);
    assert_true(n > 1000);
    assert_true(worst < 0.02);
    free(lux);
    ps_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(point_source_over_a_plane),
        cmocka_unit_test(ies_luminaire_over_a_plane),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
