/* world.h: a scene with its accelerator, answering "what does this ray hit"
 * with everything shading needs (point, normals, material, object).
 *
 * Shared by the photon tracer and the reference renderer so that both see the
 * same surfaces, the same normals and the same self-intersection offset. */
#ifndef PS_PHOTON_WORLD_H
#define PS_PHOTON_WORLD_H

#include <stdbool.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/status.h"
#include "core/vec.h"
#include "scene/scene.h"

typedef struct ps_world ps_world;

/* Where a ray met a surface. */
typedef struct ps_surface {
    double t;         /* ray parameter */
    ps_vec3 p;        /* the point */
    ps_vec3 ng;       /* unit geometric normal: triangle winding, sphere outward */
    ps_vec3 ns;       /* unit shading normal (interpolated vertex normals), same side as ng */
    uint32_t prim;    /* accelerator primitive id */
    uint32_t object;  /* scene object index */
    uint32_t material;
    uint32_t triangle; /* the scene triangle, UINT32_MAX on a sphere */
    double b1, b2;     /* triangles: barycentric weights of corners 1 and 2 */
} ps_surface;

/* The material at sp with its albedo there (ps_scene_albedo_at): the
 * scene's own material when it has no texture, else a copy in *scratch
 * with the textured albedo. */
static inline const ps_material *ps_surface_material(const ps_scene *s, const ps_material *materials,
                                                     const ps_surface *sp, ps_material *scratch)
{
    const ps_material *m = &materials[sp->material];
    if (m->texture == 0)
        return m;
    *scratch = *m;
    scratch->albedo = ps_scene_albedo_at(s, m, sp->triangle, sp->b1, sp->b2);
    return scratch;
}

/* Builds the accelerator over s (which must outlive the world). opt may be NULL. */
ps_status ps_world_create(const ps_scene *s, const ps_accel_options *opt, ps_world **out, ps_error *err);
void ps_world_destroy(ps_world *w);

const ps_scene *ps_world_scene(const ps_world *w);
const ps_accel *ps_world_accel(const ps_world *w);

/* The offset that keeps a ray leaving a surface from hitting that surface
 * again: scaled with the scene's size (ps_accel_epsilon), never a fixed value. */
double ps_world_epsilon(const ps_world *w);

/* The nearest surface along r with t in (0, tmax). */
bool ps_world_intersect(const ps_world *w, ps_ray r, double tmax, ps_surface *out);

/* Whether anything lies on r with t in (0, tmax): a shadow ray. */
bool ps_world_occluded(const ps_world *w, ps_ray r, double tmax);

/* A ray leaving surface point sp in direction dir: its origin is pushed off
 * the surface along the geometric normal, to the side dir goes. */
ps_ray ps_world_spawn(const ps_world *w, const ps_surface *sp, ps_vec3 dir);

#endif
