/* mesh.h: the scene as flat triangle arrays for OpenGL, fine enough that
 * per-vertex (Gouraud) lighting matches the reference renderer.
 *
 * Fixed-function GL evaluates lights only at vertices and interpolates
 * between them, so a 2 m wall drawn as two triangles would show the inverse-
 * square falloff of a point light as a linear ramp. Every triangle is
 * therefore cut into n x n similar ones with no edge longer than max_edge
 * (the interpolation error of I h / (h^2 + x^2)^(3/2) shrinks with the edge
 * squared: about 0.1 % at a twentieth of the light's height), and spheres are
 * tessellated within a sagitta tolerance. GL-free, so it is tested without a
 * context; src/gl draws it. */
#ifndef PS_PREVIEW_MESH_H
#define PS_PREVIEW_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"
#include "scene/scene.h"

/* Subdivision stops here whatever max_edge asks: 2 * 256^2 triangles a face. */
#define PS_MESH_MAX_SPLIT 256

/* What a vertex is planned at against the memory budget: its float position
 * and normal, twice (the arrays grow by doubling), and its shared index; its
 * texture coordinates too when the scene has textures. */
#define PS_MESH_PLAN_VERTEX_BYTES (2 * 6 * sizeof(float) + sizeof(uint32_t))
#define PS_MESH_PLAN_UV_BYTES (2 * 2 * sizeof(float))

/* ---- tiles: a range's triangles regrouped by place ---------------------------- */

/* A shadowed lit pass draws only what lies in one cube face's pyramid of a
 * light (src/gl), and a whole range was drawn wherever any of it did: a
 * Cornell wall lies in two or three pyramids, and each drew all of it.
 * Tiles let the pass skip the parts outside. */
typedef struct ps_mesh_tile {
    ps_aabb bounds;      /* of its triangles' vertices */
    size_t first, count; /* into the tiling's indices, 3 a triangle */
} ps_mesh_tile;

typedef struct ps_mesh_tiling {
    ps_mesh_tile *tiles;
    size_t tile_count;
    /* Vertex indices into the mesh's arrays (its shared ones where it has
     * them), for glDrawElements; a range's tiles are contiguous, so
     * neighbouring tiles drawn together are one run. */
    uint32_t *indices;
    size_t *range_tiles; /* range i's tiles: [range_tiles[i], range_tiles[i + 1]) */
    size_t range_count;
} ps_mesh_tiling;

/* A run of triangles of one object and one material. */
typedef struct ps_mesh_range {
    uint32_t object, material;
    size_t first, count; /* in vertices (3 per triangle) */
} ps_mesh_range;

typedef struct ps_preview_mesh {
    size_t vertex_count;  /* 3 per triangle, nothing shared: ready for glDrawArrays */
    float *positions;     /* xyz per vertex */
    float *normals;       /* unit xyz per vertex, on the side of the winding's normal */
    /* GL texture coordinates (s, t) per vertex when the scene has textures,
     * else NULL: s = u, t = 1 - v, for textures uploaded top row first (the
     * OBJ's v = 0 is the image's bottom); (0, 0) where a face has none. */
    float *texcoords;
    /* For each vertex the first one of its range with the same position and
     * normal, bit for bit: indices for glDrawElements of what lighting sees
     * (GL's vertex stage then lights each shared vertex once, not once a
     * triangle: the default scene's fine mesh has 143 070 vertices, 6x
     * fewer distinct; the same pixels, as every copy is the same input).
     * Not for per-triangle attributes (texcoords of a seam, the
     * illumination maps' colours). */
    uint32_t *shared;
    ps_mesh_range *ranges;
    size_t range_count;
    /* Its ranges in tiles (ps_mesh_make_tiles), where the session made them
     * (the fine mesh, for the shadowed lit passes); tile_count 0: none. */
    ps_mesh_tiling tiles;
} ps_preview_mesh;

typedef struct ps_mesh_options {
    double max_edge;         /* longest edge after subdivision (scene units, > 0) */
    double sphere_tolerance; /* sagitta / radius for spheres (tessellate.h) */
} ps_mesh_options;

/* max_edge a 64th of the scene's bounding-box diagonal, spheres at the
 * tessellation default. */
ps_mesh_options ps_mesh_default_options(const ps_scene *s);

/* The lit mesh of a level of detail (preview/session.h: a moving camera's,
 * and the lights' coarse levels', ps_session_lights_coarse):
 * flat faces cut with edges PS_MESH_MOVING_EDGE_SCALE times longer, a
 * quarter of their vertices (llvmpipe's lit passes are vertex-bound: the
 * default scene's lit pass, its mirror and glass left out, took 8.9 ms of a
 * moving frame on the fine mesh, 3.0 ms on this one, medians of an orbit),
 * for 4x the interpolation error (about 0.4 % where the fine
 * mesh's 0.1 % is, above) in a picture drawn at half the pixels a side
 * while it moves. Spheres as fine: the depth prepass draws their tessellation
 * (the coarse mesh), and a coarser one would lie behind it, unlit. */
#define PS_MESH_MOVING_EDGE_SCALE 2.0
ps_mesh_options ps_mesh_moving_options(const ps_mesh_options *fine);

/* The vertices ps_preview_mesh_build would make, counted without building. */
uint64_t ps_preview_mesh_vertex_count(const ps_scene *s, const ps_mesh_options *o);

/* Refuses (PS_ERR_LIMIT) a mesh that would not fit in the memory budget
 * (core/memory.h), counted before anything is allocated. */
ps_status ps_preview_mesh_build(const ps_scene *s, const ps_mesh_options *o, ps_preview_mesh *out, ps_error *err);
void ps_preview_mesh_free(ps_preview_mesh *m); /* and zero it; accepts a zeroed one */


/* About this many triangles a tile: a Cornell wall of the default scene's
 * fine mesh in some 20 tiles. */
#define PS_MESH_TILE_TRIANGLES 256

/* Each range's triangles binned by centroid into a grid over the range's
 * bounds (cells as square as its extents allow, about
 * triangles_per_tile triangles a cell; its flat axes not cut), in their
 * order within a cell; every triangle in exactly one tile, empty cells
 * left out. A range of at most triangles_per_tile triangles is one tile. */
ps_status ps_mesh_make_tiles(const ps_preview_mesh *m, size_t triangles_per_tile, ps_mesh_tiling *out, ps_error *err);
void ps_mesh_tiling_free(ps_mesh_tiling *t); /* and zero it; accepts a zeroed one */

#endif
