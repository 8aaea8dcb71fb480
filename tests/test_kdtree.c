/* test_kdtree.c: the balanced kd-tree photon map against a brute-force
 * oracle: k-nearest on random sets of every small size and on large ones,
 * ties (duplicate positions, integer grids), the search radius, the normal
 * filter, the heap layout and its invariant, degenerate and adversarial
 * (sorted, reversed) inputs.
 *
 * The oracle computes each squared distance exactly as the tree does (float
 * position minus double query, in double, dx*dx + dy*dy + dz*dz), so the
 * sorted distances must agree bit for bit: ties may pick other photons, but
 * never other distances. */
#include "core/clock.h"
#include "test.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/rng.h"
#include "photon/kdtree.h"
#include "photon/photon.h"

/* The largest k any test asks for. */
#define MAX_K 128
/* A build of 200k points takes milliseconds; quadratic behaviour would take
 * minutes. The bound only catches that, never a slow machine or ASan. */
#define BUILD_SECONDS_BOUND 20.0

static ps_photon photon_at(ps_vec3 p, ps_vec3 normal, double power)
{
    return ps_photon_pack(p, ps_rgb_make(power, 0.5 * power, 0.25 * power), ps_v3_neg(normal), normal, 0.5);
}

/* n photons uniform in [lo, hi]^3 with normal +y, their powers all different
 * and their flags set to anything. */
static ps_photon *random_photons(size_t n, uint64_t seed, double lo, double hi)
{
    ps_photon *ph = malloc((n ? n : 1) * sizeof *ph);
    assert_non_null(ph);
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(seed, PS_STREAM_TEST, i);
        ps_vec3 p = ps_v3(lo + (hi - lo) * ps_rng_uniform(&r), lo + (hi - lo) * ps_rng_uniform(&r),
                          lo + (hi - lo) * ps_rng_uniform(&r));
        ph[i] = photon_at(p, ps_v3(0, 1, 0), 1.0 + (double)i);
        /* Flags arrive set: the tree must overwrite them with its own. */
        ps_photon_set_flags(&ph[i], (unsigned)(i % 4));
    }
    return ph;
}

static ps_kdtree *build(const ps_photon *ph, size_t n)
{
    ps_kdtree *t = NULL;
    ps_error err;
    if (ps_kdtree_build(ph, n, &t, &err) != PS_OK)
        fail_msg("build of %zu photons: %s", n, err.msg);
    assert_non_null(t);
    assert_int_equal(ps_kdtree_count(t), n);
    return t;
}

/* Squared distance exactly as the tree computes it. */
static double dist2(const ps_photon *ph, ps_vec3 q)
{
    double dx = ph->pos[0] - q.x, dy = ph->pos[1] - q.y, dz = ph->pos[2] - q.z;
    return dx * dx + dy * dy + dz * dz;
}

static bool passes_filter(const ps_photon *ph, const ps_kdtree_query *q)
{
    return !(ps_v3_len2(q->normal) > 0.0) || ps_v3_dot(ps_photon_normal(ph), q->normal) > q->min_cos;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The oracle: the smallest min(k, eligible) squared distances over the input
 * photons (radius and filter applied), ascending, into best; returns how
 * many photons are eligible in all. An insertion into a sorted array of at
 * most k, so 20k-photon sets stay cheap under ASan. */
static size_t brute_knn(const ps_photon *ph, size_t n, const ps_kdtree_query *q, double *best, size_t *nbest)
{
    double max_d2 = q->max_radius * q->max_radius;
    size_t eligible = 0, m = 0;
    for (size_t i = 0; i < n; i++) {
        double d2 = dist2(&ph[i], q->p);
        if (d2 > max_d2 || !passes_filter(&ph[i], q))
            continue;
        eligible++;
        if (m == q->k && d2 >= best[m - 1])
            continue;
        size_t j = m < q->k ? m++ : m - 1;
        while (j > 0 && best[j - 1] > d2) {
            best[j] = best[j - 1];
            j--;
        }
        best[j] = d2;
    }
    *nbest = m;
    return eligible;
}

/* Runs q on t and checks it against the oracle over the input photons:
 * count, valid distinct indices, each distance recomputed, the sorted
 * distances equal, the filter and radius respected, out a max-heap on d2,
 * and *r2. Returns the number found. */
static size_t check_query(const ps_kdtree *t, const ps_photon *input, size_t n, const ps_kdtree_query *q)
{
    assert_true(q->k <= MAX_K);
    double best[MAX_K], got[MAX_K];
    ps_neighbor out[MAX_K];
    size_t nbest;
    size_t eligible = brute_knn(input, n, q, best, &nbest);
    double r2 = -1.0;
    size_t found = ps_kdtree_knn(t, q, out, &r2);
    if (found != nbest)
        fail_msg("n=%zu k=%zu at (%g, %g, %g): found %zu, brute force %zu (of %zu eligible)", n, q->k, q->p.x, q->p.y,
                 q->p.z, found, nbest, eligible);
    const ps_photon *tp = ps_kdtree_photons(t);
    double max_d2 = q->max_radius * q->max_radius, far = 0.0;
    for (size_t i = 0; i < found; i++) {
        uint32_t idx = out[i].index;
        assert_true(idx < ps_kdtree_count(t));
        for (size_t j = 0; j < i; j++)
            if (out[j].index == idx)
                fail_msg("index %u returned twice", idx);
        /* The distance it reports is the photon's. */
        assert_true(out[i].d2 == dist2(&tp[idx], q->p));
        assert_true(out[i].d2 <= max_d2);
        assert_true(passes_filter(&tp[idx], q));
        got[i] = out[i].d2;
        far = fmax(far, out[i].d2);
    }
    /* out is a max-heap on d2: out[0] the farthest, each parent at least as
     * far as its children. */
    for (size_t i = 1; i < found; i++)
        if (out[(i - 1) / 2].d2 < out[i].d2)
            fail_msg("out[%zu].d2 = %.17g beyond its parent's %.17g", i, out[i].d2, out[(i - 1) / 2].d2);
    if (found)
        assert_true(out[0].d2 == far);
    qsort(got, found, sizeof *got, cmp_double);
    for (size_t i = 0; i < found; i++)
        if (got[i] != best[i])
            fail_msg("n=%zu k=%zu at (%g, %g, %g): neighbour %zu at d2 %.17g, brute force %.17g", n, q->k, q->p.x,
                     q->p.y, q->p.z, i, got[i], best[i]);
    /* Full: the farthest found; short: the whole search radius. */
    if (found == q->k)
        assert_true(r2 == far);
    else
        assert_true(r2 == max_d2);
    return found;
}

static ps_kdtree_query make_query(ps_vec3 p, size_t k, double max_radius)
{
    ps_kdtree_query q = {p, k, max_radius, ps_v3(0, 0, 0), 0.0};
    return q;
}

/* ---- k-nearest against brute force ----------------------------------------- */

static void knn_random_sets(void **state)
{
    (void)state;
    static const size_t sizes[] = {1, 2, 3, 4, 5, 6, 7, 8, 15, 16, 17, 100, 1000, 20000};
    static const size_t ks[] = {1, 8, 100};
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        size_t n = sizes[s];
        ps_photon *ph = random_photons(n, 100 + n, 0.0, 1.0);
        ps_kdtree *t = build(ph, n);
        assert_true(ps_kdtree_check(t));
        /* Fewer queries on the big set: each is an O(n) oracle. */
        size_t queries = n >= 20000 ? 40 : 150;
        for (size_t i = 0; i < queries; i++) {
            ps_rng r = ps_rng_make(7 + n, PS_STREAM_TEST, i);
            /* Half inside the unit cube, half in a box three times its size
             * around it (mostly outside). */
            double lo = i % 2 ? -1.0 : 0.0, w = i % 2 ? 3.0 : 1.0;
            ps_vec3 p = ps_v3(lo + w * ps_rng_uniform(&r), lo + w * ps_rng_uniform(&r), lo + w * ps_rng_uniform(&r));
            for (size_t j = 0; j < sizeof ks / sizeof *ks; j++) {
                ps_kdtree_query q = make_query(p, ks[j], INFINITY);
                size_t found = check_query(t, ph, n, &q);
                assert_int_equal(found, ks[j] < n ? ks[j] : n);
                /* A finite radius around a third of the nearest distances. */
                q.max_radius = 0.15;
                check_query(t, ph, n, &q);
            }
        }
        ps_kdtree_destroy(t);
        free(ph);
    }
}

/* Many photons at few positions: every query meets runs of equal distances. */
static void knn_duplicate_positions(void **state)
{
    (void)state;
    const size_t n = 3000, distinct = 40;
    ps_photon *ph = malloc(n * sizeof *ph);
    assert_non_null(ph);
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(3, PS_STREAM_TEST, i % distinct);
        ps_vec3 p = ps_v3(ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r));
        ph[i] = photon_at(p, ps_v3(0, 1, 0), 1.0 + (double)i);
    }
    ps_kdtree *t = build(ph, n);
    assert_true(ps_kdtree_check(t));
    for (size_t i = 0; i < 200; i++) {
        ps_rng r = ps_rng_make(4, PS_STREAM_TEST, i);
        /* Half the queries exactly at a stored position. */
        ps_vec3 p = i % 2 ? ps_photon_position(&ph[i % distinct])
                          : ps_v3(ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r));
        static const size_t ks[] = {1, 8, 75, 100, 128};
        for (size_t j = 0; j < sizeof ks / sizeof *ks; j++) {
            ps_kdtree_query q = make_query(p, ks[j], INFINITY);
            assert_int_equal(check_query(t, ph, n, &q), ks[j]);
        }
    }
    ps_kdtree_destroy(t);
    free(ph);
}

/* Points on integer grids (3D, and a 2D one where whole rows tie), queried at
 * grid points, cell centres and edge midpoints: shells of equal distance. */
static void knn_grid_ties(void **state)
{
    (void)state;
    const int side = 12;
    ps_photon *ph = malloc((size_t)(side * side * side) * sizeof *ph);
    assert_non_null(ph);
    for (int flat = 0; flat < 2; flat++) {
        size_t n = 0;
        for (int x = 0; x < side; x++)
            for (int y = 0; y < side; y++)
                for (int z = 0; z < (flat ? 1 : side); z++, n++)
                    ph[n] = photon_at(ps_v3(x, y, z), ps_v3(0, 1, 0), 1.0 + (double)n);
        ps_kdtree *t = build(ph, n);
        assert_true(ps_kdtree_check(t));
        static const size_t ks[] = {1, 2, 5, 7, 8, 19, 27, 100, 128};
        for (size_t i = 0; i < 150; i++) {
            ps_rng r = ps_rng_make(5, PS_STREAM_TEST, i);
            double offs = i % 3 == 0 ? 0.0 : 0.5; /* grid points, then half-integer points */
            ps_vec3 p = ps_v3((double)ps_rng_below(&r, (uint32_t)side) + offs, (double)ps_rng_below(&r, (uint32_t)side),
                              flat ? 0.0 : (double)ps_rng_below(&r, (uint32_t)side) + (i % 3 == 2 ? offs : 0.0));
            for (size_t j = 0; j < sizeof ks / sizeof *ks; j++) {
                ps_kdtree_query q = make_query(p, ks[j], INFINITY);
                check_query(t, ph, n, &q);
                /* Radii landing exactly on a shell of grid points. */
                q.max_radius = 1.0;
                check_query(t, ph, n, &q);
                q.max_radius = 2.0;
                check_query(t, ph, n, &q);
            }
        }
        ps_kdtree_destroy(t);
    }
    free(ph);
}

/* ---- the search radius ------------------------------------------------------- */

static void max_radius_limits(void **state)
{
    (void)state;
    /* A grid: at (5, 5, 5) the ball of radius 1 holds the point and its six
     * neighbours, exactly on the boundary (d2 <= r^2 counts). */
    const int side = 11;
    ps_photon *g = malloc((size_t)(side * side * side) * sizeof *g);
    assert_non_null(g);
    size_t n = 0;
    for (int x = 0; x < side; x++)
        for (int y = 0; y < side; y++)
            for (int z = 0; z < side; z++)
                g[n++] = photon_at(ps_v3(x, y, z), ps_v3(0, 1, 0), 1.0);
    ps_kdtree *t = build(g, n);
    ps_neighbor out[MAX_K];
    double r2 = 0;
    ps_kdtree_query q = make_query(ps_v3(5, 5, 5), 100, 1.0);
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 7);
    assert_true(r2 == 1.0);
    q.max_radius = 0.999;
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 1);
    assert_true(r2 == 0.999 * 0.999);
    assert_true(out[0].d2 == 0.0);
    /* Radius sqrt(3) (rounded up): 1 + 6 + 12 + 8 points. */
    q.max_radius = nextafter(sqrt(3.0), 2.0);
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 27);
    /* k reached inside the radius: r2 is the farthest returned. */
    q.max_radius = 1.0;
    q.k = 3;
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 3);
    assert_true(r2 == 1.0);
    q.k = 1;
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 1);
    assert_true(r2 == 0.0);
    assert_true(out[0].d2 == 0.0);
    /* Off the grid, nothing within reach; r2 may be NULL. */
    q = make_query(ps_v3(-3, 5, 5), 10, 2.5);
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 0);
    assert_true(r2 == 2.5 * 2.5);
    q.max_radius = 3.0;
    assert_int_equal(ps_kdtree_knn(t, &q, out, NULL), 1);
    ps_kdtree_destroy(t);
    free(g);

    /* Random points: every photon within the radius and no other, against
     * the oracle, radius shorter than the k-th distance or longer. */
    n = 5000;
    ps_photon *ph = random_photons(n, 11, 0.0, 1.0);
    t = build(ph, n);
    size_t short_count = 0, full_count = 0;
    for (size_t i = 0; i < 200; i++) {
        ps_rng r = ps_rng_make(12, PS_STREAM_TEST, i);
        ps_vec3 p = ps_v3(ps_rng_uniform(&r), ps_rng_uniform(&r), ps_rng_uniform(&r));
        /* 100 of 5000 in a unit cube: the 100th is about 0.17 away. */
        q = make_query(p, 100, 0.05 + 0.2 * ps_rng_uniform(&r));
        size_t found = check_query(t, ph, n, &q);
        if (found < q.k)
            short_count++;
        else
            full_count++;
    }
    /* Both cases were exercised. */
    assert_true(short_count > 20);
    assert_true(full_count > 20);
    ps_kdtree_destroy(t);
    free(ph);
}

/* ---- the normal filter ------------------------------------------------------- */

static void normal_filter(void **state)
{
    (void)state;
    /* Photons of a thin slab: both faces of y = 0.5 interleaved (normals +y
     * and -y), plus a third with random normals. */
    const size_t n = 6000;
    ps_photon *ph = malloc(n * sizeof *ph);
    assert_non_null(ph);
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(21, PS_STREAM_TEST, i);
        ps_vec3 p = ps_v3(ps_rng_uniform(&r), 0.5 + 1e-3 * ps_rng_uniform(&r), ps_rng_uniform(&r));
        ps_vec3 nrm;
        if (i % 3 == 0)
            nrm = ps_v3(0, 1, 0);
        else if (i % 3 == 1)
            nrm = ps_v3(0, -1, 0);
        else
            nrm = ps_v3_norm(ps_v3(ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5));
        ph[i] = photon_at(p, nrm, 1.0);
    }
    ps_kdtree *t = build(ph, n);
    static const double cosines[] = {0.0, 0.5, -0.5, 0.9};
    size_t total_found = 0;
    for (size_t i = 0; i < 120; i++) {
        ps_rng r = ps_rng_make(22, PS_STREAM_TEST, i);
        ps_vec3 p = ps_v3(ps_rng_uniform(&r), 0.5, ps_rng_uniform(&r));
        ps_vec3 nq = i % 3 == 0   ? ps_v3(0, 1, 0)
                     : i % 3 == 1 ? ps_v3(0, -1, 0)
                                  : ps_v3_norm(ps_v3(ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5,
                                                     ps_rng_uniform(&r) - 0.5));
        for (size_t c = 0; c < sizeof cosines / sizeof *cosines; c++) {
            static const size_t ks[] = {1, 20, 100};
            for (size_t j = 0; j < sizeof ks / sizeof *ks; j++) {
                ps_kdtree_query q = {p, ks[j], INFINITY, nq, cosines[c]};
                total_found += check_query(t, ph, n, &q);
                q.max_radius = 0.05;
                check_query(t, ph, n, &q);
            }
        }
    }
    assert_true(total_found > 0);
    /* With the +y filter every photon returned faces up, and the nearest
     * facing-down photon is skipped even when it is the closest of all. */
    ps_photon two[2] = {photon_at(ps_v3(0, 0, 0), ps_v3(0, -1, 0), 1.0),
                        photon_at(ps_v3(0.5, 0, 0), ps_v3(0, 1, 0), 2.0)};
    ps_kdtree *t2 = build(two, 2);
    ps_kdtree_query q = {ps_v3(0, 0, 0), 1, INFINITY, ps_v3(0, 1, 0), 0.0};
    ps_neighbor nb;
    assert_int_equal(ps_kdtree_knn(t2, &q, &nb, NULL), 1);
    assert_true(nb.d2 == 0.25);
    q.normal = ps_v3(0, -1, 0);
    assert_int_equal(ps_kdtree_knn(t2, &q, &nb, NULL), 1);
    assert_true(nb.d2 == 0.0);
    /* Facing sideways: neither passes cos > 0. */
    q.normal = ps_v3(1, 0, 0);
    assert_int_equal(ps_kdtree_knn(t2, &q, &nb, NULL), 0);
    ps_kdtree_destroy(t2);
    ps_kdtree_destroy(t);
    free(ph);
}

/* ---- layout -------------------------------------------------------------------- */

static int cmp_photon_bytes(const void *a, const void *b) { return memcmp(a, b, sizeof(ps_photon)); }

/* Every input photon appears in the tree exactly once (flags aside), the
 * input is untouched, and the heap order holds on every node's axis. */
static void check_layout(const ps_photon *input, size_t n)
{
    ps_photon *before = malloc((n ? n : 1) * sizeof *before);
    assert_non_null(before);
    if (n)
        memcpy(before, input, n * sizeof *input);
    ps_kdtree *t = build(input, n);
    assert_memory_equal(before, input, n * sizeof *input);
    assert_true(ps_kdtree_check(t));

    ps_photon *a = malloc((n ? n : 1) * sizeof *a), *b = malloc((n ? n : 1) * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    const ps_photon *tp = ps_kdtree_photons(t);
    ps_aabb box = ps_aabb_empty();
    for (size_t i = 0; i < n; i++) {
        /* Leaves (no child in the heap) keep flags 0; any node's axis is 0-2. */
        assert_true(ps_photon_flags(&tp[i]) <= 2);
        if (2 * (i + 1) > n)
            assert_int_equal(ps_photon_flags(&tp[i]), 0);
        a[i] = input[i];
        b[i] = tp[i];
        ps_photon_set_flags(&a[i], 0);
        ps_photon_set_flags(&b[i], 0);
        box = ps_aabb_point(box, ps_photon_position(&input[i]));
    }
    qsort(a, n, sizeof *a, cmp_photon_bytes);
    qsort(b, n, sizeof *b, cmp_photon_bytes);
    if (n)
        assert_memory_equal(a, b, n * sizeof *a);
    ps_aabb tb = ps_kdtree_bounds(t);
    assert_memory_equal(&tb, &box, sizeof box);
    free(a);
    free(b);
    free(before);
    ps_kdtree_destroy(t);
}

static void heap_layout(void **state)
{
    (void)state;
    /* Every size up to 70 (all shapes of the last level), then larger ones. */
    for (size_t n = 1; n <= 70; n++) {
        ps_photon *ph = random_photons(n, 31 + n, -1.0, 1.0);
        check_layout(ph, n);
        free(ph);
    }
    static const size_t big[] = {255, 256, 257, 1000, 4095, 4097, 30000};
    for (size_t s = 0; s < sizeof big / sizeof *big; s++) {
        ps_photon *ph = random_photons(big[s], 32, -1.0, 1.0);
        check_layout(ph, big[s]);
        free(ph);
    }
}

/* The root splits the widest axis at the median; and check() is not
 * vacuous: a node moved past its ancestor's plane fails it. */
static void split_axis_and_check(void **state)
{
    (void)state;
    const size_t n = 1001;
    ps_photon *ph = random_photons(n, 41, 0.0, 1.0);
    /* Stretch: y spans 4, z 2, x 1. */
    for (size_t i = 0; i < n; i++) {
        ph[i].pos[1] *= 4.0f;
        ph[i].pos[2] *= 2.0f;
    }
    ps_kdtree *t = build(ph, n);
    const ps_photon *tp = ps_kdtree_photons(t);
    assert_int_equal(ps_photon_flags(&tp[0]), 1);
    /* Left-balanced with 1001 nodes: nine full levels hold 511, the tenth
     * 490 of 512, all 256 of the left half full; so the left subtree holds
     * 255 + 256 = 511, the right 489, and the root is the 512th smallest y. */
    size_t below = 0;
    for (size_t i = 0; i < n; i++)
        below += ph[i].pos[1] < tp[0].pos[1];
    assert_int_equal(below, 511);
    assert_true(ps_kdtree_check(t));
    /* Corrupt a copy of the heap in place (the tree owns writable memory). */
    ps_photon *w = (ps_photon *)tp;
    float saved = w[0].pos[1];
    w[0].pos[1] = 1e9f; /* the right subtree is now below its split */
    assert_false(ps_kdtree_check(t));
    w[0].pos[1] = saved;
    assert_true(ps_kdtree_check(t));
    /* A deep left node beyond the root's plane. */
    size_t deep = 1;
    while (2 * deep <= n)
        deep *= 2; /* the leftmost node of the last level, 1-based */
    saved = w[deep - 1].pos[1];
    w[deep - 1].pos[1] = 100.0f;
    assert_false(ps_kdtree_check(t));
    w[deep - 1].pos[1] = saved;
    assert_true(ps_kdtree_check(t));
    ps_kdtree_destroy(t);
    free(ph);
}

/* ---- degenerate input ------------------------------------------------------------ */

static void empty_and_degenerate(void **state)
{
    (void)state;
    ps_neighbor out[MAX_K];
    double r2 = 0;
    /* Empty. */
    ps_kdtree *t = build(NULL, 0);
    assert_true(ps_kdtree_check(t));
    assert_true(ps_aabb_is_empty(ps_kdtree_bounds(t)));
    ps_kdtree_query q = make_query(ps_v3(0, 0, 0), 10, 2.0);
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 0);
    assert_true(r2 == 4.0);
    q.max_radius = INFINITY;
    assert_int_equal(ps_kdtree_knn(t, &q, out, NULL), 0);
    ps_kdtree_destroy(t);
    ps_kdtree_destroy(NULL);

    /* One photon. */
    ps_photon one = photon_at(ps_v3(1, 2, 3), ps_v3(0, 1, 0), 1.0);
    t = build(&one, 1);
    q = make_query(ps_v3(1, 2, 4), 5, INFINITY);
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 1);
    assert_true(out[0].d2 == 1.0);
    assert_int_equal(out[0].index, 0);
    assert_true(isinf(r2)); /* fewer than k: the whole (infinite) radius */
    q.max_radius = 0.5;
    assert_int_equal(ps_kdtree_knn(t, &q, out, &r2), 0);
    ps_kdtree_destroy(t);

    /* All photons at one point. */
    const size_t n = 1000;
    ps_photon *ph = malloc(n * sizeof *ph);
    assert_non_null(ph);
    for (size_t i = 0; i < n; i++)
        ph[i] = photon_at(ps_v3(0.25, -0.5, 2.0), i % 2 ? ps_v3(0, 1, 0) : ps_v3(0, -1, 0), 1.0 + (double)i);
    check_layout(ph, n);
    t = build(ph, n);
    q = make_query(ps_v3(0.25, -0.5, 2.0), 100, INFINITY);
    assert_int_equal(check_query(t, ph, n, &q), 100);
    q.p = ps_v3(1, 1, 1);
    check_query(t, ph, n, &q);
    q.normal = ps_v3(0, 1, 0);
    assert_int_equal(check_query(t, ph, n, &q), 100);
    q.k = 1;
    q.max_radius = 0.1; /* the point is farther than that */
    assert_int_equal(check_query(t, ph, n, &q), 0);
    ps_kdtree_destroy(t);
    free(ph);

    /* Too many photons: refused before the array is read, *out set to NULL. */
    ps_error err;
    ps_kdtree *keep = build(&one, 1), *big = keep;
    assert_int_equal(ps_kdtree_build(&one, (size_t)UINT32_MAX, &big, &err), PS_ERR_LIMIT);
    assert_int_equal(err.status, PS_ERR_LIMIT);
    assert_null(big);
    ps_kdtree_destroy(keep);
}

/* ---- adversarial orders ------------------------------------------------------------ */

static void build_order(const ps_photon *ph, size_t n, const char *what)
{
    double t0 = ps_now_seconds();
    ps_kdtree *t = build(ph, n);
    double dt = ps_now_seconds() - t0;
    if (dt > BUILD_SECONDS_BOUND)
        fail_msg("%s: building %zu photons took %.2f s", what, n, dt);
    assert_true(ps_kdtree_check(t));
    for (size_t i = 0; i < 6; i++) {
        ps_vec3 p = ps_photon_position(&ph[(i * 7919 * 13) % n]);
        p.y += 0.001 * (double)i;
        ps_kdtree_query q = make_query(p, i % 2 ? 8 : 100, INFINITY);
        check_query(t, ph, n, &q);
    }
    ps_kdtree_destroy(t);
}

static void sorted_and_reversed_input(void **state)
{
    (void)state;
    const size_t n = 200000;
    ps_photon *ph = malloc(n * sizeof *ph);
    assert_non_null(ph);
    /* Sorted along x (x dominates the extent), small random y and z. */
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(51, PS_STREAM_TEST, i);
        ph[i] = photon_at(ps_v3((double)i / (double)n * 10.0, 0.1 * ps_rng_uniform(&r), 0.1 * ps_rng_uniform(&r)),
                          ps_v3(0, 1, 0), 1.0);
    }
    build_order(ph, n, "sorted along x");
    for (size_t i = 0; i < n / 2; i++) {
        ps_photon tmp = ph[i];
        ph[i] = ph[n - 1 - i];
        ph[n - 1 - i] = tmp;
    }
    build_order(ph, n, "reversed");
    /* Sorted on all three axes at once: a diagonal line. */
    for (size_t i = 0; i < n; i++) {
        double s = (double)i / (double)n;
        ph[i] = photon_at(ps_v3(s, 2.0 * s, 3.0 * s), ps_v3(0, 1, 0), 1.0);
    }
    build_order(ph, n, "diagonal line");
    /* Organ pipe: ascending then descending x; and only three distinct x. */
    for (size_t i = 0; i < n; i++) {
        size_t k = i < n / 2 ? i : n - 1 - i;
        ps_rng r = ps_rng_make(52, PS_STREAM_TEST, i);
        ph[i] = photon_at(ps_v3((double)k / (double)n * 10.0, 0.1 * ps_rng_uniform(&r), 0.1 * ps_rng_uniform(&r)),
                          ps_v3(0, 1, 0), 1.0);
    }
    build_order(ph, n, "organ pipe");
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(53, PS_STREAM_TEST, i);
        ph[i] = photon_at(ps_v3(10.0 * (double)(i % 3), 0.1 * ps_rng_uniform(&r), 0.1 * ps_rng_uniform(&r)),
                          ps_v3(0, 1, 0), 1.0);
    }
    build_order(ph, n, "three x values");
    free(ph);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(knn_random_sets),      cmocka_unit_test(knn_duplicate_positions),
        cmocka_unit_test(knn_grid_ties),        cmocka_unit_test(max_radius_limits),
        cmocka_unit_test(normal_filter),        cmocka_unit_test(heap_layout),
        cmocka_unit_test(split_axis_and_check), cmocka_unit_test(empty_and_degenerate),
        cmocka_unit_test(sorted_and_reversed_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
