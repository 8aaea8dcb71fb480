/* test_render.c: the reference renderer against closed-form answers: direct
 * light on a plane, the furnace inside a sphere, the mirror-quad caustic; the
 * components add up to the whole; thread counts never change the image. */
#include "test.h"
#include "analytic.h"

#include <stdlib.h>
#include <string.h>

#include "photon/emit.h"
#include "photon/estimate.h"
#include "photon/kdtree.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "render/render.h"
#include "scene/camera.h"
#include "scene/scene.h"

typedef struct rig {
    ps_scene *scene;
    ps_world *world;
    ps_tracer *tracer, *full_tracer;
    ps_light_sampler *ls;
    ps_photon_map maps[PS_MAP_COUNT], full;
    ps_kdtree *trees[PS_MAP_COUNT], *full_tree, *irr;
} rig;

/* Scene, both maps (and the full map with its irradiance when gathering). */
static rig rig_make(const char *text, uint64_t caustic, uint64_t global, const ps_estimate_options *est, bool gather)
{
    rig r;
    memset(&r, 0, sizeof r);
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &r.scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    assert_int_equal(ps_world_create(r.scene, NULL, &r.world, &err), PS_OK);
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 3;
    assert_int_equal(ps_tracer_create(r.world, &o, &r.tracer, &err), PS_OK);
    assert_int_equal(ps_light_sampler_create(r.scene, &r.ls, &err), PS_OK);
    uint64_t n[PS_MAP_COUNT] = {caustic, global};
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map_init(&r.maps[k], (ps_map_kind)k);
        assert_int_equal(ps_tracer_trace(r.tracer, (ps_map_kind)k, 0, n[k], n[k], &r.maps[k], &err), PS_OK);
        assert_int_equal(ps_kdtree_build(r.maps[k].photons, r.maps[k].count, &r.trees[k], &err), PS_OK);
    }
    ps_photon_map_init(&r.full, PS_MAP_GLOBAL);
    if (gather) {
        o.global_direct = true;
        assert_int_equal(ps_tracer_create(r.world, &o, &r.full_tracer, &err), PS_OK);
        assert_int_equal(ps_tracer_trace(r.full_tracer, PS_MAP_GLOBAL, 0, global, global, &r.full, &err), PS_OK);
        assert_int_equal(ps_kdtree_build(r.full.photons, r.full.count, &r.full_tree, &err), PS_OK);
        assert_int_equal(ps_irradiance_precompute(r.full_tree, est, 4, 2, &r.irr, &err), PS_OK);
    }
    return r;
}

static void rig_free(rig *r)
{
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map_free(&r->maps[k]);
        ps_kdtree_destroy(r->trees[k]);
    }
    ps_photon_map_free(&r->full);
    ps_kdtree_destroy(r->full_tree);
    ps_kdtree_destroy(r->irr);
    ps_light_sampler_destroy(r->ls);
    ps_tracer_destroy(r->full_tracer);
    ps_tracer_destroy(r->tracer);
    ps_world_destroy(r->world);
    ps_scene_destroy(r->scene);
}

static ps_render_options options(int w, int h, int spp, ps_component c, const ps_estimate_options *est, int gather)
{
    ps_render_options o;
    memset(&o, 0, sizeof o);
    o.width = w;
    o.height = h;
    o.spp = spp;
    o.light_samples = 1;
    o.gather = gather;
    o.seed = 5;
    o.threads = 2;
    o.component = c;
    o.caustic = o.global = *est;
    o.irradiance_radius = est->max_radius;
    return o;
}

static ps_image render(rig *r, const ps_render_options *o)
{
    ps_render_maps maps = {r->trees[PS_MAP_CAUSTIC], r->trees[PS_MAP_GLOBAL], r->full_tree, r->irr};
    ps_image img;
    ps_error err;
    ps_render_stats st;
    if (ps_render(r->world, r->ls, &maps, o, &img, &st, &err) != PS_OK)
        fail_msg("render: %s", err.msg);
    assert_true(st.rays > 0);
    return img;
}

static double image_mean(const ps_image *img, int channel)
{
    double s = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            s += ps_image_at(img, x, y)[channel];
    return s / ((double)img->width * img->height);
}

/* Direct light on a diffuse plane from a point light at height h:
 * L = rho / pi * I h / (h^2 + x^2)^(3/2), every pixel within 1 %. */
static void direct_on_plane(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 50\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100 material floor\n"
                       "light point position 0.3 1 -0.2 power 100 100 100\n";
    ps_estimate_options est = {50, 0.05, PS_KERNEL_BOX};
    rig r = rig_make(text, 0, 0, &est, false);
    ps_render_options o = options(48, 48, 16, PS_COMPONENT_DIRECT, &est, 0);
    ps_image img = render(&r, &o);
    ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(r.scene), o.width, o.height);
    double intensity = 100.0 / (4.0 * PS_PI), worst = 0;
    for (int y = 0; y < o.height; y++)
        for (int x = 0; x < o.width; x++) {
            /* The pixel's mean of the analytic value (8 x 8 points). */
            double expect = 0;
            for (int j = 0; j < 8; j++)
                for (int i = 0; i < 8; i++) {
                    ps_vec3 p = {0, 0, 0};
                    assert_true(floor_point(&cam, x + (i + 0.5) / 8, y + (j + 0.5) / 8, &p));
                    expect += floor_radiance(0.5, intensity, 1.0, 0.3, -0.2, p) / 64.0;
                }
            double got = ps_image_at(&img, x, y)[1];
            worst = fmax(worst, fabs(got - expect) / expect);
        }
    printf("direct on a plane: worst pixel %.3f %% off the analytic value\n", 100 * worst);
    assert_true(worst < 0.01);
    ps_image_destroy(&img);
    rig_free(&r);
}

/* A disc light of radius R = 0.3 at height h = 1 over a diffuse floor: on its
 * axis the irradiance is pi L R^2 / (h^2 + R^2) with L = P / (pi * pi R^2),
 * so the floor shows rho / pi times that (within 1 %, sampled shadow rays).
 * Seen from below, the disc itself shows L exactly; from above, its back,
 * nothing. */
static void disc_light(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.001 target 0 0 0 up 0 0 -1 fov 1\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100 material floor\n"
                       "light disc center 0 1 0 normal 0 -1 0 radius 0.3 power 100 100 100\n";
    ps_estimate_options est = {50, 0.05, PS_KERNEL_BOX};
    rig r = rig_make(text, 0, 0, &est, false);
    ps_render_options o = options(8, 8, 16, PS_COMPONENT_ALL, &est, 0);
    o.light_samples = 16;
    ps_image img = render(&r, &o);
    double radius = 0.3, h = 1.0, le = 100.0 / (PS_PI * PS_PI * radius * radius);
    double expect = 0.5 * PS_INV_PI * PS_PI * le * radius * radius / (h * h + radius * radius);
    printf("disc light: floor radiance %.5f, analytic %.5f\n", image_mean(&img, 1), expect);
    assert_near(image_mean(&img, 1), expect, 0.01 * expect);
    ps_image_destroy(&img);
    rig_free(&r);

    /* Looking up at it from 0.5 below: every pixel sees the disc. */
    const char *below = "camera eye 0 0.5 0 target 0 1 0 up 0 0 -1 fov 10\n"
                        "material floor diffuse albedo 0.5 0.5 0.5\n"
                        "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100 material floor\n"
                        "light disc center 0 1 0 normal 0 -1 0 radius 0.3 power 100 100 100\n";
    r = rig_make(below, 0, 0, &est, false);
    for (int c = 0; c < 2; c++) {
        o = options(4, 4, 1, c ? PS_COMPONENT_DIRECT : PS_COMPONENT_INDIRECT, &est, 0);
        img = render(&r, &o);
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 4; x++)
                assert_near(ps_image_at(&img, x, y)[0], c ? le : 0.0, 1e-5 * le);
        ps_image_destroy(&img);
    }
    rig_free(&r);
}

/* Inside a closed sphere of radius 1 and albedo 0.5 with a point light of
 * intensity pi at its centre, the radiance is 1 everywhere: direct 0.5 and
 * indirect 0.5 (L = rho / pi * (E_direct + pi L)). Both ways of getting the
 * indirect term: final gathering and the global map directly. */
static void furnace_sphere(void **state)
{
    (void)state;
    const char *text = "camera eye 0 0.2 0.3 target 0.3 0 -1 fov 70\n"
                       "material wall diffuse albedo 0.5 0.5 0.5\n"
                       "sphere center 0 0 0 radius 1 material wall\n"
                       "light point position 0 0 0 power 39.47841760435743 39.47841760435743 39.47841760435743\n";
    ps_estimate_options est = {200, 0.3, PS_KERNEL_BOX};
    rig r = rig_make(text, 0, 200000, &est, true);
    /* Final gathering, the global map directly, and final gathering through
     * the irradiance cache (a record every 3 pixels). */
    int gathers[3] = {16, 0, 16}, spacing[3] = {0, 0, 3};
    for (int g = 0; g < 3; g++) {
        /* Seen directly, the global map needs more photons per estimate for
         * the same noise as gathering, which averages many lookups. */
        ps_estimate_options direct_est = est;
        direct_est.k = gathers[g] ? est.k : 800;
        ps_render_options o = options(16, 16, 4, PS_COMPONENT_ALL, &direct_est, gathers[g]);
        o.cache_spacing = spacing[g];
        o.cache_rays = 256;
        ps_image img = render(&r, &o);
        double mean = image_mean(&img, 1), lo = INFINITY, hi = 0;
        for (int y = 0; y < img.height; y++)
            for (int x = 0; x < img.width; x++) {
                lo = fmin(lo, ps_image_at(&img, x, y)[1]);
                hi = fmax(hi, ps_image_at(&img, x, y)[1]);
            }
        printf("furnace sphere, gather %d, cache %d: mean radiance %.4f (pixels %.4f .. %.4f), expected 1\n", gathers[g],
               spacing[g], mean, lo, hi);
        assert_near(mean, 1.0, 0.02);
        assert_true(lo > 0.9 && hi < 1.1);
        ps_image_destroy(&img);
    }
    rig_free(&r);
}

/* A small glossy quad (albedo 0, specular 0.5, exponent 4) inside the
 * furnace sphere, seen head-on: the walls send radiance 1 from everywhere, and
 * the normalised Phong lobe reflects all of it at normal incidence, so the
 * quad shows 0.5, all of it `indirect` (the light is behind it). It is small
 * enough that its shadow on the wall changes this by under 0.2 %. */
static void glossy_in_furnace(void **state)
{
    (void)state;
    const char *text = "camera eye 0 0 0.6 target 0 0 0.5 fov 3\n"
                       "material wall diffuse albedo 0.5 0.5 0.5\n"
                       "material gloss glossy albedo 0 0 0 specular 0.5 0.5 0.5 exponent 4\n"
                       "sphere center 0 0 0 radius 1 material wall\n"
                       "quad corner -0.005 -0.005 0.5 edge1 0.01 0 0 edge2 0 0.01 0 material gloss\n"
                       "light point position 0 0 0 power 39.47841760435743 39.47841760435743 39.47841760435743\n";
    ps_estimate_options est = {100, 0.3, PS_KERNEL_BOX};
    rig r = rig_make(text, 0, 200000, &est, true);
    ps_render_options o = options(4, 4, 16, PS_COMPONENT_ALL, &est, 64);
    ps_image img = render(&r, &o);
    printf("glossy quad in the furnace: radiance %.4f, expected 0.5\n", image_mean(&img, 1));
    assert_near(image_mean(&img, 1), 0.5, 0.01);
    ps_image_destroy(&img);
    o.component = PS_COMPONENT_DIRECT;
    img = render(&r, &o);
    assert_true(image_mean(&img, 1) == 0.0);
    ps_image_destroy(&img);
    rig_free(&r);
}

/* The caustic of a mirror quad on the floor: the light of the mirror image of
 * the source (height 3), L = rho / pi * I * 3 / (9 + x^2)^(3/2), within 3 %
 * away from the edges of the lit square. */
static void mirror_caustic_image(void **state)
{
    (void)state;
    const char *text = "camera eye 0 1.5 3 target 0 0 0 fov 40\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "material mirror mirror reflectance 1 1 1\n"
                       "quad corner -20 0 20 edge1 40 0 0 edge2 0 0 -40 material floor\n"
                       "quad corner -0.5 2 -0.5 edge1 1 0 0 edge2 0 0 1 material mirror\n"
                       "light point position 0 1 0 power 100 100 100\n";
    ps_estimate_options est = {400, 0.15, PS_KERNEL_BOX};
    rig r = rig_make(text, 1000000, 0, &est, false);
    ps_render_options o = options(32, 32, 4, PS_COMPONENT_CAUSTIC, &est, 0);
    ps_image img = render(&r, &o);
    ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(r.scene), o.width, o.height);
    double intensity = 100.0 / (4.0 * PS_PI), worst = 0, sum_err = 0;
    int n = 0;
    for (int y = 0; y < o.height; y++)
        for (int x = 0; x < o.width; x++) {
            ps_vec3 p;
            if (!floor_point(&cam, x + 0.5, y + 0.5, &p))
                continue;
            /* Away from the edges of the lit square (half-width 1.5) by more
             * than the search radius, plus a margin. */
            if (fabs(p.x) > 1.2 || fabs(p.z) > 1.2)
                continue;
            double expect = floor_radiance(0.5, intensity, 3.0, 0.0, 0.0, p); /* the mirror image at height 3 */
            double got = ps_image_at(&img, x, y)[1];
            worst = fmax(worst, fabs(got - expect) / expect);
            sum_err += (got - expect) / expect;
            n++;
        }
    printf("mirror caustic: %d pixels, worst %.2f %%, mean %.2f %% off the analytic value\n", n, 100 * worst,
           100 * sum_err / n);
    assert_true(n > 100);
    assert_true(worst < 0.03);
    ps_image_destroy(&img);
    rig_free(&r);
}

/* The four components add up to the whole image, pixel by pixel (each
 * pixel's random numbers are the same in every run), and the image does not
 * depend on the thread count. */
static void components_add_up(void **state)
{
    (void)state;
    /* The default scene with a glossy back wall and an area light. */
    const char *text = "camera eye 0 1 3.4 target 0 1 0 fov 40\n"
                       "material white diffuse albedo 0.75 0.75 0.75\n"
                       "material shiny glossy albedo 0.3 0.3 0.3 specular 0.4 0.4 0.4 exponent 30\n"
                       "material glass dielectric ior 1.5\n"
                       "material mirror mirror reflectance 0.9 0.9 0.9\n"
                       "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                       "quad corner -1 2 -1 edge1 2 0 0 edge2 0 0 2 material white\n"
                       "quad corner -1 0 -1 edge1 2 0 0 edge2 0 2 0 material shiny\n"
                       "quad corner -1 0 -1 edge1 0 2 0 edge2 0 0 2 material white\n"
                       "quad corner 1 0 -1 edge1 0 0 2 edge2 0 2 0 material white\n"
                       "sphere center 0.35 0.4 0.2 radius 0.4 material glass\n"
                       "sphere center -0.45 0.35 -0.4 radius 0.35 material mirror\n"
                       "light quad corner -0.25 1.999 -0.25 edge1 0.5 0 0 edge2 0 0 0.5 power 100 100 100\n";
    ps_estimate_options est = {50, 0.1, PS_KERNEL_CONE};
    rig r = rig_make(text, 20000, 20000, &est, true);
    ps_image parts[PS_COMPONENT_COUNT];
    for (int c = 0; c < PS_COMPONENT_COUNT; c++) {
        ps_render_options o = options(24, 24, 2, (ps_component)c, &est, 4);
        parts[c] = render(&r, &o);
    }
    double worst = 0, total = 0;
    for (int y = 0; y < 24; y++)
        for (int x = 0; x < 24; x++)
            for (int ch = 0; ch < 3; ch++) {
                double all = ps_image_at(&parts[0], x, y)[ch], sum = 0;
                for (int c = 1; c < PS_COMPONENT_COUNT; c++)
                    sum += ps_image_at(&parts[c], x, y)[ch];
                worst = fmax(worst, fabs(all - sum));
                total += all;
            }
    assert_true(total > 0);
    assert_true(worst <= 1e-5 * (total / (24 * 24 * 3)) + 1e-6);
    for (int c = 1; c < PS_COMPONENT_COUNT; c++)
        assert_true(image_mean(&parts[c], 0) > 0); /* every term shows in this scene */
    /* One thread gives the same bytes as two. */
    ps_render_options o1 = options(24, 24, 2, PS_COMPONENT_ALL, &est, 4);
    o1.threads = 1;
    ps_image one = render(&r, &o1);
    assert_memory_equal(one.rgb, parts[0].rgb, sizeof(float) * 3 * 24 * 24);
    ps_image_destroy(&one);
    for (int c = 0; c < PS_COMPONENT_COUNT; c++)
        ps_image_destroy(&parts[c]);
    rig_free(&r);
}

static void camera_matches_projection(void **state)
{
    (void)state;
    ps_camera c = {{0.3, 1.2, 3.4}, {0, 1, 0}, {0, 1, 0}, 40};
    ps_camera_frame f = ps_camera_frame_make(&c, 320, 200);
    for (int k = 0; k < 50; k++) {
        double x = 3.7 * k, y = 1.9 * k;
        ps_ray r = ps_camera_ray(&f, x, y);
        double px, py;
        assert_true(ps_camera_project(&f, ps_ray_at(r, 2.5), &px, &py));
        assert_near(px, x, 1e-9);
        assert_near(py, y, 1e-9);
    }
    /* The centre pixel looks at the target; the top edge is fov/2 above it. */
    ps_ray mid = ps_camera_ray(&f, 160, 100);
    ps_vec3 to = ps_v3_norm(ps_v3_sub(c.target, c.eye));
    assert_near(ps_v3_dot(mid.d, to), 1.0, 1e-12);
    ps_ray top = ps_camera_ray(&f, 160, 0);
    assert_near(acos(ps_v3_dot(top.d, to)) * 180 / PS_PI, 20.0, 1e-9);
}

/* A raised cancel flag stops the render between rows: PS_ERR_INTERRUPTED
 * with the share finished, no image; lowered, the same render completes. */
static void cancelled_render(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 50\n"
                       "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100\n"
                       "light point position 0 1 0 power 100 100 100\n";
    ps_estimate_options est = {50, 0.05, PS_KERNEL_BOX};
    rig r = rig_make(text, 0, 0, &est, false);
    ps_render_options o = options(40, 40, 1, PS_COMPONENT_DIRECT, &est, 0);
    ps_cancel_flag flag = 2; /* as a SIGINT handler leaves it */
    o.cancel = &flag;
    ps_render_maps maps = {r.trees[PS_MAP_CAUSTIC], r.trees[PS_MAP_GLOBAL], NULL, NULL};
    ps_image img;
    ps_render_stats st;
    ps_error err;
    assert_int_equal(ps_render(r.world, r.ls, &maps, &o, &img, &st, &err), PS_ERR_INTERRUPTED);
    assert_null(img.rgb);
    assert_near(st.fraction, 0.0, 0.0);
    assert_string_equal(err.msg, "interrupted after 0 % of the image");
    flag = 0;
    assert_int_equal(ps_render(r.world, r.ls, &maps, &o, &img, &st, &err), PS_OK);
    assert_near(st.fraction, 1.0, 0.0);
    ps_image_destroy(&img);
    rig_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(camera_matches_projection), cmocka_unit_test(direct_on_plane),
        cmocka_unit_test(disc_light),
        cmocka_unit_test(furnace_sphere),
        cmocka_unit_test(glossy_in_furnace),            cmocka_unit_test(mirror_caustic_image),
        cmocka_unit_test(components_add_up),            cmocka_unit_test(cancelled_render),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
