/* obj.h: Wavefront OBJ + MTL loading (through tinyobjloader) into plain arrays.
 *
 * tinyobjloader does the parsing proper, behind a C interface
 * (obj_tinyobj.cpp), but it is lenient where we must not be: it turns "nan" into
 * 0, only warns about out-of-range indices and reports no line numbers for most
 * problems. obj.c therefore pre-scans the files and rejects what tinyobjloader
 * would accept silently, with "file:line: problem" messages. */
#ifndef PS_SCENE_OBJ_H
#define PS_SCENE_OBJ_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"

#define PS_OBJ_NAME_MAX 128
#define PS_OBJ_PATH_MAX 1024

/* One MTL material, with what the scene mapping needs (contract: MTL mapping). */
typedef struct ps_obj_material {
    char name[PS_OBJ_NAME_MAX];
    double kd[3], ks[3], ke[3];
    double ns, ni;
    int illum;
    int has_ns, has_ni; /* tinyobjloader silently defaults both to 1 */
    char map_kd[PS_OBJ_PATH_MAX]; /* map_Kd's file as the MTL names it (options dropped), or "" */
} ps_obj_material;

/* A triangulated mesh. Polygons are split into fans around their first vertex
 * (exact for the convex faces that exporters write). */
typedef struct ps_obj_mesh {
    size_t position_count; /* xyz triples in positions */
    double *positions;
    size_t normal_count; /* xyz triples in normals */
    double *normals;
    size_t triangle_count;
    int32_t *tri_v;   /* 3 per triangle: indices into positions */
    int32_t *tri_n;   /* 3 per triangle: indices into normals, or -1 */
    size_t texcoord_count; /* uv pairs in texcoords (OBJ vt) */
    double *texcoords;
    int32_t *tri_t;   /* 3 per triangle: indices into texcoords, or -1 */
    int32_t *tri_mat; /* 1 per triangle: index into materials, or -1 (none given) */
    size_t material_count;
    ps_obj_material *materials;
} ps_obj_mesh;

/* Loads path (and the MTL files it names, searched beside it). Errors: missing,
 * unreadable or non-regular file; malformed or non-finite numbers; face
 * indices out of range; no triangle at all. Warnings (through warn): a missing
 * MTL file, an undefined usemtl name, faces with fewer than 3 vertices. On
 * error *out is left empty. */
ps_status ps_obj_load(const char *path, ps_obj_mesh *out, const ps_warn_sink *warn, ps_error *err);

/* Frees the arrays of m and zeroes it (m may be zeroed already). */
void ps_obj_free(ps_obj_mesh *m);

/* Internal: the tinyobjloader call, implemented in C++, on texts the pre-scan
 * has checked (mtl_text: every MTL library named, concatenated). Fills out
 * with malloc'd arrays; returns 0 on success, else writes a one-line reason
 * into msg. Never lets an exception escape. */
int ps_tinyobj_parse(const char *obj_text, size_t obj_len, const char *mtl_text, size_t mtl_len, ps_obj_mesh *out,
                     char *msg, size_t msg_size);

#endif
