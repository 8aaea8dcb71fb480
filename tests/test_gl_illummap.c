/* test_gl_illummap.c: the global layer drawn as illumination maps
 * (--global-layer maps) shows the maps' value times albedo / pi: inside the
 * furnace sphere (albedo 0.5, a point light at its centre) every pixel of the
 * global layer lies between the least and the most of the maps' values, the
 * picture's mean is the closed form's rho^2 Phi / (4 pi^2 R^2 (1 - rho)),
 * through the window's float layers (also as a moving camera's level of
 * detail, scaled up) and through snap's single 8-bit frame; and the picture
 * is the same bytes for 1 and 2 tracing threads. */
#include "test.h"

#include <GL/osmesa.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_render.h"
#include "image/image.h"
#include "preview/session.h"
#include "scene/scene.h"

#define SIDE 48
#define RHO 0.5
#define PHI 100.0
#define EXPOSURE 0.4

static const char *const FURNACE = "camera eye 0 0.2 0.3 target 0.3 0 -1 fov 70\n"
                                   "material wall diffuse albedo 0.5 0.5 0.5\n"
                                   "sphere center 0 0 0 radius 1 material wall\n"
                                   "light point position 0 0 0 power 100 100 100\n"
                                   "photons caustic 0 global 200000\n"
                                   "radius caustic 0.02 global 0.3\n";

/* The furnace's session through the maps, traced to its caps (global_cap:
 * the global map's, 0 for the scene's), and an OSMesa context of SIDE^2
 * with a renderer for it. */
typedef struct furnace_rig {
    ps_scene *scene;
    ps_session *s;
    OSMesaContext ctx;
    uint8_t *buffer;
    ps_gl_renderer *gl;
    ps_camera_frame cam;
} furnace_rig;

static void furnace_open(furnace_rig *k, bool layers, int threads, uint64_t global_cap)
{
    ps_error err;
    if (ps_scene_load_text(FURNACE, "furnace.scn", "", NULL, &k->scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_session_settings set = ps_session_default_settings(k->scene);
    set.threads = threads;
    set.seed = 1;
    if (global_cap)
        set.caps[PS_MAP_GLOBAL] = global_cap;
    set.float_buffer = layers;
    set.incremental = layers;
    set.exposure = EXPOSURE;
    set.layers = PS_LAYER_GLOBAL;
    set.global_layer = PS_GLOBAL_MAPS;
    if (ps_session_create(k->scene, &set, &k->s, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    assert_int_equal(ps_session_trace_all(k->s, &err), PS_OK);
    k->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    assert_non_null(k->ctx);
    k->buffer = malloc(4 * SIDE * SIDE);
    assert_non_null(k->buffer);
    assert_true(OSMesaMakeCurrent(k->ctx, k->buffer, GL_UNSIGNED_BYTE, SIDE, SIDE));
    ps_gl_options go = {true, false, 0, false, false, OSMesaGetProcAddress};
    ps_gl_scene gs = ps_gl_scene_of(k->s);
    assert_int_equal(ps_gl_renderer_create(&gs, ps_session_kernel(k->s), &go, &k->gl, &err), PS_OK);
    k->cam = ps_camera_frame_make(ps_scene_camera(k->scene), SIDE, SIDE);
}

static void furnace_close(furnace_rig *k)
{
    ps_gl_renderer_destroy(k->gl);
    OSMesaDestroyContext(k->ctx);
    free(k->buffer);
    ps_session_destroy(k->s);
    ps_scene_destroy(k->scene);
}

/* The global layer of the furnace through the maps; *lo, *hi: the least and
 * most of the maps' inside values as drawn (times albedo / pi and exposure).
 * move: then a refresh with the camera turned a little, the moving camera's
 * level of detail (PS_SESSION_MOVING_SCALE fewer pixels a side, scaled up
 * by the composite), which is the picture returned. */
/* shown: where not NULL, the picture ps_gl_layers_show put in the window
 * (OSMesa's buffer, SIDE^2 RGBA8 codes, bottom row first). */
static ps_image draw_shown(bool layers, int threads, bool move, double *lo, double *hi, uint8_t *shown)
{
    furnace_rig k;
    furnace_open(&k, layers, threads, 0);
    ps_session *s = k.s;
    ps_gl_renderer *gl = k.gl;
    ps_camera_frame cam = k.cam;
    ps_error err;
    ps_session_frame f;
    ps_gl_layers *l = NULL;
    if (layers)
        assert_int_equal(ps_gl_layers_create(SIDE, SIDE, true, &l, &err), PS_OK);
    /* Incremental refreshes add a budget's worth at a time: until all are in. */
    int refreshes = 0;
    do {
        assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
        assert_non_null(f.imap_colors);
        assert_true(f.imap_redraw);
        if (l)
            ps_gl_layers_draw(l, gl, &cam, &f);
        ps_session_drawn(s, 0.01);
        refreshes++;
    } while (ps_illummap_count(ps_session_illummap(s)) < ps_session_maps(s)[PS_MAP_GLOBAL].count);
    assert_true(layers ? refreshes > 1 : refreshes == 1);
    /* No lobes: nothing glossy. */
    assert_int_equal(f.map[PS_MAP_GLOBAL].batch->vertex_count, 0);
    const ps_illummap *m = ps_session_illummap(s);
    assert_int_equal(ps_illummap_count(m), ps_session_maps(s)[PS_MAP_GLOBAL].count);
    double gain = layers ? f.map[PS_MAP_GLOBAL].gain : 1.0;
    double scale = layers ? 1.0 : EXPOSURE; /* caps = emitted: N / n = 1 */
    *lo = INFINITY, *hi = 0.0;
    for (size_t i = 0; i < ps_illummap_sample_count(m); i++) {
        double v = ps_illummap_irradiance(m, i, 1, NULL, NULL, NULL).g * RHO / PS_PI * scale * gain;
        *lo = fmin(*lo, v), *hi = fmax(*hi, v);
    }
    if (move) {
        cam.eye.x += 0.01;
        assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
        assert_true(f.moving && f.new_view);
        assert_int_equal(f.view.width, (SIDE + PS_SESSION_MOVING_SCALE - 1) / PS_SESSION_MOVING_SCALE);
        ps_gl_layers_draw(l, gl, &cam, &f);
    }
    ps_image img;
    if (layers) {
        double gains[PS_MAP_COUNT] = {f.map[0].gain, f.map[1].gain};
        assert_int_equal(ps_gl_layers_composite(l, f.direct_gain, gains, &img, &err), PS_OK);
        if (shown) {
            ps_gl_layers_show(l, f.direct_gain, gains);
            ps_gl_finish();
            memcpy(shown, k.buffer, 4 * SIDE * SIDE);
        }
        ps_gl_layers_destroy(l);
    } else {
        ps_gl_draw_frame(gl, &cam, &f);
        assert_int_equal(ps_gl_read(gl, &img, &err), PS_OK);
    }
    furnace_close(&k);
    return img;
}

static ps_image draw(bool layers, int threads, double *lo, double *hi)
{
    return draw_shown(layers, threads, false, lo, hi, NULL);
}

static void check(const ps_image *img, double lo, double hi, double tol, const char *what)
{
    double want = RHO * RHO * PHI / (4.0 * PS_PI * PS_PI * (1.0 - RHO)) * EXPOSURE, sum = 0.0;
    size_t n = 3 * (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++) {
        sum += img->rgb[i];
        if (!(img->rgb[i] >= lo - tol && img->rgb[i] <= hi + tol))
            fail_msg("%s: pixel value %g outside the maps' %g .. %g", what, img->rgb[i], lo, hi);
    }
    printf("%s: global layer mean %.5f, closed form %.5f, maps %.5f .. %.5f\n", what, sum / (double)n, want, lo, hi);
    assert_near(sum / (double)n, want, 0.03 * want);
}

static void layers_show_the_maps(void **state)
{
    (void)state;
    double lo, hi;
    ps_image img = draw(true, 2, &lo, &hi);
    check(&img, lo, hi, 1e-5, "float layers");
    ps_image_destroy(&img);
}

/* The moving camera's level of detail, scaled up bilinearly from its
 * corner of the layers: every pixel still within the maps' values (a read
 * past the corner, of black or of an older view, would fall below them on
 * the last rows and columns), the mean the closed form's; and the window's
 * picture (the corner composited, then scaled up by a blit, which filters
 * the sRGB codes) within 2 codes of that composite's, edges included. */
static void moving_view_scales_up(void **state)
{
    (void)state;
    double lo, hi;
    uint8_t *shown = malloc(4 * SIDE * SIDE);
    assert_non_null(shown);
    ps_image img = draw_shown(true, 2, true, &lo, &hi, shown);
    assert_int_equal(img.width, SIDE);
    check(&img, lo, hi, 1e-5, "moving camera, float layers");
    int worst = 0;
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++)
            for (int c = 0; c < 3; c++) {
                float v = ps_image_at(&img, x, SIDE - 1 - y)[c];
                int want = (int)lroundf(255.0f * ps_srgb_encode(fminf(fmaxf(v, 0.0f), 1.0f)));
                int d = abs((int)shown[4 * (y * SIDE + x) + c] - want);
                worst = d > worst ? d : worst;
            }
    printf("moving camera, the window's picture: %d codes at worst from the composite's\n", worst);
    assert_true(worst <= 2);
    free(shown);
    ps_image_destroy(&img);
}

static void whole_frame_shows_the_maps(void **state)
{
    (void)state;
    double lo, hi;
    ps_image img = draw(false, 2, &lo, &hi);
    check(&img, lo, hi, 0.6 / 255.0, "8-bit frame");
    ps_image_destroy(&img);
}

static void threads_do_not_matter(void **state)
{
    (void)state;
    double lo, hi;
    ps_image a = draw(true, 1, &lo, &hi), b = draw(true, 2, &lo, &hi);
    assert_memory_equal(a.rgb, b.rgb, 3 * sizeof(float) * SIDE * SIDE);
    ps_image_destroy(&a);
    ps_image_destroy(&b);
}

/* The layers a session may never draw hold no texels until drawn into
 * (gl_layers.c): the maps' not after a view alone, then theirs at the maps'
 * first pass, the linear composite's at its first read. The maps' first
 * picture drawn into a layer made then is the same floats as into one made
 * before the view (ps_gl_layers_reserve), which the view cleared. */
static void optional_layers_made_when_drawn(void **state)
{
    (void)state;
    furnace_rig k;
    furnace_open(&k, true, 2, 20000);
    ps_gl_renderer *gl = k.gl;
    ps_camera_frame cam = k.cam;
    ps_error err;
    ps_session_frame f;
    assert_int_equal(ps_session_refresh(k.s, &cam, &f, &err), PS_OK);
    assert_non_null(f.imap_colors);
    assert_true(f.new_view);
    const size_t layer = (size_t)SIDE * SIDE * 4 * sizeof(float);
    const size_t base = 3 * layer + (size_t)SIDE * SIDE * 4; /* direct, caustic, global; shown (sRGB8) */
    ps_image img[2];
    for (int reserved = 0; reserved < 2; reserved++) {
        ps_gl_layers *l;
        assert_int_equal(ps_gl_layers_create(SIDE, SIDE, true, &l, &err), PS_OK);
        assert_int_equal(ps_gl_layers_bytes(l), base);
        if (reserved)
            ps_gl_layers_reserve(l, gl, true);
        ps_gl_layers_view(l, gl, &cam, f.direct_exposure, f.direct);
        assert_int_equal(ps_gl_layers_bytes(l), base + (reserved ? layer : 0));
        ps_gl_layers_draw(l, gl, &cam, &f);
        assert_int_equal(ps_gl_layers_bytes(l), base + layer);
        double gains[PS_MAP_COUNT] = {f.map[0].gain, f.map[1].gain};
        assert_int_equal(ps_gl_layers_composite(l, f.direct_gain, gains, &img[reserved], &err), PS_OK);
        assert_int_equal(ps_gl_layers_bytes(l), base + 2 * layer);
        ps_gl_layers_destroy(l);
    }
    double sum = 0.0;
    for (size_t i = 0; i < 3 * (size_t)SIDE * SIDE; i++)
        sum += img[0].rgb[i];
    assert_true(sum > 0.0); /* the maps are in the picture */
    assert_memory_equal(img[0].rgb, img[1].rgb, 3 * sizeof(float) * SIDE * SIDE);
    for (int i = 0; i < 2; i++)
        ps_image_destroy(&img[i]);
    furnace_close(&k);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(layers_show_the_maps),
        cmocka_unit_test(moving_view_scales_up),
        cmocka_unit_test(whole_frame_shows_the_maps),
        cmocka_unit_test(threads_do_not_matter),
        cmocka_unit_test(optional_layers_made_when_drawn),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
