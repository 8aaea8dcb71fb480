/* gl_rig.h: a scene's preview session traced to its caps (or not yet
 * traced), with a current OSMesa context, for the tests that draw a
 * session's frames into the GL layers (test_gl_moving, test_gl_bake,
 * test_gl_ahead). Any failure fails the test with the
 * message. Include after test.h. */
#ifndef PS_TESTS_GL_RIG_H
#define PS_TESTS_GL_RIG_H

#include <GL/osmesa.h>
#include <stdlib.h>

#include "image/image.h"
#include "preview/session.h"
#include "scene/scene.h"

typedef struct gl_rig {
    ps_scene *scene;
    ps_session *s;
    OSMesaContext ctx;
    uint8_t *buffer;
    ps_camera_frame cam; /* the scene's camera at side x side */
} gl_rig;

/* The scene of `text`, and the window's kind of settings for it: float
 * layers refreshed incrementally, 2 tracing threads, seed 1. */
static inline ps_session_settings gl_rig_load(gl_rig *g, const char *text, const char *name)
{
    ps_error err;
    if (ps_scene_load_text(text, name, "", NULL, &g->scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_session_settings set = ps_session_default_settings(g->scene);
    set.threads = 2;
    set.seed = 1;
    set.float_buffer = true;
    set.incremental = true;
    return set;
}

/* The session of `set`, nothing traced yet, and a current context whose
 * buffer is side x side. */
static inline void gl_rig_untraced(gl_rig *g, const ps_session_settings *set, int side)
{
    ps_error err;
    if (ps_session_create(g->scene, set, &g->s, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    g->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    assert_non_null(g->ctx);
    g->buffer = malloc(4 * (size_t)side * (size_t)side);
    assert_non_null(g->buffer);
    assert_true(OSMesaMakeCurrent(g->ctx, g->buffer, GL_UNSIGNED_BYTE, side, side));
    g->cam = ps_camera_frame_make(ps_scene_camera(g->scene), side, side);
}

/* The same, the session traced to its caps. */
static inline void gl_rig_start(gl_rig *g, const ps_session_settings *set, int side)
{
    gl_rig_untraced(g, set, side);
    ps_error err;
    if (ps_session_trace_all(g->s, &err) != PS_OK)
        fail_msg("trace: %s", err.msg);
}

static inline void gl_rig_close(gl_rig *g)
{
    OSMesaDestroyContext(g->ctx);
    free(g->buffer);
    ps_session_destroy(g->s);
    ps_scene_destroy(g->scene);
}

/* The mean of every channel of every pixel. */
static inline double gl_rig_image_mean(const ps_image *img)
{
    double sum = 0.0;
    size_t n = 3 * (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++)
        sum += img->rgb[i];
    return sum / (double)n;
}

#endif
