/* test_gl_font.c: the built-in bitmap font and overlay helpers under OSMesa:
 * exact pixel patterns read back from an 8-bit RGBA buffer, layout (6 px per
 * character, 9 px per line), clipping at the window's edges, and the GL state
 * that ps_gl_overlay_begin/end must leave as they found it. */
#include "test.h"

#include <GL/osmesa.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_api.h"
#include "gl/gl_font.h"

/* An OSMesa context drawing into w x h 8-bit RGBA, with depth and stencil so
 * that the state tests have something to turn on. */
typedef struct canvas {
    OSMesaContext ctx;
    unsigned char *buffer;
    int w, h;
} canvas;

static void canvas_open(canvas *c, int w, int h)
{
    c->w = w;
    c->h = h;
    c->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    assert_non_null(c->ctx);
    c->buffer = calloc((size_t)w * (size_t)h, 4);
    assert_non_null(c->buffer);
    assert_true(OSMesaMakeCurrent(c->ctx, c->buffer, GL_UNSIGNED_BYTE, w, h));
    glViewport(0, 0, w, h);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
}

/* Destroys the context while still current, with no read-back after the last
 * overlay in some tests (width_and_height): the case where Mesa's unflushed
 * glBitmap cache used to crash, which ps_gl_overlay_end's flush prevents. */
static void canvas_close(canvas *c)
{
    OSMesaDestroyContext(c->ctx);
    free(c->buffer);
}

static void canvas_clear(void)
{
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
}

/* The red channel, row 0 the top (glReadPixels' row 0 is the bottom). */
static unsigned char *read_red(const canvas *c)
{
    size_t n = (size_t)c->w * (size_t)c->h;
    unsigned char *rgba = malloc(4 * n), *red = malloc(n);
    assert_non_null(rgba);
    assert_non_null(red);
    glFinish();
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, c->w, c->h, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    for (int y = 0; y < c->h; y++)
        for (int x = 0; x < c->w; x++)
            red[(size_t)y * (size_t)c->w + (size_t)x] = rgba[4 * ((size_t)(c->h - 1 - y) * (size_t)c->w + (size_t)x)];
    free(rgba);
    return red;
}

/* Sets the pixels of a glyph (PS_FONT_GLYPH_H rows, bit 4 leftmost) with its
 * top-left at (x, y) in a top-down mask, clipped to the canvas. */
static void stamp(unsigned char *mask, int w, int h, int x, int y, const unsigned char *rows)
{
    for (int r = 0; r < PS_FONT_GLYPH_H; r++)
        for (int k = 0; k < PS_FONT_GLYPH_W; k++) {
            int px = x + k, py = y + r;
            if (px >= 0 && px < w && py >= 0 && py < h && (rows[r] >> (PS_FONT_GLYPH_W - 1 - k) & 1))
                mask[py * w + px] = 255;
        }
}

/* Rows from 7 strings of '#' and '.'. */
static void rows_from_art(const char *const art[PS_FONT_GLYPH_H], unsigned char rows[PS_FONT_GLYPH_H])
{
    for (int r = 0; r < PS_FONT_GLYPH_H; r++) {
        assert_int_equal(strlen(art[r]), PS_FONT_GLYPH_W);
        rows[r] = 0;
        for (int k = 0; k < PS_FONT_GLYPH_W; k++)
            rows[r] = (unsigned char)(rows[r] << 1 | (art[r][k] == '#'));
    }
}

static void print_mask(const unsigned char *mask, int w, int h)
{
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++)
            putchar(mask[y * w + x] ? '#' : '.');
        putchar('\n');
    }
}

/* The whole image equals the expected mask: 255 where set, 0 elsewhere. */
static void assert_image(const canvas *c, const unsigned char *expected, const char *what)
{
    unsigned char *got = read_red(c);
    if (memcmp(got, expected, (size_t)c->w * (size_t)c->h) != 0) {
        printf("%s: expected\n", what);
        print_mask(expected, c->w, c->h);
        printf("got\n");
        print_mask(got, c->w, c->h);
        free(got);
        fail_msg("%s: pixels differ", what);
    }
    free(got);
}

/* Draws text in white on a cleared canvas inside an overlay. */
static int draw_text(int x, int y, const char *text, int w, int h)
{
    canvas_clear();
    ps_gl_overlay_begin(w, h);
    glColor3f(1, 1, 1);
    int width = ps_gl_text(x, y, text);
    ps_gl_overlay_end();
    return width;
}

/* A few glyphs against patterns written out here, independently of the
 * table: the exact pixels, nothing else lit. */
static void known_glyphs(void **state)
{
    (void)state;
    static const struct {
        char c;
        const char *art[PS_FONT_GLYPH_H];
    } cases[] = {
        {'A', {".###.", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
        {'0', {".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."}},
        {'|', {"..#..", "..#..", "..#..", "..#..", "..#..", "..#..", "..#.."}},
        {'.', {".....", ".....", ".....", ".....", ".....", ".##..", ".##.."}},
        {' ', {".....", ".....", ".....", ".....", ".....", ".....", "....."}},
    };
    canvas cv;
    canvas_open(&cv, 64, 32);
    unsigned char *expected = malloc(64 * 32);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        unsigned char rows[PS_FONT_GLYPH_H];
        rows_from_art(cases[i].art, rows);
        assert_memory_equal(rows, ps_gl_font_glyph(cases[i].c), PS_FONT_GLYPH_H);
        char text[2] = {cases[i].c, 0};
        assert_int_equal(draw_text(7, 11, text, 64, 32), PS_FONT_CELL_W);
        memset(expected, 0, 64 * 32);
        stamp(expected, 64, 32, 7, 11, rows);
        assert_image(&cv, expected, text);
    }
    free(expected);
    canvas_close(&cv);
}

/* Every character draws exactly its table entry; bytes outside 32..126 draw
 * the box; every visible glyph has ink, and no two letters or digits look
 * alike. */
static void every_glyph(void **state)
{
    (void)state;
    enum { W = 16, H = 16, X = 3, Y = 4 };
    canvas cv;
    canvas_open(&cv, W, H);
    unsigned char drawn[128][PS_FONT_GLYPH_H];
    unsigned char expected[W * H];
    const int others[] = {1, 9, 127, 128, 200, 255};
    for (int c = 32; c <= 126 + (int)(sizeof others / sizeof others[0]); c++) {
        int ch = c <= 126 ? c : others[c - 127];
        char text[2] = {(char)ch, 0};
        draw_text(X, Y, text, W, H);
        memset(expected, 0, sizeof expected);
        stamp(expected, W, H, X, Y, ps_gl_font_glyph(ch));
        assert_image(&cv, expected, text);
        if (ch <= 126) {
            /* Keep what was read back, as rows, for the checks below. */
            unsigned char *got = read_red(&cv);
            for (int r = 0; r < PS_FONT_GLYPH_H; r++) {
                drawn[ch][r] = 0;
                for (int k = 0; k < PS_FONT_GLYPH_W; k++)
                    drawn[ch][r] = (unsigned char)(drawn[ch][r] << 1 | (got[(Y + r) * W + X + k] != 0));
            }
            free(got);
        } else {
            assert_ptr_equal(ps_gl_font_glyph(ch), ps_gl_font_glyph(0));
        }
    }
    for (int c = 33; c <= 126; c++) {
        int ink = 0;
        for (int r = 0; r < PS_FONT_GLYPH_H; r++)
            ink |= drawn[c][r];
        if (!ink)
            fail_msg("'%c' draws nothing", c);
        if (memcmp(drawn[c], ps_gl_font_glyph(0), PS_FONT_GLYPH_H) == 0)
            fail_msg("'%c' looks like the box", c);
    }
    const char *alnum = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz";
    for (const char *a = alnum; *a; a++)
        for (const char *b = a + 1; *b; b++)
            if (memcmp(drawn[(int)*a], drawn[(int)*b], PS_FONT_GLYPH_H) == 0)
                fail_msg("'%c' and '%c' are identical", *a, *b);
    canvas_close(&cv);
}

/* Characters advance one 6 px cell, lines one 9 px cell; the return value is
 * the longest line's width. */
static void advance_and_lines(void **state)
{
    (void)state;
    canvas cv;
    canvas_open(&cv, 64, 32);
    unsigned char expected[64 * 32];

    assert_int_equal(draw_text(3, 4, "AB\nC|+", 64, 32), 3 * PS_FONT_CELL_W);
    memset(expected, 0, sizeof expected);
    stamp(expected, 64, 32, 3, 4, ps_gl_font_glyph('A'));
    stamp(expected, 64, 32, 9, 4, ps_gl_font_glyph('B'));
    stamp(expected, 64, 32, 3, 13, ps_gl_font_glyph('C'));
    stamp(expected, 64, 32, 9, 13, ps_gl_font_glyph('|'));
    stamp(expected, 64, 32, 15, 13, ps_gl_font_glyph('+'));
    assert_image(&cv, expected, "AB\\nC|+");

    /* Empty lines still advance; spaces move the pen without ink. */
    assert_int_equal(draw_text(0, 0, "\n\n  x", 64, 32), 3 * PS_FONT_CELL_W);
    memset(expected, 0, sizeof expected);
    stamp(expected, 64, 32, 12, 18, ps_gl_font_glyph('x'));
    assert_image(&cv, expected, "\\n\\n  x");

    assert_int_equal(draw_text(0, 0, "", 64, 32), 0);
    assert_int_equal(draw_text(0, 0, NULL, 64, 32), 0);
    canvas_close(&cv);
}

static void width_and_height(void **state)
{
    (void)state;
    static const struct {
        const char *text;
        int w, h;
    } cases[] = {
        {"", 0, 0},
        {"a", 6, 9},
        {"abc", 18, 9},
        {"ab\nlonger\nx", 36, 27},
        {"longest\nab", 42, 18},
        {"x\n", 6, 18},
        {"\n", 0, 18},
        {"x\n\nyz", 12, 27},
        {"fps: 59.9\nphotons: 1,000,000\n[h] help", 18 * 6, 27},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        assert_int_equal(ps_gl_text_width(cases[i].text), cases[i].w);
        assert_int_equal(ps_gl_text_height(cases[i].text), cases[i].h);
    }
    assert_int_equal(ps_gl_text_width(NULL), 0);
    assert_int_equal(ps_gl_text_height(NULL), 0);

    /* ps_gl_text agrees with ps_gl_text_width. */
    canvas cv;
    canvas_open(&cv, 64, 32);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        assert_int_equal(draw_text(0, 0, cases[i].text, 64, 32), cases[i].w);
    canvas_close(&cv);
}

static void get_matrix(GLenum which, double m[16])
{
    glGetDoublev(which, m);
}

/* After a scene-like pass (perspective, rotated modelview, depth test that
 * rejects everything, lighting, texturing on two units, a clip plane that
 * cuts everything, stencil, masked colour, additive blending, an offset
 * viewport), the overlay still draws exactly, and end puts all of it back. */
static void state_restored(void **state)
{
    (void)state;
    canvas cv;
    canvas_open(&cv, 64, 32);

    glViewport(4, 2, 30, 20);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glTranslated(0.25, -1.5, -3.0);
    glRotated(33.0, 0.3, 1.0, 0.2);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum(-0.7, 0.6, -0.5, 0.45, 0.5, 40.0);
    double proj[16], model[16];
    get_matrix(GL_PROJECTION_MATRIX, proj);
    get_matrix(GL_MODELVIEW_MATRIX, model);

    glClearDepth(0.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_LIGHTING);
    glEnable(GL_TEXTURE_2D);
    glActiveTexture(GL_TEXTURE1);
    glEnable(GL_TEXTURE_2D);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_NEVER, 0, 0xff);
    const double cut_all[4] = {0, 0, 0, -1};
    glClipPlane(GL_CLIP_PLANE0, cut_all);
    glEnable(GL_CLIP_PLANE0);
    glEnable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glColor4f(0.25f, 0.5f, 0.75f, 1.0f);

    ps_gl_overlay_begin(64, 32);
    assert_false(glIsEnabled(GL_DEPTH_TEST));
    assert_false(glIsEnabled(GL_LIGHTING));
    assert_false(glIsEnabled(GL_STENCIL_TEST));
    assert_false(glIsEnabled(GL_CLIP_PLANE0));
    assert_false(glIsEnabled(GL_TEXTURE_2D)); /* unit 1, still the active one */
    GLint active = 0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    assert_int_equal(active, GL_TEXTURE1);
    glActiveTexture(GL_TEXTURE0);
    assert_false(glIsEnabled(GL_TEXTURE_2D));
    glActiveTexture(GL_TEXTURE1);
    glColor3f(1, 1, 1);
    ps_gl_text(2, 3, "A");
    ps_gl_overlay_rect(40, 20, 3, 2, 1, 1, 1, 1);
    ps_gl_overlay_end();

    unsigned char expected[64 * 32];
    memset(expected, 0, sizeof expected);
    stamp(expected, 64, 32, 2, 3, ps_gl_font_glyph('A'));
    for (int y = 20; y < 22; y++)
        for (int x = 40; x < 43; x++)
            expected[y * 64 + x] = 255;
    assert_image(&cv, expected, "overlay over scene state");

    double proj2[16], model2[16];
    get_matrix(GL_PROJECTION_MATRIX, proj2);
    get_matrix(GL_MODELVIEW_MATRIX, model2);
    assert_memory_equal(proj, proj2, sizeof proj);
    assert_memory_equal(model, model2, sizeof model);
    GLint mode = 0, vp[4];
    glGetIntegerv(GL_MATRIX_MODE, &mode);
    assert_int_equal(mode, GL_PROJECTION);
    glGetIntegerv(GL_VIEWPORT, vp);
    assert_int_equal(vp[0], 4);
    assert_int_equal(vp[1], 2);
    assert_int_equal(vp[2], 30);
    assert_int_equal(vp[3], 20);
    assert_true(glIsEnabled(GL_DEPTH_TEST));
    assert_true(glIsEnabled(GL_LIGHTING));
    assert_true(glIsEnabled(GL_STENCIL_TEST));
    assert_true(glIsEnabled(GL_CLIP_PLANE0));
    assert_true(glIsEnabled(GL_CULL_FACE));
    assert_true(glIsEnabled(GL_BLEND));
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    assert_int_equal(active, GL_TEXTURE1);
    assert_true(glIsEnabled(GL_TEXTURE_2D));
    glActiveTexture(GL_TEXTURE0);
    assert_true(glIsEnabled(GL_TEXTURE_2D));
    GLint src = 0, dst = 0;
    glGetIntegerv(GL_BLEND_SRC, &src);
    glGetIntegerv(GL_BLEND_DST, &dst);
    assert_int_equal(src, GL_ONE);
    assert_int_equal(dst, GL_ONE);
    GLboolean mask[4];
    glGetBooleanv(GL_COLOR_WRITEMASK, mask);
    assert_false(mask[0]);
    float color[4];
    glGetFloatv(GL_CURRENT_COLOR, color);
    assert_near(color[0], 0.25, 1e-6);
    assert_near(color[2], 0.75, 1e-6);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    canvas_close(&cv);
}

/* Glyphs partly or wholly off the window: the visible part draws, nothing
 * else, and nothing crashes (glRasterPos would drop the whole string). */
static void partly_off_screen(void **state)
{
    (void)state;
    enum { W = 32, H = 16 };
    static const struct {
        int x, y;
        const char *text;
    } cases[] = {
        {-2, 3, "A"},         /* the left columns cut */
        {-8, 3, "AA0"},       /* the first glyph wholly off, then the rest */
        {28, 3, "AB"},        /* running off the right */
        {5, -3, "A|"},        /* the top rows cut */
        {5, 12, "A\n0"},      /* the bottom cut, the second line wholly off */
        {-3, -4, "W\nM"},     /* a corner */
        {-100, -100, "A"},    /* nowhere near */
        {200, 3, "A"},
        {5, 100, "A"},
        {-30, 2, "long line off the left\nHi"},
    };
    canvas cv;
    canvas_open(&cv, W, H);
    unsigned char expected[W * H];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        draw_text(cases[i].x, cases[i].y, cases[i].text, W, H);
        memset(expected, 0, sizeof expected);
        int line = 0, col = 0;
        for (const char *p = cases[i].text; *p; p++) {
            if (*p == '\n') {
                line++;
                col = 0;
                continue;
            }
            stamp(expected, W, H, cases[i].x + col * PS_FONT_CELL_W, cases[i].y + line * PS_FONT_CELL_H,
                  ps_gl_font_glyph(*p));
            col++;
        }
        assert_image(&cv, expected, cases[i].text);
    }
    assert_int_equal(glGetError(), GL_NO_ERROR);
    canvas_close(&cv);
}

/* The backdrop covers exactly its pixels, blends by alpha, and leaves the
 * text colour set before it. */
static void rect_blends(void **state)
{
    (void)state;
    enum { W = 32, H = 16 };
    canvas cv;
    canvas_open(&cv, W, H);
    ps_gl_overlay_begin(W, H);
    glColor3f(1, 1, 1);
    ps_gl_overlay_rect(2, 3, 10, 5, 1, 0, 0, 0.5f);
    ps_gl_overlay_rect(20, 3, 0, 5, 1, 1, 1, 1); /* empty: nothing */
    ps_gl_text(20, 3, "|");
    ps_gl_overlay_end();
    glFinish();
    unsigned char rgba[W * H * 4];
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const unsigned char *p = rgba + 4 * ((H - 1 - y) * W + x);
            int in_rect = x >= 2 && x < 12 && y >= 3 && y < 8;
            int in_bar = x == 22 && y >= 3 && y < 10;
            if (in_rect) {
                assert_in_range(p[0], 127, 128);
                assert_int_equal(p[1], 0);
            } else if (in_bar) {
                assert_int_equal(p[0], 255);
                assert_int_equal(p[1], 255);
            } else {
                assert_int_equal(p[0], 0);
                assert_int_equal(p[1], 0);
            }
        }
    canvas_close(&cv);
}

/* A sample read-out, checked against the table and printed for a reader to
 * judge legibility; PS_FONT_DUMP=1 prints the whole character set too. */
static void sample_ascii_art(void **state)
{
    (void)state;
    static const char *samples[] = {
        "Photons: 1,234,567 (12.5 fps)\n[h] help  q: quit  +/- exposure\nThe quick brown fox jumps over",
        " !\"#$%&'()*+,-./0123456789:;<=>?\n@ABCDEFGHIJKLMNOPQRSTUVWXYZ[\\]^_\n`abcdefghijklmnopqrstuvwxyz{|}~",
    };
    int count = getenv("PS_FONT_DUMP") ? 2 : 1;
    for (int s = 0; s < count; s++) {
        const char *text = samples[s];
        canvas cv;
        int w = ps_gl_text_width(text) + 2, h = ps_gl_text_height(text) + 1;
        canvas_open(&cv, w, h);
        assert_int_equal(draw_text(1, 1, text, w, h), w - 2);
        unsigned char *expected = calloc((size_t)w * (size_t)h, 1);
        int line = 0, col = 0;
        for (const char *p = text; *p; p++) {
            if (*p == '\n') {
                line++;
                col = 0;
                continue;
            }
            stamp(expected, w, h, 1 + col * PS_FONT_CELL_W, 1 + line * PS_FONT_CELL_H, ps_gl_font_glyph(*p));
            col++;
        }
        assert_image(&cv, expected, text);
        unsigned char *got = read_red(&cv);
        printf("%s\n", s == 0 ? "sample:" : "character set:");
        print_mask(got, w, h);
        free(got);
        free(expected);
        canvas_close(&cv);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(known_glyphs),     cmocka_unit_test(every_glyph),     cmocka_unit_test(advance_and_lines),
        cmocka_unit_test(width_and_height), cmocka_unit_test(state_restored),  cmocka_unit_test(partly_off_screen),
        cmocka_unit_test(rect_blends),      cmocka_unit_test(sample_ascii_art),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
