/* test_gl_moving.c: a moving camera's level of detail in the window's float
 * layers (preview/session.h), where it departs from the full view's way of
 * drawing:
 *  - the global map's splats at half the view's pixels a side
 *    (ps_session_layer.shrink), scaled up by the composite: in a closed cube
 *    of flat walls lit from its centre, the picture's mean within 1 % of the
 *    same frame drawn at the view's pixels, every pixel 0.6-1.4 of it and the
 *    relative squared error at most 0.002 (a read past the shrunk corner, of
 *    the black around it, or of the view's corner as if it were the shrunk
 *    one, fails them; a furnace sphere would not do: splats in the tangent
 *    plane of so curved a wall are cut by the depth test, and more so at a
 *    coarser depth);
 *  - the direct layer lit on the moving mesh (mesh.h: a quarter of a flat
 *    face's vertices): a floor under a low point light, where Gouraud
 *    interpolation errs most, within 3 % a pixel and 0.5 % on the mean of the
 *    same frame lit on the fine mesh, and its lit pass drawing exactly the
 *    moving mesh's vertices;
 *  - and so while the lights are a progressive start's coarse level
 *    (ps_session_lights_coarse), the camera still, in an 8-bit session's
 *    whole frames: the moving mesh until the lights are refined, the fine
 *    one after. */
#include "test.h"

#include <GL/osmesa.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_render.h"
#include "image/image.h"
#include "preview/session.h"
#include "scene/scene.h"
#include "gl_rig.h"

#define SIDE 96
#define EXPOSURE 0.4

/* A closed cube of flat walls (albedo 0.5) lit from its centre, seen from
 * inside toward a corner: splats lie in their wall's plane. */
static const char *const CUBE = "camera eye 0.2 -0.1 0.5 target -1 -0.6 -1 fov 70\n"
                                "material wall diffuse albedo 0.5 0.5 0.5\n"
                                "quad corner -1 -1 -1 edge1 0 0 2 edge2 2 0 0 material wall\n"
                                "quad corner -1 1 -1 edge1 2 0 0 edge2 0 0 2 material wall\n"
                                "quad corner -1 -1 -1 edge1 2 0 0 edge2 0 2 0 material wall\n"
                                "quad corner -1 -1 1 edge1 0 2 0 edge2 2 0 0 material wall\n"
                                "quad corner -1 -1 -1 edge1 0 2 0 edge2 0 0 2 material wall\n"
                                "quad corner 1 -1 -1 edge1 0 0 2 edge2 0 2 0 material wall\n"
                                "light point position 0 0 0 power 100 100 100\n"
                                "photons caustic 0 global 200000\n"
                                "radius caustic 0.02 global 0.3\n";

/* A 2 x 2 floor 0.4 under a point light, seen from above. */
static const char *const FLOOR = "camera eye 0 2 1.2 target 0 0 0 fov 60\n"
                                 "material white diffuse albedo 0.8 0.8 0.8\n"
                                 "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                                 "light point position 0 0.4 0 power 10 10 10\n"
                                 "photons caustic 0 global 2000\n";

typedef gl_rig rig;

static void rig_open(rig *g, const char *text, unsigned layers)
{
    ps_session_settings set = gl_rig_load(g, text, "moving.scn");
    set.exposure = EXPOSURE;
    set.layers = layers;
    gl_rig_start(g, &set, SIDE);
}

static void rig_close(rig *g) { gl_rig_close(g); }

static ps_gl_renderer *renderer_with(const ps_gl_scene *gs, ps_session *s, const ps_gl_options *go)
{
    ps_gl_renderer *gl;
    ps_error err;
    assert_int_equal(ps_gl_renderer_create(gs, ps_session_kernel(s), go, &gl, &err), PS_OK);
    return gl;
}

static ps_gl_renderer *renderer(const ps_gl_scene *gs, ps_session *s)
{
    ps_gl_options go = {true, true, 0, false, false, OSMesaGetProcAddress};
    return renderer_with(gs, s, &go);
}

/* Every photon drawn for the still camera, then one refresh with the camera
 * moved a little: the level of detail, in *f (not drawn). */
static void still_then_move(rig *g, ps_gl_layers *l, ps_gl_renderer *gl, ps_session_frame *f)
{
    ps_error err;
    do {
        assert_int_equal(ps_session_refresh(g->s, &g->cam, f, &err), PS_OK);
        assert_false(f->moving);
        ps_gl_layers_draw(l, gl, &g->cam, f);
        ps_session_drawn(g->s, 0.01);
    } while (!ps_session_settled(g->s));
    g->cam.eye.x += 0.01;
    assert_int_equal(ps_session_refresh(g->s, &g->cam, f, &err), PS_OK);
    assert_true(f->moving && f->new_view && !f->edit_lod);
    assert_int_equal(f->view.width, (SIDE + PS_SESSION_MOVING_SCALE - 1) / PS_SESSION_MOVING_SCALE);
}

static ps_image composite(ps_gl_layers *l, const ps_session_frame *f)
{
    double gains[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++)
        gains[k] = f->map[k].gain;
    ps_image img;
    ps_error err;
    assert_int_equal(ps_gl_layers_composite(l, f->direct_gain, gains, &img, &err), PS_OK);
    return img;
}

static void global_layer_shrunk(void **state)
{
    (void)state;
    rig g;
    rig_open(&g, CUBE, PS_LAYER_GLOBAL);
    ps_gl_scene gs = ps_gl_scene_of(g.s);
    ps_gl_renderer *gl = renderer(&gs, g.s);
    ps_gl_layers *l;
    ps_error err;
    assert_int_equal(ps_gl_layers_create(SIDE, SIDE, true, &l, &err), PS_OK);
    ps_session_frame f;
    still_then_move(&g, l, gl, &f);
    /* A batch of the 2 * 10^5 photons: its radius grown 2x, its layer shrunk. */
    assert_int_equal(f.map[PS_MAP_GLOBAL].shrink, PS_SESSION_MOVING_GLOBAL_SHRINK);
    assert_int_equal(f.map[PS_MAP_CAUSTIC].shrink, 1);
    ps_gl_layers_draw(l, gl, &g.cam, &f);
    ps_image shrunk = composite(l, &f);
    /* The same frame at the view's pixels. */
    f.map[PS_MAP_GLOBAL].shrink = 1;
    ps_gl_layers_draw(l, gl, &g.cam, &f);
    ps_image full = composite(l, &f);
    /* Pixel by pixel against the view's pixels: the same but where the
     * prepass taken down to half differs (within a shrunk pixel of a
     * wall's edge, where splats in one wall's plane are cut by the next). */
    size_t n = 3 * (size_t)SIDE * SIDE;
    double lo = INFINITY, hi = 0.0, se = 0.0, ss = 0.0;
    for (size_t i = 0; i < n; i++) {
        assert_true(full.rgb[i] > 0.0f);
        double q = shrunk.rgb[i] / full.rgb[i];
        lo = fmin(lo, q), hi = fmax(hi, q);
        se += (shrunk.rgb[i] - full.rgb[i]) * (shrunk.rgb[i] - full.rgb[i]);
        ss += full.rgb[i] * full.rgb[i];
    }
    double ms = gl_rig_image_mean(&shrunk), mf = gl_rig_image_mean(&full);
    printf("global layer while moving: shrunk mean %.5f, at the view's pixels %.5f; pixels %.3f .. %.3f of those, "
           "relative squared error %.2g\n",
           ms, mf, lo, hi, se / ss);
    assert_near(ms, mf, 0.01 * mf);
    assert_true(lo >= 0.6 && hi <= 1.4);
    assert_true(se / ss <= 0.002);
    ps_image_destroy(&shrunk);
    ps_image_destroy(&full);
    ps_gl_layers_destroy(l);
    ps_gl_renderer_destroy(gl);
    rig_close(&g);
}

static void direct_on_the_moving_mesh(void **state)
{
    (void)state;
    rig g;
    rig_open(&g, FLOOR, PS_LAYER_DIRECT);
    const ps_preview_mesh *fine = ps_session_mesh(g.s), *moving = ps_session_moving_mesh(g.s);
    assert_true(moving != fine);
    printf("moving mesh: %zu vertices, the fine one %zu\n", moving->vertex_count, fine->vertex_count);
    assert_true(4 * moving->vertex_count <= 3 * fine->vertex_count);
    ps_gl_scene gs = ps_gl_scene_of(g.s), gs_fine = gs;
    gs_fine.moving = NULL; /* lit on the fine mesh while moving too */
    ps_gl_renderer *gl = renderer(&gs, g.s), *gl_fine = renderer(&gs_fine, g.s);
    ps_gl_layers *l;
    ps_error err;
    assert_int_equal(ps_gl_layers_create(SIDE, SIDE, true, &l, &err), PS_OK);
    ps_session_frame f;
    still_then_move(&g, l, gl, &f);
    ps_gl_layers_draw(l, gl, &g.cam, &f);
    assert_int_equal(ps_gl_get_stats(gl).light_vertices, moving->vertex_count);
    ps_image a = composite(l, &f);
    ps_gl_layers_draw(l, gl_fine, &g.cam, &f);
    assert_int_equal(ps_gl_get_stats(gl_fine).light_vertices, fine->vertex_count);
    ps_image b = composite(l, &f);
    size_t n = 3 * (size_t)SIDE * SIDE;
    double peak = 0.0, worst = 0.0;
    for (size_t i = 0; i < n; i++)
        peak = fmax(peak, b.rgb[i]);
    assert_true(peak > 0.0);
    for (size_t i = 0; i < n; i++)
        if (b.rgb[i] > 0.01 * peak)
            worst = fmax(worst, fabs(a.rgb[i] - b.rgb[i]) / b.rgb[i]);
    double ma = gl_rig_image_mean(&a), mb = gl_rig_image_mean(&b);
    printf("direct layer while moving: moving mesh mean %.5f, fine mesh %.5f, worst pixel %.2f %%\n", ma, mb,
           100.0 * worst);
    assert_true(worst <= 0.03);
    assert_near(ma, mb, 0.005 * mb);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
    ps_gl_layers_destroy(l);
    ps_gl_renderer_destroy(gl);
    ps_gl_renderer_destroy(gl_fine);
    rig_close(&g);
}

static void coarse_lights_on_the_moving_mesh(void **state)
{
    (void)state;
    rig g;
    ps_session_settings set = gl_rig_load(&g, FLOOR, "moving.scn");
    set.exposure = EXPOSURE;
    set.layers = PS_LAYER_DIRECT;
    set.float_buffer = set.incremental = false; /* snap's 8-bit --time: whole refreshes */
    set.progressive_lights = true;
    gl_rig_start(&g, &set, SIDE);
    const ps_preview_mesh *fine = ps_session_mesh(g.s), *moving = ps_session_moving_mesh(g.s);
    assert_true(4 * moving->vertex_count <= 3 * fine->vertex_count);
    assert_true(ps_session_lights_coarse(g.s));
    ps_gl_scene gs = ps_gl_scene_of(g.s), gs_full = gs;
    assert_true(gs.coarse_lights);
    gs_full.coarse_lights = false; /* the same lights, taken as the last level */
    /* An 8-bit buffer, as snap's, without shadow maps: one lit pass, of the
     * whole mesh (the fine one's tiles are culled only against a shadow
     * face's pyramid). */
    ps_gl_options go = {false, false, 0, false, false, OSMesaGetProcAddress};
    ps_gl_renderer *gl = renderer_with(&gs, g.s, &go), *gl_full = renderer_with(&gs_full, g.s, &go);
    ps_session_frame f;
    ps_error err;
    assert_int_equal(ps_session_refresh(g.s, &g.cam, &f, &err), PS_OK);
    assert_false(f.moving || f.lights_changed);
    ps_gl_draw_frame(gl, &g.cam, &f);
    assert_int_equal(ps_gl_get_stats(gl).light_vertices, moving->vertex_count);
    ps_image a, b, c;
    assert_int_equal(ps_gl_read(gl, &a, &err), PS_OK);
    ps_gl_draw_frame(gl_full, &g.cam, &f);
    assert_int_equal(ps_gl_get_stats(gl_full).light_vertices, fine->vertex_count);
    assert_int_equal(ps_gl_read(gl_full, &b, &err), PS_OK);
    /* Refined (the full shadow maps): the fine mesh from then on. */
    ps_session_drawn(g.s, 0.01);
    assert_int_equal(ps_session_refresh(g.s, &g.cam, &f, &err), PS_OK);
    assert_true(f.lights_changed && !ps_session_lights_coarse(g.s));
    gs = ps_gl_scene_of(g.s);
    assert_false(gs.coarse_lights);
    assert_int_equal(ps_gl_renderer_set_scene(gl, &gs, &err), PS_OK);
    ps_gl_draw_frame(gl, &g.cam, &f);
    assert_int_equal(ps_gl_get_stats(gl).light_vertices, fine->vertex_count);
    assert_int_equal(ps_gl_read(gl, &c, &err), PS_OK);
    /* The 8-bit pictures (codes / 255): Gouraud's error on the floor under
     * the low light, as while moving (above), within 3 % a pixel and one
     * code of its rounding, against the coarse level lit finely; and the
     * refined level's, the same lights lit finely, the same codes. */
    size_t n = 3 * (size_t)SIDE * SIDE, over = 0;
    double refined = 0.0;
    for (size_t i = 0; i < n; i++) {
        over += fabs(a.rgb[i] - b.rgb[i]) > 0.03 * b.rgb[i] + 1.0 / 255.0;
        refined = fmax(refined, fabs(c.rgb[i] - b.rgb[i]));
    }
    double ma = gl_rig_image_mean(&a), mb = gl_rig_image_mean(&b);
    printf("coarse lights, 8 bits: moving mesh mean %.5f, fine mesh %.5f, %zu values off by more than 3 %% and a "
           "code; refined against the fine: %.4f at most\n",
           ma, mb, over, refined);
    assert_true(ma != mb); /* the meshes differ where the light is near */
    assert_int_equal(over, 0);
    assert_near(ma, mb, 0.005 * mb);
    assert_true(refined == 0.0);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
    ps_image_destroy(&c);
    ps_gl_renderer_destroy(gl);
    ps_gl_renderer_destroy(gl_full);
    rig_close(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(global_layer_shrunk),
        cmocka_unit_test(direct_on_the_moving_mesh),
        cmocka_unit_test(coarse_lights_on_the_moving_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
