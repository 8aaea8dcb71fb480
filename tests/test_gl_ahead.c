/* test_gl_ahead.c: the first picture's view drawn while its first round is
 * traced (ps_session_start_beside, ps_gl_layers_view_ahead), as
 * photosplat-snap's float layers draw it:
 *  - the first refresh's composite is the same floats as a session started
 *    the plain way, from the same photons, and its view is drawn once, not
 *    again by the refresh (ps_gl_stats.views);
 *  - a view drawn ahead for another camera, or for another exposure, is
 *    drawn again for the refresh's own, the picture again the same;
 *  - the work beside the round runs once;
 *  - with --global-layer maps, the illumination maps gather the round's
 *    photons beside the work too, before the first refresh, and its
 *    picture is still the same floats as a plain start's;
 *  - the direct layer's lit passes are left by the view (defer_lit)
 *    and drawn by the refresh after its splats: the direct layer the same
 *    floats as the passes drawn at once, an emitter in a wall's plane
 *    included; drawn first by a view begun elsewhere in between, dropped
 *    (and the view drawn again) after new materials, the picture the same;
 *  - 8 bits (ps_gl_draw_view_ahead): the view drawn beside the round into
 *    the colour buffer, the first frame draws only its splats over it, the
 *    same bytes as a frame drawn whole; for another camera or exposure, after
 *    another view begun in between, or after new materials, the frame draws
 *    its own view again, the bytes again the same. */
#include "test.h"

#include <GL/osmesa.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_render.h"
#include "image/image.h"
#include "preview/illummap.h"
#include "preview/session.h"
#include "scene/scene.h"
#include "gl_rig.h"

#define SIDE 64

/* A box's floor under a point light, a glass sphere focusing a caustic on
 * it: both maps in the first round, shadows in the view. */
#define ROOM_OBJECTS                                                                                     \
    "camera eye 0 1 3 target 0 0.5 0 fov 45\n"                                                          \
    "material white diffuse albedo 0.75 0.75 0.75\n"                                                    \
    "material glass dielectric ior 1.5\n"                                                               \
    "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"                                      \
    "quad corner -1 0 -1 edge1 2 0 0 edge2 0 2 0 material white\n"                                      \
    "sphere center 0 0.4 0 radius 0.3 material glass\n"                                                 \
    "light point position 0 1.5 0.3 power 50 50 50\n"
#define ROOM_PHOTONS "photons caustic 40000 global 10000\n"
static const char *const ROOM = ROOM_OBJECTS ROOM_PHOTONS;

/* The view drawn beside the round: into the float layers, or (layers NULL)
 * into the 8-bit colour buffer. */
typedef struct ahead_job {
    ps_gl_layers *layers;
    ps_gl_renderer *gl;
    ps_camera_frame cam;
    double exposure;
    bool direct;
    bool prepare_maps; /* then the illumination maps' programs (ps_gl_layers_prepare_maps) */
    int calls;
} ahead_job;

static void view_ahead(void *ctx)
{
    ahead_job *j = ctx;
    j->calls++;
    if (j->layers)
        ps_gl_layers_view_ahead(j->layers, j->gl, &j->cam, j->exposure, j->direct);
    else
        ps_gl_draw_view_ahead(j->gl, &j->cam, j->exposure, j->direct);
    if (j->prepare_maps)
        ps_gl_layers_prepare_maps(j->layers, j->gl);
}

/* The session started held (the first picture shows the first round's
 * photons, whichever way it started; snap's 8 bits are not held), plainly or
 * with the view drawn beside the round (into the layers l, or with l NULL
 * into the colour buffer) for the camera's eye moved eye_dx, at
 * exposure_factor times the first refresh's exposure: the calls of the work
 * beside the round. Into the layers for the camera itself at its exposure,
 * the way snap's float runs and the window start (ps_gl_layers_start), and
 * the views it drew count as the calls. */
static int start(gl_rig *g, ps_gl_layers *l, ps_gl_renderer *gl, bool ahead, double eye_dx, double exposure_factor)
{
    ps_error err;
    if (!ahead) {
        assert_int_equal(ps_session_start(g->s, true, &err), PS_OK);
        return 0;
    }
    if (l && eye_dx == 0.0 && exposure_factor == 1.0) {
        /* As snap's float runs and the window start (ps_gl_layers_start):
         * the views it drew beside the round. */
        uint64_t views = ps_gl_get_stats(gl).views;
        assert_int_equal(ps_gl_layers_start(l, gl, g->s, &g->cam, &err), PS_OK);
        return (int)(ps_gl_get_stats(gl).views - views);
    }
    /* With the illumination maps, their programs too, as snap's spare work. */
    ahead_job job = {l, gl, g->cam, 1.0, false, l && ps_session_illummap(g->s), 0};
    job.cam.eye.x += eye_dx;
    ps_session_direct_view(g->s, &job.exposure, &job.direct);
    job.exposure *= exposure_factor;
    assert_int_equal(ps_session_start_beside(g->s, true, view_ahead, NULL, &job, &err), PS_OK);
    return job.calls;
}

typedef struct first_picture {
    ps_image img;
    uint64_t views; /* the renderer's views drawn in all */
    uint64_t emitted[PS_MAP_COUNT];
    int calls;      /* view_ahead's */
    size_t gathered; /* photons the illumination maps held before the first refresh */
    size_t shown;    /* ... and after it */
    double ahead_seconds; /* the session's count of them (ps_session_counts) */
} first_picture;

/* A scene untraced at SIDE with every layer in float, its renderer and
 * its layers, as photosplat-snap's --time draws them. */
typedef struct float_rig {
    gl_rig g;
    ps_gl_renderer *gl;
    ps_gl_layers *l;
} float_rig;

static void float_rig_open(float_rig *r, const char *text, const char *name, ps_global_layer global)
{
    ps_session_settings set = gl_rig_load(&r->g, text, name);
    set.layers = PS_LAYER_DIRECT | PS_LAYER_CAUSTIC | PS_LAYER_GLOBAL;
    set.global_layer = global;
    gl_rig_untraced(&r->g, &set, SIDE);
    ps_gl_scene gs = ps_gl_scene_of(r->g.s);
    ps_gl_options go = {true, true, 0, false, false, OSMesaGetProcAddress};
    ps_error err;
    assert_int_equal(ps_gl_renderer_create(&gs, ps_session_kernel(r->g.s), &go, &r->gl, &err), PS_OK);
    assert_int_equal(ps_gl_layers_create(SIDE, SIDE, true, &r->l, &err), PS_OK);
}

static void float_rig_close(float_rig *r)
{
    ps_gl_layers_destroy(r->l);
    ps_gl_renderer_destroy(r->gl);
    gl_rig_close(&r->g);
}

/* The first refresh's composite, the session started the plain way, or
 * with the view drawn beside its round (ahead) for the scene's camera, its
 * eye moved eye_dx along x, at the refresh's exposure times exposure_factor;
 * the global layer as splats or as illumination maps. */
static first_picture first_of(bool ahead, double eye_dx, double exposure_factor, ps_global_layer global)
{
    float_rig r;
    float_rig_open(&r, ROOM, "ahead.scn", global);
    gl_rig *g = &r.g;
    ps_error err;
    first_picture out = {0};
    out.calls = start(g, r.l, r.gl, ahead, eye_dx, exposure_factor);
    const ps_illummap *imap = ps_session_illummap(g->s);
    out.gathered = imap ? ps_illummap_count(imap) : 0;
    ps_session_counts counts;
    ps_session_get_counts(g->s, &counts);
    out.ahead_seconds = counts.ahead_seconds;
    ps_session_frame f;
    assert_int_equal(ps_session_refresh(g->s, &g->cam, &f, &err), PS_OK);
    assert_true(f.new_view && !f.moving);
    out.shown = imap ? ps_illummap_count(imap) : 0;
    ps_gl_layers_draw(r.l, r.gl, &g->cam, &f);
    double gains[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        gains[k] = f.map[k].gain;
        out.emitted[k] = f.emitted[k];
        assert_true(f.emitted[k] > 0);
    }
    assert_int_equal(ps_gl_layers_composite(r.l, f.direct_gain, gains, &out.img, &err), PS_OK);
    out.views = ps_gl_get_stats(r.gl).views;
    float_rig_close(&r);
    return out;
}

static first_picture first(bool ahead, double eye_dx, double exposure_factor)
{
    return first_of(ahead, eye_dx, exposure_factor, PS_GLOBAL_SPLATS);
}

static void same_picture(const first_picture *a, const first_picture *b)
{
    for (int k = 0; k < PS_MAP_COUNT; k++)
        assert_int_equal(a->emitted[k], b->emitted[k]);
    assert_int_equal(a->img.width, b->img.width);
    assert_int_equal(a->img.height, b->img.height);
    size_t n = 3 * (size_t)a->img.width * (size_t)a->img.height;
    assert_true(gl_rig_image_mean(&a->img) > 0.0);
    assert_memory_equal(a->img.rgb, b->img.rgb, n * sizeof *a->img.rgb);
}

static void view_drawn_beside_the_round(void **state)
{
    (void)state;
    first_picture plain = first(false, 0.0, 1.0), ahead = first(true, 0.0, 1.0);
    printf("first picture: %llu caustic and %llu global photons, views drawn %llu plain, %llu ahead\n",
           (unsigned long long)ahead.emitted[PS_MAP_CAUSTIC], (unsigned long long)ahead.emitted[PS_MAP_GLOBAL],
           (unsigned long long)plain.views, (unsigned long long)ahead.views);
    assert_int_equal(ahead.calls, 1);
    assert_int_equal(plain.views, 1);
    assert_int_equal(ahead.views, 1); /* drawn beside the round, not again */
    same_picture(&ahead, &plain);
    ps_image_destroy(&plain.img);
    ps_image_destroy(&ahead.img);
}

static void another_view_drawn_again(void **state)
{
    (void)state;
    first_picture plain = first(false, 0.0, 1.0);
    /* Ahead for an eye moved a little: the refresh draws its own. */
    first_picture other = first(true, 0.05, 1.0);
    assert_int_equal(other.calls, 1);
    assert_int_equal(other.views, 2);
    same_picture(&other, &plain);
    /* Ahead for the camera at another exposure: drawn again too. */
    first_picture brighter = first(true, 0.0, 2.0);
    assert_int_equal(brighter.views, 2);
    same_picture(&brighter, &plain);
    ps_image_destroy(&plain.img);
    ps_image_destroy(&other.img);
    ps_image_destroy(&brighter.img);
}

static void maps_gathered_beside_the_round(void **state)
{
    (void)state;
    first_picture plain = first_of(false, 0.0, 1.0, PS_GLOBAL_MAPS);
    first_picture ahead = first_of(true, 0.0, 1.0, PS_GLOBAL_MAPS);
    printf("illumination maps: %zu photons gathered before the first refresh (%.4f s), %zu started plainly\n",
           ahead.gathered, ahead.ahead_seconds, plain.gathered);
    assert_int_equal(plain.gathered, 0);
    assert_true(plain.ahead_seconds == 0.0);
    /* The whole first round's global photons: the first refresh adds none. */
    assert_true(ahead.gathered > 0);
    assert_int_equal(ahead.shown, ahead.gathered);
    assert_int_equal(plain.shown, ahead.gathered);
    assert_true(ahead.ahead_seconds > 0.0);
    /* The maps' programs prepared after the view: it is still the one
     * shown, and their layer holds only the first refresh's maps. */
    assert_int_equal(ahead.views, 1);
    same_picture(&ahead, &plain);
    /* The splats' own start gathers nothing. */
    first_picture splats = first(true, 0.0, 1.0);
    assert_int_equal(splats.gathered, 0);
    assert_true(splats.ahead_seconds == 0.0);
    ps_image_destroy(&plain.img);
    ps_image_destroy(&ahead.img);
    ps_image_destroy(&splats.img);
}

/* ---- The direct layer's lit passes after the splats (defer_lit) ---------------- */

/* What happens between the view drawn ahead and the first picture: nothing,
 * a view of another camera begun (8 bits: into the colour buffer), the same
 * camera's view begun into another target (the layers: the colour buffer,
 * as a cube face is drawn before the layers' splats), new materials. */
typedef enum between { BETWEEN_NOTHING, BETWEEN_OTHER_VIEW, BETWEEN_OTHER_TARGET, BETWEEN_MATERIALS } between;

/* ROOM with a quad light in the back wall's plane, facing the camera: the
 * wall's lit passes pass the depth test on some of its pixels (the same
 * plane, rounded either way), which the view drew over with the emitter's
 * colour. */
static const char *const ROOM_LAMP =
    ROOM_OBJECTS "light quad corner -0.2 0.75 -1 edge1 0.4 0 0 edge2 0 0.4 0 power 5 5 5\n" ROOM_PHOTONS;

typedef struct deferred_picture {
    ps_image whole, direct; /* the first refresh's composite, and its direct layer alone */
    ps_image direct_now;    /* the direct layer drawn again at once (ps_gl_layers_relight) */
    unsigned passes_ahead;  /* lit passes drawn when the view beside the round was done */
    unsigned passes;        /* ... and when the first refresh was */
    uint64_t views;
} deferred_picture;

/* The first float picture of ROOM_LAMP, its view drawn beside the round
 * (ahead) or by the refresh, with `b` done between the two. */
static deferred_picture deferred_first(bool ahead, between b)
{
    float_rig r;
    float_rig_open(&r, ROOM_LAMP, "deferred.scn", PS_GLOBAL_SPLATS);
    gl_rig *g = &r.g;
    ps_error err;
    deferred_picture out;
    memset(&out, 0, sizeof out);
    start(g, r.l, r.gl, ahead, 0.0, 1.0);
    out.passes_ahead = ps_gl_get_stats(r.gl).light_passes;
    if (b == BETWEEN_OTHER_TARGET) {
        /* The same camera (the layers' splats take the last view's
         * matrices: a cube face puts the view's back, gl_specular.c). */
        double exposure;
        bool direct;
        ps_session_direct_view(g->s, &exposure, &direct);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        ps_gl_begin_frame(r.gl, &g->cam, exposure, direct);
    } else if (b == BETWEEN_MATERIALS) {
        ps_gl_renderer_set_materials(r.gl, ps_session_materials(g->s), false);
    }
    ps_session_frame f;
    assert_int_equal(ps_session_refresh(g->s, &g->cam, &f, &err), PS_OK);
    ps_gl_layers_draw(r.l, r.gl, &g->cam, &f);
    out.passes = ps_gl_get_stats(r.gl).light_passes;
    out.views = ps_gl_get_stats(r.gl).views;
    double gains[PS_MAP_COUNT], none[PS_MAP_COUNT] = {0.0, 0.0};
    for (int k = 0; k < PS_MAP_COUNT; k++)
        gains[k] = f.map[k].gain;
    assert_int_equal(ps_gl_layers_composite(r.l, f.direct_gain, gains, &out.whole, &err), PS_OK);
    assert_int_equal(ps_gl_layers_composite(r.l, f.direct_gain, none, &out.direct, &err), PS_OK);
    ps_gl_layers_relight(r.l, r.gl, &g->cam, f.direct_exposure, f.direct);
    assert_int_equal(ps_gl_layers_composite(r.l, f.direct_gain, none, &out.direct_now, &err), PS_OK);
    float_rig_close(&r);
    return out;
}

static void same_image(const ps_image *a, const ps_image *b)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    assert_true(gl_rig_image_mean(a) > 0.0);
    assert_memory_equal(a->rgb, b->rgb, 3 * (size_t)a->width * (size_t)a->height * sizeof *a->rgb);
}

static void deferred_destroy(deferred_picture *p)
{
    ps_image_destroy(&p->whole);
    ps_image_destroy(&p->direct);
    ps_image_destroy(&p->direct_now);
}

static void lit_passes_drawn_after_the_splats(void **state)
{
    (void)state;
    deferred_picture plain = deferred_first(false, BETWEEN_NOTHING);
    deferred_picture ahead = deferred_first(true, BETWEEN_NOTHING);
    printf("lit passes: %u when the view beside the round was drawn, %u after the first refresh\n",
           ahead.passes_ahead, ahead.passes);
    /* The view beside the round left them; the refresh drew them, after its splats. */
    assert_int_equal(ahead.passes_ahead, 0);
    assert_true(ahead.passes > 0);
    assert_int_equal(ahead.views, 1);
    /* The direct layer as the same passes drawn at once give it, the
     * emitter's colour over the wall it lies in included. */
    same_image(&ahead.direct, &ahead.direct_now);
    same_image(&plain.direct, &plain.direct_now);
    same_image(&ahead.whole, &plain.whole);
    /* A view begun elsewhere before the refresh draws the passes left first,
     * as the view drawn ahead saw them: the same picture. */
    deferred_picture other = deferred_first(true, BETWEEN_OTHER_TARGET);
    assert_int_equal(other.views, 2);
    same_image(&other.whole, &plain.whole);
    same_image(&other.direct, &plain.direct);
    /* New materials before it: the passes left are dropped, and the refresh
     * draws its view again. */
    deferred_picture materials = deferred_first(true, BETWEEN_MATERIALS);
    assert_int_equal(materials.views, 2);
    same_image(&materials.whole, &plain.whole);
    deferred_destroy(&plain);
    deferred_destroy(&ahead);
    deferred_destroy(&other);
    deferred_destroy(&materials);
}

/* ---- 8 bits: the view drawn into the colour buffer --------------------------- */


typedef struct first8 {
    ps_image img;
    uint64_t views;
    uint64_t emitted[PS_MAP_COUNT];
    int calls;
    bool drawn_ahead; /* the frame drew over the view drawn ahead (ps_gl_stats) */
} first8;

/* The first 8-bit frame (photosplat-snap's: no layers, the whole frame
 * redrawn), the session started plainly or with the view drawn beside its
 * round (ahead) for the camera's eye moved eye_dx, at exposure_factor times
 * the frame's exposure, and `b` done in between. */
static first8 first_8bit(bool ahead, double eye_dx, double exposure_factor, between b)
{
    gl_rig g;
    ps_session_settings set = gl_rig_load(&g, ROOM, "ahead8.scn");
    set.float_buffer = false;
    set.incremental = false;
    set.layers = PS_LAYER_DIRECT | PS_LAYER_CAUSTIC | PS_LAYER_GLOBAL;
    gl_rig_untraced(&g, &set, SIDE);
    ps_gl_scene gs = ps_gl_scene_of(g.s);
    ps_gl_options go = {true, false, 0, false, false, OSMesaGetProcAddress};
    ps_gl_renderer *gl;
    ps_error err;
    assert_int_equal(ps_gl_renderer_create(&gs, ps_session_kernel(g.s), &go, &gl, &err), PS_OK);
    first8 out = {0};
    out.calls = start(&g, NULL, gl, ahead, eye_dx, exposure_factor);
    if (b == BETWEEN_OTHER_VIEW) {
        ps_camera_frame other = g.cam;
        other.eye.y += 0.2;
        ps_gl_begin_frame(gl, &other, 0.5, true);
    } else if (b == BETWEEN_MATERIALS) {
        ps_gl_renderer_set_materials(gl, ps_session_materials(g.s), false);
    }
    ps_session_frame f;
    assert_int_equal(ps_session_refresh(g.s, &g.cam, &f, &err), PS_OK);
    assert_true(f.new_view && !f.moving);
    ps_gl_draw_frame(gl, &g.cam, &f);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        out.emitted[k] = f.emitted[k];
        assert_true(f.emitted[k] > 0 && f.splats > 0);
    }
    assert_int_equal(ps_gl_read(gl, &out.img, &err), PS_OK);
    out.views = ps_gl_get_stats(gl).views;
    out.drawn_ahead = ps_gl_get_stats(gl).drawn_ahead_last;
    ps_gl_renderer_destroy(gl);
    gl_rig_close(&g);
    return out;
}

static void same_8bit(const first8 *a, const first8 *b)
{
    for (int k = 0; k < PS_MAP_COUNT; k++)
        assert_int_equal(a->emitted[k], b->emitted[k]);
    size_t n = 3 * (size_t)a->img.width * (size_t)a->img.height;
    assert_int_equal(a->img.width, b->img.width);
    assert_true(gl_rig_image_mean(&a->img) > 0.0);
    assert_memory_equal(a->img.rgb, b->img.rgb, n * sizeof *a->img.rgb);
}

static void view_drawn_ahead_into_8_bits(void **state)
{
    (void)state;
    first8 plain = first_8bit(false, 0.0, 1.0, BETWEEN_NOTHING);
    first8 ahead = first_8bit(true, 0.0, 1.0, BETWEEN_NOTHING);
    printf("8 bits: first frame of %llu caustic and %llu global photons, views drawn %llu plain, %llu ahead\n",
           (unsigned long long)ahead.emitted[PS_MAP_CAUSTIC], (unsigned long long)ahead.emitted[PS_MAP_GLOBAL],
           (unsigned long long)plain.views, (unsigned long long)ahead.views);
    assert_int_equal(ahead.calls, 1);
    assert_int_equal(plain.views, 1);
    assert_int_equal(ahead.views, 1); /* the frame drew only its splats over it */
    assert_true(ahead.drawn_ahead);
    assert_false(plain.drawn_ahead);
    same_8bit(&ahead, &plain);
    ps_image_destroy(&plain.img);
    ps_image_destroy(&ahead.img);
}

static void view_8bit_drawn_again_when_not_the_frames(void **state)
{
    (void)state;
    first8 plain = first_8bit(false, 0.0, 1.0, BETWEEN_NOTHING);
    const struct {
        double eye_dx, exposure_factor;
        between b;
        uint64_t views;
    } cases[] = {
        {0.05, 1.0, BETWEEN_NOTHING, 2},    /* another camera */
        {0.0, 2.0, BETWEEN_NOTHING, 2},     /* another exposure */
        {0.0, 1.0, BETWEEN_OTHER_VIEW, 3},  /* a view begun in between (a cube face's) */
        {0.0, 1.0, BETWEEN_MATERIALS, 2},   /* new materials (an edit) */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        first8 a = first_8bit(true, cases[i].eye_dx, cases[i].exposure_factor, cases[i].b);
        assert_int_equal(a.calls, 1);
        assert_int_equal(a.views, cases[i].views);
        assert_false(a.drawn_ahead);
        same_8bit(&a, &plain);
        ps_image_destroy(&a.img);
    }
    ps_image_destroy(&plain.img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(view_drawn_beside_the_round),
        cmocka_unit_test(another_view_drawn_again),
        cmocka_unit_test(maps_gathered_beside_the_round),
        cmocka_unit_test(lit_passes_drawn_after_the_splats),
        cmocka_unit_test(view_drawn_ahead_into_8_bits),
        cmocka_unit_test(view_8bit_drawn_again_when_not_the_frames),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
