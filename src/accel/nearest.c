/* nearest.c: the distance from a point to the nearest primitive, through the
 * octree (best first, pruning cells farther than the best so far) or by
 * testing every primitive (the oracle).
 *
 * Why the pruning is exact: the nearest point q of a primitive lies in the
 * primitive and in some leaf cell; the build files the primitive in every cell
 * it touches (conservatively, padded by cell_pad), so that leaf lists it, and
 * the distance from p to the cell is at most |p - q|. A cell is skipped only
 * when its box grown by cell_pad is strictly farther than the best distance,
 * which the rounding of the box distance (~1e-16 relative) cannot reverse. */
#include "accel/accel_internal.h"

/* Children pushed per level (7) times levels, plus the root. */
#define NEAREST_STACK (7 * PS_OCTREE_MAX_DEPTH_LIMIT + 8)

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The point of triangle t nearest to p, by the Voronoi regions of its
 * vertices, edges and face (Ericson, Real-Time Collision Detection, 5.1.5):
 * the first region whose conditions hold gives the point, so every path
 * through is a few dot products and at most one division. */
static void tri_closest(const accel_tri *t, const double p[3], double q[3])
{
    const double *A = t->v, *B = t->v + 3, *C = t->v + 6;
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int i = 0; i < 3; i++) {
        ab[i] = B[i] - A[i];
        ac[i] = C[i] - A[i];
        ap[i] = p[i] - A[i];
        bp[i] = p[i] - B[i];
        cp[i] = p[i] - C[i];
    }
    /* Vertex regions, then edge regions (each edge between its two vertices' tests). */
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        memcpy(q, A, 3 * sizeof *q);
        return;
    }
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        memcpy(q, B, 3 * sizeof *q);
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        double v = d1 / (d1 - d3);
        for (int i = 0; i < 3; i++)
            q[i] = A[i] + v * ab[i];
        return;
    }
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        memcpy(q, C, 3 * sizeof *q);
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        double w = d2 / (d2 - d6);
        for (int i = 0; i < 3; i++)
            q[i] = A[i] + w * ac[i];
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int i = 0; i < 3; i++)
            q[i] = B[i] + w * (C[i] - B[i]);
        return;
    }
    /* The face: barycentrics from the three areas. */
    double denom = 1.0 / (va + vb + vc);
    double v = vb * denom, w = vc * denom;
    for (int i = 0; i < 3; i++)
        q[i] = A[i] + ab[i] * v + ac[i] * w;
}

/* The point of sphere s's surface nearest to p (from its centre: any point). */
static void sphere_closest(const accel_sphere *s, const double p[3], double q[3])
{
    double f[3] = {p[0] - s->c[0], p[1] - s->c[1], p[2] - s->c[2]};
    double len = sqrt(dot3(f, f));
    if (!(len > 0.0)) {
        q[0] = s->c[0] + s->r;
        q[1] = s->c[1];
        q[2] = s->c[2];
        return;
    }
    double k = s->r / len;
    for (int i = 0; i < 3; i++)
        q[i] = s->c[i] + f[i] * k;
}

typedef struct nearest_best {
    double d2;      /* squared distance of the best so far (starts at max_dist^2) */
    uint32_t prim;  /* its ps_hit id; UINT32_MAX: none yet */
    uint32_t index; /* its internal index */
    double q[3];
} nearest_best;

/* Internal primitive i against the best: closer, or as close with a lower id
 * (so that every search order gives one answer, as for rays). */
static void consider(const ps_accel *a, uint32_t i, const double p[3], nearest_best *b)
{
    double q[3];
    uint32_t id;
    if (i < a->tri_count) {
        tri_closest(&a->tris[i], p, q);
        id = a->tri_ids[i];
    } else {
        sphere_closest(&a->spheres[i - a->tri_count], p, q);
        id = a->sphere_ids[i - a->tri_count];
    }
    double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    double d2 = dot3(d, d);
    if (d2 < b->d2 || (d2 == b->d2 && id < b->prim)) {
        b->d2 = d2;
        b->prim = id;
        b->index = i;
        memcpy(b->q, q, sizeof b->q);
    }
}

/* Squared distance from p to the cube [lo, lo + side]^3 grown by pad. */
static double box_d2(const double p[3], const double lo[3], double side, double pad)
{
    double d2 = 0.0;
    for (int i = 0; i < 3; i++) {
        double l = lo[i] - pad, h = lo[i] + side + pad;
        double e = p[i] < l ? l - p[i] : p[i] > h ? p[i] - h : 0.0;
        d2 += e * e;
    }
    return d2;
}

typedef struct near_item {
    double lo[3], side, d2;
    uint32_t node;
} near_item;

static void octree_nearest(const ps_accel *a, const double p[3], nearest_best *b)
{
    near_item stack[NEAREST_STACK];
    size_t sp = 0;
    stack[sp++] = (near_item){{a->root_lo.x, a->root_lo.y, a->root_lo.z}, a->root_side, 0.0, 0};
    stack[0].d2 = box_d2(p, stack[0].lo, stack[0].side, a->cell_pad);
    while (sp > 0) {
        near_item it = stack[--sp];
        if (it.d2 > b->d2)
            continue;
        accel_node node = a->nodes[it.node];
        if (!(node.count & ACCEL_NODE_INTERIOR)) {
            for (uint32_t k = 0; k < node.count; k++)
                consider(a, a->refs[node.index + k], p, b);
            continue;
        }
        /* The non-empty children, nearest last so that it is popped first. */
        near_item kids[8];
        int n = 0;
        double half = 0.5 * it.side;
        for (unsigned c = 0; c < 8; c++) {
            if (!((node.count >> c) & 1u))
                continue;
            near_item k = {{it.lo[0] + ((c & 4) ? half : 0.0), it.lo[1] + ((c & 2) ? half : 0.0),
                            it.lo[2] + ((c & 1) ? half : 0.0)},
                           half, 0.0, node.index + c};
            k.d2 = box_d2(p, k.lo, half, a->cell_pad);
            if (k.d2 > b->d2)
                continue;
            /* Insertion by decreasing distance (at most 8). */
            int j = n++;
            while (j > 0 && kids[j - 1].d2 < k.d2) {
                kids[j] = kids[j - 1];
                j--;
            }
            kids[j] = k;
        }
        for (int j = 0; j < n; j++)
            stack[sp++] = kids[j];
    }
}

static bool nearest(const ps_accel *a, ps_vec3 point, double max_dist, ps_nearest *out, bool force_brute)
{
    double p[3] = {point.x, point.y, point.z};
    if (!a || !ps_v3_isfinite(point) || !(max_dist >= 0.0))
        return false;
    nearest_best b = {max_dist * max_dist, UINT32_MAX, 0, {0.0, 0.0, 0.0}};
    if (max_dist == INFINITY)
        b.d2 = INFINITY;
    if (force_brute || a->kind != PS_ACCEL_OCTREE || a->node_count == 0) {
        uint32_t n = a->tri_count + a->sphere_count;
        for (uint32_t i = 0; i < n; i++)
            consider(a, i, p, &b);
    } else {
        octree_nearest(a, p, &b);
    }
    if (b.prim == UINT32_MAX)
        return false;
    if (out) {
        out->distance = sqrt(b.d2);
        out->prim = b.prim;
        out->point = ps_v3(b.q[0], b.q[1], b.q[2]);
    }
    return true;
}

bool ps_accel_nearest(const ps_accel *a, ps_vec3 p, double max_dist, ps_nearest *out)
{
    return nearest(a, p, max_dist, out, false);
}

bool ps_accel_nearest_brute(const ps_accel *a, ps_vec3 p, double max_dist, ps_nearest *out)
{
    return nearest(a, p, max_dist, out, true);
}

double ps_accel_nearest_distance(const ps_accel *a, ps_vec3 p)
{
    ps_nearest n;
    return nearest(a, p, INFINITY, &n, false) ? n.distance : INFINITY;
}
