/* platform_osmesa.c: the headless context (platform.h): an OSMesa buffer of
 * RGBA with 24-bit depth and 8-bit stencil, and no accumulation buffer
 * (platform notes: it wraps above 1.0 and is no place for photon sums). */
#include "gl/platform.h"

#include <GL/osmesa.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_api.h"
#include "gl/gl_render.h"

struct ps_platform {
    OSMesaContext ctx;
    void *buffer;
    GLenum type;
    int width, height;
};

/* llvmpipe compiles a program for each new GL state on first use (the
 * fragment and vertex programs, often from Mesa's disk cache, and a triangle
 * set-up function, never cached), and most of a first picture is those
 * compiles (docs/preview.md). Mesa's GALLIVM_PERF=nopt leaves out its LLVM IR
 * optimisation passes: the same pictures, byte for byte, compiled sooner, at
 * some cost in fill rate. Set before the context is made (Mesa reads it
 * once), and never over the user's own GALLIVM_PERF. */
#define LLVMPIPE_PERF_ENV "GALLIVM_PERF"
#define LLVMPIPE_PERF_FAST_COMPILES "nopt"

ps_status ps_platform_open(const ps_platform_config *c, ps_platform **out, ps_error *err)
{
    *out = NULL;
    (void)setenv(LLVMPIPE_PERF_ENV, LLVMPIPE_PERF_FAST_COMPILES, 0);
    ps_platform *p = calloc(1, sizeof *p);
    if (!p)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for an OSMesa context");
    p->width = c->width;
    p->height = c->height;
    p->type = c->float_buffer ? GL_FLOAT : GL_UNSIGNED_BYTE;
    p->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    size_t bytes = (size_t)c->width * (size_t)c->height * 4 * (c->float_buffer ? sizeof(float) : 1);
    p->buffer = p->ctx ? malloc(bytes) : NULL;
    ps_status st = PS_OK;
    if (!p->ctx)
        st = ps_error_set(err, PS_ERR_IO, "OSMesa could not create a context");
    else if (!p->buffer)
        st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for a %dx%d buffer", c->width, c->height);
    else if (!OSMesaMakeCurrent(p->ctx, p->buffer, p->type, c->width, c->height))
        st = ps_error_set(err, PS_ERR_LIMIT, "OSMesa cannot draw a %dx%d %s buffer", c->width, c->height,
                          c->float_buffer ? "float" : "8-bit");
    if (st != PS_OK) {
        ps_platform_close(p);
        return st;
    }
    *out = p;
    return PS_OK;
}

void ps_platform_close(ps_platform *p)
{
    if (!p)
        return;
    if (p->ctx)
        OSMesaDestroyContext(p->ctx);
    free(p->buffer);
    free(p);
}

ps_platform_proc ps_platform_gl_proc(const char *name) { return (ps_platform_proc)OSMesaGetProcAddress(name); }

void ps_platform_make_current(ps_platform *p) { OSMesaMakeCurrent(p->ctx, p->buffer, p->type, p->width, p->height); }

void ps_platform_size(const ps_platform *p, int *width, int *height)
{
    *width = p->width;
    *height = p->height;
}

void ps_platform_present(ps_platform *p)
{
    (void)p;
    glFinish();
}

ps_status ps_platform_read(ps_platform *p, ps_image *out, ps_error *err)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glClampColor(GL_CLAMP_READ_COLOR, GL_FALSE);
    return ps_gl_read_pixels(p->width, p->height, out, err);
}

void *ps_platform_window(ps_platform *p)
{
    (void)p;
    return NULL;
}
