/* ref_main.c: photosplat-ref, the software reference renderer.
 *
 * For now it traces the photon maps (--photons-only) so the tracer can be
 * checked on its own: --dump-photons writes every stored photon, --stats the
 * figures of the run. The ray-traced image (-o, --hdr) comes with the
 * reference renderer itself. */
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "app/cli.h"
#include "app/stats.h"
#include "core/fileio.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "scene/scene.h"

static const char usage[] =
    "usage: photosplat-ref SCENE.scn --photons-only [options]\n"
    "       photosplat-ref SCENE.scn -o OUT.png [options]\n"
    "\n"
    "The software reference renderer: a Monte Carlo ray tracer with kd-tree photon\n"
    "maps. With --photons-only it traces the caustic and global photon maps and\n"
    "writes them (--dump-photons) and the run's figures (--stats) without an image.\n"
    "\n"
    "options:\n"
    "  -o FILE.png              8-bit PNG, sRGB after exposure (not yet available)\n"
    "  --hdr FILE.pfm           linear radiance, little-endian PFM (not yet available)\n"
    "  --size WxH               image size (default from the scene)\n"
    "  --exposure E             radiance multiplier before encoding (default 1)\n"
    "  --caustic-photons N      photons emitted for the caustic map (default from the scene)\n"
    "  --global-photons N       photons emitted for the global map (default from the scene)\n"
    "  --caustic-radius R       caustic search radius, scene units\n"
    "  --global-radius R        global search radius, scene units\n"
    "  --seed S                 photon i depends only on (scene, seed, i) (default 0)\n"
    "  --threads N              worker threads (default: all cores)\n"
    "  --stats FILE.json        figures of the run\n"
    "  --dump-photons FILE      every stored photon: map x y z r g b dx dy dz nx ny nz\n"
    "  --photons-only           trace the photon maps only; -o is not needed\n"
    "  --spp N, --k N, --max-radius R, --gather N\n"
    "                           eye samples, photons per estimate, largest radius, final gather\n"
    "  --component all|direct|caustic|indirect|specular\n"
    "                           render one term of the split rendering equation\n"
    "  --caustic-cones on|off   aim caustic photons only at specular objects (default on)\n"
    "  --first-hit-test on|off  drop cone photons that first hit another object (default on;\n"
    "                           off shows the double counting of overlapping cones)\n"
    "  --accel auto|octree|brute  ray accelerator (default auto)\n"
    "  --help                   this text\n";

typedef struct ref_options {
    const char *scene, *out_png, *out_hdr, *stats, *dump;
    int64_t photons[PS_MAP_COUNT]; /* -1: the scene's default */
    int64_t seed, threads;
    bool photons_only;
    bool cones, first_hit;
    int accel;
} ref_options;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static ps_status parse_args(int argc, char **argv, ref_options *o, bool *help, ps_error *err)
{
    static const char *const on_off[] = {"off", "on", NULL};
    static const char *const components[] = {"all", "direct", "caustic", "indirect", "specular", NULL};
    static const char *const accels[] = {"auto", "octree", "brute", NULL};
    ps_cli cli = ps_cli_begin("photosplat-ref", argc, argv);
    memset(o, 0, sizeof *o);
    o->photons[PS_MAP_CAUSTIC] = o->photons[PS_MAP_GLOBAL] = -1;
    o->cones = o->first_hit = true;
    ps_status st = PS_OK;
    double dummy_d;
    int64_t dummy_i;
    int choice, w, h;
    while (st == PS_OK && ps_cli_next(&cli)) {
        if (ps_cli_is(&cli, "--help") || ps_cli_is(&cli, "-h")) {
            *help = true;
            return PS_OK;
        } else if (ps_cli_positional(&cli)) {
            if (o->scene)
                return ps_error_set(err, PS_ERR_PARSE, "photosplat-ref: more than one scene given ('%s')",
                                    ps_cli_arg(&cli));
            o->scene = ps_cli_arg(&cli);
        } else if (ps_cli_is(&cli, "-o")) {
            st = ps_cli_string(&cli, &o->out_png, err);
        } else if (ps_cli_is(&cli, "--hdr")) {
            st = ps_cli_string(&cli, &o->out_hdr, err);
        } else if (ps_cli_is(&cli, "--stats")) {
            st = ps_cli_string(&cli, &o->stats, err);
        } else if (ps_cli_is(&cli, "--dump-photons")) {
            st = ps_cli_string(&cli, &o->dump, err);
        } else if (ps_cli_is(&cli, "--size")) {
            st = ps_cli_size(&cli, PS_SCENE_MAX_IMAGE_SIDE, &w, &h, err);
        } else if (ps_cli_is(&cli, "--exposure")) {
            st = ps_cli_double(&cli, 0.0, 1e30, &dummy_d, err);
        } else if (ps_cli_is(&cli, "--caustic-photons")) {
            st = ps_cli_int(&cli, 0, PS_SCENE_MAX_PHOTONS, &o->photons[PS_MAP_CAUSTIC], err);
        } else if (ps_cli_is(&cli, "--global-photons")) {
            st = ps_cli_int(&cli, 0, PS_SCENE_MAX_PHOTONS, &o->photons[PS_MAP_GLOBAL], err);
        } else if (ps_cli_is(&cli, "--caustic-radius") || ps_cli_is(&cli, "--global-radius") ||
                   ps_cli_is(&cli, "--max-radius")) {
            st = ps_cli_double(&cli, 1e-300, 1e300, &dummy_d, err);
        } else if (ps_cli_is(&cli, "--seed")) {
            st = ps_cli_int(&cli, 0, INT64_MAX, &o->seed, err);
        } else if (ps_cli_is(&cli, "--threads")) {
            st = ps_cli_int(&cli, 1, PS_TRACER_MAX_THREADS, &o->threads, err);
        } else if (ps_cli_is(&cli, "--spp") || ps_cli_is(&cli, "--k")) {
            st = ps_cli_int(&cli, 1, 1000000, &dummy_i, err);
        } else if (ps_cli_is(&cli, "--gather")) {
            st = ps_cli_int(&cli, 0, 1000000, &dummy_i, err);
        } else if (ps_cli_is(&cli, "--component")) {
            st = ps_cli_choice(&cli, components, &choice, err);
        } else if (ps_cli_is(&cli, "--photons-only")) {
            o->photons_only = true;
        } else if (ps_cli_is(&cli, "--caustic-cones")) {
            st = ps_cli_choice(&cli, on_off, &choice, err);
            o->cones = choice == 1;
        } else if (ps_cli_is(&cli, "--first-hit-test")) {
            st = ps_cli_choice(&cli, on_off, &choice, err);
            o->first_hit = choice == 1;
        } else if (ps_cli_is(&cli, "--accel")) {
            st = ps_cli_choice(&cli, accels, &o->accel, err);
        } else {
            return ps_cli_unknown(&cli, err);
        }
    }
    if (st != PS_OK)
        return st;
    if (!o->scene)
        return ps_error_set(err, PS_ERR_PARSE, "photosplat-ref: no scene given (see --help)");
    if (!o->photons_only)
        return ps_error_set(err, PS_ERR_PARSE,
                            "photosplat-ref: the image renderer is not built yet; use --photons-only (see --help)");
    return PS_OK;
}

static ps_status write_dump(const char *path, const ps_photon_map maps[PS_MAP_COUNT], ps_error *err)
{
    ps_outfile *out = ps_outfile_open(path, err);
    if (!out)
        return err->status;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_photon_map_write_text(ps_outfile_stream(out), &maps[k]);
    return ps_outfile_commit(out, err);
}

/* Traces both maps and writes what was asked for. */
static ps_status run(const ref_options *o, const ps_scene *scene, ps_error *err)
{
    static const ps_accel_kind kinds[] = {PS_ACCEL_AUTO, PS_ACCEL_OCTREE, PS_ACCEL_BRUTE};
    ps_accel_options aopt = {0};
    aopt.kind = kinds[o->accel];
    ps_world *world = NULL;
    ps_tracer *tracer = NULL;
    ps_photon_map maps[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_photon_map_init(&maps[k], (ps_map_kind)k);

    double t_build = now_seconds();
    ps_status st = ps_world_create(scene, &aopt, &world, err);
    t_build = now_seconds() - t_build;
    ps_tracer_options topt = ps_tracer_default_options();
    topt.seed = (uint64_t)o->seed;
    topt.threads = (int)o->threads;
    topt.caustic_cones = o->cones;
    topt.first_hit_test = o->first_hit;
    if (st == PS_OK)
        st = ps_tracer_create(world, &topt, &tracer, err);

    const ps_scene_defaults *def = ps_scene_get_defaults(scene);
    int64_t want[PS_MAP_COUNT] = {o->photons[PS_MAP_CAUSTIC] >= 0 ? o->photons[PS_MAP_CAUSTIC] : def->caustic_photons,
                                  o->photons[PS_MAP_GLOBAL] >= 0 ? o->photons[PS_MAP_GLOBAL] : def->global_photons};
    double t_trace = now_seconds();
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++) {
        if (!ps_tracer_map_enabled(tracer, (ps_map_kind)k))
            continue;
        if (want[k] == 0) {
            st = ps_tracer_note_skip(tracer, ps_map_name((ps_map_kind)k), "0 photons requested");
            if (st != PS_OK)
                ps_error_set(err, st, "photosplat-ref: out of memory");
            continue;
        }
        st = ps_tracer_trace(tracer, (ps_map_kind)k, 0, (uint64_t)want[k], (uint64_t)want[k], &maps[k], err);
    }
    t_trace = now_seconds() - t_trace;

    if (st == PS_OK && o->dump)
        st = write_dump(o->dump, maps, err);
    if (st == PS_OK) {
        ps_run_stats rs;
        memset(&rs, 0, sizeof rs);
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            rs.emitted[k] = maps[k].counters.emitted;
            rs.stored[k] = maps[k].counters.stored;
            rs.rays += maps[k].counters.rays;
        }
        rs.trace_seconds = t_trace;
        rs.skips = ps_tracer_skips(tracer, &rs.skip_count);
        ps_accel_stats as;
        ps_accel_get_stats(ps_world_accel(world), &as);
        ps_stats_add(&rs, "threads", ps_tracer_threads(tracer));
        ps_stats_add(&rs, "seed", (double)o->seed);
        ps_stats_add(&rs, "accel_build_seconds", t_build);
        ps_stats_add(&rs, "accel_nodes", (double)as.nodes);
        ps_stats_add(&rs, "escaped", (double)(maps[0].counters.escaped + maps[1].counters.escaped));
        ps_stats_add(&rs, "absorbed", (double)(maps[0].counters.absorbed + maps[1].counters.absorbed));
        ps_stats_add(&rs, "discarded_caustic", (double)maps[PS_MAP_CAUSTIC].counters.discarded);
        ps_stats_add(&rs, "truncated", (double)(maps[0].counters.truncated + maps[1].counters.truncated));
        if (o->stats)
            st = ps_stats_write(o->stats, &rs, err);
        if (st == PS_OK) {
            printf("caustic: %llu emitted, %llu stored; global: %llu emitted, %llu stored; %llu rays in %.3f s "
                   "(%d threads)\n",
                   (unsigned long long)rs.emitted[0], (unsigned long long)rs.stored[0],
                   (unsigned long long)rs.emitted[1], (unsigned long long)rs.stored[1], (unsigned long long)rs.rays,
                   t_trace, ps_tracer_threads(tracer));
            for (size_t k = 0; k < rs.skip_count; k++)
                printf("skipped %s: %s\n", rs.skips[k].pass, rs.skips[k].reason);
        }
    }
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_photon_map_free(&maps[k]);
    ps_tracer_destroy(tracer);
    ps_world_destroy(world);
    return st;
}

int main(int argc, char **argv)
{
    ps_error err;
    ps_error_clear(&err);
    ref_options o;
    bool help = false;
    if (parse_args(argc, argv, &o, &help, &err) != PS_OK)
        return ps_cli_fail(&err);
    if (help) {
        fputs(usage, stdout);
        return PS_EXIT_OK;
    }
    ps_scene *scene;
    if (ps_scene_load(o.scene, NULL, &scene, &err) != PS_OK)
        return ps_cli_fail(&err);
    ps_status st = run(&o, scene, &err);
    ps_scene_destroy(scene);
    return st == PS_OK ? PS_EXIT_OK : ps_cli_fail(&err);
}
