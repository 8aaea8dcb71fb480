/* gl_api.h: the one place src/gl includes OpenGL from. Entry points past GL
 * 1.1 (glGenFramebuffers, glPointParameterfv, glClampColor) come from the
 * implementation the program links, OSMesa or libGL, with prototypes from
 * glext.h (GL_GLEXT_PROTOTYPES is set by the build). */
#ifndef PS_GL_GL_API_H
#define PS_GL_GL_API_H

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>

#endif
