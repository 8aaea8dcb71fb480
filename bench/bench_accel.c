/* bench_accel.c: the ray accelerator's speed: octree build time against
 * Embree 3's, and rays per second against brute force and against Embree 3's
 * rtcIntersect1 (when installed), on one thread and on two, on the default
 * scene and on closed meshes of 1k to 1M triangles, all with the same random
 * rays. The octree is timed as the library runs it (the AVX2 traversal where
 * the processor has it) and with the scalar traversal (no_simd).
 *
 * Every ray is also checked: octree against brute force (must agree exactly),
 * the AVX2 traversal against the scalar one (the same primitive), and octree
 * against Embree (hit/miss and primitive; Embree works in single precision,
 * so a few rays grazing an edge may pick the neighbour). It also times the
 * nearest-geometry query (ps_accel_nearest) against its brute-force oracle,
 * checking that both answer alike. Compare ratios, not
 * absolute numbers: these machines are shared and noisy, which is why the
 * octree and Embree run in alternating chunks of the same rays. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "accel/accel.h"
#include "bench_util.h"
#include "scene/scene.h"

#ifdef PS_HAVE_EMBREE
#include <embree3/rtcore.h>
#define HAVE_EMBREE 1
#else
#define HAVE_EMBREE 0
#endif

/* The one-thread rates are per second of this thread's processor time: on a
 * shared machine the wall clock also counts the time other programs held the
 * core, which says nothing about either tracer. The two-thread rates are
 * wall-clock: there the question is what two threads deliver. */
/* Rays per scene for the octree and Embree; brute force gets about this many
 * primitive tests in all, and at least BRUTE_MIN_RAYS rays. */
#define RAYS 1000000
#define CHUNK 50000 /* rays per turn when octree and Embree alternate */
#define THREADS 2   /* the second measurement: this many threads share each chunk */
#define CHUNK_TRIES 3 /* ... each chunk this many times, the quickest counting */
#define BRUTE_TESTS 20000000.0
#define BRUTE_MIN_RAYS 1000
/* Builds are timed as the best of this many (wall clock, both): a build that
 * lost the processor to another program for a while says nothing. */
#define BUILDS 3
/* ps_accel_nearest queries from the first ray origins, and how many of them the oracle checks. */
#define NEAREST_QUERIES 20000
#define NEAREST_BRUTE 200
/* Brute force is timed only up to this many primitives (it is O(n) per ray). */
#define BRUTE_MAX_PRIMS 10000
/* Ray origins: inside and around the closed box [-1, 1]^3, so some rays start
 * outside it and can miss. */
#define ORIGIN_BOX 1.2
#define RAY_SEED 20240601u

typedef struct row {
    char name[32];
    size_t triangles, spheres;
    double build_s, refs_per_prim, mbytes;
    size_t nodes;
    double octree_rps, scalar_rps, brute_rps; /* rays per second, one thread; 0: not measured */
    double embree_build_s, embree_rps;
    double octree_rps2, embree_rps2;          /* rays per second, THREADS threads */
    double agree_scalar;                      /* AVX2 against scalar traversal, fraction of rays */
    double nearest_us, nearest_brute_us;      /* ps_accel_nearest: microseconds a query, octree and oracle */
    double agree_nearest;                     /* octree against oracle, fraction of the oracle's points */
    double agree_hit, agree_prim;   /* octree vs Embree, fractions of rays */
    double agree_brute;             /* octree vs brute force, fraction of the brute rays */
} row;

/* The scene the rays are traced against, in both representations. */
typedef struct bench_scene {
    const ps_vec3 *positions;
    size_t position_count;
    const uint32_t *indices;
    size_t triangle_count;
    const ps_vec3 *centers;
    const double *radii;
    size_t sphere_count;
} bench_scene;

#ifdef PS_HAVE_EMBREE
/* Builds an Embree scene: geometry 0 the triangles, geometry 1 the spheres
 * (sphere points), with the quality the issue names. */
static RTCScene embree_build(RTCDevice dev, const bench_scene *s, double *seconds)
{
    double t0 = bench_now();
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                       s->position_count);
    for (size_t i = 0; i < s->position_count; i++) {
        v[3 * i] = (float)s->positions[i].x;
        v[3 * i + 1] = (float)s->positions[i].y;
        v[3 * i + 2] = (float)s->positions[i].z;
    }
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                           s->triangle_count);
    memcpy(ix, s->indices, sizeof *ix * 3 * s->triangle_count);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene, g, 0);
    rtcReleaseGeometry(g);
    if (s->sphere_count) {
        RTCGeometry sg = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        float *p = rtcSetNewGeometryBuffer(sg, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                           s->sphere_count);
        for (size_t i = 0; i < s->sphere_count; i++) {
            p[4 * i] = (float)s->centers[i].x;
            p[4 * i + 1] = (float)s->centers[i].y;
            p[4 * i + 2] = (float)s->centers[i].z;
            p[4 * i + 3] = (float)s->radii[i];
        }
        rtcCommitGeometry(sg);
        rtcAttachGeometryByID(scene, sg, 1);
        rtcReleaseGeometry(sg);
    }
    rtcCommitScene(scene);
    *seconds = bench_now() - t0;
    return scene;
}

/* Traces rays [begin, end) with rtcIntersect1 on this thread; fills prim
 * (UINT32_MAX: miss) in the accelerator's numbering; returns the seconds taken. */
static double embree_trace(RTCScene scene, const ps_ray *rays, size_t begin, size_t end, size_t triangles,
                           uint32_t *prim)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    double t0 = ps_thread_cpu_seconds();
    for (size_t i = begin; i < end; i++) {
        struct RTCRayHit rh;
        rh.ray.org_x = (float)rays[i].o.x;
        rh.ray.org_y = (float)rays[i].o.y;
        rh.ray.org_z = (float)rays[i].o.z;
        rh.ray.dir_x = (float)rays[i].d.x;
        rh.ray.dir_y = (float)rays[i].d.y;
        rh.ray.dir_z = (float)rays[i].d.z;
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = INFINITY;
        rh.ray.time = 0.0f;
        rh.ray.mask = UINT32_MAX;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
            prim[i] = UINT32_MAX;
        else
            prim[i] = rh.hit.geomID == 0 ? rh.hit.primID : (uint32_t)triangles + rh.hit.primID;
    }
    return ps_thread_cpu_seconds() - t0;
}
#endif

/* One tracer of a range of rays, for the threads. */
typedef struct trace_range {
    const ps_accel *a; /* the octree, or NULL for Embree */
#ifdef PS_HAVE_EMBREE
    RTCScene scene;
#endif
    const ps_ray *rays;
    size_t begin, end, triangles;
    uint32_t *prim;
} trace_range;

static void octree_trace_range(const ps_accel *a, const ps_ray *rays, size_t begin, size_t end, uint32_t *prim)
{
    for (size_t i = begin; i < end; i++) {
        ps_hit h;
        prim[i] = ps_accel_intersect(a, rays[i], 0.0, INFINITY, &h) ? h.prim : UINT32_MAX;
    }
}

static void *trace_range_main(void *arg)
{
    trace_range *t = arg;
    if (t->a)
        octree_trace_range(t->a, t->rays, t->begin, t->end, t->prim);
#ifdef PS_HAVE_EMBREE
    else
        (void)embree_trace(t->scene, t->rays, t->begin, t->end, t->triangles, t->prim);
#endif
    return NULL;
}

/* Rays [begin, end) split between THREADS threads (this one among them);
 * returns the wall-clock seconds, or -1 when a thread could not start. */
static double trace_threads(trace_range proto, size_t begin, size_t end)
{
    trace_range part[THREADS];
    pthread_t tid[THREADS];
    size_t n = end - begin;
    for (int k = 0; k < THREADS; k++) {
        part[k] = proto;
        part[k].begin = begin + n * (size_t)k / THREADS;
        part[k].end = begin + n * (size_t)(k + 1) / THREADS;
    }
    double t0 = bench_now();
    int started = 1;
    for (; started < THREADS; started++)
        if (pthread_create(&tid[started], NULL, trace_range_main, &part[started]) != 0)
            break;
    trace_range_main(&part[0]);
    for (int k = 1; k < started; k++)
        pthread_join(tid[k], NULL);
    double s = bench_now() - t0;
    return started == THREADS ? s : -1.0;
}

/* Measures one scene into r. Returns 0, or -1 on failure (message printed). */
static int measure(const char *name, const bench_scene *s, const ps_ray *rays, row *r)
{
    memset(r, 0, sizeof *r);
    snprintf(r->name, sizeof r->name, "%s", name);
    r->triangles = s->triangle_count;
    r->spheres = s->sphere_count;

    /* Step 1: build the octree (forced: AUTO would pick brute force for the default scene). */
    ps_accel_input in = {s->positions, s->position_count, s->indices, s->triangle_count,
                         s->centers,   s->radii,          s->sphere_count};
    ps_accel_options opt = {PS_ACCEL_OCTREE, 0, 0, false};
    ps_accel *a = NULL;
    ps_error err;
    if (ps_accel_build(&in, &opt, &a, &err) != PS_OK) {
        fprintf(stderr, "bench_accel: %s: %s\n", name, err.msg);
        return -1;
    }
    ps_accel_stats st;
    ps_accel_get_stats(a, &st);
    r->build_s = st.build_seconds;
    for (int k = 1; k < BUILDS; k++) {
        ps_accel *again = NULL;
        if (ps_accel_build(&in, &opt, &again, &err) != PS_OK) {
            fprintf(stderr, "bench_accel: %s: %s\n", name, err.msg);
            ps_accel_destroy(a);
            return -1;
        }
        ps_accel_get_stats(again, &st);
        r->build_s = st.build_seconds < r->build_s ? st.build_seconds : r->build_s;
        ps_accel_destroy(again);
    }
    r->nodes = st.nodes;
    r->refs_per_prim = (double)st.prim_refs / (double)(s->triangle_count + s->sphere_count);
    r->mbytes = (double)st.bytes / (1024.0 * 1024.0);
    /* The same tree traversed by the scalar code (a second build: the choice is made at build). */
    ps_accel_options sopt = opt;
    sopt.no_simd = true;
    ps_accel *sa = NULL;
    if (ps_accel_build(&in, &sopt, &sa, &err) != PS_OK) {
        fprintf(stderr, "bench_accel: %s: %s\n", name, err.msg);
        ps_accel_destroy(a);
        return -1;
    }

    /* Step 2: octree and Embree, single thread, every ray, in alternating
     * chunks so that both see the same machine (these machines are shared). */
    uint32_t *prim = malloc(sizeof *prim * RAYS), *sprim = malloc(sizeof *sprim * RAYS);
#ifdef PS_HAVE_EMBREE
    uint32_t *eprim = malloc(sizeof *eprim * RAYS);
    RTCDevice dev = rtcNewDevice(NULL);
    RTCScene scene = embree_build(dev, s, &r->embree_build_s);
    for (int k = 1; k < BUILDS; k++) {
        double sec;
        rtcReleaseScene(scene);
        scene = embree_build(dev, s, &sec);
        r->embree_build_s = sec < r->embree_build_s ? sec : r->embree_build_s;
    }
#else
    uint32_t *eprim = NULL;
#endif
    if (!prim || !sprim || (HAVE_EMBREE && !eprim)) {
        fprintf(stderr, "bench_accel: out of memory\n");
#ifdef PS_HAVE_EMBREE
        rtcReleaseScene(scene);
        rtcReleaseDevice(dev);
#endif
        free(prim);
        free(sprim);
        free(eprim);
        ps_accel_destroy(a);
        ps_accel_destroy(sa);
        return -1;
    }
    /* One thread: octree, scalar octree and Embree take turns on each chunk. */
    double octree_s = 0.0, scalar_s = 0.0, embree_s = 0.0;
    for (size_t begin = 0; begin < RAYS; begin += CHUNK) {
        size_t end = begin + CHUNK < RAYS ? begin + CHUNK : RAYS;
        double t0 = ps_thread_cpu_seconds();
        octree_trace_range(a, rays, begin, end, prim);
        double t1 = ps_thread_cpu_seconds();
        octree_trace_range(sa, rays, begin, end, sprim);
        octree_s += t1 - t0;
        scalar_s += ps_thread_cpu_seconds() - t1;
#ifdef PS_HAVE_EMBREE
        embree_s += embree_trace(scene, rays, begin, end, s->triangle_count, eprim);
#endif
    }
    r->octree_rps = RAYS / octree_s;
    r->scalar_rps = RAYS / scalar_s;
    size_t same_scalar = 0;
    for (size_t i = 0; i < RAYS; i++)
        same_scalar += prim[i] == sprim[i];
    r->agree_scalar = (double)same_scalar / RAYS;
    /* THREADS threads: octree and Embree take turns, each chunk split between the threads. */
    trace_range oproto = {0};
    oproto.a = a;
    oproto.rays = rays;
    oproto.prim = sprim; /* the answers were checked above; these only need somewhere to go */
    double octree2_s = 0.0, embree2_s = 0.0;
    bool threads_ok = true;
    for (size_t begin = 0; begin < RAYS && threads_ok; begin += CHUNK) {
        size_t end = begin + CHUNK < RAYS ? begin + CHUNK : RAYS;
        /* Each chunk CHUNK_TRIES times in turn, the quickest counting: the
         * wall clock of two threads on a shared machine is otherwise mostly
         * a measure of who else ran. */
        double best_o = INFINITY, best_e = INFINITY;
        for (int k = 0; k < CHUNK_TRIES && threads_ok; k++) {
            double t = trace_threads(oproto, begin, end);
            threads_ok = t >= 0.0;
            best_o = fmin(best_o, t);
#ifdef PS_HAVE_EMBREE
            trace_range eproto = oproto;
            eproto.a = NULL;
            eproto.scene = scene;
            eproto.triangles = s->triangle_count;
            t = trace_threads(eproto, begin, end);
            threads_ok = threads_ok && t >= 0.0;
            best_e = fmin(best_e, t);
#endif
        }
        octree2_s += best_o;
        embree2_s += best_e;
    }
    if (threads_ok) {
        r->octree_rps2 = RAYS / octree2_s;
        r->embree_rps2 = HAVE_EMBREE ? RAYS / embree2_s : 0.0;
    }
#ifdef PS_HAVE_EMBREE
    r->embree_rps = RAYS / embree_s;
    size_t hit_same = 0, prim_same = 0;
    for (size_t i = 0; i < RAYS; i++) {
        hit_same += (prim[i] == UINT32_MAX) == (eprim[i] == UINT32_MAX);
        prim_same += prim[i] == eprim[i];
    }
    r->agree_hit = (double)hit_same / RAYS;
    r->agree_prim = (double)prim_same / RAYS;
    rtcReleaseScene(scene);
    rtcReleaseDevice(dev);
#else
    (void)embree_s;
#endif

    /* Step 3: brute force on a prefix of the rays, checked against the octree. */
    size_t prims = s->triangle_count + s->sphere_count;
    if (prims <= BRUTE_MAX_PRIMS) {
        size_t nb = (size_t)(BRUTE_TESTS / (double)prims);
        nb = nb < BRUTE_MIN_RAYS ? BRUTE_MIN_RAYS : nb > RAYS ? RAYS : nb;
        size_t same = 0;
        double t0 = bench_now();
        for (size_t i = 0; i < nb; i++) {
            ps_hit h;
            uint32_t p = ps_accel_intersect_brute(a, rays[i], 0.0, INFINITY, &h) ? h.prim : UINT32_MAX;
            same += p == prim[i];
        }
        r->brute_rps = nb / (bench_now() - t0);
        r->agree_brute = (double)same / (double)nb;
    } else {
        /* Too slow to time; still check a few thousand rays. */
        size_t nb = BRUTE_MIN_RAYS, same = 0;
        for (size_t i = 0; i < nb; i++) {
            ps_hit h;
            uint32_t p = ps_accel_intersect_brute(a, rays[i], 0.0, INFINITY, &h) ? h.prim : UINT32_MAX;
            same += p == prim[i];
        }
        r->agree_brute = (double)same / (double)nb;
    }

    /* Step 4: the nearest-geometry query from the ray origins, and its oracle on a few. */
    double t0 = ps_thread_cpu_seconds(), sink = 0.0;
    for (size_t i = 0; i < NEAREST_QUERIES; i++)
        sink += ps_accel_nearest_distance(a, rays[i].o);
    r->nearest_us = 1e6 * (ps_thread_cpu_seconds() - t0) / NEAREST_QUERIES;
    size_t same = 0;
    t0 = ps_thread_cpu_seconds();
    for (size_t i = 0; i < NEAREST_BRUTE; i++) {
        ps_nearest n1, n2;
        bool f1 = ps_accel_nearest_brute(a, rays[i].o, INFINITY, &n2);
        bool f2 = ps_accel_nearest(a, rays[i].o, INFINITY, &n1);
        same += f1 == f2 && (!f1 || (n1.prim == n2.prim && n1.distance == n2.distance));
    }
    r->nearest_brute_us = 1e6 * (ps_thread_cpu_seconds() - t0) / NEAREST_BRUTE - r->nearest_us;
    r->agree_nearest = (double)same / NEAREST_BRUTE;
    if (!(sink >= 0.0))
        fprintf(stderr, "bench_accel: %s: a nearest distance is not a number\n", name);

    free(prim);
    free(sprim);
    free(eprim);
    ps_accel_destroy(a);
    ps_accel_destroy(sa);
    return 0;
}

static void print_rows(const row *rows, int n)
{
    printf("\n%-11s %8s %3s %8s %8s %6s %7s %6s | %7s %7s %7s %7s %6s | %7s %7s %6s | %8s %9s %9s %9s\n", "scene",
           "triangl", "sph", "build_ms", "emb_b_ms", "b_rat", "nodes", "refs/p", "oct_M/s", "scal_M/s", "brut_M/s",
           "emb_M/s", "ratio", "oct2M/s", "emb2M/s", "ratio2", "MiB", "agree_bru", "agree_sca", "agree_emb");
    for (int i = 0; i < n; i++) {
        const row *r = &rows[i];
        char brute[16] = "-", emb[16] = "-", ebuild[16] = "-", brat[16] = "-", ratio[16] = "-", emb2[16] = "-",
             ratio2[16] = "-", oct2[16] = "-", ap[16] = "-";
        if (r->brute_rps > 0)
            snprintf(brute, sizeof brute, "%.4f", r->brute_rps / 1e6);
        if (r->octree_rps2 > 0)
            snprintf(oct2, sizeof oct2, "%.3f", r->octree_rps2 / 1e6);
        if (r->embree_rps > 0) {
            snprintf(emb, sizeof emb, "%.3f", r->embree_rps / 1e6);
            snprintf(ebuild, sizeof ebuild, "%.1f", r->embree_build_s * 1e3);
            snprintf(brat, sizeof brat, "%.2f", r->build_s / r->embree_build_s);
            snprintf(ratio, sizeof ratio, "%.2f", r->octree_rps / r->embree_rps);
            snprintf(ap, sizeof ap, "%.5f", r->agree_prim);
        }
        if (r->embree_rps2 > 0) {
            snprintf(emb2, sizeof emb2, "%.3f", r->embree_rps2 / 1e6);
            snprintf(ratio2, sizeof ratio2, "%.2f", r->octree_rps2 / r->embree_rps2);
        }
        printf("%-11s %8zu %3zu %8.1f %8s %6s %7zu %6.2f | %7.3f %7.3f %7s %7s %6s | %7s %7s %6s | %8.1f %9.5f %9.5f %9s\n",
               r->name, r->triangles, r->spheres, r->build_s * 1e3, ebuild, brat, r->nodes, r->refs_per_prim,
               r->octree_rps / 1e6, r->scalar_rps / 1e6, brute, emb, ratio, oct2, emb2, ratio2, r->mbytes,
               r->agree_brute, r->agree_scalar, ap);
    }
    printf("\nnearest geometry (ps_accel_nearest from the ray origins, microseconds a query, one thread):\n");
    printf("%-11s %8s %10s %10s %9s\n", "scene", "triangl", "octree_us", "brute_us", "agree");
    for (int i = 0; i < n; i++)
        printf("%-11s %8zu %10.3f %10.1f %9.5f\n", rows[i].name, rows[i].triangles, rows[i].nearest_us,
               rows[i].nearest_brute_us, rows[i].agree_nearest);
    printf("\nb_rat: octree build time / Embree's (best of %d, wall clock; Embree builds on every core, the octree "
           "on one)\n"
           "ratio: octree / Embree rays per second on one thread (per second of the thread's processor time)\n"
           "ratio2: the same on %d threads (wall clock, each chunk the quickest of %d)\n",
           BUILDS, THREADS, CHUNK_TRIES);
    printf("\ncsv:\nscene,triangles,spheres,build_s,nodes,refs_per_prim,mbytes,octree_rays_per_s,scalar_rays_per_s,"
           "brute_rays_per_s,embree_build_s,embree_rays_per_s,octree_over_embree,octree_rays_per_s_%dt,"
           "embree_rays_per_s_%dt,octree_over_embree_%dt,build_over_embree,agree_hit,agree_prim,agree_brute,"
           "agree_scalar\n",
           THREADS, THREADS, THREADS);
    for (int i = 0; i < n; i++) {
        const row *r = &rows[i];
        printf("%s,%zu,%zu,%.6f,%zu,%.4f,%.3f,%.0f,%.0f,%.0f,%.6f,%.0f,%.4f,%.0f,%.0f,%.4f,%.4f,%.6f,%.6f,%.6f,%.6f\n",
               r->name, r->triangles, r->spheres, r->build_s, r->nodes, r->refs_per_prim, r->mbytes, r->octree_rps,
               r->scalar_rps, r->brute_rps, r->embree_build_s, r->embree_rps,
               r->embree_rps > 0 ? r->octree_rps / r->embree_rps : 0.0, r->octree_rps2, r->embree_rps2,
               r->embree_rps2 > 0 ? r->octree_rps2 / r->embree_rps2 : 0.0,
               r->embree_build_s > 0 ? r->build_s / r->embree_build_s : 0.0, r->agree_hit, r->agree_prim,
               r->agree_brute, r->agree_scalar);
    }
}

int main(int argc, char **argv)
{
    const char *scene_path = argc > 1 ? argv[1] : "data/scenes/cornell-caustic.scn";
    static const size_t sizes[] = {1000, 10000, 100000, 1000000};
    enum { ROWS = 1 + sizeof sizes / sizeof sizes[0] };
    row rows[ROWS];
    int n = 0, status = 0;

#ifdef PS_HAVE_EMBREE
    printf("embree: %s (rtcIntersect1, RTC_SCENE_FLAG_NONE, RTC_BUILD_QUALITY_HIGH, single precision)\n",
           RTC_VERSION_STRING);
#else
    printf("embree: not installed (apt-get install libembree-dev), baseline skipped\n");
#endif
    printf("rays: %d per scene, origins uniform in [-%.1f, %.1f]^3, uniform directions, one thread and %d\n", RAYS,
           ORIGIN_BOX, ORIGIN_BOX, THREADS);
    ps_ray *rays = bench_rays(RAYS, ORIGIN_BOX, RAY_SEED);
    if (!rays) {
        fprintf(stderr, "bench_accel: out of memory\n");
        return 1;
    }

    /* (a) The default scene, through the scene loader. */
    ps_scene *sc = NULL;
    ps_error err;
    if (ps_scene_load(scene_path, NULL, &sc, &err) != PS_OK) {
        fprintf(stderr, "bench_accel: %s\n", err.msg);
        status = 1;
    } else {
        size_t npos, ntri, nobj;
        const ps_vec3 *pos = ps_scene_positions(sc, &npos);
        const ps_triangle *tri = ps_scene_triangles(sc, &ntri);
        const ps_object *obj = ps_scene_objects(sc, &nobj);
        uint32_t *idx = malloc(sizeof *idx * 3 * (ntri + 1));
        ps_vec3 *centers = malloc(sizeof *centers * (nobj + 1));
        double *radii = malloc(sizeof *radii * (nobj + 1));
        size_t nsph = 0;
        if (idx && centers && radii) {
            for (size_t t = 0; t < ntri; t++)
                for (int k = 0; k < 3; k++)
                    idx[3 * t + (size_t)k] = tri[t].v[k];
            for (size_t i = 0; i < nobj; i++)
                if (obj[i].type == PS_OBJ_SPHERE) {
                    centers[nsph] = obj[i].center;
                    radii[nsph++] = obj[i].radius;
                }
            /* The same primitives as ps_accel_build_scene makes (checked: it is what the renderers use). */
            ps_accel *check = NULL;
            if (ps_accel_build_scene(sc, NULL, &check, NULL, &err) == PS_OK &&
                ps_accel_prim_count(check) == ntri + nsph) {
                bench_scene s = {pos, npos, idx, ntri, centers, radii, nsph};
                /* The box spans y in [0, 2]: lift the rays by 1 to centre them on it. */
                ps_ray *lifted = malloc(sizeof *lifted * RAYS);
                if (lifted) {
                    for (size_t i = 0; i < RAYS; i++)
                        lifted[i] = ps_ray_make(ps_v3_add(rays[i].o, ps_v3(0, 1, 0)), rays[i].d);
                    if (measure("cornell", &s, lifted, &rows[n]) == 0)
                        n++;
                    free(lifted);
                }
            }
            ps_accel_destroy(check);
        }
        free(idx);
        free(centers);
        free(radii);
        ps_scene_destroy(sc);
    }

    /* (b) Bumpy spheres in a closed box, 1k to 1M triangles. */
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        bench_mesh m;
        if (bench_blob_in_box(sizes[k], &m) != 0) {
            fprintf(stderr, "bench_accel: out of memory for %zu triangles\n", sizes[k]);
            status = 1;
            continue;
        }
        char name[32];
        snprintf(name, sizeof name, "blob-%zuk", sizes[k] / 1000);
        bench_scene s = {m.positions, m.position_count, m.indices, m.triangle_count, NULL, NULL, 0};
        if (measure(name, &s, rays, &rows[n]) == 0)
            n++;
        else
            status = 1;
        bench_mesh_free(&m);
        fflush(stdout);
    }
    print_rows(rows, n);
    /* The goals, from this run's ratios (the blobs only). */
    double worst1 = INFINITY, worst2 = INFINITY, worst_build = 0.0;
    for (int i = 0; i < n; i++) {
        if (strncmp(rows[i].name, "blob", 4) != 0 || rows[i].embree_rps <= 0)
            continue;
        worst1 = fmin(worst1, rows[i].octree_rps / rows[i].embree_rps);
        if (rows[i].embree_rps2 > 0)
            worst2 = fmin(worst2, rows[i].octree_rps2 / rows[i].embree_rps2);
        worst_build = fmax(worst_build, rows[i].build_s / rows[i].embree_build_s);
    }
    if (isfinite(worst1))
        printf("\ngoals: octree / Embree on the blobs at worst %.2f on one thread, %.2f on %d (goal: >= 0.5); build "
               "at worst %.2fx Embree's (goal: <= 1.5)\n",
               worst1, worst2, THREADS, worst_build);
    for (int i = 0; i < n; i++)
        if (rows[i].agree_brute < 1.0) {
            fprintf(stderr, "bench_accel: %s: octree and brute force disagree on %.4f%% of rays\n", rows[i].name,
                    100.0 * (1.0 - rows[i].agree_brute));
            status = 1;
        } else if (rows[i].agree_nearest < 1.0) {
            fprintf(stderr, "bench_accel: %s: nearest geometry: octree and brute force disagree on %.4f%% of points\n",
                    rows[i].name, 100.0 * (1.0 - rows[i].agree_nearest));
            status = 1;
        } else if (rows[i].agree_scalar < 1.0) {
            fprintf(stderr, "bench_accel: %s: AVX2 and scalar traversal disagree on %.4f%% of rays\n", rows[i].name,
                    100.0 * (1.0 - rows[i].agree_scalar));
            status = 1;
        }
    free(rays);
    return status;
}
