/* test_estimate.c: density estimation over a photon map: the kernels and
 * their means, irradiance on a uniformly lit plane (closed form) for every
 * kernel, the estimate against a brute-force oracle of its formula, radiance
 * over diffuse and glossy materials, the search radius as the area when fewer
 * than k photons are found, and Christensen's precomputed irradiance (thread
 * count invariance, stride, values, nearest lookup). */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "photon/estimate.h"
#include "photon/kdtree.h"
#include "photon/photon.h"
#include "scene/bsdf.h"
#include "scene/scene.h"

/* The estimate against its own formula evaluated by the oracle: the same
 * doubles summed in another order. */
#define ORACLE_REL_TOL 1e-10
#define MAX_K 200

static ps_kdtree *build(const ps_photon *ph, size_t n)
{
    ps_kdtree *t = NULL;
    ps_error err;
    if (ps_kdtree_build(ph, n, &t, &err) != PS_OK)
        fail_msg("build: %s", err.msg);
    return t;
}

static double rel_err(double a, double b) { return fabs(a - b) / fmax(fabs(b), 1e-300); }

static void assert_rgb_rel(ps_rgb got, ps_rgb want, double tol, const char *what)
{
    double e = fmax(rel_err(got.r, want.r), fmax(rel_err(got.g, want.g), rel_err(got.b, want.b)));
    if (!(e <= tol))
        fail_msg("%s: got (%.10g, %.10g, %.10g), expected (%.10g, %.10g, %.10g): relative error %g > %g", what, got.r,
                 got.g, got.b, want.r, want.g, want.b, e, tol);
}

static ps_material material(ps_material_type type, ps_rgb albedo, ps_rgb specular, double exponent)
{
    ps_material m;
    memset(&m, 0, sizeof m);
    m.type = type;
    m.albedo = albedo;
    m.specular = specular;
    m.exponent = exponent;
    return m;
}

/* n photons uniform over the unit square [0, 1]^2 of the plane y = 0 (x, z),
 * with the given normal, travelling along dir, total power `total`, dithered
 * like the tracer's so that the stored total is unbiased. */
static void plane_photons(ps_photon *ph, size_t n, uint64_t seed, ps_vec3 normal, ps_vec3 dir, ps_rgb total)
{
    ps_rgb each = ps_rgb_scale(total, 1.0 / (double)n);
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(seed, PS_STREAM_TEST, i);
        ps_vec3 p = ps_v3(ps_rng_uniform(&r), 0.0, ps_rng_uniform(&r));
        ph[i] = ps_photon_pack(p, each, dir, normal, ps_rng_uniform(&r));
    }
}

/* ---- kernels ------------------------------------------------------------------ */

static void kernels(void **state)
{
    (void)state;
    assert_string_equal(ps_kernel_name(PS_KERNEL_BOX), "box");
    assert_string_equal(ps_kernel_name(PS_KERNEL_CONE), "cone");
    assert_string_equal(ps_kernel_name(PS_KERNEL_GAUSS), "gauss");
    assert_string_equal(ps_kernel_name(PS_KERNEL_EPANECHNIKOV), "epanechnikov");
    /* Closed forms the header states. */
    assert_near(ps_kernel_mean(PS_KERNEL_BOX), 1.0, 1e-15);
    assert_near(ps_kernel_mean(PS_KERNEL_CONE), 1.0 / 3.0, 1e-15);
    assert_near(ps_kernel_mean(PS_KERNEL_EPANECHNIKOV), 0.5, 1e-15);
    for (int k = 0; k < PS_KERNEL_COUNT; k++) {
        ps_kernel kk = (ps_kernel)k;
        assert_near(ps_kernel_profile(kk, 0.0), 1.0, 1e-15);
        if (kk != PS_KERNEL_BOX)
            assert_near(ps_kernel_profile(kk, 1.0), 0.0, 1e-15);
        else
            assert_near(ps_kernel_profile(kk, 1.0), 1.0, 0);
        /* Zero outside [0, 1]. */
        assert_near(ps_kernel_profile(kk, -1e-9), 0.0, 0);
        assert_near(ps_kernel_profile(kk, 1.0 + 1e-9), 0.0, 0);
        assert_near(ps_kernel_profile(kk, 3.0), 0.0, 0);
        assert_near(ps_kernel_profile(kk, NAN), 0.0, 0);
        /* C = 2 int_0^1 g(s) s ds by Simpson's rule (error ~ h^4: 1e-16). */
        const int steps = 20000;
        double h = 1.0 / steps, sum = 0.0, prev = 2.0;
        for (int i = 0; i <= steps; i++) {
            double s = i * h, g = ps_kernel_profile(kk, s);
            double w = (i == 0 || i == steps) ? 1.0 : (i % 2 ? 4.0 : 2.0);
            sum += w * 2.0 * g * s;
            /* Non-increasing and within [0, 1]. */
            assert_true(g <= prev && g >= 0.0 && g <= 1.0);
            prev = g;
        }
        if (fabs(sum * h / 3.0 - ps_kernel_mean(kk)) > 1e-6)
            fail_msg("%s: mean %.10g, integral %.10g", ps_kernel_name(kk), ps_kernel_mean(kk), sum * h / 3.0);
    }
}

/* ---- irradiance on a uniformly lit plane -------------------------------------------- */

/* N photons of total power P spread uniformly over a 1 m^2 square: E = P / 1 m^2.
 * With k = 100 the k-th neighbour is about r = sqrt(100 / (pi N)) = 0.0126
 * away; the 20 x 20 query grid, 0.04 apart over [0.1, 0.9]^2, keeps every
 * disc clear of the edges and of its neighbours' discs, so the 400 estimates
 * are independent. None is biased where the density is uniform (the k-th
 * photon sits on the rim: the smooth kernels weight it 0, the box estimate
 * leaves it out, and E[(k - 1) / (pi lambda r_k^2)] = 1). Each has a relative
 * standard deviation of about 1/sqrt(k) = 10% (box) to ~16% (cone), so their
 * mean about 0.5-0.8%. A 3% tolerance is well over three standard
 * deviations; a wrong C, a wrong area or a lost photon is off by far more. */
#define PLANE_N 200000
#define PLANE_K 100
#define PLANE_GRID 20
#define PLANE_TOL 0.03

static ps_rgb mean_over_grid(const ps_kdtree *t, ps_vec3 n, const ps_estimate_options *o, ps_rgb *each)
{
    ps_neighbor scratch[MAX_K];
    ps_rgb sum = ps_rgb_gray(0.0);
    for (int i = 0; i < PLANE_GRID; i++)
        for (int j = 0; j < PLANE_GRID; j++) {
            ps_vec3 p = ps_v3(0.1 + 0.8 * (i + 0.5) / PLANE_GRID, 0.0, 0.1 + 0.8 * (j + 0.5) / PLANE_GRID);
            ps_rgb e = ps_photon_irradiance(t, p, n, o, scratch);
            if (each)
                each[i * PLANE_GRID + j] = e;
            sum = ps_rgb_add(sum, e);
        }
    return ps_rgb_scale(sum, 1.0 / (PLANE_GRID * PLANE_GRID));
}

static void irradiance_on_plane(void **state)
{
    (void)state;
    const ps_rgb power = ps_rgb_make(100.0, 60.0, 30.0); /* on 1 m^2: E = P */
    ps_photon *ph = malloc(2 * PLANE_N * sizeof *ph);
    ps_rgb *ea = malloc(PLANE_GRID * PLANE_GRID * sizeof *ea), *eb = malloc(PLANE_GRID * PLANE_GRID * sizeof *eb);
    assert_non_null(ph);
    assert_non_null(ea);
    assert_non_null(eb);
    plane_photons(ph, PLANE_N, 1, ps_v3(0, 1, 0), ps_v3_norm(ps_v3(0.3, -1, 0.2)), power);
    /* The same number on the same plane lit from below, three times as bright. */
    plane_photons(ph + PLANE_N, PLANE_N, 2, ps_v3(0, -1, 0), ps_v3_norm(ps_v3(0.1, 1, -0.4)), ps_rgb_scale(power, 3.0));
    ps_kdtree *top = build(ph, PLANE_N), *both = build(ph, 2 * PLANE_N);
    for (int k = 0; k < PS_KERNEL_COUNT; k++) {
        ps_estimate_options o = {PLANE_K, 0.1, (ps_kernel)k};
        char what[64];
        snprintf(what, sizeof what, "%s kernel, E on the plane", ps_kernel_name((ps_kernel)k));
        ps_rgb e = mean_over_grid(top, ps_v3(0, 1, 0), &o, ea);
        assert_rgb_rel(e, power, PLANE_TOL, what);
        /* Photons on the far side are never gathered: the same photons, the
         * same estimate at every point (summed perhaps in another order). */
        mean_over_grid(both, ps_v3(0, 1, 0), &o, eb);
        for (int i = 0; i < PLANE_GRID * PLANE_GRID; i++)
            assert_rgb_rel(eb[i], ea[i], 1e-12, "photons facing away changed the estimate");
        snprintf(what, sizeof what, "%s kernel, E under the plane", ps_kernel_name((ps_kernel)k));
        assert_rgb_rel(mean_over_grid(both, ps_v3(0, -1, 0), &o, NULL), ps_rgb_scale(power, 3.0), PLANE_TOL, what);
    }
    /* Counting the rim photon would bias the box estimate by k / (k - 1):
     * 1% at k = 100, lost in the noise above, but 11% at k = 10. There
     * r = 0.004, so 80 x 80 queries 0.01 apart are still independent; each
     * varies by 1/sqrt(k - 2) = 35%, their mean by 0.45%: within 2% of P. */
    ps_estimate_options box = {10, 0.1, PS_KERNEL_BOX};
    ps_neighbor scratch[MAX_K];
    double sum = 0.0;
    const int fine = 80;
    for (int i = 0; i < fine; i++)
        for (int j = 0; j < fine; j++) {
            ps_vec3 p = ps_v3(0.1 + 0.8 * (i + 0.5) / fine, 0.0, 0.1 + 0.8 * (j + 0.5) / fine);
            sum += ps_photon_irradiance(top, p, ps_v3(0, 1, 0), &box, scratch).r;
        }
    assert_near(sum / (fine * fine) / power.r, 1.0, 0.02);
    ps_kdtree_destroy(top);
    ps_kdtree_destroy(both);
    free(ea);
    free(eb);
    free(ph);
}

/* ---- the estimate against its formula -------------------------------------------- */

typedef struct cand {
    double d2;
    size_t i;
} cand;

static int cmp_cand(const void *a, const void *b)
{
    double x = ((const cand *)a)->d2, y = ((const cand *)b)->d2;
    return x < y ? -1 : x > y;
}

/* sum_p f_p dPhi_p g(d_p / r) / (C pi r^2) over the k nearest input photons
 * facing n (all of them within max_radius if fewer), r the k-th distance or
 * max_radius; f = 1 (irradiance) when m is NULL. Sorts all candidates. */
static ps_rgb oracle(const ps_photon *ph, size_t n, ps_vec3 p, ps_vec3 nrm, const ps_estimate_options *o,
                     const ps_material *m, ps_vec3 wo)
{
    cand *c = malloc((n ? n : 1) * sizeof *c);
    assert_non_null(c);
    size_t nc = 0;
    double max_d2 = o->max_radius * o->max_radius;
    for (size_t i = 0; i < n; i++) {
        double dx = ph[i].pos[0] - p.x, dy = ph[i].pos[1] - p.y, dz = ph[i].pos[2] - p.z;
        double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 <= max_d2 && ps_v3_dot(ps_photon_normal(&ph[i]), nrm) > PS_ESTIMATE_MIN_COS)
            c[nc++] = (cand){d2, i};
    }
    qsort(c, nc, sizeof *c, cmp_cand);
    size_t found = nc < o->k ? nc : o->k;
    double r2 = found == o->k ? c[found - 1].d2 : max_d2;
    /* The box estimate leaves out the k-th photon, which sits on the rim
     * (estimate.c: unbiased where the density is uniform). */
    size_t used = found == o->k && o->k > 1 && o->kernel == PS_KERNEL_BOX ? found - 1 : found;
    ps_rgb sum = ps_rgb_gray(0.0);
    for (size_t j = 0; j < used; j++) {
        const ps_photon *q = &ph[c[j].i];
        ps_rgb f = m ? ps_bsdf_eval(m, nrm, ps_photon_dir(q), wo) : ps_rgb_gray(1.0);
        double g = ps_kernel_profile(o->kernel, sqrt(c[j].d2 / r2));
        sum = ps_rgb_add(sum, ps_rgb_scale(ps_rgb_mul(f, ps_photon_power(q)), g));
    }
    free(c);
    return found ? ps_rgb_scale(sum, 1.0 / (ps_kernel_mean(o->kernel) * PS_PI * r2)) : sum;
}

static void estimate_matches_formula(void **state)
{
    (void)state;
    /* A bumpy cluster: photons of random power, direction and normal (either
     * side of a plane, and some in between). */
    const size_t n = 3000;
    ps_photon *ph = malloc(n * sizeof *ph);
    assert_non_null(ph);
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(61, PS_STREAM_TEST, i);
        ps_vec3 p = ps_v3(ps_rng_uniform(&r), 0.05 * ps_rng_uniform(&r), ps_rng_uniform(&r));
        ps_vec3 nrm = ps_v3_norm(ps_v3(ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5));
        if (i % 3 < 2)
            nrm = i % 3 ? ps_v3(0, -1, 0) : ps_v3(0, 1, 0);
        ps_vec3 d = ps_v3_norm(ps_v3(ps_rng_uniform(&r) - 0.5, -ps_rng_uniform(&r), ps_rng_uniform(&r) - 0.5));
        ps_rgb pw = ps_rgb_make(ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r));
        ph[i] = ps_photon_pack(p, pw, d, nrm, 0.5);
    }
    ps_kdtree *t = build(ph, n);
    ps_material diffuse = material(PS_MAT_DIFFUSE, ps_rgb_make(0.7, 0.5, 0.3), ps_rgb_gray(0), 0);
    ps_material glossy = material(PS_MAT_GLOSSY, ps_rgb_make(0.2, 0.1, 0.3), ps_rgb_make(0.5, 0.6, 0.4), 15.0);
    ps_neighbor scratch[MAX_K];
    int short_seen = 0;
    for (size_t i = 0; i < 60; i++) {
        ps_rng r = ps_rng_make(62, PS_STREAM_TEST, i);
        ps_vec3 p = ps_v3(ps_rng_uniform(&r), 0.025, ps_rng_uniform(&r));
        ps_vec3 nrm = i % 2 ? ps_v3(0, 1, 0) : ps_v3(0, -1, 0);
        ps_vec3 wo = ps_v3_norm(ps_v3(ps_rng_uniform(&r) - 0.5, nrm.y * ps_rng_uniform(&r), ps_rng_uniform(&r) - 0.5));
        for (int k = 0; k < PS_KERNEL_COUNT; k++) {
            /* A radius that sometimes holds fewer than k facing photons. */
            ps_estimate_options o = {i % 3 ? 30 : 150, i % 4 ? 0.1 : 0.04, (ps_kernel)k};
            ps_rgb want = oracle(ph, n, p, nrm, &o, NULL, wo);
            assert_rgb_rel(ps_photon_irradiance(t, p, nrm, &o, scratch), want, ORACLE_REL_TOL, "irradiance");
            assert_true(want.r > 0.0);
            ps_kdtree_query q = {p, o.k, o.max_radius, nrm, PS_ESTIMATE_MIN_COS};
            short_seen += ps_kdtree_knn(t, &q, scratch, NULL) < o.k;
            assert_rgb_rel(ps_photon_radiance(t, &glossy, p, nrm, wo, &o, scratch),
                           oracle(ph, n, p, nrm, &o, &glossy, wo), ORACLE_REL_TOL, "glossy radiance");
            assert_rgb_rel(ps_photon_radiance(t, &diffuse, p, nrm, wo, &o, scratch),
                           oracle(ph, n, p, nrm, &o, &diffuse, wo), ORACLE_REL_TOL, "diffuse radiance");
        }
    }
    assert_true(short_seen > 0);
    ps_kdtree_destroy(t);
    free(ph);
}

/* ---- radiance ------------------------------------------------------------------- */

static void radiance_diffuse_and_glossy(void **state)
{
    (void)state;
    const size_t n = 20000;
    ps_photon *ph = malloc(n * sizeof *ph);
    assert_non_null(ph);
    /* Every photon travels along d. */
    ps_vec3 d = ps_v3_norm(ps_v3(1.0, -2.0, 0.5)), up = ps_v3(0, 1, 0);
    plane_photons(ph, n, 71, up, d, ps_rgb_make(10.0, 20.0, 5.0));
    ps_kdtree *t = build(ph, n);
    ps_estimate_options o = {50, 0.2, PS_KERNEL_EPANECHNIKOV};
    ps_neighbor scratch[MAX_K];
    ps_material diffuse = material(PS_MAT_DIFFUSE, ps_rgb_make(0.8, 0.5, 0.2), ps_rgb_gray(0), 0);
    ps_material glossy = material(PS_MAT_GLOSSY, ps_rgb_make(0.1, 0.2, 0.1), ps_rgb_make(0.6, 0.5, 0.4), 30.0);
    ps_material mirror = material(PS_MAT_MIRROR, ps_rgb_gray(0.5), ps_rgb_gray(0.5), 10.0);
    mirror.reflectance = ps_rgb_gray(0.9);
    /* The direction as stored (octahedral, 8+8 bits): what the estimate uses. */
    ps_vec3 ds = ps_photon_dir(&ph[0]);
    assert_true(ps_v3_dot(ds, d) > cos(1.0 * PS_PI / 180.0));
    ps_vec3 mirror_dir = ps_reflect(ds, up);
    ps_vec3 wos[3] = {mirror_dir, ps_v3_norm(ps_v3_add(mirror_dir, ps_v3(0.0, 0.0, 0.3))), ps_v3_norm(ps_v3(-1, 1, 0))};
    for (size_t i = 0; i < 50; i++) {
        ps_rng r = ps_rng_make(72, PS_STREAM_TEST, i);
        ps_vec3 p = ps_v3(0.2 + 0.6 * ps_rng_uniform(&r), 0.0, 0.2 + 0.6 * ps_rng_uniform(&r));
        ps_rgb e = ps_photon_irradiance(t, p, up, &o, scratch);
        assert_true(e.g > 0.0);
        /* Diffuse: f = albedo / pi for every photon. */
        ps_rgb ld = ps_photon_radiance(t, &diffuse, p, up, wos[i % 3], &o, scratch);
        assert_rgb_rel(ld, ps_rgb_scale(ps_rgb_mul(diffuse.albedo, e), PS_INV_PI), 1e-12, "diffuse L = albedo E / pi");
        /* Glossy, every photon from one direction: L = f(d, wo) E. */
        for (int w = 0; w < 3; w++) {
            ps_rgb f = ps_bsdf_eval(&glossy, up, ds, wos[w]);
            ps_rgb lg = ps_photon_radiance(t, &glossy, p, up, wos[w], &o, scratch);
            assert_rgb_rel(lg, ps_rgb_mul(f, e), 1e-12, "glossy L = f E");
        }
        /* Mirrors and glass have no density to estimate. */
        ps_rgb lm = ps_photon_radiance(t, &mirror, p, up, mirror_dir, &o, scratch);
        assert_true(lm.r == 0.0 && lm.g == 0.0 && lm.b == 0.0);
    }
    /* The lobe is there: at the mirror direction the Phong term is
     * specular (e + 2) / (2 pi), many times the diffuse albedo / pi. */
    ps_rgb f_peak = ps_bsdf_eval(&glossy, up, ds, mirror_dir);
    assert_near(f_peak.r, glossy.albedo.r / PS_PI + glossy.specular.r * 32.0 / (2.0 * PS_PI), 1e-9);
    ps_rgb f_away = ps_bsdf_eval(&glossy, up, ds, wos[2]);
    assert_near(f_away.r, glossy.albedo.r / PS_PI, 1e-12);
    ps_kdtree_destroy(t);
    free(ph);
}

/* ---- fewer than k photons: the search disc is the area ---------------------------- */

static void fewer_than_k(void **state)
{
    (void)state;
    /* Gray powers of two and quarter are exact in RGBE. Distances 0, 0.3, 0.4
     * (as floats) from the origin; a fourth photon faces away. */
    ps_vec3 up = ps_v3(0, 1, 0), down = ps_v3(0, -1, 0);
    ps_photon ph[4] = {
        ps_photon_pack(ps_v3(0, 0, 0), ps_rgb_gray(1.0), down, up, 0.5),
        ps_photon_pack(ps_v3(0.3, 0, 0), ps_rgb_gray(0.5), down, up, 0.5),
        ps_photon_pack(ps_v3(0, 0, 0.4), ps_rgb_gray(0.25), down, up, 0.5),
        ps_photon_pack(ps_v3(0.1, 0, 0), ps_rgb_gray(8.0), up, down, 0.5),
    };
    ps_kdtree *t = build(ph, 4);
    ps_neighbor scratch[10];
    const double R = 0.5, d1 = (double)0.3f, d2 = (double)0.4f;
    /* Box, k = 10 > 3: the three photons over the whole disc of radius R. */
    ps_estimate_options o = {10, R, PS_KERNEL_BOX};
    ps_rgb e = ps_photon_irradiance(t, ps_v3(0, 0, 0), up, &o, scratch);
    assert_near(e.r, 1.75 / (PS_PI * R * R), 1e-12);
    assert_near(e.g, e.r, 0);
    /* Cone over the same disc: weights 1 - d / R, divided by C = 1/3. */
    o.kernel = PS_KERNEL_CONE;
    e = ps_photon_irradiance(t, ps_v3(0, 0, 0), up, &o, scratch);
    double want = (1.0 + 0.5 * (1.0 - d1 / R) + 0.25 * (1.0 - d2 / R)) / (PS_PI * R * R / 3.0);
    assert_near(e.r, want, 1e-12);
    /* Epanechnikov: 1 - d^2 / R^2, C = 1/2. */
    o.kernel = PS_KERNEL_EPANECHNIKOV;
    e = ps_photon_irradiance(t, ps_v3(0, 0, 0), up, &o, scratch);
    want = (1.0 + 0.5 * (1.0 - d1 * d1 / (R * R)) + 0.25 * (1.0 - d2 * d2 / (R * R))) / (PS_PI * R * R * 0.5);
    assert_near(e.r, want, 1e-12);
    /* k = 2 reached: the disc through the second photon, which (on its rim)
     * the box estimate leaves out; the cone gives it weight 0 anyway. */
    o = (ps_estimate_options){2, R, PS_KERNEL_BOX};
    e = ps_photon_irradiance(t, ps_v3(0, 0, 0), up, &o, scratch);
    assert_near(e.r, 1.0 / (PS_PI * d1 * d1), 1e-12);
    o.kernel = PS_KERNEL_CONE;
    e = ps_photon_irradiance(t, ps_v3(0, 0, 0), up, &o, scratch);
    assert_near(e.r, 1.0 / (PS_PI * d1 * d1 / 3.0), 1e-12);
    /* k = 3 reached with the box: the two nearest over the disc through the third. */
    o = (ps_estimate_options){3, R, PS_KERNEL_BOX};
    e = ps_photon_irradiance(t, ps_v3(0, 0, 0), up, &o, scratch);
    assert_near(e.r, 1.5 / (PS_PI * d2 * d2), 1e-12);
    /* Only the photon facing down, at distance 0.1, is seen from below. */
    o = (ps_estimate_options){10, R, PS_KERNEL_BOX};
    e = ps_photon_irradiance(t, ps_v3(0, 0, 0), down, &o, scratch);
    assert_near(e.r, 8.0 / (PS_PI * R * R), 1e-12);
    /* Nothing within reach: zero. */
    o.max_radius = 0.05;
    e = ps_photon_irradiance(t, ps_v3(0, 0, 0.2), up, &o, scratch);
    assert_true(e.r == 0.0 && e.g == 0.0 && e.b == 0.0);
    ps_kdtree_destroy(t);
    /* An empty map estimates zero. */
    t = build(NULL, 0);
    e = ps_photon_irradiance(t, ps_v3(0, 0, 0), up, &o, scratch);
    assert_true(e.r == 0.0 && e.g == 0.0 && e.b == 0.0);
    ps_kdtree_destroy(t);
}

/* ---- precomputed irradiance ---------------------------------------------------------- */

/* Both faces of the floor y = 0 and the wall x = 0 facing +x, each over a
 * unit square: 3 x 2000 photons. */
#define PRE_N 6000

static ps_photon *scene_photons(void)
{
    ps_photon *ph = malloc(PRE_N * sizeof *ph);
    assert_non_null(ph);
    const size_t third = PRE_N / 3;
    plane_photons(ph, third, 81, ps_v3(0, 1, 0), ps_v3(0, -1, 0), ps_rgb_make(10, 8, 6));
    plane_photons(ph + third, third, 82, ps_v3(0, -1, 0), ps_v3(0, 1, 0), ps_rgb_make(3, 4, 5));
    plane_photons(ph + 2 * third, third, 83, ps_v3(1, 0, 0), ps_v3(-1, 0, 0), ps_rgb_make(1, 2, 1));
    for (size_t i = 2 * third; i < PRE_N; i++) { /* rotate the floor square onto the wall: (x, 0, z) -> (0, x, z) */
        ph[i].pos[1] = ph[i].pos[0];
        ph[i].pos[0] = 0.0f;
    }
    return ph;
}

typedef struct sample {
    ps_photon p; /* flags cleared */
    ps_rgb e;    /* the irradiance before encoding */
} sample;

static int cmp_sample(const void *a, const void *b) { return memcmp(a, b, sizeof(ps_photon)); }
static int cmp_photon_bytes(const void *a, const void *b) { return memcmp(a, b, sizeof(ps_photon)); }

static ps_kdtree *precompute(const ps_kdtree *map, const ps_estimate_options *o, size_t stride, int threads)
{
    ps_kdtree *irr = NULL;
    ps_error err;
    if (ps_irradiance_precompute(map, o, stride, threads, NULL, &irr, &err) != PS_OK)
        fail_msg("precompute: %s", err.msg);
    assert_non_null(irr);
    return irr;
}

static void precomputed_irradiance(void **state)
{
    (void)state;
    ps_photon *ph = scene_photons();
    ps_kdtree *map = build(ph, PRE_N);
    const ps_photon *mp = ps_kdtree_photons(map);
    ps_estimate_options o = {50, 0.2, PS_KERNEL_CONE};
    ps_neighbor scratch[MAX_K];
    static const size_t strides[] = {1, 3, 7, PRE_N, PRE_N + 1};
    for (size_t s = 0; s < sizeof strides / sizeof *strides; s++) {
        size_t stride = strides[s], samples = (PRE_N + stride - 1) / stride;
        /* Threads: byte-identical trees. */
        ps_kdtree *irr[3];
        for (int th = 0; th < 3; th++) {
            irr[th] = precompute(map, &o, stride, th + 1);
            assert_int_equal(ps_kdtree_count(irr[th]), samples);
            assert_true(ps_kdtree_check(irr[th]));
        }
        for (int th = 1; th < 3; th++) {
            assert_memory_equal(ps_kdtree_photons(irr[th]), ps_kdtree_photons(irr[0]), samples * sizeof(ps_photon));
            ps_aabb a = ps_kdtree_bounds(irr[th]), b = ps_kdtree_bounds(irr[0]);
            assert_memory_equal(&a, &b, sizeof a);
        }
        /* Values: the samples are the map's photons 0, stride, 2 stride, ...
         * (in its heap order), each carrying the irradiance estimated at its
         * own position and normal, rounded to RGBE. */
        sample *want = malloc(samples * sizeof *want);
        ps_photon *got = malloc(samples * sizeof *got);
        assert_non_null(want);
        assert_non_null(got);
        for (size_t i = 0; i < samples; i++) {
            const ps_photon *src = &mp[i * stride];
            want[i].e = ps_photon_irradiance(map, ps_photon_position(src), ps_photon_normal(src), &o, scratch);
            want[i].p = *src;
            ps_rgbe_encode(want[i].e, 0.5, want[i].p.rgbe);
            ps_photon_set_flags(&want[i].p, 0);
            got[i] = ps_kdtree_photons(irr[0])[i];
            ps_photon_set_flags(&got[i], 0);
        }
        qsort(want, samples, sizeof *want, cmp_sample);
        qsort(got, samples, sizeof *got, cmp_photon_bytes);
        for (size_t i = 0; i < samples; i++) {
            if (memcmp(&want[i].p, &got[i], sizeof got[i]) != 0)
                fail_msg("stride %zu: sample %zu differs from the map photon with its irradiance", stride, i);
            /* Within RGBE rounding (half a step of 1/256 of the largest channel). */
            ps_rgb dec = ps_photon_power(&got[i]);
            double m = ps_rgb_max(want[i].e);
            assert_true(m > 0.0);
            assert_near(dec.r, want[i].e.r, m / 256.0);
            assert_near(dec.g, want[i].e.g, m / 256.0);
            assert_near(dec.b, want[i].e.b, m / 256.0);
        }
        free(want);
        free(got);
        for (int th = 0; th < 3; th++)
            ps_kdtree_destroy(irr[th]);
    }
    /* An empty map gives an empty tree. */
    ps_kdtree *empty = build(NULL, 0), *irr0 = precompute(empty, &o, 1, 2);
    assert_int_equal(ps_kdtree_count(irr0), 0);
    ps_kdtree_destroy(irr0);
    ps_kdtree_destroy(empty);
    /* A raised cancel flag stops it: interrupted, no tree. */
    ps_cancel_flag raised = 15;
    ps_kdtree *none = NULL;
    ps_error err;
    assert_int_equal(ps_irradiance_precompute(map, &o, 1, 2, &raised, &none, &err), PS_ERR_INTERRUPTED);
    assert_null(none);
    assert_non_null(strstr(err.msg, "interrupted"));
    ps_kdtree_destroy(map);
    free(ph);
}

/* The nearest sample within the radius whose normal has a cosine above
 * PS_IRRADIANCE_MIN_COS with n, by brute force; false when none. */
static bool brute_lookup(const ps_kdtree *irr, ps_vec3 p, ps_vec3 n, double radius, ps_rgb *e)
{
    const ps_photon *s = ps_kdtree_photons(irr);
    double best = radius * radius;
    bool found = false;
    for (size_t i = 0; i < ps_kdtree_count(irr); i++) {
        double dx = s[i].pos[0] - p.x, dy = s[i].pos[1] - p.y, dz = s[i].pos[2] - p.z;
        double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 <= best && ps_v3_dot(ps_photon_normal(&s[i]), n) > PS_IRRADIANCE_MIN_COS) {
            best = d2;
            *e = ps_photon_power(&s[i]);
            found = true;
        }
    }
    return found;
}

static void irradiance_lookup(void **state)
{
    (void)state;
    ps_photon *ph = scene_photons();
    ps_kdtree *map = build(ph, PRE_N);
    ps_estimate_options o = {50, 0.2, PS_KERNEL_CONE};
    ps_kdtree *irr = precompute(map, &o, 2, 2);
    /* Query normals: the three orientations present, one tilted 20 degrees
     * from +y (cos 0.94: still +y's), one tilted 30 degrees (cos 0.87: none),
     * and +z (no sample faces it). */
    double t20 = 20.0 * PS_PI / 180.0, t30 = 30.0 * PS_PI / 180.0;
    const ps_vec3 normals[6] = {ps_v3(0, 1, 0),  ps_v3(0, -1, 0), ps_v3(1, 0, 0),
                                ps_v3(sin(t20), cos(t20), 0), ps_v3(sin(t30), cos(t30), 0), ps_v3(0, 0, 1)};
    int hits[6] = {0}, total = 0;
    for (size_t i = 0; i < 300; i++) {
        ps_rng r = ps_rng_make(91, PS_STREAM_TEST, i);
        double u = ps_rng_uniform(&r), v = ps_rng_uniform(&r), w = ps_rng_uniform(&r);
        /* Every normal with every radius; every other round near the floor. */
        int ni = (int)(i % 6), round = (int)(i / 6);
        double radius = round % 3 == 0 ? 0.05 : (round % 3 == 1 ? 0.3 : INFINITY);
        ps_vec3 p = ps_v3(1.2 * u - 0.1, round % 2 ? 0.04 * (v - 0.5) : 1.2 * v - 0.1, 1.2 * w - 0.1);
        ps_rgb want = ps_rgb_gray(-1), got = ps_rgb_gray(-2);
        bool bw = brute_lookup(irr, p, normals[ni], radius, &want);
        bool bg = ps_irradiance_lookup(irr, p, normals[ni], radius, &got);
        if (bw != bg)
            fail_msg("lookup at (%g, %g, %g) normal %d radius %g: %d, brute force %d", p.x, p.y, p.z, ni, radius, bg, bw);
        if (bw) {
            assert_true(got.r == want.r && got.g == want.g && got.b == want.b);
            hits[ni]++;
        }
        total++;
    }
    /* Each case as designed: hits for the present orientations, none for
     * the 30-degree tilt and for +z. */
    assert_true(hits[0] > 0 && hits[1] > 0 && hits[2] > 0 && hits[3] > 0);
    assert_int_equal(hits[4], 0);
    assert_int_equal(hits[5], 0);
    assert_int_equal(total, 300);
    /* By hand: on the floor, the floor's own sample; far away, nothing;
     * the right position but the wall's normal, nothing within 0.1. */
    ps_rgb e;
    /* The floor's top is lit 10 : 8 : 6, its underside 3 : 4 : 5: every
     * estimate there has that colour (one estimate is too noisy, ~25% at
     * k = 50, to pin its size), up to RGBE rounding. */
    assert_true(ps_irradiance_lookup(irr, ps_v3(0.5, 0, 0.5), ps_v3(0, 1, 0), 0.1, &e));
    assert_near(e.b / e.r, 0.6, 0.02);
    assert_true(e.r > 5.0 && e.r < 20.0);
    assert_true(ps_irradiance_lookup(irr, ps_v3(0.5, 0, 0.5), ps_v3(0, -1, 0), 0.1, &e));
    assert_near(e.r / e.b, 0.6, 0.02);
    assert_true(e.b > 2.5 && e.b < 10.0);
    assert_false(ps_irradiance_lookup(irr, ps_v3(5, 5, 5), ps_v3(0, 1, 0), 1.0, &e));
    assert_false(ps_irradiance_lookup(irr, ps_v3(0.5, 0, 0.5), ps_v3(1, 0, 0), 0.1, &e));
    ps_kdtree_destroy(irr);
    ps_kdtree_destroy(map);
    free(ph);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(kernels),
        cmocka_unit_test(irradiance_on_plane),
        cmocka_unit_test(estimate_matches_formula),
        cmocka_unit_test(radiance_diffuse_and_glossy),
        cmocka_unit_test(fewer_than_k),
        cmocka_unit_test(precomputed_irradiance),
        cmocka_unit_test(irradiance_lookup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
