/* platform_glfw.c: the window's context (platform.h): a GLFW window with an
 * OpenGL 2.1 (or later compatibility) context from libGL, never OSMesa. */
#include "gl/platform.h"

#include <stdlib.h>

#include "gl/gl_api.h"
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

struct ps_platform {
    GLFWwindow *win;
    int width, height;
};

ps_status ps_platform_open(const ps_platform_config *c, ps_platform **out, ps_error *err)
{
    *out = NULL;
    ps_platform *p = calloc(1, sizeof *p);
    if (!p)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for a window");
    if (!glfwInit()) {
        free(p);
        return ps_error_set(err, PS_ERR_IO, "cannot open a window (no display?); photosplat-snap renders headless");
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    glfwWindowHint(GLFW_STENCIL_BITS, 8);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    p->win = glfwCreateWindow(c->width, c->height, c->title ? c->title : "photosplat", NULL, NULL);
    if (!p->win) {
        ps_platform_close(p);
        return ps_error_set(err, PS_ERR_IO, "cannot create a %dx%d OpenGL 2.1 window", c->width, c->height);
    }
    glfwMakeContextCurrent(p->win);
    glfwSwapInterval(0); /* refresh on the preview's tau, not the monitor's */
    glfwGetFramebufferSize(p->win, &p->width, &p->height);
    *out = p;
    return PS_OK;
}

void ps_platform_close(ps_platform *p)
{
    if (!p)
        return;
    if (p->win)
        glfwDestroyWindow(p->win);
    glfwTerminate();
    free(p);
}

void ps_platform_make_current(ps_platform *p) { glfwMakeContextCurrent(p->win); }

ps_platform_proc ps_platform_gl_proc(const char *name) { return (ps_platform_proc)glfwGetProcAddress(name); }

void ps_platform_size(const ps_platform *p, int *width, int *height)
{
    *width = p->width;
    *height = p->height;
}

void ps_platform_present(ps_platform *p) { glfwSwapBuffers(p->win); }

ps_status ps_platform_read(ps_platform *p, ps_image *out, ps_error *err)
{
    ps_status st = ps_image_create(p->width, p->height, out, err);
    uint8_t *rgb = st == PS_OK ? malloc(3 * (size_t)p->width * (size_t)p->height) : NULL;
    if (st == PS_OK && !rgb) {
        ps_image_destroy(out);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for a screenshot");
    }
    if (st != PS_OK)
        return st;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, p->width, p->height, GL_RGB, GL_UNSIGNED_BYTE, rgb);
    for (int y = 0; y < p->height; y++) {
        float *dst = ps_image_at(out, 0, y);
        const uint8_t *src = rgb + 3 * (size_t)(p->height - 1 - y) * (size_t)p->width;
        for (int i = 0; i < 3 * p->width; i++)
            dst[i] = ps_srgb_decode((float)src[i] / 255.0f);
    }
    free(rgb);
    return PS_OK;
}

void *ps_platform_window(ps_platform *p) { return p->win; }
