/* gl_direct_bake.c: the direct light of diffuse quads laid into a texture
 * a quad side and drawn from them (gl_internal.h, preview/bake.h). The lay
 * is the view's own lit passes (ps_gl_draw_direct: each light's Gouraud
 * term times its shadow test, a pass a lit cube face), drawn for one quad
 * under an orthographic camera facing the side: GL lights, clip planes and
 * eye-linear texture coordinates are given in world coordinates and
 * carried by the modelview, which is rigid here (lighting is computed in eye
 * space), so each texel gets what a view's pixel at that point of the quad
 * gets. The quad's skew and scale are the projection's. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "gl/gl_internal.h"

/* How far the lay's eye stands off the quad, in quad sizes: its depth range
 * is half to one and a half of that (the quad is flat; nothing else is drawn). */
#define LAY_STANDOFF 1.0

void ps_gl_direct_bake_free(ps_gl_renderer *r)
{
    ps_gl_direct_bake *b = &r->direct_bake;
    if (b->count) {
        glDeleteFramebuffers((GLsizei)b->count, b->fbo);
        glDeleteTextures((GLsizei)b->count, b->tex);
    }
    free(b->targets);
    free(b->tex);
    free(b->fbo);
    free(b->flip);
    free(b->object_baked);
    memset(b, 0, sizeof *b);
}

/* The targets and their textures for the renderer's inputs; false where
 * there are none (no diffuse quad, too many texels, no memory, or a GL
 * that cannot render into them). */
static bool make_targets(ps_gl_renderer *r)
{
    ps_gl_direct_bake *b = &r->direct_bake;
    ps_error err;
    if (!r->in.scene || !r->in.materials ||
        ps_bake_direct_targets(r->in.scene, r->in.materials, &b->targets, &b->count, &err) != PS_OK || b->count == 0)
        return false;
    size_t nobj;
    ps_scene_objects(r->in.scene, &nobj);
    b->tex = calloc(b->count, sizeof *b->tex);
    b->fbo = calloc(b->count, sizeof *b->fbo);
    b->flip = calloc(b->count, sizeof *b->flip);
    b->object_baked = calloc(nobj ? nobj : 1, sizeof *b->object_baked);
    if (!b->tex || !b->fbo || !b->flip || !b->object_baked) {
        ps_gl_direct_bake_free(r);
        return false;
    }
    b->objects = nobj;
    glGenTextures((GLsizei)b->count, b->tex);
    glGenFramebuffers((GLsizei)b->count, b->fbo);
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    bool complete = true;
    for (size_t t = 0; t < b->count && complete; t++)
        complete = ps_gl_float_target(b->tex[t], b->fbo[t], b->targets[t].width, b->targets[t].height);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    if (!complete) {
        ps_gl_direct_bake_free(r);
        return false;
    }
    for (size_t t = 0; t < b->count; t++)
        b->object_baked[b->targets[t].object] = true;
    return true;
}

/* Target t's lay: a rigid modelview with the eye on its side, off the quad
 * along the side's normal, and a projection taking the quad's
 * corner + u edge1 + v edge2 to clip (2u - 1, +-(2v - 1)). The sign keeps
 * the map's determinant positive, so that GL sees each triangle wound as a
 * view from that side does (two-sided lighting lights the side it faces);
 * *flip: the rows then run against edge2. */
static void lay_matrices(const ps_bake_target *t, double view[16], double proj[16], ps_vec3 *eye, bool *flip)
{
    ps_vec3 n = ps_v3_norm(ps_v3_cross(t->edge1, t->edge2));
    ps_vec3 z = t->side == 0 ? n : ps_v3_neg(n), x = ps_v3_norm(t->edge1), y = ps_v3_cross(z, x);
    double len1 = ps_v3_len(t->edge1), a = ps_v3_dot(t->edge2, x), bb = ps_v3_dot(t->edge2, y);
    double size = len1 + ps_v3_len(t->edge2), standoff = LAY_STANDOFF * size;
    *eye = ps_v3_add(t->corner, ps_v3_scale(z, standoff));
    /* Eye coordinates: x, y, z axes, the eye at the origin (the corner at
     * (0, 0, -standoff)). */
    ps_gl_mat_look(*eye, ps_v3_neg(z), x, y, view);
    /* (xe, ye) = u (len1, 0) + v (a, bb): v = ye / bb, u = (xe - a v) / len1. */
    *flip = bb < 0.0;
    double sy = *flip ? -1.0 : 1.0;
    double zn = 0.5 * standoff, zf = 1.5 * standoff;
    memset(proj, 0, 16 * sizeof *proj);
    proj[0] = 2.0 / len1;                  /* clip x from xe */
    proj[4] = -2.0 * a / (bb * len1);      /* ... and ye */
    proj[5] = sy * 2.0 / bb;               /* clip y from ye */
    proj[10] = -2.0 / (zf - zn);           /* depth: -zn .. -zf to -1 .. 1 */
    proj[12] = -1.0;                       /* clip x at the corner */
    proj[13] = -sy;                        /* clip y at the corner */
    proj[14] = -(zf + zn) / (zf - zn);
    proj[15] = 1.0;
}

/* Whether what the textures were (or are being) laid for still stands. */
static bool current(const ps_gl_renderer *r, double exposure)
{
    const ps_gl_direct_bake *b = &r->direct_bake;
    return b->epoch == r->lit_epoch && b->exposure == exposure && b->shadows == r->opt.shadows;
}

bool ps_gl_direct_bake_ready(const ps_gl_renderer *r, double exposure)
{
    return r->opt.bake_direct && r->direct_bake.laid && current(r, exposure);
}

bool ps_gl_direct_bake_pending(const ps_gl_renderer *r, double exposure)
{
    const ps_gl_direct_bake *b = &r->direct_bake;
    return r->opt.bake_direct && exposure > 0.0 && !(current(r, exposure) && (b->laid || b->none));
}

/* Target t laid: the lit passes of its quad alone under its matrices. */
static void lay_target(ps_gl_renderer *r, size_t t, double exposure)
{
    ps_gl_direct_bake *b = &r->direct_bake;
    const ps_bake_target *q = &b->targets[t];
    double view[16], proj[16];
    ps_vec3 eye;
    lay_matrices(q, view, proj, &eye, &b->flip[t]);
    double nearest, farthest;
    ps_gl_box_range(r->in.bounds, eye, &nearest, &farthest);
    r->eye_extent = ps_v3_len(eye) + farthest;
    glBindFramebuffer(GL_FRAMEBUFFER, b->fbo[t]);
    glViewport(0, 0, q->width, q->height);
    glClear(GL_COLOR_BUFFER_BIT);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(view);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    /* The fine mesh, whatever the last frame lit (a moving one's is coarser). */
    const ps_preview_mesh *lit = r->lit;
    r->lit = r->in.mesh;
    r->only_object = q->object;
    ps_gl_draw_direct(r, exposure, r->opt.shadows);
    r->only_object = UINT32_MAX;
    r->lit = lit;
    glDisable(GL_BLEND);
}

/* What the textures are being laid for: what stands now. */
static void stamp(ps_gl_renderer *r, double exposure)
{
    ps_gl_direct_bake *b = &r->direct_bake;
    b->epoch = r->lit_epoch;
    b->exposure = exposure;
    b->shadows = r->opt.shadows;
}

bool ps_gl_direct_bake_lay(ps_gl_renderer *r, double exposure, double max_seconds)
{
    ps_gl_direct_bake *b = &r->direct_bake;
    if (!r->opt.bake_direct || !(exposure > 0.0) || (current(r, exposure) && (b->laid || b->none)))
        return false;
    /* The lights as they stand, every shadow map fresh (a frame makes them). */
    if (r->opt.shadows && !r->shadows_valid)
        return false;
    if (!current(r, exposure) || b->count == 0) {
        /* Begun again for what stands now; where nothing is to be laid, not
         * tried again until something changes. */
        ps_gl_direct_bake_free(r);
        bool made = make_targets(r);
        stamp(r, exposure);
        if (!made) {
            b->none = true;
            return false;
        }
    }
    double t0 = ps_now_seconds();
    /* Between two frames: what the last one left is left as it was (an
     * incremental refresh adds splats under its matrices and state). */
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glPushAttrib(GL_ALL_ATTRIB_BITS);
    glMatrixMode(GL_PROJECTION);
    glPushMatrix();
    glMatrixMode(GL_MODELVIEW);
    glPushMatrix();
    double old_extent = r->eye_extent;
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_SCISSOR_TEST);
    glDepthMask(GL_FALSE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    ps_gl_unclamp_colour();
    glClearColor(0, 0, 0, 0);
    /* A target at least, then as many as the time allows (each finished:
     * the time is the lay's, not queued for the next frame). */
    do {
        lay_target(r, b->next++, exposure);
        glFinish();
    } while (b->next < b->count && ps_now_seconds() - t0 < max_seconds);
    r->eye_extent = old_extent;
    glMatrixMode(GL_PROJECTION);
    glPopMatrix();
    glMatrixMode(GL_MODELVIEW);
    glPopMatrix();
    glPopAttrib();
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    if (b->next < b->count)
        return true;
    b->laid = true;
    r->stats.direct_bakes++;
    return false;
}

void ps_gl_direct_bake_draw(const ps_gl_renderer *r, ps_vec3 eye)
{
    const ps_gl_direct_bake *b = &r->direct_bake;
    glDisable(GL_LIGHTING);
    glEnable(GL_TEXTURE_2D);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_REPLACE);
    for (size_t i = 0; i < b->count; i++) {
        const ps_bake_target *t = &b->targets[i];
        double facing = ps_v3_dot(ps_v3_sub(eye, t->corner), ps_v3_cross(t->edge1, t->edge2));
        if (t->side == 0 ? !(facing > 0.0) : !(facing < 0.0))
            continue;
        glBindTexture(GL_TEXTURE_2D, b->tex[i]);
        float v0 = b->flip[i] ? 1.0f : 0.0f, v1 = 1.0f - v0;
        ps_vec3 c = t->corner, c1 = ps_v3_add(c, t->edge1), c12 = ps_v3_add(c1, t->edge2), c2 = ps_v3_add(c, t->edge2);
        glBegin(GL_QUADS);
        glTexCoord2f(0.0f, v0), glVertex3d(c.x, c.y, c.z);
        glTexCoord2f(1.0f, v0), glVertex3d(c1.x, c1.y, c1.z);
        glTexCoord2f(1.0f, v1), glVertex3d(c12.x, c12.y, c12.z);
        glTexCoord2f(0.0f, v1), glVertex3d(c2.x, c2.y, c2.z);
        glEnd();
    }
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_TEXTURE_2D);
}
