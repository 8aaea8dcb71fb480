/* test_illuminance.c: the reference renderer's illuminance in lux against
 * closed forms in the spirit of CIE 171:2006: a point source of known candela
 * over a plane (E = I cos / d^2), an IES luminaire at points worked out by
 * hand from its table, a Lambertian disc on its axis, a closed room of
 * reflectance rho (E = flux / (S (1 - rho))); direct within 1 %,
 * inter-reflected within 3 %. */
#include "test.h"
#include "render_rig.h"
#include "analytic.h"

#include <stdlib.h>
#include <string.h>

#include "core/photometry.h"
#include "photon/emit.h"
#include "photon/estimate.h"
#include "photon/kdtree.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "render/render.h"
#include "scene/camera.h"
#include "scene/scene.h"


/* The lux image (683 Y of the irradiance) of the options' component. */
static ps_image render_lux(render_rig *r, ps_render_options *o)
{
    o->illuminance = true;
    ps_image img = render(r, o);
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            float *p = ps_image_at(&img, x, y);
            p[0] = p[1] = p[2] = (float)ps_photometric(ps_rgb_make(p[0], p[1], p[2]));
        }
    return img;
}

static double image_mean(const ps_image *img)
{
    double s = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            s += ps_image_at(img, x, y)[0];
    return s / ((double)img->width * img->height);
}

/* A point source of 100 cd at height 1 over a plane: E = I h / d^3 in lux,
 * every pixel within 1 % of its analytic mean, whatever the floor's albedo. */
static void point_candela_on_plane(void **state)
{
    (void)state;
    double albedo[2] = {0.7, 0.1};
    ps_image first = {0};
    for (int a = 0; a < 2; a++) {
        char text[512];
        snprintf(text, sizeof text,
                 "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 50\n"
                 "material floor diffuse albedo %g %g %g\n"
                 "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100 material floor\n"
                 "light point position 0.3 1 -0.2 candela 100 color 1 0.8 0.5\n",
                 albedo[a], albedo[a], albedo[a]);
        ps_estimate_options est = {50, 0.05, PS_KERNEL_BOX};
        render_rig r = render_rig_make(text, 0, 0, &est, false);
        ps_render_options o = options(32, 32, 16, PS_COMPONENT_DIRECT, &est, 0);
        ps_image img = render_lux(&r, &o);
        ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(r.scene), o.width, o.height);
        double worst = 0;
        for (int y = 0; y < o.height; y++)
            for (int x = 0; x < o.width; x++) {
                double expect = 0;
                for (int j = 0; j < 8; j++)
                    for (int i = 0; i < 8; i++) {
                        ps_vec3 p = {0, 0, 0};
                        assert_true(floor_point(&cam, x + (i + 0.5) / 8, y + (j + 0.5) / 8, &p));
                        /* floor_radiance with rho = pi is the irradiance. */
                        expect += floor_radiance(PS_PI, 100.0, 1.0, 0.3, -0.2, p) / 64.0;
                    }
                worst = fmax(worst, fabs(ps_image_at(&img, x, y)[0] - expect) / expect);
            }
        printf("point of 100 cd over a plane (albedo %g): worst pixel %.3f %% off I cos / d^2\n", albedo[a],
               100 * worst);
        assert_true(worst < 0.01);
        if (a == 0) {
            first = img;
        } else {
            /* The illuminance does not depend on the surface's albedo. */
            for (int y = 0; y < o.height; y++)
                for (int x = 0; x < o.width; x++)
                    assert_near(ps_image_at(&img, x, y)[0], ps_image_at(&first, x, y)[0],
                                1e-5 * ps_image_at(&first, x, y)[0]);
            ps_image_destroy(&img);
            ps_image_destroy(&first);
        }
        render_rig_free(&r);
    }
}

/* An IES luminaire 2 m above the floor, aimed down; its table (quadrant
 * symmetric): at 0 30 60 90 degrees, 1000 800 400 0 cd in the 0 plane and
 * 1000 600 200 0 in the 90 plane. At floor points in known directions the
 * candela is worked out by hand (bilinear), E = I cos(theta) / d^2. */
static void ies_at_points(void **state)
{
    (void)state;
    const char *ies = "IESNA:LM-63-2002\n[TEST] test_illuminance\nTILT=NONE\n1 -1 2 4 2 1 2 0 0 0\n1 1 10\n"
                      "0 30 60 90\n0 90\n500 400 200 0\n500 300 100 0\n"; /* multiplier 2 */
    const char *path = test_path("quadrant.ies");
    FILE *f = fopen(path, "wb");
    fputs(ies, f);
    fclose(f);
    const double h = 2.0, deg = PS_PI / 180.0;
    static const struct {
        double theta, phi, candela; /* degrees; by hand */
    } points[] = {
        {30, 0, 800},          /* a table entry */
        {45, 90, 400},         /* between 600 and 200 in the 90 plane */
        {30, 45, 700},         /* between the planes: (800 + 600) / 2 */
        {15, 135, 850},        /* 135 mirrors 45: ((900) + (800)) / 2 */
        {50, 300, 400},        /* 300 mirrors 60 (t = 2/3), 50 is s = 2/3: 0 plane 533.33, 90 plane 333.33 */
    };
    for (size_t k = 0; k < sizeof points / sizeof points[0]; k++) {
        double t = points[k].theta * deg, p = points[k].phi * deg, dist = h * tan(t);
        /* Horizontal angle 0 is +x, 90 is -z (docs/scene-format.md). */
        double px = dist * cos(p), pz = -dist * sin(p);
        char text[2048];
        snprintf(text, sizeof text,
                 "camera eye %.9g 1 %.9g target %.9g 0 %.9g up 1 0 0 fov 0.05\n"
                 "material floor diffuse albedo 0.3 0.3 0.3\n"
                 "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100 material floor\n"
                 "light ies %s position 0 %g 0 color 1 1 1\n",
                 px, pz, px, pz, path, h);
        ps_estimate_options est = {50, 0.05, PS_KERNEL_BOX};
        render_rig r = render_rig_make(text, 0, 0, &est, false);
        ps_render_options o = options(2, 2, 1, PS_COMPONENT_DIRECT, &est, 0);
        ps_image img = render_lux(&r, &o);
        double d2 = h * h + dist * dist, expect = points[k].candela * cos(t) / d2;
        printf("IES at theta %g phi %g: %.4f lx, by hand %.4f lx\n", points[k].theta, points[k].phi,
               image_mean(&img), expect);
        assert_near(image_mean(&img), expect, 0.01 * expect);
        ps_image_destroy(&img);
        render_rig_free(&r);
    }
}

/* Caustic illuminance: a mirror quad 2 m up reflects a 100 cd point at 1 m
 * onto the floor as if from its mirror image at 3 m: E = I h / d^3 with
 * h = 3, the caustic map's irradiance, within 3 % away from the lit
 * square's edges; an IES luminaire aimed up at the mirror the same way, its
 * candela from its table (one whose candela is nearly linear in the angle:
 * the estimate's kernel would fill a batwing's central dip, a bias of the
 * density estimate, not of the light). */
static void caustic_from_mirror(void **state)
{
    (void)state;
    static const char *const lights[2] = {"light point position 0 1 0 candela 100",
                                          "light ies tests/data/ies-good/1986-rotational.ies position 0 1 0 aim 0 1 0 candela 100"};
    for (int k = 0; k < 2; k++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "camera eye 0 1.5 3 target 0 0 0 fov 40\n"
                 "material floor diffuse albedo 0.5 0.5 0.5\n"
                 "material mirror mirror reflectance 1 1 1\n"
                 "quad corner -20 0 20 edge1 40 0 0 edge2 0 0 -40 material floor\n"
                 "quad corner -0.5 2 -0.5 edge1 1 0 0 edge2 0 0 1 material mirror\n%s\n",
                 lights[k]);
        ps_estimate_options est = {400, 0.15, PS_KERNEL_BOX};
        render_rig r = render_rig_make(text, 1000000, 0, &est, false);
        ps_render_options o = options(24, 24, 4, PS_COMPONENT_CAUSTIC, &est, 0);
        ps_image img = render_lux(&r, &o);
        ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(r.scene), o.width, o.height);
        size_t nl;
        const ps_light *L = ps_scene_lights(r.scene, &nl);
        double worst = 0;
        int n = 0;
        for (int y = 0; y < o.height; y++)
            for (int x = 0; x < o.width; x++) {
                ps_vec3 p;
                if (!floor_point(&cam, x + 0.5, y + 0.5, &p) || fabs(p.x) > 1.2 || fabs(p.z) > 1.2)
                    continue;
                /* From the image source at (0, 3, 0): the direction it leaves the real light
                 * is the reflected one, (p - image) with y negated. */
                ps_vec3 from_image = ps_v3_sub(p, ps_v3(0, 3, 0));
                double d = ps_v3_len(from_image), candela = 100.0;
                if (k == 1) {
                    ps_vec3 dir = ps_v3_scale(ps_v3(from_image.x, -from_image.y, from_image.z), 1.0 / d);
                    candela = ps_photometric(L[0].power) * ps_light_ies_density(r.scene, &L[0], dir);
                }
                double expect = candela * 3.0 / (d * d * d);
                if (expect < 1.0)
                    continue; /* outside the beam */
                worst = fmax(worst, fabs(ps_image_at(&img, x, y)[0] - expect) / expect);
                n++;
            }
        printf("caustic illuminance from a mirror (%s): %d pixels, worst %.2f %% off\n", k ? "ies" : "point", n,
               100 * worst);
        assert_true(n > 30);
        assert_true(worst < 0.03);
        ps_image_destroy(&img);
        render_rig_free(&r);
    }
}

/* A Lambertian disc of radius R and flux F at height h, on its axis:
 * E = pi L R^2 / (h^2 + R^2) with L = F / (pi pi R^2), so E = F / (pi (h^2 + R^2)). */
static void disc_on_axis(void **state)
{
    (void)state;
    const char *text = "camera eye 0 0.5 0.0001 target 0 0 0 up 0 0 -1 fov 0.1\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100 material floor\n"
                       "light disc center 0 1 0 normal 0 -1 0 radius 0.3 lumens 1000\n";
    ps_estimate_options est = {50, 0.05, PS_KERNEL_BOX};
    render_rig r = render_rig_make(text, 0, 0, &est, false);
    ps_render_options o = options(8, 8, 16, PS_COMPONENT_DIRECT, &est, 0);
    o.light_samples = 16;
    ps_image img = render_lux(&r, &o);
    double expect = 1000.0 / (PS_PI * (1.0 + 0.09));
    printf("disc on its axis: %.4f lx, closed form %.4f lx\n", image_mean(&img), expect);
    assert_near(image_mean(&img), expect, 0.01 * expect);
    ps_image_destroy(&img);
    render_rig_free(&r);
}

/* A closed room of reflectance rho = 0.5 (a sphere of radius 1) lit by 1000 lm
 * at its centre: the direct illuminance is F / S, all of it F / (S (1 - rho)),
 * with final gathering (through the irradiance cache and without), and
 * the global map seen directly. */
static void closed_room(void **state)
{
    (void)state;
    const char *text = "camera eye 0 0.2 0.3 target 0.3 0 -1 fov 70\n"
                       "material wall diffuse albedo 0.5 0.5 0.5\n"
                       "sphere center 0 0 0 radius 1 material wall\n"
                       "light point position 0 0 0 lumens 1000\n";
    ps_estimate_options est = {200, 0.3, PS_KERNEL_BOX};
    render_rig r = render_rig_make(text, 0, 200000, &est, true);
    double S = 4 * PS_PI, direct = 1000.0 / S, all = 1000.0 / (S * (1 - 0.5));
    ps_render_options o = options(16, 16, 4, PS_COMPONENT_DIRECT, &est, 16);
    ps_image img = render_lux(&r, &o);
    printf("closed room: direct %.3f lx, F / S = %.3f lx\n", image_mean(&img), direct);
    assert_near(image_mean(&img), direct, 0.01 * direct);
    ps_image_destroy(&img);
    int gathers[3] = {16, 16, 0}, spacing[3] = {0, 3, 0};
    for (int g = 0; g < 3; g++) {
        ps_estimate_options e2 = est;
        e2.k = gathers[g] ? est.k : 800;
        o = options(16, 16, 4, PS_COMPONENT_ALL, &e2, gathers[g]);
        o.cache_spacing = spacing[g];
        o.cache_rays = 256;
        img = render_lux(&r, &o);
        printf("closed room, gather %d, cache %d: %.3f lx, F / (S (1 - rho)) = %.3f lx\n", gathers[g], spacing[g],
               image_mean(&img), all);
        assert_near(image_mean(&img), all, 0.03 * all);
        ps_image_destroy(&img);
    }
    render_rig_free(&r);
}

/* A closed cubic room (side 2, S = 24 m^2) of reflectance 0.5 with 1000 lm
 * off its centre: the illuminance averaged over all its surfaces is
 * F / (S (1 - rho)) = 83.33 lx, however unevenly it falls. Six views from the
 * centre, fov 90, each see one wall whole; a pinhole maps a wall parallel to
 * its image plane uniformly onto the pixels, so each wall's mean is its
 * pixels' mean, and the walls are equal. The direct part alone averages F / S. */
static void closed_box_room(void **state)
{
    (void)state;
    static const char *const views[6] = {"1 0 0 up 0 1 0",  "-1 0 0 up 0 1 0", "0 1 0 up 0 0 1",
                                         "0 -1 0 up 0 0 1", "0 0 1 up 0 1 0",  "0 0 -1 up 0 1 0"};
    const char *room = "material wall diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -1 -1 -1 edge1 2 0 0 edge2 0 0 2 material wall\n"
                       "quad corner -1 1 -1 edge1 0 0 2 edge2 2 0 0 material wall\n"
                       "quad corner -1 -1 -1 edge1 0 2 0 edge2 2 0 0 material wall\n"
                       "quad corner -1 -1 1 edge1 2 0 0 edge2 0 2 0 material wall\n"
                       "quad corner -1 -1 -1 edge1 0 0 2 edge2 0 2 0 material wall\n"
                       "quad corner 1 -1 -1 edge1 0 2 0 edge2 0 0 2 material wall\n"
                       "light point position 0.3 0.4 -0.2 lumens 1000\n";
    ps_estimate_options est = {100, 0.3, PS_KERNEL_BOX};
    double direct = 0, all = 0;
    for (int v = 0; v < 6; v++) {
        char text[2048];
        snprintf(text, sizeof text, "camera eye 0 0 0 target %s fov 90\n%s", views[v], room);
        render_rig r = render_rig_make(text, 0, 40000, &est, true);
        ps_render_options o = options(12, 12, 4, PS_COMPONENT_DIRECT, &est, 16);
        ps_image img = render_lux(&r, &o);
        direct += image_mean(&img) / 6;
        ps_image_destroy(&img);
        o = options(12, 12, 4, PS_COMPONENT_ALL, &est, 16);
        o.cache_spacing = 2;
        o.cache_rays = 256;
        img = render_lux(&r, &o);
        all += image_mean(&img) / 6;
        ps_image_destroy(&img);
        render_rig_free(&r);
    }
    double S = 24.0;
    printf("closed box room: direct %.3f lx (F / S = %.3f), all %.3f lx (F / (S (1 - rho)) = %.3f)\n", direct,
           1000.0 / S, all, 1000.0 / (S * 0.5));
    assert_near(direct, 1000.0 / S, 0.01 * 1000.0 / S);
    assert_near(all, 1000.0 / (S * 0.5), 0.03 * 1000.0 / (S * 0.5));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(point_candela_on_plane),
        cmocka_unit_test(ies_at_points),
        cmocka_unit_test(disc_on_axis),
        cmocka_unit_test(caustic_from_mirror),
        cmocka_unit_test(closed_room),
        cmocka_unit_test(closed_box_room),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
