/* test_splat.c: photons as splats (preview/splat.h): the kernel textures and
 * their measured means, the stable splat basis, the vertex arrays of the three
 * modes against the closed forms of splat.h (triangles: eq. 13 over a disc of
 * radius r; sprites: that times cos, lifted toward the eye; points: the power
 * over the surface area a point covers, also against an oracle that casts the
 * point's corner rays onto the surface), glossy colours through the BRDF, back
 * faces, batches and their stencil groups, and the 8-bit precision modes
 * (diffusion, counter) on thousands of faint photons. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "photon/estimate.h"
#include "photon/photon.h"
#include "preview/splat.h"
#include "scene/bsdf.h"
#include "scene/camera.h"
#include "scene/scene.h"

/* Colours are stored as floats: 2^-24 relative, with a margin for the few
 * double operations before the cast. */
#define FLOAT_REL_TOL 1e-6
/* Positions are floats of magnitude < 8: 2^-24 * 8 per coordinate, and a few
 * of them in each distance. */
#define POS_TOL 2e-6
/* The basis is exact up to a few double roundings. */
#define BASIS_TOL 1e-12
#define FAINT_COUNT 10000
/* A texture of PS_KERNEL_TEXTURE_SIZE texels a side spans this many radii
 * each way: size / (size - 2), so that its outermost texels are 0. */
#define TEXTURE_EXTENT (64.0 / 62.0)

static double rel_err(double a, double b) { return fabs(a - b) / fmax(fabs(b), 1e-300); }

static void assert_rgb_rel(const float *got, ps_rgb want, double tol, const char *what)
{
    double e = fmax(rel_err(got[0], want.r), fmax(rel_err(got[1], want.g), rel_err(got[2], want.b)));
    if (!(e <= tol))
        fail_msg("%s: got (%.10g, %.10g, %.10g), expected (%.10g, %.10g, %.10g): relative error %g > %g", what,
                 (double)got[0], (double)got[1], (double)got[2], want.r, want.g, want.b, e, tol);
}

static ps_vec3 vertex(const ps_splat_batch *b, size_t v)
{
    return ps_v3(b->positions[3 * v], b->positions[3 * v + 1], b->positions[3 * v + 2]);
}

static ps_material diffuse(ps_rgb albedo)
{
    ps_material m;
    memset(&m, 0, sizeof m);
    m.type = PS_MAT_DIFFUSE;
    m.albedo = albedo;
    return m;
}

static ps_camera_frame frame(ps_vec3 eye, ps_vec3 target, int width, int height)
{
    ps_camera c = {eye, target, ps_v3(0, 1, 0), 40.0};
    return ps_camera_frame_make(&c, width, height);
}

static ps_splat_params params(ps_splat_mode mode, const ps_material *materials, ps_camera_frame cam)
{
    ps_splat_params p;
    memset(&p, 0, sizeof p);
    p.mode = mode;
    p.radius = 0.1;
    p.kernel_mean = ps_kernel_mean(PS_KERNEL_CONE);
    p.kernel_extent = TEXTURE_EXTENT;
    p.scale = 0.8;
    p.point_size = 2.0;
    p.precision = PS_PRECISION_NONE;
    p.levels = 255;
    p.materials = materials;
    p.cam = cam;
    return p;
}

static void build(const ps_photon *ph, const uint16_t *mat, size_t n, const ps_splat_params *p, ps_splat_batch *b)
{
    ps_error err;
    if (ps_splat_build(ph, mat, n, p, b, &err) != PS_OK)
        fail_msg("ps_splat_build: %s", err.msg);
}

/* ---- the kernel texture ----------------------------------------------------- */

static void kernel_texture(void **state)
{
    (void)state;
    const int size = PS_KERNEL_TEXTURE_SIZE;
    assert_int_equal(size, 64);
    for (int k = 0; k < PS_KERNEL_COUNT; k++) {
        ps_kernel_texture t;
        ps_error err;
        assert_int_equal(ps_kernel_texture_make((ps_kernel)k, size, &t, &err), PS_OK);
        assert_int_equal(t.size, size);
        assert_non_null(t.alpha);
        assert_near(t.extent, TEXTURE_EXTENT, 1e-15);
        /* C is the mean over the unit disc of the stored texels, each
         * (2 extent / size)^2 of the square ... */
        double sum = 0.0;
        for (int i = 0; i < size * size; i++)
            sum += t.alpha[i] / 255.0;
        double texel = 2.0 * t.extent / size;
        assert_near(t.mean, sum * texel * texel / PS_PI, 1e-12);
        /* ... which rasterising and 8-bit rounding keep near the formula's
         * (box: 1, the covered fraction of the disc). */
        double want = ps_kernel_mean((ps_kernel)k);
        if (!(rel_err(t.mean, want) <= 0.02))
            fail_msg("%s: texture mean %.6f, formula %.6f", ps_kernel_name((ps_kernel)k), t.mean, want);
        if (k == PS_KERNEL_BOX)
            assert_near(t.mean, 1.0, 0.02);
        /* The outermost texels lie wholly outside the disc (GL clamps the
         * triangles' corners to them): the whole border is 0, corners
         * included. */
        for (int i = 0; i < size; i++) {
            assert_int_equal(t.alpha[i], 0);
            assert_int_equal(t.alpha[(size_t)(size - 1) * size + (size_t)i], 0);
            assert_int_equal(t.alpha[(size_t)i * size], 0);
            assert_int_equal(t.alpha[(size_t)i * size + (size_t)(size - 1)], 0);
        }
        /* The four centre texels sit at sqrt(2) extent / size radii from the
         * centre, where every profile is within 3 % of its peak. */
        long centre = lround(255.0 * ps_kernel_profile((ps_kernel)k, sqrt(2.0) * t.extent / size));
        for (int j = size / 2 - 1; j <= size / 2; j++)
            for (int i = size / 2 - 1; i <= size / 2; i++) {
                assert_int_equal(t.alpha[(size_t)j * size + (size_t)i], centre);
                assert_true(t.alpha[(size_t)j * size + (size_t)i] >= 245);
            }
        /* Every texel is the profile at its centre, and the texture has the
         * disc's symmetries. */
        for (int j = 0; j < size; j++)
            for (int i = 0; i < size; i++) {
                uint8_t a = t.alpha[(size_t)j * size + (size_t)i];
                double x = t.extent * (2.0 * (i + 0.5) / size - 1.0), y = t.extent * (2.0 * (j + 0.5) / size - 1.0);
                double g = ps_kernel_profile((ps_kernel)k, sqrt(x * x + y * y));
                assert_true(fabs(a - 255.0 * g) <= 0.5 + 1e-9);
                assert_int_equal(a, t.alpha[(size_t)j * size + (size_t)(size - 1 - i)]);
                assert_int_equal(a, t.alpha[(size_t)(size - 1 - j) * size + (size_t)i]);
                assert_int_equal(a, t.alpha[(size_t)i * size + (size_t)j]);
            }
        ps_kernel_texture_free(&t);
        assert_null(t.alpha);
        ps_kernel_texture_free(&t); /* twice: zeroed */
    }
    ps_kernel_texture_free(NULL);
    static const int bad[] = {-5, 0, 1, 2, 4097};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ps_kernel_texture t;
        ps_error err;
        ps_status st = ps_kernel_texture_make(PS_KERNEL_BOX, bad[i], &t, &err);
        if (st != PS_ERR_RANGE)
            fail_msg("size %d: status %d, expected PS_ERR_RANGE", bad[i], (int)st);
        assert_int_equal(err.status, PS_ERR_RANGE);
        assert_null(t.alpha);
    }
}

/* ---- the splat basis -------------------------------------------------------- */

static void check_basis(ps_vec3 n)
{
    ps_vec3 x, y;
    ps_splat_basis(n, &x, &y);
    ps_vec3 z = ps_v3_cross(x, y);
    double worst = fmax(fabs(ps_v3_len(x) - 1.0), fabs(ps_v3_len(y) - 1.0));
    worst = fmax(worst, fmax(fabs(ps_v3_dot(x, n)), fmax(fabs(ps_v3_dot(y, n)), fabs(ps_v3_dot(x, y)))));
    worst = fmax(worst, ps_v3_max_abs(ps_v3_sub(z, n)));
    if (!(ps_v3_isfinite(x) && ps_v3_isfinite(y) && worst <= BASIS_TOL))
        fail_msg("basis of n = (%.17g, %.17g, %.17g): x = (%g, %g, %g), y = (%g, %g, %g), error %g", n.x, n.y, n.z, x.x,
                 x.y, x.z, y.x, y.y, y.z, worst);
}

static void splat_basis(void **state)
{
    (void)state;
    static const double eps[] = {0.0, 1e-9, 1e-5};
    for (int axis = 0; axis < 3; axis++)
        for (int sign = -1; sign <= 1; sign += 2)
            for (size_t e = 0; e < sizeof eps / sizeof eps[0]; e++)
                /* The axis, nudged toward each of the 9 combinations of the
                 * other two (ties among the small components included). */
                for (int a = -1; a <= 1; a++)
                    for (int c = -1; c <= 1; c++) {
                        double v[3] = {0, 0, 0};
                        v[axis] = sign;
                        v[(axis + 1) % 3] = a * eps[e];
                        v[(axis + 2) % 3] = c * eps[e];
                        check_basis(ps_v3_norm(ps_v3(v[0], v[1], v[2])));
                    }
    /* Ties among the large components. */
    static const double ties[][3] = {{1, 1, 0}, {0, 1, -1}, {-1, 0, 1}, {1, 1, 1}, {-1, 1, -1}, {1, -1, 1e-7}};
    for (size_t i = 0; i < sizeof ties / sizeof ties[0]; i++)
        check_basis(ps_v3_norm(ps_v3(ties[i][0], ties[i][1], ties[i][2])));
    for (uint64_t i = 0; i < 10000; i++) {
        ps_rng r = ps_rng_make(11, PS_STREAM_TEST, i);
        double u1 = ps_rng_uniform(&r), u2 = ps_rng_uniform(&r);
        check_basis(ps_v3_norm(ps_sample_sphere(u1, u2)));
    }
}

/* ---- triangles and sprites -------------------------------------------------- */

/* The photon the geometry tests share: tilted against the view so that cos is
 * far from 1, powers that RGBE must round. */
static ps_photon tilted_photon(void)
{
    return ps_photon_pack(ps_v3(0.2, -0.1, 0.3), ps_rgb_make(1.5, 2.0, 0.7), ps_v3_norm(ps_v3(0.3, -0.5, -1.0)),
                          ps_v3_norm(ps_v3(0.8, 0.3, 1.0)), 0.5);
}

static void triangles(void **state)
{
    (void)state;
    ps_material mat = diffuse(ps_rgb_make(0.6, 0.5, 0.4));
    ps_camera_frame cam = frame(ps_v3(0.5, 0.3, 4.0), ps_v3(0, 0, 0), 640, 480);
    ps_splat_params p = params(PS_SPLAT_TRIANGLES, &mat, cam);
    ps_photon ph = tilted_photon();
    uint16_t m = 0;
    ps_splat_batch b;
    ps_splat_batch_init(&b);
    build(&ph, &m, 1, &p, &b);
    assert_int_equal(b.vertex_count, 3);
    assert_int_equal(b.splats, 1);

    /* What the splat is made of: the photon as stored. */
    ps_vec3 pos = ps_photon_position(&ph), n = ps_photon_normal(&ph);
    ps_rgb power = ps_photon_power(&ph);
    assert_true(rel_err(power.r, 1.5) < 0.01 && rel_err(power.b, 0.7) < 0.01);
    double r = p.radius, dist = ps_v3_len(ps_v3_sub(cam.eye, pos));
    ps_vec3 wo = ps_v3_scale(ps_v3_sub(cam.eye, pos), 1.0 / dist);
    assert_true(ps_v3_dot(wo, n) < 0.9); /* tilted: a missing or extra cos would show */

    /* Colour: albedo / pi * dPhi * scale / (C pi r^2), alpha 1, on every vertex. */
    ps_rgb want = ps_rgb_scale(ps_rgb_mul(ps_rgb_scale(mat.albedo, 1.0 / PS_PI), power),
                               p.scale / (p.kernel_mean * PS_PI * r * r));
    for (size_t v = 0; v < 3; v++) {
        assert_rgb_rel(&b.colors[4 * v], want, FLOAT_REL_TOL, "triangle colour");
        assert_true(b.colors[4 * v + 3] == 1.0f);
    }

    /* Geometry: an equilateral triangle around the disc of radius r in the
     * surface's plane, moved toward the eye by the offset. */
    ps_vec3 centre = ps_v3_madd(pos, wo, PS_SPLAT_EYE_OFFSET * dist);
    ps_vec3 q[3], sum = ps_v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        q[k] = vertex(&b, (size_t)k);
        sum = ps_v3_add(sum, q[k]);
        assert_near(ps_v3_len(ps_v3_sub(q[k], centre)), 2.0 * r, POS_TOL);
        assert_near(ps_v3_dot(ps_v3_sub(q[k], centre), n), 0.0, POS_TOL);
    }
    ps_vec3 centroid = ps_v3_scale(sum, 1.0 / 3.0);
    assert_near(ps_v3_len(ps_v3_sub(centroid, centre)), 0.0, POS_TOL);
    assert_near(ps_v3_len(ps_v3_sub(centroid, pos)), PS_SPLAT_EYE_OFFSET * dist, POS_TOL);
    assert_true(ps_v3_dot(ps_v3_sub(centroid, pos), wo) > 0.0);
    /* The incircle is the disc: each edge's midpoint at r from the centre. */
    for (int k = 0; k < 3; k++) {
        ps_vec3 mid = ps_v3_scale(ps_v3_add(q[k], q[(k + 1) % 3]), 0.5);
        assert_near(ps_v3_len(ps_v3_sub(mid, centre)), r, POS_TOL);
    }
    /* Wound counter-clockwise about the normal, i.e. seen from the eye. */
    assert_true(ps_v3_dot(ps_v3_cross(ps_v3_sub(q[1], q[0]), ps_v3_sub(q[2], q[0])), n) > 0.0);

    /* Texture coordinates: the unit square spans [-extent r, extent r]^2 in
     * the (x, y) basis, so the centre maps to (0.5, 0.5) and the disc's edge
     * to 0.5 +- 0.5 / extent. */
    ps_vec3 x, y;
    ps_splat_basis(n, &x, &y);
    double us = 0.0, vs = 0.0, half = 2.0 * p.kernel_extent * r;
    for (int k = 0; k < 3; k++) {
        ps_vec3 d = ps_v3_sub(q[k], centre);
        assert_near(b.texcoords[2 * k], 0.5 + ps_v3_dot(d, x) / half, 1e-5);
        assert_near(b.texcoords[2 * k + 1], 0.5 + ps_v3_dot(d, y) / half, 1e-5);
        us += b.texcoords[2 * k];
        vs += b.texcoords[2 * k + 1];
    }
    assert_near(us / 3.0, 0.5, 1e-7);
    assert_near(vs / 3.0, 0.5, 1e-7);

    ps_splat_batch_free(&b);
    assert_null(b.positions);
    ps_splat_batch_free(NULL);
}

/* One photon as a sprite: its colour is the triangle's times cos_v (it faces
 * the eye, covering 1 / cos more pixels than the surface's disc), lifted
 * toward the eye by max(offset * dist, r tan) with tan held at
 * PS_SPLAT_SPRITE_MAX_TAN, and dimmed by ((dist - lift) / dist)^2 because GL
 * sizes it by its own, shorter distance. Returns the lift used. */
static double check_sprite(ps_camera_frame cam, ps_photon ph)
{
    ps_material mat = diffuse(ps_rgb_make(0.6, 0.5, 0.4));
    ps_splat_params p = params(PS_SPLAT_TRIANGLES, &mat, cam);
    uint16_t m = 0;
    ps_splat_batch tri, spr;
    ps_splat_batch_init(&tri);
    ps_splat_batch_init(&spr);
    build(&ph, &m, 1, &p, &tri);
    p.mode = PS_SPLAT_SPRITES;
    build(&ph, &m, 1, &p, &spr);
    assert_int_equal(spr.vertex_count, 1);
    assert_int_equal(spr.splats, 1);
    ps_vec3 pos = ps_photon_position(&ph), n = ps_photon_normal(&ph);
    double dist = ps_v3_len(ps_v3_sub(cam.eye, pos));
    ps_vec3 wo = ps_v3_scale(ps_v3_sub(cam.eye, pos), 1.0 / dist);
    double cos_v = ps_v3_dot(wo, n), tan_v = sqrt(1.0 - cos_v * cos_v) / cos_v;
    double lift = fmax(PS_SPLAT_EYE_OFFSET * dist, p.radius * fmin(tan_v, PS_SPLAT_SPRITE_MAX_TAN));
    assert_near(ps_v3_len(ps_v3_sub(vertex(&spr, 0), ps_v3_madd(pos, wo, lift))), 0.0, POS_TOL);
    double dim = ((dist - lift) / dist) * ((dist - lift) / dist);
    ps_rgb want = ps_rgb_make(tri.colors[0] * cos_v * dim, tri.colors[1] * cos_v * dim, tri.colors[2] * cos_v * dim);
    assert_rgb_rel(spr.colors, want, 2.0 * FLOAT_REL_TOL, "sprite colour");
    assert_true(spr.colors[3] == 1.0f);
    /* What reaches the screen, colour times the sprite's pixel area ~ 1 /
     * its distance^2, is the surface disc's: the triangle's colour times
     * its projected area ~ cos_v / dist^2. */
    double shown = spr.colors[1] / ((dist - lift) * (dist - lift)), disc = tri.colors[1] * cos_v / (dist * dist);
    assert_near(shown, disc, 2.0 * FLOAT_REL_TOL * disc);
    ps_splat_batch_free(&tri);
    ps_splat_batch_free(&spr);
    return lift;
}

static void sprites(void **state)
{
    (void)state;
    ps_camera_frame cam = frame(ps_v3(0.5, 0.3, 4.0), ps_v3(0, 0, 0), 640, 480);
    const double r = params(PS_SPLAT_SPRITES, NULL, cam).radius;
    /* Tilted (cos about 0.8): lifted by r tan. */
    double lift = check_sprite(cam, tilted_photon());
    assert_true(lift > 0.5 * r && lift < 2.0 * r);
    /* Facing the eye: r tan is below the depth offset, which is kept. */
    ps_vec3 at = ps_v3(0.1, 0.2, 0.0);
    ps_photon head_on = ps_photon_pack(at, ps_rgb_make(1, 2, 3), ps_v3(0, 0, -1),
                                       ps_v3_norm(ps_v3_sub(cam.eye, at)), 0.5);
    double dist = ps_v3_len(ps_v3_sub(cam.eye, ps_photon_position(&head_on)));
    assert_near(check_sprite(cam, head_on), PS_SPLAT_EYE_OFFSET * dist, 1e-15);
    /* Nearly edge-on: tan held at its maximum. */
    ps_vec3 wo = ps_v3_norm(ps_v3_sub(cam.eye, at)), side = ps_v3_norm(ps_v3_cross(wo, ps_v3(0, 1, 0)));
    int found = 0;
    for (double t = 0.005; t < 0.1 && !found; t += 0.005) {
        ps_photon ph = ps_photon_pack(at, ps_rgb_make(1, 2, 3), ps_v3(0, 0, -1), ps_v3_norm(ps_v3_madd(side, wo, t)), 0.5);
        double c = ps_v3_dot(wo, ps_photon_normal(&ph));
        if (c > 0.01 && c < 0.09) {
            assert_near(check_sprite(cam, ph), PS_SPLAT_SPRITE_MAX_TAN * r, 1e-15);
            found = 1;
        }
    }
    assert_true(found);
}

/* ---- points ----------------------------------------------------------------- */

/* The oracle: the surface area a point of side point_size pixels covers,
 * found by casting its four corner rays onto the photon's plane. */
static double point_footprint(const ps_camera_frame *cam, ps_vec3 pos, ps_vec3 n, double side_px)
{
    double px, py;
    assert_true(ps_camera_project(cam, pos, &px, &py));
    static const double corner[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    ps_vec3 c[4];
    for (int k = 0; k < 4; k++) {
        ps_ray ray = ps_camera_ray(cam, px + side_px * corner[k][0], py + side_px * corner[k][1]);
        double t = ps_v3_dot(ps_v3_sub(pos, ray.o), n) / ps_v3_dot(ray.d, n);
        c[k] = ps_ray_at(ray, t);
    }
    return 0.5 * (ps_v3_len(ps_v3_cross(ps_v3_sub(c[1], c[0]), ps_v3_sub(c[2], c[0]))) +
                  ps_v3_len(ps_v3_cross(ps_v3_sub(c[2], c[0]), ps_v3_sub(c[3], c[0]))));
}

/* Builds one photon as a point and checks its colour against splat.c's
 * formula, and (unless at grazing view) against the oracle within oracle_tol;
 * returns cos_v. */
static double check_point(ps_camera_frame cam, ps_vec3 at, ps_vec3 normal, double oracle_tol, int on_axis)
{
    ps_material mat = diffuse(ps_rgb_make(0.6, 0.5, 0.4));
    ps_splat_params p = params(PS_SPLAT_POINTS, &mat, cam);
    ps_photon ph = ps_photon_pack(at, ps_rgb_make(1.5, 2.0, 0.7), ps_v3(0, -1, 0), normal, 0.5);
    uint16_t m = 0;
    ps_splat_batch b;
    ps_splat_batch_init(&b);
    build(&ph, &m, 1, &p, &b);
    assert_int_equal(b.vertex_count, 1);
    assert_int_equal(b.splats, 1);
    ps_vec3 pos = ps_photon_position(&ph), n = ps_photon_normal(&ph);
    ps_vec3 to_eye = ps_v3_sub(cam.eye, pos);
    double dist = ps_v3_len(to_eye), cos_v = ps_v3_dot(to_eye, n) / dist;
    double depth = -ps_v3_dot(to_eye, cam.forward);
    if (on_axis)
        assert_near(depth, dist, 1e-12 * dist);
    else
        assert_true(depth < 0.99 * dist);
    double pixel = 2.0 * cam.tan_half_fov / cam.height;
    double side = p.point_size * pixel * depth;
    double area = side * side * (depth / dist) / fmax(cos_v, PS_SPLAT_MIN_COS);
    ps_rgb flux = ps_rgb_scale(ps_rgb_mul(ps_rgb_scale(mat.albedo, 1.0 / PS_PI), ps_photon_power(&ph)), p.scale);
    assert_rgb_rel(b.colors, ps_rgb_scale(flux, 1.0 / area), FLOAT_REL_TOL, "point colour (formula)");
    if (oracle_tol > 0.0) {
        double oracle = point_footprint(&cam, pos, n, p.point_size);
        assert_rgb_rel(b.colors, ps_rgb_scale(flux, 1.0 / oracle), oracle_tol, "point colour (footprint oracle)");
    }
    assert_true(b.colors[3] == 1.0f);
    assert_near(ps_v3_len(ps_v3_sub(vertex(&b, 0), ps_v3_madd(pos, to_eye, PS_SPLAT_EYE_OFFSET))), 0.0, POS_TOL);
    ps_splat_batch_free(&b);
    return cos_v;
}

static void points(void **state)
{
    (void)state;
    /* On the axis, depth == dist: area = (side pixel dist)^2 / cos_v. */
    ps_camera_frame axial = frame(ps_v3(0, 0, 5), ps_v3(0, 0, 0), 640, 480);
    double c = check_point(axial, ps_v3(0, 0, 0), ps_v3_norm(ps_v3(0.5, -0.4, 1.0)), 1e-3, 1);
    assert_true(c > 0.5 && c < 0.9);
    /* Off the axis of a camera looking down at an angle, near the image's
     * corner, on surfaces tilted either way. */
    ps_camera_frame cam = frame(ps_v3(2.0, 1.5, 4.0), ps_v3(0, 0.2, 0), 640, 480);
    check_point(cam, ps_v3(-1.1, 1.3, 0.4), ps_v3_norm(ps_v3(0.2, 0.3, 1.0)), 1e-3, 0);
    check_point(cam, ps_v3(-1.1, 1.3, 0.4), ps_v3_norm(ps_v3(1.0, -0.5, 0.3)), 1e-3, 0);
    check_point(cam, ps_v3(1.6, -0.9, -1.0), ps_v3(0, 1, 0), 1e-3, 0);
    /* Grazing: past PS_SPLAT_MIN_COS the footprint is held (no oracle). */
    ps_vec3 at = ps_v3(1.2, 0.9, 0.0), wo = ps_v3_norm(ps_v3_sub(axial.eye, at));
    ps_vec3 side = ps_v3_norm(ps_v3_cross(wo, ps_v3(0, 1, 0)));
    int grazing = 0;
    for (double t = 0.005; t < 0.1 && !grazing; t += 0.005) {
        ps_vec3 n = ps_v3_norm(ps_v3_madd(side, wo, t));
        ps_photon probe = ps_photon_pack(at, ps_rgb_make(1, 1, 1), ps_v3(0, -1, 0), n, 0.5);
        double cq = ps_v3_dot(wo, ps_photon_normal(&probe));
        if (cq > 0.005 && cq < 0.8 * PS_SPLAT_MIN_COS) {
            c = check_point(axial, at, n, 0.0, 0);
            assert_true(c > 0.0 && c < PS_SPLAT_MIN_COS);
            grazing = 1;
        }
    }
    assert_true(grazing);
}

/* ---- glossy ----------------------------------------------------------------- */

static void glossy(void **state)
{
    (void)state;
    ps_material mat;
    memset(&mat, 0, sizeof mat);
    mat.type = PS_MAT_GLOSSY;
    mat.albedo = ps_rgb_make(0.1, 0.1, 0.1);
    mat.specular = ps_rgb_make(0.6, 0.5, 0.4);
    mat.exponent = 30.0;
    ps_camera_frame cam = frame(ps_v3(0.5, 0.3, 4.0), ps_v3(0, 0, 0), 640, 480);
    ps_splat_params p = params(PS_SPLAT_TRIANGLES, &mat, cam);
    ps_vec3 at = ps_v3(0.25, -0.5, 0.125), normal = ps_v3_norm(ps_v3(0.1, 0.2, 1.0));
    ps_rgb power = ps_rgb_make(1.0, 1.0, 1.0);
    /* Photon 0 arrives along the mirror image of the view direction, photon 1
     * from elsewhere; same place, normal and power. */
    ps_photon probe = ps_photon_pack(at, power, ps_v3(0, 0, -1), normal, 0.5);
    ps_vec3 pos = ps_photon_position(&probe), n = ps_photon_normal(&probe);
    ps_vec3 wo = ps_v3_norm(ps_v3_sub(cam.eye, pos));
    ps_vec3 mirror_in = ps_reflect(wo, n);
    assert_true(ps_v3_dot(mirror_in, n) < 0.0);
    ps_photon ph[2] = {ps_photon_pack(at, power, mirror_in, normal, 0.5),
                       ps_photon_pack(at, power, ps_v3_norm(ps_v3(-0.5, 0.2, -1.0)), normal, 0.5)};
    uint16_t m[2] = {0, 0};
    ps_splat_batch b;
    ps_splat_batch_init(&b);
    build(ph, m, 2, &p, &b);
    assert_int_equal(b.vertex_count, 6);
    double disc = 1.0 / (p.kernel_mean * PS_PI * p.radius * p.radius);
    ps_rgb f[2];
    for (int i = 0; i < 2; i++) {
        ps_vec3 d = ps_photon_dir(&ph[i]);
        f[i] = ps_bsdf_eval(&mat, n, d, wo);
        /* The BRDF by hand: albedo / pi + specular (e + 2) / (2 pi) cos^e. */
        double c = fmax(ps_v3_dot(ps_reflect(d, n), wo), 0.0);
        double lobe = (mat.exponent + 2.0) / (2.0 * PS_PI) * pow(c, mat.exponent);
        assert_near(f[i].r, 0.1 / PS_PI + 0.6 * lobe, 1e-12);
        assert_near(f[i].b, 0.1 / PS_PI + 0.4 * lobe, 1e-12);
        ps_rgb want = ps_rgb_scale(ps_rgb_mul(f[i], ps_photon_power(&ph[i])), p.scale * disc);
        for (int k = 0; k < 3; k++)
            assert_rgb_rel(&b.colors[4 * (3 * i + k)], want, FLOAT_REL_TOL, "glossy colour");
    }
    /* The stored mirror direction is within the octahedral code's 0.75
     * degrees: the lobe's peak, many times the other photon's value. */
    assert_true(ps_v3_dot(ps_reflect(ps_photon_dir(&ph[0]), n), wo) > 0.999);
    assert_true(b.colors[0] > 5.0f * b.colors[12]);
    assert_near(b.colors[0] / b.colors[12], f[0].r / f[1].r, FLOAT_REL_TOL * f[0].r / f[1].r * 3.0);
    assert_near(b.colors[2] / b.colors[14], f[0].b / f[1].b, FLOAT_REL_TOL * f[0].b / f[1].b * 3.0);
    ps_splat_batch_free(&b);
}

/* ---- what is skipped -------------------------------------------------------- */

static void back_faces(void **state)
{
    (void)state;
    ps_material mat = diffuse(ps_rgb_make(0.5, 0.5, 0.5));
    ps_camera_frame cam = frame(ps_v3(0, 0, 5), ps_v3(0, 0, 0), 640, 480);
    ps_photon front = tilted_photon();
    /* The same surface's other face (normal away from the eye), one seen
     * edge-on from behind, a photon at the eye itself, and two on a wall
     * behind the eye and in its plane, facing it (their point footprint
     * would be negative or zero: a NaN or negative carry). */
    ps_photon skipped[5] = {
        ps_photon_pack(ps_v3(0.2, -0.1, 0.3), ps_rgb_make(1, 1, 1), ps_v3(0, 0, 1), ps_v3_norm(ps_v3(-0.8, -0.3, -1)),
                       0.5),
        ps_photon_pack(ps_v3(0.2, -0.1, 0.3), ps_rgb_make(1, 1, 1), ps_v3(0, 0, 1), ps_v3_norm(ps_v3(1, 0, -0.2)),
                       0.5),
        ps_photon_pack(cam.eye, ps_rgb_make(1, 1, 1), ps_v3(0, 0, -1), ps_v3(0, 0, 1), 0.5),
        ps_photon_pack(ps_v3(0.5, 0, 6), ps_rgb_make(1, 1, 1), ps_v3(0, 0, 1), ps_v3(0, 0, -1), 0.5),
        ps_photon_pack(ps_v3(0.5, 0, 5), ps_rgb_make(1, 1, 1), ps_v3(1, 0, 0), ps_v3(-1, 0, 0), 0.5)};
    uint16_t m[5] = {0, 0, 0, 0, 0};
    for (int mode = 0; mode < PS_SPLAT_MODE_COUNT; mode++)
        for (int prec = 0; prec < PS_PRECISION_COUNT; prec++) {
            ps_splat_params p = params((ps_splat_mode)mode, &mat, cam);
            p.precision = (ps_precision)prec;
            p.scale = 1e-4; /* faint: the precision modes have round-off to keep */
            ps_splat_batch b;
            ps_splat_batch_init(&b);
            build(&front, m, 1, &p, &b);
            size_t per = mode == PS_SPLAT_TRIANGLES ? 3 : 1;
            assert_int_equal(b.vertex_count, per);
            assert_int_equal(b.splats, 1);
            ps_splat_batch before = b;
            float pos0 = b.positions[0], col0 = b.colors[0];
            build(skipped, m, 5, &p, &b);
            assert_int_equal(b.vertex_count, per);
            assert_int_equal(b.splats, 1);
            assert_memory_equal(b.carry, before.carry, sizeof b.carry);
            assert_true(b.wanted == before.wanted && b.lost == before.lost);
            assert_true(b.positions[0] == pos0 && b.colors[0] == col0);
            ps_splat_batch_free(&b);
        }
}

/* ---- batches ---------------------------------------------------------------- */

static void batches(void **state)
{
    (void)state;
    ps_material mat = diffuse(ps_rgb_make(0.5, 0.4, 0.3));
    ps_camera_frame cam = frame(ps_v3(0, 0, 5), ps_v3(0, 0, 0), 640, 480);
    ps_photon ph[5];
    uint16_t m[5] = {0};
    for (int i = 0; i < 5; i++)
        ph[i] = ps_photon_pack(ps_v3(0.1 * i, -0.05 * i, 0.0), ps_rgb_make(1.0 + i, 1.0, 0.5), ps_v3(0, 0, -1),
                               ps_v3_norm(ps_v3(0.1 * i, 0.0, 1.0)), 0.5);
    ps_splat_params p = params(PS_SPLAT_TRIANGLES, &mat, cam);
    p.scale = 3e-5;
    p.precision = PS_PRECISION_DIFFUSION;

    /* Appending accumulates; the earlier vertices stay as they were. */
    ps_splat_batch b, whole;
    ps_splat_batch_init(&b);
    ps_splat_batch_init(&whole);
    build(ph, m, 2, &p, &b);
    assert_int_equal(b.vertex_count, 6);
    float first[6 * 3], first_tex[6 * 2];
    memcpy(first, b.positions, sizeof first);
    memcpy(first_tex, b.texcoords, sizeof first_tex);
    build(ph + 2, m, 3, &p, &b);
    assert_int_equal(b.vertex_count, 15);
    assert_int_equal(b.splats, 5);
    assert_memory_equal(b.positions, first, sizeof first);
    assert_memory_equal(b.texcoords, first_tex, sizeof first_tex);
    /* Two appends give what one build of all five does, carry included. */
    build(ph, m, 5, &p, &whole);
    assert_int_equal(whole.vertex_count, 15);
    assert_memory_equal(b.positions, whole.positions, 15 * 3 * sizeof(float));
    assert_memory_equal(b.colors, whole.colors, 15 * 4 * sizeof(float));
    assert_memory_equal(b.texcoords, whole.texcoords, 15 * 2 * sizeof(float));
    assert_memory_equal(b.carry, whole.carry, sizeof b.carry);
    assert_true(ps_splat_batch_carry(&b, 0) != 0.0);

    /* Clearing empties the arrays and keeps carry and counters. */
    p.precision = PS_PRECISION_COUNTER;
    build(ph, m, 5, &p, &b);
    assert_true(b.wanted > 0.0 && b.lost != 0.0);
    ps_splat_batch kept = b;
    ps_splat_batch_clear(&b);
    assert_int_equal(b.vertex_count, 0);
    assert_int_equal(b.splats, 0);
    assert_memory_equal(b.carry, kept.carry, sizeof b.carry);
    assert_true(b.wanted == kept.wanted && b.lost == kept.lost);
    assert_true(b.positions == kept.positions && b.cap_pos == kept.cap_pos);
    /* ... and the counters keep adding up after it. */
    build(ph, m, 5, &p, &b);
    assert_int_equal(b.vertex_count, 15);
    assert_near(b.wanted, 2.0 * kept.wanted, 1e-12 * kept.wanted);
    assert_near(b.lost, 2.0 * kept.lost, 1e-12 * fabs(kept.lost));
    ps_splat_batch_free(&b);
    ps_splat_batch_free(&whole);
    assert_null(whole.colors);
    assert_int_equal(whole.vertex_count, 0);
}

/* ---- stencil groups --------------------------------------------------------- */

/* With object ids, a build's splats come out sorted by stencil value, stably,
 * with group_first bounding each group; without, in photon order. */
static void groups(void **state)
{
    (void)state;
    enum { N = 40 };
    ps_material mat = diffuse(ps_rgb_make(0.5, 0.4, 0.3));
    ps_camera_frame cam = frame(ps_v3(0, 0, 5), ps_v3(0, 0, 0), 640, 480);
    ps_photon ph[N];
    uint16_t m[N] = {0};
    /* Ids that share stencil values (3 and 258 both give 4) and one past 255. */
    static const uint32_t ids[] = {3, 0, 300, 1, 258, 7};
    uint32_t objects[N];
    for (int i = 0; i < N; i++) {
        objects[i] = ids[(i * 7) % 6];
        /* Every fifth photon faces away: it takes no place in any group. */
        ps_vec3 normal = i % 5 == 4 ? ps_v3(0, 0, -1) : ps_v3_norm(ps_v3(0.02 * i, 0.0, 1.0));
        ph[i] = ps_photon_pack(ps_v3(0.05 * i - 1.0, 0.03 * i - 0.6, 0.0), ps_rgb_make(1.0 + 0.1 * i, 1.0, 0.5),
                               ps_v3(0, 0, -1), normal, 0.5);
    }
    assert_int_equal(ps_splat_stencil(3), 4);
    assert_int_equal(ps_splat_stencil(258), 4);
    assert_int_equal(ps_splat_stencil(0), 1);
    assert_int_equal(ps_splat_stencil(254), 255);
    assert_int_equal(ps_splat_stencil(255), 1);
    ps_splat_params p = params(PS_SPLAT_TRIANGLES, &mat, cam);
    p.precision = PS_PRECISION_DIFFUSION;
    p.scale = 1e-4;
    ps_splat_batch ref, b;
    ps_splat_batch_init(&ref);
    ps_splat_batch_init(&b);
    /* The reference: the same build in photon order, after one earlier build
     * so that both start at the same carry and vertex offset. */
    build(ph, m, 3, &p, &ref);
    build(ph, m, 3, &p, &b);
    size_t v0 = ref.vertex_count;
    assert_int_equal(v0, 9);
    assert_false(b.grouped);
    build(ph, m, N, &p, &ref);
    assert_false(ref.grouped);
    p.objects = objects;
    build(ph, m, N, &p, &b);
    assert_true(b.grouped);
    assert_int_equal(b.vertex_count, ref.vertex_count);
    assert_int_equal(b.splats, 3 + N - N / 5);
    assert_memory_equal(b.carry, ref.carry, sizeof b.carry);
    /* The earlier build's vertices stay where they were. */
    assert_memory_equal(b.positions, ref.positions, 3 * v0 * sizeof(float));
    /* Group g holds, in photon order, the splats whose object has stencil g. */
    assert_int_equal(b.group_first[0], v0);
    assert_int_equal(b.group_first[PS_SPLAT_GROUPS], b.vertex_count);
    size_t expect = v0;
    int nonempty = 0;
    for (unsigned g = 0; g < PS_SPLAT_GROUPS; g++) {
        assert_int_equal(b.group_first[g], expect);
        size_t from = v0; /* the next reference splat to look at */
        for (int i = 0; i < N; i++) {
            if (i % 5 == 4)
                continue;
            if (ps_splat_stencil(objects[i]) == g) {
                assert_true(expect + 3 <= b.group_first[g + 1]);
                assert_memory_equal(b.positions + 3 * expect, ref.positions + 3 * from, 9 * sizeof(float));
                assert_memory_equal(b.colors + 4 * expect, ref.colors + 4 * from, 12 * sizeof(float));
                assert_memory_equal(b.texcoords + 2 * expect, ref.texcoords + 2 * from, 6 * sizeof(float));
                expect += 3;
            }
            from += 3;
        }
        assert_int_equal(b.group_first[g + 1], expect);
        nonempty += b.group_first[g + 1] > b.group_first[g];
    }
    assert_int_equal(expect, b.vertex_count);
    assert_int_equal(nonempty, 5); /* stencils 4, 1, 46, 2, 8 */
    /* Clearing forgets the grouping. */
    ps_splat_batch_clear(&b);
    assert_false(b.grouped);
    ps_splat_batch_free(&b);
    ps_splat_batch_free(&ref);
}

/* ---- precision -------------------------------------------------------------- */

typedef struct faint_set {
    ps_photon *ph;
    uint16_t *mat;
    ps_material material;
    ps_splat_params p;
} faint_set;

/* FAINT_COUNT photons on the plane z = 0 facing the eye, diffuse, each of
 * colour `colour` in every channel as a triangle splat (s->p points into s). */
static void faint_make(faint_set *s, double colour)
{
    s->ph = malloc(FAINT_COUNT * sizeof *s->ph);
    s->mat = calloc(FAINT_COUNT, sizeof *s->mat);
    assert_non_null(s->ph);
    assert_non_null(s->mat);
    s->material = diffuse(ps_rgb_make(0.5, 0.5, 0.5));
    for (size_t i = 0; i < FAINT_COUNT; i++) {
        ps_rng r = ps_rng_make(5, PS_STREAM_TEST, i);
        ps_vec3 at = ps_v3(2.0 * ps_rng_uniform(&r) - 1.0, 2.0 * ps_rng_uniform(&r) - 1.0, 0.0);
        s->ph[i] = ps_photon_pack(at, ps_rgb_make(1.0, 1.0, 1.0), ps_v3(0, 0, -1), ps_v3(0, 0, 1), 0.5);
    }
    ps_rgb power = ps_photon_power(&s->ph[0]);
    assert_true(power.r == 1.0 && power.g == 1.0 && power.b == 1.0); /* RGBE stores 1 exactly */
    s->p = params(PS_SPLAT_TRIANGLES, &s->material, frame(ps_v3(0, 0, 5), ps_v3(0, 0, 0), 640, 480));
    s->p.scale = colour / (0.5 / PS_PI / (s->p.kernel_mean * PS_PI * s->p.radius * s->p.radius));
}

static void faint_free(faint_set *s)
{
    free(s->ph);
    free(s->mat);
}

/* Builds the set with precision pr at `levels`; b is left built. */
static void faint_build(faint_set *s, ps_precision pr, int levels, ps_splat_batch *b)
{
    ps_splat_batch_init(b);
    s->p.precision = pr;
    s->p.levels = levels;
    build(s->ph, s->mat, FAINT_COUNT, &s->p, b);
    assert_int_equal(b->vertex_count, 3 * FAINT_COUNT);
}

static void colour_sums(const ps_splat_batch *b, double sum[3])
{
    sum[0] = sum[1] = sum[2] = 0.0;
    for (size_t i = 0; i < b->splats; i++)
        for (int c = 0; c < 3; c++)
            sum[c] += b->colors[4 * 3 * i + (size_t)c];
}

static void precision_diffusion(void **state)
{
    (void)state;
    const double L = 255.0;
    faint_set s;
    faint_make(&s, 0.3 / L);
    ps_splat_batch none, diff;
    faint_build(&s, PS_PRECISION_NONE, 255, &none);
    for (size_t v = 0; v < none.vertex_count; v++)
        assert_near(none.colors[4 * v], 0.3 / L, FLOAT_REL_TOL * 0.3 / L);
    double wanted[3], got[3];
    colour_sums(&none, wanted);
    assert_near(wanted[1], FAINT_COUNT * 0.3 / L, 1e-6 * wanted[1]);

    faint_build(&s, PS_PRECISION_DIFFUSION, 255, &diff);
    size_t lit = 0;
    double steps[3] = {0, 0, 0};
    for (size_t i = 0; i < diff.splats; i++)
        for (int c = 0; c < 3; c++) {
            double q = diff.colors[4 * 3 * i + (size_t)c] * L;
            if (!(fabs(q - round(q)) < 1e-4))
                fail_msg("photon %zu channel %d: colour %.9g * 255 = %.9g is not a step", i, c, q / L, q);
            /* Every vertex of a triangle has the photon's colour. */
            assert_true(diff.colors[4 * 3 * i + (size_t)c] == diff.colors[4 * (3 * i + 2) + (size_t)c]);
            lit += c == 0 && round(q) > 0.0;
            steps[c] += round(q);
        }
    colour_sums(&diff, got);
    for (int c = 0; c < 3; c++) {
        /* Each screen tile carries under half a step. */
        assert_near(got[c], wanted[c], 0.5 * PS_SPLAT_DIFFUSION_REGIONS / L);
        /* Exactly: what was sent plus what is still carried (up to the
         * float rounding of the wanted colours). */
        assert_near(steps[c] / L + ps_splat_batch_carry(&diff, c), wanted[c], 1e-7 * wanted[c]);
        for (int g = 0; g < PS_SPLAT_DIFFUSION_REGIONS; g++)
            assert_true(fabs(diff.carry[g][c]) <= 0.5 / L + 1e-12);
    }
    /* 0.3 of a step each: about 3 photons in 10 send one step. */
    assert_true(lit >= 2990 && lit <= 3010);
    /* Photon by photon, each rounded to the nearest step: the carry never
     * exceeds half a step either way, and crosses zero. */
    {
        ps_splat_batch one;
        ps_splat_batch_init(&one);
        s.p.precision = PS_PRECISION_DIFFUSION;
        double lo = 0.0, hi = 0.0;
        for (size_t i = 0; i < 1000; i++) {
            build(&s.ph[i], s.mat, 1, &s.p, &one);
            for (int g = 0; g < PS_SPLAT_DIFFUSION_REGIONS; g++) {
                lo = fmin(lo, one.carry[g][0]);
                hi = fmax(hi, one.carry[g][0]);
            }
        }
        assert_true(lo >= -0.5 / L - 1e-12 && hi <= 0.5 / L + 1e-12);
        assert_true(lo < -0.3 / L && hi > 0.25 / L);
        ps_splat_batch_free(&one);
    }
    ps_splat_batch_free(&diff);
    ps_splat_batch_free(&none);

    /* Precision none, or a float buffer (levels 0) in any mode: the colours
     * as computed. */
    faint_build(&s, PS_PRECISION_NONE, 255, &none);
    for (int pr = 0; pr < PS_PRECISION_COUNT; pr++) {
        ps_splat_batch f;
        faint_build(&s, (ps_precision)pr, 0, &f);
        assert_memory_equal(f.colors, none.colors, 4 * none.vertex_count * sizeof(float));
        assert_true(ps_splat_batch_carry(&f, 0) == 0.0 && ps_splat_batch_carry(&f, 1) == 0.0 &&
                    ps_splat_batch_carry(&f, 2) == 0.0);
        assert_true(f.wanted == 0.0 && f.lost == 0.0);
        ps_splat_batch_free(&f);
    }
    assert_true(ps_splat_batch_carry(&none, 0) == 0.0 && none.wanted == 0.0);
    ps_splat_batch_free(&none);
    faint_free(&s);

    /* Varied colours (random powers up to 3 steps): still whole steps
     * summing to what was wanted. */
    faint_make(&s, 1.0 / L);
    for (size_t i = 0; i < FAINT_COUNT; i++) {
        ps_rng r = ps_rng_make(6, PS_STREAM_TEST, i);
        ps_rgb power = ps_rgb_make(3.0 * ps_rng_uniform(&r), 3.0 * ps_rng_uniform(&r), 3.0 * ps_rng_uniform(&r));
        s.ph[i] = ps_photon_pack(ps_photon_position(&s.ph[i]), power, ps_v3(0, 0, -1), ps_v3(0, 0, 1),
                                 ps_rng_uniform(&r));
    }
    faint_build(&s, PS_PRECISION_NONE, 255, &none);
    faint_build(&s, PS_PRECISION_DIFFUSION, 255, &diff);
    colour_sums(&none, wanted);
    colour_sums(&diff, got);
    for (int c = 0; c < 3; c++) {
        assert_true(wanted[c] > 0.3 * FAINT_COUNT * 3.0 / L);
        assert_near(got[c], wanted[c], 0.5 * PS_SPLAT_DIFFUSION_REGIONS / L);
        assert_near(got[c] + ps_splat_batch_carry(&diff, c), wanted[c], 1e-7 * wanted[c]);
    }
    for (size_t v = 0; v < diff.vertex_count; v++) {
        double q = diff.colors[4 * v + 1] * L;
        assert_true(fabs(q - round(q)) < 1e-4);
    }
    ps_splat_batch_free(&diff);
    ps_splat_batch_free(&none);
    faint_free(&s);
}

static void precision_counter(void **state)
{
    (void)state;
    const double L = 255.0;
    /* Below half a step everything rounds away; bright colours lose a
     * fraction of a step either way: 0.5 + 0.3 steps (127.8 steps) gains 0.2
     * of a step, 0.4 + 0.1 steps (102.1) loses 0.1, 0.2 (51) nothing. */
    static const double colours[] = {0.3 / L, 0.49 / L, 0.5 + 0.3 / L, 0.4 + 0.1 / L, 0.2};
    for (size_t k = 0; k < sizeof colours / sizeof colours[0]; k++) {
        faint_set s;
        faint_make(&s, colours[k]);
        ps_splat_batch none, cnt;
        faint_build(&s, PS_PRECISION_NONE, 255, &none);
        faint_build(&s, PS_PRECISION_COUNTER, 255, &cnt);
        /* Sent as computed. */
        assert_memory_equal(cnt.colors, none.colors, 4 * none.vertex_count * sizeof(float));
        assert_true(ps_splat_batch_carry(&cnt, 0) == 0.0 && ps_splat_batch_carry(&cnt, 1) == 0.0 &&
                    ps_splat_batch_carry(&cnt, 2) == 0.0);
        /* Wanted: every channel of every photon (not every vertex). */
        double sum[3];
        colour_sums(&none, sum);
        assert_near(cnt.wanted, sum[0] + sum[1] + sum[2], 1e-6 * cnt.wanted);
        assert_near(cnt.wanted, 3.0 * FAINT_COUNT * colours[k], 1e-6 * cnt.wanted);
        double ratio = cnt.lost / cnt.wanted;
        if (colours[k] < 0.5 / L)
            assert_near(ratio, 1.0, 1e-9);
        else
            assert_true(fabs(ratio) < 0.01);
        /* Exactly what rounding to the nearest step takes, signed (none of
         * these colours is near a tie). */
        double lost = 0.0;
        for (size_t i = 0; i < none.splats; i++)
            for (int c = 0; c < 3; c++) {
                double col = none.colors[4 * 3 * i + (size_t)c];
                assert_true(fabs(col * L - floor(col * L) - 0.5) > 0.005);
                lost += col - round(col * L) / L;
            }
        assert_near(cnt.lost, lost, 1e-6 * cnt.wanted);
        /* More photons, more counted. */
        build(s.ph, s.mat, FAINT_COUNT, &s.p, &cnt);
        assert_near(cnt.wanted, 6.0 * FAINT_COUNT * colours[k], 1e-6 * cnt.wanted);
        assert_near(cnt.lost / cnt.wanted, ratio, 1e-9);
        ps_splat_batch_free(&cnt);
        ps_splat_batch_free(&none);
        faint_free(&s);
    }
}

/* The progressive radius: r0 at the reference count, r^2 proportional to
 * n^(alpha - 1), so 64 times the photons with alpha 2/3 give 64^(-1/6) = 1/2
 * the radius; the growth for few photons is capped; fixed ignores n. */
static void radius_schedule(void **state)
{
    (void)state;
    const double r0 = 0.02, a = PS_RADIUS_ALPHA_DEFAULT;
    const uint64_t n0 = 200000;
    assert_float_equal(ps_splat_radius_at(PS_RADIUS_FIXED, r0, n0, 64 * n0, a), r0, 0.0);
    assert_float_equal(ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, r0, n0, n0, a), r0, 1e-15);
    assert_float_equal(ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, r0, n0, 64 * n0, a), r0 / 2.0, 1e-12);
    assert_float_equal(ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, r0, n0, n0 / 64, a), 2.0 * r0, 1e-12);
    /* r^2 n^(1 - alpha) is constant: the kernel's bias falls as n^(alpha - 1). */
    for (uint64_t n = 1000; n < 1000000000; n *= 7) {
        double r = ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, r0, n0, n, a);
        if (r < r0 * PS_RADIUS_GROWTH_MAX)
            assert_float_equal(r * r * pow((double)n, 1.0 - a), r0 * r0 * pow((double)n0, 1.0 - a), 1e-9 * r0 * r0 * pow((double)n0, 1.0 - a));
    }
    assert_float_equal(ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, r0, n0, 1, a), r0 * PS_RADIUS_GROWTH_MAX, 0.0);
    assert_float_equal(ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, r0, n0, 0, a), r0 * PS_RADIUS_GROWTH_MAX, 0.0);
    /* alpha 1: no shrinking; no reference count: r0. */
    assert_float_equal(ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, r0, n0, 1000 * n0, 1.0), r0, 1e-15);
    assert_float_equal(ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, r0, 0, 1000, a), r0, 0.0);
    assert_string_equal(ps_radius_schedule_name(PS_RADIUS_PROGRESSIVE), "progressive");
    assert_string_equal(ps_radius_schedule_name(PS_RADIUS_FIXED), "fixed");
}

/* The incremental budget's cost model: a splat of each map its own cost, so
 * that a refresh of cheap caustic splats alone does not set the budget of
 * the next, which draws the dearer global ones too. */
static void splat_cost_per_map(void **state)
{
    (void)state;
    const double tau = 0.09; /* a refresh's time for splats */
    const bool both[PS_MAP_COUNT] = {true, true}, caustic[PS_MAP_COUNT] = {true, false};
    ps_splat_cost c = {{0.0, 0.0}};
    assert_float_equal(ps_splat_cost_count(&c, both, tau), 0.0, 0.0); /* nothing known: the budget stays */
    /* The caustic map alone, 0.5 us a splat: what one rate for every splat
     * gave (rate * tau / PS_MAP_COUNT) where it is the only map drawing ... */
    ps_splat_cost_learn(&c, (const size_t[PS_MAP_COUNT]){4000, 0}, 0.002);
    assert_float_equal(c.seconds[PS_MAP_CAUSTIC], 0.5e-6, 1e-18);
    assert_float_equal(ps_splat_cost_count(&c, caustic, tau), 2e6 * tau / PS_MAP_COUNT, 1e-6);
    /* ... but not where the global map draws too, its cost not known: that
     * rate gave it 9*10^4 splats a map, 0.4 s at the global's 4 us. */
    assert_float_equal(ps_splat_cost_count(&c, both, tau), 0.0, 0.0);
    /* Both drawn: the global takes what the caustic's known cost leaves. */
    ps_splat_cost_learn(&c, (const size_t[PS_MAP_COUNT]){4000, 3000}, 0.014);
    assert_float_equal(c.seconds[PS_MAP_CAUSTIC], 0.5e-6, 1e-18);
    assert_float_equal(c.seconds[PS_MAP_GLOBAL], 4e-6, 1e-15);
    /* The count a map such that a refresh drawing it in both maps takes tau. */
    double count = ps_splat_cost_count(&c, both, tau);
    assert_float_equal(count, 2e4, 1e-6);
    assert_float_equal(count * (c.seconds[0] + c.seconds[1]), tau, 1e-12);
    /* Drawn together again, twice as slow as foreseen: both costs double,
     * their ratio kept. */
    ps_splat_cost_learn(&c, (const size_t[PS_MAP_COUNT]){2000, 2000}, 2.0 * 2000 * 4.5e-6);
    assert_float_equal(c.seconds[PS_MAP_CAUSTIC], 1e-6, 1e-15);
    assert_float_equal(c.seconds[PS_MAP_GLOBAL], 8e-6, 1e-15);
    /* Nothing drawn: nothing learned. */
    ps_splat_cost_learn(&c, (const size_t[PS_MAP_COUNT]){0, 0}, 1.0);
    assert_float_equal(c.seconds[PS_MAP_GLOBAL], 8e-6, 0.0);
    /* A map not known, where the known one leaves almost no time: the
     * refresh's mean, not the near-0 rest. */
    ps_splat_cost d = {{0.0, 0.0}};
    ps_splat_cost_learn(&d, (const size_t[PS_MAP_COUNT]){1000, 0}, 0.001);
    ps_splat_cost_learn(&d, (const size_t[PS_MAP_COUNT]){1000, 1000}, 0.0012);
    assert_float_equal(d.seconds[PS_MAP_CAUSTIC], 1e-6, 1e-18);
    assert_float_equal(d.seconds[PS_MAP_GLOBAL], 0.6e-6, 1e-18);
    /* Neither known, drawn together: their mean each (one rate, as before). */
    ps_splat_cost e = {{0.0, 0.0}};
    ps_splat_cost_learn(&e, (const size_t[PS_MAP_COUNT]){3000, 1000}, 0.008);
    assert_float_equal(e.seconds[PS_MAP_CAUSTIC], 2e-6, 1e-18);
    assert_float_equal(e.seconds[PS_MAP_GLOBAL], 2e-6, 1e-18);
    assert_float_equal(ps_splat_cost_count(&e, both, tau), (4000 / 0.008) * tau / PS_MAP_COUNT, 1e-6);
    /* A refresh timed at 0: a finite cost. */
    ps_splat_cost_learn(&e, (const size_t[PS_MAP_COUNT]){10, 0}, 0.0);
    assert_true(e.seconds[PS_MAP_CAUSTIC] > 0.0 && isfinite(ps_splat_cost_count(&e, caustic, tau)));
    const bool none[PS_MAP_COUNT] = {false, false};
    assert_float_equal(ps_splat_cost_count(&e, none, tau), 0.0, 0.0);
}

static void names(void **state)
{
    (void)state;
    assert_string_equal(ps_splat_mode_name(PS_SPLAT_POINTS), "points");
    assert_string_equal(ps_splat_mode_name(PS_SPLAT_TRIANGLES), "triangles");
    assert_string_equal(ps_splat_mode_name(PS_SPLAT_SPRITES), "sprites");
    assert_string_equal(ps_splat_mode_name(PS_SPLAT_MODE_COUNT), "?");
    assert_string_equal(ps_precision_name(PS_PRECISION_NONE), "none");
    assert_string_equal(ps_precision_name(PS_PRECISION_DIFFUSION), "diffusion");
    assert_string_equal(ps_precision_name(PS_PRECISION_COUNTER), "counter");
    assert_string_equal(ps_precision_name(PS_PRECISION_COUNT), "?");
}


/* The 8-bit kernel: a halftone of 0 and 255 only, whose density follows the
 * smooth kernel's weight ring by ring, with C (the mean weight over the
 * disc) within 1 % of the smooth texture's. */
static void halftone_texture(void **state)
{
    (void)state;
    ps_error err;
    for (int k = 0; k < PS_KERNEL_COUNT; k++) {
        ps_kernel_texture h, t;
        assert_int_equal(ps_kernel_texture_make_halftone((ps_kernel)k, PS_KERNEL_HALFTONE_SIZE, &h, &err), PS_OK);
        assert_int_equal(ps_kernel_texture_make((ps_kernel)k, PS_KERNEL_HALFTONE_SIZE, &t, &err), PS_OK);
        assert_true(h.halftone);
        assert_false(t.halftone);
        size_t n = (size_t)h.size * (size_t)h.size;
        double ring_on[4] = {0}, ring_weight[4] = {0};
        for (size_t i = 0; i < n; i++) {
            assert_true(h.alpha[i] == 0 || h.alpha[i] == 255);
            int x = (int)(i % (size_t)h.size), y = (int)(i / (size_t)h.size);
            double u = h.extent * (2.0 * (x + 0.5) / h.size - 1.0), v = h.extent * (2.0 * (y + 0.5) / h.size - 1.0);
            double r = sqrt(u * u + v * v);
            if (r >= 1.0)
                continue;
            int ring = (int)(4.0 * r);
            ring_on[ring] += h.alpha[i] / 255.0;
            ring_weight[ring] += t.alpha[i] / 255.0;
        }
        assert_near(h.mean, t.mean, 0.01 * t.mean);
        for (int ring = 0; ring < 4; ring++)
            if (ring_weight[ring] > 500.0) /* a ring with weight to count; each texel a Bernoulli draw: */
                assert_near(ring_on[ring], ring_weight[ring], 4.0 * sqrt(ring_weight[ring])); /* 4 sigma */
        ps_kernel_texture_free(&h);
        ps_kernel_texture_free(&t);
    }
}

/* Built on one thread or several, in every mode and precision: the same
 * bytes (the ranges and their sums do not depend on the threads). */
static void same_bytes_for_any_threads(void **state)
{
    (void)state;
    enum { N = 200000 };
    ps_photon *ph = malloc(N * sizeof *ph);
    uint16_t *mat = calloc(N, sizeof *mat);
    uint32_t *obj = malloc(N * sizeof *obj);
    assert_non_null(ph);
    assert_non_null(mat);
    assert_non_null(obj);
    ps_material m = diffuse(ps_rgb_make(0.5, 0.5, 0.5));
    for (size_t i = 0; i < N; i++) {
        ps_rng r = ps_rng_make(7, PS_STREAM_TEST, i);
        ps_vec3 at = ps_v3(2.0 * ps_rng_uniform(&r) - 1.0, 2.0 * ps_rng_uniform(&r) - 1.0, 0.0);
        /* A tenth facing away: skipped, so that the ranges' counts differ. */
        ps_vec3 n = i % 10 == 3 ? ps_v3(0, 0, -1) : ps_v3(0, 0, 1);
        ph[i] = ps_photon_pack(at, ps_rgb_make(1.0, 0.5, 0.25), ps_v3(0, 0, -1), n, 0.5);
        obj[i] = (uint32_t)(i % 7);
    }
    for (int mode = 0; mode < PS_SPLAT_MODE_COUNT; mode++)
        for (int pr = 0; pr < PS_PRECISION_COUNT; pr++) {
            ps_splat_params p = params((ps_splat_mode)mode, &m, frame(ps_v3(0, 0, 5), ps_v3(0, 0, 0), 640, 480));
            p.scale = 1e-4;
            p.levels = 255;
            p.precision = (ps_precision)pr;
            p.objects = obj;
            ps_splat_batch a, b;
            ps_splat_batch_init(&a);
            ps_splat_batch_init(&b);
            /* b's arrays in large pages (past 4 MiB: the triangles' 6.5 MB of
             * positions; their grouping copy, 19 MB): the same bytes. */
            b.large_pages = true;
            p.threads = 1;
            build(ph, mat, N, &p, &a);
            p.threads = 3;
            build(ph, mat, N, &p, &b);
            size_t built = N;
            if (mode == PS_SPLAT_TRIANGLES && pr == 0) { /* grown again, kept */
                build(ph, mat, N / 2, &p, &b);
                p.threads = 1;
                build(ph, mat, N / 2, &p, &a);
                built += N / 2;
            }
            assert_int_equal(a.splats, b.splats);
            assert_true(a.splats > built / 2 && a.splats < built);
            assert_memory_equal(a.positions, b.positions, 3 * a.vertex_count * sizeof(float));
            assert_memory_equal(a.colors, b.colors, 4 * a.vertex_count * sizeof(float));
            if (mode == PS_SPLAT_TRIANGLES)
                assert_memory_equal(a.texcoords, b.texcoords, 2 * a.vertex_count * sizeof(float));
            assert_memory_equal(a.group_first, b.group_first, sizeof a.group_first);
            assert_true(a.wanted == b.wanted && a.lost == b.lost);
            assert_memory_equal(a.carry, b.carry, sizeof a.carry);
            ps_splat_batch_free(&a);
            ps_splat_batch_free(&b);
        }
    free(ph);
    free(mat);
    free(obj);
}

/* Error diffusion runs in screen order (a Z-order curve over the splats'
 * pixels): the codes sent into any aligned 32 x 32 block of the screen add up
 * to what its photons asked for within one code, where index order (the
 * photons in random places) would leave a few codes of noise per block. */
static void diffusion_in_screen_order(void **state)
{
    (void)state;
    const double L = 255.0;
    faint_set s;
    faint_make(&s, 0.3 / L);
    s.p.mode = PS_SPLAT_POINTS;
    ps_splat_batch none, diff;
    ps_splat_batch_init(&none);
    ps_splat_batch_init(&diff);
    s.p.precision = PS_PRECISION_NONE;
    s.p.levels = 255;
    build(s.ph, s.mat, FAINT_COUNT, &s.p, &none);
    s.p.precision = PS_PRECISION_DIFFUSION;
    build(s.ph, s.mat, FAINT_COUNT, &s.p, &diff);
    assert_int_equal(none.splats, diff.splats);
    enum { BLOCK = 32, BX = 640 / BLOCK, BY = 480 / BLOCK };
    static double want[BY][BX], got[BY][BX];
    memset(want, 0, sizeof want);
    memset(got, 0, sizeof got);
    for (size_t i = 0; i < diff.splats; i++) {
        double x, y;
        ps_vec3 q = ps_v3(diff.positions[3 * i], diff.positions[3 * i + 1], diff.positions[3 * i + 2]);
        assert_true(ps_camera_project(&s.p.cam, q, &x, &y));
        int bx = (int)x / BLOCK, by = (int)y / BLOCK;
        assert_true(bx >= 0 && bx < BX && by >= 0 && by < BY);
        want[by][bx] += none.colors[4 * i] * L;
        got[by][bx] += diff.colors[4 * i] * L;
    }
    double worst = 0.0;
    int blocks = 0;
    for (int by = 0; by < BY; by++)
        for (int bx = 0; bx < BX; bx++)
            if (want[by][bx] > 0.0) {
                worst = fmax(worst, fabs(got[by][bx] - want[by][bx]));
                blocks++;
            }
    printf("screen-order diffusion: %d blocks, worst %.3f codes off what they asked for\n", blocks, worst);
    assert_true(blocks > 50);
    assert_true(worst <= 1.0 + 1e-3);
    ps_splat_batch_free(&none);
    ps_splat_batch_free(&diff);
    faint_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(kernel_texture),
        cmocka_unit_test(halftone_texture),
        cmocka_unit_test(diffusion_in_screen_order),
        cmocka_unit_test(same_bytes_for_any_threads), cmocka_unit_test(splat_basis),         cmocka_unit_test(triangles), cmocka_unit_test(sprites),
        cmocka_unit_test(points),         cmocka_unit_test(glossy),              cmocka_unit_test(back_faces),
        cmocka_unit_test(batches), cmocka_unit_test(groups),        cmocka_unit_test(precision_diffusion), cmocka_unit_test(precision_counter),
        cmocka_unit_test(names), cmocka_unit_test(radius_schedule), cmocka_unit_test(splat_cost_per_map),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
