/* world.c: ray queries against the scene's accelerator, resolved to surfaces. */
#include "photon/world.h"

#include <stdlib.h>

struct ps_world {
    const ps_scene *scene;
    ps_accel *accel;
    uint32_t *sphere_objects; /* accelerator sphere k -> scene object */
    size_t triangle_count;
    double epsilon;
};

ps_status ps_world_create(const ps_scene *s, const ps_accel_options *opt, ps_world **out, ps_error *err)
{
    *out = NULL;
    ps_world *w = calloc(1, sizeof *w);
    if (!w)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the world", ps_scene_path(s));
    w->scene = s;
    ps_status st = ps_accel_build_scene(s, opt, &w->accel, &w->sphere_objects, err);
    if (st != PS_OK) {
        free(w);
        return st;
    }
    w->triangle_count = ps_accel_triangle_count(w->accel);
    w->epsilon = ps_accel_epsilon(w->accel);
    *out = w;
    return PS_OK;
}

void ps_world_destroy(ps_world *w)
{
    if (!w)
        return;
    ps_accel_destroy(w->accel);
    free(w->sphere_objects);
    free(w);
}

const ps_scene *ps_world_scene(const ps_world *w) { return w->scene; }
const ps_accel *ps_world_accel(const ps_world *w) { return w->accel; }
double ps_world_epsilon(const ps_world *w) { return w->epsilon; }

bool ps_world_intersect(const ps_world *w, ps_ray r, double tmax, ps_surface *out)
{
    ps_hit h;
    if (!ps_accel_intersect(w->accel, r, 0.0, tmax, &h))
        return false;
    out->t = h.t;
    out->p = ps_ray_at(r, h.t);
    out->prim = h.prim;
    if (h.prim < w->triangle_count) {
        size_t n;
        const ps_triangle *tri = &ps_scene_triangles(w->scene, &n)[h.prim];
        const ps_vec3 *normals = ps_scene_normals(w->scene, &n);
        out->ng = ps_scene_triangle_normal(w->scene, h.prim);
        out->ns = out->ng;
        if (tri->n[0] >= 0 && tri->n[1] >= 0 && tri->n[2] >= 0) {
            double b0 = 1.0 - h.b1 - h.b2;
            ps_vec3 ns = ps_v3_add(ps_v3_add(ps_v3_scale(normals[tri->n[0]], b0), ps_v3_scale(normals[tri->n[1]], h.b1)),
                                   ps_v3_scale(normals[tri->n[2]], h.b2));
            ns = ps_v3_norm(ns);
            /* Vertex normals may disagree with the winding; the shading normal
             * must name the same side as the geometric one. */
            if (ps_v3_len2(ns) > 0.0)
                out->ns = ps_v3_dot(ns, out->ng) < 0.0 ? ps_v3_neg(ns) : ns;
        }
        out->object = tri->object;
        out->material = tri->material;
        out->triangle = h.prim;
        out->b1 = h.b1;
        out->b2 = h.b2;
    } else {
        size_t n;
        uint32_t obj = w->sphere_objects[h.prim - w->triangle_count];
        const ps_object *o = &ps_scene_objects(w->scene, &n)[obj];
        out->ng = ps_v3_norm(ps_v3_sub(out->p, o->center));
        out->ns = out->ng;
        out->object = obj;
        out->material = o->material;
        out->triangle = UINT32_MAX;
        out->b1 = out->b2 = 0.0;
    }
    return true;
}

bool ps_world_occluded(const ps_world *w, ps_ray r, double tmax) { return ps_accel_occluded(w->accel, r, 0.0, tmax); }

ps_ray ps_world_spawn(const ps_world *w, const ps_surface *sp, ps_vec3 dir)
{
    double side = ps_v3_dot(dir, sp->ng) >= 0.0 ? w->epsilon : -w->epsilon;
    return ps_ray_make(ps_v3_madd(sp->p, sp->ng, side), dir);
}
