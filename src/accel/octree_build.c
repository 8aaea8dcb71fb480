/* octree_build.c: builds the octree over an accelerator's primitives.
 *
 * The root is a cube around all primitives, padded a little; a node is split
 * at its centre into eight children and every primitive goes into each child
 * it overlaps. Departure from the thesis (section 4.1.2), which files a
 * primitive in every cell its bounding box overlaps: triangles are filed with
 * the exact triangle/box separating-axis test of Akenine-Möller (2001) and
 * spheres with Arvo's (1990) box/sphere-surface test. A long diagonal
 * triangle's box overlaps many cells its plane never touches; those extra
 * references would each cost a triangle test per ray crossing the cell.
 *
 * Every overlap test is made against a child box grown by `tol` (a tiny
 * fraction of the scene), so a primitive touching a cell face, or within
 * rounding of it, is filed on both sides: the traversal, whose cell
 * boundaries are rounded ray parameters, can then never miss it. */
#define _DEFAULT_SOURCE /* madvise's MADV_HUGEPAGE (Linux) */
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "accel/accel_internal.h"
#include "core/array.h"

/* Padding of the root cube and of every overlap test, relative to the root's
 * side; and relative to the coordinates' magnitude, for a small scene far from
 * the origin, where rounding follows the coordinates rather than the size.
 * Both are far above the rounding of traversal parameters (~1e-16) and far
 * below any cell a tree of PS_OCTREE_MAX_DEPTH_LIMIT levels makes useful. */
#define PAD_REL_SIZE 1e-9
#define PAD_REL_POSITION 1e-12
/* A cube of side 0 (all primitives at one point at the origin) still needs a size. */
#define PAD_MIN 1e-300

/* Split or stay a leaf: a greedy cost model in units of one triangle test.
 * A ray crossing a node crosses a child with probability about the ratio of
 * their surface areas, 1/4 for a cube and its octant. A leaf costs its visit
 * plus a test per reference; an interior node its visit plus, for each
 * non-empty child, a quarter of that child's cost as a leaf. The visit costs
 * were tuned with bench_accel (1k to 1M triangles) once leaves were tested
 * four triangles at a time (octree_trace_avx2.c): rays per second change
 * little for COST_INTERIOR from 4 to 32, while the build time and the
 * references fall as it grows (at 10^6 triangles, 8 -> 16: 5.35 -> 3.84
 * references per triangle, build 25 % faster); 16 keeps the speed of the
 * smaller values. So a node whose primitives mostly straddle its centre, or
 * that holds only a few, stays a leaf. */
#define COST_INTERIOR 16.0
#define COST_LEAF 2.0
#define CHILD_HIT_FRACTION 0.25

typedef struct build_ctx {
    const ps_accel *a;
    ps_aabb *boxes;   /* per primitive (internal index), for the quick classification */
    accel_node *nodes;
    size_t node_count, node_cap;
    uint32_t *refs;
    size_t ref_count, ref_cap;
    /* Primitive lists of the nodes on the current path, as a stack: a split
     * node's children's lists follow everything in use, so a child's own
     * children go after all its siblings' lists. */
    uint32_t *lists;
    size_t list_cap;
    uint8_t *masks;   /* per primitive of the node being split: the children it overlaps */
    double tol;
    int max_depth, leaf_prims;
    size_t leaves, max_depth_reached;
} build_ctx;

/* ---- overlap tests ---------------------------------------------------------- */

/* Triangle/box overlap by the separating-axis theorem (Akenine-Möller 2001):
 * a box and a triangle are disjoint iff one of 13 axes separates them: the 3
 * box normals, the triangle's normal and the 9 cross products of box normals
 * with triangle edges. The box normals are the bounding-box test classify()
 * has already made; this tests the other 10 for each candidate child
 * (bit c of `candidates`; centres lo + offsets, half side h) and returns the
 * children that overlap. The triangle's projections are computed once for
 * all children: only the centre's projection changes. Near-zero axes (from
 * slivers) project everything to about 0 and never separate: conservative. */
static unsigned tri_children_overlap(const accel_tri *tri, unsigned candidates, ps_vec3 lo, double half, double h)
{
    enum { AXES = 10 };
    const double *p = tri->v;
    double axis[AXES][3], mn[AXES], mx[AXES], rad[AXES];
    /* Step 1: the axes: e_i x edge_k (e_i the box's i-th normal), then the normal. */
    int n = 0;
    for (int k = 0; k < 3; k++) {
        const double *s = p + 3 * k, *t = p + 3 * ((k + 1) % 3);
        double e[3] = {t[0] - s[0], t[1] - s[1], t[2] - s[2]};
        for (int i = 0; i < 3; i++, n++) {
            int j = (i + 1) % 3, l = (i + 2) % 3;
            axis[n][i] = 0.0;
            axis[n][j] = -e[l];
            axis[n][l] = e[j];
        }
    }
    double e0[3] = {p[3] - p[0], p[4] - p[1], p[5] - p[2]}, e1[3] = {p[6] - p[0], p[7] - p[1], p[8] - p[2]};
    axis[n][0] = e0[1] * e1[2] - e0[2] * e1[1];
    axis[n][1] = e0[2] * e1[0] - e0[0] * e1[2];
    axis[n][2] = e0[0] * e1[1] - e0[1] * e1[0];
    /* Step 2: the triangle's extent along each axis, and the box's radius. */
    for (int k = 0; k < AXES; k++) {
        const double *ax = axis[k];
        double d0 = ax[0] * p[0] + ax[1] * p[1] + ax[2] * p[2];
        double d1 = ax[0] * p[3] + ax[1] * p[4] + ax[2] * p[5];
        double d2 = ax[0] * p[6] + ax[1] * p[7] + ax[2] * p[8];
        mn[k] = d0 < d1 ? d0 : d1;
        mx[k] = d0 < d1 ? d1 : d0;
        mn[k] = d2 < mn[k] ? d2 : mn[k];
        mx[k] = d2 > mx[k] ? d2 : mx[k];
        rad[k] = h * (fabs(ax[0]) + fabs(ax[1]) + fabs(ax[2]));
    }
    /* Step 3: each candidate child: separated when the triangle's extent,
     * relative to the child's centre, lies beyond the radius on either side. */
    unsigned overlap = 0;
    double qh = 0.5 * half;
    for (unsigned c = 0; c < 8; c++) {
        if (!(candidates & (1u << c)))
            continue;
        double cc[3] = {lo.x + ((c & 4) ? half : 0.0) + qh, lo.y + ((c & 2) ? half : 0.0) + qh,
                        lo.z + ((c & 1) ? half : 0.0) + qh};
        bool separated = false;
        for (int k = 0; k < AXES && !separated; k++) {
            double dc = axis[k][0] * cc[0] + axis[k][1] * cc[1] + axis[k][2] * cc[2];
            separated = mn[k] - dc > rad[k] || mx[k] - dc < -rad[k];
        }
        if (!separated)
            overlap |= 1u << c;
    }
    return overlap;
}

/* Sphere-surface/box overlap (Arvo 1990, the hollow-sphere case): the surface
 * meets the box iff the box's nearest point is no farther than r from the
 * centre and its farthest point no nearer. Cells wholly inside a sphere get no
 * reference: a ray there hits the sphere only where it leaves the cell. */
static bool sphere_box_overlap(const accel_sphere *s, ps_vec3 c, double h)
{
    double cc[3] = {c.x, c.y, c.z};
    double dmin = 0.0, dmax = 0.0;
    for (int i = 0; i < 3; i++) {
        double lo = cc[i] - h, hi = cc[i] + h, x = s->c[i];
        double near = x < lo ? lo - x : x > hi ? x - hi : 0.0;
        double far = x - lo > hi - x ? x - lo : hi - x;
        dmin += near * near;
        dmax += far * far;
    }
    double r2 = s->r * s->r;
    return dmin <= r2 && r2 <= dmax;
}

/* Large arrays that every ray reads at random (triangles, nodes) in 2 MiB
 * pages where the system offers them: a million-triangle scene's 100 MB would
 * otherwise miss the TLB on nearly every triangle. Freed with free(). */
#define HUGE_PAGE (2u << 20)
static void *alloc_traversed(size_t bytes)
{
    if (bytes < 2 * HUGE_PAGE)
        return aligned_alloc(ACCEL_NODE_ALIGN, (bytes + ACCEL_NODE_ALIGN - 1) / ACCEL_NODE_ALIGN * ACCEL_NODE_ALIGN);
    size_t rounded = (bytes + HUGE_PAGE - 1) / HUGE_PAGE * HUGE_PAGE;
    void *p = aligned_alloc(HUGE_PAGE, rounded);
#ifdef MADV_HUGEPAGE
    if (p)
        (void)madvise(p, rounded, MADV_HUGEPAGE); /* advice only: without it the pages are small */
#endif
    return p;
}

/* ---- building --------------------------------------------------------------- */

static ps_status no_memory(ps_error *err)
{
    return ps_error_set(err, PS_ERR_NOMEM, "accel: out of memory building the octree");
}

/* The children (bit c set in the result) whose padded boxes primitive p overlaps,
 * for the node with corner lo and centre mid (half = half its side). */
static unsigned classify(const build_ctx *b, uint32_t p, ps_vec3 lo, ps_vec3 mid, double half)
{
    /* Step 1: which halves the primitive's box reaches along each axis. */
    ps_aabb box = b->boxes[p];
    double tol = b->tol;
    unsigned lower[3] = {box.lo.x <= mid.x + tol, box.lo.y <= mid.y + tol, box.lo.z <= mid.z + tol};
    unsigned upper[3] = {box.hi.x >= mid.x - tol, box.hi.y >= mid.y - tol, box.hi.z >= mid.z - tol};
    unsigned mask = 0, candidates = 0;
    for (unsigned c = 0; c < 8; c++) {
        bool in = ((c & 4) ? upper[0] : lower[0]) && ((c & 2) ? upper[1] : lower[1]) && ((c & 1) ? upper[2] : lower[2]);
        if (in) {
            mask |= 1u << c;
            candidates++;
        }
    }
    /* Step 2: in one child only: no exact test needed (it overlaps the parent). */
    if (candidates <= 1)
        return mask;
    /* Step 3: the exact test against each candidate child. */
    const ps_accel *a = b->a;
    double qh = 0.5 * half, h = qh + tol;
    if (p < a->tri_count)
        return tri_children_overlap(&a->tris[p], mask, lo, half, h);
    unsigned exact = 0;
    for (unsigned c = 0; c < 8; c++) {
        if (!(mask & (1u << c)))
            continue;
        ps_vec3 cc = ps_v3(lo.x + ((c & 4) ? half : 0.0) + qh, lo.y + ((c & 2) ? half : 0.0) + qh,
                           lo.z + ((c & 1) ? half : 0.0) + qh);
        if (sphere_box_overlap(&a->spheres[p - a->tri_count], cc, h))
            exact |= 1u << c;
    }
    return exact;
}

/* A leaf lists its references in the order of its list: ascending internal
 * index, so its triangles come before its spheres (reorder_triangles keeps
 * that: triangles are renumbered among themselves), which lets the AVX2
 * traversal take the triangles four at a time without looking at each. */
static ps_status make_leaf(build_ctx *b, uint32_t node, size_t list_off, size_t n, ps_error *err)
{
    if (b->ref_count + n > ACCEL_MAX_REFS)
        return ps_error_set(err, PS_ERR_LIMIT, "accel: octree needs more than %u primitive references",
                            (unsigned)ACCEL_MAX_REFS);
    if (!PS_RESERVE(b->refs, b->ref_cap, b->ref_count + n))
        return no_memory(err);
    if (n > 0)
        memcpy(b->refs + b->ref_count, b->lists + list_off, n * sizeof *b->refs);
    b->nodes[node].index = (uint32_t)b->ref_count;
    b->nodes[node].count = (uint32_t)n;
    b->ref_count += n;
    b->leaves++;
    return PS_OK;
}

/* Builds node `node` (already allocated) over the n primitives at
 * lists[list_off..], a cube with corner lo and the given side; lists from
 * free_off on are free (the lists of the node's siblings lie between). Recursion
 * is bounded by max_depth (at most PS_OCTREE_MAX_DEPTH_LIMIT). */
static ps_status build_node(build_ctx *b, uint32_t node, ps_vec3 lo, double side, int depth, size_t list_off,
                            size_t n, size_t free_off, ps_error *err)
{
    if ((size_t)depth > b->max_depth_reached)
        b->max_depth_reached = (size_t)depth;
    if (n <= (size_t)b->leaf_prims || depth >= b->max_depth)
        return make_leaf(b, node, list_off, n, err);

    /* Step 1: which children each primitive overlaps, and how many each child gets. */
    double half = 0.5 * side;
    ps_vec3 mid = ps_v3(lo.x + half, lo.y + half, lo.z + half);
    size_t counts[8] = {0}, total = 0, nonempty = 0, largest = 0, confined = 0;
    for (size_t k = 0; k < n; k++) {
        unsigned m = classify(b, b->lists[list_off + k], lo, mid, half);
        b->masks[k] = (uint8_t)m;
        confined += (m & (m - 1)) == 0; /* in one child only */
        for (unsigned c = 0; c < 8; c++)
            counts[c] += (m >> c) & 1u;
    }
    for (unsigned c = 0; c < 8; c++) {
        total += counts[c];
        nonempty += counts[c] > 0;
        largest = counts[c] > largest ? counts[c] : largest;
    }
    /* No progress possible: a child would keep every primitive and every one
     * straddles the centre, as a fan of triangles around a shared vertex does
     * at any depth (or a cluster at the centre). Splitting on would copy them
     * all into ever smaller cells down to max_depth. A small object in a
     * large empty cell is different: its primitives fit in one child, and
     * splitting on is how the tree reaches its scale. */
    if (largest == n && confined == 0)
        return make_leaf(b, node, list_off, n, err);

    /* Step 2: split only when the cost model says it pays; the root always
     * splits (when it holds more than leaf_prims), so that a caller who asks
     * for an octree gets a tree even in a scene as small as the default one. */
    double split_cost = COST_INTERIOR + CHILD_HIT_FRACTION * (COST_LEAF * (double)nonempty + (double)total);
    if (depth > 0 && split_cost >= COST_LEAF + (double)n)
        return make_leaf(b, node, list_off, n, err);

    /* Step 3: the children's lists, in the free space. */
    size_t child_off[8], off = free_off;
    if (!PS_RESERVE(b->lists, b->list_cap, off + total))
        return no_memory(err);
    for (unsigned c = 0; c < 8; c++) {
        child_off[c] = off;
        off += counts[c];
    }
    size_t fill[8];
    memcpy(fill, child_off, sizeof fill);
    for (size_t k = 0; k < n; k++) {
        uint32_t p = b->lists[list_off + k];
        for (unsigned c = 0; c < 8; c++)
            if (b->masks[k] & (1u << c))
                b->lists[fill[c]++] = p;
    }

    /* Step 4: eight contiguous child nodes, then each child's subtree. */
    if (b->node_count + ACCEL_NODE_BLOCK > UINT32_MAX - 1)
        return ps_error_set(err, PS_ERR_LIMIT, "accel: octree needs more than %u nodes", (unsigned)UINT32_MAX - 1);
    if (!PS_RESERVE(b->nodes, b->node_cap, b->node_count + ACCEL_NODE_BLOCK))
        return no_memory(err);
    uint32_t first = (uint32_t)b->node_count;
    b->node_count += ACCEL_NODE_BLOCK;
    unsigned visit = 0;
    for (unsigned c = 0; c < 8; c++) {
        ps_vec3 clo = ps_v3(lo.x + ((c & 4) ? half : 0.0), lo.y + ((c & 2) ? half : 0.0), lo.z + ((c & 1) ? half : 0.0));
        ps_status st = build_node(b, first + c, clo, half, depth + 1, child_off[c], counts[c], off, err);
        if (st != PS_OK)
            return st;
        if (b->nodes[first + c].count != 0)
            visit |= 1u << c;
    }
    b->nodes[node].index = first;
    b->nodes[node].count = ACCEL_NODE_INTERIOR | visit;
    return PS_OK;
}

/* Stores the triangles in the order the leaves first reference them, so that
 * a leaf's triangles are mostly neighbours in memory, and renumbers refs. */
static ps_status reorder_triangles(ps_accel *a, ps_error *err)
{
    uint32_t nt = a->tri_count;
    if (nt == 0)
        return PS_OK;
    uint32_t *new_index = malloc(sizeof *new_index * nt);
    accel_tri *tris = alloc_traversed(sizeof *tris * nt);
    uint32_t *ids = malloc(sizeof *ids * nt);
    if (!new_index || !tris || !ids) {
        free(new_index);
        free(tris);
        free(ids);
        return no_memory(err);
    }
    for (uint32_t i = 0; i < nt; i++)
        new_index[i] = UINT32_MAX;
    uint32_t next = 0;
    for (size_t k = 0; k < a->ref_count; k++) {
        uint32_t p = a->refs[k];
        if (p >= nt)
            continue;
        if (new_index[p] == UINT32_MAX)
            new_index[p] = next++;
        a->refs[k] = new_index[p];
    }
    /* Every triangle lies in the root, so all are referenced; any that were
     * not (none should be) still go to the end, for the oracle. */
    for (uint32_t i = 0; i < nt; i++)
        if (new_index[i] == UINT32_MAX)
            new_index[i] = next++;
    for (uint32_t i = 0; i < nt; i++) {
        tris[new_index[i]] = a->tris[i];
        ids[new_index[i]] = a->tri_ids[i];
    }
    free(a->tris);
    free(a->tri_ids);
    a->tris = tris;
    a->tri_ids = ids;
    free(new_index);
    return PS_OK;
}

/* The box of hittable primitive p. */
static ps_aabb prim_box(const ps_accel *a, uint32_t p)
{
    ps_aabb b = ps_aabb_empty();
    if (p < a->tri_count) {
        const double *v = a->tris[p].v;
        for (int k = 0; k < 3; k++)
            b = ps_aabb_point(b, ps_v3(v[3 * k], v[3 * k + 1], v[3 * k + 2]));
    } else {
        const accel_sphere *s = &a->spheres[p - a->tri_count];
        ps_vec3 c = ps_v3(s->c[0], s->c[1], s->c[2]), r = ps_v3(s->r, s->r, s->r);
        b.lo = ps_v3_sub(c, r);
        b.hi = ps_v3_add(c, r);
    }
    return b;
}

ps_status ps_accel_octree_build(ps_accel *a, int max_depth, int leaf_prims, ps_error *err)
{
    size_t n = (size_t)a->tri_count + a->sphere_count;
    build_ctx b;
    memset(&b, 0, sizeof b);
    b.a = a;
    b.max_depth = max_depth;
    b.leaf_prims = leaf_prims;
    ps_status st = PS_OK;

    /* Step 1: the root cube around the hittable primitives, padded. A cube
     * rather than the tight box keeps cells cubic in elongated scenes, and a
     * flat scene then lies along the root's lower faces instead of on every
     * level's split plane (where it would be filed on both sides each time). */
    b.boxes = malloc(sizeof *b.boxes * (n ? n : 1));
    b.masks = malloc(n ? n : 1);
    if (!b.boxes || !b.masks) {
        st = no_memory(err);
        goto done;
    }
    ps_aabb box = ps_aabb_empty();
    for (uint32_t p = 0; p < n; p++) {
        b.boxes[p] = prim_box(a, p);
        box = ps_aabb_union(box, b.boxes[p]);
    }
    double side = 0.0, magnitude = 0.0;
    if (n > 0) {
        side = ps_v3_max_comp(ps_aabb_diag(box));
        magnitude = ps_aabb_extent(box);
    }
    b.tol = fmax(fmax(PAD_REL_SIZE * side, PAD_REL_POSITION * magnitude), PAD_MIN);
    /* The root is padded by more than the tests are, so no primitive sits within tol of its faces. */
    double root_pad = 2.0 * b.tol;
    a->root_lo = n > 0 ? ps_v3(box.lo.x - root_pad, box.lo.y - root_pad, box.lo.z - root_pad) : ps_v3(0, 0, 0);
    a->root_side = side + 2.0 * root_pad;
    a->cell_pad = b.tol;

    /* Step 2: the root holds every primitive; build depth first. */
    if (!PS_RESERVE(b.lists, b.list_cap, n ? n : 1) || !PS_RESERVE(b.nodes, b.node_cap, ACCEL_NODE_BLOCK)) {
        st = no_memory(err);
        goto done;
    }
    for (uint32_t p = 0; p < n; p++)
        b.lists[p] = p;
    /* The root alone in the first block, so that every block of eight
     * children starts at a multiple of 8 nodes: one 64-byte cache line. */
    memset(b.nodes, 0, sizeof *b.nodes * ACCEL_NODE_BLOCK);
    b.node_count = ACCEL_NODE_BLOCK;
    st = build_node(&b, 0, a->root_lo, a->root_side, 0, 0, n, n, err);
    if (st != PS_OK)
        goto done;

    /* Step 3: hand the arrays over (nodes cache-line aligned) and lay the
     * triangles out in leaf order. */
    size_t node_bytes = sizeof *b.nodes * b.node_count;
    node_bytes = (node_bytes + ACCEL_NODE_ALIGN - 1) / ACCEL_NODE_ALIGN * ACCEL_NODE_ALIGN;
    a->nodes = alloc_traversed(node_bytes);
    if (!a->nodes) {
        st = no_memory(err);
        goto done;
    }
    memcpy(a->nodes, b.nodes, sizeof *b.nodes * b.node_count);
    a->node_count = b.node_count;
    /* The references move to their own array (growth left up to half of
     * b.refs unused), in large pages like the nodes. */
    a->refs = alloc_traversed(sizeof *b.refs * (b.ref_count ? b.ref_count : 1));
    if (!a->refs) {
        st = no_memory(err);
        goto done;
    }
    if (b.ref_count)
        memcpy(a->refs, b.refs, sizeof *b.refs * b.ref_count);
    a->ref_count = b.ref_count;
    st = reorder_triangles(a, err);
    /* Nodes 1..7 only pad the root's block. */
    a->stats.nodes = b.node_count > ACCEL_NODE_BLOCK ? b.node_count - (ACCEL_NODE_BLOCK - 1) : 1;
    a->stats.leaves = b.leaves;
    a->stats.prim_refs = a->ref_count;
    a->stats.max_depth_reached = b.max_depth_reached;
done:
    free(b.boxes);
    free(b.masks);
    free(b.lists);
    free(b.nodes);
    free(b.refs);
    return st;
}
