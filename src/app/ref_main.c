/* ref_main.c: photosplat-ref, the software reference renderer: traces the
 * photon maps, then ray traces the image over them (src/render). With
 * --photons-only it stops after the maps, so the tracer can be checked alone. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "app/cli.h"
#include "app/interrupt.h"
#include "app/options.h"
#include "app/ref_dist.h"
#include "app/stats.h"
#include "core/fileio.h"
#include "photon/estimate.h"
#include "photon/kdtree.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "image/exr_io.h"
#include "render/render.h"
#include "scene/scene.h"
#ifdef PS_REF_DIST
#include "dist/dist.h"
#endif

/* Defaults for the image: --quality default's settings (ps_render_quality),
 * then k. */
#define REF_DEFAULT_K 100
/* An option --quality leaves to the preset. */
#define REF_UNSET (-1)
/* Final gathering looks irradiance up at every this-many-th photon (Christensen 1999 uses a subset). */
#define REF_IRRADIANCE_STRIDE 4
/* The memory plan (ps_check_run_memory): maps in memory at once (caustic,
 * global, and the global map with direct hits for final gathering), and a
 * pixel's bytes (the float image; the PNG encoder works a row at a time). */
#define REF_MAPS_AT_ONCE 3
#define REF_PIXEL_BYTES (3 * sizeof(float))
/* ... and with a pixel filter other than the box, its tile buffers: 4 floats
 * a pixel over tiles grown by 2 on each side, (16 + 4)^2 / 16^2 of the image. */
#define REF_FILTER_BYTES (4 * sizeof(float) * 25 / 16)

static const char usage[] =
    "usage: photosplat-ref SCENE.scn --photons-only [options]\n"
    "       photosplat-ref SCENE.scn -o OUT.png [options]\n"
    "\n"
    "The software reference renderer: a Monte Carlo ray tracer with kd-tree photon\n"
    "maps. With --photons-only it traces the caustic and global photon maps and\n"
    "writes them (--dump-photons) and the run's figures (--stats) without an image.\n"
    "\n"
    "options:\n"
    "  -o FILE.png              8-bit PNG, sRGB after exposure\n"
    "  --hdr FILE.pfm|FILE.exr  linear radiance (W sr^-1 m^-2): little-endian PFM, or OpenEXR\n"
    "                           (32-bit float, ZIP) when the name ends in .exr\n"
    "  --illuminance FILE.pfm   one-channel PFM (or .exr) of the illuminance in lux falling on\n"
    "                           the surface seen in each pixel, whatever its albedo\n"
    "                           (--component applies)\n"
    "  --false-color FILE.png   the same as a false-colour picture with a logarithmic legend in lux\n"
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
    "  --quality draft|default|final  sets --spp, --gather, --cache, --cache-rays and the\n"
    "                           photon counts together (default: default); options given\n"
    "                           explicitly win: draft spp 1, gather 8, cache 4, 256 rays,\n"
    "                           photons x0.5; default spp 4, gather 16, cache 2, 1024 rays;\n"
    "                           final spp 16, gather 32, cache 1, 2048 rays, photons x2\n"
    "  --filter mitchell|gaussian|box  pixel filter (default mitchell; box: each pixel\n"
    "                           the mean of its own samples)\n"
    "  --spp N                  eye samples per pixel (default 4)\n"
    "  --k N                    photons per radiance estimate (default 100)\n"
    "  --max-radius R           largest search radius of both maps (default: their radii)\n"
    "  --gather N               final gather rays per indirect estimate (default 16;\n"
    "                           0: the global map's estimate directly)\n"
    "  --kernel box|cone|gauss|epanechnikov  radiance estimate kernel (default cone)\n"
    "  --light-samples N        shadow rays per area light per eye sample (default 1)\n"
    "  --cache N                irradiance cache with gradients, records placed where none\n"
    "                           reaches, asked for on pixel grids down to N apart\n"
    "                           (default 2; 0: off)\n"
    "  --cache-rays N           gather rays per cache record (default 1024)\n"
    "  --component all|direct|caustic|indirect|specular\n"
    "                           render one term of the split rendering equation: direct\n"
    "                           (lights), caustic (the caustic map), indirect (other\n"
    "                           surfaces' light, diffusely reflected), specular (all seen in\n"
    "                           mirrors and glass, and glossy lobes' reflection of the room)\n"
    "  --caustic-cones on|off   aim caustic photons only at specular objects (default on)\n"
    "  --first-hit-test on|off  drop cone photons that first hit another object (default on;\n"
    "                           off shows the double counting of overlapping cones)\n"
    "  --accel auto|octree|brute  ray accelerator (default auto)\n"
    "  --help                   this text\n";

typedef struct ref_options {
    ps_shared_options c;
    double max_radius; /* 0: the radii */
    int64_t spp, k, gather, light_samples, cache, cache_rays;
    int component, kernel, quality, filter;
    bool photons_only;
    bool cones, first_hit;
    const char *out_lux, *out_false; /* --illuminance, --false-color */
    int accel;
    const ps_cancel_flag *cancel; /* raised by SIGINT or SIGTERM */
    const ps_ref_dist *dist;      /* NULL, or the ranks of photosplat-ref-mpi (ref_dist.h) */
} ref_options;

static ps_status parse_args(int argc, char **argv, ref_options *o, bool *help, ps_error *err)
{
    static const char *const on_off[] = {"off", "on", NULL};
    static const char *const components[] = {"all", "direct", "caustic", "indirect", "specular", NULL};
    static const char *const accels[] = {"auto", "octree", "brute", NULL};
    static const char *const qualities[] = {"draft", "default", "final", NULL};
    static const char *const filters[] = {"box", "mitchell", "gaussian", NULL};
    ps_cli cli = ps_cli_begin("photosplat-ref", argc, argv);
    memset(o, 0, sizeof *o);
    ps_shared_options_init(&o->c);
    o->cones = o->first_hit = true;
    o->spp = o->gather = o->cache = o->cache_rays = REF_UNSET;
    o->quality = PS_QUALITY_DEFAULT;
    o->filter = PS_FILTER_MITCHELL;
    o->k = REF_DEFAULT_K;
    o->light_samples = 1;
    o->kernel = PS_KERNEL_CONE;
    ps_status st = PS_OK;
    int choice;
    while (st == PS_OK && ps_cli_next(&cli)) {
        if (ps_cli_is(&cli, "--help") || ps_cli_is(&cli, "-h")) {
            *help = true;
            return PS_OK;
        } else if (ps_shared_option(&cli, "photosplat-ref", &o->c, &st, err)) {
            continue;
        } else if (ps_cli_is(&cli, "--max-radius")) {
            st = ps_cli_double(&cli, 1e-300, 1e300, &o->max_radius, err);
        } else if (ps_cli_is(&cli, "--spp")) {
            st = ps_cli_int(&cli, 1, 1000000, &o->spp, err);
        } else if (ps_cli_is(&cli, "--k")) {
            st = ps_cli_int(&cli, 1, 100000, &o->k, err);
        } else if (ps_cli_is(&cli, "--gather")) {
            st = ps_cli_int(&cli, 0, 100000, &o->gather, err);
        } else if (ps_cli_is(&cli, "--cache")) {
            st = ps_cli_int(&cli, 0, 4096, &o->cache, err);
        } else if (ps_cli_is(&cli, "--cache-rays")) {
            st = ps_cli_int(&cli, 1, 1000000, &o->cache_rays, err);
        } else if (ps_cli_is(&cli, "--light-samples")) {
            st = ps_cli_int(&cli, 1, 100000, &o->light_samples, err);
        } else if (ps_cli_is(&cli, "--component")) {
            st = ps_cli_choice(&cli, components, &o->component, err);
        } else if (ps_cli_is(&cli, "--quality")) {
            st = ps_cli_choice(&cli, qualities, &o->quality, err);
        } else if (ps_cli_is(&cli, "--filter")) {
            st = ps_cli_choice(&cli, filters, &o->filter, err);
        } else if (ps_cli_is(&cli, "--kernel")) {
            st = ps_cli_choice(&cli, ps_kernel_names, &o->kernel, err);
        } else if (ps_cli_is(&cli, "--illuminance")) {
            st = ps_cli_string(&cli, &o->out_lux, err);
        } else if (ps_cli_is(&cli, "--false-color")) {
            st = ps_cli_string(&cli, &o->out_false, err);
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
    ps_render_preset pre = ps_render_quality((ps_quality)o->quality);
    if (o->spp == REF_UNSET)
        o->spp = pre.spp;
    if (o->gather == REF_UNSET)
        o->gather = pre.gather;
    if (o->cache == REF_UNSET)
        o->cache = pre.cache_spacing;
    if (o->cache_rays == REF_UNSET)
        o->cache_rays = pre.cache_rays;
    if (!o->c.scene)
        return ps_error_set(err, PS_ERR_PARSE, "photosplat-ref: no scene given (see --help)");
    if (!o->photons_only && !o->c.out_png && !o->c.out_hdr && !o->out_lux && !o->out_false)
        return ps_error_set(err, PS_ERR_PARSE,
                            "photosplat-ref: nothing to write: give -o FILE.png, --hdr FILE.pfm, --illuminance "
                            "FILE.pfm, --false-color FILE.png or --photons-only");
    return PS_OK;
}

/* A progress line on stderr when it is a terminal: percent, elapsed, left. */
typedef struct progress {
    double start, last;
} progress;

static void show_progress(void *user, double fraction)
{
    progress *p = user;
    double t = ps_now_seconds();
    if (t - p->last < 0.25 && fraction < 1.0)
        return;
    p->last = t;
    double elapsed = t - p->start, left = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    fprintf(stderr, "\rrendering %3.0f%%  %5.1f s elapsed, ~%5.1f s left ", 100.0 * fraction, elapsed, left);
    if (fraction >= 1.0)
        fputc('\n', stderr);
    fflush(stderr);
}

typedef struct ref_run {
    ps_world *world;
    ps_tracer *tracer, *full_tracer;
    ps_photon_map maps[PS_MAP_COUNT], full;
    ps_kdtree *trees[PS_MAP_COUNT], *full_tree, *irradiance;
    ps_light_sampler *lights;
    ps_image image;
    ps_image lux_image; /* --illuminance, --false-color: the irradiance (W m^-2) */
} ref_run;

static void ref_run_free(ref_run *r)
{
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map_free(&r->maps[k]);
        ps_kdtree_destroy(r->trees[k]);
    }
    ps_photon_map_free(&r->full);
    ps_kdtree_destroy(r->full_tree);
    ps_kdtree_destroy(r->irradiance);
    ps_light_sampler_destroy(r->lights);
    ps_image_destroy(&r->image);
    ps_image_destroy(&r->lux_image);
    ps_tracer_destroy(r->full_tracer);
    ps_tracer_destroy(r->tracer);
    ps_world_destroy(r->world);
}

/* The irradiance image of --illuminance / --false-color: a second pass of
 * the same options with the first surfaces taken as white Lambertian
 * (render.h); its rays and time add to the first's. */
static ps_status render_illuminance(ref_run *r, const ps_render_maps *maps, ps_render_options *ro,
                                    ps_render_stats *stats, ps_error *err)
{
    ps_render_stats more;
    memset(&more, 0, sizeof more);
    ro->illuminance = true;
    ps_status st = ps_render(r->world, r->lights, maps, ro, &r->lux_image, &more, err);
    ro->illuminance = false;
    stats->rays += more.rays;
    stats->seconds += more.seconds;
    stats->fraction = more.fraction;
    return st;
}


/* Photons [0, total) of map kind into m: here, or split over the ranks. */
static ps_status trace_map(const ref_options *o, ps_tracer *t, ps_map_kind kind, uint64_t total, uint64_t max_stored,
                           ps_photon_map *m, ps_error *err)
{
    if (o->dist)
        return o->dist->trace(o->dist->user, t, kind, total, max_stored, m, err);
    return ps_tracer_trace(t, kind, 0, total, total, m, err);
}

/* What the image needs beyond the two maps: the kd-trees, and for final
 * gathering a global map with the direct hits and its precomputed irradiance. */
static ps_status render_image(const ref_options *o, const ps_scene *scene, ref_run *r, const ps_tracer_options *topt,
                              uint64_t global_photons, double radius[PS_MAP_COUNT], ps_run_stats *rs, ps_error *err)
{
    const ps_scene_defaults *def = ps_scene_get_defaults(scene);
    ps_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = o->c.width ? o->c.width : def->width;
    ro.height = o->c.height ? o->c.height : def->height;
    ro.spp = (int)o->spp;
    ro.light_samples = (int)o->light_samples;
    ro.cache_spacing = (int)o->cache;
    ro.cache_rays = (int)o->cache_rays;
    ro.gather = (int)o->gather;
    ro.seed = (uint64_t)o->c.seed;
    ro.threads = ps_tracer_threads(r->tracer);
    ro.component = (ps_component)o->component;
    ro.filter = (ps_filter)o->filter;
    ro.caustic.k = ro.global.k = (size_t)o->k;
    ro.caustic.kernel = ro.global.kernel = (ps_kernel)o->kernel;
    ro.caustic.max_radius = o->max_radius > 0.0 ? o->max_radius : radius[PS_MAP_CAUSTIC];
    ro.global.max_radius = o->max_radius > 0.0 ? o->max_radius : radius[PS_MAP_GLOBAL];
    ro.irradiance_radius = ro.global.max_radius;
    ro.cancel = o->cancel;
    ro.share = o->dist ? o->dist->share : NULL;

    double t0 = ps_now_seconds();
    ps_status st = ps_light_sampler_create(scene, &r->lights, err);
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++)
        st = ps_kdtree_build(r->maps[k].photons, r->maps[k].count, &r->trees[k], err);
    ps_render_maps maps = {r->maps[PS_MAP_CAUSTIC].count ? r->trees[PS_MAP_CAUSTIC] : NULL, r->trees[PS_MAP_GLOBAL],
                           NULL, NULL};
    bool need_indirect = ro.component == PS_COMPONENT_ALL || ro.component == PS_COMPONENT_INDIRECT ||
                         ro.component == PS_COMPONENT_SPECULAR;
    if (st == PS_OK && ro.gather > 0 && need_indirect && ps_tracer_map_enabled(r->tracer, PS_MAP_GLOBAL) &&
        global_photons > 0) {
        ps_tracer_options full = *topt;
        full.global_direct = true;
        ps_photon_map_init(&r->full, PS_MAP_GLOBAL);
        st = ps_tracer_create(r->world, &full, &r->full_tracer, err);
        if (st == PS_OK)
            st = trace_map(o, r->full_tracer, PS_MAP_GLOBAL, global_photons, full.max_stored, &r->full, err);
        if (st == PS_OK)
            st = ps_kdtree_build(r->full.photons, r->full.count, &r->full_tree, err);
        if (st == PS_OK)
            st = ps_irradiance_precompute(r->full_tree, &ro.global, REF_IRRADIANCE_STRIDE, ro.threads, o->cancel,
                                          &r->irradiance, err);
        maps.full = r->full_tree;
        maps.irradiance = r->irradiance;
        rs->rays += r->full.counters.rays;
    }
    double t_prep = ps_now_seconds() - t0;
    progress pr = {ps_now_seconds(), 0.0};
    if (isatty(STDERR_FILENO)) {
        ro.progress = show_progress;
        ro.progress_user = &pr;
    }
    ps_render_stats stats;
    memset(&stats, 0, sizeof stats);
    if (st == PS_OK && (o->c.out_png || o->c.out_hdr))
        st = ps_render(r->world, r->lights, &maps, &ro, &r->image, &stats, err);
    if (st == PS_OK && (o->out_lux || o->out_false))
        st = render_illuminance(r, &maps, &ro, &stats, err);
    rs->rays += stats.rays;
    rs->ray_seconds = rs->trace_seconds + t_prep + stats.seconds;
    ps_stats_add(rs, "maps_seconds", t_prep);
    ps_stats_add(rs, "render_seconds", stats.seconds);
    ps_stats_add(rs, "render_rays", (double)stats.rays);
    ps_stats_add(rs, "width", ro.width);
    ps_stats_add(rs, "height", ro.height);
    ps_stats_add(rs, "spp", ro.spp);
    ps_stats_add(rs, "k", (double)ro.caustic.k);
    ps_stats_add(rs, "gather", ro.gather);
    ps_stats_add(rs, "cache", ro.cache_spacing);
    ps_stats_add(rs, "cache_rays", ro.cache_rays);
    ps_stats_add(rs, "cache_records", (double)stats.cache_records);
    ps_stats_add(rs, "cache_seconds", stats.cache_seconds);
    ps_stats_add(rs, "caustic_radius", ro.caustic.max_radius);
    ps_stats_add(rs, "global_radius", ro.global.max_radius);
    return st;
}

/* Traces both maps, renders unless --photons-only, writes what was asked for. */
static ps_status run(const ref_options *o, const ps_scene *scene, ps_error *err)
{
    static const ps_accel_kind kinds[] = {PS_ACCEL_AUTO, PS_ACCEL_OCTREE, PS_ACCEL_BRUTE};
    ps_accel_options aopt = {0};
    aopt.kind = kinds[o->accel];
    ref_run r;
    memset(&r, 0, sizeof r);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_photon_map_init(&r.maps[k], (ps_map_kind)k);
    ps_photon_map_init(&r.full, PS_MAP_GLOBAL);

    double t_build = ps_now_seconds();
    ps_status st = ps_world_create(scene, &aopt, &r.world, err);
    t_build = ps_now_seconds() - t_build;
    ps_tracer_options topt = ps_tracer_default_options();
    topt.seed = (uint64_t)o->c.seed;
    topt.threads = (int)o->c.threads;
    topt.caustic_cones = o->cones;
    topt.first_hit_test = o->first_hit;
    topt.cancel = o->cancel;
    topt.max_stored = ps_photon_cap(REF_MAPS_AT_ONCE, PS_PHOTON_PLAN_BYTES);
    if (st == PS_OK)
        st = ps_tracer_create(r.world, &topt, &r.tracer, err);

    const ps_scene_defaults *def = ps_scene_get_defaults(scene);
    uint64_t want[PS_MAP_COUNT] = {ps_shared_photons(&o->c, def, PS_MAP_CAUSTIC), ps_shared_photons(&o->c, def, PS_MAP_GLOBAL)};
    double radius[PS_MAP_COUNT] = {ps_shared_radius(&o->c, def, PS_MAP_CAUSTIC), ps_shared_radius(&o->c, def, PS_MAP_GLOBAL)};
    double t_trace = ps_now_seconds();
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++) {
        if (!ps_tracer_map_enabled(r.tracer, (ps_map_kind)k))
            continue;
        if (want[k] == 0) {
            st = ps_tracer_note_skip(r.tracer, ps_map_name((ps_map_kind)k), "0 photons requested");
            if (st != PS_OK)
                ps_error_set(err, st, "photosplat-ref: out of memory");
            continue;
        }
        st = trace_map(o, r.tracer, (ps_map_kind)k, want[k], topt.max_stored, &r.maps[k], err);
    }
    t_trace = ps_now_seconds() - t_trace;

    ps_run_stats rs;
    memset(&rs, 0, sizeof rs);
    if (st == PS_OK) {
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            rs.emitted[k] = r.maps[k].counters.emitted;
            rs.stored[k] = r.maps[k].counters.stored;
            rs.rays += r.maps[k].counters.rays;
        }
        rs.trace_seconds = t_trace;
        rs.skips = ps_tracer_skips(r.tracer, &rs.skip_count);
        ps_accel_stats as;
        ps_accel_get_stats(ps_world_accel(r.world), &as);
        ps_stats_add(&rs, "threads", ps_tracer_threads(r.tracer));
        ps_stats_add(&rs, "luminous_flux_lm", ps_scene_total_lumens(scene));
        ps_stats_add(&rs, "seed", (double)o->c.seed);
        ps_stats_add(&rs, "accel_build_seconds", t_build);
        ps_stats_add(&rs, "accel_nodes", (double)as.nodes);
        ps_stats_add(&rs, "escaped", (double)(r.maps[0].counters.escaped + r.maps[1].counters.escaped));
        ps_stats_add(&rs, "absorbed", (double)(r.maps[0].counters.absorbed + r.maps[1].counters.absorbed));
        ps_stats_add(&rs, "discarded_caustic", (double)r.maps[PS_MAP_CAUSTIC].counters.discarded);
        ps_stats_add(&rs, "truncated", (double)(r.maps[0].counters.truncated + r.maps[1].counters.truncated));
    }
    if (st == PS_OK && !o->photons_only)
        st = render_image(o, scene, &r, &topt, want[PS_MAP_GLOBAL], radius, &rs, err);
    /* Every file at the end, after the last chance of an interruption: a
     * stopped run writes none of them. */
    if (st == PS_OK && ps_cancelled(o->cancel))
        st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after the whole image, before writing it");
    /* A distributed run: every rank has the whole result; rank 0 alone
     * writes it and reports, once every rank has succeeded. */
    if (o->dist) {
        st = o->dist->agree(o->dist->user, st, err);
        if (st == PS_OK)
            o->dist->add_stats(o->dist->user, &rs);
        if (!o->dist->root) {
            ref_run_free(&r);
            return st;
        }
    }
    if (st == PS_OK && !o->photons_only && o->c.out_hdr)
        st = ps_hdr_write(&r.image, o->c.out_hdr, err);
    if (st == PS_OK && !o->photons_only && (o->out_lux || o->out_false))
        st = ps_write_illuminance(o->out_lux, o->out_false, &r.lux_image, "photosplat-ref", err);
    if (st == PS_OK && !o->photons_only && o->c.out_png)
        st = ps_png_write(&r.image, o->c.out_png, (float)o->c.exposure, err);
    if (st == PS_OK && o->c.dump)
        st = ps_write_photon_dump(o->c.dump, r.maps, err);
    if (st == PS_OK && o->c.stats)
        st = ps_stats_write(o->c.stats, &rs, err);
    if (st == PS_OK) {
        printf("caustic: %llu emitted, %llu stored; global: %llu emitted, %llu stored; traced in %.3f s; %llu rays "
               "(%d threads)\n",
               (unsigned long long)rs.emitted[0], (unsigned long long)rs.stored[0], (unsigned long long)rs.emitted[1],
               (unsigned long long)rs.stored[1], t_trace, (unsigned long long)rs.rays, ps_tracer_threads(r.tracer));
        const char *const written[] = {o->c.out_png, o->c.out_hdr, o->out_lux, o->out_false};
        ps_print_run_end(rs.skips, rs.skip_count, written, sizeof written / sizeof written[0]);
    }
    ref_run_free(&r);
    return st;
}

static int ref_main(int argc, char **argv, const ps_ref_dist *dist)
{
    ps_error err;
    ps_error_clear(&err);
    ref_options o;
    bool help = false;
    if (parse_args(argc, argv, &o, &help, &err) != PS_OK)
        return ps_cli_fail(&err);
    o.dist = dist;
    if (help) {
        fputs(usage, stdout);
        return PS_EXIT_OK;
    }
    if (ps_check_outputs(&o.c, &err) != PS_OK || (o.out_lux && ps_check_output_path(o.out_lux, &err) != PS_OK) ||
        (o.out_false && ps_check_output_path(o.out_false, &err) != PS_OK))
        return ps_cli_fail(&err);
    o.cancel = ps_interrupt_install();
    ps_scene *scene;
    if (ps_scene_load(o.c.scene, NULL, &scene, &err) != PS_OK)
        return ps_cli_fail(&err);
    /* The preset's photon counts, where none were given. */
    const ps_scene_defaults *def = ps_scene_get_defaults(scene);
    double factor = ps_render_quality((ps_quality)o.quality).photon_factor;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (o.c.photons[k] < 0)
            o.c.photons[k] = (int64_t)llround(factor * (double)ps_shared_photons(&o.c, def, (ps_map_kind)k));
    /* Refuse what would not fit before tracing a photon. */
    uint64_t photons = ps_shared_photons(&o.c, def, PS_MAP_CAUSTIC) + ps_shared_photons(&o.c, def, PS_MAP_GLOBAL);
    if (o.gather > 0 && !o.photons_only)
        photons += ps_shared_photons(&o.c, def, PS_MAP_GLOBAL); /* the map with direct hits */
    int width = o.photons_only ? 0 : o.c.width ? o.c.width : def->width;
    int height = o.photons_only ? 0 : o.c.height ? o.c.height : def->height;
    ps_status st = ps_check_run_memory("photosplat-ref", photons, PS_PHOTON_PLAN_BYTES, width, height,
                                       REF_PIXEL_BYTES + (o.filter == PS_FILTER_BOX ? 0 : REF_FILTER_BYTES), &err);
    if (st == PS_OK)
        st = run(&o, scene, &err);
    ps_scene_destroy(scene);
    if (st == PS_ERR_INTERRUPTED)
        return ps_interrupt_fail("photosplat-ref", &err);
    return st == PS_OK ? PS_EXIT_OK : ps_cli_fail(&err);
}

/* The same program is photosplat-ref-mpi when built with PS_REF_DIST
 * (mk/mpi.mk): src/dist starts MPI and hands ref_main its hooks. */
int main(int argc, char **argv)
{
#ifdef PS_REF_DIST
    return ps_dist_main(argc, argv, ref_main);
#else
    return ref_main(argc, argv, NULL);
#endif
}
