/* test_photon.c: the photon record's encodings, the samplers, Fresnel and
 * refraction, and emission from every light type (distributions and flux). */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "photon/emit.h"
#include "photon/photon.h"
#include "scene/bsdf.h"
#include "scene/scene.h"

static ps_scene *scene_from(const char *text)
{
    ps_scene *s = NULL;
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    return s;
}

static double angle_deg(ps_vec3 a, ps_vec3 b) { return acos(fmin(1.0, fmax(-1.0, ps_v3_dot(a, b)))) * 180.0 / PS_PI; }

/* ---- the record ----------------------------------------------------------- */

static void record_is_20_bytes(void **state)
{
    (void)state;
    assert_true(sizeof(ps_photon) <= 20);
    ps_photon p = ps_photon_pack(ps_v3(1.5, -2.25, 1e-3), ps_rgb_make(0.5, 0.25, 0.125), ps_v3(0, -1, 0), ps_v3(0, 1, 0), 0.5);
    /* Positions are stored as floats: exact for these values. */
    assert_near(ps_photon_position(&p).x, 1.5, 0);
    assert_near(ps_photon_position(&p).y, -2.25, 0);
    assert_near(ps_photon_position(&p).z, (float)1e-3, 0);
    /* Powers of two are exact in RGBE. */
    assert_near(ps_photon_power(&p).r, 0.5, 0);
    assert_near(ps_photon_power(&p).b, 0.125, 0);
    assert_near(ps_photon_dir(&p).y, -1.0, 1e-12);
    assert_near(ps_photon_normal(&p).y, 1.0, 1e-12);
}

static void rgbe_round_trip(void **state)
{
    (void)state;
    ps_rng r = ps_rng_make(1, PS_STREAM_TEST, 0);
    double worst = 0.0, bias = 0.0;
    int n = 100000;
    for (int i = 0; i < n; i++) {
        double scale = pow(10.0, -12.0 + 18.0 * ps_rng_uniform(&r));
        ps_rgb c = ps_rgb_make(scale * ps_rng_uniform(&r), scale * ps_rng_uniform(&r), scale * ps_rng_uniform(&r));
        uint8_t e[4];
        ps_rgbe_encode(c, 0.5, e);
        ps_rgb d = ps_rgbe_decode(e);
        double m = ps_rgb_max(c);
        double err = fmax(fabs(d.r - c.r), fmax(fabs(d.g - c.g), fabs(d.b - c.b))) / m;
        worst = fmax(worst, err);
        bias += (ps_rgb_max(d) - m) / m;
    }
    /* Rounding to 8-bit mantissas: at most half a step of 1/256 of a value in [0.5, 1). */
    assert_true(worst <= 1.0 / 256.0 + 1e-12);
    assert_true(fabs(bias / n) < 1e-4);
    /* One value that rounding biases by +0.27 % (mantissa 153.58 -> 154):
     * dithered over many photons its mean is exact. */
    ps_rgb one = ps_rgb_gray(100.0 * (1.0 - sqrt(0.5)) / 2.0 / 200000.0);
    uint8_t e[4];
    ps_rgbe_encode(one, 0.5, e);
    assert_true(ps_rgbe_decode(e).g > one.g * 1.002);
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        ps_rgbe_encode(one, ps_rng_uniform(&r), e);
        sum += ps_rgbe_decode(e).g;
    }
    assert_near(sum / n, one.g, one.g * 1e-4);
    ps_rgbe_encode(ps_rgb_make(0, 0, 0), 0.5, e);
    assert_int_equal(e[3], 0);
    ps_rgbe_encode(ps_rgb_make(-1, NAN, 2.0), 0.5, e);
    assert_near(ps_rgbe_decode(e).r, 0, 0);
    assert_near(ps_rgbe_decode(e).g, 0, 0);
    assert_near(ps_rgbe_decode(e).b, 2.0, 0);
    /* 255.9/256 rounds up into the next exponent, not past 255. */
    ps_rgbe_encode(ps_rgb_make(0.9995, 0.5, 0), 0.5, e);
    assert_near(ps_rgbe_decode(e).r, 1.0, 1.0 / 256);
}

static void octahedral_directions(void **state)
{
    (void)state;
    ps_rng r = ps_rng_make(2, PS_STREAM_TEST, 0);
    double worst8 = 0.0, worst7 = 0.0, worst_photon = 0.0;
    for (int i = 0; i < 200000; i++) {
        ps_vec3 v = ps_sample_sphere(ps_rng_uniform(&r), ps_rng_uniform(&r));
        ps_vec3 d = ps_oct_decode_bits(ps_oct_encode_bits(v, 8), 8);
        assert_near(ps_v3_len(d), 1.0, 1e-12);
        worst8 = fmax(worst8, angle_deg(v, d));
        worst7 = fmax(worst7, angle_deg(v, ps_oct_decode_bits(ps_oct_encode_bits(v, 7), 7)));
        /* In a record, flags never disturb the normal. */
        ps_photon p = ps_photon_pack(ps_v3(0, 0, 0), ps_rgb_gray(1), v, v, 0.5);
        ps_photon_set_flags(&p, (unsigned)i & 3u);
        assert_int_equal(ps_photon_flags(&p), (unsigned)i & 3u);
        worst_photon = fmax(worst_photon, angle_deg(v, ps_photon_normal(&p)));
    }
    /* Best of four neighbours: 8 bits an axis under 0.75 degrees, 7 under 1.5. */
    assert_true(worst8 < 0.75);
    assert_true(worst8 > 0.1); /* it is quantised: the test would notice a lossless fake */
    assert_true(worst7 < 1.5);
    assert_near(worst_photon, worst7, 1e-9);
    ps_vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int k = 0; k < 6; k++)
        for (int bits = 7; bits <= 8; bits++)
            assert_true(angle_deg(axes[k], ps_oct_decode_bits(ps_oct_encode_bits(axes[k], bits), bits)) < 1e-6);
}

/* ---- Fresnel and refraction --------------------------------------------- */

static void fresnel_values(void **state)
{
    (void)state;
    /* ((n - 1) / (n + 1))^2 at normal incidence: 0.04 for glass, either way through. */
    assert_near(ps_fresnel_dielectric(1.0, 1.0, 1.5), 0.04, 1e-15);
    assert_near(ps_fresnel_dielectric(1.0, 1.5, 1.0), 0.04, 1e-15);
    assert_near(ps_fresnel_dielectric(0.0, 1.0, 1.5), 1.0, 1e-12); /* grazing */
    /* Inside glass beyond the critical angle asin(1/1.5): total internal reflection. */
    double crit = asin(1.0 / 1.5);
    assert_near(ps_fresnel_dielectric(cos(crit + 0.01), 1.5, 1.0), 1.0, 0);
    assert_true(ps_fresnel_dielectric(cos(crit - 0.01), 1.5, 1.0) < 1.0);
    /* Brewster's angle atan(1.5): the parallel part vanishes, R = R_perp / 2. */
    double b = atan(1.5), ct = cos(asin(sin(b) / 1.5));
    double rs = (cos(b) - 1.5 * ct) / (cos(b) + 1.5 * ct);
    assert_near(ps_fresnel_dielectric(cos(b), 1.0, 1.5), 0.5 * rs * rs, 1e-12);
}

static void snell(void **state)
{
    (void)state;
    ps_vec3 n = ps_v3(0, 1, 0);
    for (int k = 1; k < 89; k += 7) {
        double th = k * PS_PI / 180.0;
        ps_vec3 d = ps_v3(sin(th), -cos(th), 0), t;
        assert_true(ps_refract(d, n, 1.0 / 1.5, &t));
        assert_near(t.x, sin(th) / 1.5, 1e-12); /* sin theta_t = sin theta_i / n */
        assert_true(t.y < 0);
        assert_near(ps_v3_len(t), 1.0, 1e-12);
        /* Leaving glass: TIR beyond the critical angle. */
        bool ok = ps_refract(d, n, 1.5, &t);
        assert_int_equal(ok, sin(th) * 1.5 < 1.0);
    }
    ps_vec3 r = ps_reflect(ps_v3_norm(ps_v3(1, -1, 0)), n);
    assert_near(r.x, sqrt(0.5), 1e-15);
    assert_near(r.y, sqrt(0.5), 1e-15);
}

/* ---- samplers ------------------------------------------------------------- */

static void samplers(void **state)
{
    (void)state;
    ps_rng r = ps_rng_make(3, PS_STREAM_TEST, 0);
    ps_vec3 n = ps_v3_norm(ps_v3(0.3, -0.5, 0.8));
    int N = 200000;
    double cos_sum = 0, cone_min = 1, cone_sum = 0, phong_sum = 0, sph_z2 = 0;
    ps_vec3 sph_mean = {0, 0, 0};
    double cmax = cos(25.0 * PS_PI / 180.0), e = 20.0;
    for (int i = 0; i < N; i++) {
        double u1 = ps_rng_uniform(&r), u2 = ps_rng_uniform(&r);
        ps_vec3 c = ps_sample_cosine(u1, u2, n);
        assert_true(ps_v3_dot(c, n) >= 0);
        cos_sum += ps_v3_dot(c, n);
        ps_vec3 k = ps_sample_cone(u1, u2, n, cmax);
        cone_min = fmin(cone_min, ps_v3_dot(k, n));
        cone_sum += ps_v3_dot(k, n);
        phong_sum += ps_v3_dot(ps_sample_phong(u1, u2, n, e), n);
        ps_vec3 s = ps_sample_sphere(u1, u2);
        sph_mean = ps_v3_add(sph_mean, s);
        sph_z2 += s.z * s.z;
    }
    assert_near(cos_sum / N, 2.0 / 3.0, 0.003);           /* E[cos] under cos/pi */
    assert_true(cone_min >= cmax - 1e-12);
    assert_near(cone_sum / N, (1.0 + cmax) / 2.0, 0.001); /* uniform in cos theta */
    assert_near(phong_sum / N, (e + 1.0) / (e + 2.0), 0.001);
    assert_near(ps_v3_len(sph_mean) / N, 0.0, 0.006);
    assert_near(sph_z2 / N, 1.0 / 3.0, 0.003);
    assert_near(ps_cone_solid_angle(-1.0), 4.0 * PS_PI, 1e-12);
}

/* ---- emission ------------------------------------------------------------- */

typedef struct emit_moments {
    double power_r;     /* mean power, red */
    ps_vec3 mean_dir, mean_pos;
    double mean_cos;    /* against `axis` */
    double min_cos;
    double mean_r2;     /* |pos - center|^2 */
    double min_r, max_r;
    int count;
} emit_moments;

static emit_moments emit_many(const ps_scene *s, uint32_t light, const ps_caustic_cone *cone, ps_vec3 axis_or_zero,
                              ps_vec3 center, int n)
{
    ps_light_sampler *ls;
    ps_error err;
    assert_int_equal(ps_light_sampler_create(s, &ls, &err), PS_OK);
    emit_moments m;
    memset(&m, 0, sizeof m);
    m.min_cos = 2;
    m.min_r = INFINITY;
    ps_rng r = ps_rng_make(4, PS_STREAM_TEST, light);
    for (int i = 0; i < n; i++) {
        double u[4] = {ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r)};
        ps_emission e;
        if (!ps_light_emit(ls, light, cone, u, &e))
            continue;
        m.count++;
        m.power_r += e.power.r;
        m.mean_dir = ps_v3_add(m.mean_dir, e.ray.d);
        m.mean_pos = ps_v3_add(m.mean_pos, e.ray.o);
        ps_vec3 axis = ps_v3_len2(axis_or_zero) > 0 ? axis_or_zero : e.normal;
        double c = ps_v3_dot(e.ray.d, axis);
        m.mean_cos += c;
        m.min_cos = fmin(m.min_cos, c);
        double r2 = ps_v3_len2(ps_v3_sub(e.ray.o, center));
        m.mean_r2 += r2;
        m.min_r = fmin(m.min_r, sqrt(r2));
        m.max_r = fmax(m.max_r, sqrt(r2));
    }
    m.power_r /= n; /* over all samples, the empty ones included: what the estimator sees */
    m.mean_dir = ps_v3_scale(m.mean_dir, 1.0 / m.count);
    m.mean_pos = ps_v3_scale(m.mean_pos, 1.0 / m.count);
    m.mean_cos /= m.count;
    m.mean_r2 /= m.count;
    ps_light_sampler_destroy(ls);
    return m;
}

static const char lights_scene[] =
    "camera eye 0 1 4 target 0 1 0\n"
    "quad corner -5 0 -5 edge1 10 0 0 edge2 0 0 10\n"
    "light point position 0 1 0 power 100 50 25\n"                                         /* 0 */
    "light spot position 0 2 0 direction 0 -1 0 angle 30 power 40 40 40\n"                 /* 1 */
    "light quad corner -0.25 1.9 -0.25 edge1 0.5 0 0 edge2 0 0 0.5 power 80 80 80\n"       /* 2: faces down */
    "light disc center 1 1.5 0 normal 0 -1 0 radius 0.2 power 30 30 30\n"                  /* 3 */
    "light sphere center -1 1 0 radius 0.1 power 60 60 60\n";                              /* 4 */

static void point_and_spot(void **state)
{
    (void)state;
    ps_scene *s = scene_from(lights_scene);
    int n = 200000;
    emit_moments p = emit_many(s, 0, NULL, ps_v3(0, 1, 0), ps_v3(0, 1, 0), n);
    assert_near(p.power_r, 100.0, 1e-9); /* every photon carries the whole flux */
    assert_near(ps_v3_len(p.mean_dir), 0.0, 0.006); /* uniform over the sphere */
    assert_near(p.max_r, 0.0, 0);
    emit_moments sp = emit_many(s, 1, NULL, ps_v3(0, -1, 0), ps_v3(0, 2, 0), n);
    double c30 = cos(30.0 * PS_PI / 180.0);
    assert_near(sp.power_r, 40.0, 1e-9);
    assert_true(sp.min_cos >= c30 - 1e-12);
    assert_near(sp.mean_cos, (1.0 + c30) / 2.0, 0.001); /* uniform inside the cone */
    ps_scene_destroy(s);
}

static void area_lights(void **state)
{
    (void)state;
    ps_scene *s = scene_from(lights_scene);
    int n = 200000;
    emit_moments q = emit_many(s, 2, NULL, ps_v3(0, 0, 0), ps_v3(0, 1.9, 0), n);
    assert_near(q.power_r, 80.0, 1e-9);
    assert_true(q.min_cos >= 0.0);            /* one-sided, towards edge1 x edge2 = -y */
    assert_near(q.mean_cos, 2.0 / 3.0, 0.003); /* Lambertian */
    assert_near(q.mean_dir.y, -2.0 / 3.0, 0.003);
    assert_near(q.mean_pos.x, 0.0, 0.002);     /* uniform over the quad */
    assert_near(q.mean_pos.y, 1.9, 1e-9);
    assert_near(q.mean_r2, 2.0 * 0.25 * 0.25 / 3.0, 0.001); /* E[x^2 + z^2] for a 0.5 square */
    assert_true(q.max_r <= sqrt(2.0) * 0.25 + 1e-12);

    emit_moments d = emit_many(s, 3, NULL, ps_v3(0, 0, 0), ps_v3(1, 1.5, 0), n);
    assert_near(d.power_r, 30.0, 1e-9);
    assert_near(d.mean_cos, 2.0 / 3.0, 0.003);
    assert_near(d.mean_dir.y, -2.0 / 3.0, 0.003);
    assert_near(d.mean_r2, 0.2 * 0.2 / 2.0, 0.0003); /* uniform over the disc */
    assert_true(d.max_r <= 0.2 + 1e-12);

    emit_moments sph = emit_many(s, 4, NULL, ps_v3(0, 0, 0), ps_v3(-1, 1, 0), n);
    assert_near(sph.power_r, 60.0, 1e-9);
    assert_near(sph.min_r, 0.1, 1e-12); /* on the surface */
    assert_near(sph.max_r, 0.1, 1e-12);
    assert_true(sph.min_cos >= 0.0);    /* outward, Lambertian */
    assert_near(sph.mean_cos, 2.0 / 3.0, 0.003);
    assert_near(ps_v3_len(ps_v3_sub(sph.mean_pos, ps_v3(-1, 1, 0))), 0.0, 0.001);
    ps_scene_destroy(s);
}

static void mesh_light(void **state)
{
    (void)state;
    char obj[1024], mtl[1024];
    snprintf(obj, sizeof obj, "%s", test_path("panel.obj"));
    snprintf(mtl, sizeof mtl, "%s", test_path("panel.mtl"));
    FILE *f = fopen(mtl, "w");
    fprintf(f, "newmtl glow\nKd 0.5 0.5 0.5\nKe 2 2 2\n");
    fclose(f);
    f = fopen(obj, "w");
    /* Two faces facing -y, areas 0.5 and 1.5 (x in [0,1] and [2,5]). */
    fprintf(f, "mtllib panel.mtl\nusemtl glow\n"
               "v 0 1 0\nv 0 1 1\nv 1 1 0\nv 2 1 0\nv 2 1 1\nv 5 1 0\n"
               "f 1 3 2\nf 4 6 5\n");
    fclose(f);
    char text[512];
    snprintf(text, sizeof text, "camera eye 0 0 5 target 0 0 0\nmesh %s\n", "panel.obj");
    ps_scene *s = NULL;
    ps_error err;
    char dir[1024];
    memcpy(dir, obj, sizeof dir);
    *strrchr(dir, '/') = '\0';
    if (ps_scene_load_text(text, "mesh.scn", dir, NULL, &s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    size_t nl;
    const ps_light *L = ps_scene_lights(s, &nl);
    assert_int_equal(nl, 1);
    assert_near(L[0].power.r, PS_PI * 2.0 * 2.0, 1e-12); /* pi * area * Ke */
    ps_light_sampler *ls;
    assert_int_equal(ps_light_sampler_create(s, &ls, &err), PS_OK);
    ps_rng r = ps_rng_make(5, PS_STREAM_TEST, 0);
    int n = 100000, second = 0;
    double cos_sum = 0;
    for (int i = 0; i < n; i++) {
        double u[4] = {ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r)};
        ps_emission e;
        assert_true(ps_light_emit(ls, 0, NULL, u, &e));
        assert_near(e.ray.o.y, 1.0, 1e-12);
        second += e.ray.o.x >= 2.0;
        cos_sum += -e.ray.d.y;
        assert_true(e.ray.d.y <= 0.0);
    }
    assert_near((double)second / n, 0.75, 0.005); /* faces chosen by area */
    assert_near(cos_sum / n, 2.0 / 3.0, 0.004);
    ps_light_sampler_destroy(ls);
    ps_scene_destroy(s);
}

/* Inside a cone, the expected power that reaches a target equals what the
 * light's own distribution sends there: the cone changes variance, not flux. */
static double flux_into_sphere(const ps_light_sampler *ls, uint32_t l, const ps_caustic_cone *cone, ps_vec3 c,
                               double rad, int n)
{
    ps_rng r = ps_rng_make(6, PS_STREAM_TEST, l * 2 + (cone != NULL));
    double sum = 0;
    for (int i = 0; i < n; i++) {
        double u[4] = {ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r)};
        ps_emission e;
        if (!ps_light_emit(ls, l, cone, u, &e))
            continue;
        ps_vec3 oc = ps_v3_sub(c, e.ray.o);
        double b = ps_v3_dot(oc, e.ray.d);
        if (b > 0 && ps_v3_len2(oc) - b * b <= rad * rad)
            sum += e.power.r;
    }
    return sum / n;
}

static void cones_keep_flux(void **state)
{
    (void)state;
    ps_scene *s = scene_from(lights_scene);
    ps_light_sampler *ls;
    ps_error err;
    assert_int_equal(ps_light_sampler_create(s, &ls, &err), PS_OK);
    ps_vec3 target = ps_v3(0.3, 0.3, 0.2);
    double rad = 0.15;
    /* Point light: analytic, P * Omega / (4 pi) with Omega = 2 pi (1 - cos). */
    ps_caustic_cone cone;
    assert_true(ps_light_caustic_cone(ls, 0, target, rad, &cone));
    double d = ps_v3_len(ps_v3_sub(target, ps_v3(0, 1, 0)));
    double exact = 100.0 * (1.0 - sqrt(1.0 - rad * rad / (d * d))) / 2.0;
    assert_near(flux_into_sphere(ls, 0, &cone, target, rad, 400000), exact, exact * 0.01);
    assert_near(flux_into_sphere(ls, 0, NULL, target, rad, 400000), exact, exact * 0.03);
    /* Spot, quad, disc and sphere lights: cone against own distribution. */
    for (uint32_t l = 1; l <= 4; l++) {
        assert_true(ps_light_caustic_cone(ls, l, target, rad, &cone));
        double with = flux_into_sphere(ls, l, &cone, target, rad, 400000);
        double without = flux_into_sphere(ls, l, NULL, target, rad, 1600000);
        if (fabs(with - without) > 0.03 * without)
            fail_msg("light %u: %g W into the sphere with the cone, %g W without", l, with, without);
    }
    /* Empty cones: behind the one-sided quad light, and outside the spot. */
    assert_false(ps_light_caustic_cone(ls, 2, ps_v3(0, 3, 0), 0.2, &cone));
    assert_true(ps_light_caustic_cone(ls, 2, ps_v3(0, 2.0, 0), 0.2, &cone)); /* straddles its plane */
    assert_false(ps_light_caustic_cone(ls, 1, ps_v3(3, 0, 0), 0.1, &cone));
    assert_false(ps_light_caustic_cone(ls, 1, ps_v3(0, 3, 0), 0.1, &cone));
    /* Inside the widened sphere: every direction. */
    assert_true(ps_light_caustic_cone(ls, 0, ps_v3(0, 1.1, 0), 0.2, &cone));
    assert_near(cone.cos_half, -1.0, 0);
    ps_light_sampler_destroy(ls);
    ps_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(record_is_20_bytes), cmocka_unit_test(rgbe_round_trip),
        cmocka_unit_test(octahedral_directions), cmocka_unit_test(fresnel_values),
        cmocka_unit_test(snell), cmocka_unit_test(samplers),
        cmocka_unit_test(point_and_spot), cmocka_unit_test(area_lights),
        cmocka_unit_test(mesh_light), cmocka_unit_test(cones_keep_flux),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
