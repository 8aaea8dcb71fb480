/* accel_internal.h: the layout of ps_accel and the primitive tests, shared by
 * accel.c (build entry points, oracle), octree_build.c and octree_trace.c only.
 *
 * The primitive tests are static inline so that the traversal and the oracle
 * compile the very same arithmetic: both return bit-identical t for the same
 * primitive, which is what lets the tests demand that the octree and brute
 * force agree exactly. (C11 mode keeps GCC from contracting a*b+c into FMA,
 * -ffp-contract=off being the ISO default, so no call site rounds differently.) */
#ifndef PS_ACCEL_ACCEL_INTERNAL_H
#define PS_ACCEL_ACCEL_INTERNAL_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "accel/accel.h"

#if defined(__GNUC__)
#define PS_ALWAYS_INLINE inline __attribute__((always_inline))
#define PS_PREFETCH(p) __builtin_prefetch(p)
#else
#define PS_ALWAYS_INLINE inline
#define PS_PREFETCH(p) ((void)0)
#endif

/* A triangle as its three vertices, exactly as given: the watertight test
 * needs every triangle sharing a vertex to see the same numbers for it, so no
 * edge vectors or normals are precomputed (they would round differently per
 * triangle and reopen the cracks the test closes). 72 bytes. */
typedef struct accel_tri {
    double v[9]; /* v0.xyz, v1.xyz, v2.xyz */
} accel_tri;

typedef struct accel_sphere {
    double c[3], r;
} accel_sphere;

/* An octree node, 8 bytes. Interior nodes have the ACCEL_NODE_INTERIOR bit
 * set in count, and in its low 8 bits which children are worth visiting (bit
 * c: child c is interior or a leaf with references), so the traversal skips
 * empty cells without loading them; index is their first child, the eight
 * contiguous, child c covering the octant with x upper if c & 4, y upper if
 * c & 2, z upper if c & 1 (the numbering of Revelles et al.). Leaves hold
 * refs[index, index + count), count < ACCEL_NODE_INTERIOR. */
typedef struct accel_node {
    uint32_t index, count;
} accel_node;
#define ACCEL_NODE_INTERIOR 0x80000000u
#define ACCEL_NODE_BLOCK 8           /* children per interior node, contiguous */
#define ACCEL_NODE_ALIGN 64          /* a block of 8 nodes is one cache line */
#define ACCEL_MAX_REFS 0x7fffffffu   /* so that a leaf's count never has the interior bit */
/* Above this many bytes of triangles (a core's L2 cache, about) the AVX2
 * traversal prefetches a leaf's triangles before testing them; below, the
 * loop costs more than the misses it hides (bench_accel: 4 % at 10^3
 * triangles, 10 % gained at 10^6). */
#define ACCEL_PREFETCH_BYTES (1u << 20)

struct ps_accel {
    ps_accel_kind kind;
    bool prefetch_leaves; /* the triangles outgrow a core's cache (ACCEL_PREFETCH_BYTES): prefetch a leaf's */
    bool simd; /* query with the AVX2 code (octree_trace_avx2.c): the processor has it, no_simd not asked */
    /* Hittable primitives. Triangles are stored in the order the octree's
     * leaves first reference them (depth first), so a leaf's triangles mostly
     * sit together in memory; tri_ids maps back to the input's numbering.
     * Internal primitive index i < tri_count is tris[i], else spheres[i - tri_count]. */
    accel_tri *tris;
    uint32_t *tri_ids;
    uint32_t tri_count;
    accel_sphere *spheres;
    uint32_t *sphere_ids; /* the ps_hit prim of each sphere (input triangle count + k) */
    uint32_t sphere_count;
    /* The octree (kind == PS_ACCEL_OCTREE): a cube with corner root_lo.
     * nodes[0] is the root and nodes[1..7] pad its block, so that every
     * block of eight children starts a 64-byte line of the aligned array. */
    accel_node *nodes;
    size_t node_count;
    uint32_t *refs;
    size_t ref_count;
    ps_vec3 root_lo;
    double root_side;
    double cell_pad; /* the padding of the build's overlap tests: a primitive within it of a cell is filed there */
    /* What the API reports. */
    ps_aabb bounds;
    double epsilon;
    size_t input_triangles, input_spheres;
    ps_accel_stats stats;
};

/* ---- per-ray precomputation ------------------------------------------------ */

/* What every primitive test of one ray shares, computed once per ray. */
typedef struct accel_ray {
    double o[3];
    /* Watertight triangle test: kz is the dominant axis of d, (kx, ky) the
     * other two; the shear (sx, sy, sz) maps the ray onto +z of unit length. */
    int kx, ky, kz;
    double sx, sy, sz;
    /* Sphere test: the unit direction and 1/|d| (sphere roots are solved
     * along dn for precision, then converted back to units of |d|). */
    double dn[3], inv_len;
    /* Traversal: d / tscale (tscale a power of two making the largest
     * component 1 <= |.| < 2), so that traversal parameters, t * tscale, stay
     * far from overflow whatever |d| is. */
    double ds[3], tscale;
} accel_ray;

/* 2^e for e in the normal range [-1022, 1023], from its bits (ldexp is a
 * libm call, and this runs once per ray). */
static inline double accel_pow2(int e)
{
    uint64_t bits = (uint64_t)(e + 1023) << 52;
    double x;
    memcpy(&x, &bits, sizeof x);
    return x;
}

/* Fills r from a ray; false when the ray can hit nothing (non-finite origin,
 * or a direction that is zero, NaN or infinite). The sphere test's fields
 * (a square root and a division) are filled only when spheres is true. */
static PS_ALWAYS_INLINE bool accel_ray_prepare(ps_ray ray, accel_ray *r, bool spheres)
{
    if (!ps_v3_isfinite(ray.o) || !ps_v3_isfinite(ray.d))
        return false;
    double d[3] = {ray.d.x, ray.d.y, ray.d.z};
    double ad[3] = {fabs(d[0]), fabs(d[1]), fabs(d[2])};
    /* Woop et al.: the dominant axis becomes z; the winding swap of the paper
     * is left out because the test is two-sided (det's sign is ignored). */
    int kz = ad[0] >= ad[1] ? (ad[0] >= ad[2] ? 0 : 2) : (ad[1] >= ad[2] ? 1 : 2);
    double dmax = ad[kz];
    if (!(dmax > 0.0))
        return false;
    /* The power-of-two scale: the exponent from the bits, subnormals aside. */
    uint64_t bits;
    memcpy(&bits, &dmax, sizeof bits);
    int e = (int)((bits >> 52) & 0x7ffu) - 1023;
    if (e > -1022 && e < 1023) {
        r->tscale = accel_pow2(e);
        double down = accel_pow2(-e);
        for (int i = 0; i < 3; i++)
            r->ds[i] = d[i] * down; /* exact: a power-of-two scale */
    } else {
        e = ilogb(dmax);
        r->tscale = ldexp(1.0, e);
        for (int i = 0; i < 3; i++)
            r->ds[i] = ldexp(d[i], -e);
    }
    if (spheres) {
        double len_s = sqrt(r->ds[0] * r->ds[0] + r->ds[1] * r->ds[1] + r->ds[2] * r->ds[2]); /* in [1, 2 sqrt 3) */
        double inv_len_s = 1.0 / len_s;
        for (int i = 0; i < 3; i++)
            r->dn[i] = r->ds[i] * inv_len_s;
        r->inv_len = inv_len_s / r->tscale;
    }
    r->o[0] = ray.o.x;
    r->o[1] = ray.o.y;
    r->o[2] = ray.o.z;
    r->kz = kz;
    r->kx = kz == 2 ? 0 : kz + 1;
    r->ky = r->kx == 2 ? 0 : r->kx + 1;
    r->sz = 1.0 / d[kz];
    r->sx = d[r->kx] * r->sz;
    r->sy = d[r->ky] * r->sz;
    return true;
}

/* ---- primitive tests ----------------------------------------------------- */

/* Watertight ray/triangle intersection (Woop, Benthin, Wald 2013) in double
 * precision. Returns t, or NaN for a miss (every comparison with NaN is false,
 * so callers need only test tmin < t < best). kx, ky, kz are the ray's axes,
 * passed as constants by specialised callers so the permutation costs nothing.
 *
 * Why watertight: each vertex is transformed into the ray's sheared frame on
 * its own, so two triangles sharing an edge compute that edge's function from
 * identical numbers, and the two results are exact negatives of each other
 * (a*b - c*d against c*d - a*b). A ray can thus never be outside both: the
 * inclusive sign test below accepts 0 for either. */
static PS_ALWAYS_INLINE double accel_tri_hit(const accel_tri *tri, const accel_ray *r, int kx, int ky, int kz,
                                             double *b1, double *b2)
{
    const double *v = tri->v;
    /* Step 1: vertices relative to the ray origin. */
    double A[3] = {v[0] - r->o[0], v[1] - r->o[1], v[2] - r->o[2]};
    double B[3] = {v[3] - r->o[0], v[4] - r->o[1], v[5] - r->o[2]};
    double C[3] = {v[6] - r->o[0], v[7] - r->o[1], v[8] - r->o[2]};
    /* Step 2: shear so the ray runs along +z; only x and y are needed for the edge tests. */
    double ax = A[kx] - r->sx * A[kz], ay = A[ky] - r->sy * A[kz];
    double bx = B[kx] - r->sx * B[kz], by = B[ky] - r->sy * B[kz];
    double cx = C[kx] - r->sx * C[kz], cy = C[ky] - r->sy * C[kz];
    /* Step 3: scaled barycentrics: the 2D edge functions at the ray (the origin). */
    double u = cx * by - cy * bx;
    double w_v = ax * cy - ay * cx;
    double w = bx * ay - by * ax;
    /* Step 4: inside when no two signs differ (zeros count as inside:
     * watertight). Bitwise, not short-circuit: one branch instead of six. */
    if (((u < 0.0) | (w_v < 0.0) | (w < 0.0)) & ((u > 0.0) | (w_v > 0.0) | (w > 0.0)))
        return NAN;
    double det = u + w_v + w;
    if (det == 0.0) /* the ray lies in the triangle's plane, or the triangle has no area seen along it */
        return NAN;
    /* Step 5: the distance: interpolate the sheared z of the vertices. */
    double t_scaled = u * (r->sz * A[kz]) + w_v * (r->sz * B[kz]) + w * (r->sz * C[kz]);
    double inv_det = 1.0 / det;
    *b1 = w_v * inv_det;
    *b2 = w * inv_det;
    return t_scaled * inv_det;
}

/* Ray/sphere intersection, robust at any radius: the discriminant is taken
 * from the ray's closest approach to the centre, r^2 - |f - (f.dn)dn|^2
 * (Haines et al., Ray Tracing Gems ch. 7) rather than b^2 - c, which cancels
 * catastrophically for distant or tiny spheres, and the roots come from the
 * stable q = -(b + sign(b) sqrt(disc)) form, so the root near 0 of a ray that
 * starts on the surface is computed as c / q without cancellation. Returns the
 * nearest root above tmin (the far root from inside: glass is entered and
 * left), or NaN. */
static PS_ALWAYS_INLINE double accel_sphere_hit(const accel_sphere *s, const accel_ray *r, double tmin)
{
    double f[3] = {r->o[0] - s->c[0], r->o[1] - s->c[1], r->o[2] - s->c[2]};
    double b = f[0] * r->dn[0] + f[1] * r->dn[1] + f[2] * r->dn[2];
    double l[3] = {f[0] - b * r->dn[0], f[1] - b * r->dn[1], f[2] - b * r->dn[2]};
    double disc = s->r * s->r - (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    if (disc < 0.0)
        return NAN;
    double q = -(b + copysign(sqrt(disc), b));
    double c = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) - s->r * s->r;
    /* Roots along dn (a = 1): q and c / q; q is 0 only when both are. */
    double t0 = q, t1 = q != 0.0 ? c / q : 0.0;
    if (t0 > t1) {
        double tmp = t0;
        t0 = t1;
        t1 = tmp;
    }
    t0 *= r->inv_len;
    t1 *= r->inv_len;
    if (t0 > tmin)
        return t0;
    if (t1 > tmin)
        return t1;
    return NAN;
}

/* Whether a hit at t on primitive id beats the best so far (best->t starts at
 * tmax). Equal t goes to the lower id, so every search order gives one answer. */
static inline bool accel_hit_better(double t, uint32_t id, const ps_hit *best, bool found, double tmin)
{
    return t > tmin && (t < best->t || (found && t == best->t && id < best->prim));
}

/* ---- entry points between the files ----------------------------------------- */

/* Builds a's octree over its hittable primitives (tris, spheres already
 * filled), reorders a->tris into leaf order and fills the octree stats. */
ps_status ps_accel_octree_build(ps_accel *a, int max_depth, int leaf_prims, ps_error *err);
/* Octree query: nearest hit (any == false) or any hit (any == true). */
bool ps_accel_octree_trace(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit, bool any);
/* The same query with AVX2 vectors (octree_trace_avx2.c), bit-identical
 * results; only where ps_accel_cpu_has_avx2() (elsewhere it is the scalar one). */
bool ps_accel_octree_trace_avx2(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit, bool any);
/* A brute-force accelerator's query with AVX2 (triangles four at a time), same answers. */
bool ps_accel_brute_avx2(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit, bool any);
bool ps_accel_cpu_has_avx2(void);

#endif
