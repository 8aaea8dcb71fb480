/* octree_trace_avx2.c: the octree traversal of octree_trace.c written with
 * AVX2 vectors, chosen at build time when the processor has them
 * (ps_accel_options.no_simd turns it off).
 *
 * The same algorithm as octree_trace.c (Revelles et al., with the same
 * departures), with two changes of representation, neither changing a result:
 *
 * - A node's parameters are two vectors, T0 = (tx0, ty0, tz0, tmin) and
 *   T1 = (tx1, ty1, tz1, +big): the midplanes are one add and one multiply, a
 *   child's parameters one blend each (lane i takes the upper half when the
 *   child's bit for axis i is set), the entry parameter clipped to tmin is the
 *   largest lane of T0, and a stack entry is two vector stores.
 * - A leaf's triangles are tested four at a time: the vertices of four
 *   triangles are loaded and transposed into one vector per coordinate, and
 *   each step of the watertight test (Woop et al.) is the scalar test's very
 *   operation on four lanes: the same IEEE operations in the same order, no
 *   fused multiply-add (AVX2 alone does not enable FMA, and C11 mode does not
 *   contract), so every lane's t, b1 and b2 are bit-identical to
 *   accel_tri_hit's, and the octree still agrees exactly with the oracle.
 *
 * Spheres, rare in leaves, use the scalar test. A brute-force accelerator
 * (the tiny scenes PS_ACCEL_AUTO leaves without a tree) tests its triangles
 * four at a time here too; ps_accel_intersect_brute, the oracle, stays scalar. */
#if defined(__GNUC__) && defined(__x86_64__)
#include <float.h>
#include <immintrin.h>

#include "accel/accel_internal.h"

/* Every function here is compiled for AVX2 (per function, so that the rest of
 * the program runs anywhere, and the same with GCC and clang); AVX2 does not
 * imply FMA, so no multiply-add is fused. */
#define AVX2 __attribute__((target("avx2")))

/* As in octree_trace.c: zero direction components raised to this. */
#define DIR_ZERO 1e-100
#define STACK_SIZE (3 * PS_OCTREE_MAX_DEPTH_LIMIT + 4)

/* As in octree_trace.c: the midplanes sorted by parameter, as the child bits
 * of each prefix, indexed by the order bits (tmx <= tmy) << 2 |
 * (tmy <= tmz) << 1 | (tmx <= tmz). */
static const unsigned char sorted_prefix[8][4] = {
    {0, 1, 3, 7}, {0, 4, 6, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 1, 5, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}, {0, 4, 6, 7},
};

/* The lanes of child c that take the upper half: lane 0 is x (bit 2 of c),
 * lane 1 y (bit 1), lane 2 z (bit 0), lane 3 (the padding) never. */
static const int64_t child_lanes[8][4] __attribute__((aligned(32))) = {
    {0, 0, 0, 0}, {0, 0, -1, 0}, {0, -1, 0, 0}, {0, -1, -1, 0},
    {-1, 0, 0, 0}, {-1, 0, -1, 0}, {-1, -1, 0, 0}, {-1, -1, -1, 0},
};

typedef struct trav_item {
    __m256d t0, t1;
    uint32_t node;
} trav_item;

static inline AVX2 double hmax4(__m256d v)
{
    __m128d m = _mm_max_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
    return _mm_cvtsd_f64(_mm_max_sd(m, _mm_unpackhi_pd(m, m)));
}

static inline AVX2 double hmin4(__m256d v)
{
    __m128d m = _mm_min_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
    return _mm_cvtsd_f64(_mm_min_sd(m, _mm_unpackhi_pd(m, m)));
}

/* Rows r0..r3 (one per triangle) into columns c0..c3 (one per coordinate). */
#define TRANSPOSE4(r0, r1, r2, r3, c0, c1, c2, c3)                                                               \
    do {                                                                                                         \
        __m256d lo01_ = _mm256_unpacklo_pd(r0, r1), hi01_ = _mm256_unpackhi_pd(r0, r1);                         \
        __m256d lo23_ = _mm256_unpacklo_pd(r2, r3), hi23_ = _mm256_unpackhi_pd(r2, r3);                         \
        c0 = _mm256_permute2f128_pd(lo01_, lo23_, 0x20);                                                         \
        c1 = _mm256_permute2f128_pd(hi01_, hi23_, 0x20);                                                         \
        c2 = _mm256_permute2f128_pd(lo01_, lo23_, 0x31);                                                         \
        c3 = _mm256_permute2f128_pd(hi01_, hi23_, 0x31);                                                         \
    } while (0)

/* What the leaf test needs of the ray, as vectors. */
typedef struct ray4 {
    __m256d ox, oy, oz, sx, sy, sz;
} ray4;

/* Up to four triangles (t0..t3, the first n of them real, n in 1..4; the
 * others repeat one of them) against the ray: the lanes that hit, as bits,
 * with t, b1, b2 per lane. Step for step accel_tri_hit. */
static PS_ALWAYS_INLINE AVX2 unsigned tri_hit4(const accel_tri *t0, const accel_tri *t1, const accel_tri *t2,
                                          const accel_tri *t3, unsigned n, const ray4 *q, int kx, int ky, int kz,
                                          double t[4], double b1[4], double b2[4])
{
    const double *p0 = t0->v, *p1 = t1->v, *p2 = t2->v, *p3 = t3->v;
    /* Step 0: the coordinates, one vector each: V[vertex][axis]. */
    __m256d V[3][3];
    TRANSPOSE4(_mm256_loadu_pd(p0), _mm256_loadu_pd(p1), _mm256_loadu_pd(p2), _mm256_loadu_pd(p3), V[0][0], V[0][1],
               V[0][2], V[1][0]);
    TRANSPOSE4(_mm256_loadu_pd(p0 + 4), _mm256_loadu_pd(p1 + 4), _mm256_loadu_pd(p2 + 4), _mm256_loadu_pd(p3 + 4),
               V[1][1], V[1][2], V[2][0], V[2][1]);
    V[2][2] = _mm256_set_pd(p3[8], p2[8], p1[8], p0[8]);
    const __m256d o[3] = {q->ox, q->oy, q->oz}; /* indexed by axis, as V */
    /* Step 1: vertices relative to the origin (the axes the shear needs). */
    __m256d Ax = _mm256_sub_pd(V[0][kx], o[kx]), Ay = _mm256_sub_pd(V[0][ky], o[ky]), Az = _mm256_sub_pd(V[0][kz], o[kz]);
    __m256d Bx = _mm256_sub_pd(V[1][kx], o[kx]), By = _mm256_sub_pd(V[1][ky], o[ky]), Bz = _mm256_sub_pd(V[1][kz], o[kz]);
    __m256d Cx = _mm256_sub_pd(V[2][kx], o[kx]), Cy = _mm256_sub_pd(V[2][ky], o[ky]), Cz = _mm256_sub_pd(V[2][kz], o[kz]);
    /* Step 2: the shear. */
    __m256d ax = _mm256_sub_pd(Ax, _mm256_mul_pd(q->sx, Az)), ay = _mm256_sub_pd(Ay, _mm256_mul_pd(q->sy, Az));
    __m256d bx = _mm256_sub_pd(Bx, _mm256_mul_pd(q->sx, Bz)), by = _mm256_sub_pd(By, _mm256_mul_pd(q->sy, Bz));
    __m256d cx = _mm256_sub_pd(Cx, _mm256_mul_pd(q->sx, Cz)), cy = _mm256_sub_pd(Cy, _mm256_mul_pd(q->sy, Cz));
    /* Step 3: the edge functions. */
    __m256d u = _mm256_sub_pd(_mm256_mul_pd(cx, by), _mm256_mul_pd(cy, bx));
    __m256d w_v = _mm256_sub_pd(_mm256_mul_pd(ax, cy), _mm256_mul_pd(ay, cx));
    __m256d w = _mm256_sub_pd(_mm256_mul_pd(bx, ay), _mm256_mul_pd(by, ax));
    /* Step 4: inside unless two signs differ; det zero is a miss. */
    __m256d zero = _mm256_setzero_pd();
    __m256d neg = _mm256_or_pd(_mm256_or_pd(_mm256_cmp_pd(u, zero, _CMP_LT_OQ), _mm256_cmp_pd(w_v, zero, _CMP_LT_OQ)),
                               _mm256_cmp_pd(w, zero, _CMP_LT_OQ));
    __m256d pos = _mm256_or_pd(_mm256_or_pd(_mm256_cmp_pd(u, zero, _CMP_GT_OQ), _mm256_cmp_pd(w_v, zero, _CMP_GT_OQ)),
                               _mm256_cmp_pd(w, zero, _CMP_GT_OQ));
    __m256d det = _mm256_add_pd(_mm256_add_pd(u, w_v), w);
    __m256d bad = _mm256_or_pd(_mm256_and_pd(neg, pos), _mm256_cmp_pd(det, zero, _CMP_EQ_OQ));
    unsigned mask = ~(unsigned)_mm256_movemask_pd(bad) & ((1u << n) - 1u);
    if (!mask)
        return 0;
    /* Step 5: the distance and the barycentrics, as accel_tri_hit rounds them. */
    __m256d ts = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(u, _mm256_mul_pd(q->sz, Az)),
                                             _mm256_mul_pd(w_v, _mm256_mul_pd(q->sz, Bz))),
                               _mm256_mul_pd(w, _mm256_mul_pd(q->sz, Cz)));
    __m256d inv_det = _mm256_div_pd(_mm256_set1_pd(1.0), det);
    _mm256_storeu_pd(b1, _mm256_mul_pd(w_v, inv_det));
    _mm256_storeu_pd(b2, _mm256_mul_pd(w, inv_det));
    _mm256_storeu_pd(t, _mm256_mul_pd(ts, inv_det));
    return mask;
}

static PS_ALWAYS_INLINE AVX2 bool trace(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit,
                                   bool any, int kx, int ky, int kz)
{
    /* Step 1: mirror mask, inverse direction and the root's parameters, as
     * the scalar traversal computes them, lane by lane: |ds| raised to
     * DIR_ZERO keeping its sign, its inverse, and for a negative component the
     * planes swapped. Lane 3 (the padding) holds tmin in T0 and +inf in T1:
     * T0's largest lane is then the clipped entry and T1's padding is never
     * the smallest; tmin is kept finite there so that the padding's midplane,
     * (tmin + inf) / 2, is inf rather than NaN. */
    double ts = r->tscale;
    double tmin_s = tmin * ts, best_s = tmax * ts;
    const __m256d sign_bit = _mm256_set1_pd(-0.0);
    __m256d ds = _mm256_set_pd(1.0, r->ds[2], r->ds[1], r->ds[0]);
    __m256d mag = _mm256_max_pd(_mm256_andnot_pd(sign_bit, ds), _mm256_set1_pd(DIR_ZERO));
    ds = _mm256_or_pd(mag, _mm256_and_pd(sign_bit, ds));
    __m256d inv = _mm256_div_pd(_mm256_set1_pd(1.0), ds);
    __m256d negative = _mm256_cmp_pd(ds, _mm256_setzero_pd(), _CMP_LT_OQ); /* |ds| >= DIR_ZERO: never -0 */
    unsigned neg_bits = (unsigned)_mm256_movemask_pd(negative);
    unsigned mirror = (neg_bits & 1u) << 2 | (neg_bits & 2u) | (neg_bits >> 2 & 1u);
    __m256d lo = _mm256_set_pd(0.0, a->root_lo.z, a->root_lo.y, a->root_lo.x);
    __m256d hi = _mm256_add_pd(lo, _mm256_set1_pd(a->root_side));
    __m256d org = _mm256_set_pd(0.0, r->o[2], r->o[1], r->o[0]);
    __m256d T0 = _mm256_mul_pd(_mm256_sub_pd(_mm256_blendv_pd(lo, hi, negative), org), inv);
    __m256d T1 = _mm256_mul_pd(_mm256_sub_pd(_mm256_blendv_pd(hi, lo, negative), org), inv);
    T0 = _mm256_blend_pd(T0, _mm256_set1_pd(tmin_s > -DBL_MAX ? tmin_s : -DBL_MAX), 8);
    T1 = _mm256_blend_pd(T1, _mm256_set1_pd(INFINITY), 8);
    /* Step 2: clip to [tmin, tmax]. */
    if (hmax4(T0) > best_s || hmin4(T1) < tmin_s)
        return false;
    ray4 q = {_mm256_set1_pd(r->o[0]), _mm256_set1_pd(r->o[1]), _mm256_set1_pd(r->o[2]),
              _mm256_set1_pd(r->sx),   _mm256_set1_pd(r->sy),   _mm256_set1_pd(r->sz)};
    const __m256d half = _mm256_set1_pd(0.5);

    ps_hit best = {tmax, UINT32_MAX, 0.0, 0.0};
    bool found = false;
    const accel_node *nodes = a->nodes;
    trav_item stack[STACK_SIZE];
    size_t sp = 0;
    uint32_t node_index = 0;
    for (;;) {
        accel_node node = nodes[node_index];
        if (!(node.count & ACCEL_NODE_INTERIOR)) {
            /* Step 3: a leaf: its triangles four at a time, then its spheres
             * (a leaf lists its triangles first: octree_build.c). */
            const uint32_t *refs = a->refs + node.index;
            uint32_t count = node.count, ntri = count;
            while (ntri > 0 && refs[ntri - 1] >= a->tri_count)
                ntri--;
            /* Ask for all the leaf's triangles before testing any, so that
             * their misses overlap; only worth it when they may miss. */
            if (a->prefetch_leaves)
                for (uint32_t k = 0; k < ntri; k++) {
                    const char *p = (const char *)&a->tris[refs[k]];
                    PS_PREFETCH(p);
                    PS_PREFETCH(p + sizeof(accel_tri) - 1);
                }
            for (uint32_t k = 0; k < ntri; k += 4) {
                double t[4], b1[4], b2[4];
                unsigned n = ntri - k < 4 ? ntri - k : 4;
                const uint32_t *rk = refs + k;
                unsigned mask = tri_hit4(&a->tris[rk[0]], &a->tris[rk[n > 1 ? 1 : 0]], &a->tris[rk[n > 2 ? 2 : 0]],
                                         &a->tris[rk[n > 3 ? 3 : 0]], n, &q, kx, ky, kz, t, b1, b2);
                while (mask) {
                    unsigned j = (unsigned)__builtin_ctz(mask);
                    mask &= mask - 1;
                    if (!(t[j] > tmin && t[j] <= best.t))
                        continue;
                    uint32_t id = a->tri_ids[refs[k + j]];
                    if (!accel_hit_better(t[j], id, &best, found, tmin))
                        continue;
                    if (any)
                        return true;
                    best = (ps_hit){t[j], id, b1[j], b2[j]};
                    found = true;
                    best_s = t[j] * ts;
                }
            }
            for (uint32_t k = ntri; k < count; k++) {
                uint32_t s = refs[k] - a->tri_count;
                double t = accel_sphere_hit(&a->spheres[s], r, tmin);
                if (!(t > tmin && t <= best.t))
                    continue;
                uint32_t id = a->sphere_ids[s];
                if (!accel_hit_better(t, id, &best, found, tmin))
                    continue;
                if (any)
                    return true;
                best = (ps_hit){t, id, 0.0, 0.0};
                found = true;
                best_s = t * ts;
            }
        } else {
            /* Step 4: an interior node: midplanes, and the ray's span in it. */
            PS_PREFETCH(&nodes[node.index]);
            __m256d TM = _mm256_mul_pd(half, _mm256_add_pd(T0, T1));
            double start = hmax4(T0), end = hmin4(T1);
            end = end < best_s ? end : best_s;
            /* Step 5: the children in ray order (as octree_trace.c): the
             * order of the midplanes, and how many lie before start and end.
             * Lanes (x, y, x) against (y, z, z) give the order bits. */
            __m256d lhs = _mm256_permute4x64_pd(TM, 0x04 /* x y x x */);
            __m256d rhs = _mm256_permute4x64_pd(TM, 0x29 /* y z z x */);
            unsigned le = (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(lhs, rhs, _CMP_LE_OQ));
            unsigned order = (le & 1u) << 2 | (le & 2u) | (le >> 2 & 1u);
            const unsigned char *prefix = sorted_prefix[order];
            unsigned k0 = (unsigned)__builtin_popcount(
                (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(TM, _mm256_set1_pd(start), _CMP_LT_OQ)) & 7u);
            unsigned k1 = (unsigned)__builtin_popcount(
                (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(TM, _mm256_set1_pd(end), _CMP_LT_OQ)) & 7u);
            unsigned n = k1 > k0 ? k1 - k0 : 0u;
            unsigned vis = node.count, seq[4];
            int count = 0;
            for (unsigned m = 0; m < 4; m++) {
                unsigned c = prefix[k0 + m < 3 ? k0 + m : 3];
                seq[count] = c;
                count += (m <= n) & (vis >> (c ^ mirror)) & 1u;
            }
            /* Step 6: push the farther ones, descend into the nearest. */
            if (count > 0) {
                for (int k = count - 1; k > 0; k--) {
                    trav_item *it = &stack[sp++];
                    __m256d up = _mm256_load_pd((const double *)child_lanes[seq[k]]);
                    it->t0 = _mm256_blendv_pd(T0, TM, up);
                    it->t1 = _mm256_blendv_pd(TM, T1, up);
                    it->node = node.index + (seq[k] ^ mirror);
                    accel_node sn = nodes[it->node];
                    PS_PREFETCH((sn.count & ACCEL_NODE_INTERIOR) ? (const void *)&nodes[sn.index]
                                                                 : (const void *)&a->refs[sn.index]);
                }
                __m256d up = _mm256_load_pd((const double *)child_lanes[seq[0]]);
                T0 = _mm256_blendv_pd(T0, TM, up);
                T1 = _mm256_blendv_pd(TM, T1, up);
                node_index = node.index + (seq[0] ^ mirror);
                continue;
            }
        }
        /* Step 7: the next node along the ray, or the end. */
        if (sp == 0)
            break;
        const trav_item *it = &stack[--sp];
        T0 = it->t0;
        if (hmax4(T0) > best_s)
            break;
        T1 = it->t1;
        node_index = it->node;
    }
    if (found && !any)
        *hit = best;
    return found;
}

/* Every primitive, the triangles four at a time: the query of a brute-force
 * accelerator (tiny scenes) where the processor has AVX2. The same answers
 * as accel.c's loop, which stays the oracle. */
static PS_ALWAYS_INLINE AVX2 bool brute(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit,
                                   bool any, int kx, int ky, int kz)
{
    ray4 q = {_mm256_set1_pd(r->o[0]), _mm256_set1_pd(r->o[1]), _mm256_set1_pd(r->o[2]),
              _mm256_set1_pd(r->sx),   _mm256_set1_pd(r->sy),   _mm256_set1_pd(r->sz)};
    ps_hit best = {tmax, UINT32_MAX, 0.0, 0.0};
    bool found = false;
    const accel_tri *tris = a->tris;
    for (uint32_t k = 0; k < a->tri_count; k += 4) {
        double t[4], b1[4], b2[4];
        unsigned n = a->tri_count - k < 4 ? a->tri_count - k : 4;
        unsigned mask = tri_hit4(&tris[k], &tris[k + (n > 1 ? 1 : 0)], &tris[k + (n > 2 ? 2 : 0)], &tris[k + (n > 3 ? 3 : 0)],
                                 n, &q, kx, ky, kz, t, b1, b2);
        while (mask) {
            unsigned j = (unsigned)__builtin_ctz(mask);
            mask &= mask - 1;
            uint32_t id = a->tri_ids[k + j];
            if (!accel_hit_better(t[j], id, &best, found, tmin))
                continue;
            if (any)
                return true;
            best = (ps_hit){t[j], id, b1[j], b2[j]};
            found = true;
        }
    }
    for (uint32_t k = 0; k < a->sphere_count; k++) {
        double t = accel_sphere_hit(&a->spheres[k], r, tmin);
        if (!accel_hit_better(t, a->sphere_ids[k], &best, found, tmin))
            continue;
        if (any)
            return true;
        best = (ps_hit){t, a->sphere_ids[k], 0.0, 0.0};
        found = true;
    }
    if (found && !any)
        *hit = best;
    return found;
}

AVX2 bool ps_accel_brute_avx2(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit, bool any)
{
    switch (r->kz) {
    case 0:
        return any ? brute(a, r, tmin, tmax, hit, true, 1, 2, 0) : brute(a, r, tmin, tmax, hit, false, 1, 2, 0);
    case 1:
        return any ? brute(a, r, tmin, tmax, hit, true, 2, 0, 1) : brute(a, r, tmin, tmax, hit, false, 2, 0, 1);
    default:
        return any ? brute(a, r, tmin, tmax, hit, true, 0, 1, 2) : brute(a, r, tmin, tmax, hit, false, 0, 1, 2);
    }
}

AVX2 bool ps_accel_octree_trace_avx2(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit,
                                     bool any)
{
    if (a->node_count == 0)
        return false;
    switch (r->kz) {
    case 0:
        return any ? trace(a, r, tmin, tmax, hit, true, 1, 2, 0) : trace(a, r, tmin, tmax, hit, false, 1, 2, 0);
    case 1:
        return any ? trace(a, r, tmin, tmax, hit, true, 2, 0, 1) : trace(a, r, tmin, tmax, hit, false, 2, 0, 1);
    default:
        return any ? trace(a, r, tmin, tmax, hit, true, 0, 1, 2) : trace(a, r, tmin, tmax, hit, false, 0, 1, 2);
    }
}
#else
#include "accel/accel_internal.h"

bool ps_accel_brute_avx2(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit, bool any)
{
    (void)a, (void)r, (void)tmin, (void)tmax, (void)hit, (void)any;
    return false; /* never called: a->simd is false without AVX2 */
}

bool ps_accel_octree_trace_avx2(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit, bool any)
{
    return ps_accel_octree_trace(a, r, tmin, tmax, hit, any);
}
#endif
