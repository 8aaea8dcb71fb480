/* sampling.h: warping [0,1)^2 onto directions, with the densities they give.
 *
 * Every sampler takes its uniform numbers as arguments (never a generator), so
 * callers decide whether they come from a per-index PCG stream or a
 * quasi-random sequence; a photon's path stays a pure function of its index. */
#ifndef PS_CORE_SAMPLING_H
#define PS_CORE_SAMPLING_H

#include "core/vec.h"

/* A unit vector expressed in the frame (t, b, n) of unit n. */
static inline ps_vec3 ps_frame_to_world(ps_vec3 n, double x, double y, double z)
{
    ps_vec3 t, b;
    ps_v3_basis(n, &t, &b);
    return ps_v3_add(ps_v3_add(ps_v3_scale(t, x), ps_v3_scale(b, y)), ps_v3_scale(n, z));
}

/* Uniform over the unit sphere; density 1/(4 pi). */
static inline ps_vec3 ps_sample_sphere(double u1, double u2)
{
    double z = 1.0 - 2.0 * u1;
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    double phi = 2.0 * PS_PI * u2;
    return ps_v3(r * cos(phi), r * sin(phi), z);
}

/* Uniform inside the cone of directions within acos(cos_max) of unit axis;
 * density 1 / ps_cone_solid_angle(cos_max). cos_max = -1 is the whole sphere. */
static inline ps_vec3 ps_sample_cone(double u1, double u2, ps_vec3 axis, double cos_max)
{
    double z = 1.0 - u1 * (1.0 - cos_max);
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    double phi = 2.0 * PS_PI * u2;
    return ps_frame_to_world(axis, r * cos(phi), r * sin(phi), z);
}

/* Solid angle of a cone of half-angle acos(cos_max): 2 pi (1 - cos_max). */
static inline double ps_cone_solid_angle(double cos_max) { return 2.0 * PS_PI * (1.0 - cos_max); }

/* Cosine-weighted over the hemisphere around unit n (Malley's method: uniform
 * on the disc, projected up); density cos(theta) / pi. */
static inline ps_vec3 ps_sample_cosine(double u1, double u2, ps_vec3 n)
{
    double r = sqrt(u1);
    double phi = 2.0 * PS_PI * u2;
    double x = r * cos(phi), y = r * sin(phi);
    return ps_frame_to_world(n, x, y, sqrt(fmax(0.0, 1.0 - u1)));
}

/* Directions around unit axis r with density (e + 1)/(2 pi) cos^e(alpha),
 * alpha the angle to r: the Phong lobe of exponent e (Lafortune & Willems 1994). */
static inline ps_vec3 ps_sample_phong(double u1, double u2, ps_vec3 r, double e)
{
    double z = pow(u1, 1.0 / (e + 1.0));
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    double phi = 2.0 * PS_PI * u2;
    return ps_frame_to_world(r, s * cos(phi), s * sin(phi), z);
}

/* Uniform on the unit disc (concentric map of Shirley & Chiu, which keeps
 * strata compact for the quasi-random emission samples). */
static inline void ps_sample_disc(double u1, double u2, double *x, double *y)
{
    double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    double r, phi;
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (PS_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = (PS_PI / 2.0) - (PS_PI / 4.0) * (a / b);
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

/* Uniform barycentrics (b1, b2) over a triangle. */
static inline void ps_sample_triangle(double u1, double u2, double *b1, double *b2)
{
    double s = sqrt(u1);
    *b1 = s * (1.0 - u2);
    *b2 = s * u2;
}

#endif
