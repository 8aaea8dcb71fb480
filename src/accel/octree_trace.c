/* octree_trace.c: ray traversal of the octree, the parametric algorithm of
 * Revelles, Ureña and Lastra (2000), "An efficient parametric algorithm for
 * octree traversal" (the thesis' reference [20]).
 *
 * The ray is mirrored so that every direction component is positive (the
 * paper's mask a, here `mirror`: child c of the mirrored ray is child
 * c ^ mirror of the tree), which makes the order of children along the ray a
 * function of the ray parameters alone. For a node, tx0 / tx1 are the
 * parameters where the ray crosses its lower / upper x planes (after
 * mirroring), likewise y and z; the children's parameters are those and the
 * midpoints txm = (tx0 + tx1) / 2, so neighbouring cells share the very same
 * numbers and the ray cannot fall through a crack between them. The first
 * child is given by the midplanes the ray has crossed when it enters
 * (first_node), each next one by the plane it leaves through (new_node).
 *
 * Departures from the paper, all for speed or robustness, none changing
 * which cells are visited: an explicit stack instead of recursion (the
 * nearest child is entered at once, its farther siblings pushed); first_node
 * and new_node in closed form without branches (Step 5), since with random
 * rays every branch there is a coin toss; the ray clipped to [tmin, best hit]
 * so that no cell behind tmin or past the best hit is visited; parameters
 * computed from the real coordinates (for a negative component, tx0 uses the
 * upper plane) rather than from a mirrored origin, which would round; and
 * zero direction components handled by DIR_ZERO. */
#include "accel/accel_internal.h"

/* Direction components smaller than this (the largest is scaled to [1, 2))
 * are raised to it, keeping their sign, for the traversal only: the ray then
 * stays within 1e-100 * t of its true path, far inside the cells' padding,
 * and a zero component gets a large finite inverse instead of infinity, so
 * that parameters stay finite (the paper's midpoint (tx0 + tx1) / 2 of -inf
 * and +inf would be NaN) and keep the right sign: a ray lying exactly on a
 * plane crosses it at t = 0. */
#define DIR_ZERO 1e-100

/* At most 3 pending siblings per level of at most PS_OCTREE_MAX_DEPTH_LIMIT. */
#define STACK_SIZE (3 * PS_OCTREE_MAX_DEPTH_LIMIT + 4)

/* The midplanes sorted by crossing parameter, as the child bits of each
 * prefix: sorted_prefix[order][k] is the child past the first k planes.
 * order = (tmx <= tmy) << 2 | (tmy <= tmz) << 1 | (tmx <= tmz), which is a
 * total order with ties going x, y, z; orders 1 and 6 cannot occur. */
static const unsigned char sorted_prefix[8][4] = {
    {0, 1, 3, 7}, /* z y x */
    {0, 4, 6, 7}, /* (impossible) */
    {0, 2, 3, 7}, /* y z x */
    {0, 2, 6, 7}, /* y x z */
    {0, 1, 5, 7}, /* z x y */
    {0, 4, 5, 7}, /* x z y */
    {0, 4, 6, 7}, /* (impossible) */
    {0, 4, 6, 7}, /* x y z */
};

typedef struct trav_item {
    double t0[3], t1[3]; /* the node's entry and exit parameter on each axis (traversal units) */
    uint32_t node;
} trav_item;

/* Plain comparisons rather than fmax / fmin: those handle NaN, so without
 * -ffast-math GCC calls libm for them, and the traversal makes dozens per
 * node. Traversal parameters are never NaN (see DIR_ZERO). */
static inline double max2(double a, double b) { return a > b ? a : b; }
static inline double min2(double a, double b) { return a < b ? a : b; }
static inline double max3(double a, double b, double c) { return max2(a, max2(b, c)); }
static inline double min3(double a, double b, double c) { return min2(a, min2(b, c)); }

/* The parameters of child c of a node, without branches (which the ray's
 * direction makes unpredictable): tt[i] = {t0, tm, t1} on axis i; the lower
 * half (bit clear) spans tt[i][0..1], the upper half tt[i][1..2]. */
#define CHILD_T(c, tt, ct0, ct1)                                                                                 \
    do {                                                                                                         \
        unsigned ux_ = ((c) >> 2) & 1u, uy_ = ((c) >> 1) & 1u, uz_ = (c)&1u;                                     \
        (ct0)[0] = (tt)[0][ux_];                                                                                 \
        (ct1)[0] = (tt)[0][ux_ + 1];                                                                             \
        (ct0)[1] = (tt)[1][uy_];                                                                                 \
        (ct1)[1] = (tt)[1][uy_ + 1];                                                                             \
        (ct0)[2] = (tt)[2][uz_];                                                                                 \
        (ct1)[2] = (tt)[2][uz_ + 1];                                                                             \
    } while (0)

/* The traversal, specialised by the compiler for each dominant axis kz (so the
 * triangle test's permutation is free) and for nearest versus any hit. The
 * node in hand lives in locals; of an interior node's children the nearest is
 * descended into at once and only the others are pushed. */
static PS_ALWAYS_INLINE bool trace(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit,
                                   bool any, int kx, int ky, int kz)
{
    /* Step 1: mirror mask, inverse direction, and the root's parameters. */
    unsigned mirror = 0;
    double t0[3], t1[3];
    double root_lo[3] = {a->root_lo.x, a->root_lo.y, a->root_lo.z};
    for (int i = 0; i < 3; i++) {
        /* |ds| raised to DIR_ZERO (a zero keeps its sign), without branches. */
        double mag = fabs(r->ds[i]);
        mag = mag > DIR_ZERO ? mag : DIR_ZERO;
        double ds = copysign(mag, r->ds[i]), inv = 1.0 / ds;
        bool neg = signbit(ds) != 0;
        mirror |= (unsigned)neg << (2 - i);
        double lo = root_lo[i], hi = root_lo[i] + a->root_side;
        t0[i] = ((neg ? hi : lo) - r->o[i]) * inv;
        t1[i] = ((neg ? lo : hi) - r->o[i]) * inv;
    }

    /* Step 2: clip to [tmin, tmax] (in traversal units: t * tscale, exact). */
    double ts = r->tscale;
    double tmin_s = tmin * ts, best_s = tmax * ts;
    if (max3(t0[0], t0[1], t0[2]) > best_s || min3(t1[0], t1[1], t1[2]) < tmin_s)
        return false;

    ps_hit best = {tmax, UINT32_MAX, 0.0, 0.0};
    bool found = false;
    const accel_node *nodes = a->nodes;
    trav_item stack[STACK_SIZE];
    size_t sp = 0;
    uint32_t node_index = 0;
    for (;;) {
        accel_node node = nodes[node_index];
        if (!(node.count & ACCEL_NODE_INTERIOR)) {
            /* Step 3: a leaf: test its primitives. A hit beyond the leaf only
             * tightens best_s; whether to go on is decided at the next pop. */
            const uint32_t *refs = a->refs + node.index;
            /* Ask for all the leaf's triangles (72 bytes: two cache lines
             * each) before testing any, so that their misses overlap. */
            for (uint32_t k = 0; k < node.count; k++) {
                const char *q = (const char *)&a->tris[refs[k] < a->tri_count ? refs[k] : 0];
                PS_PREFETCH(q);
                PS_PREFETCH(q + sizeof(accel_tri) - 1);
            }
            for (uint32_t k = 0; k < node.count; k++) {
                uint32_t p = refs[k];
                double t, b1 = 0.0, b2 = 0.0;
                uint32_t id;
                if (p < a->tri_count) {
                    t = accel_tri_hit(&a->tris[p], r, kx, ky, kz, &b1, &b2);
                    if (!(t > tmin && t <= best.t))
                        continue;
                    id = a->tri_ids[p];
                } else {
                    t = accel_sphere_hit(&a->spheres[p - a->tri_count], r, tmin);
                    if (!(t > tmin && t <= best.t))
                        continue;
                    id = a->sphere_ids[p - a->tri_count];
                }
                if (!accel_hit_better(t, id, &best, found, tmin))
                    continue;
                if (any)
                    return true;
                best.t = t;
                best.prim = id;
                best.b1 = b1;
                best.b2 = b2;
                found = true;
                best_s = t * ts;
            }
        } else {
            /* Step 4: an interior node. Its children's block (one cache line)
             * is fetched while the order of the children is worked out. Its
             * midplanes' parameters tm; the ray is in it over [start, end]
             * (clipped to tmin and the best hit). */
            PS_PREFETCH(&nodes[node.index]);
            double tt[3][3];
            for (int i = 0; i < 3; i++) {
                tt[i][0] = t0[i];
                tt[i][1] = 0.5 * (t0[i] + t1[i]);
                tt[i][2] = t1[i];
            }
            double tmx = tt[0][1], tmy = tt[1][1], tmz = tt[2][1];
            double start = max2(max3(t0[0], t0[1], t0[2]), tmin_s);
            double end = min2(min3(t1[0], t1[1], t1[2]), best_s);

            /* Step 5: the children in ray order, without branches (the ray
             * makes them unpredictable). first_node and new_node in closed
             * form: sort the midplanes by their parameter; the ray starts in
             * the child past the k0 planes crossed before start, and each
             * plane crossed before end adds its bit, in sorted order. So the
             * children are prefixes of the sorted planes, k0 to k1 long. */
            unsigned order = (tmx <= tmy) << 2 | (tmy <= tmz) << 1 | (unsigned)(tmx <= tmz);
            const unsigned char *prefix = sorted_prefix[order];
            unsigned k0 = (unsigned)(tmx < start) + (tmy < start) + (tmz < start);
            unsigned k1 = (unsigned)(tmx < end) + (tmy < end) + (tmz < end);
            unsigned n = k1 > k0 ? k1 - k0 : 0u;
            /* Keep a child unless past the sequence or not worth a visit (empty). */
            unsigned vis = node.count, seq[4];
            int count = 0;
            for (unsigned m = 0; m < 4; m++) {
                unsigned c = prefix[k0 + m < 3 ? k0 + m : 3];
                seq[count] = c;
                count += (m <= n) & (vis >> (c ^ mirror)) & 1u;
            }

            /* Step 6: push the farther ones (farthest on the bottom), descend
             * into the nearest. */
            if (count > 0) {
                for (int k = count - 1; k > 0; k--) {
                    trav_item *it = &stack[sp++];
                    CHILD_T(seq[k], tt, it->t0, it->t1);
                    it->node = node.index + (seq[k] ^ mirror);
                    /* Its record shares the nearest child's cache line, needed
                     * now anyway; what it points to is fetched meanwhile. */
                    accel_node sn = nodes[it->node];
                    PS_PREFETCH((sn.count & ACCEL_NODE_INTERIOR) ? (const void *)&nodes[sn.index]
                                                                 : (const void *)&a->refs[sn.index]);
                }
                CHILD_T(seq[0], tt, t0, t1);
                node_index = node.index + (seq[0] ^ mirror);
                continue;
            }
        }

        /* Step 7: the next node along the ray. Nodes come off the stack in ray
         * order, so once one starts beyond the best hit, all the rest do too. */
        if (sp == 0)
            break;
        const trav_item *it = &stack[--sp];
        if (max3(it->t0[0], it->t0[1], it->t0[2]) > best_s)
            break;
        for (int i = 0; i < 3; i++) {
            t0[i] = it->t0[i];
            t1[i] = it->t1[i];
        }
        node_index = it->node;
    }
    if (found && !any)
        *hit = best;
    return found;
}

bool ps_accel_octree_trace(const ps_accel *a, const accel_ray *r, double tmin, double tmax, ps_hit *hit, bool any)
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
