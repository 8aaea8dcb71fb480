/* scene.c: scene storage, accessors and derived quantities. */
#include "scene/scene_internal.h"

#include <stdlib.h>
#include <string.h>

ps_scene *ps_scene_alloc(void)
{
    ps_scene *s = calloc(1, sizeof *s);
    if (s)
        s->bounds = ps_aabb_empty();
    return s;
}

void ps_scene_destroy(ps_scene *s)
{
    if (!s)
        return;
    free(s->path);
    free(s->materials.items);
    free(s->positions.items);
    free(s->normals.items);
    free(s->triangles.items);
    free(s->objects.items);
    free(s->lights.items);
    free(s->emitters.items);
    free(s);
}

const char *ps_scene_path(const ps_scene *s) { return s->path; }
const ps_camera *ps_scene_camera(const ps_scene *s) { return &s->camera; }
const ps_scene_defaults *ps_scene_get_defaults(const ps_scene *s) { return &s->defaults; }
ps_aabb ps_scene_bounds(const ps_scene *s) { return s->bounds; }

#define VIEW(field)                                                                                       \
    do {                                                                                                  \
        if (count)                                                                                        \
            *count = s->field.count;                                                                      \
        return s->field.items;                                                                            \
    } while (0)

const ps_material *ps_scene_materials(const ps_scene *s, size_t *count) { VIEW(materials); }
const ps_vec3 *ps_scene_positions(const ps_scene *s, size_t *count) { VIEW(positions); }
const ps_vec3 *ps_scene_normals(const ps_scene *s, size_t *count) { VIEW(normals); }
const ps_triangle *ps_scene_triangles(const ps_scene *s, size_t *count) { VIEW(triangles); }
const ps_object *ps_scene_objects(const ps_scene *s, size_t *count) { VIEW(objects); }
const ps_light *ps_scene_lights(const ps_scene *s, size_t *count) { VIEW(lights); }
const uint32_t *ps_scene_emitters(const ps_scene *s, size_t *count) { VIEW(emitters); }

static ps_vec3 tri_cross(const ps_scene *s, uint32_t t)
{
    const ps_triangle *tr = &s->triangles.items[t];
    ps_vec3 p0 = s->positions.items[tr->v[0]];
    return ps_v3_cross(ps_v3_sub(s->positions.items[tr->v[1]], p0), ps_v3_sub(s->positions.items[tr->v[2]], p0));
}

double ps_scene_triangle_area(const ps_scene *s, uint32_t t) { return 0.5 * ps_v3_len(tri_cross(s, t)); }
ps_vec3 ps_scene_triangle_normal(const ps_scene *s, uint32_t t) { return ps_v3_norm(tri_cross(s, t)); }

ps_rgb ps_scene_total_power(const ps_scene *s)
{
    ps_rgb sum = ps_rgb_gray(0.0);
    for (size_t i = 0; i < s->lights.count; i++)
        sum = ps_rgb_add(sum, s->lights.items[i].power);
    return sum;
}

static ps_aabb light_bounds(const ps_light *l)
{
    ps_aabb b = ps_aabb_point(ps_aabb_empty(), l->position);
    switch (l->type) {
    case PS_LIGHT_QUAD:
        b = ps_aabb_point(b, ps_v3_add(l->position, l->edge1));
        b = ps_aabb_point(b, ps_v3_add(l->position, l->edge2));
        b = ps_aabb_point(b, ps_v3_add(ps_v3_add(l->position, l->edge1), l->edge2));
        break;
    case PS_LIGHT_SPHERE:
    case PS_LIGHT_DISC: {
        ps_vec3 r = ps_v3(l->radius, l->radius, l->radius);
        b.lo = ps_v3_sub(l->position, r);
        b.hi = ps_v3_add(l->position, r);
        break;
    }
    default:
        break; /* point, spot: the position; mesh: covered by its object */
    }
    return b;
}

void ps_scene_update_object(ps_scene *s, uint32_t index)
{
    ps_object *obj = &s->objects.items[index];
    if (obj->type == PS_OBJ_SPHERE) {
        ps_vec3 r = ps_v3(obj->radius, obj->radius, obj->radius);
        obj->bounds.lo = ps_v3_sub(obj->center, r);
        obj->bounds.hi = ps_v3_add(obj->center, r);
        obj->specular = ps_material_is_specular(&s->materials.items[obj->material]);
        return;
    }
    obj->bounds = ps_aabb_empty();
    obj->specular = 0;
    for (uint32_t t = obj->first_triangle; t < obj->first_triangle + obj->triangle_count; t++) {
        const ps_triangle *tr = &s->triangles.items[t];
        for (int c = 0; c < 3; c++)
            obj->bounds = ps_aabb_point(obj->bounds, s->positions.items[tr->v[c]]);
        obj->specular |= ps_material_is_specular(&s->materials.items[tr->material]);
    }
}

void ps_scene_finish(ps_scene *s)
{
    ps_aabb all = ps_aabb_empty();
    for (size_t o = 0; o < s->objects.count; o++) {
        ps_scene_update_object(s, (uint32_t)o);
        all = ps_aabb_union(all, s->objects.items[o].bounds);
    }
    for (size_t i = 0; i < s->lights.count; i++)
        all = ps_aabb_union(all, light_bounds(&s->lights.items[i]));
    s->bounds = all;
}

const char *ps_material_type_name(ps_material_type t)
{
    switch (t) {
    case PS_MAT_DIFFUSE: return "diffuse";
    case PS_MAT_GLOSSY: return "glossy";
    case PS_MAT_MIRROR: return "mirror";
    case PS_MAT_DIELECTRIC: return "dielectric";
    }
    return "?";
}

const char *ps_light_type_name(ps_light_type t)
{
    switch (t) {
    case PS_LIGHT_POINT: return "point";
    case PS_LIGHT_SPOT: return "spot";
    case PS_LIGHT_QUAD: return "quad";
    case PS_LIGHT_SPHERE: return "sphere";
    case PS_LIGHT_DISC: return "disc";
    case PS_LIGHT_MESH: return "mesh";
    }
    return "?";
}
