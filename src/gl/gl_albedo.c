/* gl_albedo.c: map_Kd textures in the fixed-function preview (gl_internal.h).
 *
 * The photon splats carry power times the plain BRDF (Kd / pi): a photon
 * record knows its material, not where on the texture it landed. Textured
 * surfaces are therefore drawn, lit and splatted, with Kd, and what shows is
 * multiplied per pixel by T, the texture at the visible point (1 on untextured
 * surfaces): for a Lambertian surface Kd T / pi E, as the reference renders
 * it. (A glossy material's lobe is multiplied too, which the reference does
 * not do: an approximation of the preview's.) */
#include <stdlib.h>

#include "gl/gl_internal.h"
#include "scene/texture.h"

void ps_gl_albedo_free(ps_gl_renderer *r)
{
    if (r->albedo_count)
        glDeleteTextures((GLsizei)r->albedo_count, r->albedo_tex);
    free(r->albedo_tex);
    free(r->albedo_src);
    r->albedo_tex = NULL;
    r->albedo_src = NULL;
    r->albedo_count = 0;
}

ps_status ps_gl_albedo_sync(ps_gl_renderer *r, ps_error *err)
{
    size_t n = r->in.scene ? ps_scene_texture_count(r->in.scene) : 0;
    /* Edits make clones sharing the same textures: upload only new ones. */
    bool same = n == r->albedo_count;
    for (size_t k = 0; same && k < n; k++)
        same = r->albedo_src[k] == ps_scene_texture(r->in.scene, (uint32_t)k);
    if (same)
        return PS_OK;
    ps_gl_albedo_free(r);
    if (n == 0)
        return PS_OK;
    r->albedo_tex = calloc(n, sizeof *r->albedo_tex);
    r->albedo_src = calloc(n, sizeof *r->albedo_src);
    if (!r->albedo_tex || !r->albedo_src) {
        ps_gl_albedo_free(r);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for %zu textures", n);
    }
    r->albedo_count = n;
    glGenTextures((GLsizei)n, r->albedo_tex);
    GLint max_side = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_side);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (size_t k = 0; k < n; k++) {
        const ps_texture *t = ps_scene_texture(r->in.scene, (uint32_t)k);
        r->albedo_src[k] = t;
        glBindTexture(GL_TEXTURE_2D, r->albedo_tex[k]);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        /* Linear floats, top row first (the mesh's t = 1 - v says so). A
         * texture larger than GL takes stays white: Kd alone. */
        static const float white[3] = {1.0f, 1.0f, 1.0f};
        bool fits = ps_texture_width(t) <= max_side && ps_texture_height(t) <= max_side;
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, fits ? ps_texture_width(t) : 1, fits ? ps_texture_height(t) : 1, 0,
                     GL_RGB, GL_FLOAT, fits ? ps_texture_texels(t) : white);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    return PS_OK;
}

bool ps_gl_has_albedo(const ps_gl_renderer *r) { return r->albedo_count > 0; }

/* multiply: into what is there (dst = dst * T), else replacing it. */
static void draw(const ps_gl_renderer *r, bool multiply)
{
    const ps_preview_mesh *m = r->lit; /* the frame's lit surfaces: the same texture coordinates */
    if (!r->albedo_count || !m->texcoords)
        return;
    glDisable(GL_LIGHTING);
    if (multiply) {
        glEnable(GL_BLEND);
        glBlendFunc(GL_ZERO, GL_SRC_COLOR);
    } else {
        glDisable(GL_BLEND);
    }
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glColor4f(1.0f, 1.0f, 1.0f, 1.0f);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_TEXTURE_COORD_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, m->positions);
    glTexCoordPointer(2, GL_FLOAT, 0, m->texcoords);
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_mesh_range *rg = &m->ranges[i];
        uint32_t tex = r->in.materials[rg->material].texture;
        if (tex > 0 && tex <= r->albedo_count) {
            glEnable(GL_TEXTURE_2D);
            glBindTexture(GL_TEXTURE_2D, r->albedo_tex[tex - 1]);
        } else {
            glDisable(GL_TEXTURE_2D);
        }
        glDrawArrays(GL_TRIANGLES, (GLint)rg->first, (GLsizei)rg->count);
    }
    glDisableClientState(GL_TEXTURE_COORD_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
}

void ps_gl_draw_albedo(const ps_gl_renderer *r) { draw(r, false); }

void ps_gl_multiply_albedo(const ps_gl_renderer *r)
{
    if (!r->albedo_count)
        return;
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(r->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(r->view);
    glDisable(GL_STENCIL_TEST);
    draw(r, true);
}
