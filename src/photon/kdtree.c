/* kdtree.c: balancing a photon array into a left-balanced kd-tree, and the
 * k-nearest search with a bounded max-heap (thesis 2.5, Jensen 1996). */
#include "photon/kdtree.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

struct ps_kdtree {
    /* heap[1..count]: node i's children are 2i and 2i + 1. heap[0] is unused,
     * so that the arithmetic stays the thesis'. */
    ps_photon *heap;
    size_t count;
    ps_aabb bounds;
};

/* Both the build and the search are depth-first with an explicit stack that
 * holds at most one pending subtree per level (plus one), and a tree of at
 * most UINT32_MAX photons has 32 levels. */
#define KD_STACK 64

static double coord(const ps_photon *p, int axis) { return p->pos[axis]; }

/* ---- building ------------------------------------------------------------ */

/* How many of a segment's n photons go into the left subtree so that the
 * tree stays left-balanced (every level full but the last, which fills from
 * the left); Jensen's rule. m ends as the largest power of two with 2m <= n,
 * the most nodes the left subtree's last level can hold: when the tree's last
 * level reaches past the left half, the left subtree is complete (2m - 1
 * nodes); else the right one holds only its full levels (m - 1 nodes) and the
 * left the rest, n - m. */
static size_t left_size(size_t n)
{
    size_t m = 1;
    while (4 * m <= n)
        m *= 2;
    return 3 * m <= n ? 2 * m - 1 : n - m;
}

/* Rearranges idx[0, n) so that the element at position m is the one a sort on
 * `axis` would put there, no greater ones before it and no smaller ones after
 * (Hoare's selection, as in Wirth; expected linear time, and runs of equal
 * coordinates split evenly instead of degrading it). */
static void select_median(const ps_photon *src, uint32_t *idx, size_t n, size_t m, int axis)
{
    ptrdiff_t lo = 0, hi = (ptrdiff_t)n - 1, want = (ptrdiff_t)m;
    while (lo < hi) {
        /* The median of three as the pivot keeps sorted input from degrading it. */
        ptrdiff_t mid = lo + (hi - lo) / 2;
        double a = coord(&src[idx[lo]], axis), b = coord(&src[idx[mid]], axis), c = coord(&src[idx[hi]], axis);
        double pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        ptrdiff_t i = lo, j = hi;
        while (i <= j) {
            while (coord(&src[idx[i]], axis) < pivot)
                i++;
            while (coord(&src[idx[j]], axis) > pivot)
                j--;
            if (i <= j) {
                uint32_t t = idx[i];
                idx[i++] = idx[j];
                idx[j--] = t;
            }
        }
        /* Now [lo, j] <= pivot <= [i, hi], and anything between equals it. */
        if (want <= j)
            hi = j;
        else if (want >= i)
            lo = i;
        else
            return;
    }
}

/* One pending segment of the build: idx[first, first + n) becomes the subtree
 * rooted at heap node `node`, inside box b. An explicit stack instead of
 * recursion, like the search. */
typedef struct build_item {
    size_t first, n, node;
    ps_aabb b;
} build_item;

static int widest_axis(ps_aabb b)
{
    ps_vec3 d = ps_aabb_diag(b);
    return d.x >= d.y && d.x >= d.z ? 0 : (d.y >= d.z ? 1 : 2);
}

static void balance(const ps_photon *src, uint32_t *idx, size_t count, ps_aabb bounds, ps_photon *heap)
{
    build_item stack[KD_STACK];
    int top = 0;
    stack[top++] = (build_item){0, count, 1, bounds};
    while (top > 0) {
        build_item it = stack[--top];
        if (it.n == 1) {
            heap[it.node] = src[idx[it.first]];
            ps_photon_set_flags(&heap[it.node], 0);
            continue;
        }
        /* Thesis 2.5: split on the dimension of greatest extent, at the median.
         * The box is narrowed at each split rather than recomputed, which keeps
         * building O(n log n). */
        int axis = widest_axis(it.b);
        size_t m = left_size(it.n);
        select_median(src, idx + it.first, it.n, m, axis);
        const ps_photon *median = &src[idx[it.first + m]];
        heap[it.node] = *median;
        ps_photon_set_flags(&heap[it.node], (unsigned)axis);
        double split = coord(median, axis);
        size_t right_n = it.n - m - 1;
        if (right_n > 0) {
            ps_aabb rb = it.b;
            if (axis == 0) rb.lo.x = split;
            else if (axis == 1) rb.lo.y = split;
            else rb.lo.z = split;
            stack[top++] = (build_item){it.first + m + 1, right_n, 2 * it.node + 1, rb};
        }
        if (m > 0) {
            ps_aabb lb = it.b;
            if (axis == 0) lb.hi.x = split;
            else if (axis == 1) lb.hi.y = split;
            else lb.hi.z = split;
            stack[top++] = (build_item){it.first, m, 2 * it.node, lb};
        }
    }
}

ps_status ps_kdtree_build(const ps_photon *photons, size_t count, ps_kdtree **out, ps_error *err)
{
    *out = NULL;
    if (count > UINT32_MAX - 1)
        return ps_error_set(err, PS_ERR_LIMIT, "kd-tree: %zu photons exceed the limit of %u", count,
                            (unsigned)UINT32_MAX - 1);
    ps_kdtree *t = calloc(1, sizeof *t);
    uint32_t *idx = count ? malloc(count * sizeof *idx) : NULL;
    if (t)
        t->heap = malloc((count + 1) * sizeof *t->heap);
    if (!t || !t->heap || (count && !idx)) {
        free(idx);
        ps_kdtree_destroy(t);
        return ps_error_set(err, PS_ERR_NOMEM, "kd-tree: out of memory for %zu photons", count);
    }
    t->count = count;
    t->bounds = ps_aabb_empty();
    for (size_t i = 0; i < count; i++) {
        idx[i] = (uint32_t)i;
        t->bounds = ps_aabb_point(t->bounds, ps_photon_position(&photons[i]));
    }
    memset(&t->heap[0], 0, sizeof t->heap[0]);
    if (count)
        balance(photons, idx, count, t->bounds, t->heap);
    free(idx);
    *out = t;
    return PS_OK;
}

void ps_kdtree_destroy(ps_kdtree *t)
{
    if (!t)
        return;
    free(t->heap);
    free(t);
}

size_t ps_kdtree_count(const ps_kdtree *t) { return t->count; }
const ps_photon *ps_kdtree_photons(const ps_kdtree *t) { return t->heap + 1; }
ps_aabb ps_kdtree_bounds(const ps_kdtree *t) { return t->bounds; }

/* ---- searching ----------------------------------------------------------- */

/* A max-heap on d2 of the neighbours found so far (out[0] the farthest). */
static void heap_push(ps_neighbor *h, size_t n, ps_neighbor v)
{
    size_t i = n;
    while (i > 0) {
        size_t parent = (i - 1) / 2;
        if (h[parent].d2 >= v.d2)
            break;
        h[i] = h[parent];
        i = parent;
    }
    h[i] = v;
}

static void heap_replace_top(ps_neighbor *h, size_t n, ps_neighbor v)
{
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && h[c + 1].d2 > h[c].d2)
            c++;
        if (h[c].d2 <= v.d2)
            break;
        h[i] = h[c];
        i = c;
    }
    h[i] = v;
}

/* A subtree still to visit, and how far its half-space is from the query. */
typedef struct search_item {
    size_t node;
    double plane_d2;
} search_item;

size_t ps_kdtree_knn(const ps_kdtree *t, const ps_kdtree_query *q, ps_neighbor *out, double *r2)
{
    double max_d2 = q->max_radius * q->max_radius;
    if (r2)
        *r2 = max_d2;
    if (t->count == 0 || q->k == 0)
        return 0;
    const double p[3] = {q->p.x, q->p.y, q->p.z};
    bool filter = ps_v3_len2(q->normal) > 0.0;
    size_t found = 0;
    search_item stack[KD_STACK];
    int top = 0;
    stack[top++] = (search_item){1, 0.0};
    while (top > 0) {
        search_item it = stack[--top];
        /* The bound may have shrunk since this subtree was pushed. */
        if (it.plane_d2 > max_d2)
            continue;
        size_t node = it.node;
        /* Walk down to a leaf on the near side, pushing the far sides. */
        while (node <= t->count) {
            const ps_photon *ph = &t->heap[node];
            size_t left = 2 * node;
            if (left <= t->count) {
                int axis = (int)ps_photon_flags(ph);
                double delta = p[axis] - coord(ph, axis);
                size_t near = delta <= 0.0 ? left : left + 1, far = delta <= 0.0 ? left + 1 : left;
                double d2 = delta * delta;
                if (far <= t->count && d2 <= max_d2)
                    stack[top++] = (search_item){far, d2};
                /* Look at this node's own photon once its near side is done:
                 * pushed as a zero-size subtree would be, so it is simpler to
                 * test it here; the order does not change the result. */
                node = near;
            } else {
                node = left; /* a leaf: only its own photon below */
            }
            double dx = ph->pos[0] - p[0], dy = ph->pos[1] - p[1], dz = ph->pos[2] - p[2];
            double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 > max_d2 || (found == q->k && d2 >= max_d2))
                continue;
            if (filter && ps_v3_dot(ps_photon_normal(ph), q->normal) <= q->min_cos)
                continue;
            ps_neighbor nb = {d2, (uint32_t)(ph - t->heap - 1)};
            if (found < q->k) {
                heap_push(out, found++, nb);
                if (found == q->k)
                    max_d2 = out[0].d2; /* full: only closer photons matter now */
            } else {
                heap_replace_top(out, found, nb);
                max_d2 = out[0].d2;
            }
        }
    }
    if (r2 && found == q->k)
        *r2 = out[0].d2;
    return found;
}

bool ps_kdtree_check(const ps_kdtree *t)
{
    /* For every node, walk up its ancestors: on each ancestor's axis, a node in
     * its left subtree is <= the ancestor's split, in its right >= it. */
    for (size_t i = 2; i <= t->count; i++) {
        for (size_t child = i, anc = i / 2; anc >= 1; child = anc, anc /= 2) {
            int axis = (int)ps_photon_flags(&t->heap[anc]);
            double c = coord(&t->heap[i], axis), s = coord(&t->heap[anc], axis);
            if (axis > 2 || (child == 2 * anc && c > s) || (child == 2 * anc + 1 && c < s))
                return false;
        }
    }
    return true;
}
