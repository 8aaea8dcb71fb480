/* specular_rig.h: a session with no photons over an OSMesa float buffer,
 * its GL renderer and specular layer, for the tests of that layer
 * (test_gl_specular, test_gl_glossy): the direct light and what mirrors,
 * glass and glossy lobes show of it. Include after test.h. */
#ifndef PS_TESTS_SPECULAR_RIG_H
#define PS_TESTS_SPECULAR_RIG_H

#include <GL/osmesa.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_render.h"
#include "gl/gl_specular.h"
#include "preview/session.h"
#include "scene/camera.h"
#include "scene/scene.h"

typedef struct rig {
    ps_scene *scene;
    ps_session *session;
    OSMesaContext ctx;
    float *buffer;
    ps_gl_renderer *gl;
    ps_gl_specular *spec;
    ps_camera_frame cam;
    int w, h;
} rig;

/* refining: a session with progressive lights, held (refined only when
 * asked), its tracer started and held but not paused (photons still to
 * come: never settled), the specular layer's first round over
 * PS_GL_SPECULAR_FIRST_REFRESHES refreshes, for the rounds of cube faces as
 * lights are refined; else no photons at all. */
static void rig_make_as(rig *r, ps_scene *scene, int w, int h, bool refining)
{
    memset(r, 0, sizeof *r);
    ps_error err;
    r->scene = scene;
    r->w = w, r->h = h;
    ps_session_settings set = ps_session_default_settings(scene);
    set.float_buffer = true;
    if (refining) {
        set.caps[0] = 1000000, set.caps[1] = 100000;
        set.incremental = set.progressive_lights = true;
    } else {
        set.caps[0] = set.caps[1] = 0;
        set.precision = PS_PRECISION_NONE;
    }
    assert_int_equal(ps_session_create(scene, &set, &r->session, &err), PS_OK);
    if (refining) {
        ps_session_hold_lights(r->session, true);
        assert_int_equal(ps_session_start(r->session, true, &err), PS_OK);
        ps_session_hold(r->session, true);
    } else {
        assert_int_equal(ps_session_trace_all(r->session, &err), PS_OK);
    }
    r->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    assert_non_null(r->ctx);
    r->buffer = malloc(sizeof(float) * 4 * (size_t)w * (size_t)h);
    assert_true(OSMesaMakeCurrent(r->ctx, r->buffer, GL_FLOAT, w, h));
    ps_gl_options go = {true, true, 0, false, false, OSMesaGetProcAddress};
    ps_gl_scene gs = ps_gl_scene_of(r->session);
    assert_int_equal(ps_gl_renderer_create(&gs, ps_session_kernel(r->session), &go, &r->gl, &err), PS_OK);
    assert_int_equal(ps_gl_specular_create(0, &r->spec, &err), PS_OK);
    if (refining)
        ps_gl_specular_set_first_round(r->spec, PS_GL_SPECULAR_FIRST_REFRESHES);
    r->cam = ps_camera_frame_make(ps_scene_camera(scene), w, h);
}

static void rig_make(rig *r, ps_scene *scene, int w, int h) { rig_make_as(r, scene, w, h, false); }

static void rig_free(rig *r)
{
    ps_gl_specular_destroy(r->spec);
    ps_gl_renderer_destroy(r->gl);
    OSMesaDestroyContext(r->ctx);
    free(r->buffer);
    ps_session_destroy(r->session);
    ps_scene_destroy(r->scene);
}

static ps_scene *load_text(const char *text)
{
    ps_scene *s;
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    return s;
}

/* The specular layer alone (the scene black, still hiding what lies
 * behind), its cube maps (and glossy levels) rendered whole unless
 * `filled`. */
static ps_image specular_alone(rig *r, bool filled)
{
    ps_error err;
    ps_session_frame f;
    assert_int_equal(ps_session_refresh(r->session, &r->cam, &f, &err), PS_OK);
    assert_true(f.specular);
    if (!filled)
        assert_int_equal(ps_gl_specular_refresh(r->spec, r->gl, r->session, &f, 0, &err), PS_OK);
    ps_gl_begin_frame(r->gl, &r->cam, 1.0, false);
    ps_gl_specular_draw(r->spec, r->gl, r->session, 1.0);
    ps_image img;
    assert_int_equal(ps_gl_read(r->gl, &img, &err), PS_OK);
    return img;
}

#endif
