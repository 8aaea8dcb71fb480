/* specular.h: the `specular` layer's lookups, GL-free: what mirrors and glass
 * show, as per-vertex directions into environment cube maps with Fresnel
 * weights (issue 15; Larsen & Christensen, section 6, draw specular
 * reflections from a dynamic environment cube map).
 *
 * Every mirror or dielectric object of the session's fine mesh gets a cube
 * map rendered by src/gl (gl_specular.c) from its centre (the centre of its
 * vertices' bounding box), showing the other layers of the scene around it
 * with every mirror and glass object left out. For each vertex of such an
 * object the eye ray is traced on the CPU with the project's own geometry
 * (ps_world) and Fresnel code (scene/bsdf.h), as the reference renderer's
 * eye paths do: mirror reflection, Fresnel reflection and refraction, total
 * internal reflection, the exit through the far side of the glass, other
 * mirrors and glass objects on the way, up to PS_SPECULAR_MAX_DEPTH
 * surfaces. Each path ends on a diffuse or glossy surface at a point P (or
 * leaves the scene); its lookup direction is P - centre, the direction in
 * which the cube map sees that very point (a distance-corrected lookup: a
 * plain reflection-map lookup would assume the environment infinitely far).
 * The weight is the product of the reflectances, Fresnel factors and tints
 * on the way. A vertex keeps its PS_SPECULAR_TERMS heaviest paths; the
 * weight of the others is added to the kept path nearest in direction, so
 * that no energy is lost (a furnace stays at 1).
 *
 * Departures, said where they show (docs/preview.md): the cube map shows P
 * only if nothing diffuse lies between the centre and P; the per-vertex
 * lookups are interpolated over the mesh's triangles (Gouraud), which is why
 * a still camera gets per-pixel paths instead (below); area lights are seen in
 * the cube map as the direct layer draws them, point and spot lights not at
 * all (as in photosplat-ref). Glossy objects are in the set too, each with a
 * cube of its own and one lookup a vertex along its mirror direction into a
 * blurred level (preview/specular_glossy.h). */
#ifndef PS_PREVIEW_SPECULAR_H
#define PS_PREVIEW_SPECULAR_H

#include <stdbool.h>
#include <stddef.h>

#include "core/status.h"
#include "core/vec.h"
#include "photon/world.h"
#include "preview/mesh.h"
#include "scene/camera.h"
#include "scene/scene.h"

/* Lookups a vertex: each one a drawing pass of the object. */
#define PS_SPECULAR_TERMS 4
/* Surfaces one eye path meets at most (the reference's own bound is 16;
 * past 8 mirror or glass bounces little weight is left). */
#define PS_SPECULAR_MAX_DEPTH 16
/* Paths with less weight than this (of a unit eye ray) are not followed. */
#define PS_SPECULAR_MIN_WEIGHT 1e-4
/* Paths collected a vertex before the heaviest are kept. */
#define PS_SPECULAR_MAX_PATHS 64
/* Cube maps at most; objects past these share the nearest cube. */
#define PS_SPECULAR_MAX_CUBES 8

typedef struct ps_specular ps_specular;

/* One mesh range drawn with the lookups. */
typedef struct ps_specular_range {
    size_t range;     /* index into the mesh's ranges */
    size_t offset;    /* its first vertex in the lookup arrays */
    int cube;         /* the cube map it looks up */
} ps_specular_range;

/* The mirror and dielectric ranges of `mesh` (materials indexed by its
 * ranges), their cube maps' centres; no lookups yet. A mesh with none gives
 * a set of 0 ranges. mesh and materials must outlive it. */
ps_status ps_specular_create(const ps_preview_mesh *mesh, const ps_material *materials, ps_specular **out,
                             ps_error *err);
void ps_specular_destroy(ps_specular *sp); /* accepts NULL */

size_t ps_specular_range_count(const ps_specular *sp);
const ps_specular_range *ps_specular_ranges(const ps_specular *sp);
int ps_specular_cube_count(const ps_specular *sp);
ps_vec3 ps_specular_cube_centre(const ps_specular *sp, int cube);
/* Where cube's lookups look from: the centre its shown map was rendered
 * from. Until set, the cube's centre; after an edit that moved the object,
 * the old centre until a map from the new one is whole (src/gl keeps the
 * map it shows until then), so that the lookups find in the old map the
 * very points the eye paths end at, not the same directions from elsewhere
 * (the default scene's mirror moved 10 cm showed its reflections shifted
 * for the seconds a new map took). Paths are traced from the cube's own
 * centre (which decides how the lightest are merged, below) and keep where
 * they end, so a new lookup centre re-aims the cube's lookups and per-pixel
 * points without tracing anything: the same bytes as tracing them afresh
 * from it (the swap to a new map used to throw the per-pixel paths away,
 * and the mirror showed per-vertex lookups for another 0.7 s). */
ps_vec3 ps_specular_lookup_centre(const ps_specular *sp, int cube);
/* Whether that changed the centre (and so the lookups were re-aimed). */
bool ps_specular_set_lookup_centre(ps_specular *sp, int cube, ps_vec3 centre);
/* Threads the lookups and per-pixel paths are traced on (1 by default,
 * values below 1 as 1): the same bytes for any count. */
void ps_specular_set_threads(ps_specular *sp, int threads);

/* Traces the lookups for an eye at `eye` through `world` (the session's:
 * the same surfaces as the mesh), at most max_vertices distinct vertices
 * this call (0: all). A new eye starts over; the vertices not traced again
 * yet keep their last lookups. Returns how many distinct vertices are left
 * for this eye (0: all done). Deterministic: a vertex's lookups depend only
 * on the scene and the eye. */
size_t ps_specular_update(ps_specular *sp, const ps_world *world, ps_vec3 eye, size_t max_vertices);
/* Whether the lookups have changed since the last ps_specular_take_changed. */
bool ps_specular_take_changed(ps_specular *sp);
/* Every vertex traced again at the next update (geometry or materials moved). */
void ps_specular_invalidate(ps_specular *sp);

/* Lookup term k (< PS_SPECULAR_TERMS) of the lookup arrays' vertices, in
 * the ranges' order from their offsets: an xyz direction from the cube's
 * centre, and an rgb weight (0 where a vertex has fewer paths). */
const float *ps_specular_dirs(const ps_specular *sp, int k);
const float *ps_specular_weights(const ps_specular *sp, int k);
/* The triangles (vertices 3t, 3t + 1, 3t + 2 of `vertices`) that one term's
 * rgb weights (3 floats a vertex) give any light: an index list of their
 * vertices into out (room for `vertices`), its length returned. The rest add
 * 0 to the layer at every pixel: most of a term past the first (a mirror's
 * vertices have one path; vertices facing away from the eye none), which
 * llvmpipe's passes, bound by vertices, would transform for nothing. */
size_t ps_specular_weighted_triangles(const float *weights, size_t vertices, unsigned *out);

/* ---- per-pixel eye paths ------------------------------------------------------ */

/* The lookups above are interpolated over the mesh's triangles, which bends
 * what refraction through a curved glass shows and what a sphere's mirror
 * shows past a reflected edge, and leaves a silhouette's pixels all or
 * nothing where the reference averages 16 samples. Once the camera holds
 * still, each pixel that an object of the layer may cover (near one of its
 * triangles: each one's projected rectangle, a little wider) is traced on
 * the CPU instead, PS_SPECULAR_PIXEL_SAMPLES^2 stratified eye rays a pixel
 * through the exact surfaces, each path ending as above; every kept path of
 * every sample is one point of the layer: its pixel, its lookup direction
 * and its weight over the samples a pixel (a box filter; the reference's
 * Mitchell filter is wider by a pixel). src/gl draws those points instead of
 * the objects once a camera frame is traced whole. */
#define PS_SPECULAR_PIXEL_SAMPLES 2
/* Eye rays a refresh in incremental sessions (the window), at most, and
 * the share of tau they may take (a guard: at half of tau the sanitizer
 * build's window had not traced a 128^2 view's spheres by the picture
 * cli_window.sh compares with snap's): the default scene's spheres at 512^2 take
 * about 2.7 10^5 rays, 65 536 of them 0.33 s on the loaded 2-core machine
 * (several times that in the sanitizer build), so a still view shows
 * per-pixel paths after some 17 refreshes or more (the per-vertex lookups
 * until then), or at once where few rays are left (the session's
 * PS_SESSION_PIXEL_RAYS_WHOLE). */
#define PS_SPECULAR_PIXEL_RAYS 16384
#define PS_SPECULAR_PIXEL_TIME_SHARE 2.0

/* Traces at most max_rays eye rays (0: all) of camera frame cam's pixels,
 * stopping once max_seconds have gone by (0: no limit; what is traced does
 * not depend on where it stops); a new frame (or ps_specular_invalidate)
 * starts over. Returns the rays left for this frame (0: done, and the
 * points below are this frame's). */
size_t ps_specular_update_pixels(ps_specular *sp, const ps_world *world, const ps_camera_frame *cam,
                                 size_t max_rays, double max_seconds);
/* The eye rays left to trace for camera frame cam (starting it over when it
 * is new): an upper bound, 0 once its points are ready. */
size_t ps_specular_pixel_rays_left(ps_specular *sp, const ps_camera_frame *cam);
/* The points of the current camera frame, once traced whole: their count,
 * else 0 and *ready false (draw the per-vertex lookups then). xy: pixel
 * (column, row from the top); dirs: lookup direction from cube[i]'s centre;
 * weights: rgb, already divided by the samples a pixel. */
typedef struct ps_specular_points {
    bool ready;
    size_t count;
    const float *xy, *dirs, *weights;
    const int *cube;
} ps_specular_points;
ps_specular_points ps_specular_pixel_points(const ps_specular *sp);

/* ---- for tests --------------------------------------------------------------- */

/* Whether every pixel of each range's box rectangle is traced (true), not
 * only those near its triangles (false, the default): the oracle for the
 * pixels the triangles leave out. The current camera frame starts over. */
void ps_specular_set_pixel_boxes(ps_specular *sp, bool boxes);

/* One path's end: its lookup direction from `centre` (or the direction it
 * leaves in, far away, when it meets nothing) and its weight; and what the
 * direction is made of, so that it can be taken from another centre
 * (ps_specular_term_dir): where the path ends (or that far direction) and
 * its scale (0 for a path that meets nothing: then dir is end). */
typedef struct ps_specular_term {
    ps_vec3 dir;
    ps_rgb weight;
    ps_vec3 end;
    double scale;
} ps_specular_term;
/* t's lookup direction from `centre`: (end - centre) * scale, or end. */
ps_vec3 ps_specular_term_dir(const ps_specular_term *t, ps_vec3 centre);
/* The eye ray from `eye` to surface point p (normal n, on the winding's side)
 * of material m, traced as above: up to PS_SPECULAR_TERMS terms into out,
 * their count returned; *dropped: the weight of the paths cut short by depth
 * or the weight floor (not added to any term). */
int ps_specular_trace_point(const ps_world *world, const ps_material *materials, const ps_material *m, ps_vec3 eye,
                            ps_vec3 p, ps_vec3 n, ps_vec3 centre, ps_specular_term out[PS_SPECULAR_TERMS],
                            double *dropped);

#endif
