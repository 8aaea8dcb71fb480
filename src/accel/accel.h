/* accel.h: the ray-intersection accelerator: an octree over triangles and
 * analytic spheres, traversed with the parametric algorithm of Revelles,
 * Ureña and Lastra (2000), as the thesis does (section 4.1.2), plus the
 * brute-force oracle it is tested against.
 *
 * Primitive tests are exact enough to trust: triangles use the watertight test
 * of Woop, Benthin and Wald (2013) in double precision, so a ray never slips
 * between two triangles sharing an edge or a vertex; spheres use the stable
 * quadratic, so rays leaving a sphere's surface behave alike at any scale.
 * Ties (two primitives hit at exactly the same t) go to the lower primitive
 * id, so the octree and the oracle always return the same primitive.
 *
 * Where the processor has AVX2 the queries run vector code (octree_trace_avx2.c)
 * that performs the scalar tests' operations lane by lane: the same bits, so
 * the octree, the vector code and the oracle all agree exactly.
 *
 * A built ps_accel is immutable: every query is const, allocates nothing and
 * may run on any number of threads at once. */
#ifndef PS_ACCEL_ACCEL_H
#define PS_ACCEL_ACCEL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"
#include "scene/scene.h"

/* PS_ACCEL_AUTO builds no tree below this many primitives: testing a dozen
 * primitives costs less than walking a tree to them (the default scene has 12). */
#define PS_ACCEL_BRUTE_MAX_PRIMS 16
/* Deep enough for a 0.1 mm detail in a 100 m scene (2^-20 of the root). */
#define PS_OCTREE_DEFAULT_MAX_DEPTH 20
/* A node with at most this many primitive references becomes a leaf; above
 * it a cost model decides (octree_build.c), so larger nodes may stay leaves. */
#define PS_OCTREE_DEFAULT_LEAF_PRIMS 6
/* Larger max_depth options are clamped to this: cells 2^-32 of the root are
 * already smaller than the padding that keeps overlap tests conservative, so
 * deeper splits could not separate anything; it also bounds the traversal stack. */
#define PS_OCTREE_MAX_DEPTH_LIMIT 32

/* Self-intersection offset relative to the scene's extent (largest coordinate
 * magnitude): 1 nm in a 1 m scene, some 10^7 units in the last place of the
 * coordinates, far above the rounding of any hit point, far below any feature. */
#define PS_RAY_EPSILON_REL 1e-9
/* The epsilon of a scene with no extent at all (empty, or a point at the origin). */
#define PS_RAY_EPSILON_MIN 1e-300

typedef struct ps_accel ps_accel; /* opaque, immutable after build, safe to query from many threads */

typedef enum ps_accel_kind { PS_ACCEL_AUTO, PS_ACCEL_OCTREE, PS_ACCEL_BRUTE } ps_accel_kind;

typedef struct ps_accel_options {
    ps_accel_kind kind; /* AUTO: brute force below PS_ACCEL_BRUTE_MAX_PRIMS primitives (tiny scenes), else octree */
    int max_depth;      /* 0: default (PS_OCTREE_DEFAULT_MAX_DEPTH); clamped to PS_OCTREE_MAX_DEPTH_LIMIT */
    int leaf_prims;     /* 0: default (PS_OCTREE_DEFAULT_LEAF_PRIMS): a node with at most this many primitives is a leaf */
    bool no_simd;       /* true: the scalar traversal even where the processor has AVX2 (same results; tests, bench) */
} ps_accel_options;     /* zero-initialised = all defaults */

/* Geometry to build over; arrays are only read during build (the accel copies what it needs).
 * Positions, centres and radii must be finite and radii >= 0 (PS_ERR_RANGE otherwise);
 * zero-area triangles and zero-radius spheres are accepted and never hit. */
typedef struct ps_accel_input {
    const ps_vec3 *positions; /* vertex positions */
    size_t position_count;
    const uint32_t *indices; /* 3 per triangle, into positions */
    size_t triangle_count;
    const ps_vec3 *sphere_centers; /* analytic spheres */
    const double *sphere_radii;
    size_t sphere_count;
} ps_accel_input;

/* Primitive ids: triangles are [0, triangle_count) in input order, spheres follow: triangle_count + k. */
typedef struct ps_hit {
    double t;       /* ray parameter of the hit (in units of |d|; d need not be unit) */
    uint32_t prim;  /* primitive id as above */
    double b1, b2;  /* triangles: barycentric weights of vertex 1 and vertex 2 (vertex 0 = 1-b1-b2); spheres: 0 */
} ps_hit;

/* Builds over in; opt may be NULL (all defaults). On error *out is NULL. */
ps_status ps_accel_build(const ps_accel_input *in, const ps_accel_options *opt, ps_accel **out, ps_error *err);
/* Over a scene: triangles = ps_scene_triangles in order; spheres = the PS_OBJ_SPHERE objects in scene order.
 * *sphere_objects (may be NULL) receives a malloc'ed array mapping sphere k -> object index (caller
 * frees; NULL when the scene has no sphere). */
ps_status ps_accel_build_scene(const ps_scene *s, const ps_accel_options *opt, ps_accel **out,
                               uint32_t **sphere_objects, ps_error *err);
void ps_accel_destroy(ps_accel *a); /* accepts NULL */

/* Nearest hit with t in (tmin, tmax); false when none. Rays with NaN/inf/zero direction never hit. */
bool ps_accel_intersect(const ps_accel *a, ps_ray r, double tmin, double tmax, ps_hit *hit);
/* Any hit with t in (tmin, tmax). */
bool ps_accel_occluded(const ps_accel *a, ps_ray r, double tmin, double tmax);
/* The oracle: tests every primitive (same primitive tests, no tree). */
bool ps_accel_intersect_brute(const ps_accel *a, ps_ray r, double tmin, double tmax, ps_hit *hit);

/* The nearest point of the geometry to a point: of the hittable primitives
 * (triangles with area, spheres with a radius: their surfaces). */
typedef struct ps_nearest {
    double distance; /* |point - p| */
    uint32_t prim;   /* primitive id as in ps_hit; equally near ones go to the lower id */
    ps_vec3 point;   /* the nearest point on that primitive */
} ps_nearest;
/* The primitive nearest to p within max_dist (inclusive; INFINITY: any); false
 * when none is (or p is not finite, or max_dist is NaN or negative). Through
 * the octree, visiting only cells nearer than the best so far; the same answer
 * as ps_accel_nearest_brute, bit for bit. Const, thread-safe like the ray queries.
 * (What a light's shadow cube needs for its near plane: nothing is nearer.) */
bool ps_accel_nearest(const ps_accel *a, ps_vec3 p, double max_dist, ps_nearest *out);
/* The oracle: every primitive (same distance arithmetic). */
bool ps_accel_nearest_brute(const ps_accel *a, ps_vec3 p, double max_dist, ps_nearest *out);
/* Shorthand: the distance from p to the nearest primitive; INFINITY when there is none. */
double ps_accel_nearest_distance(const ps_accel *a, ps_vec3 p);

/* Self-intersection offset for rays leaving a surface: PS_RAY_EPSILON_REL times the scene's extent
 * (ps_aabb_extent of all geometry; at least PS_RAY_EPSILON_MIN). Scales with the scene: a scene
 * scaled by 1e-3 or 1e3 gets an epsilon scaled the same way. */
double ps_accel_epsilon(const ps_accel *a);
/* The box around all primitives (degenerate ones included); empty when there are none. */
ps_aabb ps_accel_bounds(const ps_accel *a);
/* Primitives as numbered in ps_hit: triangles plus spheres, degenerate ones included. */
size_t ps_accel_prim_count(const ps_accel *a);
size_t ps_accel_triangle_count(const ps_accel *a);

typedef struct ps_accel_stats {
    ps_accel_kind kind; /* what was built (OCTREE or BRUTE) */
    bool simd;          /* queries run the AVX2 code */
    size_t nodes, leaves, prim_refs, max_depth_reached, bytes;
    double build_seconds;
} ps_accel_stats;
void ps_accel_get_stats(const ps_accel *a, ps_accel_stats *st);

#endif
