/* test_gl_bake.c: finished maps baked into textures on their quads
 * (preview/bake.h, settings.bake) and drawn from them for a new view,
 * against the same view's splats:
 *  - the Cornell box with its glass and mirror spheres: each map's layer
 *    drawn from its textures within 0.5 % of the splats' mean and at a
 *    relative squared error of at most 0.001 (measured: 0.04 % and 0.19 %,
 *    2.6e-4 and 2.0e-4; the caustic's sharp edges sampled at a quarter
 *    radius; a texture shifted by half a texel, drawn on the wrong side or
 *    without its last batch of photons fails);
 *  - a map with photons on a diffuse sphere is not baked, and the session
 *    still settles; nor one whose floor would need more than
 *    PS_BAKE_MAX_SIDE texels a side;
 *  - a quad whose photons are all on its back is baked on that side;
 *  - a hidden layer's bake waits (the refreshes not back to back meanwhile);
 *  - an edit drops the textures (the frame says so) and the maps are baked
 *    again once traced. */
#include "test.h"

#include <GL/osmesa.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_render.h"
#include "image/image.h"
#include "preview/bake.h"
#include "preview/session.h"
#include "scene/scene.h"
#include "gl_rig.h"

#define SIDE 128

static const char *const BOX = "camera eye 0 1 3.4 target 0 1 0 up 0 1 0 fov 40\n"
                               "material white diffuse albedo 0.75 0.75 0.75\n"
                               "material red diffuse albedo 0.75 0.25 0.25\n"
                               "material green diffuse albedo 0.25 0.75 0.25\n"
                               "material glass dielectric ior 1.5\n"
                               "material mirror mirror reflectance 1 1 1\n"
                               "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                               "quad corner -1 2 -1 edge1 2 0 0 edge2 0 0 2 material white\n"
                               "quad corner -1 0 -1 edge1 2 0 0 edge2 0 2 0 material white\n"
                               "quad corner -1 0 -1 edge1 0 2 0 edge2 0 0 2 material red\n"
                               "quad corner 1 0 -1 edge1 0 0 2 edge2 0 2 0 material green\n"
                               "sphere center 0.35 0.4 0.2 radius 0.4 material glass\n"
                               "sphere center -0.45 0.35 -0.4 radius 0.35 material mirror\n"
                               "light point position 0 1.9 0 power 100 100 100\n"
                               "photons caustic 60000 global 20000\n"
                               "radius caustic 0.03 global 0.12\n";

/* The same with the mirror sphere diffuse: global photons land on it. */
static const char *const MATTE_SPHERE = "camera eye 0 1 3.4 target 0 1 0 up 0 1 0 fov 40\n"
                                        "material white diffuse albedo 0.75 0.75 0.75\n"
                                        "material glass dielectric ior 1.5\n"
                                        "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                                        "quad corner -1 0 -1 edge1 2 0 0 edge2 0 2 0 material white\n"
                                        "sphere center 0.35 0.4 0.2 radius 0.4 material glass\n"
                                        "sphere center -0.45 0.35 -0.4 radius 0.35 material white\n"
                                        "light point position 0 1.9 0 power 100 100 100\n"
                                        "photons caustic 20000 global 20000\n"
                                        "radius caustic 0.03 global 0.12\n";

/* The session (bake on, the two maps' layers only), its renderer and
 * layers. */
typedef struct rig {
    gl_rig base; /* scene, session (s), camera (cam) */
    ps_gl_renderer *gl;
    ps_gl_layers *layers;
} rig;

static void rig_open(rig *g, const char *text)
{
    ps_session_settings set = gl_rig_load(&g->base, text, "bake.scn");
    set.bake = true;
    set.layers = PS_LAYER_CAUSTIC | PS_LAYER_GLOBAL;
    gl_rig_start(&g->base, &set, SIDE);
    ps_gl_scene gs = ps_gl_scene_of(g->base.s);
    ps_gl_options go = {true, true, 0, false, false, OSMesaGetProcAddress};
    ps_error err;
    assert_int_equal(ps_gl_renderer_create(&gs, ps_session_kernel(g->base.s), &go, &g->gl, &err), PS_OK);
    assert_int_equal(ps_gl_layers_create(SIDE, SIDE, true, &g->layers, &err), PS_OK);
}

static void rig_close(rig *g)
{
    ps_gl_layers_destroy(g->layers);
    ps_gl_renderer_destroy(g->gl);
    gl_rig_close(&g->base);
}

/* One refresh at cam, drawn, said to take draw_seconds (the next budget). */
static void refresh_taking(rig *g, const ps_camera_frame *cam, ps_session_frame *f, double draw_seconds)
{
    ps_error err;
    assert_int_equal(ps_session_refresh(g->base.s, cam, f, &err), PS_OK);
    ps_gl_layers_draw(g->layers, g->gl, cam, f);
    ps_session_drawn(g->base.s, draw_seconds);
}

static void refresh(rig *g, const ps_camera_frame *cam, ps_session_frame *f) { refresh_taking(g, cam, f, 0.01); }

/* Refreshes at the rig's camera until everything is shown (and baked):
 * the refreshes that lay a bake need not wait for tau. */
static void settle(rig *g, ps_session_frame *f)
{
    int n = 0;
    do {
        refresh(g, &g->base.cam, f);
        bool laid = false, more = false; /* laid this refresh; more to lay */
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            laid = laid || f->map[k].bake;
            more = more || (f->map[k].bake && !ps_session_baked(g->base.s, (ps_map_kind)k, NULL));
            /* The share laid: in [0, 1) while laying, 1 once baked. */
            double share = ps_session_bake_progress(g->base.s, (ps_map_kind)k);
            if (f->map[k].bake)
                assert_true(ps_session_baked(g->base.s, (ps_map_kind)k, NULL) ? share == 1.0 : share > 0.0 && share < 1.0);
        }
        if (laid)
            assert_true(ps_session_catching_up(g->base.s) == more);
        assert_true(++n < 10000);
    } while (!ps_session_settled(g->base.s));
    assert_false(ps_session_catching_up(g->base.s));
}

/* Map k's layer alone, composited. */
static ps_image layer(rig *g, const ps_session_frame *f, int k)
{
    double gains[PS_MAP_COUNT] = {0.0, 0.0};
    gains[k] = f->map[k].gain;
    ps_image img;
    ps_error err;
    assert_int_equal(ps_gl_layers_composite(g->layers, 0.0, gains, &img, &err), PS_OK);
    return img;
}

/* The camera away and back: the second refresh back is the full view
 * again, drawn anew. */
static void away_and_back(rig *g, ps_session_frame *f)
{
    ps_camera_frame away = g->base.cam;
    away.eye.x += 0.05;
    refresh(g, &away, f);
    assert_true(f->moving);
    refresh(g, &g->base.cam, f);
    assert_true(f->moving);
    refresh(g, &g->base.cam, f);
    assert_false(f->moving);
    assert_true(f->new_view);
}

/* A settled view's layers (every photon splatted), then the same view drawn
 * from the baked textures (away and back): each map's splats and baked
 * means, and the relative squared error of the baked layer. */
typedef struct against {
    double splats[PS_MAP_COUNT], baked[PS_MAP_COUNT], rse[PS_MAP_COUNT];
} against;

static against baked_against_splats(rig *g, ps_session_frame *f)
{
    ps_image splats[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++)
        splats[k] = layer(g, f, k);
    away_and_back(g, f);
    against a;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_true(f->map[k].baked && f->map[k].clear);
        ps_image baked = layer(g, f, k);
        size_t n = 3 * (size_t)SIDE * SIDE;
        double se = 0.0, ss = 0.0;
        for (size_t i = 0; i < n; i++) {
            se += (baked.rgb[i] - splats[k].rgb[i]) * (baked.rgb[i] - splats[k].rgb[i]);
            ss += splats[k].rgb[i] * splats[k].rgb[i];
        }
        a.baked[k] = gl_rig_image_mean(&baked);
        a.splats[k] = gl_rig_image_mean(&splats[k]);
        a.rse[k] = ss > 0.0 ? se / ss : 0.0;
        printf("%s layer: baked mean %.5f, splats %.5f; relative squared error %.2g\n", k ? "global" : "caustic",
               a.baked[k], a.splats[k], a.rse[k]);
        assert_true(a.splats[k] > 0.0);
        ps_image_destroy(&baked);
        ps_image_destroy(&splats[k]);
    }
    return a;
}

static void baked_layers_match_the_splats(void **state)
{
    (void)state;
    rig g;
    rig_open(&g, BOX);
    ps_session_frame f;
    settle(&g, &f);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        size_t texels;
        assert_true(ps_session_baked(g.base.s, (ps_map_kind)k, &texels));
        assert_true(texels > 0);
    }
    /* The view settled before the bake: its layers are the splats. */
    against a = baked_against_splats(&g, &f);
    assert_int_equal(f.splats, 0);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_near(a.baked[k], a.splats[k], 0.005 * a.splats[k]);
        assert_true(a.rse[k] <= 0.001);
    }
    /* Moving, the layers are the textures too: no level of detail. */
    ps_camera_frame away = g.base.cam;
    away.eye.y += 0.1;
    refresh(&g, &away, &f);
    assert_true(f.moving && f.map[PS_MAP_CAUSTIC].baked && f.map[PS_MAP_GLOBAL].baked);
    assert_int_equal(f.splats, 0);
    rig_close(&g);
}

static void photons_off_the_quads_are_splatted(void **state)
{
    (void)state;
    rig g;
    rig_open(&g, MATTE_SPHERE);
    ps_session_frame f;
    settle(&g, &f);
    /* A map is baked exactly when all its photons lie on quads (the
     * global map's land on the matte sphere too). */
    const ps_photon_map *maps = ps_session_maps(g.base.s);
    size_t nobj;
    const ps_object *obj = ps_scene_objects(g.base.scene, &nobj);
    bool on_quads[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        on_quads[k] = maps[k].count > 0;
        for (size_t i = 0; i < maps[k].count; i++)
            on_quads[k] = on_quads[k] && obj[maps[k].objects[i]].type == PS_OBJ_QUAD;
        assert_int_equal(ps_session_baked(g.base.s, (ps_map_kind)k, NULL), on_quads[k]);
        assert_true(ps_session_bake_progress(g.base.s, (ps_map_kind)k) == (on_quads[k] ? 1.0 : -1.0));
    }
    assert_false(on_quads[PS_MAP_GLOBAL]);
    away_and_back(&g, &f);
    assert_int_equal(f.map[PS_MAP_CAUSTIC].baked, on_quads[PS_MAP_CAUSTIC]);
    assert_false(f.map[PS_MAP_GLOBAL].baked);
    assert_true(f.splats > 0);
    rig_close(&g);
}

/* A radius so fine that the floor would need more than PS_BAKE_MAX_SIDE
 * texels a side (though its texels would fit PS_BAKE_MAX_TEXELS): that map is
 * splatted (coarser texels would blur it), the other baked. */
static void too_fine_a_radius_is_not_baked(void **state)
{
    (void)state;
    static const char *const FLOOR = "camera eye 0 1 3.4 target 0 0.3 0 up 0 1 0 fov 40\n"
                                     "material white diffuse albedo 0.75 0.75 0.75\n"
                                     "material glass dielectric ior 1.5\n"
                                     "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                                     "sphere center 0 0.5 0 radius 0.4 material glass\n"
                                     "light point position 0 1.9 0 power 100 100 100\n"
                                     "photons caustic 20000 global 5000\n"
                                     "radius caustic 0.0035 global 0.12\n";
    double side = 2.0 * PS_BAKE_TEXELS_PER_RADIUS / 0.0035;
    assert_true(side > PS_BAKE_MAX_SIDE && side * side < (double)PS_BAKE_MAX_TEXELS);
    rig g;
    rig_open(&g, FLOOR);
    ps_session_frame f;
    settle(&g, &f);
    assert_false(ps_session_baked(g.base.s, PS_MAP_CAUSTIC, NULL));
    assert_true(ps_session_baked(g.base.s, PS_MAP_GLOBAL, NULL));
    rig_close(&g);
}

/* A floor whose winding puts its front face down, lit from above (the
 * global photons come from the ceiling over it): its photons are all on its
 * back, the only side of it baked, and the view from above drawn from that
 * texture is the splats'. */
static void a_quad_lit_on_its_back(void **state)
{
    (void)state;
    static const char *const BACK = "camera eye 0 2 1.5 target 0 0 0 up 0 1 0 fov 60\n"
                                    "material white diffuse albedo 0.75 0.75 0.75\n"
                                    "quad corner -1 0 -1 edge1 2 0 0 edge2 0 0 2 material white\n"
                                    "quad corner -1 2 -1 edge1 2 0 0 edge2 0 0 2 material white\n"
                                    "light point position 0 1 0 power 100 100 100\n"
                                    "photons caustic 0 global 20000\n"
                                    "radius caustic 0.03 global 0.12\n";
    rig g;
    rig_open(&g, BACK);
    ps_session_frame f;
    settle(&g, &f);
    assert_true(ps_session_baked(g.base.s, PS_MAP_GLOBAL, NULL));
    ps_image splats = layer(&g, &f, PS_MAP_GLOBAL);
    away_and_back(&g, &f);
    assert_true(f.map[PS_MAP_GLOBAL].baked);
    ps_image baked = layer(&g, &f, PS_MAP_GLOBAL);
    double mb = gl_rig_image_mean(&baked), ms = gl_rig_image_mean(&splats);
    printf("a floor lit on its back: baked mean %.5f, splats %.5f\n", mb, ms);
    assert_true(ms > 0.0);
    assert_near(mb, ms, 0.005 * ms);
    ps_image_destroy(&baked);
    ps_image_destroy(&splats);
    rig_close(&g);
}

/* The textures are the same bytes however many refreshes laid them: each
 * target's splats go in index order whatever the budget. */
static void baked_bytes_do_not_depend_on_the_budget(void **state)
{
    (void)state;
    ps_image img[2][PS_MAP_COUNT];
    int refreshes[2] = {0, 0};
    for (int run = 0; run < 2; run++) {
        rig g;
        rig_open(&g, BOX);
        ps_session_frame f;
        do { /* a slow drawing makes a small budget: more refreshes */
            refresh_taking(&g, &g.base.cam, &f, run == 0 ? 0.01 : 10.0);
            refreshes[run]++;
        } while (!ps_session_settled(g.base.s));
        away_and_back(&g, &f);
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            assert_true(f.map[k].baked);
            img[run][k] = layer(&g, &f, k);
        }
        rig_close(&g);
    }
    printf("laid and drawn in %d and %d refreshes\n", refreshes[0], refreshes[1]);
    assert_true(refreshes[1] > refreshes[0]);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        size_t n = 3 * (size_t)SIDE * SIDE;
        assert_memory_equal(img[0][k].rgb, img[1][k].rgb, n * sizeof *img[0][k].rgb);
        ps_image_destroy(&img[0][k]);
        ps_image_destroy(&img[1][k]);
    }
}

/* A bake waits while its layer is hidden, and the refreshes then wait for
 * tau again (back to back they would lay nothing); shown again, it goes on. */
static void a_hidden_layer_waits(void **state)
{
    (void)state;
    rig g;
    rig_open(&g, BOX);
    ps_session_frame f;
    do { /* until the caustic's bake has begun (a slow drawing: a batch a refresh) */
        refresh_taking(&g, &g.base.cam, &f, 10.0);
    } while (!f.map[PS_MAP_CAUSTIC].bake);
    assert_false(ps_session_baked(g.base.s, PS_MAP_CAUSTIC, NULL));
    assert_true(ps_session_catching_up(g.base.s));
    ps_session_set_layers(g.base.s, PS_LAYER_GLOBAL);
    for (int i = 0; i < 20; i++) {
        refresh_taking(&g, &g.base.cam, &f, 10.0);
        assert_null(f.map[PS_MAP_CAUSTIC].bake);
    }
    assert_false(ps_session_baked(g.base.s, PS_MAP_CAUSTIC, NULL));
    assert_false(ps_session_catching_up(g.base.s));
    ps_session_set_layers(g.base.s, PS_LAYER_CAUSTIC | PS_LAYER_GLOBAL);
    settle(&g, &f);
    assert_true(ps_session_baked(g.base.s, PS_MAP_CAUSTIC, NULL));
    rig_close(&g);
}

static void an_edit_drops_the_textures(void **state)
{
    (void)state;
    rig g;
    rig_open(&g, BOX);
    ps_session_frame f;
    settle(&g, &f);
    ps_error err;
    assert_int_equal(ps_session_move_light(g.base.s, 0, ps_v3(0.2, 1.9, 0.0), &err), PS_OK);
    ps_session_changes ch;
    assert_int_equal(ps_session_update(g.base.s, &ch, &err), PS_OK);
    assert_int_equal(ps_session_trace_all(g.base.s, &err), PS_OK);
    /* The edit's first refresh: the textures dropped, the layers not drawn
     * from them (its bake may already be laid again within it). */
    refresh(&g, &g.base.cam, &f);
    assert_true(f.map[PS_MAP_CAUSTIC].bake_reset && f.map[PS_MAP_GLOBAL].bake_reset);
    assert_false(f.map[PS_MAP_CAUSTIC].baked || f.map[PS_MAP_GLOBAL].baked);
    settle(&g, &f);
    assert_true(ps_session_baked(g.base.s, PS_MAP_CAUSTIC, NULL) && ps_session_baked(g.base.s, PS_MAP_GLOBAL, NULL));
    /* Laid again from the new photons alone: the same view drawn from them
     * is the splats' (textures kept and added to would show both lights). */
    against a = baked_against_splats(&g, &f);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        assert_near(a.baked[k], a.splats[k], 0.005 * a.splats[k]);
    rig_close(&g);
}

/* The direct light's targets (ps_bake_direct_targets, GL-free): both sides
 * of each diffuse quad, as the scene has it, texels of a 1024th of the
 * scene's diagonal; a mirror quad none; too many texels none at all. */
static void direct_light_targets(void **state)
{
    (void)state;
    char text[4096];
    snprintf(text, sizeof text, "%squad corner -0.5 1 -0.9 edge1 1 0 0 edge2 0 0.5 0 material mirror\n", BOX);
    ps_scene *s;
    ps_error err;
    assert_int_equal(ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err), PS_OK);
    size_t nmat, nobj;
    const ps_material *mats = ps_scene_materials(s, &nmat);
    const ps_object *obj = ps_scene_objects(s, &nobj);
    ps_bake_target *t;
    size_t n;
    assert_int_equal(ps_bake_direct_targets(s, mats, &t, &n, &err), PS_OK);
    assert_int_equal(n, 10); /* five walls, two sides each; not the spheres, not the mirror quad */
    double texel = ps_v3_len(ps_aabb_diag(ps_scene_bounds(s))) / PS_BAKE_DIRECT_TEXELS_PER_DIAG;
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(t[i].object, i / 2);
        assert_int_equal(t[i].side, (int)(i % 2));
        assert_int_equal(obj[t[i].object].type, PS_OBJ_QUAD);
        assert_int_equal(t[i].width, (int)ceil(ps_v3_len(t[i].edge1) / texel));
        assert_int_equal(t[i].height, (int)ceil(ps_v3_len(t[i].edge2) / texel));
        assert_int_equal(t[i].width, 592); /* 2 m walls over a 3.46 m diagonal */
    }
    /* The floor as written: corner (-1, 0, -1), edge1 (0, 0, 2), edge2 (2, 0, 0). */
    assert_true(ps_v3_equal(t[0].corner, ps_v3(-1, 0, -1)) && ps_v3_equal(t[0].edge1, ps_v3(0, 0, 2)) &&
                ps_v3_equal(t[0].edge2, ps_v3(2, 0, 0)));
    free(t);
    ps_scene_destroy(s);
    /* Twelve 2 x 2 floors 0.1 apart: 2 m over a 3.03 m diagonal is 676 texels,
     * 0.91 10^6 a floor's two sides, 1.1 10^7 in all: past
     * PS_BAKE_MAX_TEXELS (8.4 10^6), none baked. */
    char many[4096];
    int at = snprintf(many, sizeof many, "camera eye 0 1 3 target 0 0 0\nmaterial white diffuse albedo 0.5 0.5 0.5\n"
                                         "light point position 0 1.1 0 power 10 10 10\n");
    for (int q = 0; q < 12; q++)
        at += snprintf(many + at, sizeof many - (size_t)at,
                       "quad corner -1 %.1f -1 edge1 0 0 2 edge2 2 0 0 material white\n", 0.1 * q);
    assert_int_equal(ps_scene_load_text(many, "inline.scn", "", NULL, &s, &err), PS_OK);
    assert_int_equal(ps_bake_direct_targets(s, ps_scene_materials(s, &nmat), &t, &n, &err), PS_OK);
    assert_int_equal(n, 0);
    assert_null(t);
    ps_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(baked_layers_match_the_splats),
        cmocka_unit_test(photons_off_the_quads_are_splatted),
        cmocka_unit_test(too_fine_a_radius_is_not_baked),
        cmocka_unit_test(a_quad_lit_on_its_back),
        cmocka_unit_test(baked_bytes_do_not_depend_on_the_budget),
        cmocka_unit_test(a_hidden_layer_waits),
        cmocka_unit_test(an_edit_drops_the_textures),
        cmocka_unit_test(direct_light_targets),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
