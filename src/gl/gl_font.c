/* gl_font.c: the built-in 5x7 font, drawn with glBitmap, and the overlay state set-up. */
#include "gl/gl_font.h"

#include <stddef.h>

#include "gl/gl_api.h"
#include "image/glyphs.h"

/* The glyphs are the one GL-free table in src/image/glyphs.c, which the
 * false-colour legends of image files draw with too. */
const unsigned char *ps_gl_font_glyph(int c) { return ps_glyph(c); }

void ps_gl_overlay_begin(int width, int height)
{
    /* Save everything changed below on GL's own stacks, so that no state of
     * ours lives between begin and end. GL_CURRENT_BIT covers the colour and
     * the raster position that drawing moves. */
    glPushAttrib(GL_ENABLE_BIT | GL_COLOR_BUFFER_BIT | GL_CURRENT_BIT | GL_TRANSFORM_BIT | GL_VIEWPORT_BIT |
                 GL_POLYGON_BIT);

    /* Everything that would alter, hide or cull an overlay fragment: the
     * scene pass leaves depth test, lighting, shadow-map texturing, stencil
     * and clip planes on, and glBitmap fragments are textured, fogged and
     * tested like any other. */
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_LIGHTING);
    glDisable(GL_FOG);
    glDisable(GL_ALPHA_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_CULL_FACE); /* the y flip below turns the rectangle's winding clockwise */
    glDisable(GL_COLOR_LOGIC_OP);
    glDisable(GL_COLOR_SUM);
    glDisable(GL_POLYGON_STIPPLE);
    glDisable(GL_POLYGON_SMOOTH);
    glDisable(GL_DITHER); /* text pixels come out exactly the glColor */
    GLint planes = 0;
    glGetIntegerv(GL_MAX_CLIP_PLANES, &planes);
    for (GLint i = 0; i < planes; i++)
        glDisable((GLenum)(GL_CLIP_PLANE0 + i));
    /* Texturing on every fixed-function unit: GL_ENABLE_BIT saves the
     * enables of all units, and the active unit is put back here, so end has
     * nothing more to undo. */
    GLint active = GL_TEXTURE0, units = 1;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    glGetIntegerv(GL_MAX_TEXTURE_UNITS, &units);
    for (GLint i = 0; i < units; i++) {
        glActiveTexture((GLenum)(GL_TEXTURE0 + i));
        glDisable(GL_TEXTURE_1D);
        glDisable(GL_TEXTURE_2D);
        glDisable(GL_TEXTURE_3D);
        glDisable(GL_TEXTURE_CUBE_MAP);
    }
    glActiveTexture((GLenum)active);

    /* Plain alpha blending, whatever the splat passes left (additive). */
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE); /* the depth prepass masks colour */
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);

    /* Pixel coordinates, y down: pixel (x, y) spans [x, x+1] x [y, y+1], so
     * integer rectangles cover whole pixels. */
    glViewport(0, 0, width, height);
    glMatrixMode(GL_PROJECTION);
    glPushMatrix();
    glLoadIdentity();
    glOrtho(0.0, (double)width, (double)height, 0.0, -1.0, 1.0);
    glMatrixMode(GL_MODELVIEW);
    glPushMatrix();
    glLoadIdentity();
}

void ps_gl_overlay_end(void)
{
    glMatrixMode(GL_PROJECTION);
    glPopMatrix();
    glMatrixMode(GL_MODELVIEW);
    glPopMatrix();
    glPopAttrib(); /* also the matrix mode, saved with GL_TRANSFORM_BIT */
    /* Mesa (22.3, OSMesa) queues glBitmap glyphs in a cache and crashes if a
     * context is destroyed while current with the cache unflushed; the
     * overlay is the last thing in a frame, so flushing here costs nothing
     * that the swap or read-back would not. */
    glFlush();
}

/* One glyph at the current raster position, which glBitmap then moves one
 * cell to the right. */
static void draw_glyph(int c)
{
    /* glBitmap wants the bottom row first, MSB the leftmost pixel. */
    const unsigned char *rows = ps_gl_font_glyph(c);
    GLubyte bits[PS_FONT_GLYPH_H];
    for (int r = 0; r < PS_FONT_GLYPH_H; r++)
        bits[r] = (GLubyte)(rows[PS_FONT_GLYPH_H - 1 - r] << (8 - PS_FONT_GLYPH_W));
    glBitmap(PS_FONT_GLYPH_W, PS_FONT_GLYPH_H, 0.0f, 0.0f, (GLfloat)PS_FONT_CELL_W, 0.0f, bits);
}

int ps_gl_text(int x, int y, const char *text)
{
    if (!text)
        return 0;
    /* glWindowPos is in window coordinates, bottom-up: offset by the
     * viewport (which overlay_begin set) and flip. */
    GLint vp[4];
    glGetIntegerv(GL_VIEWPORT, vp);
    glPushClientAttrib(GL_CLIENT_PIXEL_STORE_BIT);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1); /* one byte per glyph row, unpadded */
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
    glPixelStorei(GL_UNPACK_LSB_FIRST, GL_FALSE);

    int line = 0, col = 0, widest = 0;
    int line_start = 1;
    for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
        if (*p == '\n') {
            line++;
            col = 0;
            line_start = 1;
            continue;
        }
        if (line_start) {
            /* The raster position is the glyph's bottom-left pixel. Unlike
             * glRasterPos, glWindowPos stays valid off the window, so a line
             * that starts left of it still shows its visible part. It also
             * latches the current colour for glBitmap. */
            int top = y + line * PS_FONT_CELL_H;
            glWindowPos2i(vp[0] + x, vp[1] + vp[3] - top - PS_FONT_GLYPH_H);
            line_start = 0;
        }
        draw_glyph(*p);
        col++;
        if (col * PS_FONT_CELL_W > widest)
            widest = col * PS_FONT_CELL_W;
    }
    glPopClientAttrib();
    return widest;
}

int ps_gl_text_width(const char *text)
{
    if (!text)
        return 0;
    int col = 0, widest = 0;
    for (const char *p = text; *p; p++) {
        col = *p == '\n' ? 0 : col + 1;
        if (col > widest)
            widest = col;
    }
    return widest * PS_FONT_CELL_W;
}

int ps_gl_text_height(const char *text)
{
    if (!text || !*text)
        return 0;
    int lines = 1;
    for (const char *p = text; *p; p++)
        lines += *p == '\n';
    return lines * PS_FONT_CELL_H;
}

void ps_gl_overlay_rect(int x, int y, int w, int h, float r, float g, float b, float a)
{
    if (w <= 0 || h <= 0)
        return;
    glPushAttrib(GL_CURRENT_BIT); /* so that a text colour set before survives */
    glColor4f(r, g, b, a);
    glRectd((double)x, (double)y, (double)x + w, (double)y + h);
    glPopAttrib();
}

void ps_gl_overlay_panel(const char *text)
{
    const int pad = 4;
    ps_gl_overlay_rect(0, 0, ps_gl_text_width(text) + 2 * pad, ps_gl_text_height(text) + 2 * pad, 0, 0, 0, 0.6f);
    glColor3f(1.0f, 1.0f, 0.85f);
    ps_gl_text(pad, pad, text);
}
