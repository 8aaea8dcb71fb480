/* gl_font.h: a built-in 5x7 bitmap font and overlay helpers (text, backdrop
 * rectangles) for on-screen read-outs drawn with fixed-function OpenGL.
 *
 * Glyphs are drawn with glBitmap at positions set by glWindowPos, so they work
 * on any GL from 1.4 (OSMesa/llvmpipe included) and a glyph that starts off
 * the window still draws its visible part: glRasterPos would mark the raster
 * position invalid there and drop the whole string.
 *
 * Coordinates are window pixels relative to the viewport, origin top-left, y
 * down. Each character occupies a PS_FONT_CELL_W x PS_FONT_CELL_H cell: the
 * PS_FONT_GLYPH_W x PS_FONT_GLYPH_H glyph at its top-left, then 1 px of
 * spacing to the right and a 2 px line gap below. Widths and heights count
 * whole cells, so text_width("ab") is 12, not 11.
 *
 * Call the drawing functions between ps_gl_overlay_begin and
 * ps_gl_overlay_end; the caller owns the context and must have made it
 * current. */
#ifndef PS_GL_GL_FONT_H
#define PS_GL_GL_FONT_H

#include "image/glyphs.h"

#define PS_FONT_GLYPH_W PS_GLYPH_W
#define PS_FONT_GLYPH_H PS_GLYPH_H
#define PS_FONT_CELL_W PS_GLYPH_CELL_W
#define PS_FONT_CELL_H PS_GLYPH_CELL_H

/* Sets up window-pixel coordinates (origin top-left, y down) for overlay
 * drawing over a width x height viewport at the window's origin, saving the GL
 * state it changes (viewport, projection/modelview matrices, depth test,
 * lighting, texturing, blending, stencil, clip planes, ...); ps_gl_overlay_end
 * restores it. Uses one level of the attribute, projection and modelview
 * stacks, so it does not nest. */
void ps_gl_overlay_begin(int width, int height);
void ps_gl_overlay_end(void);

/* Text at pixel (x, y) = top-left of the first cell, in the current glColor
 * (its alpha blends); '\n' starts a new line, any other byte outside 32..126
 * draws as a hollow box. Returns the width in pixels of the longest line.
 * NULL draws nothing and returns 0. */
int ps_gl_text(int x, int y, const char *text);
/* The longest line, in pixels (characters * PS_FONT_CELL_W). */
int ps_gl_text_width(const char *text);
/* Lines * PS_FONT_CELL_H: "" has no lines, otherwise one plus one per '\n'
 * (a trailing '\n' starts an empty line that counts). */
int ps_gl_text_height(const char *text);

/* A filled w x h rectangle with top-left (x, y) (a translucent backdrop
 * behind text), in colour rgba blended over what is there; leaves the current
 * glColor as it was. */
void ps_gl_overlay_rect(int x, int y, int w, int h, float r, float g, float b, float a);

/* The overlay's panel: text in pale yellow at the top-left corner over a
 * translucent black backdrop, 4 pixels of margin. Between begin and end. */
void ps_gl_overlay_panel(const char *text);

/* The glyph that character c draws: PS_FONT_GLYPH_H rows, top row first, each
 * in the low PS_FONT_GLYPH_W bits with bit 4 the leftmost pixel. Characters
 * outside 32..126 give the box. For tests and text-mode dumps. */
const unsigned char *ps_gl_font_glyph(int c);

#endif
