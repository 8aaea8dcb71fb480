/* bench_kdtree.c: the photon map's speed: k-nearest queries per second
 * (k = 50 and 200) on 10^5 and 10^6 photons against a brute-force linear
 * scan measured in the same run, and balancing time against qsort of the
 * same array.
 *
 * The photons lie on the surfaces of a Cornell-like scene (five walls of
 * [-1, 1]^3 and a sphere), where real photons are; queries are other random
 * points of those surfaces, with no search radius and no normal filter (the
 * plain k-nearest problem both sides solve). The brute force runs on fewer
 * queries (it is O(n) each) and is scaled to a rate; each of its queries is
 * also checked against the tree (same k-th distance). Each timing runs for at
 * least MIN_SECONDS. Compare ratios, not absolute numbers: these machines
 * are noisy. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "photon/kdtree.h"
#include "photon/photon.h"

#define SEED 20240611u
#define MIN_SECONDS 0.4
#define TREE_CHUNK 1000 /* queries per timing step */
#define BRUTE_CHUNK 4
#define QUERY_POOL 200000 /* distinct query points, reused cyclically */
#define MAX_K 200
#define SPHERE_R 0.4

/* A random point of the scene's surfaces (area-weighted) and its normal:
 * floor, ceiling, back and side walls of [-1, 1]^3 (area 4 each), and a
 * sphere of radius SPHERE_R at the origin. */
static ps_vec3 surface_point(ps_rng *r, ps_vec3 *normal)
{
    double sphere_area = 4.0 * PS_PI * SPHERE_R * SPHERE_R, total = 5 * 4.0 + sphere_area;
    double pick = ps_rng_uniform(r) * total, u = 2 * ps_rng_uniform(r) - 1, v = 2 * ps_rng_uniform(r) - 1;
    if (pick >= 20.0) {
        double z = u, phi = PS_PI * (v + 1), s = sqrt(fmax(0.0, 1 - z * z));
        *normal = ps_v3(s * cos(phi), s * sin(phi), z);
        return ps_v3_scale(*normal, SPHERE_R);
    }
    switch ((int)(pick / 4.0)) {
    case 0: *normal = ps_v3(0, 1, 0); return ps_v3(u, -1, v);
    case 1: *normal = ps_v3(0, -1, 0); return ps_v3(u, 1, v);
    case 2: *normal = ps_v3(0, 0, 1); return ps_v3(u, v, -1);
    case 3: *normal = ps_v3(1, 0, 0); return ps_v3(-1, u, v);
    default: *normal = ps_v3(-1, 0, 0); return ps_v3(1, u, v);
    }
}

static ps_photon *make_photons(size_t n)
{
    ps_photon *ph = malloc(n * sizeof *ph);
    if (!ph)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(SEED, PS_STREAM_TEST, i);
        ps_vec3 nrm, p = surface_point(&r, &nrm);
        ph[i] = ps_photon_pack(p, ps_rgb_gray(1e-5), ps_v3_neg(nrm), nrm, ps_rng_uniform(&r));
    }
    return ph;
}

static ps_vec3 *make_queries(size_t n)
{
    ps_vec3 *q = malloc(n * sizeof *q);
    if (!q)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(SEED + 1, PS_STREAM_TEST, i);
        ps_vec3 nrm;
        q[i] = surface_point(&r, &nrm);
    }
    return q;
}

/* ---- the brute-force baseline: one pass, a bounded max-heap ------------------ */

static void sift_down(double *h, size_t n)
{
    size_t i = 0;
    double v = h[0];
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && h[c + 1] > h[c])
            c++;
        if (h[c] <= v)
            break;
        h[i] = h[c];
        i = c;
    }
    h[i] = v;
}

/* The k-th smallest squared distance from p (k <= n), as the tree computes it. */
static double brute_kth(const ps_photon *ph, size_t n, ps_vec3 p, size_t k, double *heap)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        double dx = ph[i].pos[0] - p.x, dy = ph[i].pos[1] - p.y, dz = ph[i].pos[2] - p.z;
        double d2 = dx * dx + dy * dy + dz * dz;
        if (m < k) {
            size_t j = m++;
            while (j > 0 && heap[(j - 1) / 2] < d2) {
                heap[j] = heap[(j - 1) / 2];
                j = (j - 1) / 2;
            }
            heap[j] = d2;
        } else if (d2 < heap[0]) {
            heap[0] = d2;
            sift_down(heap, m);
        }
    }
    return heap[0];
}

/* ---- timings ------------------------------------------------------------------ */

static int cmp_x(const void *a, const void *b)
{
    float x = ((const ps_photon *)a)->pos[0], y = ((const ps_photon *)b)->pos[0];
    return x < y ? -1 : x > y;
}

typedef struct knn_row {
    size_t n, k;
    double tree_qps, brute_qps;
    size_t tree_queries, brute_queries, agree;
    double found_mean;
} knn_row;

static void time_knn(const ps_kdtree *t, const ps_photon *ph, size_t n, const ps_vec3 *queries, size_t k, knn_row *row)
{
    ps_neighbor out[MAX_K];
    double heap[MAX_K];
    row->n = n;
    row->k = k;
    /* The tree. */
    size_t q = 0, found = 0;
    double t0 = bench_now(), dt;
    do {
        for (size_t i = 0; i < TREE_CHUNK; i++, q++) {
            ps_kdtree_query kq = {queries[q % QUERY_POOL], k, INFINITY, ps_v3(0, 0, 0), 0.0};
            found += ps_kdtree_knn(t, &kq, out, NULL);
        }
        dt = bench_now() - t0;
    } while (dt < MIN_SECONDS);
    row->tree_queries = q;
    row->tree_qps = (double)q / dt;
    row->found_mean = (double)found / (double)q;
    /* Brute force on the first queries, each checked against the tree. */
    size_t b = 0, agree = 0;
    double sink = 0.0;
    t0 = bench_now();
    do {
        for (size_t i = 0; i < BRUTE_CHUNK; i++, b++) {
            sink += brute_kth(ph, n, queries[b], k, heap);
        }
        dt = bench_now() - t0;
    } while (dt < MIN_SECONDS);
    row->brute_queries = b;
    row->brute_qps = (double)b / dt;
    for (size_t i = 0; i < b; i++) {
        ps_kdtree_query kq = {queries[i], k, INFINITY, ps_v3(0, 0, 0), 0.0};
        double r2;
        ps_kdtree_knn(t, &kq, out, &r2);
        agree += r2 == brute_kth(ph, n, queries[i], k, heap);
    }
    row->agree = agree;
    if (sink < 0.0) /* keeps the brute-force loop from being optimised away */
        printf("?");
}

int main(void)
{
    static const size_t sizes[] = {100000, 1000000};
    static const size_t ks[] = {50, 200};
    ps_vec3 *queries = make_queries(QUERY_POOL);
    if (!queries) {
        fprintf(stderr, "bench_kdtree: out of memory\n");
        return 1;
    }
    knn_row rows[4];
    size_t nrows = 0;
    double build_s[2], qsort_s[2];
    for (size_t s = 0; s < 2; s++) {
        size_t n = sizes[s];
        ps_photon *ph = make_photons(n), *copy = malloc(n * sizeof *copy);
        if (!ph || !copy) {
            fprintf(stderr, "bench_kdtree: out of memory for %zu photons\n", n);
            return 1;
        }
        /* Build, best of three, against qsort (on x) of the same array. */
        ps_kdtree *t = NULL;
        build_s[s] = qsort_s[s] = INFINITY;
        for (int rep = 0; rep < 3; rep++) {
            ps_kdtree_destroy(t);
            ps_error err;
            double t0 = bench_now();
            if (ps_kdtree_build(ph, n, &t, &err) != PS_OK) {
                fprintf(stderr, "bench_kdtree: %s\n", err.msg);
                return 1;
            }
            build_s[s] = fmin(build_s[s], bench_now() - t0);
            memcpy(copy, ph, n * sizeof *ph);
            t0 = bench_now();
            qsort(copy, n, sizeof *copy, cmp_x);
            qsort_s[s] = fmin(qsort_s[s], bench_now() - t0);
        }
        if (!ps_kdtree_check(t)) {
            fprintf(stderr, "bench_kdtree: the tree of %zu photons fails its check\n", n);
            return 1;
        }
        for (size_t j = 0; j < 2; j++)
            time_knn(t, ph, n, queries, ks[j], &rows[nrows++]);
        ps_kdtree_destroy(t);
        free(copy);
        free(ph);
    }
    free(queries);

    printf("kd-tree photon map: k-nearest (no radius, no normal filter) vs a brute-force scan in the same run\n");
    printf("%-10s %5s %14s %14s %10s %12s %14s\n", "photons", "k", "tree q/s", "brute q/s", "speed-up", "found/query",
           "brute agrees");
    for (size_t i = 0; i < nrows; i++) {
        knn_row *r = &rows[i];
        char agree[32];
        snprintf(agree, sizeof agree, "%zu/%zu", r->agree, r->brute_queries);
        printf("%-10zu %5zu %14.0f %14.1f %9.0fx %12.1f %14s\n", r->n, r->k, r->tree_qps, r->brute_qps,
               r->tree_qps / r->brute_qps, r->found_mean, agree);
    }
    printf("\nbalancing (best of 3) vs qsort of the same array on x\n");
    printf("%-10s %12s %12s %12s\n", "photons", "build ms", "qsort ms", "build/qsort");
    for (size_t s = 0; s < 2; s++)
        printf("%-10zu %12.1f %12.1f %12.2f\n", sizes[s], 1e3 * build_s[s], 1e3 * qsort_s[s], build_s[s] / qsort_s[s]);
    printf("csv,photons,k,tree_qps,brute_qps,speedup\n");
    for (size_t i = 0; i < nrows; i++)
        printf("csv,%zu,%zu,%.0f,%.1f,%.1f\n", rows[i].n, rows[i].k, rows[i].tree_qps, rows[i].brute_qps,
               rows[i].tree_qps / rows[i].brute_qps);
    printf("csv,photons,build_ms,qsort_ms\n");
    for (size_t s = 0; s < 2; s++)
        printf("csv,%zu,%.2f,%.2f\n", sizes[s], 1e3 * build_s[s], 1e3 * qsort_s[s]);
    for (size_t i = 0; i < nrows; i++)
        if (rows[i].agree != rows[i].brute_queries) {
            fprintf(stderr, "bench_kdtree: the tree and brute force disagree\n");
            return 1;
        }
    return 0;
}
