/* tessellate.h: triangle meshes of analytic spheres, for OpenGL only.
 *
 * The ray tracers intersect spheres exactly; the preview must draw them as
 * triangles, and the finer those are, the closer the two pictures. The mesh is
 * chosen by the largest distance allowed between the true sphere and a
 * triangle (the sagitta), relative to the radius. */
#ifndef PS_SCENE_TESSELLATE_H
#define PS_SCENE_TESSELLATE_H

#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"

/* The preview's default: 0.1 % of the radius, about 5000 triangles a sphere. */
#define PS_SPHERE_DEFAULT_TOLERANCE 1e-3

typedef struct ps_trimesh {
    uint32_t vertex_count;
    ps_vec3 *positions;
    ps_vec3 *normals; /* unit, per vertex */
    uint32_t triangle_count;
    uint32_t *indices; /* 3 per triangle, counter-clockwise seen from outside */
} ps_trimesh;

/* A latitude-longitude sphere whose triangles lie within tolerance * radius of
 * the true surface (tolerance in (0, 0.5]); poles are single vertices, so the
 * mesh is closed and every edge is shared by exactly two triangles. */
ps_status ps_sphere_tessellate(ps_vec3 center, double radius, double tolerance, ps_trimesh *out, ps_error *err);

/* How many triangles ps_sphere_tessellate makes for this tolerance (0 when
 * it is out of range): what a caller checks against memory first. */
uint32_t ps_sphere_triangle_count(double tolerance);

/* Frees and zeroes m (m may be zeroed already). */
void ps_trimesh_free(ps_trimesh *m);

#endif
