/* test_gl_shadow_faces.c: after an edit the renderer renders again only the
 * shadow-cube faces whose depths can have changed (gl_lights.c), and the
 * direct layer it then draws is the same, float for float, as a fresh
 * renderer's of the edited scene. Under OSMesa, float colour buffer.
 *
 * The scene: a floor at y = 0, a small square occluder at y = 0.5 and a
 * point light at y = 1 above it, a smaller square 0.2 above the light (the
 * nearest geometry, which sets the cube's near plane, stays where it is).
 * The light's cube has 6 faces; the occluder
 * lies in the -y face only, so moving it a little renders that face alone;
 * moving it out to the side (direction (1.5, -0.5) from the light: the +x
 * face) renders the face it left and the one it entered; a power change
 * renders none; a moved light all of its own. */
#include "test.h"

#include <GL/osmesa.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "gl/gl_internal.h" /* ps_gl_begin_frame_shadows: a moving frame; the shadow query */
#include "gl/gl_render.h"
#include "preview/lights.h"
#include "preview/mesh.h"
#include "preview/splat.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "two_lights.h"

static const char *const scene_text = "camera eye 0 3 0.01 target 0 0 0 up 0 0 -1 fov 70\n"
                                      "material floor diffuse albedo 0.5 0.5 0.5\n"
                                      "quad corner -2 0 2 edge1 4 0 0 edge2 0 0 -4 material floor\n"
                                      "quad corner -0.1 0.5 -0.1 edge1 0.2 0 0 edge2 0 0 0.2 material floor\n"
                                      "quad corner -0.05 1.2 -0.05 edge1 0.1 0 0 edge2 0 0 0.1 material floor\n"
                                      "light point position 0 1 0 power 100 100 100\n";

#define W 96
#define H 96

/* The GL-free inputs of a renderer: built from the scene as the session does. */
typedef struct inputs {
    ps_preview_mesh mesh, coarse;
    ps_preview_lights lights;
} inputs;

static void inputs_make_sized(const ps_scene *s, int shadow_size, inputs *in)
{
    ps_error err;
    memset(in, 0, sizeof *in);
    ps_mesh_options mo = ps_mesh_default_options(s);
    assert_int_equal(ps_preview_mesh_build(s, &mo, &in->mesh, &err), PS_OK);
    assert_int_equal(ps_mesh_make_tiles(&in->mesh, PS_MESH_TILE_TRIANGLES, &in->mesh.tiles, &err), PS_OK); /* as the session's */
    mo.max_edge = HUGE_VAL;
    assert_int_equal(ps_preview_mesh_build(s, &mo, &in->coarse, &err), PS_OK);
    assert_int_equal(ps_preview_lights_build(s, NULL, &in->coarse, shadow_size, PS_PREVIEW_AREA_SIDE, &in->lights, &err),
                     PS_OK);
    assert_int_equal(in->lights.shadow_size, shadow_size);
}

static void inputs_make(const ps_scene *s, inputs *in) { inputs_make_sized(s, PS_GL_SHADOW_SIZE, in); }

static void inputs_free(inputs *in)
{
    ps_preview_mesh_free(&in->mesh);
    ps_preview_mesh_free(&in->coarse);
    ps_preview_lights_free(&in->lights);
}

static ps_gl_scene gl_scene(const ps_scene *s, const inputs *in)
{
    size_t nmat;
    ps_gl_scene gs = {&in->mesh, &in->coarse, ps_scene_materials(s, &nmat), &in->lights, ps_scene_bounds(s), false, s,
                      NULL, false};
    return gs;
}

/* The direct layer with shadows, read back. */
static ps_image draw(ps_gl_renderer *r, const ps_scene *s)
{
    ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(s), W, H);
    ps_gl_begin_frame(r, &cam, 1.0, true);
    ps_image img;
    ps_error err;
    assert_int_equal(ps_gl_read(r, &img, &err), PS_OK);
    return img;
}

static bool same_pixels(const ps_image *a, const ps_image *b)
{
    return a->width == b->width && a->height == b->height &&
           memcmp(a->rgb, b->rgb, sizeof(float) * 3 * (size_t)a->width * (size_t)a->height) == 0;
}

typedef enum edit_kind { MOVE_OCCLUDER_A_LITTLE, MOVE_OCCLUDER_ASIDE, POWER, MOVE_LIGHT } edit_kind;

static void apply(ps_scene *s, edit_kind e)
{
    ps_error err;
    switch (e) {
    case MOVE_OCCLUDER_A_LITTLE: assert_int_equal(ps_scene_translate_object(s, 1, ps_v3(0.2, 0, 0), &err), PS_OK); break;
    case MOVE_OCCLUDER_ASIDE: assert_int_equal(ps_scene_translate_object(s, 1, ps_v3(1.5, 0, 0), &err), PS_OK); break;
    case POWER: assert_int_equal(ps_scene_set_light_power(s, 0, ps_rgb_make(50, 60, 70), &err), PS_OK); break;
    case MOVE_LIGHT: assert_int_equal(ps_scene_set_light_position(s, 0, ps_v3(0.3, 1, 0.1), &err), PS_OK); break;
    }
}

/* A scene with a float OSMesa context current and the box kernel. */
typedef struct gl_rig {
    ps_scene *s;
    float *buffer;
    OSMesaContext ctx;
    ps_kernel_texture kernel;
} gl_rig;

static gl_rig gl_rig_open(const char *text)
{
    gl_rig g;
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &g.s, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    g.buffer = malloc(sizeof(float) * 4 * W * H);
    g.ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    assert_non_null(g.ctx);
    assert_true(OSMesaMakeCurrent(g.ctx, g.buffer, GL_FLOAT, W, H));
    assert_int_equal(ps_kernel_texture_make(PS_KERNEL_BOX, PS_KERNEL_TEXTURE_SIZE, &g.kernel, &err), PS_OK);
    return g;
}

static void gl_rig_close(gl_rig *g)
{
    ps_kernel_texture_free(&g->kernel);
    OSMesaDestroyContext(g->ctx);
    free(g->buffer);
    ps_scene_destroy(g->s);
}

/* One edit: the faces the renderer rendered again, and its picture against
 * a fresh renderer's of the edited scene. */
static void edit_renders(edit_kind e, unsigned expect_faces, bool picture_changes)
{
    ps_error err;
    gl_rig g = gl_rig_open(scene_text);
    ps_scene *s = g.s;
    ps_gl_options go = {true, true, 0, false, false, OSMesaGetProcAddress};

    inputs before;
    inputs_make(s, &before);
    assert_int_equal(before.lights.count, 1);
    unsigned lit = (unsigned)__builtin_popcount(before.lights.lights[0].faces);
    assert_int_equal(lit, 6); /* a point light: the whole cube */
    ps_gl_scene gs = gl_scene(s, &before);
    ps_gl_renderer *r;
    assert_int_equal(ps_gl_renderer_create(&gs, &g.kernel, &go, &r, &err), PS_OK);
    ps_gl_clear_shadow_timing(r);
    ps_image old_pic = draw(r, s);
    assert_int_equal(ps_gl_get_stats(r).shadow_faces_last, 6);

    /* The edit, the inputs made again, the renderer given them. */
    apply(s, e);
    inputs after;
    inputs_make(s, &after);
    gs = gl_scene(s, &after);
    assert_int_equal(ps_gl_renderer_set_scene(r, &gs, &err), PS_OK);
    inputs_free(&before);
    ps_gl_clear_shadow_timing(r);
    ps_image new_pic = draw(r, s);
    unsigned faces = ps_gl_get_stats(r).shadow_faces_last;

    ps_gl_renderer *fresh;
    assert_int_equal(ps_gl_renderer_create(&gs, &g.kernel, &go, &fresh, &err), PS_OK);
    ps_gl_clear_shadow_timing(fresh);
    ps_image fresh_pic = draw(fresh, s);
    assert_int_equal(ps_gl_get_stats(fresh).shadow_faces_last, 6);

    bool same = same_pixels(&new_pic, &fresh_pic), changed = !same_pixels(&old_pic, &new_pic);
    printf("edit %d: %u of 6 shadow faces rendered again; the picture %s a fresh renderer's, %s the one before\n", (int)e,
           faces, same ? "equals" : "DIFFERS from", changed ? "differs from" : "equals");
    assert_int_equal(faces, expect_faces);
    assert_true(same);
    assert_true(changed == picture_changes);
    /* Drawn again with nothing changed: no face at all. */
    ps_gl_clear_shadow_timing(r);
    ps_image again = draw(r, s);
    assert_int_equal(ps_gl_get_stats(r).shadow_faces_last, 0);
    assert_true(same_pixels(&again, &fresh_pic));

    ps_image_destroy(&again);
    ps_image_destroy(&old_pic);
    ps_image_destroy(&new_pic);
    ps_image_destroy(&fresh_pic);
    ps_gl_renderer_destroy(fresh);
    ps_gl_renderer_destroy(r);
    inputs_free(&after);
    gl_rig_close(&g);
}

static void occluder_moved_a_little(void **state)
{
    (void)state;
    edit_renders(MOVE_OCCLUDER_A_LITTLE, 1, true); /* the -y face alone */
}

static void occluder_moved_aside(void **state)
{
    (void)state;
    edit_renders(MOVE_OCCLUDER_ASIDE, 2, true); /* the -y face it left and the +x face it entered */
}

static void power_renders_no_face(void **state)
{
    (void)state;
    edit_renders(POWER, 0, true);
}

static void moved_light_renders_its_cube(void **state)
{
    (void)state;
    edit_renders(MOVE_LIGHT, 6, true);
}

/* The shadowed lit passes leave out the objects outside each cube face's
 * pyramid (ps_gl_draw_mesh_within), and mirrors and glass, which add
 * nothing there: the same picture, float for float, as passes that draw
 * every object in every face, from fewer vertices: here, in the two-light
 * box (its spheres lie in one face of the point light, its walls in two or
 * three) and here with a mirror and a glass sphere added (none of their
 * vertices drawn). */
static void culled_faces_draw_the_same(void **state)
{
    (void)state;
    char box[2048], spheres[2048];
    snprintf(box, sizeof box, TWO_LIGHTS_SCENE "60 50 40\n");
    /* A mirror and a glass sphere beside the occluder: lit passes leave them out. */
    snprintf(spheres, sizeof spheres,
             "%smaterial m mirror reflectance 1 1 1\nmaterial g dielectric ior 1.5\n"
             "sphere center 0.8 0.3 0.6 radius 0.3 material m\nsphere center -0.8 0.3 -0.6 radius 0.3 material g\n",
             scene_text);
    const char *texts[3] = {scene_text, box, spheres};
    for (int t = 0; t < 3; t++) {
        ps_error err;
        gl_rig g = gl_rig_open(texts[t]);
        ps_scene *s = g.s;
        inputs in;
        inputs_make(s, &in);
        ps_gl_scene gs = gl_scene(s, &in);
        ps_image pic[3];
        uint64_t vertices[3];
        /* Culled by tiles, every object whole, culled by whole ranges (the
         * mesh's tiles dropped: what a mesh without them draws). */
        for (int v = 0; v < 3; v++) {
            ps_gl_options go = {true, true, 0, v == 1, false, OSMesaGetProcAddress};
            if (v == 2)
                ps_mesh_tiling_free(&in.mesh.tiles);
            ps_gl_renderer *r;
            assert_int_equal(ps_gl_renderer_create(&gs, &g.kernel, &go, &r, &err), PS_OK);
            pic[v] = draw(r, s);
            vertices[v] = ps_gl_get_stats(r).light_vertices;
            ps_gl_renderer_destroy(r);
        }
        printf("scene %d: the lit passes drew %llu vertices culled by tiles, %llu by whole ranges, %llu whole (%.2f, "
               "%.2f)\n",
               t, (unsigned long long)vertices[0], (unsigned long long)vertices[2], (unsigned long long)vertices[1],
               (double)vertices[0] / (double)vertices[1], (double)vertices[2] / (double)vertices[1]);
        assert_true(same_pixels(&pic[0], &pic[1]));
        assert_true(same_pixels(&pic[2], &pic[1]));
        assert_true(vertices[0] < vertices[2]); /* a wall in two or three pyramids is drawn in parts */
        assert_true(vertices[2] < vertices[1]);
        assert_true(vertices[0] < vertices[1]);
        if (t == 1) /* six faces of the point light, the spot's one or two */
            assert_true(vertices[0] < vertices[1] / 2);
        if (t == 2) { /* the spheres' vertices (most of the mesh) in no pass */
            size_t nobj;
            const ps_object *objects = ps_scene_objects(s, &nobj);
            uint64_t sphere_vertices = 0;
            for (size_t i = 0; i < in.mesh.range_count; i++)
                if (objects[in.mesh.ranges[i].object].type == PS_OBJ_SPHERE)
                    sphere_vertices += in.mesh.ranges[i].count;
            assert_true(sphere_vertices > 0);
            assert_true(vertices[0] + sphere_vertices <= vertices[1]);
        }
        for (int v = 0; v < 3; v++)
            ps_image_destroy(&pic[v]);
        inputs_free(&in);
        gl_rig_close(&g);
    }
}

/* Lights planned at another side (a session's coarse first shadows refined,
 * preview/session.h): the renderer draws every face again at that side,
 * the same picture as a fresh renderer's made with them, and not the coarse
 * one (32 texels a side here, so that the occluder's shadow edge moves by
 * pixels); the renderer's own option gives way to the lights' side. */
static void resized_shadows_render_every_face(void **state)
{
    (void)state;
    ps_error err;
    gl_rig g = gl_rig_open(scene_text);
    ps_gl_options go = {true, true, 0, false, false, OSMesaGetProcAddress};
    inputs coarse, full;
    inputs_make_sized(g.s, 32, &coarse);
    inputs_make(g.s, &full);
    ps_gl_scene gs = gl_scene(g.s, &coarse);
    ps_gl_renderer *r, *fresh;
    assert_int_equal(ps_gl_renderer_create(&gs, &g.kernel, &go, &r, &err), PS_OK);
    ps_gl_clear_shadow_timing(r);
    ps_image coarse_pic = draw(r, g.s);
    assert_int_equal(ps_gl_get_stats(r).shadow_faces_last, 6);
    gs = gl_scene(g.s, &full);
    assert_int_equal(ps_gl_renderer_set_scene(r, &gs, &err), PS_OK);
    ps_gl_clear_shadow_timing(r);
    ps_image full_pic = draw(r, g.s);
    assert_int_equal(ps_gl_get_stats(r).shadow_faces_last, 6);
    go.shadow_size = 64; /* the lights' side wins */
    assert_int_equal(ps_gl_renderer_create(&gs, &g.kernel, &go, &fresh, &err), PS_OK);
    ps_image fresh_pic = draw(fresh, g.s);
    assert_true(same_pixels(&full_pic, &fresh_pic));
    assert_false(same_pixels(&full_pic, &coarse_pic));
    ps_image_destroy(&coarse_pic);
    ps_image_destroy(&full_pic);
    ps_image_destroy(&fresh_pic);
    ps_gl_renderer_destroy(fresh);
    ps_gl_renderer_destroy(r);
    inputs_free(&coarse);
    inputs_free(&full);
    gl_rig_close(&g);
}

/* The shadow maps' seconds, from their start to GL's end of them: by a
 * timestamp query where the platform gives one (ps_gl_options.gl_proc),
 * which the passes after them do not wait for, else by waiting. Either way
 * more than nothing and no more than the frame that made them, and the same
 * picture; a time dropped (ps_gl_clear_shadow_timing) while its query is
 * still pending stays dropped. And the first maps draw with the colour
 * clamps off, as every pass after them: llvmpipe keys its programs on the
 * clamps, and maps drawn under GL's defaults (vertex colours clamped) loaded
 * a program of their own in every first picture. */
static void shadow_maps_timed_to_their_end(void **state)
{
    (void)state;
    ps_error err;
    gl_rig g = gl_rig_open(scene_text);
    inputs in;
    inputs_make(g.s, &in);
    ps_gl_scene gs = gl_scene(g.s, &in);
    ps_image pic[2];
    for (int v = 0; v < 2; v++) {
        ps_gl_options go = {true, true, 0, false, false, v == 0 ? OSMesaGetProcAddress : NULL};
        ps_gl_renderer *r;
        assert_int_equal(ps_gl_renderer_create(&gs, &g.kernel, &go, &r, &err), PS_OK);
        assert_true((r->query_counter != NULL) == (v == 0)); /* llvmpipe has GL 3.3's timer queries */
        const GLenum clamps[] = {GL_CLAMP_VERTEX_COLOR, GL_CLAMP_FRAGMENT_COLOR, GL_CLAMP_READ_COLOR};
        for (size_t i = 0; i < sizeof clamps / sizeof clamps[0]; i++) {
            GLint c = -1;
            glGetIntegerv(clamps[i], &c);
            assert_int_equal(c, GL_FALSE);
        }
        ps_gl_clear_shadow_timing(r);
        double t0 = ps_now_seconds();
        pic[v] = draw(r, g.s);
        double frame = ps_now_seconds() - t0;
        ps_gl_stats st = ps_gl_get_stats(r);
        printf("shadow maps %s: %.2f ms of a %.2f ms frame\n", v == 0 ? "by a timestamp" : "waited for",
               1e3 * st.shadow_seconds_last, 1e3 * frame);
        assert_int_equal(st.shadow_faces_last, 6);
        assert_true(st.shadow_seconds_last > 0.0);
        assert_true(st.shadow_seconds_last <= frame);
        /* Made again, the time dropped before it is read: none. */
        assert_int_equal(ps_gl_renderer_set_scene(r, &gs, &err), PS_OK);
        ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(g.s), W, H);
        ps_gl_begin_frame(r, &cam, 1.0, true);
        ps_gl_clear_shadow_timing(r);
        ps_gl_finish();
        assert_false(r->shadow_query_pending);
        assert_true(ps_gl_get_stats(r).shadow_seconds_last == 0.0);
        ps_gl_renderer_destroy(r);
    }
    assert_true(same_pixels(&pic[0], &pic[1]));
    ps_image_destroy(&pic[0]);
    ps_image_destroy(&pic[1]);
    inputs_free(&in);
    gl_rig_close(&g);
}

/* ps_gl_options.bake_direct: the direct layer of diffuse quads drawn from
 * textures laid once (gl_direct_bake.c) against the lit passes themselves
 * (a renderer without them), at the laying view and at another: relative
 * squared error (pixels over 1 % of the peak) and the mean. Texels of a
 * 1024th of the scene's diagonal against pixels of about a 96th of the
 * view: the error is the shadow edges' and the Gouraud ramps' resampling.
 * Not the contract's relMSE (image/compare.h): it counts the pixels on a
 * hard shadow edge that the lit pass's test leaves black and the texture's
 * bilinear sample does not (12 of the back side's 9 216 gave it 2.1e-2, the
 * means within 0.07 %). */
static double rel_mse(const ps_image *a, const ps_image *b, double *mean_a, double *mean_b)
{
    size_t n = 3 * (size_t)a->width * (size_t)a->height, counted = 0;
    double peak = 0.0, e = 0.0, sa = 0.0, sb = 0.0;
    for (size_t i = 0; i < n; i++)
        peak = fmax(peak, b->rgb[i]);
    for (size_t i = 0; i < n; i++) {
        sa += a->rgb[i], sb += b->rgb[i];
        if (b->rgb[i] > 0.01 * peak) {
            double d = (double)a->rgb[i] - (double)b->rgb[i];
            e += d * d / ((double)b->rgb[i] * (double)b->rgb[i]);
            counted++;
        }
    }
    *mean_a = sa / (double)n, *mean_b = sb / (double)n;
    return counted ? e / (double)counted : 0.0;
}

static ps_image draw_at(ps_gl_renderer *r, const ps_camera_frame *cam, bool moving)
{
    ps_gl_begin_frame_shadows(r, cam, 1.0, true, !moving, moving, false);
    ps_image img;
    ps_error err;
    assert_int_equal(ps_gl_read(r, &img, &err), PS_OK);
    return img;
}

static void baked_against_lit(const char *text, const char *what, ps_vec3 other_eye)
{
    ps_error err;
    gl_rig g = gl_rig_open(text);
    inputs in;
    inputs_make(g.s, &in);
    ps_gl_scene gs = gl_scene(g.s, &in);
    ps_gl_options lit_o = {true, true, 0, false, false, OSMesaGetProcAddress}, baked_o = {true, true, 0, false, true, OSMesaGetProcAddress};
    ps_gl_renderer *lit, *baked;
    assert_int_equal(ps_gl_renderer_create(&gs, &g.kernel, &lit_o, &lit, &err), PS_OK);
    assert_int_equal(ps_gl_renderer_create(&gs, &g.kernel, &baked_o, &baked, &err), PS_OK);
    ps_camera cam0 = *ps_scene_camera(g.s), cam1 = cam0;
    cam1.eye = other_eye;
    ps_camera_frame frames[2] = {ps_camera_frame_make(&cam0, W, H), ps_camera_frame_make(&cam1, W, H)};
    /* Nothing to lay before a frame has made the shadow maps; the first
     * view draws the lit passes (the same pixels); then the textures are
     * laid (in parts, as the window does while it waits), and the views
     * draw them: the first camera's again, a moving one after another
     * camera, and a still one there. */
    assert_false(ps_gl_direct_bake_lay(baked, 1.0, HUGE_VAL));
    ps_image first = draw_at(baked, &frames[0], false), want0 = draw_at(lit, &frames[0], false);
    assert_false(ps_gl_get_stats(baked).direct_baked_last);
    assert_true(same_pixels(&first, &want0));
    int parts = 1;
    while (ps_gl_direct_bake_lay(baked, 1.0, 0.0))
        parts++;
    assert_true(parts > 1); /* a side a call at least */
    assert_false(ps_gl_direct_bake_lay(baked, 1.0, 0.0)); /* laid: nothing left */
    assert_int_equal(ps_gl_get_stats(baked).direct_bakes, 1);
    for (int v = 0; v < 3; v++) {
        const ps_camera_frame *f = &frames[v == 0 ? 0 : 1];
        ps_image got = draw_at(baked, f, v == 1), want = draw_at(lit, f, false);
        assert_true(ps_gl_get_stats(baked).direct_baked_last);
        assert_int_equal(ps_gl_get_stats(baked).direct_bakes, 1);
        double ma, mb, e = rel_mse(&got, &want, &ma, &mb);
        print_message("%s, view %d%s: the direct layer from its textures, mean %.5f against %.5f (%.3f %%), relMSE "
                      "%.2e\n",
                      what, v, v == 1 ? " (moving)" : "", ma, mb, 100.0 * (ma / mb - 1.0), e);
        assert_true(mb > 0.0);
        assert_true(fabs(ma / mb - 1.0) < 0.005);
        assert_true(e < 5e-3);
        ps_image_destroy(&got);
        ps_image_destroy(&want);
    }
    /* A moved light: the textures are dropped, the lit passes draw (the same
     * pixels as a fresh renderer's), and the next still view lays them again. */
    assert_int_equal(ps_scene_set_light_position(g.s, 0, ps_v3_add(ps_scene_lights(g.s, NULL)[0].position,
                                                                    ps_v3(0.1, -0.05, 0.05)),
                                                 &err),
                     PS_OK);
    inputs after;
    inputs_make(g.s, &after);
    gs = gl_scene(g.s, &after);
    assert_int_equal(ps_gl_renderer_set_scene(baked, &gs, &err), PS_OK);
    assert_int_equal(ps_gl_renderer_set_scene(lit, &gs, &err), PS_OK);
    ps_image got = draw_at(baked, &frames[1], false), want = draw_at(lit, &frames[1], false);
    assert_false(ps_gl_get_stats(baked).direct_baked_last);
    assert_true(same_pixels(&got, &want));
    ps_image_destroy(&got);
    /* Laid again, but a change halfway starts it over: the exposure. */
    assert_true(ps_gl_direct_bake_lay(baked, 2.0, 0.0));
    while (ps_gl_direct_bake_lay(baked, 1.0, 0.0))
        ;
    got = draw_at(baked, &frames[1], false);
    assert_true(ps_gl_get_stats(baked).direct_baked_last);
    assert_int_equal(ps_gl_get_stats(baked).direct_bakes, 2);
    double ma, mb;
    assert_true(rel_mse(&got, &want, &ma, &mb) < 1e-3);
    ps_image_destroy(&got);
    ps_image_destroy(&want);
    ps_image_destroy(&first);
    ps_image_destroy(&want0);
    ps_gl_renderer_destroy(lit);
    ps_gl_renderer_destroy(baked);
    inputs_free(&in);
    inputs_free(&after);
    gl_rig_close(&g);
}

static void direct_light_baked_on_quads(void **state)
{
    (void)state;
    char box[2048];
    snprintf(box, sizeof box, TWO_LIGHTS_SCENE "60 50 40\n");
    /* The floor and its occluder from above, then from a side. */
    baked_against_lit(scene_text, "floor", ps_v3(1.5, 2.0, 1.5));
    /* The box with its spot and point light, its spheres' shadows. */
    baked_against_lit(box, "box", ps_v3(0.6, 1.3, 2.9));
}

/* A quad lit on its back, seen from there: its back side's texture (its
 * lay must see the triangles wound as that view does). */
static void direct_light_baked_on_a_back_side(void **state)
{
    (void)state;
    const char *text = "camera eye 0 -2 0.01 target 0 0 0 up 0 0 -1 fov 70\n"
                       "material floor diffuse albedo 0.5 0.5 0.5\n"
                       "quad corner -2 0 2 edge1 4 0 0 edge2 0 0 -4 material floor\n"
                       "quad corner -0.2 -0.5 -0.2 edge1 0.4 0 0 edge2 0 0 0.4 material floor\n"
                       "light point position 0.1 -1 0 power 100 100 100\n";
    baked_against_lit(text, "back side", ps_v3(1.0, -1.8, 0.5));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(occluder_moved_a_little),
        cmocka_unit_test(occluder_moved_aside),
        cmocka_unit_test(power_renders_no_face),
        cmocka_unit_test(moved_light_renders_its_cube),
        cmocka_unit_test(culled_faces_draw_the_same),
        cmocka_unit_test(resized_shadows_render_every_face),
        cmocka_unit_test(shadow_maps_timed_to_their_end),
        cmocka_unit_test(direct_light_baked_on_quads),
        cmocka_unit_test(direct_light_baked_on_a_back_side),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
