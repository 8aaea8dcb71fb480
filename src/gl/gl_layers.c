/* gl_layers.c: the layers the window keeps between refreshes, and their
 * composite shown with the display's encoding done by GL (gl_render.h). */
#include <stdlib.h>
#include <string.h>

#include "gl/gl_internal.h"



/* The direct layer, a layer a map, the global map's illumination maps
 * (--global-layer maps: redrawn whole when they change, beside the global
 * layer's lobe splats, which accumulate), the composite as linear floats
 * (read back by tests), and the composite encoded for display (sRGB, 8
 * bits). LAYER_ALBEDO_TEX: the visible surfaces' texture factor T
 * (gl_albedo.c), by which the composite multiplies every layer when the
 * scene has textures. */
enum {
    LAYER_DIRECT_TEX,
    LAYER_CAUSTIC_TEX,
    LAYER_GLOBAL_TEX,
    LAYER_IMAP_TEX,
    LAYER_FINAL_TEX,
    LAYER_SHOWN_TEX,
    LAYER_ALBEDO_TEX,
    LAYER_TEX_COUNT
};

struct ps_gl_layers {
    int width, height;
    /* The view the layers hold, in their lower left corner: width x height,
     * or fewer pixels for a moving camera's level of detail, which the
     * composite scales up (ps_session_frame.view). */
    int view_w, view_h;
    /* The corner each map's layer holds: the view's, or fewer pixels for a
     * layer drawn shrunk (ps_session_layer.shrink), into its own FBO whose
     * depth and stencil are the view's prepass taken down to that size
     * (shrunk_depth, made on first use: the window's moving camera only). */
    int map_w[PS_MAP_COUNT], map_h[PS_MAP_COUNT];
    GLuint shrunk_fbo[PS_MAP_COUNT], shrunk_depth;
    bool float_buffers;
    bool imap_drawn; /* LAYER_IMAP_TEX holds maps (else it is black and not composited) */
    GLuint tex[LAYER_TEX_COUNT], fbo[LAYER_TEX_COUNT], depth_stencil;
    /* Which layers hold their texels (view-sized; else a 1x1 stand-in of
     * the same format, see ps_gl_layers_create): the direct, map and shown
     * layers from the start, the others (layer_optional) when first drawn
     * into or reserved (ps_gl_layers_reserve). */
    bool made[LAYER_TEX_COUNT];
    bool albedo; /* LAYER_ALBEDO_TEX holds this view's T */
    GLuint extra_tex; /* the specular layer (gl_specular.c), times extra_gain */
    double extra_gain;
    ps_gl_bake bake[PS_MAP_COUNT]; /* each map's baked textures (preview/bake.h) */
    /* ps_gl_layers_view_ahead: the still view drawn ahead; the next
     * ps_gl_layers_draw's new view, when it is that one, is not drawn again.
     * Any other view, relight or splat drawn into the layers drops it. */
    ps_gl_ahead ahead;
};

/* The layers a session may never draw: the illumination maps' (only with
 * --global-layer maps), the linear composite (read back: snap's pictures,
 * the window's false colour), the texture factor (only where the scene has
 * textures). Each is a float texture of the view's size, which Mesa zeroes
 * when it is made: 4 MiB at 512^2, 32 MiB at 1920x1080. Made with the
 * others, they took the window's first picture (the default box at 512^2)
 * 40-50 ms longer. */
static bool layer_optional(int i) { return i == LAYER_IMAP_TEX || i == LAYER_FINAL_TEX || i == LAYER_ALBEDO_TEX; }

static GLint layer_format(const ps_gl_layers *l, int i, GLenum *type)
{
    /* The linear composite is always float; the shown one is sRGB-encoded
     * 8 bits, written through GL_FRAMEBUFFER_SRGB. */
    bool is_float = l->float_buffers || i == LAYER_FINAL_TEX || i == LAYER_ALBEDO_TEX;
    *type = is_float ? GL_FLOAT : GL_UNSIGNED_BYTE;
    return i == LAYER_SHOWN_TEX ? GL_SRGB8_ALPHA8 : is_float ? GL_RGBA32F : GL_RGBA8;
}

/* Layer i's texels at the view's size, black, if it has only its stand-in
 * yet (GL leaves a new texture's texels undefined). The bindings and the
 * scissor are kept. */
static void make_layer(ps_gl_layers *l, int i)
{
    if (l->made[i])
        return;
    GLint old_fbo = 0, old_tex = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &old_tex);
    GLenum type;
    GLint format = layer_format(l, i, &type);
    glBindTexture(GL_TEXTURE_2D, l->tex[i]);
    glTexImage2D(GL_TEXTURE_2D, 0, format, l->width, l->height, 0, GL_RGBA, type, NULL);
    glBindTexture(GL_TEXTURE_2D, (GLuint)old_tex);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[i]);
    GLboolean scissor = glIsEnabled(GL_SCISSOR_TEST);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    if (scissor)
        glEnable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    l->made[i] = true;
}

void ps_gl_layers_reserve(ps_gl_layers *l, const ps_gl_renderer *r, bool maps)
{
    if (maps)
        make_layer(l, LAYER_IMAP_TEX);
    if (ps_gl_has_albedo(r))
        make_layer(l, LAYER_ALBEDO_TEX);
}

size_t ps_gl_layers_bytes(const ps_gl_layers *l)
{
    size_t bytes = 0, pixels = (size_t)l->width * (size_t)l->height;
    for (int i = 0; i < LAYER_TEX_COUNT; i++) {
        GLenum type;
        if (l->made[i])
            bytes += pixels * (layer_format(l, i, &type) == GL_RGBA32F ? 4 * sizeof(float) : 4);
    }
    return bytes;
}

GLuint ps_gl_layers_depth_stencil(const ps_gl_layers *l) { return l->depth_stencil; }

void ps_gl_layers_size(const ps_gl_layers *l, int *width, int *height)
{
    *width = l->width;
    *height = l->height;
}

void ps_gl_layers_set_extra(ps_gl_layers *l, GLuint texture, double gain)
{
    l->extra_tex = texture;
    l->extra_gain = gain;
}

ps_status ps_gl_layers_create(int width, int height, bool float_buffers, ps_gl_layers **out, ps_error *err)
{
    *out = NULL;
    ps_gl_layers *l = calloc(1, sizeof *l);
    if (!l)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the GL layers");
    l->width = l->view_w = width;
    l->height = l->view_h = height;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        l->map_w[k] = width, l->map_h[k] = height;
    l->float_buffers = float_buffers;
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    /* One depth-stencil buffer for all: the prepass drawn once serves every
     * layer's depth test and stencil clipping. */
    glGenRenderbuffers(1, &l->depth_stencil);
    glBindRenderbuffer(GL_RENDERBUFFER, l->depth_stencil);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, width, height);
    glGenTextures(LAYER_TEX_COUNT, l->tex);
    glGenFramebuffers(LAYER_TEX_COUNT, l->fbo);
    bool complete = true;
    for (int i = 0; i < LAYER_TEX_COUNT; i++) {
        glBindTexture(GL_TEXTURE_2D, l->tex[i]);
        /* An optional layer gets a 1x1 stand-in of its format for now, so
         * that its framebuffer's completeness (the format's support) is
         * known here; its texels come with make_layer (framebuffer objects
         * allow attachments of different sizes). */
        GLenum type;
        GLint format = layer_format(l, i, &type);
        l->made[i] = !layer_optional(i);
        glTexImage2D(GL_TEXTURE_2D, 0, format, l->made[i] ? width : 1, l->made[i] ? height : 1, 0, GL_RGBA, type,
                     NULL);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[i]);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, l->tex[i], 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, l->depth_stencil);
        complete = complete && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    if (!complete) {
        ps_gl_layers_destroy(l);
        return ps_error_set(err, PS_ERR_IO, "the GL implementation cannot render to %s and sRGB textures of %dx%d",
                            float_buffers ? "RGBA32F" : "RGBA8", width, height);
    }
    *out = l;
    return PS_OK;
}

void ps_gl_layers_destroy(ps_gl_layers *l)
{
    if (!l)
        return;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_gl_bake_reset(&l->bake[k]);
    glDeleteFramebuffers(LAYER_TEX_COUNT, l->fbo);
    glDeleteFramebuffers(PS_MAP_COUNT, l->shrunk_fbo);
    glDeleteTextures(LAYER_TEX_COUNT, l->tex);
    glDeleteRenderbuffers(1, &l->depth_stencil);
    glDeleteRenderbuffers(1, &l->shrunk_depth);
    free(l);
}

static void clear_imap(ps_gl_layers *l)
{
    l->imap_drawn = false;
    if (!l->made[LAYER_IMAP_TEX]) /* black when made */
        return;
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_IMAP_TEX]);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

/* Maps' colours added into their layer over the spans (gl_illummap.c). */
static void imap_pass(ps_gl_layers *l, ps_gl_renderer *r, const float *colors, const ps_illum_span *spans,
                      size_t span_count)
{
    make_layer(l, LAYER_IMAP_TEX);
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_IMAP_TEX]);
    glViewport(0, 0, l->view_w, l->view_h);
    ps_gl_draw_illummap(r, colors, spans, span_count);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

/* The illumination maps drawn again into their layer. */
static void draw_imap(ps_gl_layers *l, ps_gl_renderer *r, const ps_session_frame *f)
{
    clear_imap(l);
    if (!f->imap_colors)
        return;
    imap_pass(l, r, f->imap_colors, f->imap_spans, f->imap_span_count);
    l->imap_drawn = true;
}

void ps_gl_layers_prepare_maps(ps_gl_layers *l, ps_gl_renderer *r)
{
    /* The same state as draw_imap's, so the same programs; black with alpha
     * 0 adds nothing, whatever the blend. The default box's and the design
     * room's first float pictures with the maps came about 3 ms sooner
     * (docs/preview.md). */
    static const float black[3 * 4];
    static const ps_illum_span first = {0, 3};
    if (r->in.mesh->vertex_count >= 3)
        imap_pass(l, r, black, &first, 1);
}

/* ps_gl_layers_start's work beside the first round. */
typedef struct first_view {
    ps_gl_layers *l;
    ps_gl_renderer *r;
    ps_camera_frame cam;
    double exposure; /* the direct layer as the first refresh asks for it */
    bool direct;
    bool maps; /* the session has illumination maps */
} first_view;

static void first_view_draw(void *ctx)
{
    first_view *v = ctx;
    ps_gl_layers_view_ahead(v->l, v->r, &v->cam, v->exposure, v->direct);
}

static void first_view_spare(void *ctx)
{
    first_view *v = ctx;
    if (v->maps)
        ps_gl_layers_prepare_maps(v->l, v->r);
}

ps_status ps_gl_layers_start(ps_gl_layers *l, ps_gl_renderer *r, ps_session *s, const ps_camera_frame *cam,
                             ps_error *err)
{
    /* Asked before the start: the work beside the round must not call the
     * session (ps_session_start_beside). */
    first_view v = {l, r, *cam, 1.0, false, ps_session_illummap(s) != NULL};
    ps_session_direct_view(s, &v.exposure, &v.direct);
    return ps_session_start_beside(s, true, first_view_draw, first_view_spare, &v, err);
}

/* A new view, the direct layer's shadows as said; moving: a moving
 * camera's level of detail (no shadows, the moving mesh). */
static void new_view(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct,
                     bool shadows, bool moving)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    l->view_w = cam->width < l->width ? cam->width : l->width;
    l->view_h = cam->height < l->height ? cam->height : l->height;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        l->map_w[k] = l->view_w, l->map_h[k] = l->view_h;
    /* A level of detail clears only its corner (what the composite reads). */
    bool corner = l->view_w < l->width || l->view_h < l->height;
    if (corner) {
        glScissor(0, 0, l->view_w, l->view_h);
        glEnable(GL_SCISSOR_TEST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_DIRECT_TEX]);
    /* The direct layer's lit passes after the map layers' splats
     * (ps_gl_layers_draw): the layers are apart, so the order changes no
     * pixel, and llvmpipe rasterises the splats while the passes are
     * issued. The default box's and the area box's first float pictures at
     * 256^2 came 5-8 ms sooner (docs/preview.md). */
    ps_gl_begin_frame_shadows(r, cam, exposure, direct, shadows, moving || r->in.coarse_lights, true);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_gl_layers_clear_map(l, k);
    l->albedo = ps_gl_has_albedo(r);
    if (l->albedo) {
        make_layer(l, LAYER_ALBEDO_TEX);
        glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_ALBEDO_TEX]);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glClearColor(1, 1, 1, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        glClearColor(0, 0, 0, 0);
        ps_gl_draw_albedo(r);
    }
    clear_imap(l);
    if (corner)
        glDisable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

void ps_gl_layers_view(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct)
{
    l->ahead.held = false;
    new_view(l, r, cam, exposure, direct, r->opt.shadows, false);
    ps_gl_draw_deferred_lit(r); /* no splats to draw beside them here */
}

void ps_gl_layers_view_ahead(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure,
                             bool direct)
{
    new_view(l, r, cam, exposure, direct, r->opt.shadows, false);
    ps_gl_ahead_hold(&l->ahead, r, cam, exposure, direct);
}

void ps_gl_layers_relight(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct)
{
    /* Its pass redraws the shared depth prepass too, the same depths, so the
     * map layers' splats stay right. */
    l->ahead.held = false;
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_DIRECT_TEX]);
    ps_gl_begin_frame(r, cam, exposure, direct);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

void ps_gl_layers_clear_map(ps_gl_layers *l, int map)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_CAUSTIC_TEX + map]);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT); /* colour only: the shared depth is the view's */
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

/* Map k's layer drawn shrunk this view: its FBO (made on first use, with
 * the shared shrunk depth-stencil buffer), whether it could be made. */
static bool shrunk_fbo(ps_gl_layers *l, int k)
{
    if (l->shrunk_fbo[k])
        return true;
    if (!l->shrunk_depth) {
        glGenRenderbuffers(1, &l->shrunk_depth);
        glBindRenderbuffer(GL_RENDERBUFFER, l->shrunk_depth);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, l->width, l->height);
    }
    GLuint fbo;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, l->tex[LAYER_CAUSTIC_TEX + k], 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, l->shrunk_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        glDeleteFramebuffers(1, &fbo);
        return false;
    }
    l->shrunk_fbo[k] = fbo;
    return true;
}

/* After a new view: the map layers its frame asks to shrink get their
 * corner, and the prepass's depth and stencil, taken nearest, at that size.
 * A blit, 0.3 ms at 256^2 to 128^2, but llvmpipe builds its code on first
 * use, 0.04 s that the first moving frame pays: done once ahead (after the
 * first picture), later moving frames were slower, 49 against 43 ms over six
 * orbits each (not explained). The prepass drawn again at the fewer pixels
 * instead left dark pixels along the walls' edges (3 % of the full view's
 * global layer there). A layer whose FBO cannot be made keeps the view's
 * pixels. */
static void shrink_maps(ps_gl_layers *l, const ps_session_frame *f)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    int blitted_w = 0, blitted_h = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        int s = f->map[k].shrink;
        if (s <= 1 || !shrunk_fbo(l, k))
            continue;
        int w = (l->view_w + s - 1) / s, h = (l->view_h + s - 1) / s;
        if (w != blitted_w || h != blitted_h) {
            glBindFramebuffer(GL_READ_FRAMEBUFFER, l->fbo[LAYER_DIRECT_TEX]);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, l->shrunk_fbo[k]);
            glBlitFramebuffer(0, 0, l->view_w, l->view_h, 0, 0, w, h, GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT,
                              GL_NEAREST);
            blitted_w = w, blitted_h = h;
        }
        l->map_w[k] = w, l->map_h[k] = h;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

void ps_gl_layers_add(ps_gl_layers *l, ps_gl_renderer *r, int map, const ps_splat_batch *b, ps_splat_mode mode,
                      double radius, double point_size)
{
    l->ahead.held = false; /* the map no longer as a new view leaves it */
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    bool shrunk = l->map_w[map] < l->view_w || l->map_h[map] < l->view_h;
    glBindFramebuffer(GL_FRAMEBUFFER, shrunk ? l->shrunk_fbo[map] : l->fbo[LAYER_CAUSTIC_TEX + map]);
    glViewport(0, 0, l->map_w[map], l->map_h[map]);
    ps_gl_draw_splats(r, b, mode, radius, point_size);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

/* Map k's layer drawn from its baked textures (the layer cleared first). */
static void draw_baked(ps_gl_layers *l, ps_gl_renderer *r, int k, ps_vec3 eye)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_CAUSTIC_TEX + k]);
    glViewport(0, 0, l->map_w[k], l->map_h[k]);
    ps_gl_bake_draw(&l->bake[k], r, eye);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

/* The bound texture sampled texel for texel (the view fills the layers),
 * or bilinearly (a level of detail scaled up). */
static void set_filter(bool scaled)
{
    GLint f = scaled ? GL_LINEAR : GL_NEAREST;
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, f);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, f);
}

/* Where the composite reads the layers: the view's corner, texel for texel
 * into a target of its size, or scaled up into a bigger one from its first
 * texel's centre to its last one's, so that the bilinear filter never
 * reads past it. */
typedef struct view_read {
    bool scaled;
    float s0, t0, s1, t1;
} view_read;

static view_read read_corner(const ps_gl_layers *l, int w, int h, int target_w, int target_h)
{
    view_read v = {false, 0.0f, 0.0f, (float)w / (float)l->width, (float)h / (float)l->height};
    if (target_w != w || target_h != h) {
        v.scaled = true;
        v.s0 = 0.5f / (float)l->width, v.s1 = ((float)w - 0.5f) / (float)l->width;
        v.t0 = 0.5f / (float)l->height, v.t1 = ((float)h - 0.5f) / (float)l->height;
    }
    return v;
}

static view_read read_view(const ps_gl_layers *l, int target_w, int target_h)
{
    return read_corner(l, l->view_w, l->view_h, target_w, target_h);
}

/* A quad over the viewport of texture t times gain, added to what is there
 * (times texture unit 1's, the T layer, when that is enabled), t read as v
 * says and the T layer as w does (the view's corner: v reads a shrunk
 * layer's smaller one). */
static void add_texture(const view_read *v, const view_read *w, GLuint t, double gain)
{
    glBindTexture(GL_TEXTURE_2D, t);
    set_filter(v->scaled);
    glColor4f((GLfloat)gain, (GLfloat)gain, (GLfloat)gain, 1.0f);
    glBegin(GL_QUADS);
    glMultiTexCoord2f(GL_TEXTURE1, w->s0, w->t0), glTexCoord2f(v->s0, v->t0), glVertex2f(-1, -1);
    glMultiTexCoord2f(GL_TEXTURE1, w->s1, w->t0), glTexCoord2f(v->s1, v->t0), glVertex2f(1, -1);
    glMultiTexCoord2f(GL_TEXTURE1, w->s1, w->t1), glTexCoord2f(v->s1, v->t1), glVertex2f(1, 1);
    glMultiTexCoord2f(GL_TEXTURE1, w->s0, w->t1), glTexCoord2f(v->s0, v->t1), glVertex2f(-1, 1);
    glEnd();
}

void ps_gl_layers_draw(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, const ps_session_frame *f)
{
    if (f->view.width > 0) /* the refresh's view: the camera's, or its level of detail */
        cam = &f->view;
    if (f->new_view) {
        /* While the camera moves, the direct layer's level of detail: no
         * shadow passes (one pass a light instead of one a lit cube face,
         * most of a moving frame's time); they come back with the full view
         * when the camera stops. An edit's level of detail keeps them: the
         * edit may be what they show. The moving camera's passes light the
         * moving mesh (a quarter of the fine one's vertices on flat faces). */
        bool moving = f->moving && !f->edit_lod;
        if (!ps_gl_ahead_is(&l->ahead, r, cam, f))
            new_view(l, r, cam, f->direct_exposure, f->direct, r->opt.shadows && !moving, moving);
        shrink_maps(l, f);
    } else if (f->lights_changed) {
        ps_gl_layers_relight(l, r, cam, f->direct_exposure, f->direct);
    }
    l->ahead.held = false;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        const ps_session_layer *m = &f->map[k];
        if (m->bake_reset)
            ps_gl_bake_reset(&l->bake[k]);
        if (m->bake)
            ps_gl_bake_lay(&l->bake[k], r, m->bake);
        if (m->clear)
            ps_gl_layers_clear_map(l, k);
        if (m->baked)
            draw_baked(l, r, k, cam->eye);
        ps_gl_layers_add(l, r, k, m->batch, f->splat, m->radius, f->point_size);
    }
    if (f->imap_colors ? f->imap_redraw || !l->imap_drawn : l->imap_drawn)
        draw_imap(l, r, f);
    /* The new view's lit passes, or those of the view drawn ahead, behind
     * what was drawn above (new_view). */
    ps_gl_draw_deferred_lit(r);
}

/* direct * direct_gain + sum of map * map_gain into layer `target`, its
 * lower left target_w x target_h pixels. */
static void composite(ps_gl_layers *l, int target, int target_w, int target_h, double direct_gain,
                      const double map_gain[PS_MAP_COUNT])
{
    view_read v = read_view(l, target_w, target_h);
    make_layer(l, target);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[target]);
    glViewport(0, 0, target_w, target_h);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0, 0, 0, 0);
    /* Only the corner written (what the blit reads). */
    bool corner = target_w < l->width || target_h < l->height;
    if (corner) {
        glScissor(0, 0, target_w, target_h);
        glEnable(GL_SCISSOR_TEST);
    }
    glClear(GL_COLOR_BUFFER_BIT);
    if (corner)
        glDisable(GL_SCISSOR_TEST);
    /* Gains above 1 (N/n early on) must not clamp on the way. */
    ps_gl_unclamp_colour();
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_LIGHTING);
    glEnable(GL_TEXTURE_2D);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    /* Into the sRGB texture the blend adds in linear and the store encodes:
     * the sum of the layers, clamped to [0, 1], as sRGB codes. */
    if (target == LAYER_SHOWN_TEX)
        glEnable(GL_FRAMEBUFFER_SRGB);
    if (l->albedo) {
        /* Every layer times T, before the sum (which an 8-bit target clamps). */
        glActiveTexture(GL_TEXTURE1);
        glEnable(GL_TEXTURE_2D);
        glBindTexture(GL_TEXTURE_2D, l->tex[LAYER_ALBEDO_TEX]);
        set_filter(v.scaled);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        glActiveTexture(GL_TEXTURE0);
    }
    add_texture(&v, &v, l->tex[LAYER_DIRECT_TEX], direct_gain);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        view_read m = read_corner(l, l->map_w[k], l->map_h[k], target_w, target_h);
        if (map_gain[k] > 0.0)
            add_texture(&m, &v, l->tex[LAYER_CAUSTIC_TEX + k], map_gain[k]);
    }
    if (l->imap_drawn && map_gain[PS_MAP_GLOBAL] > 0.0)
        add_texture(&v, &v, l->tex[LAYER_IMAP_TEX], map_gain[PS_MAP_GLOBAL]);
    if (l->albedo) {
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, 0);
        glDisable(GL_TEXTURE_2D);
        glActiveTexture(GL_TEXTURE0);
    }
    if (l->extra_tex && l->extra_gain > 0.0)
        add_texture(&v, &v, l->extra_tex, l->extra_gain);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glDisable(GL_BLEND);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_TEXTURE_2D);
}

void ps_gl_layers_show(ps_gl_layers *l, double direct_gain, const double map_gain[PS_MAP_COUNT])
{
    /* At the view's size: a level of detail is scaled up by the blit (a
     * quarter of the composite's fill, which took 20 ms at 512^2). */
    composite(l, LAYER_SHOWN_TEX, l->view_w, l->view_h, direct_gain, map_gain);
    /* Copied as stored: with GL_FRAMEBUFFER_SRGB off a blit neither decodes
     * the sRGB source nor encodes again (a scaled one filters the codes:
     * the moving picture only). */
    bool scaled = l->view_w != l->width || l->view_h != l->height;
    if (scaled) {
        /* The scaled blit's bilinear filter reads half a texel past the
         * corner on its last column and row: they are repeated there (the
         * texture's own edge clamp, moved to the corner's edge), not the
         * older picture the texture holds beyond it. */
        glBindFramebuffer(GL_READ_FRAMEBUFFER, l->fbo[LAYER_SHOWN_TEX]);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, l->fbo[LAYER_SHOWN_TEX]);
        int w = l->view_w, h = l->view_h;
        if (w < l->width)
            glBlitFramebuffer(w - 1, 0, w, h, w, 0, w + 1, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        if (h < l->height)
            glBlitFramebuffer(0, h - 1, w + (w < l->width), h, 0, h, w + (w < l->width), h + 1, GL_COLOR_BUFFER_BIT,
                              GL_NEAREST);
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, l->fbo[LAYER_SHOWN_TEX]);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, l->view_w, l->view_h, 0, 0, l->width, l->height, GL_COLOR_BUFFER_BIT,
                      scaled ? GL_LINEAR : GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void ps_gl_layers_warm_up(ps_gl_layers *l)
{
    /* What the scaled show draws, drawn once: llvmpipe builds a variant of
     * its blit for the bilinear scale on first use, 0.06-0.07 s at 512^2,
     * which the first edit's level of detail (or the first orbit step) paid
     * on top of its own time. The layers are only read; the shown texture
     * and the back buffer are drawn over by the next show. */
    int w = l->view_w, h = l->view_h;
    l->view_w = l->width > 1 ? l->width / 2 : 1;
    l->view_h = l->height > 1 ? l->height / 2 : 1;
    double gains[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++)
        gains[k] = 1.0;
    ps_gl_layers_show(l, 1.0, gains);
    glFinish();
    l->view_w = w, l->view_h = h;
}

ps_status ps_gl_layers_composite(ps_gl_layers *l, double direct_gain, const double map_gain[PS_MAP_COUNT],
                                 ps_image *out, ps_error *err)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    composite(l, LAYER_FINAL_TEX, l->width, l->height, direct_gain, map_gain);
    ps_status st = ps_gl_read_pixels(l->width, l->height, out, err);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    return st;
}

void ps_gl_show_rgb8(int width, int height, const uint8_t *rgb)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width, height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_BLEND);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glWindowPos2i(0, 0);
    glDrawPixels(width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb);
}

ps_status ps_gl_layers_show_by_cpu(ps_gl_layers *l, double direct_gain, const double map_gain[PS_MAP_COUNT],
                                   ps_error *err)
{
    ps_image img;
    ps_status st = ps_gl_layers_composite(l, direct_gain, map_gain, &img, err);
    uint8_t *rgb = st == PS_OK ? malloc(3 * (size_t)l->width * (size_t)l->height) : NULL;
    if (st == PS_OK && !rgb)
        st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for a %dx%d picture", l->width, l->height);
    if (st == PS_OK) {
        for (int y = 0; y < l->height; y++) {
            const float *src = ps_image_at(&img, 0, l->height - 1 - y);
            uint8_t *dst = rgb + 3 * (size_t)y * (size_t)l->width;
            for (int i = 0; i < 3 * l->width; i++)
                dst[i] = ps_tonemap_8bit(src[i], 1.0f);
        }
        ps_gl_show_rgb8(l->width, l->height, rgb);
    }
    free(rgb);
    ps_image_destroy(&img);
    return st;
}
