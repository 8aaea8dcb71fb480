/* test_tracer.c: the photon tracer against closed-form answers: flux in a
 * closed box, the caustic of a mirror quad, overlapping caustic cones, no
 * leaks, per-index determinism, scale invariance and the skip rules. */
#include "test.h"
#include "rig.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/sampling.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "scene/scene.h"

static ps_tracer_options options(int threads)
{
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 7;
    o.threads = threads;
    return o;
}

/* A closed box [-1,1]^3 of six inward quads with albedo rho and three lights
 * of one colour each, so each channel's flux is one light's power. */
static void box_scene(char *buf, size_t size, double rho)
{
    snprintf(buf, size,
             "camera eye 0 0 0.5 target 0 0 0\n"
             "material wall diffuse albedo %g %g %g\n"
             "quad corner -1 -1 -1 edge1 0 0 2 edge2 2 0 0 material wall\n" /* floor, +y */
             "quad corner -1 1 -1 edge1 2 0 0 edge2 0 0 2 material wall\n"  /* ceiling, -y */
             "quad corner -1 -1 -1 edge1 0 2 0 edge2 0 0 2 material wall\n" /* x = -1, +x */
             "quad corner 1 -1 -1 edge1 0 0 2 edge2 0 2 0 material wall\n"  /* x = +1, -x */
             "quad corner -1 -1 -1 edge1 2 0 0 edge2 0 2 0 material wall\n" /* z = -1, +z */
             "quad corner -1 -1 1 edge1 0 2 0 edge2 2 0 0 material wall\n"  /* z = +1, -z */
             "light point position 0.2 0.3 -0.1 power 30 0 0\n"
             "light quad corner -0.2 0.9 -0.2 edge1 0.4 0 0 edge2 0 0 0.4 power 0 50 0\n"
             "light sphere center -0.4 -0.5 0.3 radius 0.1 power 0 0 20\n",
             rho, rho, rho);
}

/* Stored global flux in a closed box: every photon bounces until absorbed, and
 * photons after the first bounce are stored, so the flux is
 * Phi (rho + rho^2 + ...) = Phi rho / (1 - rho). */
static void furnace_box(void **state)
{
    (void)state;
    double rhos[2] = {0.5, 0.8};
    for (int k = 0; k < 2; k++) {
        char text[2048];
        box_scene(text, sizeof text, rhos[k]);
        ps_tracer_options o = options(0);
        rig r = rig_make(text, "", &o, PS_ACCEL_AUTO);
        /* Russian roulette's noise: about 0.3 % (one sigma) at this count. */
        uint64_t n = 500000;
        ps_photon_map m = rig_trace(&r, PS_MAP_GLOBAL, n);
        ps_rgb flux = ps_photon_map_power(&m);
        double f = rhos[k] / (1.0 - rhos[k]);
        printf("furnace rho %.1f: stored flux %.4f %.4f %.4f W, expected %.4f %.4f %.4f W\n", rhos[k], flux.r, flux.g,
               flux.b, 30 * f, 50 * f, 20 * f);
        assert_int_equal(m.counters.escaped, 0);
        assert_int_equal(m.counters.emitted, n);
        /* Each light's photons carry exactly its flux: check per channel. */
        assert_near(flux.r, 30.0 * f, 30.0 * f * 0.01);
        assert_near(flux.g, 50.0 * f, 50.0 * f * 0.01);
        assert_near(flux.b, 20.0 * f, 20.0 * f * 0.01);
        /* The box has no specular object: no caustic pass, and it says why. */
        assert_false(ps_tracer_map_enabled(r.tracer, PS_MAP_CAUSTIC));
        size_t ns;
        const ps_skip *sk = ps_tracer_skips(r.tracer, &ns);
        assert_int_equal(ns, 1);
        assert_string_equal(sk[0].pass, "caustic");
        assert_non_null(strstr(sk[0].reason, "no specular"));
        ps_photon_map_free(&m);
        rig_free(&r);
    }
}

/* Photons are shared between lights in proportion to flux for every prefix,
 * within a few photons (the van der Corput sequence's discrepancy). */
static void photons_per_light(void **state)
{
    (void)state;
    char text[2048];
    box_scene(text, sizeof text, 0.5);
    ps_tracer_options o = options(1);
    rig r = rig_make(text, "", &o, PS_ACCEL_AUTO);
    uint64_t totals[] = {1, 7, 100, 1000, 12345, 1000000};
    double share[3] = {0.3, 0.5, 0.2};
    for (size_t k = 0; k < sizeof totals / sizeof *totals; k++) {
        uint64_t sum = 0;
        for (uint32_t l = 0; l < 3; l++) {
            uint64_t n = ps_tracer_light_photons(r.tracer, PS_MAP_GLOBAL, l, totals[k]);
            double expect = share[l] * (double)totals[k];
            if (fabs((double)n - expect) > 2.0 + log2((double)totals[k] + 1.0))
                fail_msg("total %llu light %u: %llu photons, expected %g", (unsigned long long)totals[k], l,
                         (unsigned long long)n, expect);
            sum += n;
        }
        assert_int_equal(sum, totals[k]);
    }
    rig_free(&r);
}

/* The ranks a trace finds for photon i and the photon sources' jobs start
 * from (each stratum's indices below, in closed form; the jobs 2^19 indices
 * long, on every core), against ranks counted here from index 0: 1.5*10^6
 * indices, three jobs, three strata, for one thread and two. */
static void ranks_across_job_seams(void **state)
{
    (void)state;
    char text[2048];
    box_scene(text, sizeof text, 0.5);
    const uint64_t total = 1500000;
    for (int threads = 1; threads <= 2; threads++) {
        ps_tracer_options o = options(threads);
        rig r = rig_make(text, "", &o, PS_ACCEL_AUTO);
        ps_photon_source *src = malloc(total * sizeof *src);
        assert_non_null(src);
        bool resampled[3] = {false, false, false};
        ps_error err;
        assert_int_equal(ps_tracer_photon_sources(r.tracer, r.tracer, PS_MAP_GLOBAL, total, total, resampled, 3, src,
                                                  &err),
                         PS_OK);
        uint64_t counted[3] = {0, 0, 0}, checked = 0;
        for (uint64_t i = 0; i < total; i++) {
            uint32_t k = src[i].stratum;
            assert_true(k < 3);
            uint64_t rank = counted[k]++;
            if (src[i].rank != rank || src[i].from != i) /* the same plan: every photon its own */
                fail_msg("photon %llu: source rank %llu from %llu, counted %llu", (unsigned long long)i,
                         (unsigned long long)src[i].rank, (unsigned long long)src[i].from, (unsigned long long)rank);
            /* The trace's lookup: every index near the jobs' seams (524288
             * apart), a sample elsewhere. */
            if ((i + 2000) % 524288 < 4000 || i % 97 == 0) {
                uint32_t kt;
                uint64_t rt;
                assert_true(ps_tracer_photon_rank(r.tracer, PS_MAP_GLOBAL, i, total, &kt, &rt));
                if (kt != k || rt != rank)
                    fail_msg("photon %llu: stratum %u rank %llu from the tracer, %u %llu counted", (unsigned long long)i,
                             kt, (unsigned long long)rt, k, (unsigned long long)rank);
                checked++;
            }
        }
        assert_true(checked > 20000);
        for (int k = 0; k < 3; k++) /* all three strata, each far past a job */
            assert_true(counted[k] > 200000);
        uint32_t kt;
        uint64_t rt;
        assert_false(ps_tracer_photon_rank(r.tracer, PS_MAP_GLOBAL, total, total, &kt, &rt));
        free(src);
        rig_free(&r);
    }
}

/* A mirror quad above a point light and a wide floor: the caustic is the
 * light of the mirror image of the source (at y = 3), seen through the mirror. */
static const char mirror_scene[] =
    "camera eye 0 1 5 target 0 1 0\n"
    "material floor diffuse albedo 0.5 0.5 0.5\n"
    "material mirror mirror reflectance 1 1 1\n"
    "quad corner -20 0 20 edge1 40 0 0 edge2 0 0 -40 material floor\n"
    "quad corner -0.5 2 -0.5 edge1 1 0 0 edge2 0 0 1 material mirror\n"
    "light point position 0 1 0 power 100 100 100\n";

static void mirror_caustic(void **state)
{
    (void)state;
    ps_tracer_options o = options(0);
    rig r = rig_make(mirror_scene, "", &o, PS_ACCEL_AUTO);
    ps_photon_map m = rig_trace(&r, PS_MAP_CAUSTIC, 200000);
    /* All that reaches the mirror lands on the floor: P Omega / (4 pi), with
     * the solid angle of a 1 x 1 square at distance 1: 4 asin(a b / sqrt((a^2+d^2)(b^2+d^2))). */
    double omega = 4.0 * asin(0.25 / 1.25);
    double total = 100.0 * omega / (4.0 * PS_PI);
    assert_near(ps_photon_map_power(&m).g, total, total * 0.01);
    /* Under the mirror, within radius a = 0.5 of the axis (inside the lit
     * footprint, half-width 1.5): the image source at height h = 3 gives
     * P / 2 (1 - h / sqrt(h^2 + a^2)). */
    double disc = 0.0;
    for (size_t i = 0; i < m.count; i++) {
        ps_vec3 p = ps_photon_position(&m.photons[i]);
        assert_near(p.y, 0.0, 1e-6);
        assert_true(fabs(p.x) <= 1.5 + 1e-3 && fabs(p.z) <= 1.5 + 1e-3);
        assert_true(ps_photon_dir(&m.photons[i]).y < 0.0);
        assert_near(ps_photon_normal(&m.photons[i]).y, 1.0, 1e-4);
        if (p.x * p.x + p.z * p.z <= 0.25)
            disc += ps_photon_power(&m.photons[i]).g;
    }
    double expect = 50.0 * (1.0 - 3.0 / sqrt(9.25));
    printf("mirror caustic: total %.5f W (analytic %.5f), under the mirror %.5f W (analytic %.5f)\n",
           ps_photon_map_power(&m).g, total, disc, expect);
    assert_near(disc, expect, expect * 0.01);
    /* Every caustic photon went into the cone; those that missed the mirror
     * (the cone is round, the mirror square) escaped upwards, unstored. */
    assert_true(m.counters.escaped > 0);
    assert_int_equal(m.counters.stored + m.counters.escaped, m.counters.emitted);
    ps_photon_map_free(&m);
    rig_free(&r);
}

/* Two specular objects whose cones overlap (the mirror sphere partly behind
 * the glass one, seen from the light). With cones and the first-hit test the
 * caustic flux equals plain emission over the whole sphere of directions;
 * without the test the overlap is counted twice. */
static const char overlap_scene[] =
    "camera eye 0 1 5 target 0 1 0\n"
    "material floor diffuse albedo 0.5 0.5 0.5\n"
    "material glass dielectric ior 1.5\n"
    "material mirror mirror reflectance 0.9 0.9 0.9\n"
    "quad corner -20 -0.5 20 edge1 40 0 0 edge2 0 0 -40 material floor\n"
    "sphere center 0 1 0 radius 0.3 material glass\n"
    "sphere center 0.5 0.5 0 radius 0.3 material mirror\n"
    "light point position 0 2 0 power 100 100 100\n";

static double caustic_flux(bool cones, bool first_hit, uint64_t n)
{
    ps_tracer_options o = options(0);
    o.caustic_cones = cones;
    o.first_hit_test = first_hit;
    rig r = rig_make(overlap_scene, "", &o, PS_ACCEL_AUTO);
    ps_photon_map m = rig_trace(&r, PS_MAP_CAUSTIC, n);
    double f = ps_photon_map_power(&m).g;
    ps_photon_map_free(&m);
    rig_free(&r);
    return f;
}

static void overlapping_cones(void **state)
{
    (void)state;
    double with = caustic_flux(true, true, 200000);
    double whole = caustic_flux(false, true, 2000000);
    double doubled = caustic_flux(true, false, 200000);
    printf("overlapping cones: %.4f W with cones, %.4f W over the whole sphere, %.4f W without the first-hit test\n",
           with, whole, doubled);
    if (fabs(with - whole) > 0.02 * whole)
        fail_msg("caustic flux %g W with cones, %g W over the whole sphere", with, whole);
    /* The test matters: without it the overlap adds a clear excess. */
    if (!(doubled > with * 1.05))
        fail_msg("without the first-hit test %g W, with it %g W: no double counting shown", doubled, with);
}

/* ---- leaks, determinism, scale ------------------------------------------- */

/* Writes an OBJ cube [-1,1]^3 of n x n squares a face, split into triangles
 * along alternating diagonals, all edges shared, normals inward. */
static void write_cube_obj(const char *path, int n)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    int verts = 0;
    for (int face = 0; face < 6; face++) {
        int axis = face / 2;
        double side = face % 2 ? 1.0 : -1.0;
        for (int i = 0; i <= n; i++)
            for (int j = 0; j <= n; j++) {
                double c[3];
                c[axis] = side;
                c[(axis + 1) % 3] = -1.0 + 2.0 * i / n;
                c[(axis + 2) % 3] = -1.0 + 2.0 * j / n;
                fprintf(f, "v %.17g %.17g %.17g\n", c[0], c[1], c[2]);
            }
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                int a = verts + i * (n + 1) + j + 1, b = a + 1, c = a + n + 1, d = c + 1;
                if ((i + j) % 2)
                    fprintf(f, "f %d %d %d\nf %d %d %d\n", a, b, d, a, d, c);
                else
                    fprintf(f, "f %d %d %d\nf %d %d %d\n", a, b, c, b, d, c);
            }
        verts += (n + 1) * (n + 1);
    }
    fclose(f);
}

/* A million photons in a closed mesh box (duplicated vertices on the cube's
 * edges: separate faces meet only edge to edge) never get out, with the
 * octree and the light placed on a cell boundary. */
static void no_leaks(void **state)
{
    (void)state;
    char obj[1024], dir[1024];
    snprintf(obj, sizeof obj, "%s", test_path("cube.obj"));
    snprintf(dir, sizeof dir, "%s", obj);
    *strrchr(dir, '/') = '\0';
    write_cube_obj(obj, 12);
    const char *text = "camera eye 0 0 0.5 target 0 0 0\n"
                       "material wall diffuse albedo 0.7 0.7 0.7\n"
                       "mesh cube.obj material wall\n"
                       "light point position 0 0 0 power 10 10 10\n"
                       "light point position 0.5 -0.5 0.5 power 10 10 10\n";
    ps_tracer_options o = options(0);
    rig r = rig_make(text, dir, &o, PS_ACCEL_OCTREE);
    ps_photon_map m = rig_trace(&r, PS_MAP_GLOBAL, 1000000);
    assert_int_equal(m.counters.emitted, 1000000);
    assert_int_equal(m.counters.escaped, 0);
    assert_true(m.counters.rays > 3000000); /* albedo 0.7: about 1/(1-0.7) rays a photon */
    for (size_t i = 0; i < m.count; i += 97) {
        ps_vec3 p = ps_photon_position(&m.photons[i]);
        assert_true(ps_v3_max_abs(p) <= 1.0 + 1e-6 && ps_v3_max_abs(p) >= 1.0 - 1e-6);
    }
    ps_photon_map_free(&m);
    rig_free(&r);
}

static const char *default_scene_path = "data/scenes/cornell-caustic.scn";

static rig rig_file(const char *path, const ps_tracer_options *opt)
{
    rig r;
    memset(&r, 0, sizeof r);
    ps_error err;
    if (ps_scene_load(path, NULL, &r.scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    if (ps_world_create(r.scene, NULL, &r.world, &err) != PS_OK)
        fail_msg("world: %s", err.msg);
    if (ps_tracer_create(r.world, opt, &r.tracer, &err) != PS_OK)
        fail_msg("tracer: %s", err.msg);
    return r;
}

static bool maps_equal(const ps_photon_map *a, const ps_photon_map *b)
{
    return a->count == b->count && memcmp(a->photons, b->photons, a->count * sizeof *a->photons) == 0 &&
           (a->count == 0 || (memcmp(a->materials, b->materials, a->count * sizeof *a->materials) == 0 &&
                              memcmp(a->objects, b->objects, a->count * sizeof *a->objects) == 0));
}

/* Photon i depends on (scene, seed, i) only: 1, 2 and 5 threads, and one
 * batch or many, give the same bytes; another seed does not. */
static void determinism(void **state)
{
    (void)state;
    uint64_t n = 30000;
    ps_photon_map ref[PS_MAP_COUNT];
    int threads[] = {1, 2, 5};
    for (int t = 0; t < 3; t++) {
        ps_tracer_options o = options(threads[t]);
        rig r = rig_file(default_scene_path, &o);
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            ps_photon_map m = rig_trace(&r, (ps_map_kind)k, n);
            assert_true(m.count > 1000);
            if (t == 0) {
                ref[k] = m;
                continue;
            }
            assert_true(maps_equal(&m, &ref[k]));
            ps_photon_map_free(&m);
            /* In uneven batches, which straddle the chunk size. */
            ps_photon_map b;
            ps_photon_map_init(&b, (ps_map_kind)k);
            uint64_t cuts[] = {0, 1, 1500, 1501, 17000, n};
            ps_error err;
            for (int c = 0; c + 1 < 6; c++)
                assert_int_equal(ps_tracer_trace(r.tracer, (ps_map_kind)k, cuts[c], cuts[c + 1] - cuts[c], n, &b, &err),
                                 PS_OK);
            assert_true(maps_equal(&b, &ref[k]));
            ps_photon_map_free(&b);
        }
        rig_free(&r);
    }
    ps_tracer_options o = options(2);
    o.seed = 8;
    rig r = rig_file(default_scene_path, &o);
    ps_photon_map other = rig_trace(&r, PS_MAP_CAUSTIC, n);
    assert_false(maps_equal(&other, &ref[PS_MAP_CAUSTIC]));
    ps_photon_map_free(&other);
    rig_free(&r);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_photon_map_free(&ref[k]);
}

/* The default Cornell box scaled by s about the origin: same photons, scaled. */
static void scaled_cornell(char *buf, size_t size, double s)
{
    snprintf(buf, size,
             "camera eye 0 %.17g %.17g target 0 %.17g 0\n"
             "material white diffuse albedo 0.75 0.75 0.75\n"
             "material red diffuse albedo 0.75 0.2 0.2\n"
             "material glass dielectric ior 1.5\n"
             "material mirror mirror reflectance 1 1 1\n"
             "quad corner %.17g 0 %.17g edge1 %.17g 0 0 edge2 0 0 %.17g material white\n"
             "quad corner %.17g %.17g %.17g edge1 0 0 %.17g edge2 %.17g 0 0 material white\n"
             "quad corner %.17g 0 %.17g edge1 0 %.17g 0 edge2 0 0 %.17g material red\n"
             "sphere center %.17g %.17g %.17g radius %.17g material glass\n"
             "sphere center %.17g %.17g %.17g radius %.17g material mirror\n"
             "light point position 0 %.17g 0 power 100 100 100\n",
             1 * s, 3.4 * s, 1 * s, -1 * s, 1 * s, 2 * s, -2 * s, -1 * s, 2 * s, -1 * s, 2 * s, 2 * s, -1 * s,
             -1 * s, 2 * s, 2 * s, 0.35 * s, 0.4 * s, 0.2 * s, 0.4 * s, -0.45 * s, 0.35 * s, -0.4 * s, 0.35 * s,
             1.9 * s);
}

static void scale_invariance(void **state)
{
    (void)state;
    double scales[3] = {1.0, 1e-3, 1e3};
    ps_photon_map maps[3][PS_MAP_COUNT];
    for (int k = 0; k < 3; k++) {
        char text[4096];
        scaled_cornell(text, sizeof text, scales[k]);
        ps_tracer_options o = options(0);
        rig r = rig_make(text, "", &o, PS_ACCEL_OCTREE);
        for (int m = 0; m < PS_MAP_COUNT; m++)
            maps[k][m] = rig_trace(&r, (ps_map_kind)m, 40000);
        rig_free(&r);
    }
    for (int k = 1; k < 3; k++)
        for (int m = 0; m < PS_MAP_COUNT; m++) {
            const ps_photon_map *a = &maps[0][m], *b = &maps[k][m];
            /* Rounding differs between scales, so a path that grazes an edge
             * may go the other way; almost all paths are the same. */
            assert_true(fabs((double)a->count - (double)b->count) <= 0.001 * (double)a->count + 2);
            size_t n = a->count < b->count ? a->count : b->count, same = 0;
            for (size_t i = 0; i < n; i++) {
                ps_vec3 pa = ps_photon_position(&a->photons[i]);
                ps_vec3 pb = ps_v3_scale(ps_photon_position(&b->photons[i]), 1.0 / scales[k]);
                same += ps_v3_len(ps_v3_sub(pa, pb)) < 1e-4;
            }
            if ((double)same < 0.99 * (double)n)
                fail_msg("scale %g, %s map: only %zu of %zu photons at the scaled place", scales[k],
                         ps_map_name((ps_map_kind)m), same, n);
            ps_rgb fa = ps_photon_map_power(a), fb = ps_photon_map_power(b);
            assert_near(fb.g, fa.g, 0.005 * fa.g);
        }
    for (int k = 0; k < 3; k++)
        for (int m = 0; m < PS_MAP_COUNT; m++)
            ps_photon_map_free(&maps[k][m]);
}

/* ---- what the scene does not need ---------------------------------------- */

static void skips(void **state)
{
    (void)state;
    ps_tracer_options o = options(1);
    /* A spot light turned away from the only glass sphere: no cone, no caustic. */
    rig r = rig_make("camera eye 0 1 5 target 0 1 0\n"
                     "material glass dielectric ior 1.5\n"
                     "quad corner -5 0 5 edge1 10 0 0 edge2 0 0 -10\n"
                     "sphere center 0 0.5 0 radius 0.3 material glass\n"
                     "light spot position 0 2 0 direction 1 0 0 angle 20 power 10 10 10\n",
                     "", &o, PS_ACCEL_AUTO);
    assert_false(ps_tracer_map_enabled(r.tracer, PS_MAP_CAUSTIC));
    assert_true(ps_tracer_map_enabled(r.tracer, PS_MAP_GLOBAL));
    size_t n;
    const ps_skip *sk = ps_tracer_skips(r.tracer, &n);
    assert_int_equal(n, 1);
    assert_non_null(strstr(sk[0].reason, "spot light 0 (line 5): no specular object inside its emission"));
    ps_photon_map m = rig_trace(&r, PS_MAP_CAUSTIC, 1000);
    assert_int_equal(m.count, 0);
    assert_int_equal(m.counters.rays, 0);
    rig_free(&r);

    /* Only mirrors: nothing reflects diffusely, so neither map is traced. */
    r = rig_make("camera eye 0 1 5 target 0 1 0\n"
                 "material m mirror reflectance 1 1 1\n"
                 "quad corner -5 0 5 edge1 10 0 0 edge2 0 0 -10 material m\n"
                 "light point position 0 2 0 power 10 10 10\n",
                 "", &o, PS_ACCEL_AUTO);
    assert_false(ps_tracer_map_enabled(r.tracer, PS_MAP_GLOBAL));
    assert_false(ps_tracer_map_enabled(r.tracer, PS_MAP_CAUSTIC));
    sk = ps_tracer_skips(r.tracer, &n);
    assert_int_equal(n, 2);
    assert_non_null(strstr(sk[1].reason, "no diffuse reflectance anywhere"));
    rig_free(&r);

    /* The default scene needs both. */
    r = rig_file(default_scene_path, &o);
    assert_true(ps_tracer_map_enabled(r.tracer, PS_MAP_CAUSTIC));
    assert_true(ps_tracer_map_enabled(r.tracer, PS_MAP_GLOBAL));
    (void)ps_tracer_skips(r.tracer, &n);
    assert_int_equal(n, 0);
    rig_free(&r);
}

/* Each photon's material and object are those of the surface it landed on:
 * in a box whose walls each have their own material, the wall a photon lies
 * on tells both. */
static void photon_materials(void **state)
{
    (void)state;
    const char *text = "camera eye 0 1 3.4 target 0 1 0 fov 40\n"
                       "material floor diffuse albedo 0.7 0.7 0.7\n"
                       "material ceiling diffuse albedo 0.6 0.6 0.6\n"
                       "material left diffuse albedo 0.5 0.2 0.2\n"
                       "material glass dielectric ior 1.5\n"
                       "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material floor\n"
                       "quad corner -1 2 -1 edge1 2 0 0 edge2 0 0 2 material ceiling\n"
                       "quad corner -1 0 -1 edge1 0 2 0 edge2 0 0 2 material left\n"
                       "sphere center 0.3 0.5 0 radius 0.3 material glass\n"
                       "light point position 0 1.5 0 power 10 10 10\n";
    ps_tracer_options o = options(2);
    rig r = rig_make(text, "", &o, PS_ACCEL_AUTO);
    int seen[3] = {0, 0, 0};
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map m = rig_trace(&r, (ps_map_kind)k, 20000);
        assert_true(m.count > 1000);
        for (size_t i = 0; i < m.count; i++) {
            const float *p = m.photons[i].pos;
            /* The walls the point lies on (two near an edge, where either is right). */
            bool on[3] = {fabsf(p[1]) < 1e-4f, fabsf(p[1] - 2.0f) < 1e-4f, fabsf(p[0] + 1.0f) < 1e-4f};
            assert_true(on[0] || on[1] || on[2]); /* only the three walls store */
            assert_true(m.materials[i] < 3 && on[m.materials[i]]);
            assert_int_equal(m.objects[i], m.materials[i]); /* the walls are objects 0, 1, 2 too */
            seen[m.materials[i]]++;
        }
        ps_photon_map_free(&m);
    }
    assert_true(seen[0] > 0 && seen[1] > 0 && seen[2] > 0);
    rig_free(&r);
}

/* A raised cancel flag stops a trace before its first chunk; a cap on the
 * stored photons stops one that would pass it. Either way the map keeps what
 * it had, and the next trace within the cap appends as usual. */
static void cancel_and_cap(void **state)
{
    (void)state;
    ps_tracer_options o = options(2);
    ps_cancel_flag flag;
    atomic_init(&flag, 15); /* SIGTERM */
    o.cancel = &flag;
    o.max_stored = 3000;
    char text[2048];
    box_scene(text, sizeof text, 0.9);
    rig r = rig_make(text, "", &o, PS_ACCEL_AUTO);
    ps_photon_map m;
    ps_photon_map_init(&m, PS_MAP_GLOBAL);
    ps_error err;
    assert_int_equal(ps_tracer_trace(r.tracer, PS_MAP_GLOBAL, 0, 5000, 5000, &m, &err), PS_ERR_INTERRUPTED);
    assert_string_equal(err.msg, "interrupted after 0 % of the global photons");
    assert_int_equal(m.count, 0);
    atomic_store(&flag, 0);
    /* A closed box of albedo 0.9 stores several photons per path: 100 paths
     * fit, 20000 would pass 3000 (about 9 a path). */
    assert_int_equal(ps_tracer_trace(r.tracer, PS_MAP_GLOBAL, 0, 100, 20000, &m, &err), PS_OK);
    size_t kept = m.count;
    assert_true(kept > 100 && kept <= 3000);
    assert_int_equal(ps_tracer_trace(r.tracer, PS_MAP_GLOBAL, 100, 19900, 20000, &m, &err), PS_ERR_LIMIT);
    assert_non_null(strstr(err.msg, "the global photon map would hold more than 3000 photons"));
    assert_int_equal(m.count, kept);
    assert_int_equal(m.counters.emitted, 100);
    ps_photon_map_free(&m);
    rig_free(&r);
}

/* ps_tracer_trace in its two steps: the traced range holds what one call
 * would store, joined it gives the same bytes and counters; nothing traced
 * is NULL, and joining NULL does nothing. The store cap counts the photons
 * the destination already holds. */
static void traced_range_and_join(void **state)
{
    (void)state;
    ps_tracer_options o = options(2);
    rig r = rig_file(default_scene_path, &o);
    ps_photon_map whole = rig_trace(&r, PS_MAP_GLOBAL, 5000);
    assert_true(whole.count > 1000);
    ps_traced *t = NULL;
    ps_error err;
    assert_int_equal(ps_tracer_trace_range(r.tracer, PS_MAP_GLOBAL, 0, 5000, 5000, 0, &t, &err), PS_OK);
    assert_non_null(t);
    assert_int_equal(ps_traced_count(t), whole.count);
    ps_photon_map m;
    ps_photon_map_init(&m, PS_MAP_GLOBAL);
    assert_int_equal(ps_traced_join(t, &m, &err), PS_OK);
    ps_traced_destroy(t);
    assert_true(maps_equal(&m, &whole));
    /* Traced in one call, a map is allocated to its exact size. */
    assert_int_equal(whole.cap, whole.count);
    assert_int_equal(m.cap, whole.cap);
    assert_int_equal(ps_photon_map_bytes(&m), whole.cap * PS_PHOTON_MAP_BYTES);
    assert_memory_equal(&m.counters, &whole.counters, sizeof m.counters);
    assert_int_equal(m.counters.emitted, 5000);
    assert_int_equal(m.counters.stored, m.count);
    assert_int_equal(ps_tracer_trace_range(r.tracer, PS_MAP_GLOBAL, 5000, 0, 5000, m.count, &t, &err), PS_OK);
    assert_null(t);
    assert_int_equal(ps_traced_count(t), 0);
    assert_int_equal(ps_traced_join(NULL, &m, &err), PS_OK);
    assert_int_equal(m.count, whole.count);
    ps_traced_destroy(NULL);
    ps_photon_map_free(&m);
    ps_photon_map_free(&whole);
    rig_free(&r);

    o.max_stored = 3000;
    char text[2048];
    box_scene(text, sizeof text, 0.9);
    r = rig_make(text, "", &o, PS_ACCEL_AUTO);
    t = (ps_traced *)&o; /* set to NULL on failure */
    assert_int_equal(ps_tracer_trace_range(r.tracer, PS_MAP_GLOBAL, 0, 100, 20000, 3000, &t, &err), PS_ERR_LIMIT);
    assert_string_equal(err.msg,
                        "inline.scn: the global photon map is full: 3000 photons, the most the memory budget allows");
    assert_null(t);
    /* 100 paths store about 900 photons: alone they fit, after 2900 they do not. */
    assert_int_equal(ps_tracer_trace_range(r.tracer, PS_MAP_GLOBAL, 0, 100, 20000, 0, &t, &err), PS_OK);
    assert_true(ps_traced_count(t) > 100 && ps_traced_count(t) < 3000);
    ps_traced_destroy(t);
    assert_int_equal(ps_tracer_trace_range(r.tracer, PS_MAP_GLOBAL, 0, 100, 20000, 2900, &t, &err), PS_ERR_LIMIT);
    assert_non_null(strstr(err.msg, "the global photon map would hold more than 3000 photons"));
    assert_null(t);
    rig_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(furnace_box),    cmocka_unit_test(photons_per_light), cmocka_unit_test(ranks_across_job_seams),
        cmocka_unit_test(mirror_caustic),
        cmocka_unit_test(overlapping_cones), cmocka_unit_test(no_leaks),      cmocka_unit_test(determinism),
        cmocka_unit_test(scale_invariance), cmocka_unit_test(skips),
        cmocka_unit_test(photon_materials), cmocka_unit_test(cancel_and_cap), cmocka_unit_test(traced_range_and_join),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
