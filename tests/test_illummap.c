/* test_illummap.c: the global map as illumination maps (preview/illummap.h):
 * the furnace's uniform indirect irradiance, a closed box's flux, the same
 * maps however the photons arrive, the radius levels, the lobe list. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "core/memory.h"

#include "preview/feed.h"
#include "preview/illummap.h"
#include "preview/session.h"
#include "preview/mesh.h"
#include "rig.h"

/* Inside a sphere of albedo RHO and radius R lit from its centre by PHI
 * watts, the global map (paths after their first diffuse bounce) carries
 * PHI (rho + rho^2 + ...) spread uniformly: E = rho PHI / (4 pi R^2 (1 - rho)). */
#define RHO 0.5
#define R 1.0
#define PHI 100.0
static const char *const FURNACE = "camera eye 0 0.2 0.3 target 0.3 0 -1 fov 70\n"
                                   "material wall diffuse albedo 0.5 0.5 0.5\n"
                                   "sphere center 0 0 0 radius 1 material wall\n"
                                   "light point position 0 0 0 power 100 100 100\n";

/* A closed box of six quads, an inner glossy box and a glass sphere. */
static const char *const BOX = "camera eye 0 0 0.9 target 0 0 0 fov 60\n"
                               "material white diffuse albedo 0.6 0.5 0.4\n"
                               "material shiny glossy albedo 0.3 0.3 0.3 specular 0.3 0.3 0.3 exponent 20\n"
                               "material glass dielectric ior 1.5\n"
                               "quad corner -1 -1 -1 edge1 2 0 0 edge2 0 2 0 material white\n"
                               "quad corner -1 -1 1 edge1 0 2 0 edge2 2 0 0 material white\n"
                               "quad corner -1 -1 -1 edge1 0 2 0 edge2 0 0 2 material white\n"
                               "quad corner 1 -1 -1 edge1 0 0 2 edge2 0 2 0 material white\n"
                               "quad corner -1 -1 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                               "quad corner -1 1 -1 edge1 2 0 0 edge2 0 0 2 material white\n"
                               "quad corner -0.5 -0.6 -0.5 edge1 0 0 0.6 edge2 0.6 0 0 material shiny\n"
                               "sphere center 0.4 0.2 0.3 radius 0.25 material glass\n"
                               "light point position 0 0.5 0 power 30 40 50\n";

typedef struct fixture {
    rig r;
    ps_preview_mesh mesh;
    ps_illummap *map;
    ps_photon_map photons;
} fixture;

/* Into *fp, which must stay put: the map points at its mesh. */
static void open_fixture_at(fixture *f, const char *text, uint64_t n)
{
    memset(f, 0, sizeof *f);
    ps_tracer_options to = ps_tracer_default_options();
    to.seed = 3;
    to.threads = 2;
    f->r = rig_make(text, ".", &to, PS_ACCEL_OCTREE);
    ps_error err;
    ps_mesh_options mo = ps_mesh_default_options(f->r.scene);
    if (ps_preview_mesh_build(f->r.scene, &mo, &f->mesh, &err) != PS_OK)
        fail_msg("mesh: %s", err.msg);
    if (ps_illummap_create(f->r.scene, &f->mesh, PS_KERNEL_CONE, &f->map, &err) != PS_OK)
        fail_msg("illummap: %s", err.msg);
    f->photons = rig_trace(&f->r, PS_MAP_GLOBAL, n);
}

static void close_fixture(fixture *f)
{
    ps_illummap_destroy(f->map);
    ps_photon_map_free(&f->photons);
    ps_preview_mesh_free(&f->mesh);
    rig_free(&f->r);
}

static void update(fixture *f, size_t count, double radius)
{
    size_t added;
    ps_error err;
    if (ps_illummap_update(f->map, f->photons.photons, f->photons.materials, f->photons.objects, count, radius, &added,
                           &err) != PS_OK)
        fail_msg("update: %s", err.msg);
}

/* The furnace through the maps: every sample's inside within 2 % of the
 * closed form on average, each within the noise, nothing outside. */
static void furnace_is_uniform(void **state)
{
    (void)state;
    const uint64_t n = 400000;
    fixture f;
    open_fixture_at(&f, FURNACE, n);
    update(&f, f.photons.count, 0.3);
    double want = RHO * PHI / (4.0 * PS_PI * R * R * (1.0 - RHO));
    double sum = 0.0, area_sum = 0.0, lo = INFINITY, hi = 0.0, outside = 0.0;
    size_t ns = ps_illummap_sample_count(f.map);
    assert_true(ns > 1000);
    for (size_t s = 0; s < ns; s++) {
        double a;
        ps_rgb in = ps_illummap_irradiance(f.map, s, 1, NULL, NULL, &a);
        ps_rgb out = ps_illummap_irradiance(f.map, s, 0, NULL, NULL, NULL);
        sum += in.g * a;
        area_sum += a;
        lo = fmin(lo, in.g);
        hi = fmax(hi, in.g);
        outside += out.r + out.g + out.b;
    }
    double mean = sum / area_sum;
    printf("furnace: %zu samples, mean indirect irradiance %.4f W/m^2 (%.4f .. %.4f), closed form %.4f; "
           "mesh area %.5f of 4 pi R^2\n",
           ns, mean, lo, hi, want, area_sum / (4.0 * PS_PI * R * R));
    assert_near(mean, want, 0.02 * want);
    /* Uniform: the noise of ~4000 photons a sample under the cone kernel. */
    assert_true(lo > 0.9 * want && hi < 1.1 * want);
    assert_true(outside == 0.0);
    assert_true(ps_illummap_lost(f.map).g == 0.0);
    close_fixture(&f);
}

/* A closed box: sum of E A over samples and sides equals the photons'
 * power, channel by channel, to rounding; the glossy box's photons are in
 * the lobe list and nothing else is. */
static void box_flux_is_the_photons(void **state)
{
    (void)state;
    fixture f;
    open_fixture_at(&f, BOX, 100000);
    update(&f, f.photons.count, 0.1);
    ps_rgb flux = ps_rgb_gray(0.0);
    for (size_t s = 0; s < ps_illummap_sample_count(f.map); s++)
        for (int side = 0; side < 2; side++) {
            double a;
            ps_rgb e = ps_illummap_irradiance(f.map, s, side, NULL, NULL, &a);
            flux = ps_rgb_add(flux, ps_rgb_scale(e, a));
        }
    ps_rgb want = ps_photon_map_power(&f.photons), lost = ps_illummap_lost(f.map);
    printf("box: flux through the maps %.6f %.6f %.6f W, photons %.6f %.6f %.6f W, lost %.3g W\n", flux.r, flux.g,
           flux.b, want.r, want.g, want.b, lost.r + lost.g + lost.b);
    assert_true(want.r > 1.0);
    assert_near(flux.r, want.r, 1e-9 * want.r);
    assert_near(flux.g, want.g, 1e-9 * want.g);
    assert_near(flux.b, want.b, 1e-9 * want.b);
    assert_true(lost.r == 0.0 && lost.g == 0.0 && lost.b == 0.0);
    /* The lobe list: exactly the photons on the glossy material (index 1). */
    size_t glossy = 0;
    for (size_t i = 0; i < f.photons.count; i++)
        glossy += f.photons.materials[i] == 1;
    const ps_photon *lp;
    const uint16_t *lm;
    const uint32_t *lo;
    size_t nl = ps_illummap_lobe(f.map, &lp, &lm, &lo);
    assert_true(glossy > 100);
    assert_int_equal(nl, glossy);
    for (size_t i = 0; i < nl; i++)
        assert_int_equal(lm[i], 1);
    close_fixture(&f);
}

/* The same photons in any batches and on any number of threads give the
 * same bytes (f sums each photon as it is gathered, on one thread; g's
 * larger batches go through three workers' lists); another radius
 * rebuilds from photon 0 to the same bytes as a map built at that radius. */
static void batches_do_not_matter(void **state)
{
    (void)state;
    fixture f;
    open_fixture_at(&f, BOX, 30000);
    fixture g;
    open_fixture_at(&g, BOX, 30000);
    size_t n = f.photons.count;
    ps_error err;
    assert_int_equal(ps_illummap_set_threads(f.map, 1, &err), PS_OK);
    assert_int_equal(ps_illummap_set_threads(g.map, 3, &err), PS_OK);
    update(&f, n, 0.15);
    size_t steps[] = {1, 7, 1000, n / 3, n / 2 + 5, n};
    for (size_t i = 0; i < sizeof steps / sizeof *steps; i++)
        update(&g, steps[i], 0.15);
    const float *ff, *fb, *gf, *gb;
    size_t nv = f.mesh.vertex_count;
    size_t nmat;
    const ps_material *mats = ps_scene_materials(f.r.scene, &nmat);
    ps_illummap_colors(f.map, mats, 1.0, &ff, &fb);
    ps_illummap_colors(g.map, mats, 1.0, &gf, &gb);
    assert_memory_equal(ff, gf, 4 * nv * sizeof *ff);
    assert_memory_equal(fb, gb, 4 * nv * sizeof *fb);
    /* Half the photons at another radius, then all at the first: rebuilt. */
    update(&g, n / 2, 0.2);
    assert_true(ps_illummap_radius(g.map) == 0.2);
    update(&g, n, 0.15);
    ps_illummap_colors(g.map, mats, 1.0, &gf, &gb);
    assert_memory_equal(ff, gf, 4 * nv * sizeof *ff);
    assert_false(ps_illummap_changed(g.map));
    close_fixture(&f);
    close_fixture(&g);
}

/* The spans GL draws (ps_illummap_spans) are the surfaces the maps colour:
 * every vertex outside them is black on both sides, the glass between two
 * walls splits them, and the view's colours inside them are a side's. */
static void spans_are_the_coloured_surfaces(void **state)
{
    (void)state;
    static const char *const SPLIT = "camera eye 0 0 0.9 target 0 0 0 fov 60\n"
                                     "material white diffuse albedo 0.6 0.5 0.4\n"
                                     "material glass dielectric ior 1.5\n"
                                     "material mirror mirror reflectance 0.9 0.9 0.9\n"
                                     "quad corner -1 -1 -1 edge1 2 0 0 edge2 0 2 0 material white\n"
                                     "sphere center 0 0 -0.5 radius 0.3 material glass\n"
                                     "quad corner -1 -1 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                                     "quad corner 1 -1 -1 edge1 0 0 2 edge2 0 2 0 material mirror\n"
                                     "light point position 0 0.5 0 power 30 40 50\n";
    const char *const scenes[] = {BOX, SPLIT};
    const size_t want_spans[] = {1, 2};
    for (int sc = 0; sc < 2; sc++) {
        fixture f;
        open_fixture_at(&f, scenes[sc], 20000);
        update(&f, f.photons.count, 0.15);
        size_t nmat;
        const ps_material *mats = ps_scene_materials(f.r.scene, &nmat);
        const float *front, *back;
        ps_illummap_colors(f.map, mats, 1.0, &front, &back);
        const float *view = ps_illummap_view_colors(f.map, ps_v3(0.0, 0.0, 0.9));
        const ps_illum_span *sp;
        size_t n = ps_illummap_spans(f.map, &sp);
        assert_int_equal(n, want_spans[sc]);
        size_t nv = f.mesh.vertex_count, in = 0, lit = 0;
        bool *spanned = calloc(nv, sizeof *spanned);
        assert_non_null(spanned);
        for (size_t i = 0; i < n; i++) {
            assert_true(sp[i].count > 0 && sp[i].count % 3 == 0 && sp[i].first + sp[i].count <= nv);
            if (i > 0) /* in order, apart: neighbours would have been joined */
                assert_true(sp[i].first > sp[i - 1].first + sp[i - 1].count);
            for (size_t v = sp[i].first; v < sp[i].first + sp[i].count; v++) {
                spanned[v] = true;
                in++;
                bool is_front = !memcmp(view + 4 * v, front + 4 * v, 4 * sizeof *view);
                assert_true(is_front || !memcmp(view + 4 * v, back + 4 * v, 4 * sizeof *view));
                lit += front[4 * v + 1] > 0.0f || back[4 * v + 1] > 0.0f;
            }
        }
        /* Every range of a diffuse or glossy surface spanned, the rest not. */
        size_t want_in = 0;
        for (size_t r = 0; r < f.mesh.range_count; r++) {
            const ps_mesh_range *rg = &f.mesh.ranges[r];
            bool coloured = mats[rg->material].type == PS_MAT_DIFFUSE || mats[rg->material].type == PS_MAT_GLOSSY;
            want_in += coloured ? rg->count : 0;
            for (size_t v = rg->first; v < rg->first + rg->count; v++)
                assert_true(spanned[v] == coloured);
        }
        assert_int_equal(in, want_in);
        assert_true(in < nv);
        assert_true(lit > in / 2);
        for (size_t v = 0; v < nv; v++)
            if (!spanned[v])
                for (int c = 0; c < 3; c++)
                    assert_true(front[4 * v + c] == 0.0f && back[4 * v + c] == 0.0f);
        free(spanned);
        close_fixture(&f);
    }
}

/* Colours: E albedo / pi times the scale, black on the glass. */
static void colours_are_radiance(void **state)
{
    (void)state;
    fixture f;
    open_fixture_at(&f, BOX, 20000);
    update(&f, f.photons.count, 0.15);
    size_t nmat;
    const ps_material *mats = ps_scene_materials(f.r.scene, &nmat);
    const float *front, *back;
    ps_illummap_colors(f.map, mats, 2.0, &front, &back);
    size_t checked = 0;
    for (size_t r = 0; r < f.mesh.range_count; r++) {
        const ps_mesh_range *rg = &f.mesh.ranges[r];
        for (size_t v = rg->first; v < rg->first + rg->count; v += 97) {
            if (mats[rg->material].type == PS_MAT_DIELECTRIC) {
                assert_true(front[4 * v] == 0.0f && back[4 * v] == 0.0f);
                continue;
            }
            /* The sample at this vertex: the nearest with its normal (walls
             * meet at shared corners). */
            const float *p = f.mesh.positions + 3 * v, *nv = f.mesh.normals + 3 * v;
            size_t best = 0;
            double bd = INFINITY;
            for (size_t s = 0; s < ps_illummap_sample_count(f.map); s++) {
                ps_vec3 q, qn;
                ps_illummap_irradiance(f.map, s, 0, &q, &qn, NULL);
                if (ps_v3_dot(qn, ps_v3(nv[0], nv[1], nv[2])) < 0.99)
                    continue;
                double d = ps_v3_len(ps_v3_sub(q, ps_v3(p[0], p[1], p[2])));
                if (d < bd)
                    bd = d, best = s;
            }
            ps_rgb e0 = ps_illummap_irradiance(f.map, best, 0, NULL, NULL, NULL);
            ps_rgb e1 = ps_illummap_irradiance(f.map, best, 1, NULL, NULL, NULL);
            double a = mats[rg->material].albedo.g;
            assert_near(front[4 * v + 1], 2.0 * e0.g * a / PS_PI, 1e-5 * (1.0 + e0.g));
            assert_near(back[4 * v + 1], 2.0 * e1.g * a / PS_PI, 1e-5 * (1.0 + e1.g));
            checked++;
        }
    }
    assert_true(checked > 20);
    close_fixture(&f);
}

/* Levels: r0 2^(j/2), the smallest not below r, never below the mesh's edges. */
static void radius_levels(void **state)
{
    (void)state;
    fixture f;
    open_fixture_at(&f, BOX, 10);
    double r0 = 0.1;
    assert_near(ps_illummap_level_radius(f.map, r0, 0.1), 0.1, 1e-15);
    assert_near(ps_illummap_level_radius(f.map, r0, 0.12), 0.1 * sqrt(2.0), 1e-15);
    assert_near(ps_illummap_level_radius(f.map, r0, 0.15), 0.2, 1e-15);
    assert_near(ps_illummap_level_radius(f.map, r0, 0.4), 0.4, 1e-15);
    /* The box's fine mesh: edges of at most a 64th of its diagonal (2 sqrt 3),
     * the quads' 2 m cut in 53, their diagonals 2 sqrt 2 / 53. */
    double edge = ps_illummap_level_radius(f.map, r0, 1e-4);
    assert_near(edge, 2.0 * sqrt(2.0) / 53.0, 1e-6);
    for (double r = 0.05; r < 0.5; r *= 1.07) {
        double l = ps_illummap_level_radius(f.map, r0, r);
        assert_true(l >= r && l < r * sqrt(2.0) * (1.0 + 1e-12) + edge);
    }
    close_fixture(&f);
}

static void refuses_over_budget(void **state)
{
    (void)state;
    fixture f;
    open_fixture_at(&f, BOX, 10);
    setenv(PS_MEMORY_LIMIT_ENV, "1M", 1);
    ps_illummap *m;
    ps_error err;
    assert_int_equal(ps_illummap_create(f.r.scene, &f.mesh, PS_KERNEL_CONE, &m, &err), PS_ERR_LIMIT);
    assert_non_null(strstr(err.msg, "illumination maps"));
    unsetenv(PS_MEMORY_LIMIT_ENV);
    close_fixture(&f);
}

/* ---- through the session ------------------------------------------------------- */

static ps_session_settings maps_settings(ps_scene *scene, bool incremental, ps_radius_schedule schedule)
{
    ps_session_settings set = ps_session_default_settings(scene);
    set.caps[PS_MAP_CAUSTIC] = 5000;
    set.caps[PS_MAP_GLOBAL] = 40000;
    set.seed = 9;
    set.threads = 2;
    set.float_buffer = set.incremental = incremental;
    set.radius_schedule = schedule;
    set.global_layer = PS_GLOBAL_MAPS;
    return set;
}

/* A session of set, traced to its caps. */
static ps_session *open_session_with(ps_scene *scene, const ps_session_settings *set)
{
    ps_session *s;
    ps_error err;
    if (ps_session_create(scene, set, &s, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    if (ps_session_trace_all(s, &err) != PS_OK)
        fail_msg("trace: %s", err.msg);
    return s;
}

static ps_session *open_session(ps_scene *scene, bool incremental, ps_radius_schedule schedule)
{
    ps_session_settings set = maps_settings(scene, incremental, schedule);
    return open_session_with(scene, &set);
}

/* Refreshes until everything is shown; the number of refreshes. */
static int settle(ps_session *s, const ps_camera_frame *cam)
{
    int n = 0;
    ps_error err;
    do {
        ps_session_frame f;
        if (ps_session_refresh(s, cam, &f, &err) != PS_OK)
            fail_msg("refresh: %s", err.msg);
        bool shown = (ps_session_get_settings(s)->layers & PS_LAYER_GLOBAL) != 0;
        assert_true(shown == (f.imap_colors != NULL));
        ps_session_drawn(s, 0.001);
        n++;
    } while (!ps_session_settled(s) && n < 1000);
    return n;
}

/* The default box, and its camera at 32 x 32. */
static ps_scene *load_box(ps_camera_frame *cam)
{
    ps_scene *scene;
    ps_error err;
    if (ps_scene_load("data/scenes/cornell-caustic.scn", NULL, &scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    *cam = ps_camera_frame_make(ps_scene_camera(scene), 32, 32);
    return scene;
}

/* The session's maps: every photon once, at the schedule's level for the
 * photons emitted; the same sums from incremental refreshes as from one
 * whole refresh; other settings and edits start them over. */
static void session_fills_the_maps(void **state)
{
    (void)state;
    ps_camera_frame cam;
    ps_scene *scene = load_box(&cam);
    ps_error err;
    for (int sched = 0; sched < PS_RADIUS_SCHEDULE_COUNT; sched++) {
        ps_session *inc = open_session(scene, true, (ps_radius_schedule)sched);
        ps_session *whole = open_session(scene, false, (ps_radius_schedule)sched);
        int n_inc = settle(inc, &cam), n_whole = settle(whole, &cam);
        const ps_illummap *a = ps_session_illummap(inc), *b = ps_session_illummap(whole);
        size_t stored = ps_session_maps(inc)[PS_MAP_GLOBAL].count;
        printf("session, %s radius: %d incremental refreshes, %d whole; %zu photons, radius %.4f\n",
               ps_radius_schedule_name((ps_radius_schedule)sched), n_inc, n_whole, stored, ps_illummap_radius(a));
        assert_true(n_inc > 1);
        assert_int_equal(ps_illummap_count(a), stored);
        assert_int_equal(ps_illummap_count(b), stored);
        double want = ps_illummap_level_radius(a, ps_session_get_settings(inc)->radius[PS_MAP_GLOBAL],
                                               ps_session_radius(inc, PS_MAP_GLOBAL));
        assert_true(ps_illummap_radius(a) == want && ps_illummap_radius(b) == want);
        for (size_t i = 0; i < ps_illummap_sample_count(a); i++)
            for (int side = 0; side < 2; side++) {
                ps_rgb ea = ps_illummap_irradiance(a, i, side, NULL, NULL, NULL);
                ps_rgb eb = ps_illummap_irradiance(b, i, side, NULL, NULL, NULL);
                if (memcmp(&ea, &eb, sizeof ea) != 0)
                    fail_msg("sample %zu side %d: %g incremental, %g whole", i, side, ea.g, eb.g);
            }
        /* Hidden, the layer waits for nothing; shown again, it refreshes. */
        ps_session_set_layers(inc, PS_LAYER_DIRECT | PS_LAYER_CAUSTIC);
        settle(inc, &cam);
        ps_session_set_layers(inc, PS_LAYER_ALL);
        /* Splats and back: new maps, filled again. */
        assert_int_equal(ps_session_set_global_layer(inc, PS_GLOBAL_SPLATS, &err), PS_OK);
        assert_null(ps_session_illummap(inc));
        ps_session_frame f;
        assert_int_equal(ps_session_refresh(inc, &cam, &f, &err), PS_OK);
        assert_null(f.imap_colors);
        assert_int_equal(ps_session_set_global_layer(inc, PS_GLOBAL_MAPS, &err), PS_OK);
        assert_int_equal(ps_illummap_count(ps_session_illummap(inc)), 0);
        settle(inc, &cam);
        assert_int_equal(ps_illummap_count(ps_session_illummap(inc)), stored);
        /* An edit restarts the maps from photon 0. */
        assert_int_equal(ps_session_move_object(inc, 0, ps_v3(0.0, 0.01, 0.0), &err), PS_OK);
        ps_session_changes ch;
        assert_int_equal(ps_session_update(inc, &ch, &err), PS_OK);
        assert_int_equal(ps_illummap_count(ps_session_illummap(inc)), 0);
        ps_session_destroy(inc);
        ps_session_destroy(whole);
    }
    ps_scene_destroy(scene);
}

/* ps_session_set_budget_share: the maps take that share of their budget
 * (a batch at least), as the splats do (photosplat-snap's checkpoint frames:
 * pace.h). With tau so long that their budget is every photon, a second
 * incremental refresh at the whole budget adds all the rest; at a share of
 * 10^-9, one batch. */
static void maps_take_the_budget_share(void **state)
{
    (void)state;
    ps_camera_frame cam;
    ps_scene *scene = load_box(&cam);
    ps_error err;
    ps_session_settings set = maps_settings(scene, true, PS_RADIUS_FIXED);
    set.tau = 1e4;
    size_t added[2];
    for (int v = 0; v < 2; v++) {
        ps_session *s = open_session_with(scene, &set);
        size_t stored = ps_session_maps(s)[PS_MAP_GLOBAL].count;
        ps_session_frame f;
        assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK); /* PS_SESSION_BUDGET_START: a batch */
        ps_session_drawn(s, 0.001);
        size_t first = ps_illummap_count(ps_session_illummap(s));
        assert_true(first > 0 && first < stored);
        ps_session_set_budget_share(s, v == 0 ? 1.0 : 1e-9);
        assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
        added[v] = ps_illummap_count(ps_session_illummap(s)) - first;
        if (v == 0)
            assert_int_equal(first + added[v], stored);
        ps_session_destroy(s);
    }
    printf("maps' second refresh: %zu photons at the whole budget, %zu at a share of 1e-9\n", added[0], added[1]);
    assert_true(added[1] > 0 && added[1] <= PS_FEED_BATCH && added[1] < added[0]);
    ps_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(furnace_is_uniform),   cmocka_unit_test(box_flux_is_the_photons),
        cmocka_unit_test(batches_do_not_matter), cmocka_unit_test(spans_are_the_coloured_surfaces),
        cmocka_unit_test(colours_are_radiance),
        cmocka_unit_test(radius_levels),        cmocka_unit_test(refuses_over_budget),
        cmocka_unit_test(session_fills_the_maps), cmocka_unit_test(maps_take_the_budget_share),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
