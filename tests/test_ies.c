/* test_ies.c: the LM-63 reader (a good corpus of every format and symmetry
 * with candela worked out by hand, a bad corpus of one-line refusals), the
 * table's integral and sampler against brute force, photometric units on
 * every light type, and the photons an IES light emits. */
#include "test.h"
#include "rig.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>

#include "core/photometry.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "photon/emit.h"
#include "scene/ies.h"
#include "scene/scene.h"

#define DEG (PS_PI / 180.0)

static ps_ies *load_ies(const char *path)
{
    ps_ies *ies = NULL;
    ps_error err;
    if (ps_ies_load(path, &ies, &err) != PS_OK)
        fail_msg("%s", err.msg);
    return ies;
}

/* The integral of the candela over the sphere by the midpoint rule on a fine
 * grid: the oracle for ps_ies_flux, which integrates cell by cell in closed form. */
static double brute_flux(const ps_ies *ies, int n)
{
    double sum = 0.0, dt = PS_PI / n, dp = 2.0 * PS_PI / n;
    for (int i = 0; i < n; i++) {
        double t = (i + 0.5) * dt;
        for (int j = 0; j < n; j++)
            sum += ps_ies_candela(ies, t, (j + 0.5) * dp) * sin(t) * dt * dp;
    }
    return sum;
}

/* Every file of tests/data/ies-good: its `[_CHECK] THETA PHI CANDELA` lines
 * (degrees; worked out by hand from its table, multipliers and symmetry)
 * and `[_TILT] DEGREES FACTOR`; the flux against brute force. */
static void good_corpus(void **state)
{
    (void)state;
    const char *dir = "tests/data/ies-good";
    DIR *d = opendir(dir);
    assert_non_null(d);
    int files = 0, checks = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (!strstr(e->d_name, ".ies"))
            continue;
        char path[512];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        ps_ies *ies = load_ies(path);
        FILE *f = fopen(path, "rb");
        char line[512];
        while (fgets(line, sizeof line, f)) {
            double t, p, c;
            if (sscanf(line, "[_CHECK] %lf %lf %lf", &t, &p, &c) == 3) {
                double got = ps_ies_candela(ies, t * DEG, p * DEG);
                if (!(fabs(got - c) <= 1e-9 * (1.0 + c)))
                    fail_msg("%s: candela at (%g, %g) is %.12g, by hand %.12g", path, t, p, got, c);
                checks++;
            } else if (sscanf(line, "[_TILT] %lf %lf", &t, &c) == 2) {
                assert_near(ps_ies_tilt_factor(ies, t), c, 1e-12);
                checks++;
            }
        }
        fclose(f);
        double flux = ps_ies_flux(ies), brute = brute_flux(ies, 2000);
        printf("%-28s %-10s flux %.6g lm (brute force %.6g), peak %g cd\n", e->d_name, ps_ies_get_info(ies)->format,
               flux, brute, ps_ies_peak(ies));
        assert_near(flux, brute, 1e-4 * flux);
        ps_ies_destroy(ies);
        files++;
    }
    closedir(d);
    assert_int_equal(files, 6);
    assert_true(checks >= 30);
}

/* Formats told by the first line, the multipliers each applies. */
static void formats_and_factors(void **state)
{
    (void)state;
    ps_ies *ies = load_ies("tests/data/ies-good/1995-bilateral-tilt.ies");
    assert_string_equal(ps_ies_get_info(ies)->format, "LM-63-1995");
    assert_near(ps_ies_get_info(ies)->multiplier, 0.5, 1e-15); /* 2 x 0.5 x 0.5 */
    assert_int_equal(ps_ies_get_info(ies)->has_tilt, 1);
    ps_ies_destroy(ies);
    ies = load_ies("tests/data/ies-good/2019-full.ies");
    assert_string_equal(ps_ies_get_info(ies)->format, "LM-63-2019");
    assert_near(ps_ies_get_info(ies)->multiplier, 2.0, 1e-15); /* not x 1.1: that is the generation type */
    ps_ies_destroy(ies);
    ies = load_ies("tests/data/ies-good/1986-rotational.ies");
    assert_string_equal(ps_ies_get_info(ies)->format, "LM-63-1986");
    assert_near(ps_ies_get_info(ies)->lamp_lumens, 1000, 0);
    /* 100 80 40 0 at 0 30 60 90 degrees, rotationally symmetric: flux by hand,
     * 2 pi sum over cells of the integral of the linear candela times sin. */
    double flux = 0.0, a[4] = {0, 30 * DEG, 60 * DEG, 90 * DEG}, c[4] = {100, 80, 40, 0};
    for (int i = 0; i < 3; i++) {
        double d = a[i + 1] - a[i];
        double k1 = (sin(a[i + 1]) - sin(a[i]) - d * cos(a[i + 1])) / d, k0 = cos(a[i]) - cos(a[i + 1]) - k1;
        flux += 2.0 * PS_PI * (c[i] * k0 + c[i + 1] * k1);
    }
    assert_near(ps_ies_flux(ies), flux, 1e-9 * flux);
    ps_ies_destroy(ies);
}

/* A constant 50 cd over the whole sphere (0-180, one horizontal angle):
 * exactly 4 pi 50 lm. A cone 0-90 linear 100..0: (2 pi - 4) 100 lm. */
static void closed_form_flux(void **state)
{
    (void)state;
    const char *uniform = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 180\n0\n50 50\n";
    const char *linear = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n100 0\n";
    ps_ies *ies;
    ps_error err;
    assert_int_equal(ps_ies_parse(uniform, strlen(uniform), "u.ies", &ies, &err), PS_OK);
    assert_near(ps_ies_flux(ies), 4.0 * PS_PI * 50.0, 1e-10);
    ps_ies_destroy(ies);
    assert_int_equal(ps_ies_parse(linear, strlen(linear), "l.ies", &ies, &err), PS_OK);
    assert_near(ps_ies_flux(ies), (2.0 * PS_PI - 4.0) * 100.0, 1e-10);
    ps_ies_destroy(ies);
}

/* Sizes beyond the limits are refused before anything is allocated. */
static void limits(void **state)
{
    (void)state;
    const char *many = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2000 1000 1 2 0 0 0\n1 1 0\n";
    const char *angles = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 20000 1 1 2 0 0 0\n1 1 0\n";
    ps_ies *ies;
    ps_error err;
    assert_int_equal(ps_ies_parse(many, strlen(many), "m.ies", &ies, &err), PS_ERR_LIMIT);
    assert_non_null(strstr(err.msg, "m.ies:3: 2000 x 1000 candela values are more than"));
    assert_int_equal(ps_ies_parse(angles, strlen(angles), "a.ies", &ies, &err), PS_ERR_LIMIT);
    assert_non_null(strstr(err.msg, "a.ies:3: the number of vertical angles: 20000 is outside"));
}

/* Every file of tests/data/ies-bad is refused with "file:LINE: FRAGMENT" as
 * its `[_EXPECT] LINE: FRAGMENT` line says; a directory is refused too. */
static void bad_corpus(void **state)
{
    (void)state;
    const char *dir = "tests/data/ies-bad";
    DIR *d = opendir(dir);
    assert_non_null(d);
    int files = 0, wrong = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (!strstr(e->d_name, ".ies"))
            continue;
        char path[512], line[512], fragment[400] = "", want[1024];
        int at = 0;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        FILE *f = fopen(path, "rb");
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "[_EXPECT] %d: %399[^\n]", &at, fragment) == 2)
                break;
        fclose(f);
        assert_true(at > 0);
        ps_ies *ies = (ps_ies *)1;
        ps_error err;
        ps_status st = ps_ies_load(path, &ies, &err);
        assert_int_not_equal(st, PS_OK);
        assert_null(ies);
        snprintf(want, sizeof want, "%s:%d: %s", path, at, fragment);
        if (strncmp(err.msg, want, strlen(want)) != 0) {
            printf("%s: got \"%s\", want \"%s...\"\n", e->d_name, err.msg, want);
            wrong++;
        }
        assert_null(strchr(err.msg, '\n'));
        files++;
    }
    closedir(d);
    assert_int_equal(wrong, 0);
    assert_int_equal(files, 22);
    ps_ies *ies;
    ps_error err;
    assert_int_not_equal(ps_ies_load("tests/data", &ies, &err), PS_OK);
    assert_non_null(strstr(err.msg, "tests/data"));
    assert_int_not_equal(ps_ies_load("tests/data/ies-good/nonexistent.ies", &ies, &err), PS_OK);
}

/* The sampler's directions follow candela / flux: the fraction of samples in
 * each of 12 x 16 solid-angle bins against the bin's integral, on the
 * asymmetric wall washer; and the density it returns is candela / flux. */
static void sampler_matches_table(void **state)
{
    (void)state;
    ps_ies *ies = load_ies("data/ies/wallwasher.ies");
    enum { NT = 12, NP = 16, N = 400000 };
    static double count[NT][NP];
    memset(count, 0, sizeof count);
    ps_rng rng = ps_rng_make(7, PS_STREAM_TEST, 0);
    double flux = ps_ies_flux(ies);
    for (int k = 0; k < N; k++) {
        double u0 = ps_rng_uniform(&rng), u1 = ps_rng_uniform(&rng), u2 = ps_rng_uniform(&rng), t, p;
        double pdf = ps_ies_sample(ies, u0, u1, u2, &t, &p);
        if (k < 1000)
            assert_near(pdf, ps_ies_candela(ies, t, p) / flux, 1e-12 * pdf);
        assert_true(t >= 0 && t <= PS_PI && pdf > 0);
        p = fmod(p, 2 * PS_PI);
        int i = (int)(t / PS_PI * NT), j = (int)(p / (2 * PS_PI) * NP);
        count[i < NT ? i : NT - 1][j < NP ? j : NP - 1] += 1.0 / N;
    }
    double worst = 0;
    for (int i = 0; i < NT; i++)
        for (int j = 0; j < NP; j++) {
            double expect = 0;
            int m = 40;
            for (int a = 0; a < m; a++)
                for (int b = 0; b < m; b++) {
                    double t = (i + (a + 0.5) / m) * PS_PI / NT, p = (j + (b + 0.5) / m) * 2 * PS_PI / NP;
                    expect += ps_ies_candela(ies, t, p) * sin(t) * (PS_PI / NT / m) * (2 * PS_PI / NP / m) / flux;
                }
            /* Four binomial standard deviations, plus the brute-force integral's error. */
            double sigma = sqrt(expect * (1 - expect) / N);
            if (!(fabs(count[i][j] - expect) <= 4 * sigma + 1e-4 * expect))
                fail_msg("bin (%d, %d): %.5f of the samples, %.5f of the flux", i, j, count[i][j], expect);
            worst = fmax(worst, expect > 0.01 ? fabs(count[i][j] - expect) / expect : 0);
        }
    printf("sampler: worst bin holding > 1 %% of the flux %.2f %% off\n", 100 * worst);
    ps_ies_destroy(ies);
}

/* ---- scenes -------------------------------------------------------------- */

static ps_scene *load_scene(const char *text)
{
    ps_scene *s;
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    return s;
}

static void refuse_scene(const char *text, const char *fragment)
{
    ps_scene *s;
    ps_error err;
    assert_int_not_equal(ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err), PS_OK);
    if (!strstr(err.msg, fragment))
        fail_msg("got \"%s\", want \"%s\"", err.msg, fragment);
}

/* lumens and candela on every light type, and color: 683 lm/W times Y. */
static void photometric_units(void **state)
{
    (void)state;
    static const struct {
        const char *light;
        double lumens; /* what it must emit */
    } cases[] = {
        {"light point position 0 1 0 lumens 683", 683},
        {"light point position 0 1 0 candela 100", 4 * PS_PI * 100},
        {"light point position 0 1 0 lumens 800 color 1 0.5 0.25", 800},
        {"light spot position 0 1 0 direction 0 -1 0 angle 30 candela 50", 50 * 2 * PS_PI * (1 - 0.86602540378443865)},
        {"light quad corner 0 1 0 edge1 1 0 0 edge2 0 0 1 candela 10", 10 * PS_PI},
        {"light disc center 0 1 0 normal 0 -1 0 radius 0.2 lumens 1234", 1234},
        {"light sphere center 0 1 0 radius 0.1 candela 7", 7 * 4 * PS_PI},
        {"light point position 0 1 0 power 1 2 3", 683 * (0.2126 + 2 * 0.7152 + 3 * 0.0722)},
        {"light ies data/ies/downlight-narrow.ies position 0 2 0 lumens 1200 color 1 0.9 0.8", 1200},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char text[512];
        snprintf(text, sizeof text, "camera eye 0 1 3 target 0 1 0\n%s\n", cases[k].light);
        ps_scene *s = load_scene(text);
        assert_near(ps_scene_total_lumens(s), cases[k].lumens, 1e-9 * cases[k].lumens);
        ps_scene_destroy(s);
    }
    /* lumens 683 white: 1 W in each channel; red: R = 1 / 0.2126. */
    ps_scene *s = load_scene("camera eye 0 1 3 target 0 1 0\nlight point position 0 1 0 lumens 683 color 1 0 0\n");
    size_t n;
    const ps_light *l = ps_scene_lights(s, &n);
    assert_near(l->power.r, 1.0 / 0.2126, 1e-12);
    assert_near(l->power.g, 0.0, 0);
    assert_near(ps_photometric(l->power), 683.0, 1e-9);
    ps_scene_destroy(s);

    const char *cam = "camera eye 0 1 3 target 0 1 0\n";
    char text[512];
#define REFUSE(light, fragment)                                                                                \
    (snprintf(text, sizeof text, "%s%s\n", cam, light), refuse_scene(text, fragment))
    REFUSE("light point position 0 1 0 power 1 1 1 lumens 5", "inline.scn:2: light point: give one of");
    REFUSE("light point position 0 1 0 power 1 1 1 color 1 0 0", "inline.scn:2: light point: 'color' goes with");
    REFUSE("light point position 0 1 0 lumens -5", "'lumens' must not be negative");
    REFUSE("light point position 0 1 0 candela 5 color 0 0 0", "'color' must be non-negative with some luminance");
    REFUSE("light point position 0 1 0", "missing 'power'");
    REFUSE("light spot position 0 1 0 direction 0 -1 0 angle 20 lumens 1 candela 2", "give one of");
    REFUSE("light point position 0 1 0 lumens 1e40", "above the");
    REFUSE("light ies data/ies/none.ies position 0 1 0", "inline.scn:2: light ies: ");
    REFUSE("light ies tests/data/ies-bad/04-negative-candela.ies position 0 1 0",
           "tests/data/ies-bad/04-negative-candela.ies:9: candela value 2 is negative (-5) (light ies at inline.scn:2)");
    REFUSE("light ies data/ies/batwing.ies position 0 1 0 aim 0 0 0", "'aim' must not be the zero vector");
    REFUSE("light ies data/ies/batwing.ies aim 0 -1 0", "missing 'position'");
    REFUSE("light ies", "missing IES file name");
#undef REFUSE
}

/* An ies light's own flux, its frame (aim, spin) and the clone. */
static void ies_light_frame(void **state)
{
    (void)state;
    ps_scene *s = load_scene("camera eye 0 1 3 target 0 1 0\n"
                             "light ies data/ies/batwing.ies position 0 3 0\n"
                             "light ies data/ies/batwing.ies position 0 3 0 spin 90\n"
                             "light ies data/ies/batwing.ies position 0 3 0 aim 1 0 0\n");
    size_t n;
    const ps_light *l = ps_scene_lights(s, &n);
    assert_int_equal(n, 3);
    const ps_ies *ies = ps_scene_ies_profile(s, l[0].profile);
    /* Its table's flux, white: flux / 683 W a channel. */
    assert_near(ps_scene_total_lumens(s), ps_ies_flux(ies) * (2.0 + 0.9), 1e-9 * ps_ies_flux(ies));
    assert_near(l[0].power.g, ps_ies_flux(ies) / 683.0, 1e-12);
    assert_near(l[2].power.g, ps_ies_flux(ies) * 0.9 / 683.0, 1e-12); /* TILT=INCLUDE: 0.9 at 90 degrees */
    /* Default aim straight down: horizontal 0 is +x, 90 is -z (counter-clockwise from above). */
    ps_vec3 d = ps_light_ies_direction(&l[0], 90 * DEG, 0);
    assert_near(d.x, 1, 1e-12);
    d = ps_light_ies_direction(&l[0], 90 * DEG, 90 * DEG);
    assert_near(d.z, -1, 1e-12);
    d = ps_light_ies_direction(&l[0], 0, 0);
    assert_near(d.y, -1, 1e-12);
    d = ps_light_ies_direction(&l[1], 90 * DEG, 0); /* spin 90: horizontal 0 where 90 was */
    assert_near(d.z, -1, 1e-12);
    /* The density is candela / flux, and the angles invert the direction. */
    for (int k = 0; k < 20; k++) {
        double t = (k * 9 + 1) * DEG, p = (k * 37 + 3) * DEG, t2, p2;
        ps_vec3 w = ps_light_ies_direction(&l[2], t, p);
        ps_light_ies_angles(&l[2], w, &t2, &p2);
        assert_near(t2, t, 1e-9);
        assert_near(ps_light_ies_density(s, &l[2], w), ps_ies_candela(ies, t, p) / ps_ies_flux(ies), 1e-12);
    }
    ps_scene *c;
    ps_error err;
    assert_int_equal(ps_scene_clone(s, &c, &err), PS_OK);
    ps_scene_destroy(s);
    l = ps_scene_lights(c, &n);
    assert_true(ps_scene_ies_profile(c, l[1].profile) != NULL);
    assert_near(ps_light_ies_density(c, &l[0], ps_v3(0, -1, 0)),
                ps_ies_candela(ps_scene_ies_profile(c, 0), 0, 0) / ps_ies_flux(ps_scene_ies_profile(c, 0)), 1e-15);
    ps_scene_destroy(c);
}

/* ---- photons ------------------------------------------------------------- */

/* The photons an IES light emits carry its lumens (each flux / N, the
 * directions from the table): traced into a closed sphere around it, the
 * global map with first hits keeps every photon once where it first lands, and their power sums to the
 * light's flux within 0.5 %; the stored directions follow the table. */
static void photons_carry_lumens(void **state)
{
    (void)state;
    const char *text = "camera eye 0 0 0.5 target 0 0 0\n"
                       "material grey diffuse albedo 0.5 0.5 0.5\n"
                       "sphere center 0 0 0 radius 10 material grey\n"
                       "light ies data/ies/wallwasher.ies position 0 0 0 aim 0 -1 0 spin 30 lumens 2500 color 1 0.8 0.6\n";
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 11;
    o.threads = 2;
    o.global_direct = true;
    rig r = rig_make(text, "", &o, PS_ACCEL_AUTO);
    uint64_t n = 100000;
    ps_photon_map m = rig_trace(&r, PS_MAP_GLOBAL, n);
    ps_rgb sum = ps_rgb_gray(0);
    size_t nl;
    const ps_light *L = ps_scene_lights(r.scene, &nl);
    size_t first = 0;
    double up = 0, toward0 = 0; /* flux fractions: above the horizontal, and towards horizontal angle 0 */
    for (size_t k = 0; k < m.count; k++) {
        /* First hits travel radially (the light is at the centre); what
         * bounced comes from elsewhere on the sphere. */
        ps_vec3 radial = ps_v3_norm(ps_photon_position(&m.photons[k]));
        if (ps_v3_dot(ps_photon_dir(&m.photons[k]), radial) < 0.9997)
            continue;
        first++;
        sum = ps_rgb_add(sum, ps_photon_power(&m.photons[k]));
        double t, ph; /* from the position: the stored direction has 8-bit rounding */
        ps_light_ies_angles(&L[0], radial, &t, &ph);
        up += t > PS_PI / 2 + 1e-6 ? 1 : 0;
        toward0 += cos(ph) > 0 ? 1 : 0;
    }
    double lumens = ps_photometric(sum);
    printf("photons from an IES light: %zu first hits, %.2f lm of 2500; %.4f towards horizontal 0\n", first, lumens,
           toward0 / (double)first);
    assert_true(first >= n && first < n + n / 1000);
    assert_near(lumens, 2500.0, 0.005 * 2500.0);
    /* The table ends at 90 degrees: only the few bounced photons that passed
     * the radial test (from near the antipode, below) land above. */
    assert_true(up <= (double)(first - n));
    /* The fraction of the table's flux with cos(phi) > 0, by brute force. */
    const ps_ies *ies = ps_scene_ies_profile(r.scene, 0);
    double half = 0, all = 0;
    for (int i = 0; i < 400; i++)
        for (int j = 0; j < 800; j++) {
            double t = (i + 0.5) * PS_PI / 400, ph = (j + 0.5) * 2 * PS_PI / 800;
            double w = ps_ies_candela(ies, t, ph) * sin(t);
            all += w;
            half += cos(ph) > 0 ? w : 0;
        }
    assert_near(toward0 / (double)first, half / all, 4 * sqrt(0.25 / n));
    ps_photon_map_free(&m);
    rig_free(&r);
}

/* Inside a caustic cone the photons are uniform and weighted by the table:
 * the mean power over the cone is the flux the table sends into it. */
static void cone_weighting(void **state)
{
    (void)state;
    ps_scene *s = load_scene("camera eye 0 0 3 target 0 0 0\n"
                             "light ies data/ies/batwing.ies position 0 0 0 lumens 1000\n");
    ps_light_sampler *ls;
    ps_error err;
    assert_int_equal(ps_light_sampler_create(s, &ls, &err), PS_OK);
    size_t nl;
    const ps_light *L = ps_scene_lights(s, &nl);
    ps_caustic_cone cone = {ps_v3_norm(ps_v3(0.6, -0.7, 0.2)), cos(20 * DEG)};
    ps_rng rng = ps_rng_make(3, PS_STREAM_TEST, 0);
    double sum = 0;
    int n = 200000;
    for (int k = 0; k < n; k++) {
        double u[4] = {ps_rng_uniform(&rng), ps_rng_uniform(&rng), ps_rng_uniform(&rng), ps_rng_uniform(&rng)};
        ps_emission e;
        if (ps_light_emit(ls, 0, &cone, u, &e)) {
            assert_true(ps_v3_dot(e.ray.d, cone.axis) >= cone.cos_half - 1e-12);
            sum += ps_photometric(e.power);
        }
    }
    /* The flux into the cone: the candela integrated over it (fine grid in the cone's own frame). */
    double inside = 0;
    int m = 600;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            double u1 = (i + 0.5) / m, u2 = (j + 0.5) / m;
            ps_vec3 d = ps_sample_cone(u1, u2, cone.axis, cone.cos_half);
            inside += ps_light_ies_density(s, &L[0], d);
        }
    inside *= ps_cone_solid_angle(cone.cos_half) / ((double)m * m) * 1000.0;
    printf("cone: %.3f lm of photon power, %.3f lm of the table in the cone\n", sum / n, inside);
    assert_near(sum / n, inside, 0.01 * inside);
    ps_light_sampler_destroy(ls);
    ps_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(good_corpus),       cmocka_unit_test(formats_and_factors),
        cmocka_unit_test(closed_form_flux),  cmocka_unit_test(bad_corpus), cmocka_unit_test(limits),
        cmocka_unit_test(sampler_matches_table), cmocka_unit_test(photometric_units),
        cmocka_unit_test(ies_light_frame),   cmocka_unit_test(photons_carry_lumens),
        cmocka_unit_test(cone_weighting),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
