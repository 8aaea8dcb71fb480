/* gl_specular_blur.h: the blurred levels of the specular layer's cube maps
 * for glossy objects (preview/specular_glossy.h), in fixed-function GL.
 *
 * Each cube that a glossy range looks up gets a level: a second cube
 * texture of ps_glossy_level_size texels a side (RGBA16F), the cube's faces
 * read back as they are rendered and convolved on the CPU with the
 * normalised lobe cos^(e+1) of the first glossy range's exponent e (other
 * glossy ranges sharing the cube use it too). The level's faces are redone
 * one a refresh in the window (a face of 32^2: 5-10 ms), all at once for a
 * single frame, a snapshot's last picture and a test's furnace. A cube whose
 * ranges are all glossy is rendered without the area lights and emissive
 * faces: a glossy surface's reflection of them is the direct layer's (the GL
 * highlight of their virtual point lights), as it is the reference's direct
 * term, and the reference's gather rays look through them. */
#ifndef PS_GL_GL_SPECULAR_BLUR_H
#define PS_GL_GL_SPECULAR_BLUR_H

#include <stdbool.h>

#include "core/status.h"
#include "gl/gl_api.h"
#include "preview/session.h"

/* Level faces redone a refresh in the window. */
#define PS_GL_GLOSSY_FACES_PER_REFRESH 1

typedef struct ps_gl_glossy ps_gl_glossy;

ps_status ps_gl_glossy_create(ps_gl_glossy **out, ps_error *err);
void ps_gl_glossy_destroy(ps_gl_glossy *g); /* accepts NULL */

/* Levels for the session's cubes (cube_count of them, cube_size texels a
 * side), made or remade where a cube's glossy exponent changed. */
ps_status ps_gl_glossy_sync(ps_gl_glossy *g, ps_session *s, int cube_count, int cube_size, ps_error *err);
/* Whether cube c has a level, and whether all its ranges are glossy. */
bool ps_gl_glossy_has(const ps_gl_glossy *g, int c);
bool ps_gl_glossy_only(const ps_gl_glossy *g, int c);
/* Face f of cube c (texture tex, size^2) rendered: read back; every face
 * of c's level is to be redone. */
void ps_gl_glossy_read_face(ps_gl_glossy *g, int c, int f, GLuint tex, int size);
/* Up to `faces` level faces redone (0: all that wait); true when one was. */
bool ps_gl_glossy_blur(ps_gl_glossy *g, int faces);
/* Whether level faces wait to be redone. */
bool ps_gl_glossy_pending(const ps_gl_glossy *g);
/* Cube c's level texture, or 0. */
GLuint ps_gl_glossy_texture(const ps_gl_glossy *g, int c);

#endif
