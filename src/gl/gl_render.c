/* gl_render.c: the renderer, the mesh and the frame in fixed-function GL (gl_render.h). */
#include "gl/gl_internal.h"

#include "core/clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


/* The camera's near plane: never nearer than this fraction of its far plane,
 * which keeps 24-bit depth fine enough for the depth prepass and the splats. */
#define CAMERA_DEPTH_RATIO 4096.0
/* The depth prepass is pushed back so that later passes of the same surface
 * pass GL_LEQUAL even where a clip plane re-rasterises it (glPolygonOffset's
 * factor and units). */
#define PREPASS_OFFSET 1.0f
/* Blinn's (n.h)^s is about Phong's cos^e(alpha) when s = 4e; GL caps s at 128. */
#define BLINN_PER_PHONG 4.0
#define GL_MAX_SHININESS 128.0

/* ---- matrices (column-major, as GL) --------------------------------------- */

static void mat_identity(double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = m[15] = 1.0;
}

void ps_gl_mat_mul(const double a[16], const double b[16], double out[16])
{
    double r[16];
    for (int c = 0; c < 4; c++)
        for (int rr = 0; rr < 4; rr++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += a[k * 4 + rr] * b[c * 4 + k];
            r[c * 4 + rr] = s;
        }
    memcpy(out, r, sizeof r);
}

void ps_gl_mat_look(ps_vec3 eye, ps_vec3 forward, ps_vec3 right, ps_vec3 up, double m[16])
{
    mat_identity(m);
    m[0] = right.x, m[4] = right.y, m[8] = right.z, m[12] = -ps_v3_dot(right, eye);
    m[1] = up.x, m[5] = up.y, m[9] = up.z, m[13] = -ps_v3_dot(up, eye);
    m[2] = -forward.x, m[6] = -forward.y, m[10] = -forward.z, m[14] = ps_v3_dot(forward, eye);
}

void ps_gl_mat_perspective(double tan_half, double aspect, double znear, double zfar, double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    double f = 1.0 / tan_half;
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (zfar + znear) / (znear - zfar);
    m[11] = -1.0;
    m[14] = 2.0 * zfar * znear / (znear - zfar);
}

void ps_gl_box_range(ps_aabb b, ps_vec3 p, double *nearest, double *farthest)
{
    double n2 = 0.0, f2 = 0.0;
    for (int a = 0; a < 3; a++) {
        double v = ps_v3_get(p, a), lo = ps_v3_get(b.lo, a), hi = ps_v3_get(b.hi, a);
        double d = v < lo ? lo - v : v > hi ? v - hi : 0.0;
        double far = fmax(fabs(v - lo), fabs(v - hi));
        n2 += d * d;
        f2 += far * far;
    }
    *nearest = sqrt(n2);
    *farthest = sqrt(f2);
}

/* ---- drawing the mesh ----------------------------------------------------- */

/* A range is culled only when it lies this far (relative to the plane's
 * terms' sizes) on the clipped side: float positions and GL's float clip
 * test stay far inside it. */
#define MESH_CULL_MARGIN 1e-5

/* Whether box b lies wholly where plane p clips (a x + b y + c z + d < 0 at
 * every corner), by a margin over the float rounding of the positions and
 * of GL's own evaluation. */
static bool box_clipped(ps_aabb b, const double p[4])
{
    double most = p[3], size = fabs(p[3]);
    const double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    for (int a = 0; a < 3; a++) {
        most += p[a] * (p[a] > 0.0 ? hi[a] : lo[a]);
        size += fabs(p[a]) * fmax(fabs(lo[a]), fabs(hi[a]));
    }
    return most < -MESH_CULL_MARGIN * size;
}

static void draw_ranges(const ps_gl_renderer *r, bool with_materials, bool stencil, const double (*planes)[4],
                        int plane_count, uint64_t *vertices)
{
    const ps_preview_mesh *m = with_materials ? r->lit : r->in.coarse;
    bool cull = planes && with_materials && r->range_bounds && r->range_bounds_of == m->positions &&
                !r->opt.whole_face_passes;
    /* Mirrors and glass add nothing to a lit pass (no diffuse or Phong
     * term below: their light is the specular layer's), which writes no
     * depth: left out, the same pixels. The default scene's two spheres
     * were 58 800 of the 143 070 vertices every lit pass drew. */
    bool skip_black = with_materials && !r->opt.whole_face_passes;
    glEnableClientState(GL_VERTEX_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, m->positions);
    if (with_materials) {
        glEnableClientState(GL_NORMAL_ARRAY);
        glNormalPointer(GL_FLOAT, 0, m->normals);
    }
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_mesh_range *rg = &m->ranges[i];
        if ((r->skip_specular || skip_black) && ps_material_is_specular(&r->in.materials[rg->material]))
            continue;
        /* Laying one quad's textures; or its direct light drawn from them. */
        if (with_materials && r->only_object != UINT32_MAX && rg->object != r->only_object)
            continue;
        if (with_materials && r->skip_baked && rg->object < r->direct_bake.objects &&
            r->direct_bake.object_baked[rg->object])
            continue;
        bool outside = false;
        for (int p = 0; cull && p < plane_count && !outside; p++)
            outside = box_clipped(r->range_bounds[i], planes[p]);
        if (outside)
            continue;
        if (with_materials) {
            const ps_material *mat = &r->in.materials[rg->material];
            GLfloat diffuse[4] = {0, 0, 0, 1}, specular[4] = {0, 0, 0, 1};
            GLfloat shininess = 0.0f;
            if (mat->type == PS_MAT_DIFFUSE || mat->type == PS_MAT_GLOSSY) {
                diffuse[0] = (GLfloat)(mat->albedo.r * PS_INV_PI);
                diffuse[1] = (GLfloat)(mat->albedo.g * PS_INV_PI);
                diffuse[2] = (GLfloat)(mat->albedo.b * PS_INV_PI);
            }
            if (mat->type == PS_MAT_GLOSSY) {
                /* The lobe GL draws: past the cap on s, a wider one (s / 4),
                 * normalised as that one, or it would carry (e + 2) / (32 + 2)
                 * times its energy (1.8x at the design room's e = 60). */
                double e = fmin(mat->exponent, GL_MAX_SHININESS / BLINN_PER_PHONG);
                double k = (e + 2.0) * 0.5 * PS_INV_PI;
                specular[0] = (GLfloat)(mat->specular.r * k);
                specular[1] = (GLfloat)(mat->specular.g * k);
                specular[2] = (GLfloat)(mat->specular.b * k);
                shininess = (GLfloat)fmin(BLINN_PER_PHONG * mat->exponent, GL_MAX_SHININESS);
            }
            glMaterialfv(GL_FRONT_AND_BACK, GL_DIFFUSE, diffuse);
            glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, specular);
            glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, shininess);
        }
        if (stencil)
            glStencilFunc(GL_ALWAYS, (GLint)ps_splat_stencil(rg->object), 0xff);
        if (cull && m->tiles.tile_count > 0) {
            /* Only its tiles in the pyramid, neighbours in one call. */
            const ps_mesh_tiling *t = &m->tiles;
            size_t run_first = 0, run_count = 0;
            for (size_t x = t->range_tiles[i]; x <= t->range_tiles[i + 1]; x++) {
                bool in = x < t->range_tiles[i + 1];
                for (int p = 0; in && p < plane_count; p++)
                    in = !box_clipped(t->tiles[x].bounds, planes[p]);
                if (in && run_count > 0 && t->tiles[x].first == run_first + run_count) {
                    run_count += t->tiles[x].count;
                    continue;
                }
                if (run_count > 0) {
                    glDrawElements(GL_TRIANGLES, (GLsizei)run_count, GL_UNSIGNED_INT, t->indices + run_first);
                    if (vertices)
                        *vertices += run_count;
                }
                run_first = in ? t->tiles[x].first : 0;
                run_count = in ? t->tiles[x].count : 0;
            }
            continue;
        }
        if (vertices)
            *vertices += rg->count;
        /* Shared vertices (mesh.h): each lit once, the same triangles. */
        if (m->shared)
            glDrawElements(GL_TRIANGLES, (GLsizei)rg->count, GL_UNSIGNED_INT, m->shared + rg->first);
        else
            glDrawArrays(GL_TRIANGLES, (GLint)rg->first, (GLsizei)rg->count);
    }
    glDisableClientState(GL_NORMAL_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
}

void ps_gl_draw_mesh(const ps_gl_renderer *r, bool with_materials, bool stencil)
{
    draw_ranges(r, with_materials, stencil, NULL, 0, NULL);
}

void ps_gl_draw_mesh_within(ps_gl_renderer *r, const double (*planes)[4], int plane_count)
{
    draw_ranges(r, true, false, planes, plane_count, &r->stats.light_vertices);
}

/* The fine mesh's range bounds, for ps_gl_draw_mesh_within. */
static void make_range_bounds(ps_gl_renderer *r)
{
    const ps_preview_mesh *m = r->in.mesh;
    free(r->range_bounds);
    r->range_bounds = NULL;
    r->range_bounds_of = NULL;
    if (!m || !m->positions || m->range_count == 0)
        return;
    r->range_bounds = malloc(m->range_count * sizeof *r->range_bounds);
    if (!r->range_bounds)
        return;
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_mesh_range *rg = &m->ranges[i];
        ps_aabb b = ps_aabb_empty();
        for (size_t j = rg->first; j < rg->first + rg->count; j++) {
            size_t v = m->shared ? m->shared[j] : j;
            const float *q = m->positions + 3 * v;
            b = ps_aabb_point(b, ps_v3(q[0], q[1], q[2]));
        }
        r->range_bounds[i] = b;
    }
    r->range_bounds_of = m->positions;
}

void ps_gl_begin_frame(ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct)
{
    ps_gl_begin_frame_shadows(r, cam, exposure, direct, r->opt.shadows, r->in.coarse_lights, false);
}

/* The lit passes after the prepass (ps_gl_begin_frame_shadows), or those a
 * view left (ps_gl_draw_deferred_lit): each light added, with shadows, over
 * the direct light's textures where they are laid. */
static void draw_lit(ps_gl_renderer *r, ps_vec3 eye, double exposure, bool shadows, bool baked)
{
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_LEQUAL);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    if (baked)
        ps_gl_direct_bake_draw(r, eye);
    /* With shadows where the textures have them: a moving frame's
     * other objects keep its level of detail (none). */
    r->skip_baked = baked;
    ps_gl_draw_direct(r, exposure, shadows);
    r->skip_baked = false;
    glDisable(GL_BLEND);
}

void ps_gl_begin_frame_shadows(ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct,
                               bool shadows, bool lod, bool defer_lit)
{
    /* A view whose lit passes wait (defer_lit): drawn now where this
     * view has another target (a cube face before the layers' splats),
     * dropped where it has theirs, which this view clears. */
    if (r->deferred.pending) {
        GLint fbo = 0;
        glGetIntegerv(GL_FRAMEBUFFER_BINDING, &fbo);
        if (fbo == r->deferred.fbo)
            r->deferred.pending = false;
        else
            ps_gl_draw_deferred_lit(r);
    }
    r->ahead.held = false; /* the framebuffer's view is this one from here on */
    r->lit = lod && r->in.moving ? r->in.moving : r->in.mesh;
    r->stats.views++;
    r->stats.light_passes = 0;
    r->stats.light_vertices = 0;
    if (direct && shadows && !r->shadows_valid)
        ps_gl_make_shadow_maps(r);
    /* The direct light of diffuse quads from their textures (bake_direct,
     * laid while the program waits: ps_gl_direct_bake_lay), drawn by every
     * view while they hold, moving ones with their shadows. */
    bool baked = direct && !r->direct_bake_off && ps_gl_direct_bake_ready(r, exposure);
    r->stats.direct_baked_last = baked;
    r->width = cam->width;
    r->height = cam->height;
    glViewport(0, 0, cam->width, cam->height);
    /* No clamping on the way, in any buffer: radiance is interpolated and
     * modulated (shadows, spot discs, IES tables) as it is, and only an 8-bit
     * buffer's store clamps it, once, as a display would; float targets (the
     * window's layers, the illuminance pass) keep it all. */
    ps_gl_unclamp_colour();
    glClearColor(0, 0, 0, 0);
    glClearDepth(1.0);
    /* glClear obeys the write masks, which the last frame's splats left off. */
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glStencilMask(0xff);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);

    double nearest, farthest;
    ps_gl_box_range(r->in.bounds, cam->eye, &nearest, &farthest);
    r->eye_extent = ps_v3_len(cam->eye) + farthest;
    double zfar = fmax(farthest * 1.01, 1e-300);
    double znear = fmax(nearest * 0.5, zfar / CAMERA_DEPTH_RATIO);
    ps_gl_mat_perspective(cam->tan_half_fov, cam->aspect, znear, zfar, r->proj);
    ps_gl_mat_look(cam->eye, cam->forward, cam->right, cam->up, r->view);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(r->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(r->view);

    /* Depth first, pushed back a little (see PREPASS_OFFSET). */
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(PREPASS_OFFSET, PREPASS_OFFSET);
    /* Each visible pixel keeps its object's stencil value, for clipping splats. */
    glEnable(GL_STENCIL_TEST);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    glStencilMask(0xff);
    ps_gl_draw_mesh(r, false, true);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    if (direct && defer_lit) {
        /* The lit passes later (ps_gl_draw_deferred_lit); the emitters now,
         * whose depth hides the splats behind them. */
        ps_gl_deferred_lit *d = &r->deferred;
        d->pending = true;
        GLint fbo = 0;
        glGetIntegerv(GL_FRAMEBUFFER_BINDING, &fbo);
        d->fbo = fbo;
        d->width = cam->width;
        d->height = cam->height;
        memcpy(d->proj, r->proj, sizeof d->proj);
        memcpy(d->view, r->view, sizeof d->view);
        d->eye_extent = r->eye_extent;
        d->lit = r->lit;
        d->eye = cam->eye;
        d->exposure = exposure;
        d->shadows = shadows;
        d->baked = baked;
        d->skip_specular = r->skip_specular;
        d->hide_emitters = r->in.hide_emitters;
        d->epoch = r->lit_epoch;
    } else if (direct) {
        draw_lit(r, cam->eye, exposure, shadows, baked); /* each light adds its pass on top */
    }
    ps_gl_draw_emitters(r, exposure, direct);
}

void ps_gl_draw_deferred_lit(ps_gl_renderer *r)
{
    ps_gl_deferred_lit *d = &r->deferred;
    if (!d->pending)
        return;
    d->pending = false;
    if (d->epoch != r->lit_epoch)
        return;
    GLint old_fbo = 0, old_box[4] = {0, 0, 0, 0};
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glGetIntegerv(GL_SCISSOR_BOX, old_box);
    GLboolean old_scissor = glIsEnabled(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)d->fbo);
    glViewport(0, 0, d->width, d->height);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(d->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(d->view);
    /* The state the view's own passes had after its prepass
     * (ps_gl_begin_frame_shadows), whatever was drawn since; the scissor
     * too, which a level of detail's view had on its corner (gl_layers.c). */
    glScissor(0, 0, d->width, d->height);
    glEnable(GL_SCISSOR_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    /* The view's own settings, where a cube face begun since (which draws
     * these first) has its own. */
    const ps_preview_mesh *lit = r->lit;
    double extent = r->eye_extent;
    bool skip_specular = r->skip_specular, hide_emitters = r->in.hide_emitters;
    r->lit = d->lit;
    r->eye_extent = d->eye_extent;
    r->skip_specular = d->skip_specular;
    r->in.hide_emitters = d->hide_emitters;
    draw_lit(r, d->eye, d->exposure, d->shadows, d->baked);
    ps_gl_draw_emitters_colour(r, d->exposure, true);
    r->lit = lit;
    r->eye_extent = extent;
    r->skip_specular = skip_specular;
    r->in.hide_emitters = hide_emitters;
    glScissor(old_box[0], old_box[1], old_box[2], old_box[3]);
    if (!old_scissor)
        glDisable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

void ps_gl_ahead_hold(ps_gl_ahead *a, const ps_gl_renderer *r, const ps_camera_frame *cam, double exposure,
                      bool direct)
{
    *a = (ps_gl_ahead){true, *cam, exposure, direct, r, r->lit_epoch, r->stats.direct_bakes};
}

bool ps_gl_ahead_is(const ps_gl_ahead *a, const ps_gl_renderer *r, const ps_camera_frame *cam,
                    const ps_session_frame *f)
{
    return a->held && !f->moving && a->renderer == r && a->epoch == r->lit_epoch &&
           a->bakes == r->stats.direct_bakes && a->exposure == f->direct_exposure && a->direct == f->direct &&
           ps_camera_frame_equal(&a->cam, cam);
}

void ps_gl_draw_view_ahead(ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct)
{
    ps_gl_begin_frame(r, cam, exposure, direct);
    ps_gl_ahead_hold(&r->ahead, r, cam, exposure, direct);
}

void ps_gl_draw_frame(ps_gl_renderer *r, const ps_camera_frame *cam, const ps_session_frame *f)
{
    ps_gl_draw_frame_timed(r, cam, f, NULL);
}

void ps_gl_draw_frame_timed(ps_gl_renderer *r, const ps_camera_frame *cam, const ps_session_frame *f,
                            double *splat_seconds)
{
    /* The view drawn ahead is used once: the splats go over it, and every
     * pass after it loads the camera's matrices itself (r->proj, r->view);
     * the viewport is set again in case a pass that restores its own moved it. */
    r->stats.drawn_ahead_last = ps_gl_ahead_is(&r->ahead, r, cam, f);
    if (r->stats.drawn_ahead_last) {
        r->ahead.held = false;
        glViewport(0, 0, cam->width, cam->height);
    } else {
        ps_gl_begin_frame(r, cam, f->direct_exposure, f->direct);
    }
    ps_gl_draw_illummap(r, f->imap_colors, f->imap_spans, f->imap_span_count);
    double t0 = 0.0;
    if (splat_seconds) {
        glFinish();
        t0 = ps_now_seconds();
    }
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (f->map[k].gain > 0.0)
            ps_gl_draw_splats(r, f->map[k].batch, f->splat, f->map[k].radius, f->point_size);
    if (splat_seconds) {
        glFinish();
        *splat_seconds = ps_now_seconds() - t0;
    }
    /* All of it (lit with Kd, splats with Kd) times the surfaces' textures. */
    ps_gl_multiply_albedo(r);
}

void ps_gl_finish(void) { glFinish(); }

ps_status ps_gl_read_pixels(int width, int height, ps_image *out, ps_error *err)
{
    ps_status st = ps_image_create(width, height, out, err);
    if (st != PS_OK)
        return st;
    float *rows = malloc(sizeof(float) * 3 * (size_t)width * (size_t)height);
    if (!rows) {
        ps_image_destroy(out);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory reading the picture back");
    }
    glFinish();
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGB, GL_FLOAT, rows);
    /* GL's row 0 is the bottom; ours the top. */
    for (int y = 0; y < height; y++)
        memcpy(ps_image_at(out, 0, y), rows + 3 * (size_t)(height - 1 - y) * (size_t)width,
               sizeof(float) * 3 * (size_t)width);
    free(rows);
    return PS_OK;
}

ps_status ps_gl_read(ps_gl_renderer *r, ps_image *out, ps_error *err)
{
    return ps_gl_read_pixels(r->width, r->height, out, err);
}

ps_gl_scene ps_gl_scene_of(const ps_session *s)
{
    ps_gl_scene in = {ps_session_mesh(s), ps_session_coarse_mesh(s), ps_session_materials(s), ps_session_lights(s),
                      ps_scene_bounds(ps_session_scene(s)), ps_session_illuminance(s), ps_session_scene(s),
                      ps_session_moving_mesh(s), ps_session_lights_coarse(s)};
    return in;
}

static void set_inputs(ps_gl_renderer *r, const ps_gl_scene *in)
{
    r->in = *in;
    r->lit_epoch++;
    r->lit = in->mesh;
    make_range_bounds(r);
    r->scene_diag = ps_v3_len(ps_aabb_diag(in->bounds));
    if (!(r->scene_diag > 0.0) || !isfinite(r->scene_diag))
        r->scene_diag = 1.0;
}

ps_status ps_gl_renderer_set_scene(ps_gl_renderer *r, const ps_gl_scene *in, ps_error *err)
{
    set_inputs(r, in);
    ps_status st = ps_gl_albedo_sync(r, err);
    return st != PS_OK ? st : ps_gl_lights_reset(r, err);
}

void ps_gl_renderer_set_kernel(ps_gl_renderer *r, const ps_kernel_texture *kernel) { ps_gl_upload_kernel(r, kernel); }

void ps_gl_renderer_set_materials(ps_gl_renderer *r, const ps_material *materials, bool hide_emitters)
{
    r->in.materials = materials;
    r->in.hide_emitters = hide_emitters;
    r->lit_epoch++;
}

ps_status ps_gl_renderer_create(const ps_gl_scene *in, const ps_kernel_texture *kernel, const ps_gl_options *o,
                                ps_gl_renderer **out, ps_error *err)
{
    *out = NULL;
    ps_gl_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the GL renderer");
    r->opt = *o;
    r->only_object = UINT32_MAX;
    r->shadow_size = o->shadow_size > 0 ? o->shadow_size : PS_GL_SHADOW_SIZE;
    ps_status st = ps_gl_renderer_set_scene(r, in, err);
    if (st != PS_OK) {
        ps_gl_renderer_destroy(r);
        return st;
    }
    glGenFramebuffers(1, &r->fbo);
    /* The colour clamps as every frame sets them (ps_gl_begin_frame_shadows),
     * before the first shadow maps: llvmpipe keys its programs on them, and
     * those maps, drawn under GL's defaults, loaded a program of their own
     * in every first picture. */
    ps_gl_unclamp_colour();
    ps_gl_timer_init(r);
    ps_gl_upload_kernel(r, kernel);
    ps_gl_make_spot_texture(r);
    *out = r;
    return PS_OK;
}

ps_gl_stats ps_gl_get_stats(ps_gl_renderer *r)
{
    ps_gl_settle_shadow_timing(r);
    return r->stats;
}

void ps_gl_renderer_destroy(ps_gl_renderer *r)
{
    if (!r)
        return;
    ps_gl_lights_free(r);
    ps_gl_albedo_free(r);
    ps_gl_direct_bake_free(r);
    free(r->range_bounds);
    if (r->fbo)
        glDeleteFramebuffers(1, &r->fbo);
    if (r->shadow_query)
        glDeleteQueries(1, &r->shadow_query);
    if (r->kernel_tex)
        glDeleteTextures(1, &r->kernel_tex);
    free(r);
}

void ps_gl_unclamp_colour(void)
{
    glClampColor(GL_CLAMP_VERTEX_COLOR, GL_FALSE);
    glClampColor(GL_CLAMP_FRAGMENT_COLOR, GL_FALSE);
    glClampColor(GL_CLAMP_READ_COLOR, GL_FALSE);
}

void ps_gl_begin_additive_pass(const ps_gl_renderer *r)
{
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(r->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(r->view);
    glDisable(GL_LIGHTING);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL); /* the prepass is pushed back */
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
}

void ps_gl_cube_linear_clamped(void)
{
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
}
