/* analytic.h: what the closed-form image tests share: where a pixel looks
 * on the floor, and the radiance a point light puts there. */
#ifndef PS_TESTS_ANALYTIC_H
#define PS_TESTS_ANALYTIC_H

#include <math.h>
#include <stdbool.h>

#include "scene/camera.h"

/* The point of the plane y = 0 that image position (x, y) sees, or false. */
static inline bool floor_point(const ps_camera_frame *cam, double x, double y, ps_vec3 *p)
{
    ps_ray r = ps_camera_ray(cam, x, y);
    if (!(r.d.y < 0))
        return false;
    *p = ps_ray_at(r, -r.o.y / r.d.y);
    return true;
}

/* Radiance of a diffuse floor of albedo rho at p under a point light of
 * intensity I (W/sr) at height h above (lx, lz): rho / pi * I h / d^3. */
static inline double floor_radiance(double rho, double intensity, double h, double lx, double lz, ps_vec3 p)
{
    double dx = p.x - lx, dz = p.z - lz;
    return rho * PS_INV_PI * intensity * h / pow(h * h + dx * dx + dz * dz, 1.5);
}

#endif
