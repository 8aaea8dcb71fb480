/* glyphs.h: the 5x7 bitmap font, the one table for the GL overlay
 * (src/gl/gl_font.h) and for text drawn into images without GL. */
#ifndef PS_IMAGE_GLYPHS_H
#define PS_IMAGE_GLYPHS_H

#define PS_GLYPH_W 5
#define PS_GLYPH_H 7
#define PS_GLYPH_CELL_W 6 /* a glyph and 1 px of spacing */
#define PS_GLYPH_CELL_H 9 /* a glyph and a 2 px line gap */

/* The glyph of character c: PS_GLYPH_H rows, top row first, each in the low
 * PS_GLYPH_W bits with bit 4 the leftmost pixel; outside 32..126 a hollow box. */
const unsigned char *ps_glyph(int c);

#endif
