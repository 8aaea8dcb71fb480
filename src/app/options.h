/* options.h: what photosplat-ref and photosplat-snap share: the contract's
 * common options ("Options shared by snap and ref"), the photon dump, a clock. */
#ifndef PS_APP_OPTIONS_H
#define PS_APP_OPTIONS_H

#include <stdbool.h>
#include <stdint.h>

#include "app/cli.h"
#include "core/clock.h"
#include "core/status.h"
#include "image/image.h"
#include "photon/path_record.h"
#include "photon/tracer.h"
#include "preview/session.h"

typedef struct ps_shared_options {
    const char *scene, *out_png, *out_hdr, *stats, *dump;
    int64_t photons[PS_MAP_COUNT]; /* -1: the scene's `photons` */
    double radius[PS_MAP_COUNT];   /* 0: the scene's `radius` */
    int width, height;             /* 0: the scene's `image` */
    double exposure;               /* 1 */
    int64_t seed, threads;         /* 0, 0 (all cores) */
} ps_shared_options;

void ps_shared_options_init(ps_shared_options *o);

/* When the current argument is one of the shared options or the scene,
 * consumes it (and its value) and returns true, with *st the outcome;
 * false leaves it to the program. `prog` names the program in messages. */
bool ps_shared_option(ps_cli *cli, const char *prog, ps_shared_options *o, ps_status *st, ps_error *err);

/* The photons each map emits and the radius each uses: the options', else
 * the scene's defaults. */
uint64_t ps_shared_photons(const ps_shared_options *o, const ps_scene_defaults *d, ps_map_kind k);
double ps_shared_radius(const ps_shared_options *o, const ps_scene_defaults *d, ps_map_kind k);

/* The preview's options, shared by photosplat-snap and the window (layers:
 * PS_LAYER_* of preview/session.h). */

typedef struct ps_preview_options {
    double tau;               /* seconds between refreshes (0.1) */
    double counter_threshold; /* the error counter's stopping fraction (0.1) */
    double point_size;        /* points: side in pixels (1) */
    ps_splat_mode splat;      /* triangles */
    ps_kernel kernel;         /* cone */
    ps_color_depth color_depth; /* 8 bits (snap) or float (the window) */
    ps_precision precision;   /* diffusion */
    bool shadows, stencil_clip; /* on/off (on) */
    unsigned layers;          /* PS_LAYER_* bits (all) */
    ps_radius_schedule radius_schedule; /* fixed */
    double radius_alpha;      /* progressive schedule's alpha (2/3) */
    ps_global_layer global_layer; /* splats (the thesis) or illumination maps */
    bool bake;                /* finished maps on diffuse quads laid into textures (preview/bake.h):
                               * on in the window, off in snap */
} ps_preview_options;

/* float_depth: whether the colour depth defaults to float (the window) or
 * 8 bits (photosplat-snap, as the thesis' preview). */
void ps_preview_options_init(ps_preview_options *o, bool float_depth);
/* Like ps_shared_option, for the preview's options. */
bool ps_preview_option(ps_cli *cli, const char *prog, ps_preview_options *o, ps_status *st, ps_error *err);
/* The session settings these options and the shared ones make for scene s
 * (its photon counts and radii unless the options give them): the memory
 * cap of each map planned as the preview's, exposure as given. The program
 * sets what only it knows (threads, incremental, shadow size, cancel). */
ps_session_settings ps_preview_settings(const ps_shared_options *c, const ps_preview_options *o, const ps_scene *s);
/* "direct,caustic,global,specular" (any non-empty subset) to PS_LAYER_* bits. */
ps_status ps_parse_layers(const char *text, const char *prog, unsigned *out, ps_error *err);

/* --illuminance (a one-channel PFM or EXR of lux) and --false-color (its
 * false-colour PNG with a legend) from an irradiance image (W m^-2 per
 * channel); either path may be NULL. */
ps_status ps_write_illuminance(const char *out_lux, const char *out_false, const ps_image *irradiance,
                               const char *prog, ps_error *err);

/* What a run tells on stdout at its end: each skipped stage ("skipped PASS:
 * REASON") and each file written ("wrote PATH", NULL paths left out). */
void ps_print_run_end(const ps_skip *skips, size_t skip_count, const char *const *paths, size_t path_count);

/* --dump-photons: every photon of both maps, written whole or not at all. */
ps_status ps_write_photon_dump(const char *path, const ps_photon_map maps[PS_MAP_COUNT], ps_error *err);

/* Every output file the options name can be made (ps_check_output_path):
 * checked before any work, so a typo does not cost a whole render. */
ps_status ps_check_outputs(const ps_shared_options *o, ps_error *err);

/* What one emitted photon is planned at when checking a run against the
 * memory budget: its map entry twice and its kd-tree node with the build's
 * index. Twice: while a traced range is joined, its chunks and the map exist
 * at once (each photon is copied once, chunk to map; a map traced in one
 * call is allocated to its exact size); a map that grows batch by batch (the
 * preview's feed) holds at most twice its entries in capacity, its chunks
 * then only one batch's. One stored photon per emitted one: the global map
 * may store more, which the tracer's cap (ps_photon_cap) catches as it grows. */
#define PS_PHOTON_PLAN_BYTES (2 * PS_PHOTON_MAP_BYTES + sizeof(ps_photon) + sizeof(uint32_t))

/* A photon of the preview (snap, window): its map entry, its splat
 * geometry (triangles: 3 vertices of position, colour and texture coordinate
 * floats, the largest splat mode) and its path record for the selective
 * repair after edits (photon/path_record.h). */
#define PS_PREVIEW_PHOTON_BYTES (PS_PHOTON_PLAN_BYTES + 3 * (3 + 4 + 2) * sizeof(float) + PS_PATH_PLAN_BYTES)
/* The preview holds both maps at once. */
#define PS_PREVIEW_MAPS 2

/* The most photons one map may hold when `maps` maps of `bytes_each` bytes a
 * photon share the memory budget (ps_tracer_options.max_stored). */
uint64_t ps_photon_cap(int maps, uint64_t bytes_each);

/* Refuses (PS_ERR_LIMIT, "PROG: N photons and a WxH image need ...") a run
 * whose photons at photon_bytes each and image at pixel_bytes a pixel would
 * not fit in the memory budget, before anything is allocated. */
ps_status ps_check_run_memory(const char *prog, uint64_t photons, uint64_t photon_bytes, int width, int height,
                              uint64_t pixel_bytes, ps_error *err);
/* The same with extra_bytes more held whatever the image (the specular
 * layer's cube maps, ps_specular_plan_bytes). */
ps_status ps_check_run_memory_extra(const char *prog, uint64_t photons, uint64_t photon_bytes, int width, int height,
                                    uint64_t pixel_bytes, uint64_t extra_bytes, ps_error *err);

#endif
