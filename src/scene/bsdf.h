/* bsdf.h: how each material reflects and refracts, for photons and eye rays.
 *
 * Directions follow one convention throughout: `d` is the direction a ray
 * travels (towards the surface), `n` a unit normal; results are unit vectors
 * leaving the surface. The glossy model is the normalised modified Phong BRDF
 *     f = albedo / pi + specular (e + 2) / (2 pi) cos^e(alpha),
 * alpha between the outgoing direction and the mirror direction, which keeps
 * albedo + specular <= 1 energy conserving. */
#ifndef PS_SCENE_BSDF_H
#define PS_SCENE_BSDF_H

#include <stdbool.h>

#include "core/vec.h"
#include "scene/scene.h"

/* Mirror direction of d about n (either side). */
static inline ps_vec3 ps_reflect(ps_vec3 d, ps_vec3 n) { return ps_v3_sub(d, ps_v3_scale(n, 2.0 * ps_v3_dot(d, n))); }

/* Fresnel reflectance of unpolarised light at a smooth interface, arriving at
 * cos_i (>= 0) from a medium of index eta_i into one of eta_t. 1 under total
 * internal reflection. */
double ps_fresnel_dielectric(double cos_i, double eta_i, double eta_t);

/* Refraction of d through a surface with normal n facing against d
 * (dot(d, n) < 0), eta = eta_i / eta_t. False under total internal reflection. */
bool ps_refract(ps_vec3 d, ps_vec3 n, double eta, ps_vec3 *out);

/* The modified Phong BRDF of a diffuse or glossy material for light arriving
 * along d_in (travelling) and leaving along w_out, both on the side of n. */
ps_rgb ps_bsdf_eval(const ps_material *m, ps_vec3 n, ps_vec3 d_in, ps_vec3 w_out);

#endif
