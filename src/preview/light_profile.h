/* light_profile.h: what the GL preview needs to draw any light's angular
 * distribution in fixed function: a lat-long table of its relative radiant
 * intensity over directions in the light's own frame, normalised for upload
 * as a one-channel texture (projected from the light with texgen and the
 * texture matrix, as the per-pixel spot cone is). GL-free.
 *
 * Texel (i, j) of a width x height table (width = 2 height) covers the
 * directions with theta (from `axis`) in [j, j + 1] pi / height and phi (from
 * axis0 towards axis90) in [i, i + 1] 2 pi / width; its value is the mean of
 * the light's intensity over those directions (solid-angle weighted), over the
 * largest such mean, so the table's largest value is 1. Then a light of power
 * P sends about P * peak * value W/sr towards a direction in that texel, and
 * the sum of value * peak * texel solid angle is 1 (the whole flux). */
#ifndef PS_PREVIEW_LIGHT_PROFILE_H
#define PS_PREVIEW_LIGHT_PROFILE_H

#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"
#include "scene/scene.h"

/* Sub-samples per texel side for the solid-angle mean. */
#define PS_LIGHT_PROFILE_SUPERSAMPLE 8
#define PS_LIGHT_PROFILE_MAX_HEIGHT 2048

typedef struct ps_light_profile {
    int width, height;           /* width = 2 height */
    float *texels;               /* width * height values in [0, 1], row j = theta band j */
    double peak;                 /* intensity per watt of power (1/sr) at value 1 */
    ps_vec3 axis, axis0, axis90; /* the frame: unit, right-handed as ps_light's (axis0 x axis = axis90) */
} ps_light_profile;

/* The table of light l of scene s, `height` texels from theta 0 to pi (1 to
 * PS_LIGHT_PROFILE_MAX_HEIGHT). Every light type: point and sphere uniform;
 * spot 1 inside its cone; quad and disc cos(theta) about their normal; mesh
 * the sum of its faces' cosines; ies its candela table. */
ps_status ps_light_profile_make(const ps_scene *s, size_t light, int height, ps_light_profile *out, ps_error *err);
void ps_light_profile_free(ps_light_profile *p); /* accepts a zeroed one */

/* The texel value (nearest) towards unit world direction d. */
float ps_light_profile_lookup(const ps_light_profile *p, ps_vec3 d);
/* The solid angle of a texel of row j (every texel of a row has the same). */
double ps_light_profile_texel_solid_angle(const ps_light_profile *p, int j);
/* For GL_LUMINANCE / GL_UNSIGNED_BYTE uploads: out[k] = round(255 texels[k]). */
void ps_light_profile_to_u8(const ps_light_profile *p, uint8_t *out);

#endif
