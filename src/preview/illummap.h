/* illummap.h: the global photon map as illumination maps on the surfaces
 * (issue 22), GL-free: irradiance held at the fine preview mesh's vertices,
 * filled by density estimation as photons arrive, drawn by src/gl as vertex
 * colours modulated by the albedo.
 *
 * Why: the thesis found splatted indirect light "much more splotchy than in a
 * final render" and its fill rate the frame-rate limit (5.3, 6), and proposed
 * light maps instead; Larsen & Christensen keep indirect light in light maps,
 * Dmitriev et al. on mesh vertices. Here it is on the vertices of the fine
 * preview mesh (mesh.h) for every surface: quads, spheres and OBJ meshes
 * alike. The fine mesh is already cut so that Gouraud interpolation between
 * its vertices is within about 0.1 % of a point light's falloff, so it is a
 * texture of that resolution with bilinear filtering for a quad, a (theta,
 * phi) texture for a sphere and an atlas for a mesh, without parameterising
 * anything or any texel wasted on a seam, and GL draws it with the same
 * vertex arrays as the direct layer. Departure from the texture:
 * one representation for all surfaces, documented in docs/preview.md.
 *
 * Samples. The fine mesh's vertices (3 a triangle, nothing shared) are
 * welded into samples: same object, position and normal to within
 * PS_ILLUM_WELD_FRACTION of the scene's diagonal. Each sample carries the
 * area A_s of a third of each triangle that uses it (a texel's true area)
 * and, for each side of its surface (surfaces are two-sided), the irradiance
 * of stored power in W m^-2.
 *
 * The estimate: a photon of power Phi on object o with normal n_p gives each
 * sample s of o within the radius r (and with |n_s . n_p| at least
 * PS_ILLUM_MIN_COS: another face of the same object is not this one) the
 * share w_s = g(d_s / r) A_s / sum_t g(d_t / r) A_t of its power, on the
 * side n_p is on; E_s = sum_p Phi_p w_s / A_s. Away from edges sum_t g A_t is
 * the kernel's integral C pi r^2 and this is the kernel estimate of thesis
 * eq. 9; at edges and corners it does not darken as a cut disc does, and the
 * maps' flux sum_s E_s A_s is exactly the photons' (a photon with no sample
 * within r is counted lost; the radius is never below the mesh's longest
 * edge, so none is on a meshed surface).
 *
 * Progressive and exact: photons are added in index order, one at a time,
 * so the map after n photons is a pure function of photons 0..n-1 whatever
 * the batches, timing or thread count. The radius follows the session's
 * schedule (ps_splat_radius_at), rounded up to a level r0 * 2^(j/2): while
 * the level holds, new photons are added to the sums; when the schedule
 * crosses into the next level the map is rebuilt from photon 0 at the new
 * radius (under the progressive schedule r^2 ~ n^-1/3, so a level lasts 8
 * times as many photons and rebuilding costs at most 1/7 more than adding
 * each photon once). Under the fixed schedule there is one level.
 *
 * Glossy surfaces: the map holds irradiance, which times albedo / pi is the
 * diffuse part of their BRDF; their photons are also kept (the lobe list)
 * to be splatted with only the glossy lobe (ps_illummap_lobe_materials), so
 * that the view-dependent highlight of indirect light stays. */
#ifndef PS_PREVIEW_ILLUMMAP_H
#define PS_PREVIEW_ILLUMMAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "photon/estimate.h"
#include "photon/photon.h"
#include "preview/mesh.h"
#include "scene/scene.h"

/* How the global layer is drawn. */
typedef enum ps_global_layer {
    PS_GLOBAL_SPLATS, /* the thesis: a splat a photon */
    PS_GLOBAL_MAPS,   /* illumination maps on the surfaces, glossy lobes still splatted */
    PS_GLOBAL_LAYER_COUNT
} ps_global_layer;
extern const char *const ps_global_layer_names[PS_GLOBAL_LAYER_COUNT + 1]; /* splats, maps */
const char *ps_global_layer_name(ps_global_layer g);

/* Vertices closer than this fraction of the scene's diagonal (and normals
 * within PS_ILLUM_WELD_NORMAL) are one sample. Two copies of one vertex that
 * fail to weld (a rounding boundary between them) are harmless: each gets the
 * same share per unit area, so the same value. */
#define PS_ILLUM_WELD_FRACTION 1e-6
#define PS_ILLUM_WELD_NORMAL 1e-3
/* A photon reaches a sample only where their normals are within this cosine
 * (either side): a box's adjacent faces are another surface. */
#define PS_ILLUM_MIN_COS 0.5
/* The cap on samples, whatever the memory budget allows: the maps' texture
 * size cap (16 M samples; the default scenes have about 10^5). */
#define PS_ILLUM_MAX_SAMPLES ((size_t)1 << 24)
/* What a fine-mesh vertex is planned at against the memory budget: its
 * sample index and three colours (front, back, the view's), and at most one sample of position, normal,
 * object, area, two sides' sums, the grid's two words and its 40-byte item. */
#define PS_ILLUM_PLAN_VERTEX_BYTES (sizeof(uint32_t) + 12 * sizeof(float) + 6 * sizeof(float) + 12 + 6 * sizeof(double) + 8 + 40)

/* The gather runs on every core in contiguous ranges of a chunk of photons
 * (at least PS_ILLUM_MIN_PHOTONS_A_THREAD each), and the shares it found are
 * summed in photon order on the calling thread: the same bytes for any
 * number of cores. On one thread each photon's shares are summed as soon as
 * they are found, in the same order. */
#define PS_ILLUM_CHUNK 16384
#define PS_ILLUM_MIN_PHOTONS_A_THREAD 1024
#define PS_ILLUM_MAX_THREADS 64

typedef struct ps_illummap ps_illummap;

/* The samples of `mesh` (the session's fine mesh, which must outlive the
 * map) for the scene's materials (those with diffuse reflection get
 * samples), the kernel g for the estimate. Refuses (PS_ERR_LIMIT) a mesh
 * over PS_ILLUM_MAX_SAMPLES or the memory budget. */
ps_status ps_illummap_create(const ps_scene *scene, const ps_preview_mesh *mesh, ps_kernel kernel, ps_illummap **out,
                             ps_error *err);
void ps_illummap_destroy(ps_illummap *m); /* accepts NULL */

/* The gather's threads (0: one a core; at most PS_ILLUM_MAX_THREADS); the
 * sums do not depend on it. PS_ERR_NOMEM leaves it as it was. */
ps_status ps_illummap_set_threads(ps_illummap *m, int threads, ps_error *err);

/* Empties the map (new photons from 0, or another kernel). */
void ps_illummap_reset(ps_illummap *m, ps_kernel kernel);

/* The radius level for a scheduled radius r (>= r): r0 * 2^(j/2), the
 * smallest such not below r, and never below the mesh's longest edge. */
double ps_illummap_level_radius(const ps_illummap *m, double r0, double r);

/* Brings the map to photons [0, count) of the global map (parallel arrays as
 * in ps_photon_map) at radius `radius` (a level radius): the photons from the
 * map's own count on are added, or, if the radius is not the map's, all of
 * them again from 0. count below the map's count (a new map) starts over too.
 * *added: the photons added (what it cost). PS_ERR_NOMEM (the lobe list or
 * the scratch could not grow) leaves the map empty. */
ps_status ps_illummap_update(ps_illummap *m, const ps_photon *photons, const uint16_t *materials,
                             const uint32_t *objects, size_t count, double radius, size_t *added, ps_error *err);

/* The photons in the map, and its radius (0 before the first photon). */
size_t ps_illummap_count(const ps_illummap *m);
double ps_illummap_radius(const ps_illummap *m);
/* Whether the map changed since the last ps_illummap_colors. */
bool ps_illummap_changed(const ps_illummap *m);

/* Samples, and the irradiance of one side of sample s (0: the side its
 * normal points to, 1: the other), W m^-2 of stored power, with its area. */
size_t ps_illummap_sample_count(const ps_illummap *m);
ps_rgb ps_illummap_irradiance(const ps_illummap *m, size_t s, int side, ps_vec3 *pos, ps_vec3 *normal, double *area);
/* The power of photons that found no sample within the radius. */
ps_rgb ps_illummap_lost(const ps_illummap *m);

/* The albedo the map is modulated by: the diffuse part of a diffuse or
 * glossy material, zero for others (the one place the maps' colour takes the
 * material; a textured albedo would multiply here, or in GL_MODULATE). */
ps_rgb ps_illummap_albedo(const ps_material *mat);

/* Per fine-mesh vertex RGBA colours, front (the winding's side) and back:
 * E * albedo / pi * scale (radiance of a Lambertian surface, as splats show
 * it), the materials indexed by the mesh's ranges. Arrays owned by the map,
 * valid until the next call or destroy. Clears the changed flag. */
void ps_illummap_colors(ps_illummap *m, const ps_material *materials, double scale, const float **front,
                        const float **back);
/* One RGBA a vertex for a view from eye: each triangle takes the colours of
 * the side the eye sees (the front's where (eye - p0) . ((p1 - p0) x (p2 -
 * p0)) > 0, the face GL culls as front with GL_CCW, else the back's), from
 * the last ps_illummap_colors. So GL draws both sides in one pass. Owned by
 * the map; only the spans' vertices are set (the others are not drawn). */
const float *ps_illummap_view_colors(ps_illummap *m, ps_vec3 eye);

/* A run of fine-mesh vertices, [first, first + count). */
typedef struct ps_illum_span {
    size_t first, count;
} ps_illum_span;
/* The runs of fine-mesh vertices on surfaces with samples (those with
 * diffuse reflection), in order, neighbouring ranges joined: all that the
 * maps colour. The rest (mirrors, glass) are black in the maps, so drawing
 * them adds nothing, and costs: the default box's spheres are 41 % of its
 * fine mesh's vertices. Owned by the map. */
size_t ps_illummap_spans(const ps_illummap *m, const ps_illum_span **spans);

/* The lobe list: the photons (of those added) on glossy surfaces, as
 * parallel arrays for ps_splat_build. */
size_t ps_illummap_lobe(const ps_illummap *m, const ps_photon **photons, const uint16_t **materials,
                        const uint32_t **objects);
/* materials with each glossy one's diffuse albedo zeroed (the maps show it),
 * into out (n entries): what the lobe splats are built with. */
void ps_illummap_lobe_materials(const ps_material *materials, size_t n, ps_material *out);

#endif
