/* test_gl_glossy.c: glossy lobes in the specular layer (gl/gl_specular_blur.h,
 * preview/specular_glossy.h) over OSMesa, float buffers, against closed
 * forms: a glossy sphere in a furnace shows specular (n . v) L, the
 * normalised lobe's energy, for two exponents; a glossy floor shows a lit
 * wall at the mirrored point, blurred by its lobe, times specular (n . v). */
#include "test.h"

#include <GL/osmesa.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_render.h"
#include "gl/gl_specular.h"
#include "photon/world.h"
#include "preview/session.h"
#include "preview/specular_glossy.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "specular_rig.h"

/* A glossy sphere in a furnace (every cube texel radiance 1, the level
 * blurred from them): each pixel shows specular (n . v), the energy of the
 * normalised lobe about the mirror direction (its part below the surface
 * not cut off, specular_glossy.h), within 2 % where n . v > 0.5. */
#define FURNACE_SPECULAR 0.6

static void furnace(double exponent)
{
    char text[512];
    snprintf(text, sizeof text,
             "camera eye 0 0 3 target 0 0 0 up 0 1 0 fov 40\n"
             "material m glossy albedo 0.2 0.2 0.2 specular %g %g %g exponent %g\n"
             "sphere center 0 0 0 radius 0.8 material m\n"
             "light point position 0 3 0 power 1 1 1\n",
             FURNACE_SPECULAR, FURNACE_SPECULAR, FURNACE_SPECULAR, exponent);
    rig r;
    rig_make(&r, load_text(text), 96, 96);
    ps_gl_specular_fill(r.spec, r.session, 1.0f);
    ps_image img = specular_alone(&r, true);
    const ps_world *w = ps_session_world(r.session);
    size_t counted = 0;
    double worst = 0.0;
    for (int y = 0; y < r.h; y++)
        for (int x = 0; x < r.w; x++) {
            ps_ray ray = ps_camera_ray(&r.cam, x + 0.5, y + 0.5);
            ps_surface sp;
            if (!ps_world_intersect(w, ray, INFINITY, &sp))
                continue;
            /* The exact sphere's normal, not the mesh's. */
            ps_vec3 n = ps_v3_norm(sp.p);
            double cos_v = -ps_v3_dot(n, ray.d);
            if (cos_v < 0.5)
                continue;
            double want = FURNACE_SPECULAR * cos_v;
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(ps_image_at(&img, x, y)[c] / want - 1.0));
            counted++;
        }
    print_message("glossy furnace, exponent %g: %zu pixels, worst %.3f %% off specular (n . v)\n", exponent, counted,
                  100.0 * worst);
    assert_true(counted > 2000);
    assert_true(worst < 0.02);
    ps_image_destroy(&img);
    rig_free(&r);
}

static void furnace_glossy_sphere_e20(void **state)
{
    (void)state;
    furnace(20.0);
}

static void furnace_glossy_sphere_e200(void **state)
{
    (void)state;
    furnace(200.0);
}

/* A glossy floor (no albedo) before a diffuse wall at z = -1 lit by a point
 * light, wall radiance albedo / pi * I cos / d^2: each floor pixel against
 * the BRDF's own integral, specular (e + 2) / (2 pi) * integral of cos^e(a)
 * cos(theta) L over the lobe (by quadrature in a and phi; the lobe spans
 * 9.5 degrees at half maximum at e = 200, some 15 cm of the wall, over which
 * its radiance curves by a few per cent): the mean within 2 %, every pixel
 * within 4 %, where the mirror direction meets the wall 0.2 from its edges
 * and LOW_Y above the floor. */
#define WALL_ALBEDO 0.6
#define WALL_POWER 40.0
#define LIGHT_X 0.0
#define LIGHT_Y 0.8
#define LIGHT_Z 0.2
#define FLOOR_SPECULAR 0.5
#define FLOOR_EXPONENT 200.0
/* Mirror rays meeting the wall lower than this see it from the cube's
 * centre (on the floor, 1.5 from the wall) within a lobe's width of the
 * horizon, below which the cube holds nothing (specular_glossy.h). */
#define LOW_Y 0.4
#define LOBE_ALPHA_STEPS 48
#define LOBE_PHI_STEPS 64

static double wall_radiance(ps_vec3 p, ps_vec3 d)
{
    if (!(d.z < 0.0))
        return 0.0;
    ps_vec3 q = ps_v3_add(p, ps_v3_scale(d, (-1.0 - p.z) / d.z));
    if (fabs(q.x) > 2.0 || q.y < 0.0 || q.y > 2.0)
        return 0.0;
    ps_vec3 to_light = ps_v3_sub(ps_v3(LIGHT_X, LIGHT_Y, LIGHT_Z), q);
    double dist = ps_v3_len(to_light);
    return WALL_ALBEDO * PS_INV_PI * (WALL_POWER / (4.0 * PS_PI)) * (to_light.z / dist) / (dist * dist);
}

/* The glossy term's integral at floor point p for mirror direction r (n = +y). */
static double lobe_integral(ps_vec3 p, ps_vec3 r)
{
    /* An orthonormal frame about r. */
    ps_vec3 a = ps_v3_norm(ps_v3_cross(r, ps_v3(1, 0, 0))), b = ps_v3_cross(r, a);
    double amax = acos(pow(1e-5, 1.0 / FLOOR_EXPONENT)), sum = 0.0;
    for (int i = 0; i < LOBE_ALPHA_STEPS; i++) {
        double al = (i + 0.5) / LOBE_ALPHA_STEPS * amax;
        double lobe = pow(cos(al), FLOOR_EXPONENT) * sin(al) * (amax / LOBE_ALPHA_STEPS) * (2.0 * PS_PI / LOBE_PHI_STEPS);
        for (int j = 0; j < LOBE_PHI_STEPS; j++) {
            double ph = (j + 0.5) / LOBE_PHI_STEPS * 2.0 * PS_PI;
            ps_vec3 w = ps_v3_add(ps_v3_scale(r, cos(al)),
                                  ps_v3_add(ps_v3_scale(a, sin(al) * cos(ph)), ps_v3_scale(b, sin(al) * sin(ph))));
            if (w.y > 0.0)
                sum += lobe * w.y * wall_radiance(p, w);
        }
    }
    return FLOOR_SPECULAR * (FLOOR_EXPONENT + 2.0) / (2.0 * PS_PI) * sum;
}

static void glossy_floor_shows_the_wall(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text,
             "camera eye 0 0.5 1.6 target 0 0.25 -1 up 0 1 0 fov 50\n"
             "material floor glossy albedo 0 0 0 specular %g %g %g exponent %g\n"
             "material wall diffuse albedo %g %g %g\n"
             "quad corner -2 0 -1 edge1 0 0 3 edge2 4 0 0 material floor\n"
             "quad corner -2 0 -1 edge1 4 0 0 edge2 0 2 0 material wall\n"
             "light point position %g %g %g power %g %g %g\n",
             FLOOR_SPECULAR, FLOOR_SPECULAR, FLOOR_SPECULAR, FLOOR_EXPONENT, WALL_ALBEDO, WALL_ALBEDO, WALL_ALBEDO, LIGHT_X, LIGHT_Y,
             LIGHT_Z, WALL_POWER, WALL_POWER, WALL_POWER);
    rig r;
    rig_make(&r, load_text(text), 128, 128);
    ps_image img = specular_alone(&r, false);
    const ps_world *w = ps_session_world(r.session);
    size_t counted = 0;
    double worst = 0.0, sum_got = 0.0, sum_want = 0.0, low_got = 0.0, low_want = 0.0;
    size_t low = 0;
    for (int y = 0; y < r.h; y++)
        for (int x = 0; x < r.w; x++) {
            ps_ray ray = ps_camera_ray(&r.cam, x + 0.5, y + 0.5);
            ps_surface sp;
            if (!ps_world_intersect(w, ray, INFINITY, &sp) || sp.object != 0)
                continue;
            ps_vec3 d = ps_v3(ray.d.x, -ray.d.y, ray.d.z); /* the mirror direction */
            if (!(d.z < 0.0))
                continue;
            ps_vec3 q = ps_v3_add(sp.p, ps_v3_scale(d, (-1.0 - sp.p.z) / d.z));
            if (fabs(q.x) > 1.8 || q.y < 0.2 || q.y > 1.8 || sp.p.z > 1.8)
                continue;
            if (q.y < LOW_Y) { /* near the cube centre's horizon: said, not held to 4 % */
                double got = ps_image_at(&img, x, y)[1];
                low_got += got, low_want += lobe_integral(sp.p, d);
                low++;
                continue;
            }
            double want = lobe_integral(sp.p, d);
            double got = ps_image_at(&img, x, y)[1];
            if (getenv("PS_TEST_VERBOSE") && fabs(got / want - 1.0) > 0.04)
                print_message("  %d %d p %.2f %.2f q-dir %.2f %.2f %.2f got %g want %g\n", x, y, sp.p.x, sp.p.z, d.x,
                              d.y, d.z, got, want);
            worst = fmax(worst, fabs(got / want - 1.0));
            sum_got += got, sum_want += want;
            counted++;
        }
    print_message("glossy floor: %zu pixels, mean %.4g against %.4g (%.2f %%), worst %.2f %%; %zu pixels whose "
                  "mirror ray meets the wall below %.1f: mean %.2f %% off\n",
                  counted, sum_got / counted, sum_want / counted, 100.0 * (sum_got / sum_want - 1.0), 100.0 * worst,
                  low, LOW_Y, 100.0 * (low_got / low_want - 1.0));
    assert_true(counted > 1000);
    assert_true(fabs(sum_got / sum_want - 1.0) < 0.02);
    assert_true(worst < 0.04);
    ps_image_destroy(&img);
    rig_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(furnace_glossy_sphere_e20),
        cmocka_unit_test(furnace_glossy_sphere_e200),
        cmocka_unit_test(glossy_floor_shows_the_wall),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
