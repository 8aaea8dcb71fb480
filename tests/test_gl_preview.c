/* test_gl_preview.c: the OpenGL preview (src/gl under OSMesa) against closed
 * forms and the reference renderer: the direct layer of a finely tessellated
 * plane under a point light, and the caustic layer of a mirror quad. Float
 * colour buffers, so that what is measured is the method, not 8-bit rounding
 * (the command-line tests cover that). */
#include "test.h"
#include "analytic.h"

#include <GL/osmesa.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_render.h"
#include "photon/estimate.h"
#include "photon/kdtree.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "preview/mesh.h"
#include "preview/splat.h"
#include "render/render.h"
#include "scene/camera.h"
#include "scene/scene.h"

typedef struct preview {
    ps_scene *scene;
    ps_world *world;
    ps_tracer *tracer;
    ps_preview_mesh mesh, coarse;
    ps_preview_lights lights;
    ps_kernel_texture kernel;
    OSMesaContext ctx;
    float *buffer;
    ps_gl_renderer *gl;
    ps_camera_frame cam;
    int w, h;
} preview;

/* Fills *out in place: the renderer keeps a pointer to the mesh inside it. */
static void preview_make(preview *out, const char *text, int w, int h, ps_kernel kernel)
{
    preview *pp = out, p;
    memset(&p, 0, sizeof p);
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &p.scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    assert_int_equal(ps_world_create(p.scene, NULL, &p.world, &err), PS_OK);
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 11;
    assert_int_equal(ps_tracer_create(p.world, &o, &p.tracer, &err), PS_OK);
    ps_mesh_options mo = ps_mesh_default_options(p.scene);
    assert_int_equal(ps_preview_mesh_build(p.scene, &mo, &p.mesh, &err), PS_OK);
    mo.max_edge = HUGE_VAL;
    assert_int_equal(ps_preview_mesh_build(p.scene, &mo, &p.coarse, &err), PS_OK);
    assert_int_equal(ps_kernel_texture_make(kernel, PS_KERNEL_TEXTURE_SIZE, &p.kernel, &err), PS_OK);
    p.w = w;
    p.h = h;
    p.ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    assert_non_null(p.ctx);
    p.buffer = malloc(sizeof(float) * 4 * (size_t)w * (size_t)h);
    assert_true(OSMesaMakeCurrent(p.ctx, p.buffer, GL_FLOAT, w, h));
    ps_gl_options go = {true, true, 0, false, false, OSMesaGetProcAddress};
    *pp = p;
    assert_int_equal(ps_preview_lights_build(pp->scene, NULL, &pp->coarse, PS_GL_SHADOW_SIZE, PS_PREVIEW_AREA_SIDE, &pp->lights, &err), PS_OK);
    size_t nmat;
    ps_gl_scene gs = {&pp->mesh, &pp->coarse, ps_scene_materials(pp->scene, &nmat), &pp->lights, ps_scene_bounds(pp->scene),
                      false, pp->scene, NULL, false};
    assert_int_equal(ps_gl_renderer_create(&gs, &pp->kernel, &go, &pp->gl, &err), PS_OK);
    pp->cam = ps_camera_frame_make(ps_scene_camera(pp->scene), w, h);
}

static void preview_free(preview *p)
{
    ps_gl_renderer_destroy(p->gl);
    OSMesaDestroyContext(p->ctx);
    free(p->buffer);
    ps_kernel_texture_free(&p->kernel);
    ps_preview_mesh_free(&p->mesh);
    ps_preview_mesh_free(&p->coarse);
    ps_preview_lights_free(&p->lights);
    ps_tracer_destroy(p->tracer);
    ps_world_destroy(p->world);
    ps_scene_destroy(p->scene);
}

static ps_image read_back(preview *p)
{
    ps_image img;
    ps_error err;
    assert_int_equal(ps_gl_read(p->gl, &img, &err), PS_OK);
    return img;
}

/* The reference renderer's picture of one component. */
static ps_image reference(preview *p, ps_component c, const ps_kdtree *caustic, double radius, int spp)
{
    ps_light_sampler *ls;
    ps_error err;
    assert_int_equal(ps_light_sampler_create(p->scene, &ls, &err), PS_OK);
    ps_render_maps maps = {caustic, NULL, NULL, NULL};
    ps_render_options o;
    memset(&o, 0, sizeof o);
    o.width = p->w;
    o.height = p->h;
    o.spp = spp;
    o.light_samples = 1;
    o.seed = 1;
    o.threads = 2;
    o.component = c;
    o.caustic.k = 400;
    o.caustic.max_radius = radius;
    o.caustic.kernel = PS_KERNEL_BOX;
    o.global = o.caustic;
    ps_image img;
    ps_render_stats st;
    assert_int_equal(ps_render(p->world, ls, &maps, &o, &img, &st, &err), PS_OK);
    ps_light_sampler_destroy(ls);
    return img;
}

/* A spot straight down at height 1 over the plane, half-angle 25 degrees:
 * inside the cone rho / pi * I h / (h^2 + r^2)^(3/2) with I = power / (2 pi
 * (1 - cos 25)), outside exactly 0, and the edge where the cone meets the
 * plane to within a pixel (the cone texture), not a mesh edge (GL's
 * per-vertex cutoff, which lit or darkened whole mesh triangles there). */
static void spot_cone_on_plane(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 50\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -2 0 2 edge1 4 0 0 edge2 0 0 -4 material floor\n"
                       "light spot position 0.1 1 -0.1 direction 0 -1 0 angle 25 power 100 100 100\n";
    preview p;
    preview_make(&p, text, 128, 128, PS_KERNEL_BOX);
    const double exposure = 0.25, cutoff = tan(25.0 * PS_PI / 180.0);
    ps_gl_begin_frame(p.gl, &p.cam, exposure, true);
    ps_image img = read_back(&p);
    double intensity = 100.0 / (2.0 * PS_PI * (1.0 - cos(25.0 * PS_PI / 180.0))), worst = 0, brightest_out = 0;
    /* A pixel's footprint on the floor: 2 * 3 tan(25 deg) / 128 wide; the
     * edge may fall anywhere in the pixels it crosses. */
    const double pixel = 2.0 * 3.0 * tan(25.0 * PS_PI / 180.0) / 128.0;
    int inside = 0, outside = 0;
    for (int y = 0; y < p.h; y++)
        for (int x = 0; x < p.w; x++) {
            ps_vec3 q;
            if (!floor_point(&p.cam, x + 0.5, y + 0.5, &q))
                continue;
            double r = hypot(q.x - 0.1, q.z + 0.1);
            double got = ps_image_at(&img, x, y)[1] / exposure;
            if (r < cutoff - pixel) {
                double expect = floor_radiance(0.5, intensity, 1.0, 0.1, -0.1, q);
                worst = fmax(worst, fabs(got - expect) / expect);
                inside++;
            } else if (r > cutoff + pixel) {
                brightest_out = fmax(brightest_out, got);
                outside++;
            }
        }
    printf("spot cone: %d pixels inside, worst %.3f %% off; %d outside, brightest %g\n", inside, 100 * worst, outside,
           brightest_out);
    assert_true(inside > 500 && outside > 500);
    assert_true(worst < 0.02);
    assert_true(brightest_out == 0.0);
    ps_image_destroy(&img);
    preview_free(&p);
}

/* A point light at height 1 over a diffuse plane: GL lights in physical units
 * give rho / pi * I h / (h^2 + x^2)^(3/2) at every pixel centre (within 2 %:
 * Gouraud interpolation over the fine mesh), and the reference renderer's
 * `direct` component agrees within 2 % too. The exposure scales all of it. */
static void direct_layer_on_plane(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 50\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -2 0 2 edge1 4 0 0 edge2 0 0 -4 material floor\n"
                       "light point position 0.3 1 -0.2 power 100 100 100\n";
    preview p;
    preview_make(&p, text, 48, 48, PS_KERNEL_BOX);
    const double exposure = 0.25;
    ps_gl_begin_frame(p.gl, &p.cam, exposure, true);
    ps_image img = read_back(&p);
    ps_image ref = reference(&p, PS_COMPONENT_DIRECT, NULL, 0.1, 16);
    double intensity = 100.0 / (4.0 * PS_PI), worst = 0, worst_ref = 0;
    int n = 0;
    for (int y = 0; y < p.h; y++)
        for (int x = 0; x < p.w; x++) {
            ps_vec3 q;
            if (!floor_point(&p.cam, x + 0.5, y + 0.5, &q) || fabs(q.x) > 1.9 || fabs(q.z) > 1.9)
                continue;
            double expect = floor_radiance(0.5, intensity, 1.0, 0.3, -0.2, q);
            double got = ps_image_at(&img, x, y)[1] / exposure;
            worst = fmax(worst, fabs(got - expect) / expect);
            double r = ps_image_at(&ref, x, y)[1];
            worst_ref = fmax(worst_ref, fabs(got - r) / r);
            n++;
        }
    printf("direct layer: %d pixels, worst %.3f %% off the analytic value, %.3f %% off photosplat-ref\n", n,
           100 * worst, 100 * worst_ref);
    assert_true(n > 1000);
    assert_true(worst < 0.02);
    assert_true(worst_ref < 0.02);
    ps_gl_stats gs = ps_gl_get_stats(p.gl);
    assert_int_equal(gs.virtual_lights, 1);
    assert_int_equal(gs.shadow_maps, 6); /* a point light: the whole cube */
    ps_image_destroy(&ref);
    ps_image_destroy(&img);
    preview_free(&p);
}

/* An IES luminaire (the bundled batwing, quadrant-symmetric, TILT=INCLUDE)
 * 1 m over a floor, drawn by its cube table per pixel: the direct layer
 * within 2 % of albedo / pi * P d(w) cos / r^2 and of photosplat-ref, with
 * the shadow cube only where the table lights (the batwing lights no
 * direction above its horizon: 5 faces). */
#define NADIR_DEG 10.0
static void ies_light_on_plane(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 50\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -2 0 2 edge1 4 0 0 edge2 0 0 -4 material floor\n"
                       "light ies data/ies/batwing.ies position 0.2 1 -0.1 spin 20\n";
    preview p;
    preview_make(&p, text, 48, 48, PS_KERNEL_BOX);
    const double exposure = 0.5;
    ps_gl_begin_frame(p.gl, &p.cam, exposure, true);
    ps_image img = read_back(&p);
    ps_image ref = reference(&p, PS_COMPONENT_DIRECT, NULL, 0.1, 16);
    size_t nl;
    const ps_light *L = &ps_scene_lights(p.scene, &nl)[0];
    double worst = 0, worst_ref = 0;
    int n = 0;
    for (int y = 0; y < p.h; y++)
        for (int x = 0; x < p.w; x++) {
            ps_vec3 q;
            if (!floor_point(&p.cam, x + 0.5, y + 0.5, &q) || fabs(q.x) > 1.9 || fabs(q.z) > 1.9)
                continue;
            ps_vec3 to = ps_v3_sub(q, L->position);
            double d2 = ps_v3_len2(to);
            ps_vec3 w = ps_v3_scale(to, 1.0 / sqrt(d2));
            /* The synthetic batwing's table is not single-valued at its
             * nadir (its theta = 0 row varies with phi), so no table at a
             * finite resolution follows it there: left out. */
            if (-w.y > cos(NADIR_DEG * PS_PI / 180.0))
                continue;
            double expect = 0.5 * PS_INV_PI * L->power.g * ps_light_ies_density(p.scene, L, w) * -w.y / d2;
            double got = ps_image_at(&img, x, y)[1] / exposure;
            double r = ps_image_at(&ref, x, y)[1];
            worst = fmax(worst, fabs(got - expect) / expect);
            worst_ref = fmax(worst_ref, fabs(got - r) / r);
            n++;
        }
    printf("IES light: %d pixels, worst %.3f %% off the table's value, %.3f %% off photosplat-ref\n", n, 100 * worst,
           100 * worst_ref);
    assert_true(n > 1000);
    assert_true(worst < 0.02);
    assert_true(worst_ref < 0.02);
    ps_gl_stats gs = ps_gl_get_stats(p.gl);
    assert_int_equal(gs.shadow_maps, 5);
    ps_image_destroy(&ref);
    ps_image_destroy(&img);
    preview_free(&p);
}

/* Shadow maps: a 0.2 m square at half the light's height shades a 0.4 m
 * square of the floor. Seen from above, the square itself hides the floor
 * within 0.12 of the centre; between 0.13 and 0.18 the floor is seen and in
 * shadow (black in the direct layer: the depth compare is per pixel), and
 * beyond 0.25 it is lit as if the square were not there. */
static void shadow_of_a_square(void **state)
{
    (void)state;
    const char *text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 40\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -2 0 2 edge1 4 0 0 edge2 0 0 -4 material floor\n"
                       "quad corner -0.1 0.5 -0.1 edge1 0.2 0 0 edge2 0 0 0.2 material floor\n"
                       "light point position 0 1 0 power 100 100 100\n";
    preview p;
    preview_make(&p, text, 96, 96, PS_KERNEL_BOX);
    ps_gl_begin_frame(p.gl, &p.cam, 1.0, true);
    ps_image img = read_back(&p);
    double intensity = 100.0 / (4.0 * PS_PI), worst_lit = 0, brightest_shadow = 0;
    int lit = 0, dark = 0;
    for (int y = 0; y < p.h; y++)
        for (int x = 0; x < p.w; x++) {
            ps_vec3 q;
            if (!floor_point(&p.cam, x + 0.5, y + 0.5, &q))
                continue;
            double m = fmax(fabs(q.x), fabs(q.z)), got = ps_image_at(&img, x, y)[1];
            double expect = floor_radiance(0.5, intensity, 1.0, 0.0, 0.0, q);
            if (m > 0.13 && m < 0.18) {
                brightest_shadow = fmax(brightest_shadow, got);
                dark++;
            } else if (m > 0.25 && m < 1.0) {
                worst_lit = fmax(worst_lit, fabs(got - expect) / expect);
                lit++;
            }
        }
    printf("shadow: %d lit pixels within %.3f %% of the unshadowed value; %d shadowed pixels, brightest %.4g\n", lit,
           100 * worst_lit, dark, brightest_shadow);
    assert_true(lit > 500 && dark > 20);
    assert_true(worst_lit < 0.02);
    assert_true(brightest_shadow == 0.0);
    ps_image_destroy(&img);
    preview_free(&p);
}

/* The caustic of a mirror quad: light at height 1, mirror 1 above it, so the
 * floor sees the mirror image of the source at height 3 (reflectance 1):
 * L = rho / pi * I * 3 / (9 + x^2)^(3/2). Triangle splats of the caustic map
 * within 5 % of it away from the lit square's edges, and within 5 % of the
 * reference renderer's `caustic` component, for two kernels. */
static void caustic_layer_mirror_quad(void **state)
{
    (void)state;
    const char *text = "camera eye 0 1.5 3 target 0 0 0 fov 40\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "material mirror mirror reflectance 1 1 1\n"
                       "quad corner -20 0 20 edge1 40 0 0 edge2 0 0 -40 material floor\n"
                       "quad corner -0.5 2 -0.5 edge1 1 0 0 edge2 0 0 1 material mirror\n"
                       "light point position 0 1 0 power 100 100 100\n";
    const uint64_t photons = 400000;
    const double radius = 0.15, exposure = 2.0;
    ps_kernel kernels[2] = {PS_KERNEL_BOX, PS_KERNEL_EPANECHNIKOV};
    for (int kk = 0; kk < 2; kk++) {
        preview p;
        preview_make(&p, text, 40, 40, kernels[kk]);
        ps_photon_map m;
        ps_photon_map_init(&m, PS_MAP_CAUSTIC);
        ps_error err;
        assert_int_equal(ps_tracer_trace(p.tracer, PS_MAP_CAUSTIC, 0, photons, photons, &m, &err), PS_OK);
        size_t nmat;
        ps_splat_params sp;
        memset(&sp, 0, sizeof sp);
        sp.mode = PS_SPLAT_TRIANGLES;
        sp.radius = radius;
        sp.kernel_mean = p.kernel.mean;
        sp.kernel_extent = p.kernel.extent;
        sp.scale = exposure;
        sp.precision = PS_PRECISION_NONE;
        sp.materials = ps_scene_materials(p.scene, &nmat);
        sp.cam = p.cam;
        ps_splat_batch b;
        ps_splat_batch_init(&b);
        assert_int_equal(ps_splat_build(m.photons, m.materials, m.count, &sp, &b, &err), PS_OK);
        ps_gl_begin_frame(p.gl, &p.cam, exposure, false);
        ps_gl_draw_splats(p.gl, &b, PS_SPLAT_TRIANGLES, radius, 1.0);
        ps_image img = read_back(&p);
        ps_kdtree *tree;
        assert_int_equal(ps_kdtree_build(m.photons, m.count, &tree, &err), PS_OK);
        ps_image ref = reference(&p, PS_COMPONENT_CAUSTIC, tree, radius, 4);
        double intensity = 100.0 / (4.0 * PS_PI), worst = 0, sum = 0, sum_ref = 0;
        int n = 0;
        for (int y = 0; y < p.h; y++)
            for (int x = 0; x < p.w; x++) {
                ps_vec3 q;
                if (!floor_point(&p.cam, x + 0.5, y + 0.5, &q) || fabs(q.x) > 1.2 || fabs(q.z) > 1.2)
                    continue;
                double expect = floor_radiance(0.5, intensity, 3.0, 0.0, 0.0, q); /* the mirror image at height 3 */
                double got = ps_image_at(&img, x, y)[1] / exposure;
                worst = fmax(worst, fabs(got - expect) / expect);
                sum += got / expect;
                sum_ref += got / ps_image_at(&ref, x, y)[1];
                n++;
            }
        printf("caustic layer (%s kernel): %d pixels, worst %.2f %% off the analytic value; mean ratio to it %.4f, "
               "to photosplat-ref %.4f\n",
               ps_kernel_name(kernels[kk]), n, 100 * worst, sum / n, sum_ref / n);
        assert_true(n > 100);
        assert_true(worst < 0.05);
        assert_near(sum_ref / n, 1.0, 0.05);
        ps_kdtree_destroy(tree);
        ps_image_destroy(&ref);
        ps_image_destroy(&img);
        ps_splat_batch_free(&b);
        ps_photon_map_free(&m);
        preview_free(&p);
    }
}

/* Photon haze (thesis 5.2): photons near a sphere's silhouette, whose flat
 * splats reach past its outline onto the floor behind. Clipped by the
 * stencil buffer to the sphere's own pixels, nothing of them shows on the
 * floor; unclipped, their haze does. Either way the sphere shows them. */
static void stencil_clips_haze(void **state)
{
    (void)state;
    const char *text = "camera eye 0 1 4 target 0 0.5 0 fov 30\n"
                       "material white diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -5 0 5 edge1 10 0 0 edge2 0 0 -10 material white\n"
                       "sphere center 0 0.6 0 radius 0.5 material white\n"
                       "light point position 0 3 2 power 10 10 10\n";
    preview p;
    preview_make(&p, text, 64, 64, PS_KERNEL_BOX);
    /* 64 photons around the sphere's outline as the eye sees it, on its
     * surface and facing the eye a little (70-80 degrees from the view ray). */
    ps_photon ph[64];
    uint16_t mats[64];
    uint32_t objs[64];
    for (int i = 0; i < 64; i++) {
        double a = 2.0 * PS_PI * i / 64.0, tilt = 0.25;
        ps_vec3 view = ps_v3_norm(ps_v3_sub(p.cam.eye, ps_v3(0, 0.6, 0)));
        ps_vec3 side = ps_v3_add(ps_v3_scale(p.cam.right, cos(a)), ps_v3_scale(p.cam.up, sin(a)));
        ps_vec3 n = ps_v3_norm(ps_v3_add(side, ps_v3_scale(view, tilt)));
        ps_vec3 pos = ps_v3_add(ps_v3(0, 0.6, 0), ps_v3_scale(n, 0.5));
        ph[i] = ps_photon_pack(pos, ps_rgb_gray(1.0), ps_v3_neg(n), n, 0.5);
        mats[i] = 0;
        objs[i] = 1;
    }
    int floor_lit[2];
    for (int clip = 0; clip < 2; clip++) {
        size_t nmat;
        ps_splat_params sp;
        memset(&sp, 0, sizeof sp);
        sp.mode = PS_SPLAT_TRIANGLES;
        sp.radius = 0.1;
        sp.kernel_mean = p.kernel.mean;
        sp.kernel_extent = p.kernel.extent;
        sp.scale = 1.0;
        sp.materials = ps_scene_materials(p.scene, &nmat);
        sp.objects = clip ? objs : NULL;
        sp.cam = p.cam;
        ps_splat_batch b;
        ps_splat_batch_init(&b);
        ps_error err;
        assert_int_equal(ps_splat_build(ph, mats, 64, &sp, &b, &err), PS_OK);
        assert_int_equal(b.splats, 64);
        ps_gl_begin_frame(p.gl, &p.cam, 1.0, false);
        ps_gl_draw_splats(p.gl, &b, PS_SPLAT_TRIANGLES, sp.radius, 1.0);
        ps_image img = read_back(&p);
        /* Pixels whose ray misses the sphere see the floor (or nothing). */
        int floor = 0, sphere = 0;
        for (int y = 0; y < p.h; y++)
            for (int x = 0; x < p.w; x++) {
                ps_ray r = ps_camera_ray(&p.cam, x + 0.5, y + 0.5);
                ps_vec3 oc = ps_v3_sub(r.o, ps_v3(0, 0.6, 0));
                double bb = ps_v3_dot(oc, r.d), c = ps_v3_len2(oc) - 0.25;
                bool on_sphere = bb * bb - c > 0.0;
                bool lit = ps_image_at(&img, x, y)[1] > 0.0f;
                floor += lit && !on_sphere;
                sphere += lit && on_sphere;
            }
        printf("haze, stencil clip %s: %d lit pixels on the sphere, %d off it\n", clip ? "on" : "off", sphere, floor);
        assert_true(sphere > 50);
        floor_lit[clip] = floor;
        ps_image_destroy(&img);
        ps_splat_batch_free(&b);
    }
    assert_true(floor_lit[0] > 20); /* the haze is there to clip */
    assert_true(floor_lit[1] <= 2);  /* a pixel or two where the mesh's outline differs from the sphere's */
    preview_free(&p);
}

/* Area lights are seen as the reference renderer sees them: a disc light
 * from below shows its radiance P / (pi * pi R^2) in every pixel (times the
 * exposure), black with the direct layer off; from above, its back, nothing:
 * the floor under it shows through; a quad light flush with a ceiling
 * shows. */
static void area_light_seen(void **state)
{
    (void)state;
    const char *below = "camera eye 0 0.5 0 target 0 1 0 up 0 0 -1 fov 10\n"
                        "material floor diffuse albedo 0.5 0.5 0.5\n"
                        "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100 material floor\n"
                        "light disc center 0 1 0 normal 0 -1 0 radius 0.3 power 100 100 100\n";
    const double exposure = 0.01, le = 100.0 / (PS_PI * PS_PI * 0.09);
    preview p;
    preview_make(&p, below, 8, 8, PS_KERNEL_BOX);
    for (int direct = 0; direct < 2; direct++) {
        ps_gl_begin_frame(p.gl, &p.cam, exposure, direct != 0);
        ps_image img = read_back(&p);
        for (int y = 0; y < p.h; y++)
            for (int x = 0; x < p.w; x++)
                assert_near(ps_image_at(&img, x, y)[0], direct ? le * exposure : 0.0, 1e-5 * le * exposure);
        ps_image_destroy(&img);
    }
    preview_free(&p);
    const char *above = "camera eye 0 3 0.001 target 0 0 0 up 0 0 -1 fov 1\n"
                        "material floor diffuse albedo 0.5 0.5 0.5\n"
                        "quad corner -50 0 50 edge1 100 0 0 edge2 0 0 -100 material floor\n"
                        "light disc center 0 1 0 normal 0 -1 0 radius 0.3 power 100 100 100\n";
    preview_make(&p, above, 8, 8, PS_KERNEL_BOX);
    ps_gl_begin_frame(p.gl, &p.cam, 1.0, true);
    ps_image img = read_back(&p);
    /* The floor lit by the disc: rho / pi * pi L R^2 / (h^2 + R^2), within the
     * 16 virtual lights' error. */
    double floor = 0.5 * le * 0.09 / 1.09;
    printf("disc light from above: floor %.4f, analytic %.4f\n", ps_image_at(&img, 4, 4)[0], floor);
    assert_near(ps_image_at(&img, 4, 4)[0], floor, 0.03 * floor);
    ps_image_destroy(&img);
    preview_free(&p);
    /* A quad light in the plane of the ceiling it hangs from, seen from
     * below at a slant: every pixel of it shows its radiance, L = P / (pi A).
     * Emitters are drawn without the prepass's polygon offset, which pushes
     * the ceiling's depth behind theirs. Given that offset to share the
     * prepass's llvmpipe set-up function (one compile less in the area box's
     * first frame), with GL_LEQUAL, they lost the tie in all 256 pixels. */
    const char *flush = "camera eye 0.3 0.2 0.1 target 0 1 0 up 0 0 -1 fov 8\n"
                        "material white diffuse albedo 0.5 0.5 0.5\n"
                        "quad corner -50 1 -50 edge1 100 0 0 edge2 0 0 100 material white\n"
                        "light quad corner -0.5 1 -0.5 edge1 1 0 0 edge2 0 0 1 power 100 100 100\n";
    const double lq = 100.0 / PS_PI; /* P / (pi A), A = 1 */
    preview_make(&p, flush, 16, 16, PS_KERNEL_BOX);
    ps_gl_begin_frame(p.gl, &p.cam, 0.01, true);
    img = read_back(&p);
    size_t off = 0;
    for (int y = 0; y < p.h; y++)
        for (int x = 0; x < p.w; x++)
            off += fabs(ps_image_at(&img, x, y)[0] - lq * 0.01) > 1e-5 * lq * 0.01;
    printf("quad light flush with the ceiling: %zu of %d pixels not its radiance\n", off, p.w * p.h);
    assert_int_equal(off, 0);
    ps_image_destroy(&img);
    preview_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(direct_layer_on_plane),
        cmocka_unit_test(spot_cone_on_plane),
        cmocka_unit_test(shadow_of_a_square),
        cmocka_unit_test(ies_light_on_plane),
        cmocka_unit_test(caustic_layer_mirror_quad),
        cmocka_unit_test(stencil_clips_haze),
        cmocka_unit_test(area_light_seen),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
