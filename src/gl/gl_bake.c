/* gl_bake.c: a map's splats laid into textures on its quads, and the
 * textures drawn into a view (preview/bake.h). Fixed function: an
 * orthographic projection of each quad's (u, v) onto its texture, and the
 * quads drawn textured where the prepass says they show. */
#include <stdlib.h>
#include <string.h>

#include "gl/gl_internal.h"

void ps_gl_bake_reset(ps_gl_bake *g)
{
    if (g->count) {
        glDeleteFramebuffers((GLsizei)g->count, g->fbo);
        glDeleteTextures((GLsizei)g->count, g->tex);
    }
    free(g->targets);
    free(g->tex);
    free(g->fbo);
    memset(g, 0, sizeof *g);
}

/* The plan's textures, cleared; false (and none) where memory or the GL
 * implementation refuses. The session cannot hear of it: the map's layer
 * then shows nothing of its textures. Only memory should fail here: baking
 * needs float layers, whose RGBA32F framebuffers ps_gl_layers_create has
 * already made (it refuses a GL without them). */
static bool make_textures(ps_gl_bake *g, const ps_bake *plan)
{
    size_t n = ps_bake_target_count(plan);
    g->targets = malloc(n * sizeof *g->targets);
    g->tex = calloc(n, sizeof *g->tex);
    g->fbo = calloc(n, sizeof *g->fbo);
    if (!g->targets || !g->tex || !g->fbo) {
        ps_gl_bake_reset(g);
        return false;
    }
    memcpy(g->targets, ps_bake_targets(plan), n * sizeof *g->targets);
    g->count = n;
    glGenTextures((GLsizei)n, g->tex);
    glGenFramebuffers((GLsizei)n, g->fbo);
    bool complete = true;
    for (size_t t = 0; t < n; t++)
        complete = ps_gl_float_target(g->tex[t], g->fbo[t], g->targets[t].width, g->targets[t].height) && complete;
    g->complete = complete;
    return complete;
}

bool ps_gl_float_target(GLuint tex, GLuint fbo, int width, int height)
{
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    return complete;
}

/* World to the quad's (u, v) and its normal offset, column-major: the rows
 * are the dual basis of (edge1, edge2) in its plane and the unit normal, so
 * that corner + u edge1 + v edge2 goes to (u, v, 0) for any parallelogram. */
static void quad_matrix(const ps_bake_target *t, double m[16])
{
    ps_vec3 e1 = t->edge1, e2 = t->edge2;
    double a = ps_v3_dot(e1, e1), b = ps_v3_dot(e1, e2), c = ps_v3_dot(e2, e2), det = a * c - b * b;
    ps_vec3 d1 = ps_v3_scale(ps_v3_sub(ps_v3_scale(e1, c), ps_v3_scale(e2, b)), 1.0 / det);
    ps_vec3 d2 = ps_v3_scale(ps_v3_sub(ps_v3_scale(e2, a), ps_v3_scale(e1, b)), 1.0 / det);
    ps_vec3 n = ps_v3_norm(ps_v3_cross(e1, e2));
    const ps_vec3 rows[3] = {d1, d2, n};
    memset(m, 0, 16 * sizeof *m);
    for (int i = 0; i < 3; i++) {
        m[i] = rows[i].x, m[4 + i] = rows[i].y, m[8 + i] = rows[i].z;
        m[12 + i] = -ps_v3_dot(rows[i], t->corner);
    }
    m[15] = 1.0;
}

void ps_gl_bake_lay(ps_gl_bake *g, ps_gl_renderer *r, const ps_bake *plan)
{
    if (ps_bake_splats(plan) == 0)
        return;
    /* The caller's framebuffer, before making the textures binds theirs. */
    GLint old_fbo = 0, vp[4];
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    bool made = g->count > 0 || make_textures(g, plan);
    if (!made || !g->complete || g->count != ps_bake_target_count(plan)) {
        glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
        return;
    }
    glGetIntegerv(GL_VIEWPORT, vp);
    /* Every splat lies in its quad's plane: no depth, no clipping but the
     * texture's edges (the quad's), the kernel texture's alpha summed. */
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_LIGHTING);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE);
    glEnable(GL_TEXTURE_2D);
    glBindTexture(GL_TEXTURE_2D, r->kernel_tex);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glOrtho(0.0, 1.0, 0.0, 1.0, -1.0, 1.0);
    glMatrixMode(GL_MODELVIEW);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glEnableClientState(GL_TEXTURE_COORD_ARRAY);
    for (size_t t = 0; t < g->count; t++) {
        const ps_splat_batch *b = ps_bake_batch(plan, t);
        if (b->vertex_count == 0)
            continue;
        double m[16];
        quad_matrix(&g->targets[t], m);
        glLoadMatrixd(m);
        glBindFramebuffer(GL_FRAMEBUFFER, g->fbo[t]);
        glViewport(0, 0, g->targets[t].width, g->targets[t].height);
        glVertexPointer(3, GL_FLOAT, 0, b->positions);
        glColorPointer(4, GL_FLOAT, 0, b->colors);
        glTexCoordPointer(2, GL_FLOAT, 0, b->texcoords);
        glDrawArrays(GL_TRIANGLES, 0, (GLsizei)b->vertex_count);
    }
    glDisableClientState(GL_TEXTURE_COORD_ARRAY);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    glViewport(vp[0], vp[1], vp[2], vp[3]);
}

void ps_gl_bake_draw(const ps_gl_bake *g, const ps_gl_renderer *r, ps_vec3 eye)
{
    if (g->count == 0 || !g->complete)
        return;
    ps_gl_begin_additive_pass(r);
    glBlendFunc(GL_ONE, GL_ONE);
    glEnable(GL_TEXTURE_2D);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_REPLACE);
    /* Pulled forward as the splats are (gl_splat.c), and only where the
     * quad's object shows (the prepass's stencil), as they are clipped. */
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(-1.0f, -1.0f);
    glEnable(GL_STENCIL_TEST);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    for (size_t i = 0; i < g->count; i++) {
        const ps_bake_target *t = &g->targets[i];
        double facing = ps_v3_dot(ps_v3_sub(eye, t->corner), ps_v3_cross(t->edge1, t->edge2));
        if (t->side == 0 ? !(facing > 0.0) : !(facing < 0.0))
            continue;
        glStencilFunc(GL_EQUAL, (GLint)ps_splat_stencil(t->object), 0xff);
        glBindTexture(GL_TEXTURE_2D, g->tex[i]);
        ps_vec3 c = t->corner, c1 = ps_v3_add(c, t->edge1), c12 = ps_v3_add(c1, t->edge2), c2 = ps_v3_add(c, t->edge2);
        glBegin(GL_QUADS);
        glTexCoord2f(0.0f, 0.0f), glVertex3d(c.x, c.y, c.z);
        glTexCoord2f(1.0f, 0.0f), glVertex3d(c1.x, c1.y, c1.z);
        glTexCoord2f(1.0f, 1.0f), glVertex3d(c12.x, c12.y, c12.z);
        glTexCoord2f(0.0f, 1.0f), glVertex3d(c2.x, c2.y, c2.z);
        glEnd();
    }
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_BLEND);
}
