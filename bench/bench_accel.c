/* bench_accel.c: the ray accelerator's speed: octree build time and
 * single-threaded rays per second against brute force and against Embree 3's
 * rtcIntersect1 (when installed), on the default scene and on closed meshes
 * of 1k to 1M triangles, all with the same random rays.
 *
 * Every ray is also checked: octree against brute force (must agree exactly)
 * and octree against Embree (hit/miss and primitive; Embree works in single
 * precision, so a few rays grazing an edge may pick the neighbour).
 * Compare ratios, not absolute numbers: these machines are noisy. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "bench_util.h"
#include "scene/scene.h"

#ifdef PS_HAVE_EMBREE
#include <embree3/rtcore.h>
#define HAVE_EMBREE 1
#else
#define HAVE_EMBREE 0
#endif

/* Rays per scene for the octree and Embree; brute force gets about this many
 * primitive tests in all, and at least BRUTE_MIN_RAYS rays. */
#define RAYS 1000000
#define CHUNK 50000 /* rays per turn when octree and Embree alternate */
#define BRUTE_TESTS 20000000.0
#define BRUTE_MIN_RAYS 1000
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
    double octree_rps, brute_rps;   /* rays per second; 0: not measured */
    double embree_build_s, embree_rps;
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
    double t0 = bench_now();
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
    return bench_now() - t0;
}
#endif

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
    r->nodes = st.nodes;
    r->refs_per_prim = (double)st.prim_refs / (double)(s->triangle_count + s->sphere_count);
    r->mbytes = (double)st.bytes / (1024.0 * 1024.0);

    /* Step 2: octree and Embree, single thread, every ray, in alternating
     * chunks so that both see the same machine (these machines are shared). */
    uint32_t *prim = malloc(sizeof *prim * RAYS);
#ifdef PS_HAVE_EMBREE
    uint32_t *eprim = malloc(sizeof *eprim * RAYS);
    RTCDevice dev = rtcNewDevice(NULL);
    RTCScene scene = embree_build(dev, s, &r->embree_build_s);
#else
    uint32_t *eprim = NULL;
#endif
    if (!prim || (HAVE_EMBREE && !eprim)) {
        fprintf(stderr, "bench_accel: out of memory\n");
#ifdef PS_HAVE_EMBREE
        rtcReleaseScene(scene);
        rtcReleaseDevice(dev);
#endif
        free(prim);
        free(eprim);
        ps_accel_destroy(a);
        return -1;
    }
    double octree_s = 0.0, embree_s = 0.0;
    for (size_t begin = 0; begin < RAYS; begin += CHUNK) {
        size_t end = begin + CHUNK < RAYS ? begin + CHUNK : RAYS;
        double t0 = bench_now();
        for (size_t i = begin; i < end; i++) {
            ps_hit h;
            prim[i] = ps_accel_intersect(a, rays[i], 0.0, INFINITY, &h) ? h.prim : UINT32_MAX;
        }
        octree_s += bench_now() - t0;
#ifdef PS_HAVE_EMBREE
        embree_s += embree_trace(scene, rays, begin, end, s->triangle_count, eprim);
#endif
    }
    r->octree_rps = RAYS / octree_s;
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

    free(prim);
    free(eprim);
    ps_accel_destroy(a);
    return 0;
}

static void print_rows(const row *rows, int n)
{
    printf("\n%-12s %9s %4s %9s %8s %9s %7s %10s %10s %10s %10s %7s %9s %9s %9s\n", "scene", "triangles", "sph",
           "build_ms", "nodes", "refs/prim", "MiB", "octree_M/s", "brute_M/s", "emb_bld_ms", "embree_M/s", "ratio",
           "agree_hit", "agree_pri", "agree_bru");
    for (int i = 0; i < n; i++) {
        const row *r = &rows[i];
        char brute[16] = "-", emb[16] = "-", ebuild[16] = "-", ratio[16] = "-", ah[16] = "-", ap[16] = "-";
        if (r->brute_rps > 0)
            snprintf(brute, sizeof brute, "%.4f", r->brute_rps / 1e6);
        if (r->embree_rps > 0) {
            snprintf(emb, sizeof emb, "%.3f", r->embree_rps / 1e6);
            snprintf(ebuild, sizeof ebuild, "%.1f", r->embree_build_s * 1e3);
            snprintf(ratio, sizeof ratio, "%.2f", r->octree_rps / r->embree_rps);
            snprintf(ah, sizeof ah, "%.5f", r->agree_hit);
            snprintf(ap, sizeof ap, "%.5f", r->agree_prim);
        }
        printf("%-12s %9zu %4zu %9.1f %8zu %9.2f %7.1f %10.3f %10s %10s %10s %7s %9s %9s %9.5f\n", r->name, r->triangles,
               r->spheres, r->build_s * 1e3, r->nodes, r->refs_per_prim, r->mbytes, r->octree_rps / 1e6, brute, ebuild,
               emb, ratio, ah, ap, r->agree_brute);
    }
    printf("\ncsv:\nscene,triangles,spheres,build_s,nodes,refs_per_prim,mbytes,octree_rays_per_s,brute_rays_per_s,"
           "embree_build_s,embree_rays_per_s,octree_over_embree,agree_hit,agree_prim,agree_brute\n");
    for (int i = 0; i < n; i++) {
        const row *r = &rows[i];
        printf("%s,%zu,%zu,%.6f,%zu,%.4f,%.3f,%.0f,%.0f,%.6f,%.0f,%.4f,%.6f,%.6f,%.6f\n", r->name, r->triangles,
               r->spheres, r->build_s, r->nodes, r->refs_per_prim, r->mbytes, r->octree_rps, r->brute_rps,
               r->embree_build_s, r->embree_rps, r->embree_rps > 0 ? r->octree_rps / r->embree_rps : 0.0, r->agree_hit,
               r->agree_prim, r->agree_brute);
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
    printf("rays: %d per scene, origins uniform in [-%.1f, %.1f]^3, uniform directions, one thread\n", RAYS,
           ORIGIN_BOX, ORIGIN_BOX);
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
    for (int i = 0; i < n; i++)
        if (rows[i].agree_brute < 1.0) {
            fprintf(stderr, "bench_accel: %s: octree and brute force disagree on %.4f%% of rays\n", rows[i].name,
                    100.0 * (1.0 - rows[i].agree_brute));
            status = 1;
        }
    free(rays);
    return status;
}
