/* bench_util.h: what the bench programs share: a monotonic clock and
 * deterministic test geometry generated in memory. Header-only (static
 * functions), as each bench is a single file linked against the library. */
#ifndef PS_BENCH_BENCH_UTIL_H
#define PS_BENCH_BENCH_UTIL_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>

#include "core/rng.h"
#include "core/vec.h"

static inline double bench_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* An indexed triangle mesh owned by the bench (free with bench_mesh_free). */
typedef struct bench_mesh {
    ps_vec3 *positions;
    size_t position_count;
    uint32_t *indices;
    size_t triangle_count;
} bench_mesh;

static inline void bench_mesh_free(bench_mesh *m)
{
    free(m->positions);
    free(m->indices);
    m->positions = NULL;
    m->indices = NULL;
}

/* Bumpy sphere radius: a smooth displacement plus per-vertex noise that is a
 * pure function of the vertex's grid position, so every run builds the same mesh. */
#define BENCH_BLOB_RADIUS 0.6
#define BENCH_BLOB_WAVE 0.08
#define BENCH_BLOB_NOISE 0.02

/* A closed box [-1, 1]^3 (12 triangles, inward or not: tests are two-sided)
 * around a closed bumpy latitude-longitude sphere at the origin, about
 * `triangles` triangles in all. Returns 0, or -1 when out of memory. */
static inline int bench_blob_in_box(size_t triangles, bench_mesh *m)
{
    int lat = (int)ceil(sqrt((double)triangles / 4.0));
    if (lat < 3)
        lat = 3;
    int lon = 2 * lat;
    size_t nv = (size_t)(lat - 1) * (size_t)lon + 2 + 8;
    size_t nt = 2 * (size_t)lon * (size_t)(lat - 1) + 12;
    m->positions = malloc(sizeof *m->positions * nv);
    m->indices = malloc(sizeof *m->indices * 3 * nt);
    if (!m->positions || !m->indices) {
        bench_mesh_free(m);
        return -1;
    }
    size_t v = 0, t = 0;
    /* Step 1: the blob's vertices: north pole, rings, south pole. */
    m->positions[v++] = ps_v3(0, BENCH_BLOB_RADIUS, 0);
    for (int i = 1; i < lat; i++)
        for (int j = 0; j < lon; j++) {
            double th = PS_PI * i / lat, ph = 2 * PS_PI * j / lon;
            double noise = (double)(ps_hash64((uint64_t)i * 1000003u + (uint64_t)j) >> 11) * 0x1p-53 - 0.5;
            double r = BENCH_BLOB_RADIUS * (1.0 + BENCH_BLOB_WAVE * sin(7 * th) * cos(5 * ph) + BENCH_BLOB_NOISE * noise);
            m->positions[v++] = ps_v3(r * sin(th) * cos(ph), r * cos(th), r * sin(th) * sin(ph));
        }
    m->positions[v++] = ps_v3(0, -BENCH_BLOB_RADIUS, 0);
    uint32_t south = (uint32_t)(v - 1);
#define BENCH_TRI(a, b, c)                                                                                       \
    do {                                                                                                         \
        m->indices[3 * t] = (uint32_t)(a);                                                                       \
        m->indices[3 * t + 1] = (uint32_t)(b);                                                                   \
        m->indices[3 * t + 2] = (uint32_t)(c);                                                                   \
        t++;                                                                                                     \
    } while (0)
    /* Step 2: its faces: fans at the poles, quads between rings. */
    for (int j = 0; j < lon; j++)
        BENCH_TRI(0, 1 + (j + 1) % lon, 1 + j);
    for (int i = 0; i + 2 < lat; i++)
        for (int j = 0; j < lon; j++) {
            uint32_t a = (uint32_t)(1 + i * lon + j), b = (uint32_t)(1 + i * lon + (j + 1) % lon);
            uint32_t c = a + (uint32_t)lon, d = b + (uint32_t)lon;
            BENCH_TRI(a, b, d);
            BENCH_TRI(a, d, c);
        }
    for (int j = 0; j < lon; j++)
        BENCH_TRI(south, 1 + (lat - 2) * lon + j, 1 + (lat - 2) * lon + (j + 1) % lon);
    /* Step 3: the box: 8 corners (bit 0: x, 1: y, 2: z), two triangles per face. */
    uint32_t base = (uint32_t)v;
    for (int k = 0; k < 8; k++)
        m->positions[v++] = ps_v3((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1);
    static const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (int f = 0; f < 6; f++) {
        BENCH_TRI(base + (uint32_t)faces[f][0], base + (uint32_t)faces[f][1], base + (uint32_t)faces[f][2]);
        BENCH_TRI(base + (uint32_t)faces[f][0], base + (uint32_t)faces[f][2], base + (uint32_t)faces[f][3]);
    }
#undef BENCH_TRI
    m->position_count = v;
    m->triangle_count = t;
    return 0;
}

/* n rays with origins uniform in [-lo_hi, lo_hi]^3 and uniformly distributed
 * unit directions, a pure function of seed. */
static inline ps_ray *bench_rays(size_t n, double lo_hi, uint64_t seed)
{
    ps_ray *rays = malloc(sizeof *rays * (n ? n : 1));
    if (!rays)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        ps_rng r = ps_rng_make(seed, PS_STREAM_TEST, i);
        ps_vec3 o = ps_v3(lo_hi * (2 * ps_rng_uniform(&r) - 1), lo_hi * (2 * ps_rng_uniform(&r) - 1),
                          lo_hi * (2 * ps_rng_uniform(&r) - 1));
        double z = 2 * ps_rng_uniform(&r) - 1, phi = 2 * PS_PI * ps_rng_uniform(&r), s = sqrt(fmax(0.0, 1 - z * z));
        rays[i] = ps_ray_make(o, ps_v3(s * cos(phi), s * sin(phi), z));
    }
    return rays;
}

#endif
