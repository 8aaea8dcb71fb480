/* kdtree.h: the balanced kd-tree photon map (thesis 2.4-2.5, Jensen 1996).
 *
 * The photons are copied into one flat array laid out as a left-balanced
 * binary heap: node i (1-based) has children 2i and 2i+1, so no pointers are
 * stored and the whole tree is the 20-byte records themselves. Each node
 * splits its subtree at the median on the axis of greatest extent, chosen by
 * linear-time selection (quickselect), not a full sort; the axis is kept in
 * the photon's two flag bits, as the thesis' photon keeps it in its flags.
 * Building is O(n log n); a query allocates nothing: the caller passes the
 * neighbour buffer. Immutable once built, so threads may query it at once. */
#ifndef PS_PHOTON_KDTREE_H
#define PS_PHOTON_KDTREE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"
#include "photon/photon.h"

typedef struct ps_kdtree ps_kdtree;

/* One photon found by a query: its index in ps_kdtree_photons and its squared
 * distance to the query point. */
typedef struct ps_neighbor {
    double d2;
    uint32_t index;
} ps_neighbor;

/* A k-nearest query. Photons farther than max_radius are never returned.
 * When `normal` is not zero, photons whose stored normal has a cosine of at
 * most `min_cos` with it are passed over, and do not count towards k: they lie
 * on a surface facing another way (the far side of a thin wall, a corner). */
typedef struct ps_kdtree_query {
    ps_vec3 p;
    size_t k;          /* >= 1 */
    double max_radius; /* > 0; infinity for none */
    ps_vec3 normal;    /* unit, or (0, 0, 0) for no filter */
    double min_cos;
} ps_kdtree_query;

/* Builds the tree from a copy of photons[0, count) (the input is untouched).
 * count may be 0 (every query then finds nothing). PS_ERR_LIMIT beyond
 * UINT32_MAX photons, PS_ERR_NOMEM when the copy does not fit. */
ps_status ps_kdtree_build(const ps_photon *photons, size_t count, ps_kdtree **out, ps_error *err);
void ps_kdtree_destroy(ps_kdtree *t); /* accepts NULL */

size_t ps_kdtree_count(const ps_kdtree *t);
/* The photons in heap order (flags hold split axes). */
const ps_photon *ps_kdtree_photons(const ps_kdtree *t);
/* The box around every photon (empty for an empty tree). */
ps_aabb ps_kdtree_bounds(const ps_kdtree *t);

/* The up to q->k photons nearest to q->p (ties broken arbitrarily) into out,
 * which holds at least q->k entries, as a max-heap on d2: out[0] is the
 * farthest, the rest in no particular order; returns how many.
 * *r2 (may be NULL) receives the squared radius the result covers: the
 * farthest found when k were found, max_radius^2 otherwise (the region whose
 * area the density estimate divides by). */
size_t ps_kdtree_knn(const ps_kdtree *t, const ps_kdtree_query *q, ps_neighbor *out, double *r2);

/* Checks the heap layout: every node's left subtree lies at or below its split
 * and the right at or above, on its axis. For tests; O(n log n). */
bool ps_kdtree_check(const ps_kdtree *t);

#endif
