/* scene_internal.h: the layout of ps_scene, shared by scene.c (storage) and
 * scene_parse.c (the .scn reader) only. */
#ifndef PS_SCENE_SCENE_INTERNAL_H
#define PS_SCENE_SCENE_INTERNAL_H

#include <string.h>

#include "core/array.h"
#include "scene/scene.h"

/* A growable array: items, count, capacity. */
#define PS_VEC(T) struct { T *items; size_t count, cap; }

struct ps_scene {
    char *path;
    ps_camera camera;
    ps_scene_defaults defaults;
    ps_aabb bounds;
    PS_VEC(ps_material) materials;
    PS_VEC(ps_vec3) positions;
    PS_VEC(ps_vec3) normals;
    PS_VEC(ps_triangle) triangles;
    PS_VEC(ps_object) objects;
    PS_VEC(ps_light) lights;
    PS_VEC(uint32_t) emitters;
    PS_VEC(struct ps_ies *) profiles; /* owned: the IES lights' tables */
};

/* Appends one zeroed item to a PS_VEC, returning it, or NULL when out of memory. */
#define PS_VEC_PUSH(vec)                                                                                  \
    (PS_RESERVE((vec).items, (vec).cap, (vec).count + 1)                                                 \
         ? (memset(&(vec).items[(vec).count], 0, sizeof *(vec).items), &(vec).items[(vec).count++])       \
         : NULL)

ps_scene *ps_scene_alloc(void);
/* Recomputes one object's bounds and specular flag from its geometry. */
void ps_scene_update_object(ps_scene *s, uint32_t index);
/* Recomputes every object's bounds and flags, and the scene's bounds. */
void ps_scene_finish(ps_scene *s);

#endif
