/* estimate.h: density estimation over a photon map: the radiance estimate
 * (thesis eq. 9) with its kernels, and irradiance precomputed at photon
 * positions for final gathering (Christensen 1999).
 *
 * A kernel is a radial profile g(s), s = d / r in [0, 1], with g(0) = 1. Its
 * mean over the unit disc, C = 2 * integral_0^1 g(s) s ds, is what both the
 * estimate and the GL splats (thesis eq. 13: colour = dPhi / (C pi r^2))
 * divide by, so that a kernel of any shape sums to the same total energy:
 *     L(x, w) = sum_p f(x, w_p, w) dPhi_p g(d_p / r) / (C pi r^2). */
#ifndef PS_PHOTON_ESTIMATE_H
#define PS_PHOTON_ESTIMATE_H

#include <stddef.h>

#include "core/cancel.h"
#include "core/status.h"
#include "core/vec.h"
#include "photon/kdtree.h"
#include "scene/scene.h"

typedef enum ps_kernel {
    PS_KERNEL_BOX,          /* g = 1: the plain estimate */
    PS_KERNEL_CONE,         /* g = 1 - s (Jensen's cone filter, k = 1): C = 1/3 */
    PS_KERNEL_GAUSS,        /* g = exp(-beta s^2 / 2) - exp(-beta / 2), scaled to g(0) = 1 */
    PS_KERNEL_EPANECHNIKOV, /* g = 1 - s^2: C = 1/2 */
    PS_KERNEL_COUNT
} ps_kernel;

/* The kernels' names in enum order, NULL-terminated (options, scripts, stats):
 * "box", "cone", "gauss", "epanechnikov". */
extern const char *const ps_kernel_names[PS_KERNEL_COUNT + 1];
const char *ps_kernel_name(ps_kernel k); /* ps_kernel_names[k], "?" out of range */
/* The profile g(s) (0 outside [0, 1]) and its disc mean C. */
double ps_kernel_profile(ps_kernel k, double s);
double ps_kernel_mean(ps_kernel k);

typedef struct ps_estimate_options {
    size_t k;          /* photons per estimate */
    double max_radius; /* the search radius (scene units) */
    ps_kernel kernel;
} ps_estimate_options;

/* Photons whose normal is within this cosine of the query normal count;
 * others lie on a surface facing another way (7-bit normals are within 1.5
 * degrees, so a plane's own photons always pass). */
#define PS_ESTIMATE_MIN_COS 0.0

/* Irradiance (W/m^2) arriving at point p of a surface with unit normal n on
 * the side photons came from. scratch holds at least o->k neighbours. */
ps_rgb ps_photon_irradiance(const ps_kdtree *map, ps_vec3 p, ps_vec3 n, const ps_estimate_options *o,
                            ps_neighbor *scratch);

/* Radiance (W sr^-1 m^-2) leaving p towards wo over material m (diffuse or
 * glossy; zero for others): each photon weighted by the BRDF for its own
 * incoming direction. n: unit shading normal on wo's side. */
ps_rgb ps_photon_radiance(const ps_kdtree *map, const ps_material *m, ps_vec3 p, ps_vec3 n, ps_vec3 wo,
                          const ps_estimate_options *o, ps_neighbor *scratch);

/* Christensen's precomputation: the irradiance at every stride-th photon of
 * map (stride >= 1), as a new tree whose photons carry E in place of power
 * (same position and normal). Computed on `threads` threads; the result does
 * not depend on their number. cancel (NULL: none) stops it between chunks
 * with PS_ERR_INTERRUPTED and nothing made: at the reference's final quality
 * it takes seconds, and mpirun kills ranks that do not stop within about a
 * second of its SIGTERM. */
ps_status ps_irradiance_precompute(const ps_kdtree *map, const ps_estimate_options *o, size_t stride, int threads,
                                   const ps_cancel_flag *cancel, ps_kdtree **out, ps_error *err);

/* The precomputed irradiance nearest to p within radius whose normal faces
 * the same way as n (cosine above PS_IRRADIANCE_MIN_COS); false when none. */
#define PS_IRRADIANCE_MIN_COS 0.9
bool ps_irradiance_lookup(const ps_kdtree *irr, ps_vec3 p, ps_vec3 n, double radius, ps_rgb *e);

#endif
