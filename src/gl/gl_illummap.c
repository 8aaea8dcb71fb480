/* gl_illummap.c: the global layer's illumination maps (preview/illummap.h)
 * drawn in fixed function: the fine mesh with the maps' colours per vertex
 * (irradiance times albedo / pi times the gain, made GL-free by
 * ps_illummap_colors), Gouraud-interpolated, no lighting, added to what is
 * there where the depth prepass says the surface shows. Two-sided surfaces
 * carry a value a side; the colours given are already the side each
 * triangle shows this view (ps_illummap_view_colors), so one pass draws both. */
#include "gl/gl_internal.h"

void ps_gl_draw_illummap(ps_gl_renderer *r, const float *colors)
{
    const ps_preview_mesh *m = r->in.mesh;
    if (!colors || m->vertex_count == 0)
        return;
    ps_gl_begin_additive_pass(r);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_STENCIL_TEST);
    glBlendFunc(GL_ONE, GL_ONE);
    glShadeModel(GL_SMOOTH);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, m->positions);
    glColorPointer(4, GL_FLOAT, 0, colors);
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)m->vertex_count);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glDisable(GL_BLEND);
}
