/* gl_illummap.c: the global layer's illumination maps (preview/illummap.h)
 * drawn in fixed function: the fine mesh with the maps' colours per vertex
 * (irradiance times albedo / pi times the gain, made GL-free by
 * ps_illummap_colors), Gouraud-interpolated, no lighting, added to what is
 * there where the depth prepass says the surface shows; only the surfaces
 * the maps hold (ps_illummap_spans). Two-sided surfaces
 * carry a value a side; the colours given are already the side each
 * triangle shows this view (ps_illummap_view_colors), so one pass draws both. */
#include "gl/gl_internal.h"

void ps_gl_draw_illummap(ps_gl_renderer *r, const float *colors, const ps_illum_span *spans, size_t span_count)
{
    const ps_preview_mesh *m = r->in.mesh;
    if (!colors || span_count == 0)
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
    /* Only the surfaces in the maps: mirrors and glass would add black, and
     * took 41 % of the default box's pass. */
    for (size_t i = 0; i < span_count; i++)
        glDrawArrays(GL_TRIANGLES, (GLint)spans[i].first, (GLsizei)spans[i].count);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glDisable(GL_BLEND);
}
