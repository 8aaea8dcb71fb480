/* scene_internal.h: the layout of ps_scene, shared by scene.c (storage) and
 * scene_parse.c (the .scn reader) only. */
#ifndef PS_SCENE_SCENE_INTERNAL_H
#define PS_SCENE_SCENE_INTERNAL_H

#include <string.h>

#include "core/array.h"
#include "scene/scene.h"

/* A growable array: items, count, capacity. */
#define PS_VEC(T) struct { T *items; size_t count, cap; }

/* What ps_scene_write needs to write the scene back as statements that load
 * to the same numbers (scene_write.c): the statements in file order, what each
 * mesh, quad and light was written with, and the edits made to meshes and
 * quads since (moves and emissive-mesh powers), which a saved file replays in
 * order: x + d1 + d2 is not x + (d1 + d2), so a sum would not be the same
 * scene. Strings are offsets into `strings` (NUL-terminated), so that a clone
 * copies flat arrays only; PS_SOURCE_NONE for none. */
#define PS_SOURCE_NONE UINT32_MAX
/* What the loader names the material of surfaces that name none. */
#define PS_DEFAULT_MATERIAL_NAME "(default)"

typedef enum ps_stmt_kind { PS_STMT_MATERIAL, PS_STMT_OBJECT, PS_STMT_LIGHT } ps_stmt_kind;

typedef struct ps_scene_stmt {
    ps_stmt_kind kind;
    uint32_t index; /* into materials, objects or lights */
} ps_scene_stmt;

typedef struct ps_object_source {
    uint32_t file;            /* mesh: the OBJ's absolute path */
    uint32_t keys;            /* mesh: its keys as written (material, scale, rotate, translate) */
    uint32_t first_light;     /* mesh: index of its first emissive light */
    ps_vec3 corner, edge1, edge2; /* quad: as written */
} ps_object_source;

typedef struct ps_light_source {
    uint32_t file;  /* ies: the file's absolute path */
    ps_vec3 dir;    /* spot direction, disc normal, ies aim: as written (unnormalised) */
} ps_light_source;

typedef struct ps_scene_edit {
    uint32_t object;
    uint32_t light; /* PS_SOURCE_NONE: a move by v; else that mesh light's power set to v */
    ps_vec3 v;
} ps_scene_edit;

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
    /* The source (see above): obj_src parallel to objects, light_src to lights. */
    PS_VEC(ps_scene_stmt) stmts;
    PS_VEC(ps_object_source) obj_src;
    PS_VEC(ps_light_source) light_src;
    PS_VEC(ps_scene_edit) edits;
    PS_VEC(char) strings;
};

/* The absolute form of path (realpath when it exists, else joined to the
 * current directory), malloc'd; NULL when out of memory. */
char *ps_scene_abs_path(const char *path);

/* Appends a NUL-terminated copy of text to s->strings: its offset, or
 * PS_SOURCE_NONE when out of memory. */
uint32_t ps_scene_add_string(ps_scene *s, const char *text);
static inline const char *ps_scene_string(const ps_scene *s, uint32_t at)
{
    return at == PS_SOURCE_NONE ? NULL : s->strings.items + at;
}

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
