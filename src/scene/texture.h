/* texture.h: diffuse albedo textures (MTL map_Kd), shared between a scene and
 * its clones.
 *
 * A texture is immutable once loaded: linear RGB floats (decoded from the
 * sRGB codes exporters write), row 0 at the top as in the file. Clones share
 * it by reference count (ps_texture_ref / ps_texture_unref), which is
 * atomic, so a clone may be destroyed on another thread. */
#ifndef PS_SCENE_TEXTURE_H
#define PS_SCENE_TEXTURE_H

#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"

typedef struct ps_texture ps_texture;

/* What one texel is planned at against the memory budget: the linear floats
 * kept here, the GL preview's float copy, and the reader's decoded copy. */
#define PS_TEXTURE_PLAN_TEXEL_BYTES (3 * sizeof(float) * 2 + 4 * sizeof(uint16_t))

/* Reads a PNG or JPEG (by its name's ending: .png, .jpg, .jpeg, any case).
 * planned_bytes: what the scene's other textures already take, so that the
 * sum is checked against the memory budget. */
ps_status ps_texture_load(const char *path, uint64_t planned_bytes, ps_texture **out, ps_error *err);
ps_texture *ps_texture_ref(ps_texture *t);
void ps_texture_unref(ps_texture *t); /* accepts NULL */

int ps_texture_width(const ps_texture *t);
int ps_texture_height(const ps_texture *t);
const char *ps_texture_path(const ps_texture *t);
/* width * height * 3 linear floats, row 0 at the top. */
const float *ps_texture_texels(const ps_texture *t);
uint64_t ps_texture_bytes(const ps_texture *t);

/* The linear colour at texture coordinates (u, v), as OBJ exporters mean
 * them: v = 0 at the image's bottom row, both wrapping (repeat), filtered
 * bilinearly between texel centres as GL_LINEAR with GL_REPEAT does. */
ps_rgb ps_texture_sample(const ps_texture *t, double u, double v);

#endif
