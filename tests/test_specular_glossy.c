/* test_specular_glossy.c: the specular layer's glossy lobes, GL-free
 * (preview/specular_glossy.h): cube directions against GL's table of major
 * axes, a blurred level of a cube with one bright texel against a
 * brute-force convolution with the normalised Phong lobe and against the
 * lobe's closed form, the level of a uniform cube, a glossy vertex's lookup
 * and weight, and the splats' materials without the lobe. */
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "photon/world.h"
#include "preview/specular_glossy.h"
#include "scene/bsdf.h"
#include "scene/scene.h"

/* GL's rule (the spec's table of major axes): the face and (s, t) of d. */
static void gl_face_of(ps_vec3 d, int *face, double *s, double *t)
{
    double ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z), sc, tc, ma;
    if (ax >= ay && ax >= az) {
        *face = d.x > 0 ? 0 : 1;
        sc = d.x > 0 ? -d.z : d.z, tc = -d.y, ma = ax;
    } else if (ay >= az) {
        *face = d.y > 0 ? 2 : 3;
        sc = d.x, tc = d.y > 0 ? d.z : -d.z, ma = ay;
    } else {
        *face = d.z > 0 ? 4 : 5;
        sc = d.z > 0 ? d.x : -d.x, tc = -d.y, ma = az;
    }
    *s = 0.5 * (sc / ma + 1.0), *t = 0.5 * (tc / ma + 1.0);
}

static void cube_dirs_follow_gl(void **state)
{
    (void)state;
    uint64_t x = 12345;
    for (int i = 0; i < 1000; i++) {
        double c[3];
        for (int k = 0; k < 3; k++) {
            x = x * 6364136223846793005ull + 1442695040888963407ull;
            c[k] = (double)(x >> 11) / 9007199254740992.0 * 2.0 - 1.0;
        }
        ps_vec3 d = ps_v3_norm(ps_v3(c[0], c[1], c[2]));
        int f;
        double s, t;
        gl_face_of(d, &f, &s, &t);
        ps_vec3 e = ps_cube_dir(f, s, t);
        assert_near(ps_v3_dot(d, e), 1.0, 1e-12);
    }
}

/* The exact solid angle of [u0, u1] x [v0, v1] on the plane at unit
 * distance: the sum of atan(u v / sqrt(1 + u^2 + v^2)) over the corners. */
static double corner(double u, double v) { return atan2(u * v, sqrt(1.0 + u * u + v * v)); }
static double texel_omega(int n, int i, int j)
{
    double u0 = 2.0 * i / n - 1.0, u1 = 2.0 * (i + 1) / n - 1.0, v0 = 2.0 * j / n - 1.0, v1 = 2.0 * (j + 1) / n - 1.0;
    return corner(u1, v1) - corner(u0, v1) - corner(u1, v0) + corner(u0, v0);
}

/* A cube of n^2 faces, black but for texel (bi, bj) of face bf, radiance e. */
static float **bright_cube(int n, int bf, int bi, int bj, float e)
{
    float **faces = malloc(6 * sizeof *faces);
    for (int f = 0; f < 6; f++) {
        faces[f] = calloc(4 * (size_t)n * n, sizeof(float));
        for (size_t k = 0; k < (size_t)n * n; k++)
            faces[f][4 * k + 3] = 1.0f;
    }
    for (int c = 0; c < 3; c++)
        faces[bf][4 * ((size_t)bj * n + bi) + c] = e;
    return faces;
}

static void free_cube(float **faces)
{
    for (int f = 0; f < 6; f++)
        free(faces[f]);
    free(faces);
}

/* Brute force over every input texel: sum Omega cos^m L / sum Omega cos^m. */
static double brute(float **in, int n, double m, ps_vec3 o)
{
    double s = 0.0, w = 0.0;
    for (int f = 0; f < 6; f++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                double c = ps_v3_dot(o, ps_cube_dir(f, (i + 0.5) / n, (j + 0.5) / n));
                if (c <= 0.0)
                    continue;
                double k = texel_omega(n, i, j) * pow(c, m);
                s += k * in[f][4 * ((size_t)j * n + i)];
                w += k;
            }
    return s / w;
}

/* One bright texel: the level equals the brute-force convolution (within
 * 1 % of its peak where the level's texels are the input's, 5 % where it
 * takes 2 x 2 of them first), and near the peak the closed form of the
 * normalised lobe, E Omega cos^m(a) (m + 1) / (2 pi), within 3 %. */
static void check_bright(int in_size, int out_size, double m, double tol_brute)
{
    ps_error err;
    const int bf = 4, bi = in_size / 2 - 1, bj = in_size / 2 - 1;
    const float e = 1000.0f;
    float **in = bright_cube(in_size, bf, bi, bj, e);
    ps_glossy_filter *flt;
    assert_int_equal(ps_glossy_filter_create(in_size, out_size, m, &flt, &err), PS_OK);
    for (int f = 0; f < 6; f++)
        ps_glossy_filter_set_face(flt, f, in[f]);
    float *out = malloc(4 * (size_t)out_size * out_size * sizeof *out);
    ps_vec3 bright = ps_cube_dir(bf, (bi + 0.5) / in_size, (bj + 0.5) / in_size);
    double omega = texel_omega(in_size, bi, bj);
    double peak = 0.0, worst = 0.0, worst_form = 0.0;
    int near_peak = 0;
    for (int f = 0; f < 6; f++) {
        ps_glossy_filter_face(flt, f, out);
        for (int j = 0; j < out_size; j++)
            for (int i = 0; i < out_size; i++) {
                ps_vec3 o = ps_cube_dir(f, (i + 0.5) / out_size, (j + 0.5) / out_size);
                double got = out[4 * ((size_t)j * out_size + i)];
                double want = brute(in, in_size, m, o);
                peak = fmax(peak, want);
                worst = fmax(worst, fabs(got - want));
                double c = ps_v3_dot(o, bright);
                double form = c > 0.0 ? e * omega * pow(c, m) * (m + 1.0) / (2.0 * PS_PI) : 0.0;
                if (c > 0.0 && pow(c, m) > 0.5) { /* within the lobe's half maximum */
                    worst_form = fmax(worst_form, fabs(got / form - 1.0));
                    near_peak++;
                }
            }
    }
    print_message("bright texel, %d -> %d, m %g: peak %.4g, worst %.3f %% of it off the brute force, %d texels "
                  "near the peak worst %.2f %% off the closed form\n",
                  in_size, out_size, m, peak, 100.0 * worst / peak, near_peak, 100.0 * worst_form);
    assert_true(peak > 0.0);
    assert_true(worst < tol_brute * peak);
    assert_true(near_peak >= 1);
    if (in_size == out_size)
        assert_true(worst_form < 0.03);
    free(out);
    ps_glossy_filter_destroy(flt);
    free_cube(in);
}

static void bright_texel_same_size(void **state)
{
    (void)state;
    check_bright(16, 16, 11.0, 0.01);
    check_bright(16, 16, 3.0, 0.01);
}

static void bright_texel_averaged(void **state)
{
    (void)state;
    check_bright(32, 16, 11.0, 0.05);
}

/* A uniform cube stays uniform: the lobe is normalised (a furnace). */
static void uniform_cube_stays(void **state)
{
    (void)state;
    ps_error err;
    float **in = bright_cube(32, 0, 0, 0, 0.0f);
    for (int f = 0; f < 6; f++)
        for (size_t k = 0; k < 32 * 32; k++)
            for (int c = 0; c < 3; c++)
                in[f][4 * k + c] = 2.5f;
    ps_glossy_filter *flt;
    assert_int_equal(ps_glossy_filter_create(32, 16, 61.0, &flt, &err), PS_OK);
    for (int f = 0; f < 6; f++)
        ps_glossy_filter_set_face(flt, f, in[f]);
    float out[4 * 16 * 16];
    for (int f = 0; f < 6; f++) {
        ps_glossy_filter_face(flt, f, out);
        for (int k = 0; k < 16 * 16; k++)
            for (int c = 0; c < 3; c++)
                assert_near(out[4 * k + c], 2.5, 1e-5);
    }
    ps_glossy_filter_destroy(flt);
    free_cube(in);
}

static void level_sizes(void **state)
{
    (void)state;
    /* e + 1 = 61 (the design room's floor): half maximum at 8.7 degrees, a
     * lobe of 17.4 degrees wants 4 texels of 4.4: 20.7 texels a face, 32. */
    assert_int_equal(ps_glossy_level_size(61.0, 128), 32);
    assert_int_equal(ps_glossy_level_size(61.0, 16), 16);
    assert_int_equal(ps_glossy_level_size(2.0, 128), 8);
    assert_int_equal(ps_glossy_level_size(1000.0, 128), PS_GLOSSY_MAX_LEVEL);
    assert_int_equal(ps_glossy_level_size(11.0, 128), 16);
}

/* A glossy floor alone: the vertex's lookup is its mirror direction (far
 * away: nothing there), its weight specular (n . r). */
static void glossy_vertex_lookup(void **state)
{
    (void)state;
    ps_scene *s;
    ps_error err;
    const char *text = "camera eye 0 1 2 target 0 0 0 up 0 1 0 fov 40\n"
                       "material g glossy albedo 0.2 0.2 0.2 specular 0.3 0.4 0.5 exponent 40\n"
                       "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material g\n"
                       "light point position 0 2 0 power 1 1 1\n";
    assert_int_equal(ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err), PS_OK);
    ps_world *w;
    assert_int_equal(ps_world_create(s, NULL, &w, &err), PS_OK);
    size_t nm;
    const ps_material *mats = ps_scene_materials(s, &nm);
    ps_vec3 eye = ps_v3(0.3, 1.2, 1.5), p = ps_v3(0.1, 0.0, -0.2), n = ps_v3(0, 1, 0);
    ps_specular_term t[PS_SPECULAR_TERMS];
    double dropped;
    int k = ps_glossy_trace_point(w, mats, &mats[0], eye, p, n, ps_v3(0, 0, 0), t, &dropped);
    assert_int_equal(k, 1);
    ps_vec3 d = ps_v3_norm(ps_v3_sub(p, eye));
    ps_vec3 r = ps_reflect(d, n);
    assert_near(ps_v3_dot(ps_v3_norm(t[0].dir), r), 1.0, 1e-9);
    double cos_r = ps_v3_dot(r, n);
    assert_near(t[0].weight.r, 0.3 * cos_r, 1e-12);
    assert_near(t[0].weight.g, 0.4 * cos_r, 1e-12);
    assert_near(t[0].weight.b, 0.5 * cos_r, 1e-12);
    assert_near(dropped, 0.0, 0.0);
    assert_true(ps_glossy_wants(&mats[0]) && ps_specular_wants(&mats[0]));
    assert_near(ps_glossy_lobe_exponent(&mats[0]), 41.0, 0.0);
    ps_world_destroy(w);
    ps_scene_destroy(s);
}

static void splat_materials_lose_the_lobe(void **state)
{
    (void)state;
    ps_material m[3];
    memset(m, 0, sizeof m);
    m[0].type = PS_MAT_GLOSSY, m[0].albedo = ps_rgb_gray(0.3), m[0].specular = ps_rgb_gray(0.2), m[0].exponent = 9;
    m[1].type = PS_MAT_DIFFUSE, m[1].albedo = ps_rgb_gray(0.5);
    m[2].type = PS_MAT_MIRROR, m[2].reflectance = ps_rgb_gray(1.0);
    ps_material out[3];
    ps_glossy_diffuse_materials(m, 3, out);
    assert_near(out[0].specular.g, 0.0, 0.0);
    assert_near(out[0].albedo.g, 0.3, 0.0);
    assert_int_equal(out[0].type, PS_MAT_GLOSSY);
    assert_memory_equal(&out[1], &m[1], sizeof m[1]);
    assert_memory_equal(&out[2], &m[2], sizeof m[2]);
    assert_false(ps_glossy_wants(&m[1]) || ps_glossy_wants(&m[2]) || ps_glossy_wants(&out[0]));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cube_dirs_follow_gl),      cmocka_unit_test(bright_texel_same_size),
        cmocka_unit_test(bright_texel_averaged),    cmocka_unit_test(uniform_cube_stays),
        cmocka_unit_test(level_sizes),              cmocka_unit_test(glossy_vertex_lookup),
        cmocka_unit_test(splat_materials_lose_the_lobe),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
