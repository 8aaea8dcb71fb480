/* options.c: the shared options, the photon dump, the clock. */
#include "app/options.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/memory.h"
#include "image/exr_io.h"
#include "image/falsecolor.h"

#include "core/fileio.h"
#include "photon/estimate.h"
#include "preview/splat.h"

void ps_shared_options_init(ps_shared_options *o)
{
    memset(o, 0, sizeof *o);
    o->photons[PS_MAP_CAUSTIC] = o->photons[PS_MAP_GLOBAL] = -1;
    o->exposure = 1.0;
}

bool ps_shared_option(ps_cli *cli, const char *prog, ps_shared_options *o, ps_status *st, ps_error *err)
{
    /* Radii are lengths in scene units, which may be anything from 1e-300 up. */
    const double min_len = 1e-300, max_len = 1e300;
    if (ps_cli_positional(cli)) {
        if (o->scene)
            *st = ps_error_set(err, PS_ERR_PARSE, "%s: more than one scene given ('%s')", prog, ps_cli_arg(cli));
        else
            o->scene = ps_cli_arg(cli), *st = PS_OK;
    } else if (ps_cli_is(cli, "-o")) {
        *st = ps_cli_string(cli, &o->out_png, err);
    } else if (ps_cli_is(cli, "--hdr")) {
        *st = ps_cli_string(cli, &o->out_hdr, err);
    } else if (ps_cli_is(cli, "--stats")) {
        *st = ps_cli_string(cli, &o->stats, err);
    } else if (ps_cli_is(cli, "--dump-photons")) {
        *st = ps_cli_string(cli, &o->dump, err);
    } else if (ps_cli_is(cli, "--size")) {
        *st = ps_cli_size(cli, PS_SCENE_MAX_IMAGE_SIDE, &o->width, &o->height, err);
    } else if (ps_cli_is(cli, "--exposure")) {
        *st = ps_cli_double(cli, 0.0, 1e30, &o->exposure, err);
    } else if (ps_cli_is(cli, "--caustic-photons")) {
        *st = ps_cli_int(cli, 0, PS_SCENE_MAX_PHOTONS, &o->photons[PS_MAP_CAUSTIC], err);
    } else if (ps_cli_is(cli, "--global-photons")) {
        *st = ps_cli_int(cli, 0, PS_SCENE_MAX_PHOTONS, &o->photons[PS_MAP_GLOBAL], err);
    } else if (ps_cli_is(cli, "--caustic-radius")) {
        *st = ps_cli_double(cli, min_len, max_len, &o->radius[PS_MAP_CAUSTIC], err);
    } else if (ps_cli_is(cli, "--global-radius")) {
        *st = ps_cli_double(cli, min_len, max_len, &o->radius[PS_MAP_GLOBAL], err);
    } else if (ps_cli_is(cli, "--seed")) {
        *st = ps_cli_int(cli, 0, INT64_MAX, &o->seed, err);
    } else if (ps_cli_is(cli, "--threads")) {
        *st = ps_cli_int(cli, 1, PS_TRACER_MAX_THREADS, &o->threads, err);
    } else {
        return false;
    }
    return true;
}

uint64_t ps_shared_photons(const ps_shared_options *o, const ps_scene_defaults *d, ps_map_kind k)
{
    if (o->photons[k] >= 0)
        return (uint64_t)o->photons[k];
    return (uint64_t)(k == PS_MAP_CAUSTIC ? d->caustic_photons : d->global_photons);
}

double ps_shared_radius(const ps_shared_options *o, const ps_scene_defaults *d, ps_map_kind k)
{
    if (o->radius[k] > 0.0)
        return o->radius[k];
    return k == PS_MAP_CAUSTIC ? d->caustic_radius : d->global_radius;
}

ps_status ps_write_photon_dump(const char *path, const ps_photon_map maps[PS_MAP_COUNT], ps_error *err)
{
    ps_outfile *out = ps_outfile_open(path, err);
    if (!out)
        return err->status;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_photon_map_write_text(ps_outfile_stream(out), &maps[k]);
    return ps_outfile_commit(out, err);
}

ps_status ps_write_illuminance(const char *out_lux, const char *out_false, const ps_image *irr, const char *prog,
                               ps_error *err)
{
    size_t n = (size_t)irr->width * (size_t)irr->height;
    float *lux = malloc(n * sizeof *lux);
    if (!lux)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the illuminance image", prog);
    ps_lux_from_irradiance(irr, lux);
    ps_status st = PS_OK;
    if (out_lux)
        st = ps_gray_write(lux, irr->width, irr->height, out_lux, err);
    if (st == PS_OK && out_false)
        st = ps_falsecolor_write(lux, irr->width, irr->height, out_false, err);
    free(lux);
    return st;
}

void ps_print_run_end(const ps_skip *skips, size_t skip_count, const char *const *paths, size_t path_count)
{
    for (size_t k = 0; k < skip_count; k++)
        printf("skipped %s: %s\n", skips[k].pass, skips[k].reason);
    for (size_t k = 0; k < path_count; k++)
        if (paths[k])
            printf("wrote %s\n", paths[k]);
}

ps_status ps_check_outputs(const ps_shared_options *o, ps_error *err)
{
    const char *paths[] = {o->out_png, o->out_hdr, o->stats, o->dump};
    for (size_t k = 0; k < sizeof paths / sizeof paths[0]; k++)
        if (paths[k] && ps_check_output_path(paths[k], err) != PS_OK)
            return err->status;
    return PS_OK;
}

uint64_t ps_photon_cap(int maps, uint64_t bytes_each)
{
    uint64_t per = ps_memory_mul((uint64_t)(maps > 0 ? maps : 1), bytes_each ? bytes_each : 1);
    uint64_t cap = ps_memory_budget() / per;
    return cap ? cap : 1;
}

ps_status ps_check_run_memory(const char *prog, uint64_t photons, uint64_t photon_bytes, int width, int height,
                              uint64_t pixel_bytes, ps_error *err)
{
    return ps_check_run_memory_extra(prog, photons, photon_bytes, width, height, pixel_bytes, 0, err);
}

ps_status ps_check_run_memory_extra(const char *prog, uint64_t photons, uint64_t photon_bytes, int width, int height,
                                    uint64_t pixel_bytes, uint64_t extra_bytes, ps_error *err)
{
    uint64_t pixels = (uint64_t)(width > 0 ? width : 0) * (uint64_t)(height > 0 ? height : 0);
    uint64_t a = ps_memory_mul(photons, photon_bytes), b = ps_memory_mul(pixels, pixel_bytes);
    uint64_t total = a > UINT64_MAX - b ? UINT64_MAX : a + b;
    total = total > UINT64_MAX - extra_bytes ? UINT64_MAX : total + extra_bytes;
    char what[128];
    if (pixels)
        snprintf(what, sizeof what, "%llu photons and a %dx%d image", (unsigned long long)photons, width, height);
    else
        snprintf(what, sizeof what, "%llu photons", (unsigned long long)photons);
    return ps_memory_check(total, prog, what, err);
}

void ps_preview_options_init(ps_preview_options *o, bool float_depth)
{
    memset(o, 0, sizeof *o);
    o->tau = 0.1;
    o->counter_threshold = 0.1;
    o->point_size = 1.0;
    o->splat = PS_SPLAT_TRIANGLES;
    o->kernel = PS_KERNEL_CONE;
    o->color_depth = float_depth ? PS_COLOR_DEPTH_FLOAT : PS_COLOR_DEPTH_8;
    o->precision = PS_PRECISION_DIFFUSION;
    o->shadows = o->stencil_clip = true;
    o->layers = PS_LAYER_ALL;
    o->radius_schedule = PS_RADIUS_FIXED;
    o->radius_alpha = PS_RADIUS_ALPHA_DEFAULT;
    o->bake = float_depth;
}

ps_session_settings ps_preview_settings(const ps_shared_options *c, const ps_preview_options *o, const ps_scene *s)
{
    const ps_scene_defaults *d = ps_scene_get_defaults(s);
    ps_session_settings set = ps_session_default_settings(s);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        set.caps[k] = ps_shared_photons(c, d, (ps_map_kind)k);
        set.radius[k] = ps_shared_radius(c, d, (ps_map_kind)k);
    }
    set.seed = (uint64_t)c->seed;
    set.threads = (int)c->threads;
    set.first_round_threads = (int)c->threads; /* the programs may leave a core to drawing after it */
    set.max_map_photons = ps_photon_cap(PS_PREVIEW_MAPS, PS_PREVIEW_PHOTON_BYTES);
    set.layers = o->layers;
    set.splat = o->splat;
    set.kernel = o->kernel;
    set.point_size = o->point_size;
    set.float_buffer = o->color_depth == PS_COLOR_DEPTH_FLOAT;
    set.precision = o->precision;
    set.counter_threshold = o->counter_threshold;
    set.stencil_clip = o->stencil_clip;
    set.radius_schedule = o->radius_schedule;
    set.radius_alpha = o->radius_alpha;
    set.global_layer = o->global_layer;
    set.bake = o->bake;
    set.exposure = c->exposure;
    set.tau = o->tau;
    set.shadow_size = o->shadows ? PS_SHADOW_SIZE_DEFAULT : 0;
    /* Both programs draw the specular layer with src/gl's, which keeps it
     * from there: their first pictures, before any cube map is shown (all
     * black), trace no eye paths for it. */
    set.specular_wait = true;
    return set;
}

ps_status ps_parse_layers(const char *text, const char *prog, unsigned *out, ps_error *err)
{
    char why[PS_ERROR_MSG_MAX];
    if (!ps_layers_parse(text, out, why, sizeof why))
        return ps_error_set(err, PS_ERR_PARSE, "%s: --layers: %s", prog, why);
    return PS_OK;
}

/* ps_cli_choice into a typed field: the index is read as an int and stored
 * as the field's own type (an enum's size is the compiler's choice, so the
 * field is never written through an int pointer). */
#define TYPED_CHOICE(fn, type)                                                                            \
    static ps_status fn(ps_cli *cli, const char *const *names, type *out, ps_error *err)               \
    {                                                                                                     \
        int k;                                                                                            \
        ps_status st = ps_cli_choice(cli, names, &k, err);                                                \
        if (st == PS_OK)                                                                                  \
            *out = (type)k;                                                                               \
        return st;                                                                                        \
    }
TYPED_CHOICE(choose_splat, ps_splat_mode)
TYPED_CHOICE(choose_kernel, ps_kernel)
TYPED_CHOICE(choose_depth, ps_color_depth)
TYPED_CHOICE(choose_precision, ps_precision)
TYPED_CHOICE(choose_schedule, ps_radius_schedule)
TYPED_CHOICE(choose_bool, bool)
TYPED_CHOICE(choose_global, ps_global_layer)
#undef TYPED_CHOICE

bool ps_preview_option(ps_cli *cli, const char *prog, ps_preview_options *o, ps_status *st, ps_error *err)
{
    static const char *const on_off[] = {"off", "on", NULL}; /* so that on = true */
    /* Times: from a millisecond (a refresh faster than GL can draw is no use) up. */
    const double min_time = 1e-3, max_time = 1e6;
    const char *text;
    if (ps_cli_is(cli, "--tau"))
        *st = ps_cli_double(cli, min_time, max_time, &o->tau, err);
    else if (ps_cli_is(cli, "--splat"))
        *st = choose_splat(cli, ps_splat_mode_names, &o->splat, err);
    else if (ps_cli_is(cli, "--kernel"))
        *st = choose_kernel(cli, ps_kernel_names, &o->kernel, err);
    else if (ps_cli_is(cli, "--color-depth"))
        *st = choose_depth(cli, ps_color_depth_names, &o->color_depth, err);
    else if (ps_cli_is(cli, "--precision"))
        *st = choose_precision(cli, ps_precision_names, &o->precision, err);
    else if (ps_cli_is(cli, "--counter-threshold"))
        *st = ps_cli_double(cli, 1e-9, 1.0, &o->counter_threshold, err);
    else if (ps_cli_is(cli, "--point-size"))
        *st = ps_cli_double(cli, 1.0, 64.0, &o->point_size, err);
    else if (ps_cli_is(cli, "--shadows"))
        *st = choose_bool(cli, on_off, &o->shadows, err);
    else if (ps_cli_is(cli, "--stencil-clip"))
        *st = choose_bool(cli, on_off, &o->stencil_clip, err);
    else if (ps_cli_is(cli, "--radius-schedule"))
        *st = choose_schedule(cli, ps_radius_schedule_names, &o->radius_schedule, err);
    else if (ps_cli_is(cli, "--global-layer"))
        *st = choose_global(cli, ps_global_layer_names, &o->global_layer, err);
    else if (ps_cli_is(cli, "--bake"))
        *st = choose_bool(cli, on_off, &o->bake, err);
    else if (ps_cli_is(cli, "--radius-alpha"))
        *st = ps_cli_double(cli, 0.01, 1.0, &o->radius_alpha, err);
    else if (ps_cli_is(cli, "--layers")) {
        *st = ps_cli_string(cli, &text, err);
        if (*st == PS_OK)
            *st = ps_parse_layers(text, prog, &o->layers, err);
    } else
        return false;
    return true;
}
