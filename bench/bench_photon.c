/* bench_photon.c: photons traced per second, and how time per photon grows
 * with the triangle count (1k to 1M), on one thread and on all cores.
 *
 * The figures are rates measured in this run, printed next to the default
 * scene's own rate as the baseline (these machines are noisy: compare ratios,
 * not absolute numbers). Each row also prints what the photons look like
 * (stored per emitted, rays per photon), so a speed-up that silently changed
 * the photon set would show. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "photon/tracer.h"
#include "photon/world.h"
#include "scene/scene.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A bumpy latitude-longitude sphere of about `triangles` triangles, radius
 * 0.4 at (0, 0.6, 0), as an OBJ file: a closed mesh that photons must find. */
static int write_blob(const char *path, long triangles)
{
    int lat = (int)ceil(sqrt((double)triangles / 4.0)), lon = 2 * lat;
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "v 0 1.0 0\n");
    for (int i = 1; i < lat; i++)
        for (int j = 0; j < lon; j++) {
            double th = PS_PI * i / lat, ph = 2 * PS_PI * j / lon;
            double r = 0.4 * (1.0 + 0.08 * sin(7 * th) * cos(5 * ph));
            fprintf(f, "v %.9g %.9g %.9g\n", r * sin(th) * cos(ph), 0.6 + r * cos(th), r * sin(th) * sin(ph));
        }
    fprintf(f, "v 0 0.2 0\n");
    int south = 2 + (lat - 1) * lon;
    for (int j = 0; j < lon; j++)
        fprintf(f, "f 1 %d %d\n", 2 + (j + 1) % lon, 2 + j);
    for (int i = 0; i + 2 < lat; i++)
        for (int j = 0; j < lon; j++) {
            int a = 2 + i * lon + j, b = 2 + i * lon + (j + 1) % lon, c = a + lon, d = b + lon;
            fprintf(f, "f %d %d %d\nf %d %d %d\n", a, b, d, a, d, c);
        }
    for (int j = 0; j < lon; j++)
        fprintf(f, "f %d %d %d\n", south, 2 + (lat - 2) * lon + j, 2 + (lat - 2) * lon + (j + 1) % lon);
    return fclose(f);
}

typedef struct result {
    double seconds, rays_per_photon, stored_per_photon;
    size_t triangles;
} result;

static int run_map(const char *scene_path, const char *text, const char *dir, int threads, uint64_t photons,
                   ps_map_kind kind, ps_accel_kind accel, result *r)
{
    ps_scene *s = NULL;
    ps_world *w = NULL;
    ps_tracer *t = NULL;
    ps_error err;
    ps_status st = text ? ps_scene_load_text(text, "bench.scn", dir, NULL, &s, &err)
                        : ps_scene_load(scene_path, NULL, &s, &err);
    ps_accel_options aopt = {0};
    aopt.kind = accel;
    if (st == PS_OK)
        st = ps_world_create(s, &aopt, &w, &err);
    ps_tracer_options o = ps_tracer_default_options();
    o.threads = threads;
    if (st == PS_OK)
        st = ps_tracer_create(w, &o, &t, &err);
    if (st != PS_OK) {
        fprintf(stderr, "bench_photon: %s\n", err.msg);
        ps_tracer_destroy(t);
        ps_world_destroy(w);
        ps_scene_destroy(s);
        return -1;
    }
    ps_photon_map m;
    ps_photon_map_init(&m, kind);
    double t0 = now();
    st = ps_tracer_trace(t, kind, 0, photons, photons, &m, &err);
    r->seconds = now() - t0;
    r->rays_per_photon = (double)m.counters.rays / (double)photons;
    r->stored_per_photon = (double)m.counters.stored / (double)photons;
    (void)ps_scene_triangles(s, &r->triangles);
    ps_photon_map_free(&m);
    ps_tracer_destroy(t);
    ps_world_destroy(w);
    ps_scene_destroy(s);
    return st == PS_OK ? 0 : -1;
}

static int run(const char *scene_path, const char *text, const char *dir, int threads, uint64_t photons, result *r)
{
    return run_map(scene_path, text, dir, threads, photons, PS_MAP_GLOBAL, PS_ACCEL_AUTO, r);
}

int main(void)
{
    const char *dir = "build/bench-tmp";
    mkdir("build", 0777);
    mkdir(dir, 0777);
    const uint64_t photons = 200000;
    int all = 0; /* 0: one thread per core */
    /* The default scene (12 primitives), both maps, with the octree and with
     * the brute-force loop as the baseline measured in the same run. */
    const char *def = "data/scenes/cornell-caustic.scn";
    result base1, baseN, c1, cN, b1, bc1;
    if (run_map(def, NULL, NULL, 1, photons, PS_MAP_GLOBAL, PS_ACCEL_OCTREE, &base1) ||
        run_map(def, NULL, NULL, all, photons, PS_MAP_GLOBAL, PS_ACCEL_OCTREE, &baseN) ||
        run_map(def, NULL, NULL, 1, photons, PS_MAP_CAUSTIC, PS_ACCEL_OCTREE, &c1) ||
        run_map(def, NULL, NULL, all, photons, PS_MAP_CAUSTIC, PS_ACCEL_OCTREE, &cN) ||
        run_map(def, NULL, NULL, 1, photons, PS_MAP_GLOBAL, PS_ACCEL_BRUTE, &b1) ||
        run_map(def, NULL, NULL, 1, photons, PS_MAP_CAUSTIC, PS_ACCEL_BRUTE, &bc1))
        return 1;
    printf("photon tracing: %llu photons a run; 1t: one thread, Nt: all cores\n", (unsigned long long)photons);
    printf("vs base: one-thread speed relative to the first row\n");
    printf("%-34s %10s %12s %12s %9s %9s %10s\n", "scene", "triangles", "photons/s 1t", "photons/s Nt",
           "vs base", "rays/ph", "stored/ph");
    printf("%-34s %10zu %12.0f %12.0f %9.2f %9.2f %10.2f\n", "cornell global, octree (base)", base1.triangles,
           photons / base1.seconds, photons / baseN.seconds, 1.0, base1.rays_per_photon, base1.stored_per_photon);
    printf("%-34s %10zu %12.0f %12s %9.2f %9.2f %10.2f\n", "cornell global, brute force", b1.triangles,
           photons / b1.seconds, "-", base1.seconds / b1.seconds, b1.rays_per_photon, b1.stored_per_photon);
    printf("%-34s %10zu %12.0f %12.0f %9.2f %9.2f %10.2f\n", "cornell caustic, octree", c1.triangles,
           photons / c1.seconds, photons / cN.seconds, base1.seconds / c1.seconds, c1.rays_per_photon,
           c1.stored_per_photon);
    printf("%-34s %10zu %12.0f %12s %9.2f %9.2f %10.2f\n", "cornell caustic, brute force", bc1.triangles,
           photons / bc1.seconds, "-", base1.seconds / bc1.seconds, bc1.rays_per_photon, bc1.stored_per_photon);
    long sizes[] = {1000, 10000, 100000, 1000000};
    double first_us = 0;
    printf("csv,scene,triangles,photons_per_s_1t,photons_per_s_nt,us_per_photon_1t,rays_per_photon\n");
    printf("csv,cornell-caustic,%zu,%.0f,%.0f,%.4f,%.3f\n", base1.triangles, photons / base1.seconds,
           photons / baseN.seconds, 1e6 * base1.seconds / photons, base1.rays_per_photon);
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        char obj[256], text[1024], name[64];
        snprintf(obj, sizeof obj, "%s/blob%ld.obj", dir, sizes[k]);
        if (write_blob(obj, sizes[k]) != 0) {
            fprintf(stderr, "bench_photon: cannot write %s\n", obj);
            return 1;
        }
        /* The default box with the blob (diffuse) in place of the spheres. */
        snprintf(text, sizeof text,
                 "camera eye 0 1 3.4 target 0 1 0\n"
                 "material white diffuse albedo 0.75 0.75 0.75\n"
                 "material blob diffuse albedo 0.6 0.6 0.6\n"
                 "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                 "quad corner -1 2 -1 edge1 2 0 0 edge2 0 0 2 material white\n"
                 "quad corner -1 0 -1 edge1 2 0 0 edge2 0 2 0 material white\n"
                 "quad corner -1 0 -1 edge1 0 2 0 edge2 0 0 2 material white\n"
                 "quad corner 1 0 -1 edge1 0 0 2 edge2 0 2 0 material white\n"
                 "mesh blob%ld.obj material blob\n"
                 "light point position 0 1.9 0 power 100 100 100\n",
                 sizes[k]);
        result r1, rN;
        if (run(NULL, text, dir, 1, photons, &r1) || run(NULL, text, dir, all, photons, &rN))
            return 1;
        double us = 1e6 * r1.seconds / photons;
        if (k == 0)
            first_us = us;
        snprintf(name, sizeof name, "blob %ldk triangles", sizes[k] / 1000);
        printf("%-34s %10zu %12.0f %12.0f %9.2f %9.2f %10.2f   time/photon x%.2f of 1k\n", name, r1.triangles,
               photons / r1.seconds, photons / rN.seconds, base1.seconds / r1.seconds, r1.rays_per_photon,
               r1.stored_per_photon, us / first_us);
        printf("csv,blob%ld,%zu,%.0f,%.0f,%.4f,%.3f\n", sizes[k], r1.triangles, photons / r1.seconds,
               photons / rN.seconds, us, r1.rays_per_photon);
        remove(obj);
    }
    return 0;
}
