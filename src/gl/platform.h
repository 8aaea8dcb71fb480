/* platform.h: where the preview's GL context comes from, behind the same few
 * functions for both programs (in the spirit of raylib's platforms/): a
 * headless OSMesa buffer (platform_osmesa.c, photosplat-snap) or a GLFW
 * window with libGL (platform_glfw.c, the window). A program links exactly
 * one of them, never both GL implementations (platform notes). The drawing
 * itself is libpsgl's, the same for both. */
#ifndef PS_GL_PLATFORM_H
#define PS_GL_PLATFORM_H

#include <stdbool.h>

#include "core/status.h"
#include "image/image.h"

typedef struct ps_platform ps_platform;

typedef struct ps_platform_config {
    int width, height;  /* the picture's size in pixels */
    bool float_buffer;  /* OSMesa: a float colour buffer (else 8 bits); the window's is 8 bits */
    const char *title;  /* the window's title */
} ps_platform_config;

/* Opens the context (and window) and makes it current. */
ps_status ps_platform_open(const ps_platform_config *c, ps_platform **out, ps_error *err);
void ps_platform_close(ps_platform *p); /* accepts NULL */
void ps_platform_make_current(ps_platform *p);
/* The size actually drawn to (a window's framebuffer may differ from the
 * size asked for). */
void ps_platform_size(const ps_platform *p, int *width, int *height);
/* Shows what was drawn: swaps a window's buffers; finishes OSMesa's drawing. */
void ps_platform_present(ps_platform *p);
/* The picture as drawn so far (before present), into out (created here, row
 * 0 the top): OSMesa's colour buffer as stored (floats, or 8-bit codes / 255);
 * the window's back buffer as its 8-bit sRGB codes, decoded to linear so that
 * the PNG encoder gives the same codes back. */
ps_status ps_platform_read(ps_platform *p, ps_image *out, ps_error *err);
/* The window (a GLFWwindow *, for input callbacks), or NULL headless. */
void *ps_platform_window(ps_platform *p);
/* A GL entry point of the current context by name, or NULL: for those the
 * GL library need not export (OSMesa exports no glQueryCounter), as
 * ps_gl_options.gl_proc. */
typedef void (*ps_platform_proc)(void);
ps_platform_proc ps_platform_gl_proc(const char *name);

#endif
