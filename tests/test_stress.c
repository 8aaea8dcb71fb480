/* test_stress.c: the numerical stress suite (issue 7), GL-free: extreme
 * powers through RGBE and the tracer, the default scene scaled by 1e-4 and
 * 1e4, degenerate and coincident geometry, lights in awkward places (on a
 * mirror's plane, inside a glass sphere, inside a specular object's bounding
 * sphere, a hair above a surface), ior 1 and 4, total internal reflection,
 * splat bases along and near the axes, and NaN / Inf refused at parse time.
 * Every case asserts a value against a closed form (energy, position,
 * direction), and every photon of every map is checked finite and in place.
 *
 * Photon counts are multiplied by PS_STRESS_FACTOR (environment, default 1):
 * `make stress` runs this file again with a larger factor (docs/stress.md). */
#include "test.h"
#include "rig.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "core/sampling.h"
#include "photon/emit.h"
#include "photon/photon.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "preview/mesh.h"
#include "preview/splat.h"
#include "scene/bsdf.h"
#include "scene/camera.h"
#include "scene/scene.h"

/* At most this factor more photons than `make test` traces. */
#define STRESS_FACTOR_MAX 1000
/* Positions are floats: 2^-24 relative, and a margin for the ray offset. */
#define POS_REL_TOL 1e-5
/* RGBE mantissas hold 8 bits: one step is 2^(e-8) and the largest channel is
 * at least 2^(e-1), so a dithered floor is within 1/128 of it, a plain
 * rounding (dither 0.5) within 1/256. */
#define RGBE_STEP_REL (1.0 / 128.0)
#define RGBE_HALF_STEP_REL (1.0 / 256.0)

static uint64_t stress_factor(void)
{
    const char *s = getenv("PS_STRESS_FACTOR");
    long f = s ? strtol(s, NULL, 10) : 1;
    return f < 1 ? 1 : f > STRESS_FACTOR_MAX ? STRESS_FACTOR_MAX : (uint64_t)f;
}

/* The sanitizer build runs about ten times slower: half the photons there
 * (the tolerances follow the count). */
#if defined(__SANITIZE_ADDRESS__)
#define SANITIZER_DIVISOR 2
#else
#define SANITIZER_DIVISOR 1
#endif

/* Photon counts: n in `make test`, n times the factor under `make stress`. */
static uint64_t photons(uint64_t n) { return n * stress_factor() / SANITIZER_DIVISOR; }

/* One sigma of a Monte Carlo sum of n photons is about 1/sqrt(n) relative;
 * tolerances are a few sigmas of the smallest run, never looser with more. */
static double mc_tol(uint64_t n, double sigmas) { return sigmas / sqrt((double)n); }

/* ---- rigs ------------------------------------------------------------------- */

/* rig_trace, and every photon asked for was emitted. */
static ps_photon_map trace(rig *r, ps_map_kind kind, uint64_t n)
{
    ps_photon_map m = rig_trace(r, kind, n);
    assert_int_equal(m.counters.emitted, n);
    return m;
}

static ps_tracer_options options(void)
{
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 11;
    return o;
}

/* Every photon finite, of non-negative power, with unit direction and normal,
 * inside the box [lo, hi] (widened by the float tolerance); returns the map's
 * total power. */
static ps_rgb check_map(const ps_photon_map *m, ps_vec3 lo, ps_vec3 hi, const char *what)
{
    double tol = POS_REL_TOL * fmax(ps_v3_max_abs(lo), ps_v3_max_abs(hi));
    ps_rgb sum = ps_rgb_gray(0.0);
    for (size_t i = 0; i < m->count; i++) {
        const ps_photon *p = &m->photons[i];
        ps_vec3 x = ps_photon_position(p);
        ps_rgb c = ps_photon_power(p);
        ps_vec3 d = ps_photon_dir(p), n = ps_photon_normal(p);
        if (!ps_v3_isfinite(x) || !ps_rgb_isfinite(c) || c.r < 0 || c.g < 0 || c.b < 0)
            fail_msg("%s: photon %zu not finite: (%g %g %g) power (%g %g %g)", what, i, x.x, x.y, x.z, c.r, c.g, c.b);
        if (fabs(ps_v3_len(d) - 1.0) > 1e-9 || fabs(ps_v3_len(n) - 1.0) > 1e-9)
            fail_msg("%s: photon %zu: direction or normal not unit", what, i);
        if (x.x < lo.x - tol || x.y < lo.y - tol || x.z < lo.z - tol || x.x > hi.x + tol || x.y > hi.y + tol ||
            x.z > hi.z + tol)
            fail_msg("%s: photon %zu at (%.9g %.9g %.9g) is outside the box (%g %g %g)-(%g %g %g)", what, i, x.x, x.y,
                     x.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
        sum = ps_rgb_add(sum, c);
    }
    assert_true(ps_rgb_isfinite(sum));
    return sum;
}

/* The closed box [-1,1]^3 of six inward diffuse quads of albedo rho; `extra`
 * (statements) is appended. */
static void box_scene(char *buf, size_t size, double rho, const char *extra)
{
    int n = snprintf(buf, size,
                     "camera eye 0 0 0.5 target 0 0 -1\n"
                     "material wall diffuse albedo %.17g %.17g %.17g\n"
                     "material glass dielectric ior 1.5\n"
                     "material mirror mirror reflectance 1 1 1\n"
                     "quad corner -1 -1 -1 edge1 0 0 2 edge2 2 0 0 material wall\n"
                     "quad corner -1 1 -1 edge1 2 0 0 edge2 0 0 2 material wall\n"
                     "quad corner -1 -1 -1 edge1 0 2 0 edge2 0 0 2 material wall\n"
                     "quad corner 1 -1 -1 edge1 0 0 2 edge2 0 2 0 material wall\n"
                     "quad corner -1 -1 -1 edge1 2 0 0 edge2 0 2 0 material wall\n"
                     "quad corner -1 -1 1 edge1 0 2 0 edge2 2 0 0 material wall\n"
                     "%s",
                     rho, rho, rho, extra);
    assert_true(n > 0 && (size_t)n < size);
}

static const ps_vec3 box_lo = {-1, -1, -1}, box_hi = {1, 1, 1};

/* Stored global flux in a closed box of albedo rho (no first diffuse hits):
 * Phi (rho + rho^2 + ...) = Phi rho / (1 - rho), whatever lossless specular
 * objects the photons cross on the way. */
static double furnace(double phi, double rho) { return phi * rho / (1.0 - rho); }

/* Traces the global map of a closed box and checks the geometric series,
 * no escape, and every photon inside. */
static void check_furnace(rig *r, double phi, double rho, uint64_t n, const char *what)
{
    ps_photon_map m = trace(r, PS_MAP_GLOBAL, n);
    double got = check_map(&m, box_lo, box_hi, what).g;
    double want = furnace(phi, rho);
    printf("%s: global flux %.5f W, furnace %.5f W, %llu escaped, %llu truncated\n", what, got, want,
           (unsigned long long)m.counters.escaped, (unsigned long long)m.counters.truncated);
    assert_int_equal(m.counters.escaped, 0);
    if (fabs(got - want) > want * mc_tol(n, 4.0))
        fail_msg("%s: global flux %g W, the geometric series says %g W", what, got, want);
    ps_photon_map_free(&m);
}

static void write_file_at(const char *name, const char *text)
{
    FILE *f = fopen(test_path(name), "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* ---- RGBE over 60 decades -------------------------------------------------- */

static void rgbe_extremes(void **state)
{
    (void)state;
    const double dithers[] = {0.0, 0.25, 0.5, 0.999};
    for (int decade = -30; decade <= 30; decade++)
        for (int k = 0; k < 8; k++) {
            /* Values across the decade, one channel at the top, the others
             * smaller (down to zero). */
            double v = pow(10.0, decade + k / 8.0);
            ps_rgb c = ps_rgb_make(v, v * (k / 8.0), v * 1e-3);
            for (size_t d = 0; d < sizeof dithers / sizeof *dithers; d++) {
                uint8_t e[4];
                ps_rgbe_encode(c, dithers[d], e);
                ps_rgb back = ps_rgbe_decode(e);
                assert_true(ps_rgb_isfinite(back));
                double tol = (dithers[d] == 0.5 ? RGBE_HALF_STEP_REL : RGBE_STEP_REL) * v;
                double err = fmax(fabs(back.r - c.r), fmax(fabs(back.g - c.g), fabs(back.b - c.b)));
                if (!(err <= tol))
                    fail_msg("rgbe %g (dither %g): decoded (%g %g %g), error %g > %g", v, dithers[d], back.r, back.g,
                             back.b, err, tol);
            }
        }
    /* Zero stays zero; negative, NaN and below 2^-128 store nothing; +Inf and
     * beyond 2^127 clamp to the largest code, still finite. */
    const double zeros[] = {0.0, -0.0, -1.0, NAN, -INFINITY, 1e-40, 1e-300, 4.9e-324};
    for (size_t i = 0; i < sizeof zeros / sizeof *zeros; i++) {
        uint8_t e[4];
        ps_rgbe_encode(ps_rgb_gray(zeros[i]), 0.5, e);
        ps_rgb back = ps_rgbe_decode(e);
        if (!(back.r == 0.0 && back.g == 0.0 && back.b == 0.0 && !signbit(back.r)))
            fail_msg("rgbe of %g decodes to %g, not +0", zeros[i], back.r);
    }
    const double huge[] = {INFINITY, 1e39, 1e300, DBL_MAX};
    for (size_t i = 0; i < sizeof huge / sizeof *huge; i++) {
        uint8_t e[4];
        ps_rgbe_encode(ps_rgb_gray(huge[i]), 0.5, e);
        ps_rgb back = ps_rgbe_decode(e);
        assert_true(ps_rgb_isfinite(back));
        assert_true(back.r > 1e38);
    }
    /* Dithered, the mean over photons is the value itself at both ends of
     * the range (1e-30 W photons of a faint light, 1e30 W of a bright one). */
    const double ends[] = {1e-30, 3.3e-30, 1e30, 7.7e29};
    for (size_t i = 0; i < sizeof ends / sizeof *ends; i++) {
        const int steps = 4096;
        double sum = 0.0;
        for (int k = 0; k < steps; k++) {
            uint8_t e[4];
            ps_rgbe_encode(ps_rgb_gray(ends[i]), (k + 0.5) / steps, e);
            sum += ps_rgbe_decode(e).g;
        }
        assert_near(sum / steps, ends[i], ends[i] * 1e-6);
    }
}

/* Lights of 2^-100, 2^99, 1e-30 and 1e30 W against 1 W: the same photons in
 * the same places; powers scaled by exactly the factor (a power of two moves
 * only the RGBE exponent), or within the mantissa's rounding. */
static void light_power_extremes(void **state)
{
    (void)state;
    const double powers[] = {1.0, 0x1p-100, 0x1p99, 1e-30, 1e30};
    const uint64_t n = photons(20000);
    ps_photon_map maps[5];
    for (int k = 0; k < 5; k++) {
        char light[256], text[4096];
        snprintf(light, sizeof light, "light point position 0.1 0.2 0.3 power %.17g %.17g %.17g\n", powers[k],
                 powers[k], powers[k]);
        box_scene(text, sizeof text, 0.6, light);
        ps_tracer_options o = options();
        rig r = rig_make(text, "", &o, PS_ACCEL_AUTO);
        maps[k] = trace(&r, PS_MAP_GLOBAL, n);
        ps_rgb sum = check_map(&maps[k], box_lo, box_hi, "power extremes");
        double want = furnace(powers[k], 0.6);
        printf("light of %g W: %zu photons, flux %g W (furnace %g W)\n", powers[k], maps[k].count, sum.g, want);
        assert_near(sum.g, want, want * mc_tol(n, 4.0));
        rig_free(&r);
    }
    for (int k = 1; k < 5; k++) {
        assert_int_equal(maps[k].count, maps[0].count);
        int shift = k == 1 ? -100 : k == 2 ? 99 : 0;
        for (size_t i = 0; i < maps[0].count; i++) {
            const ps_photon *a = &maps[0].photons[i], *b = &maps[k].photons[i];
            assert_memory_equal(a->pos, b->pos, sizeof a->pos);
            assert_int_equal(a->dir, b->dir);
            if (shift) {
                assert_memory_equal(a->rgbe, b->rgbe, 3);
                assert_int_equal((int)b->rgbe[3] - (int)a->rgbe[3], shift);
            } else {
                double pa = ps_photon_power(a).g * powers[k], pb = ps_photon_power(b).g;
                if (fabs(pb - pa) > 2.0 * RGBE_STEP_REL * pa)
                    fail_msg("photon %zu: %g W at %g W light, %g W expected", i, pb, powers[k], pa);
            }
        }
    }
    for (int k = 0; k < 5; k++)
        ps_photon_map_free(&maps[k]);
}

/* Past PS_SCENE_MAX_LIGHT_POWER a photon's RGBE power would clamp (2^127 W)
 * and three channels near DBL_MAX would sum to infinity, which once turned
 * the global map off without a word: such lights are refused, in a scene, in
 * an MTL's Ke, and by the editing API. */
static void light_power_limit(void **state)
{
    (void)state;
    const char *const too_bright[] = {"1e308", "1.0000001e30", "1e31"};
    for (size_t k = 0; k < sizeof too_bright / sizeof *too_bright; k++) {
        char light[256], text[4096];
        snprintf(light, sizeof light, "light point position 0 0 0 power 1 %s 1\n", too_bright[k]);
        box_scene(text, sizeof text, 0.5, light);
        ps_scene *s = NULL;
        ps_error err;
        assert_int_equal(ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err), PS_ERR_RANGE);
        assert_non_null(strstr(err.msg, "inline.scn:11: light: 'power'"));
        assert_non_null(strstr(err.msg, "is above the 1e+30 W a light may have"));
        assert_null(s);
    }
    /* A Ke mesh light of 1e30 W/m^2/sr over 1 m^2: pi * 1e30 W. */
    write_file_at("bright.obj", "mtllib bright.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl k\nf 1 2 3 4\n");
    write_file_at("bright.mtl", "newmtl k\nKd 0 0 0\nKe 1e30 1e30 1e30\n");
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path("bright.obj"));
    *strrchr(dir, '/') = '\0';
    ps_scene *s = NULL;
    ps_error err;
    assert_int_equal(ps_scene_load_text("camera eye 0 0 3 target 0 0 0\nmesh bright.obj\n", "inline.scn", dir, NULL, &s,
                                        &err),
                     PS_ERR_RANGE);
    assert_non_null(strstr(err.msg, "inline.scn:2: mesh: its emitting faces' power"));
    /* The bound itself is fine, and editing past it is refused, scene unchanged. */
    char text[4096];
    box_scene(text, sizeof text, 0.5, "light point position 0 0 0 power 1e30 1e30 1e30\n");
    assert_int_equal(ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err), PS_OK);
    assert_int_equal(ps_scene_set_light_power(s, 0, ps_rgb_make(1, 1, 2e30), &err), PS_ERR_RANGE);
    assert_non_null(strstr(err.msg, "is above the 1e+30 W a light may have"));
    size_t nl;
    assert_true(ps_scene_lights(s, &nl)[0].power.b == 1e30);
    assert_int_equal(ps_scene_set_light_power(s, 0, ps_rgb_make(1, 1, 1e30), &err), PS_OK);
    ps_scene_destroy(s);
}

/* ---- the default scene scaled by 1e-4 and 1e4 ------------------------------------ */

/* Scales a .scn text by s about the origin: every coordinate, edge, radius
 * and the photon radii; light powers by s^2, so that irradiance (power per
 * area) is unchanged. Comments are dropped. */
static void scale_scene(const char *in, double s, char *out, size_t size)
{
    static const char *const vec_keys[] = {"eye", "target", "corner", "edge1", "edge2", "center", "position"};
    size_t used = 0;
    out[0] = '\0';
    const char *line = in;
    while (*line) {
        const char *nl = strchr(line, '\n');
        size_t len = nl ? (size_t)(nl - line) : strlen(line);
        char buf[1024];
        assert_true(len < sizeof buf);
        memcpy(buf, line, len);
        buf[len] = '\0';
        char *hash = strchr(buf, '#');
        if (hash)
            *hash = '\0';
        bool radius_statement = false;
        int scale_next = 0;
        double factor = 1.0;
        int first = 1;
        for (char *tok = strtok(buf, " \t\r"); tok; tok = strtok(NULL, " \t\r")) {
            char word[128];
            char *end;
            double v = strtod(tok, &end);
            bool number = end != tok && *end == '\0';
            if (number && (scale_next > 0 || radius_statement)) {
                snprintf(word, sizeof word, "%.17g", v * (radius_statement ? s : factor));
                if (scale_next > 0)
                    scale_next--;
            } else {
                snprintf(word, sizeof word, "%s", tok);
                scale_next = 0;
                if (first && !strcmp(tok, "radius"))
                    radius_statement = true;
                for (size_t k = 0; k < sizeof vec_keys / sizeof *vec_keys; k++)
                    if (!strcmp(tok, vec_keys[k]))
                        scale_next = 3, factor = s;
                if (!first && !strcmp(tok, "radius"))
                    scale_next = 1, factor = s;
                if (!strcmp(tok, "power"))
                    scale_next = 3, factor = s * s;
            }
            int w = snprintf(out + used, size - used, "%s%s", first ? "" : " ", word);
            assert_true(w > 0 && (size_t)w < size - used);
            used += (size_t)w;
            first = 0;
        }
        assert_true(used + 1 < size);
        out[used++] = '\n';
        out[used] = '\0';
        line = nl ? nl + 1 : line + len;
    }
}

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        fail_msg("cannot open %s", path);
    static char buf[16384];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return buf;
}

/* Floor irradiance of a map on a grid of CELLS x CELLS over the default
 * scene's floor (y = 0, x and z in [-s, s]): power per area. */
#define CELLS 6
static void floor_grid(const ps_photon_map *m, double s, double grid[CELLS][CELLS])
{
    memset(grid, 0, sizeof(double) * CELLS * CELLS);
    double area = (2.0 * s / CELLS) * (2.0 * s / CELLS);
    for (size_t i = 0; i < m->count; i++) {
        ps_vec3 p = ps_photon_position(&m->photons[i]);
        if (fabs(p.y) > 1e-6 * s)
            continue;
        int a = (int)((p.x / s + 1.0) * 0.5 * CELLS), b = (int)((p.z / s + 1.0) * 0.5 * CELLS);
        a = a < 0 ? 0 : a >= CELLS ? CELLS - 1 : a;
        b = b < 0 ? 0 : b >= CELLS ? CELLS - 1 : b;
        grid[a][b] += ps_photon_power(&m->photons[i]).g / area;
    }
}

static void scaled_default_scene(void **state)
{
    (void)state;
    const char *orig = read_text("data/scenes/cornell-caustic.scn");
    const double scales[] = {1.0, 1e-4, 1e4};
    const uint64_t n[PS_MAP_COUNT] = {photons(60000), photons(30000)};
    ps_photon_map maps[3][PS_MAP_COUNT];
    double grids[3][PS_MAP_COUNT][CELLS][CELLS];
    for (int k = 0; k < 3; k++) {
        static char text[16384];
        scale_scene(orig, scales[k], text, sizeof text);
        ps_tracer_options o = options();
        rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
        double s = scales[k];
        for (int m = 0; m < PS_MAP_COUNT; m++) {
            maps[k][m] = trace(&r, (ps_map_kind)m, n[m]);
            /* The box x, z in [-1, 1], y in [0, 2], open toward +z: every
             * stored photon lies on a wall (none leaked through). */
            check_map(&maps[k][m], ps_v3(-s, 0, -s), ps_v3(s, 2 * s, s), "scaled scene");
            floor_grid(&maps[k][m], s, grids[k][m]);
        }
        rig_free(&r);
    }
    for (int k = 1; k < 3; k++)
        for (int m = 0; m < PS_MAP_COUNT; m++) {
            const ps_photon_map *a = &maps[0][m], *b = &maps[k][m];
            const ps_trace_counters *ca = &a->counters, *cb = &b->counters;
            printf("scale %g, %s: %zu stored (%zu at 1), %llu rays (%llu), %llu escaped (%llu)\n", scales[k],
                   ps_map_name((ps_map_kind)m), b->count, a->count, (unsigned long long)cb->rays,
                   (unsigned long long)ca->rays, (unsigned long long)cb->escaped, (unsigned long long)ca->escaped);
            /* Rounding differs between scales, so a path grazing an edge may
             * go the other way: almost every path is the same. Acne (a ray
             * meeting its own surface) would add rays and stored photons. */
            assert_true(fabs((double)a->count - (double)b->count) <= 0.002 * (double)a->count + 2);
            assert_true(fabs((double)ca->rays - (double)cb->rays) <= 0.002 * (double)ca->rays + 2);
            assert_true(fabs((double)ca->escaped - (double)cb->escaped) <= 0.002 * (double)ca->escaped + 2);
            size_t same = 0, count = a->count < b->count ? a->count : b->count;
            for (size_t i = 0; i < count; i++) {
                ps_vec3 pa = ps_photon_position(&a->photons[i]);
                ps_vec3 pb = ps_v3_scale(ps_photon_position(&b->photons[i]), 1.0 / scales[k]);
                same += ps_v3_len(ps_v3_sub(pa, pb)) < 1e-4;
            }
            if ((double)same < 0.99 * (double)count)
                fail_msg("scale %g, %s map: only %zu of %zu photons at the scaled place", scales[k],
                         ps_map_name((ps_map_kind)m), same, count);
            /* Irradiance, cell by cell: power s^2 over area s^2. */
            double peak = 0.0, worst = 0.0;
            for (int i = 0; i < CELLS; i++)
                for (int j = 0; j < CELLS; j++)
                    peak = fmax(peak, grids[0][m][i][j]);
            for (int i = 0; i < CELLS; i++)
                for (int j = 0; j < CELLS; j++)
                    worst = fmax(worst, fabs(grids[k][m][i][j] - grids[0][m][i][j]));
            printf("   floor irradiance: peak %.4f W/m^2, largest cell difference %.2g W/m^2\n", peak, worst);
            assert_true(peak > 0.0);
            if (worst > 0.01 * peak)
                fail_msg("scale %g, %s map: floor irradiance differs by %g W/m^2 (peak %g)", scales[k],
                         ps_map_name((ps_map_kind)m), worst, peak);
        }
    for (int k = 0; k < 3; k++)
        for (int m = 0; m < PS_MAP_COUNT; m++)
            ps_photon_map_free(&maps[k][m]);
}

/* ---- degenerate and coincident geometry --------------------------------------- */

/* Writes the cube [-1,1]^3 as an OBJ whose faces (inward) are each cut into
 * five triangles around a point m on one edge and a point q a hair (1e-9)
 * inside the face from it, so that one triangle is a sliver; and two
 * zero-area triangles a face (collinear corners, a repeated corner). */
static void write_degenerate_cube(const char *path)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    int base = 1;
    for (int face = 0; face < 6; face++) {
        int axis = face / 2;
        double side = face % 2 ? 1.0 : -1.0;
        /* Corners a, b, c, d counter-clockwise seen from inside. */
        double uv[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        double pts[6][2] = {{0}};
        for (int k = 0; k < 4; k++) {
            pts[k][0] = uv[k][0];
            pts[k][1] = side > 0 ? -uv[k][1] : uv[k][1]; /* flip the winding on the far side */
        }
        pts[4][0] = 0.0, pts[4][1] = pts[0][1];             /* m: middle of a-b */
        pts[5][0] = 0.0, pts[5][1] = pts[0][1] * (1 - 1e-9); /* q: a hair toward c-d */
        for (int k = 0; k < 6; k++) {
            double c[3];
            c[axis] = side;
            c[(axis + 1) % 3] = pts[k][0];
            c[(axis + 2) % 3] = pts[k][1];
            fprintf(f, "v %.17g %.17g %.17g\n", c[0], c[1], c[2]);
        }
        int a = base, b = base + 1, c = base + 2, d = base + 3, m = base + 4, q = base + 5;
        fprintf(f, "f %d %d %d\nf %d %d %d\nf %d %d %d\nf %d %d %d\nf %d %d %d\n", a, m, q, m, b, c, m, c, q, q, c, d,
                a, q, d);
        fprintf(f, "f %d %d %d\nf %d %d %d\n", a, m, b, m, m, c);
        base += 6;
    }
    fclose(f);
}

static void degenerate_triangles(void **state)
{
    (void)state;
    char obj[1024], dir[1024];
    snprintf(obj, sizeof obj, "%s", test_path("degenerate-cube.obj"));
    snprintf(dir, sizeof dir, "%s", obj);
    *strrchr(dir, '/') = '\0';
    write_degenerate_cube(obj);
    const char *text = "camera eye 0 0 0.5 target 0 0 -1\n"
                       "material wall diffuse albedo 0.5 0.5 0.5\n"
                       "mesh degenerate-cube.obj material wall\n"
                       "light point position 0 -0.999999 0 power 10 10 10\n"
                       "light point position 0.3 0.2 0.1 power 10 10 10\n";
    ps_tracer_options o = options();
    rig r = rig_make(text, dir, &o, PS_ACCEL_OCTREE);
    size_t nt;
    (void)ps_scene_triangles(r.scene, &nt);
    assert_int_equal(nt, 6 * 7);
    /* Every face's normal, even the zero-area ones', finite (zero or unit). */
    for (uint32_t t = 0; t < nt; t++) {
        ps_vec3 nrm = ps_scene_triangle_normal(r.scene, t);
        assert_true(ps_v3_isfinite(nrm));
        double len = ps_v3_len(nrm);
        assert_true(len == 0.0 || fabs(len - 1.0) < 1e-12);
    }
    check_furnace(&r, 20.0, 0.5, photons(200000), "degenerate cube");
    /* The preview's mesh of it: all finite. */
    ps_preview_mesh pm;
    ps_error err;
    ps_mesh_options mo = ps_mesh_default_options(r.scene);
    assert_int_equal(ps_preview_mesh_build(r.scene, &mo, &pm, &err), PS_OK);
    for (size_t i = 0; i < 3 * pm.vertex_count; i++)
        assert_true(isfinite(pm.positions[i]) && isfinite(pm.normals[i]));
    ps_preview_mesh_free(&pm);
    rig_free(&r);
}

/* The floor three times over (same place, same and opposite winding): which
 * of the coincident faces a ray meets may vary, but nothing leaks and no
 * energy appears or vanishes. */
static void coincident_faces(void **state)
{
    (void)state;
    char text[4096];
    box_scene(text, sizeof text, 0.5,
              "quad corner -1 -1 -1 edge1 0 0 2 edge2 2 0 0 material wall\n"
              "quad corner -1 -1 -1 edge1 2 0 0 edge2 0 0 2 material wall\n"
              "light point position 0.1 0.2 0.3 power 10 10 10\n");
    ps_tracer_options o = options();
    rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
    check_furnace(&r, 10.0, 0.5, photons(100000), "coincident floors");
    rig_free(&r);
}

/* ---- lights in awkward places ------------------------------------------------ */

/* A point light exactly in the plane of a mirror quad (inside it, and on its
 * edge), and a hair (1e-9) above it. Above: the mirror takes the lower half
 * of the directions, caustic flux Phi Omega / (4 pi) of the square seen from
 * there (nearly 2 pi). In the plane the mirror is edge-on to the light: every
 * ray from the light meets that plane only at its own origin (t = 0, which
 * no intersection counts), so there is no caustic at all, the photons cross
 * the plane as if the mirror were not there, and the box's energy balance
 * holds either way. */
static double square_solid_angle(double a, double b, double d)
{
    /* A rectangle of half-sides a, b seen from distance d over its centre. */
    return 4.0 * asin(a * b / sqrt((a * a + d * d) * (b * b + d * d)));
}

static void light_on_mirror_plane(void **state)
{
    (void)state;
    const double heights[] = {1e-9, 0.0};
    const double xs[] = {0.0, 0.5};
    for (int h = 0; h < 2; h++)
        for (int x = 0; x < 2; x++) {
            if (h == 0 && x == 1)
                continue;
            char extra[512], text[4096];
            snprintf(extra, sizeof extra,
                     "quad corner -0.5 0 -0.5 edge1 0 0 1 edge2 1 0 0 material mirror\n"
                     "light point position %.17g %.17g 0 power 10 10 10\n",
                     xs[x], heights[h]);
            box_scene(text, sizeof text, 0.5, extra);
            ps_tracer_options o = options();
            rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
            uint64_t n = photons(100000);
            check_furnace(&r, 10.0, 0.5, n, "light on a mirror's plane");
            ps_photon_map m = trace(&r, PS_MAP_CAUSTIC, n);
            double got = check_map(&m, box_lo, box_hi, "mirror plane caustic").g;
            double above = 10.0 * square_solid_angle(0.5, 0.5, 1e-9) / (4.0 * PS_PI);
            printf("light at x %g, %g above a mirror's plane: caustic flux %.5f W (from above %.5f W)\n", xs[x],
                   heights[h], got, above);
            assert_int_equal(m.counters.escaped, 0);
            if (heights[h] > 0.0)
                assert_near(got, above, above * mc_tol(n, 4.0));
            else
                assert_true(got <= above * 1e-6);
            ps_photon_map_free(&m);
            rig_free(&r);
        }
}

/* A point light inside a glass sphere in the closed box. At the centre every
 * ray meets the glass head-on and, lossless, all of the flux reaches the
 * walls through it: caustic flux Phi, global flux the furnace's. Off centre
 * (0.9 r, ior 1.5) total internal reflection traps the rays that meet the
 * surface beyond the critical angle for good (a sphere keeps the angle of
 * incidence along every chord): sin i = (d / r) sin phi > 1 / n, a fraction
 * sqrt(1 - (r / (n d))^2) of the directions, cut at the bounce limit. */
static void light_inside_glass(void **state)
{
    (void)state;
    const double r_sphere = 0.4, ior = 1.5;
    const double offsets[] = {0.0, 0.9};
    for (int k = 0; k < 2; k++) {
        char extra[512], text[4096];
        double d = offsets[k] * r_sphere;
        snprintf(extra, sizeof extra,
                 "sphere center 0 0 0 radius %.17g material glass\n"
                 "light point position %.17g 0 0 power 10 10 10\n",
                 r_sphere, d);
        box_scene(text, sizeof text, 0.5, extra);
        ps_tracer_options o = options();
        rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
        uint64_t n = photons(60000);
        double trapped = d > 0.0 ? sqrt(1.0 - pow(r_sphere / (ior * d), 2.0)) : 0.0;
        ps_photon_map m = trace(&r, PS_MAP_CAUSTIC, n);
        double got = check_map(&m, box_lo, box_hi, "light in glass").g;
        double frac_cut = (double)m.counters.truncated / (double)n;
        printf("light %g off the centre of a glass sphere: caustic %.5f W of 10 W, %.4f of the photons trapped "
               "(analytic %.4f)\n",
               d, got, frac_cut, trapped);
        assert_int_equal(m.counters.escaped, 0);
        /* Rays just short of the critical angle reflect almost wholly and may
         * reach the bounce limit too: a small excess over the analytic share. */
        assert_true(frac_cut >= trapped - mc_tol(n, 4.0) && frac_cut <= trapped + 0.02);
        assert_true(got <= 10.0 * (1.0 - trapped) * (1.0 + mc_tol(n, 4.0)));
        assert_true(got >= 10.0 * (1.0 - trapped - 0.02) * (1.0 - mc_tol(n, 4.0)));
        if (d == 0.0)
            assert_near(got, 10.0, 10.0 * mc_tol(n, 4.0));
        ps_photon_map_free(&m);
        if (d == 0.0)
            check_furnace(&r, 10.0, 0.5, n, "light in glass, global");
        rig_free(&r);
    }
}

/* A point light inside a closed box of lossless mirrors whose floor alone is
 * diffuse (albedo a): every watt ends on the floor, so with every diffuse
 * hit stored (global_direct) the map holds Phi / (1 - a); paths nearly
 * parallel to the floor may reach the bounce limit first, so what is stored
 * lies between that less the truncated photons' share and that: never more
 * (no energy created), and every photon on the floor. */
static void mirror_furnace(void **state)
{
    (void)state;
    const char *text = "camera eye 0 0 0.5 target 0 0 -1\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "material mirror mirror reflectance 1 1 1\n"
                       "quad corner -1 -1 -1 edge1 0 0 2 edge2 2 0 0 material floor\n"
                       "quad corner -1 1 -1 edge1 2 0 0 edge2 0 0 2 material mirror\n"
                       "quad corner -1 -1 -1 edge1 0 2 0 edge2 0 0 2 material mirror\n"
                       "quad corner 1 -1 -1 edge1 0 0 2 edge2 0 2 0 material mirror\n"
                       "quad corner -1 -1 -1 edge1 2 0 0 edge2 0 2 0 material mirror\n"
                       "quad corner -1 -1 1 edge1 0 2 0 edge2 2 0 0 material mirror\n"
                       "light point position 0.1 0.3 0.2 power 10 10 10\n";
    ps_tracer_options o = options();
    o.global_direct = true;
    rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
    uint64_t n = photons(100000);
    ps_photon_map m = trace(&r, PS_MAP_GLOBAL, n);
    double got = check_map(&m, ps_v3(-1, -1, -1), ps_v3(1, -1, 1), "mirror furnace").g;
    double want = 10.0 / (1.0 - 0.5), cut = (double)m.counters.truncated / (double)n;
    printf("mirror furnace: stored %.5f W, at most %.5f W; %.4f of the paths truncated\n", got, want, cut);
    assert_int_equal(m.counters.escaped, 0);
    assert_true(got <= want * (1.0 + mc_tol(n, 4.0)));
    assert_true(got >= want * (1.0 - 2.0 * cut - mc_tol(n, 4.0)));
    ps_photon_map_free(&m);
    rig_free(&r);
}

/* A point light 0.1 under the middle of a 1 x 1 mirror: inside the mirror's
 * bounding sphere, so its caustic cone is every direction. The caustic is
 * what the mirror subtends, Phi Omega / (4 pi), with cones or without. */
static void light_inside_bounding_sphere(void **state)
{
    (void)state;
    char text[4096];
    box_scene(text, sizeof text, 0.5,
              "quad corner -0.5 0.5 -0.5 edge1 1 0 0 edge2 0 0 1 material mirror\n"
              "light point position 0 0.4 0 power 10 10 10\n");
    double want = 10.0 * square_solid_angle(0.5, 0.5, 0.1) / (4.0 * PS_PI);
    uint64_t n = photons(100000);
    double got[2];
    for (int cones = 0; cones < 2; cones++) {
        ps_tracer_options o = options();
        o.caustic_cones = cones;
        rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
        if (cones) {
            ps_light_sampler *ls;
            ps_error err;
            assert_int_equal(ps_light_sampler_create(r.scene, &ls, &err), PS_OK);
            ps_caustic_cone cone;
            assert_true(ps_light_caustic_cone(ls, 0, ps_v3(0, 0.5, 0), sqrt(0.5), &cone));
            assert_true(cone.cos_half <= -1.0);
            ps_light_sampler_destroy(ls);
        }
        ps_photon_map m = trace(&r, PS_MAP_CAUSTIC, n);
        got[cones] = check_map(&m, box_lo, box_hi, "light in bounding sphere").g;
        assert_int_equal(m.counters.escaped, 0);
        ps_photon_map_free(&m);
        rig_free(&r);
    }
    printf("light inside a mirror's bounding sphere: caustic %.5f W with cones, %.5f W without, analytic %.5f W\n",
           got[1], got[0], want);
    assert_near(got[1], want, want * mc_tol(n, 4.0));
    assert_near(got[0], want, want * mc_tol(n, 4.0));
}

/* A point light a hair (1e-6 r) above a glass or mirror sphere: half the
 * directions meet it, most near grazing, where Fresnel goes to 1. All of it
 * still lands on the walls: caustic flux Phi (1 - cos theta) / 2, with
 * sin theta = r / (r + h). And a spot shining along the floor 1e-7 above it:
 * every photon stays in the box, the furnace holds. */
static void grazing_incidence(void **state)
{
    (void)state;
    const double r_sphere = 0.4, h = 1e-6 * 0.4;
    const char *mats[] = {"glass", "mirror"};
    uint64_t n = photons(60000);
    for (int k = 0; k < 2; k++) {
        char extra[512], text[4096];
        snprintf(extra, sizeof extra,
                 "sphere center 0 0 0 radius %.17g material %s\n"
                 "light point position 0 %.17g 0 power 10 10 10\n",
                 r_sphere, mats[k], r_sphere + h);
        box_scene(text, sizeof text, 0.5, extra);
        ps_tracer_options o = options();
        rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
        double s = r_sphere / (r_sphere + h);
        double want = 10.0 * (1.0 - sqrt(1.0 - s * s)) / 2.0;
        ps_photon_map m = trace(&r, PS_MAP_CAUSTIC, n);
        double got = check_map(&m, box_lo, box_hi, "grazing sphere").g;
        printf("light %g above a %s sphere: caustic %.5f W, analytic %.5f W\n", h, mats[k], got, want);
        assert_int_equal(m.counters.escaped, 0);
        assert_near(got, want, want * mc_tol(n, 4.0));
        ps_photon_map_free(&m);
        rig_free(&r);
    }
    char text[4096];
    box_scene(text, sizeof text, 0.5, "light spot position -0.9 -0.9999999 0 direction 1 0 0 angle 1 power 10 10 10\n");
    ps_tracer_options o = options();
    rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
    check_furnace(&r, 10.0, 0.5, photons(100000), "spot grazing the floor");
    rig_free(&r);
}

/* ---- ior 1 and 4, total internal reflection ------------------------------------- */

/* Glass of ior 1 is invisible: nothing reflects, every caustic photon lands
 * where the light would have put it directly, along the straight line from
 * the light, and the floor under the sphere gets the direct irradiance:
 * Phi / 2 (1 - H / sqrt(H^2 + a^2)) inside radius a. */
static void ior_one_is_invisible(void **state)
{
    (void)state;
    const double cosines[] = {0.0, 1e-300, 1e-9, 1e-4, 0.125, 0.5, 0.875, 1.0};
    for (size_t k = 0; k < sizeof cosines / sizeof *cosines; k++)
        if (ps_fresnel_dielectric(cosines[k], 1.0, 1.0) != 0.0)
            fail_msg("ior 1 reflects %g at cos %g", ps_fresnel_dielectric(cosines[k], 1.0, 1.0), cosines[k]);
    const char *text = "camera eye 0 1 5 target 0 1 0\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "material air dielectric ior 1\n"
                       "quad corner -20 0 20 edge1 40 0 0 edge2 0 0 -40 material floor\n"
                       "sphere center 0 1 0 radius 0.3 material air\n"
                       "light point position 0 2 0 power 100 100 100\n";
    ps_tracer_options o = options();
    rig r = rig_make(text, "", &o, PS_ACCEL_AUTO);
    uint64_t n = photons(100000);
    ps_photon_map m = trace(&r, PS_MAP_CAUSTIC, n);
    check_map(&m, ps_v3(-20, 0, -20), ps_v3(20, 0, 20), "ior 1");
    const double H = 2.0, a = 0.5;
    double disc = 0.0, worst = 0.0;
    for (size_t i = 0; i < m.count; i++) {
        ps_vec3 p = ps_photon_position(&m.photons[i]);
        ps_vec3 straight = ps_v3_norm(ps_v3_sub(p, ps_v3(0, H, 0)));
        worst = fmax(worst, acos(fmin(1.0, ps_v3_dot(straight, ps_photon_dir(&m.photons[i])))));
        if (p.x * p.x + p.z * p.z <= a * a)
            disc += ps_photon_power(&m.photons[i]).g;
    }
    double want = 50.0 * (1.0 - H / sqrt(H * H + a * a));
    double total = 100.0 * (1.0 - sqrt(1.0 - 0.09)) / 2.0;
    double got = ps_photon_map_power(&m).g;
    printf("ior 1: caustic %.5f W (the sphere's cone %.5f W), %.5f W under it (direct %.5f W), worst direction %.3f deg\n",
           got, total, disc, want, worst * 180.0 / PS_PI);
    assert_int_equal(m.counters.escaped, 0); /* nothing reflected back up */
    assert_near(got, total, total * mc_tol(n, 4.0));
    assert_near(disc, want, want * mc_tol(n, 6.0));
    /* The photon's direction is stored in 8+8 octahedral bits: 0.75 degrees. */
    assert_true(worst * 180.0 / PS_PI < 0.8);
    ps_photon_map_free(&m);
    rig_free(&r);
}

/* Glass of ior 4 (36 % reflected head-on) in the closed box: all that the
 * sphere subtends still reaches the walls, and the furnace holds. */
static void ior_four(void **state)
{
    (void)state;
    assert_near(ps_fresnel_dielectric(1.0, 1.0, 4.0), 0.36, 1e-12);
    char text[4096];
    box_scene(text, sizeof text, 0.5,
              "material dense dielectric ior 4\n"
              "sphere center 0 -0.3 0 radius 0.4 material dense\n"
              "light point position 0 0.5 0 power 10 10 10\n");
    ps_tracer_options o = options();
    rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
    uint64_t n = photons(60000);
    ps_photon_map m = trace(&r, PS_MAP_CAUSTIC, n);
    double got = check_map(&m, box_lo, box_hi, "ior 4").g;
    double s = 0.4 / 0.8, want = 10.0 * (1.0 - sqrt(1.0 - s * s)) / 2.0;
    printf("ior 4: caustic %.5f W, analytic %.5f W, %llu truncated\n", got, want,
           (unsigned long long)m.counters.truncated);
    assert_int_equal(m.counters.escaped, 0);
    assert_near(got, want, want * mc_tol(n, 4.0));
    ps_photon_map_free(&m);
    check_furnace(&r, 10.0, 0.5, n, "ior 4, global");
    rig_free(&r);
}

/* Total internal reflection on its own: beyond the critical angle Fresnel is
 * 1 and refraction refuses; just inside it, refraction works. */
static void total_internal_reflection(void **state)
{
    (void)state;
    const double iors[] = {1.0001, 1.5, 4.0};
    for (size_t k = 0; k < sizeof iors / sizeof *iors; k++) {
        double crit = asin(1.0 / iors[k]);
        for (int s = -1; s <= 1; s += 2) {
            double i = crit * (1.0 + s * 1e-6);
            ps_vec3 d = ps_v3(sin(i), -cos(i), 0.0), out;
            bool refracts = ps_refract(d, ps_v3(0, 1, 0), iors[k], &out);
            double f = ps_fresnel_dielectric(cos(i), iors[k], 1.0);
            assert_true(f >= 0.0 && f <= 1.0);
            if (s > 0) {
                assert_false(refracts);
                assert_near(f, 1.0, 0.0);
            } else {
                assert_true(refracts);
                assert_true(ps_v3_isfinite(out));
                assert_near(ps_v3_len(out), 1.0, 1e-9);
                assert_true(out.y < 0.0 || fabs(out.y) < 1e-2); /* nearly along the surface, onward */
            }
        }
        /* Grazing from outside: Fresnel 1 in the limit, never above it. */
        assert_true(ps_fresnel_dielectric(0.0, 1.0, iors[k]) <= 1.0);
        assert_true(ps_fresnel_dielectric(1e-300, 1.0, iors[k]) <= 1.0);
    }
}

/* ---- the splat basis along and near the axes --------------------------------- */

static void splat_basis_axes(void **state)
{
    (void)state;
    const double offs[] = {0.0, 1e-7, -1e-7};
    ps_material white;
    memset(&white, 0, sizeof white);
    white.type = PS_MAT_DIFFUSE;
    white.albedo = ps_rgb_gray(0.5);
    for (int axis = 0; axis < 3; axis++)
        for (int sign = -1; sign <= 1; sign += 2)
            for (size_t a = 0; a < 3; a++)
                for (size_t b = 0; b < 3; b++) {
                    double v[3] = {0, 0, 0};
                    v[axis] = sign;
                    v[(axis + 1) % 3] = offs[a];
                    v[(axis + 2) % 3] = offs[b];
                    ps_vec3 n = ps_v3_norm(ps_v3(v[0], v[1], v[2])), x, y;
                    ps_splat_basis(n, &x, &y);
                    assert_true(ps_v3_isfinite(x) && ps_v3_isfinite(y));
                    assert_near(ps_v3_len(x), 1.0, 1e-12);
                    assert_near(ps_v3_len(y), 1.0, 1e-12);
                    assert_near(ps_v3_dot(x, y), 0.0, 1e-12);
                    assert_near(ps_v3_dot(x, n), 0.0, 1e-12);
                    assert_near(ps_v3_dot(y, n), 0.0, 1e-12);
                    assert_true(ps_v3_max_abs(ps_v3_sub(ps_v3_cross(x, y), n)) < 1e-12);
                    /* The triangle splat of a photon with this normal, seen
                     * from 3 m along it: in the surface's plane, of area
                     * 3 sqrt(3) r^2 (the equilateral triangle around the disc). */
                    ps_vec3 pos = ps_v3(0.25, -0.5, 0.75);
                    ps_photon ph = ps_photon_pack(pos, ps_rgb_gray(1.0), ps_v3_neg(n), n, 0.5);
                    uint16_t mat = 0;
                    ps_vec3 up = axis == 1 ? ps_v3(0, 0, 1) : ps_v3(0, 1, 0);
                    ps_camera c = {ps_v3_madd(pos, n, 3.0), pos, up, 40.0};
                    ps_splat_params p;
                    memset(&p, 0, sizeof p);
                    p.mode = PS_SPLAT_TRIANGLES;
                    p.radius = 0.05;
                    p.kernel_mean = 0.5;
                    p.kernel_extent = 1.0;
                    p.scale = 1.0;
                    p.levels = 0;
                    p.materials = &white;
                    p.cam = ps_camera_frame_make(&c, 64, 64);
                    ps_splat_batch bt;
                    ps_splat_batch_init(&bt);
                    ps_error err;
                    assert_int_equal(ps_splat_build(&ph, &mat, 1, &p, &bt, &err), PS_OK);
                    assert_int_equal(bt.vertex_count, 3);
                    ps_vec3 q[3];
                    for (int k = 0; k < 3; k++) {
                        q[k] = ps_v3(bt.positions[3 * k], bt.positions[3 * k + 1], bt.positions[3 * k + 2]);
                        assert_true(ps_v3_isfinite(q[k]));
                        assert_true(isfinite(bt.colors[4 * k]) && bt.colors[4 * k] > 0.0f);
                    }
                    ps_vec3 cr = ps_v3_cross(ps_v3_sub(q[1], q[0]), ps_v3_sub(q[2], q[0]));
                    double area = 0.5 * ps_v3_len(cr);
                    assert_near(area, 3.0 * sqrt(3.0) * p.radius * p.radius, 1e-5);
                    /* Its plane is the stored normal's (7+7 bits: 1.5 degrees). */
                    assert_true(ps_v3_dot(ps_v3_norm(cr), ps_photon_normal(&ph)) > cos(1.5 * PS_PI / 180.0));
                    ps_splat_batch_free(&bt);
                }
}

/* ---- NaN and Inf at parse time ------------------------------------------------- */

static const char *const bad_numbers[] = {"nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e999", "-1e999",
                                          "0x1p99999"};

/* Replaces the idx-th token of line `line` (from 1) of text by word. False
 * when the line has no such token. */
static bool replace_token(const char *text, int line, int idx, const char *word, char *out, size_t size)
{
    const char *p = text;
    for (int l = 1; l < line && p; l++) {
        p = strchr(p, '\n');
        if (p)
            p++;
    }
    if (!p || !*p)
        return false;
    const char *eol = strchr(p, '\n');
    if (!eol)
        eol = p + strlen(p);
    const char *t = p;
    for (int k = 0;; k++) {
        while (t < eol && (*t == ' ' || *t == '\t'))
            t++;
        if (t >= eol || *t == '#')
            return false;
        const char *e = t;
        while (e < eol && *e != ' ' && *e != '\t')
            e++;
        if (k == idx) {
            int n = snprintf(out, size, "%.*s%s%s", (int)(t - text), text, word, e);
            assert_true(n > 0 && (size_t)n < size);
            return true;
        }
        t = e;
    }
}

static bool is_number(const char *text, int line, int idx)
{
    char buf[16384];
    if (!replace_token(text, line, idx, "@", buf, sizeof buf))
        return false;
    /* Find the token again: the character where the copies differ. */
    size_t at = 0;
    while (buf[at] == text[at])
        at++;
    char *end;
    strtod(text + at, &end);
    return end != text + at && (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\0' || *end == '\r');
}

/* Every number of the default scene, replaced in turn by each spelling of a
 * non-finite value: refused, naming the file and that line. */
static void nan_inf_in_scenes(void **state)
{
    (void)state;
    const char *text = read_text("data/scenes/cornell-caustic.scn");
    static char orig[16384], bad[16384];
    snprintf(orig, sizeof orig, "%s", text);
    int tried = 0;
    for (int line = 1; line < 60; line++)
        for (int idx = 1; idx < 16; idx++) {
            if (!is_number(orig, line, idx))
                continue;
            for (size_t w = 0; w < sizeof bad_numbers / sizeof *bad_numbers; w++) {
                assert_true(replace_token(orig, line, idx, bad_numbers[w], bad, sizeof bad));
                ps_scene *s = NULL;
                ps_error err;
                ps_status st = ps_scene_load_text(bad, "inline.scn", "", NULL, &s, &err);
                char want[64];
                snprintf(want, sizeof want, "inline.scn:%d:", line);
                if (st == PS_OK || strncmp(err.msg, want, strlen(want)) != 0 || strchr(err.msg, '\n'))
                    fail_msg("line %d token %d = %s: status %d, message '%s'", line, idx, bad_numbers[w], (int)st,
                             st == PS_OK ? "" : err.msg);
                assert_null(s);
                tried++;
            }
        }
    printf("%d non-finite numbers refused in the default scene\n", tried);
    assert_true(tried > 200);
}

/* The same for every number of an OBJ (v, vn, vt) and its MTL (Kd, Ks, Ke,
 * Tf, Ns, Ni, d, Tr), loaded through a scene. */
static void nan_inf_in_obj_mtl(void **state)
{
    (void)state;
    const char *obj = "mtllib s.mtl\n"
                      "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                      "vn 0 0 1\nvt 0.5 0.5\n"
                      "usemtl a\nf 1/1/1 2/1/1 3/1/1\n";
    const char *mtl = "newmtl a\nKd 0.5 0.5 0.5\nKs 0.1 0.1 0.1\nKe 0 0 0\nTf 1 1 1\nNs 10\nNi 1.5\nd 1\nTr 0\n";
    const char *scene = "camera eye 0 0 3 target 0 0 0\nmesh s.obj\nlight point position 0 0 1 power 1 1 1\n";
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path("s.obj"));
    *strrchr(dir, '/') = '\0';
    int tried = 0;
    for (int which = 0; which < 2; which++) {
        const char *orig = which ? mtl : obj;
        const char *name = which ? "s.mtl" : "s.obj";
        for (int line = 1; line < 12; line++)
            for (int idx = 1; idx < 4; idx++) {
                if (!is_number(orig, line, idx))
                    continue;
                for (size_t w = 0; w < sizeof bad_numbers / sizeof *bad_numbers; w++) {
                    char bad[1024];
                    assert_true(replace_token(orig, line, idx, bad_numbers[w], bad, sizeof bad));
                    write_file_at("s.obj", which ? obj : bad);
                    write_file_at("s.mtl", which ? bad : mtl);
                    ps_scene *s = NULL;
                    ps_error err;
                    ps_status st = ps_scene_load_text(scene, "inline.scn", dir, NULL, &s, &err);
                    char want[64];
                    snprintf(want, sizeof want, "%s:%d:", name, line);
                    if (st == PS_OK || !strstr(err.msg, want) || !strstr(err.msg, "not a finite number"))
                        fail_msg("%s line %d token %d = %s: status %d, message '%s'", name, line, idx, bad_numbers[w],
                                 (int)st, st == PS_OK ? "" : err.msg);
                    assert_null(s);
                    tried++;
                }
            }
    }
    /* And the originals load. */
    write_file_at("s.obj", obj);
    write_file_at("s.mtl", mtl);
    ps_scene *s = NULL;
    ps_error err;
    assert_int_equal(ps_scene_load_text(scene, "inline.scn", dir, NULL, &s, &err), PS_OK);
    ps_scene_destroy(s);
    printf("%d non-finite numbers refused in OBJ and MTL files\n", tried);
    assert_true(tried > 100);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(rgbe_extremes),
        cmocka_unit_test(light_power_extremes),
        cmocka_unit_test(light_power_limit),
        cmocka_unit_test(scaled_default_scene),
        cmocka_unit_test(degenerate_triangles),
        cmocka_unit_test(coincident_faces),
        cmocka_unit_test(light_on_mirror_plane),
        cmocka_unit_test(light_inside_glass),
        cmocka_unit_test(mirror_furnace),
        cmocka_unit_test(light_inside_bounding_sphere),
        cmocka_unit_test(grazing_incidence),
        cmocka_unit_test(ior_one_is_invisible),
        cmocka_unit_test(ior_four),
        cmocka_unit_test(total_internal_reflection),
        cmocka_unit_test(splat_basis_axes),
        cmocka_unit_test(nan_inf_in_scenes),
        cmocka_unit_test(nan_inf_in_obj_mtl),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
