/* gl_splat.c: photon splats drawn additively over the frame (gl_render.h):
 * glPoints, kernel-textured triangles in the surface's plane, or point
 * sprites, each clipped to its object's pixels by the stencil. */
#include "gl/gl_internal.h"

/* Triangle splats are pulled forward (thesis 4.2), in glPolygonOffset's
 * (factor, units). */
#define SPLAT_OFFSET -1.0f

/* The batch's primitives; grouped, each group only where its object shows
 * (the stencil test), else all at once. */
static void draw_groups(const ps_splat_batch *b, GLenum prim)
{
    if (!b->grouped) {
        glDrawArrays(prim, 0, (GLsizei)b->vertex_count);
        return;
    }
    glEnable(GL_STENCIL_TEST);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    for (int g = 0; g < PS_SPLAT_GROUPS; g++) {
        size_t first = b->group_first[g], n = b->group_first[g + 1] - first;
        if (n == 0)
            continue;
        if (g == 0)
            glStencilFunc(GL_ALWAYS, 0, 0xff);
        else
            glStencilFunc(GL_EQUAL, g, 0xff);
        glDrawArrays(prim, (GLint)first, (GLsizei)n);
    }
    glDisable(GL_STENCIL_TEST);
}

void ps_gl_draw_splats(ps_gl_renderer *r, const ps_splat_batch *b, ps_splat_mode mode, double radius,
                       double point_size)
{
    if (b->vertex_count == 0)
        return;
    ps_gl_begin_additive_pass(r);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, b->positions);
    glColorPointer(4, GL_FLOAT, 0, b->colors);
    if (mode == PS_SPLAT_POINTS) {
        glBlendFunc(GL_ONE, GL_ONE);
        glPointSize((GLfloat)point_size);
        draw_groups(b, GL_POINTS);
    } else {
        glEnable(GL_TEXTURE_2D);
        glBindTexture(GL_TEXTURE_2D, r->kernel_tex);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE);
        if (mode == PS_SPLAT_TRIANGLES) {
            glEnableClientState(GL_TEXTURE_COORD_ARRAY);
            glTexCoordPointer(2, GL_FLOAT, 0, b->texcoords);
            glEnable(GL_POLYGON_OFFSET_FILL);
            glPolygonOffset(SPLAT_OFFSET, SPLAT_OFFSET);
            draw_groups(b, GL_TRIANGLES);
            glDisable(GL_POLYGON_OFFSET_FILL);
            glDisableClientState(GL_TEXTURE_COORD_ARRAY);
        } else {
            /* Point sprites whose side is the kernel square's in pixels at
             * distance d: 2 extent r f / d, f the focal length in pixels
             * (GL_POINT_DISTANCE_ATTENUATION {0, 0, 1} divides by d). */
            double focal = 0.5 * r->height / (r->proj[5] > 0.0 ? 1.0 / r->proj[5] : 1.0);
            const GLfloat atten[3] = {0.0f, 0.0f, 1.0f};
            GLfloat range[2] = {1.0f, 64.0f};
            glGetFloatv(GL_ALIASED_POINT_SIZE_RANGE, range);
            glPointParameterfv(GL_POINT_DISTANCE_ATTENUATION, atten);
            glPointParameterf(GL_POINT_SIZE_MIN, 1.0f);
            glPointParameterf(GL_POINT_SIZE_MAX, range[1]);
            glEnable(GL_POINT_SPRITE);
            glTexEnvi(GL_POINT_SPRITE, GL_COORD_REPLACE, GL_TRUE);
            glPointSize((GLfloat)(2.0 * r->kernel_extent * radius * focal));
            draw_groups(b, GL_POINTS);
            glTexEnvi(GL_POINT_SPRITE, GL_COORD_REPLACE, GL_FALSE);
            glDisable(GL_POINT_SPRITE);
            const GLfloat none[3] = {1.0f, 0.0f, 0.0f};
            glPointParameterfv(GL_POINT_DISTANCE_ATTENUATION, none);
        }
        glBindTexture(GL_TEXTURE_2D, 0);
        glDisable(GL_TEXTURE_2D);
    }
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glDisable(GL_BLEND);
}

void ps_gl_upload_kernel(ps_gl_renderer *r, const ps_kernel_texture *k)
{
    r->kernel_extent = k->extent;
    if (!r->kernel_tex)
        glGenTextures(1, &r->kernel_tex);
    glBindTexture(GL_TEXTURE_2D, r->kernel_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_ALPHA8, k->size, k->size, 0, GL_ALPHA, GL_UNSIGNED_BYTE, k->alpha);
    /* A halftone only works sampled nearest: filtering would blend its 0 and
     * 255 texels into the fractions that round away (splat.h). */
    GLint filter = k->halftone ? GL_NEAREST : GL_LINEAR;
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
}

