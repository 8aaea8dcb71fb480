/* session.c: the preview's progressive policy (session.h). */
#include "preview/session.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/jobs.h"
#include "preview/feed.h"
#include "preview/repair.h"
#include "preview/specular.h"
#include "preview/specular_glossy.h"

struct ps_session {
    ps_scene *scene;
    ps_session_settings set;
    ps_world *world;
    ps_tracer *tracer;
    ps_feed *feed;
    ps_preview_mesh mesh, coarse;
    /* The lit mesh while the camera moves (ps_mesh_moving_options): built
     * for incremental sessions, the only ones with a level of detail, where
     * it is lighter than the fine one; else empty and the fine one serves. */
    ps_preview_mesh moving_mesh;
    ps_specular *spec;     /* the specular layer's lookups over mesh */
    ps_preview_lights lights;
    ps_kernel_texture kernel;
    ps_splat_batch batch[PS_MAP_COUNT];
    bool illuminance;      /* white Lambertian, exposure 1, float (ps_session_set_illuminance) */
    int area_side;         /* an area light's virtual lights a side, refined up to PS_PREVIEW_AREA_SIDE */
    bool coarse_shadows;   /* the lights' shadow maps at the first picture's side (session.h) */
    int built_side;        /* the area_side the lights were last built at */
    bool built_coarse;     /* ... and whether a level was to come then (ps_session_lights_coarse) */
    bool lights_pending;   /* a level refined: lights to rebuild at the next refresh */
    bool lights_held;      /* the levels grow only by ps_session_refine_lights */
    ps_material *white;    /* as many as the scene's, for illuminance mode */
    /* Invariant: drawn[k] photons of map k (a prefix ending at a feed mark,
     * drawn_emitted[k] emitted) are in the layers since the last new view. */
    size_t drawn[PS_MAP_COUNT];
    uint64_t drawn_emitted[PS_MAP_COUNT];
    double splat_radius[PS_MAP_COUNT];
    double budget;         /* incremental: photons a map per refresh */
    double budget_share;   /* incremental: of the budget, what a refresh draws (ps_session_set_budget_share) */
    double whole_most[PS_MAP_COUNT]; /* whole: each map's photons emitted a refresh draws at most
                                      * (ps_session_set_whole_most; HUGE_VAL: all) */
    size_t last_splats[PS_MAP_COUNT]; /* each map's built by the last refresh ... */
    double last_build;     /* ... in this many seconds */
    bool budget_maps[PS_MAP_COUNT]; /* incremental: the maps the budget is for after it (splats
                                     * shown, photons still to come or to bake) */
    ps_splat_cost splat_cost; /* incremental: what a splat of each map costs (splat.h) */
    bool last_lit;         /* ... with new lights built */
    double round_off;
    bool have_cam, view_dirty;
    bool moving;           /* the last refresh had a new camera: a level of detail */
    bool edit_view;        /* the next refresh is an update's first (PS_SESSION_EDIT_SPLATS_WHOLE) */
    uint64_t edit_held;    /* ... and the maps held this many photons before it (a repair
                            * left to the thread has not copied them all yet) */
    bool dragging;         /* ps_session_set_dragging */
    bool catch_up;         /* still after a move, the view not yet drawn in full */
    int still_refreshes;   /* ... and the refreshes drawn since the camera stopped */
    ps_camera_frame cam;
    /* ps_session_set_specular_wait: while it holds, a refresh leaves the
     * specular layer's eye paths owed, for the view and moving state kept
     * here, until ps_session_trace_specular. */
    bool specular_wait, specular_owed, owed_moving;
    ps_camera_frame owed_view;
    bool edited, geometry_edited;
    uint64_t edits;
    /* Tracing: the feed is held while any of these holds. */
    bool started, user_paused, hold, first_pending, counter_stopped;
    uint64_t counter_at;
    double splat_seconds;
    double ahead_seconds; /* the first refresh's work done beside the first round (prime_main) */
    uint64_t refreshes;
    /* --global-layer maps (illummap.h): the maps hold photons [0, count) of
     * the global map, imap_emitted emitted, whatever the view; lobe_drawn of
     * their glossy photons are in the global layer since the last new view. */
    ps_illummap *imap;
    double imap_budget;    /* incremental: photons the maps take in a refresh, from their own
                            * rate (their redraw is a fixed cost, not the photons') */
    uint64_t imap_emitted;
    double imap_scale;
    const float *imap_view;      /* the view's colours, as last made */           /* what the maps' colours were last made with ... */
    const ps_material *imap_mats;/* ... (colours are remade only when these or the maps change) */
    size_t lobe_drawn;
    ps_material *lobe_mats;
    ps_material *nolobe_mats; /* the splats' while the specular layer draws the lobes (specular_glossy.h) */
    /* Selective repair (repair.h): the scene the maps were traced for, the
     * box path records are quantised in, what the last edit kept. */
    ps_repair_state traced;
    ps_aabb record_box;
    bool repaired;         /* the last update repaired the maps (else restarted them) */
    uint64_t repairs_before; /* repairs before the feed's own, and what they kept and retraced */
    uint64_t kept_before[PS_MAP_COUNT], retraced_before[PS_MAP_COUNT];
    bool skip_prime;       /* ... and every map kept photons: no first round to prime */
    uint64_t feed_gen;     /* the feed's generation the drawn prefixes belong to */
    uint64_t maps_epoch;   /* ps_session_maps_epoch */
    /* settings.bake (bake.h): each map's plan, and how far it is laid. */
    ps_bake *bake[PS_MAP_COUNT];
    struct session_bake {
        int state;             /* BAKE_* */
        size_t total;          /* photons of the map when planned */
        size_t laid;           /* photons in the textures (a prefix ending at a feed mark) ... */
        uint64_t laid_emitted; /* ... this many emitted */
        /* What the textures were laid from: another of any drops them. */
        uint64_t epoch;        /* maps_epoch */
        const ps_material *mats;
        double radius, kernel_mean;
    } baked[PS_MAP_COUNT];
};

/* A map's bake: not planned yet; refused (not all on diffuse quads, or too
 * many texels); being laid; laid, the layer drawn from it. */
enum { BAKE_NONE, BAKE_REFUSED, BAKE_LAYING, BAKE_DONE };

int ps_session_tracing_threads(int64_t requested, bool draws_while_tracing)
{
    if (requested > 0)
        return (int)requested;
    int cores = ps_online_cores();
    return draws_while_tracing && cores > 1 ? cores - 1 : 0;
}

ps_session_settings ps_session_default_settings(const ps_scene *scene)
{
    const ps_scene_defaults *d = ps_scene_get_defaults(scene);
    ps_session_settings set;
    memset(&set, 0, sizeof set);
    set.caps[PS_MAP_CAUSTIC] = d->caustic_photons > 0 ? (uint64_t)d->caustic_photons : 0;
    set.caps[PS_MAP_GLOBAL] = d->global_photons > 0 ? (uint64_t)d->global_photons : 0;
    set.radius[PS_MAP_CAUSTIC] = d->caustic_radius;
    set.radius[PS_MAP_GLOBAL] = d->global_radius;
    set.layers = PS_LAYER_ALL;
    set.splat = PS_SPLAT_TRIANGLES;
    set.kernel = PS_KERNEL_CONE;
    set.point_size = 1.0;
    set.precision = PS_PRECISION_DIFFUSION;
    set.counter_threshold = 0.1;
    set.stencil_clip = true;
    set.radius_schedule = PS_RADIUS_FIXED;
    set.radius_alpha = PS_RADIUS_ALPHA_DEFAULT;
    set.exposure = 1.0;
    set.tau = 0.1;
    set.splat_share = PS_SESSION_SPLAT_TIME_SHARE;
    set.shadow_size = PS_SHADOW_SIZE_DEFAULT;
    set.repair = true;
    set.retrace_first = PS_SESSION_RETRACE_FIRST;
    set.pixel_rays_whole = PS_SESSION_PIXEL_RAYS_WHOLE;
    set.edit_splats_whole = PS_SESSION_EDIT_SPLATS_WHOLE;
    return set;
}

static bool incremental(const ps_session *s) { return s->set.incremental && s->set.float_buffer; }
/* What the splats are drawn in: floats, or an 8-bit buffer's codes. */
static bool float_splats(const ps_session *s) { return s->set.float_buffer || s->illuminance; }
/* The exposure splats and lights are drawn with: illuminance is radiometric. */
static double exposure(const ps_session *s) { return s->illuminance ? 1.0 : s->set.exposure; }

void ps_session_direct_view(const ps_session *s, double *exposure_out, bool *direct)
{
    /* Incremental layers are float: the gain is the composite's (direct_gain). */
    *exposure_out = incremental(s) ? 1.0 : exposure(s);
    *direct = (s->set.layers & PS_LAYER_DIRECT) != 0;
}

/* The feed runs only while nothing holds it. */
static void apply_pause(ps_session *s)
{
    if (s->feed)
        ps_feed_pause(s->feed, s->user_paused || s->hold || s->first_pending || s->counter_stopped || s->edited);
}

/* ---- building ----------------------------------------------------------------- */

static ps_status build_geometry(ps_session *s, ps_error *err)
{
    ps_world_destroy(s->world);
    s->world = NULL;
    int old_cubes = s->spec ? ps_specular_cube_count(s->spec) : 0;
    ps_vec3 looked[PS_SPECULAR_MAX_CUBES];
    for (int c = 0; c < old_cubes; c++)
        looked[c] = ps_specular_lookup_centre(s->spec, c);
    ps_specular_destroy(s->spec);
    s->spec = NULL;
    ps_preview_mesh_free(&s->mesh);
    ps_preview_mesh_free(&s->coarse);
    ps_preview_mesh_free(&s->moving_mesh);
    ps_status st = ps_world_create(s->scene, NULL, &s->world, err);
    ps_mesh_options mo = ps_mesh_default_options(s->scene);
    if (st == PS_OK)
        st = ps_preview_mesh_build(s->scene, &mo, &s->mesh, err);
    /* Its tiles, for the shadowed lit passes (mesh.h): without them (out of
     * memory) those passes draw whole ranges, the same pixels. */
    ps_error tile_err;
    if (st == PS_OK && ps_mesh_make_tiles(&s->mesh, PS_MESH_TILE_TRIANGLES, &s->mesh.tiles, &tile_err) != PS_OK)
        ps_mesh_tiling_free(&s->mesh.tiles);
    size_t nm;
    if (st == PS_OK)
        st = ps_specular_create(&s->mesh, ps_scene_materials(s->scene, &nm), &s->spec, err);
    /* Lookups and per-pixel paths on every core: the refresh waits for
     * them (the window's tracing thread, one core of two, is idle once the
     * maps are full, when the camera moves over them). */
    if (st == PS_OK)
        ps_specular_set_threads(s->spec, ps_online_cores());
    /* The drawing side still shows the maps it had (ps_session_set_specular_centre). */
    if (st == PS_OK && ps_specular_cube_count(s->spec) == old_cubes)
        for (int c = 0; c < old_cubes; c++)
            ps_specular_set_lookup_centre(s->spec, c, looked[c]);
    /* Where it saves a quarter of the vertices or more (a scene of small
     * triangles, cut no further, would only hold a second copy); for
     * progressive lights too, whose coarse levels draw it
     * (ps_session_lights_coarse). */
    ps_mesh_options moving = ps_mesh_moving_options(&mo);
    if (st == PS_OK && (incremental(s) || s->set.progressive_lights) &&
        4 * ps_preview_mesh_vertex_count(s->scene, &moving) <= 3 * (uint64_t)s->mesh.vertex_count)
        st = ps_preview_mesh_build(s->scene, &moving, &s->moving_mesh, err);
    /* The scene's own triangles, not subdivided, for depth-only passes:
     * subdividing changes no depth, only how many vertices are lit. */
    mo.max_edge = HUGE_VAL;
    if (st == PS_OK)
        st = ps_preview_mesh_build(s->scene, &mo, &s->coarse, err);
    return st;
}

/* A progressive start's first shadow side (session.h): size itself where
 * it is no larger than the least. */
static int coarse_shadow_size(int size)
{
    int coarse = size / PS_SESSION_COARSE_SHADOW_DIVISOR;
    if (coarse >= PS_SESSION_COARSE_SHADOW_MIN)
        return coarse;
    return size < PS_SESSION_COARSE_SHADOW_MIN ? size : PS_SESSION_COARSE_SHADOW_MIN;
}

static ps_status build_lights(ps_session *s, ps_error *err)
{
    ps_preview_lights_free(&s->lights);
    int size = s->set.shadow_size;
    if (s->coarse_shadows)
        size = coarse_shadow_size(size);
    s->built_side = s->area_side;
    s->built_coarse = ps_session_lights_to_come(s) > 1.0;
    return ps_preview_lights_build(s->scene, ps_world_accel(s->world), &s->coarse, size, s->area_side, &s->lights,
                                   err);
}

static void free_maps(ps_session *s)
{
    ps_feed_destroy(s->feed);
    s->feed = NULL;
    ps_tracer_destroy(s->tracer);
    s->tracer = NULL;
}

/* The kernel texture: smooth for float buffers, a halftone for 8 bits, where
 * a smooth kernel's fragments round away (splat.h). */
static ps_status make_kernel(bool float_splats, ps_kernel k, ps_kernel_texture *out, ps_error *err)
{
    if (float_splats)
        return ps_kernel_texture_make(k, PS_KERNEL_TEXTURE_SIZE, out, err);
    return ps_kernel_texture_make_halftone(k, PS_KERNEL_HALFTONE_SIZE, out, err);
}

static ps_status new_tracer(ps_session *s, ps_error *err)
{
    ps_tracer_options to = ps_tracer_default_options();
    to.seed = s->set.seed;
    to.threads = s->set.threads;
    to.cancel = s->set.cancel;
    to.max_stored = s->set.max_map_photons;
    to.records = s->set.repair;
    to.record_box = s->record_box;
    return ps_tracer_create(s->world, &to, &s->tracer, err);
}

/* A new feed from photon 0. Which maps it traces: a disabled one (the scene
 * needs none) never; one of 0 photons, or not shown when the session skips
 * hidden layers, is recorded as skipped with its reason. */
/* The illumination maps start over (they sum photons in the map's order). */
static void forget_imap(ps_session *s)
{
    if (s->imap)
        ps_illummap_reset(s->imap, s->set.kernel);
    s->imap_emitted = 0;
    s->lobe_drawn = 0;
}

/* The feed's maps are other photons now (a new feed, a repaired one): nothing
 * drawn from them stands, the illumination maps included. */
static void forget_drawn(ps_session *s)
{
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        s->drawn[k] = 0;
        s->drawn_emitted[k] = 0;
    }
    forget_imap(s);
    s->counter_stopped = false;
    s->view_dirty = true;
    s->feed_gen = 0;
    s->maps_epoch++;
}

static ps_status new_feed(ps_session *s, ps_error *err)
{
    bool active[PS_MAP_COUNT] = {false, false};
    ps_status st = PS_OK;
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++) {
        if (!ps_tracer_map_enabled(s->tracer, (ps_map_kind)k))
            continue;
        const char *name = ps_map_name((ps_map_kind)k);
        if (s->set.skip_hidden && !(s->set.layers & ps_map_layer((ps_map_kind)k)))
            st = ps_tracer_note_skip(s->tracer, name, "layer not shown (--layers)");
        else if (s->set.caps[k] == 0)
            st = ps_tracer_note_skip(s->tracer, name, "0 photons requested");
        else
            active[k] = true;
    }
    if (st == PS_OK && s->set.skip_hidden && !(s->set.layers & PS_LAYER_DIRECT))
        st = ps_tracer_note_skip(s->tracer, "direct", "layer not shown (--layers)");
    if (st != PS_OK)
        return ps_error_set(err, st, "%s: out of memory", ps_scene_path(s->scene));
    st = ps_feed_create(s->tracer, s->set.caps, active, &s->feed, err);
    if (st == PS_OK)
        ps_feed_set_store_limit(s->feed, s->set.max_stored);
    forget_drawn(s);
    return st;
}

/* The illumination maps of the fine mesh, and the lobe splats' materials. */
static ps_status imap_make(ps_session *s, ps_error *err)
{
    size_t n;
    ps_scene_materials(s->scene, &n);
    ps_illummap_destroy(s->imap);
    s->imap = NULL;
    free(s->lobe_mats);
    s->lobe_mats = calloc(n ? n : 1, sizeof *s->lobe_mats);
    if (!s->lobe_mats)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for %zu materials", ps_scene_path(s->scene), n);
    s->imap_emitted = 0;
    s->lobe_drawn = 0;
    s->imap_budget = PS_SESSION_BUDGET_START;
    s->imap_scale = -1.0; /* colours to make */
    s->imap_view = NULL;
    ps_status st = ps_illummap_create(s->scene, &s->mesh, s->set.kernel, &s->imap, err);
    if (st == PS_OK)
        st = ps_illummap_set_threads(s->imap, s->set.threads, err);
    return st;
}

ps_status ps_session_create(ps_scene *scene, const ps_session_settings *set, ps_session **out, ps_error *err)
{
    *out = NULL;
    ps_session *s = calloc(1, sizeof *s);
    if (!s)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the preview", ps_scene_path(scene));
    s->scene = scene;
    s->set = *set;
    s->specular_wait = set->specular_wait;
    s->budget = PS_SESSION_BUDGET_START;
    s->budget_share = 1.0;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        s->whole_most[k] = HUGE_VAL;
    s->area_side = set->progressive_lights ? 1 : PS_PREVIEW_AREA_SIDE;
    s->coarse_shadows = set->progressive_lights && set->shadow_size > 0 &&
                        coarse_shadow_size(set->shadow_size) < set->shadow_size;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_splat_batch_init(&s->batch[k]);
        /* Whole refreshes' batches grow with the maps; incremental ones hold
         * a budget's splats and are reused (splat.h). */
        s->batch[k].large_pages = !(set->incremental && set->float_buffer);
        s->splat_radius[k] = set->radius[k];
    }
    s->record_box = ps_repair_record_box(scene);
    ps_status st = build_geometry(s, err);
    if (st == PS_OK)
        st = ps_repair_state_take(scene, ps_world_epsilon(s->world), &s->traced, err);
    if (st == PS_OK)
        st = new_tracer(s, err);
    if (st == PS_OK)
        st = make_kernel(set->float_buffer, set->kernel, &s->kernel, err);
    if (st == PS_OK)
        st = build_lights(s, err);
    if (st == PS_OK)
        st = new_feed(s, err);
    if (st == PS_OK && set->global_layer == PS_GLOBAL_MAPS)
        st = imap_make(s, err);
    if (st != PS_OK) {
        ps_session_destroy(s);
        return st;
    }
    *out = s;
    return PS_OK;
}

void ps_session_destroy(ps_session *s)
{
    if (!s)
        return;
    free_maps(s);
    ps_world_destroy(s->world);
    ps_specular_destroy(s->spec);
    ps_preview_mesh_free(&s->mesh);
    ps_preview_mesh_free(&s->coarse);
    ps_preview_mesh_free(&s->moving_mesh);
    ps_preview_lights_free(&s->lights);
    ps_kernel_texture_free(&s->kernel);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_splat_batch_free(&s->batch[k]);
        ps_bake_destroy(s->bake[k]);
    }
    free(s->white);
    ps_illummap_destroy(s->imap);
    free(s->lobe_mats);
    free(s->nolobe_mats);
    ps_repair_state_free(&s->traced);
    free(s);
}

/* ---- tracing ------------------------------------------------------------------- */

ps_status ps_session_trace_all(ps_session *s, ps_error *err) { return ps_feed_run(s->feed, err); }

static ps_status imap_gather(ps_session *s, const ps_photon_map *m, size_t *end, ps_error *err);

/* The first round on its own thread, beside the caller's work. */
typedef struct prime_job {
    ps_session *s;
    ps_status st;
    ps_error err;
    atomic_bool done; /* the round and the maps' gathering (spare work is done only before) */
} prime_job;

static void *prime_main(void *arg)
{
    prime_job *j = arg;
    ps_session *s = j->s;
    /* The tracer's threads it starts inherit this: they take little of
     * the cores the caller's work wants, and the rest. */
    ps_thread_low_priority();
    ps_error_clear(&j->err);
    j->st = ps_feed_prime(s->feed, &j->err);
    /* The illumination maps gather the round's photons here too: they do
     * not depend on the view, and the first refresh goes on from them
     * (imap_refresh). The round ended before the caller's view: the default
     * box's took 0.013-0.024 s beside a view of 0.027-0.034 s, and its
     * maps' first gathering 0.004-0.010 s after it, in the first refresh. */
    if (j->st == PS_OK && s->imap && (s->set.layers & PS_LAYER_GLOBAL)) {
        size_t end;
        double t0 = ps_now_seconds();
        ps_feed_lock(s->feed);
        j->st = imap_gather(s, &ps_feed_maps(s->feed)[PS_MAP_GLOBAL], &end, &j->err);
        /* Under the lock: ps_session_get_counts may read them beside. */
        s->ahead_seconds = ps_now_seconds() - t0;
        s->splat_seconds += s->ahead_seconds;
        ps_feed_unlock(s->feed);
    }
    atomic_store(&j->done, true);
    return NULL;
}

ps_status ps_session_start(ps_session *s, bool held, ps_error *err)
{
    return ps_session_start_beside(s, held, NULL, NULL, NULL, err);
}

ps_status ps_session_start_beside(ps_session *s, bool held, ps_session_beside_fn *beside,
                                  ps_session_beside_fn *spare, void *ctx, ps_error *err)
{
    s->started = true;
    ps_status st = PS_OK;
    /* After a repair the kept photons are the first picture: the thread
     * retraces the rest. */
    if (!s->skip_prime) {
        /* On every core: a session that draws while it traces leaves a
         * core to the drawing only from here on (ps_session_tracing_threads;
         * the default box's first round took 0.015 s on one core of two).
         * Beside the caller's work, at a low priority (prime_main), so that
         * the work has the cores it asks for: on the session's one tracing
         * thread beside it (two cores) the default box's view was drawn
         * slower and its first float picture came later, 0.061-0.069 s
         * against 0.056-0.067 s. */
        int threads = ps_tracer_threads(s->tracer);
        ps_tracer_set_threads(s->tracer, s->set.first_round_threads);
        prime_job job = {s, PS_OK, {0}, false};
        pthread_t thread;
        if (beside && pthread_create(&thread, NULL, prime_main, &job) == 0) {
            beside(ctx);
            beside = NULL;
            if (spare && !atomic_load(&job.done))
                spare(ctx);
            pthread_join(thread, NULL);
            st = job.st;
            if (st != PS_OK && err)
                *err = job.err;
        } else {
            st = ps_feed_prime(s->feed, err);
        }
        ps_tracer_set_threads(s->tracer, threads);
    }
    if (beside) /* nothing to trace first, or no thread to trace it on */
        beside(ctx);
    if (st != PS_OK)
        return st;
    s->first_pending = held;
    apply_pause(s);
    return ps_feed_start(s->feed, err);
}

ps_status ps_session_stop(ps_session *s, ps_error *err)
{
    ps_feed_stop(s->feed);
    return ps_feed_status(s->feed, err);
}

ps_status ps_session_status(const ps_session *s, ps_error *err) { return ps_feed_status(s->feed, err); }

void ps_session_set_paused(ps_session *s, bool paused)
{
    s->user_paused = paused;
    apply_pause(s);
}

void ps_session_hold(ps_session *s, bool held)
{
    s->hold = held;
    apply_pause(s);
}

bool ps_session_paused(const ps_session *s) { return s->user_paused; }

bool ps_session_counter_stopped(const ps_session *s, uint64_t *at_photons)
{
    if (at_photons)
        *at_photons = s->counter_at;
    return s->counter_stopped;
}

/* ---- refreshing ------------------------------------------------------------------- */

/* How far into map k this refresh draws, from `from` photons (`from_emitted`
 * emitted): whole batches as the feed handed them over, at most `budget`
 * photons beyond `from` (HUGE_VAL: all of them), but at least one batch.
 * *emitted: the photons emitted for that prefix, which its splats are scaled
 * by. Under the lock. */
static size_t prefix_within(const ps_session *s, int k, size_t from, uint64_t from_emitted, double budget,
                            uint64_t *emitted);

/* Whether an edit's first refresh draws all of `photons` stored photons
 * (PS_SESSION_EDIT_SPLATS_WHOLE): not during a drag, and not past the count
 * for the view's pixels (the last camera's; the count itself before any). */
static bool edit_draws_whole(const ps_session *s, uint64_t photons)
{
    double pixels = s->have_cam ? (double)s->cam.width * (double)s->cam.height : PS_SESSION_EDIT_WHOLE_PIXELS;
    return !s->dragging &&
           (double)photons * pixels <= (double)s->set.edit_splats_whole * PS_SESSION_EDIT_WHOLE_PIXELS;
}

static size_t prefix(const ps_session *s, int k, size_t from, uint64_t from_emitted, uint64_t *emitted)
{
    if (!incremental(s)) {
        /* At most whole_most[k] emitted: the stored photons up to the last
         * batch within it (prefix_within keeps at least one). */
        double budget = HUGE_VAL;
        if (isfinite(s->whole_most[k])) {
            size_t n;
            const ps_feed_mark *m = ps_feed_marks(s->feed, (ps_map_kind)k, &n);
            budget = 0.0;
            for (size_t i = 0; i < n; i++)
                if ((double)m[i].emitted <= s->whole_most[k])
                    budget = fmax(budget, (double)m[i].stored - (double)from);
        }
        return prefix_within(s, k, from, from_emitted, budget, emitted);
    }
    double budget = s->moving     ? s->budget * PS_SESSION_MOVING_SHARE
                    : s->catch_up ? s->budget * (s->still_refreshes > 0 ? PS_SESSION_CATCH_UP_GAIN : 1.0)
                                  : s->budget;
    budget *= s->budget_share;
    if (s->edit_view && !s->moving && edit_draws_whole(s, s->edit_held))
        budget = HUGE_VAL;
    return prefix_within(s, k, from, from_emitted, budget, emitted);
}

static size_t prefix_within(const ps_session *s, int k, size_t from, uint64_t from_emitted, double budget,
                            uint64_t *emitted)
{
    size_t n;
    const ps_feed_mark *m = ps_feed_marks(s->feed, (ps_map_kind)k, &n);
    size_t end = from;
    *emitted = from_emitted;
    for (size_t i = 0; i < n; i++) {
        if (m[i].stored < from || m[i].emitted < *emitted)
            continue;
        bool over = (double)(m[i].stored - from) > budget;
        if (over && end > from)
            break;
        end = m[i].stored;
        *emitted = m[i].emitted;
        if (over)
            break;
    }
    return end;
}

/* The radius of map k's splats after `emitted` photons: r0 under the
 * schedule, its reference count the scene's photon count for the map (what
 * r0 was chosen for), else the cap. */
static double radius_at(const ps_session *s, int k, uint64_t emitted)
{
    const ps_scene_defaults *d = ps_scene_get_defaults(s->scene);
    int64_t scene_n = k == PS_MAP_CAUSTIC ? d->caustic_photons : d->global_photons;
    uint64_t n0 = scene_n > 0 ? (uint64_t)scene_n : s->set.caps[k];
    return ps_splat_radius_at(s->set.radius_schedule, s->set.radius[k], n0, emitted, s->set.radius_alpha);
}

/* The illumination maps (illummap.h) brought to the prefix a refresh's
 * budget allows, under the lock: they do not depend on the view, so they go
 * on from their own count, at the schedule's radius level. Incremental: the
 * maps' own budget, its share as the splats' (a checkpoint's frame in snap
 * took a whole one, 2.4*10^4 photons and 0.028 s, where its splats took a
 * quarter of theirs: the design room's 0.2 s checkpoint came at 0.24-
 * 0.30 s). *end: the stored photons they hold, s->imap_emitted the photons
 * emitted for them (0: none). */
static ps_status imap_gather(ps_session *s, const ps_photon_map *m, size_t *end, ps_error *err)
{
    const int k = PS_MAP_GLOBAL;
    bool inc = incremental(s);
    uint64_t emitted;
    /* The maps only grow (a whole refresh's cap, ps_session_set_whole_most,
     * does not apply: they hold what earlier refreshes added, and drawing
     * them costs no more). */
    *end = prefix_within(s, k, ps_illummap_count(s->imap), s->imap_emitted,
                         inc ? s->imap_budget * s->budget_share : HUGE_VAL, &emitted);
    if (emitted == 0)
        return PS_OK;
    size_t added;
    double level = ps_illummap_level_radius(s->imap, s->set.radius[k], radius_at(s, k, emitted));
    double t0 = ps_now_seconds();
    ps_status st = ps_illummap_update(s->imap, m->photons, m->materials, m->objects, *end, level, &added, err);
    if (st != PS_OK)
        return st;
    if (inc && added > 0) {
        double rate = (double)added / fmax(ps_now_seconds() - t0, 1e-6);
        s->imap_budget = fmax(PS_SESSION_BUDGET_MIN, rate * s->set.tau * s->set.splat_share / PS_MAP_COUNT);
    }
    s->imap_emitted = emitted;
    return PS_OK;
}

/* The global map with --global-layer maps, under the lock: the maps brought
 * on (imap_gather); the glossy photons' lobes splatted as the other layers'
 * photons are; the colours remade when the maps or the view changed. */
static ps_status imap_refresh(ps_session *s, const ps_photon_map *m, const ps_camera_frame *cam, ps_session_frame *out,
                              ps_error *err)
{
    const int k = PS_MAP_GLOBAL;
    bool inc = incremental(s);
    ps_splat_batch *b = &s->batch[k];
    ps_splat_batch_clear(b);
    ps_splat_batch_reset_carry(b);
    b->wanted = b->lost = 0.0;
    size_t end;
    ps_status st = imap_gather(s, m, &end, err);
    uint64_t emitted = s->imap_emitted;
    if (st != PS_OK || emitted == 0)
        return st;
    s->drawn[k] = end;
    s->drawn_emitted[k] = emitted;
    out->emitted[k] = emitted;
    double scale = inc ? 1.0 : exposure(s) * (double)s->set.caps[k] / (double)emitted;
    /* The lobes: the glossy photons not yet in this view's layer. */
    const ps_photon *lp;
    const uint16_t *lm;
    const uint32_t *lo;
    size_t nl = ps_illummap_lobe(s->imap, &lp, &lm, &lo), from = inc ? s->lobe_drawn : 0;
    s->splat_radius[k] = radius_at(s, k, emitted);
    /* While the specular layer shows, the lobes are its (specular_glossy.h). */
    bool lobes_here = !((s->set.layers & PS_LAYER_SPECULAR) && ps_glossy_any(s->spec, &s->mesh, ps_session_materials(s)));
    if (nl > from && !s->illuminance && lobes_here) {
        size_t nmat;
        ps_scene_materials(s->scene, &nmat);
        ps_illummap_lobe_materials(ps_session_materials(s), nmat, s->lobe_mats);
        ps_splat_params p;
        memset(&p, 0, sizeof p);
        p.mode = s->set.splat;
        p.radius = s->splat_radius[k];
        p.kernel_mean = s->kernel.mean;
        p.kernel_extent = s->kernel.extent;
        p.scale = scale;
        p.point_size = s->set.point_size;
        p.precision = s->set.precision;
        p.levels = float_splats(s) ? 0 : 255;
        p.materials = s->lobe_mats;
        p.objects = s->set.stencil_clip ? lo + from : NULL;
        p.cam = *cam;
        st = ps_splat_build(lp + from, lm + from, nl - from, &p, b, err);
        out->splats += b->splats;
        s->last_splats[k] += b->splats;
    }
    s->lobe_drawn = nl;
    /* The colours follow the maps, the scale and the materials; which side
     * each triangle shows follows the view. */
    bool recolour = ps_illummap_changed(s->imap) || scale != s->imap_scale || ps_session_materials(s) != s->imap_mats;
    if (recolour) {
        const float *front, *back;
        ps_illummap_colors(s->imap, ps_session_materials(s), scale, &front, &back);
        s->imap_scale = scale;
        s->imap_mats = ps_session_materials(s);
    }
    out->imap_redraw = recolour || out->new_view || !inc;
    if (out->imap_redraw)
        s->imap_view = ps_illummap_view_colors(s->imap, cam->eye);
    out->imap_colors = s->imap_view;
    out->imap_span_count = ps_illummap_spans(s->imap, &out->imap_spans);
    return st;
}

/* Whether map k may be baked at all (settings.bake): incremental triangle
 * splats, not the illumination maps' global layer. */
static bool bake_wanted(const ps_session *s, int k)
{
    return s->set.bake && incremental(s) && s->set.splat == PS_SPLAT_TRIANGLES && !(k == PS_MAP_GLOBAL && s->imap);
}

/* Map k's bake dropped when what it was laid from changed (the maps, the
 * materials the splats take, the radius for its photons, the kernel), or
 * baking no longer applies: the textures to be dropped too. */
static void bake_check(ps_session *s, int k, const ps_material *mats, ps_session_frame *out)
{
    struct session_bake *b = &s->baked[k];
    if (b->state == BAKE_NONE)
        return;
    /* The radius for the photons it was laid from: the map's last mark's. */
    size_t nm;
    const ps_feed_mark *mk = ps_feed_marks(s->feed, (ps_map_kind)k, &nm);
    double radius = radius_at(s, k, nm ? mk[nm - 1].emitted : 0);
    if (!bake_wanted(s, k) || b->epoch != s->maps_epoch || b->mats != mats || b->radius != radius ||
        b->kernel_mean != s->kernel.mean) {
        out->map[k].bake_reset = b->state != BAKE_REFUSED;
        memset(b, 0, sizeof *b);
    }
}

/* Under the lock, once the feed is over and map k's layer shows all of it
 * for a still camera: planned the first time (the textures made anew), then
 * a budget's photons a refresh laid into the textures. */
static ps_status bake_step(ps_session *s, int k, const ps_photon_map *m, const ps_material *mats,
                           ps_session_frame *out, ps_error *err)
{
    struct session_bake *b = &s->baked[k];
    if (b->state == BAKE_NONE) {
        if (!s->bake[k]) {
            ps_status st = ps_bake_create(&s->bake[k], err);
            if (st != PS_OK)
                return st;
        }
        double radius = radius_at(s, k, s->drawn_emitted[k]);
        bool covered;
        ps_status st = ps_bake_plan(s->bake[k], s->scene, mats, m->photons, m->materials, m->objects, m->count, radius,
                                    &covered, err);
        if (st != PS_OK)
            return st;
        b->state = covered ? BAKE_LAYING : BAKE_REFUSED;
        b->total = m->count;
        b->laid = 0;
        b->laid_emitted = 0;
        b->epoch = s->maps_epoch;
        b->mats = mats;
        b->radius = radius;
        b->kernel_mean = s->kernel.mean;
        out->map[k].bake_reset = true;
    }
    if (b->state != BAKE_LAYING)
        return PS_OK;
    /* The catch-up's larger share: nothing else waits for these refreshes
     * (ps_session_catching_up), and each pays the view's fixed costs. */
    uint64_t emitted;
    size_t end = prefix_within(s, k, b->laid, b->laid_emitted, PS_SESSION_CATCH_UP_GAIN * s->budget * s->budget_share,
                               &emitted);
    ps_splat_params p;
    memset(&p, 0, sizeof p);
    p.mode = PS_SPLAT_TRIANGLES;
    p.radius = b->radius;
    p.kernel_mean = s->kernel.mean;
    p.kernel_extent = s->kernel.extent;
    p.scale = 1.0; /* stored powers, as the incremental layers sum them */
    p.materials = mats;
    ps_status st = ps_bake_build(s->bake[k], m->photons, m->materials, m->objects, b->laid, end, &p, err);
    if (st != PS_OK)
        return st;
    out->splats += ps_bake_splats(s->bake[k]);
    s->last_splats[k] += ps_bake_splats(s->bake[k]);
    out->map[k].bake = s->bake[k];
    b->laid = end;
    b->laid_emitted = emitted;
    if (end >= m->count)
        b->state = BAKE_DONE;
    /* Its photons still to lay are the budget's, as a map's still to draw. */
    s->budget_maps[k] = b->state == BAKE_LAYING;
    return PS_OK;
}

/* Under the lock: nothing more will arrive for the maps drawn now (the feed
 * ended, no repair's merge pending, the same generation). */
static bool feed_over(const ps_session *s)
{
    return ps_feed_ended(s->feed) && !ps_feed_merge_pending(s->feed) && ps_feed_generation(s->feed) == s->feed_gen;
}

/* A view still to draw: an edit, a new or moving camera, lights to rebuild. */
static bool view_pending(const ps_session *s)
{
    return s->edited || s->view_dirty || !s->have_cam || s->lights_pending || s->moving;
}

/* Whether map k still waits to be baked (ps_session_settled), under the lock. */
static bool bake_pending(const ps_session *s, int k, const ps_photon_map *m)
{
    return bake_wanted(s, k) && (s->set.layers & ps_map_layer((ps_map_kind)k)) && m->count > 0 &&
           (s->baked[k].state == BAKE_NONE || s->baked[k].state == BAKE_LAYING);
}

double ps_session_bake_progress(const ps_session *s, ps_map_kind k)
{
    const struct session_bake *b = &s->baked[k];
    if (b->state == BAKE_DONE)
        return 1.0;
    return b->state == BAKE_LAYING && b->total > 0 ? (double)b->laid / (double)b->total : -1.0;
}

bool ps_session_baked(const ps_session *s, ps_map_kind k, size_t *texels)
{
    bool done = s->baked[k].state == BAKE_DONE;
    if (texels)
        *texels = done ? ps_bake_texels(s->bake[k]) : 0;
    return done;
}

/* The specular layer's eye paths for a refresh's view `cam` (the still
 * camera `still`'s, or its level of detail while `moving`): its lookups, in
 * incremental sessions (the window) at most PS_SESSION_SPECULAR_VERTICES a
 * refresh, the rest in the next ones (the default scene's two spheres: 10^4,
 * 12 ms); per-pixel paths once the camera holds still (specular.h), a
 * budget a refresh, or whole when few are left (PS_SESSION_PIXEL_RAYS_WHOLE). */
static void trace_eye_paths(ps_session *s, const ps_camera_frame *cam, const ps_camera_frame *still, bool moving)
{
    bool inc = incremental(s);
    ps_specular_update(s->spec, s->world, cam->eye,
                       !inc ? 0 : moving ? PS_SESSION_SPECULAR_VERTICES_MOVING : PS_SESSION_SPECULAR_VERTICES);
    if (!moving) {
        bool at_once = !inc || ps_specular_pixel_rays_left(s->spec, still) <= s->set.pixel_rays_whole;
        ps_specular_update_pixels(s->spec, s->world, still, at_once ? 0 : PS_SPECULAR_PIXEL_RAYS,
                                  at_once ? 0.0 : PS_SPECULAR_PIXEL_TIME_SHARE * s->set.tau);
    }
}

void ps_session_set_specular_wait(ps_session *s, bool wait) { s->specular_wait = wait; }

void ps_session_trace_specular(ps_session *s)
{
    if (!s->specular_owed)
        return;
    s->specular_owed = false;
    trace_eye_paths(s, &s->owed_view, &s->cam, s->owed_moving);
}

bool ps_session_specular_owed(const ps_session *s) { return s->specular_owed; }

void ps_session_trace_specular_until(ps_session *s, double deadline)
{
    /* Lookups a slice at a time, then the per-pixel paths to the deadline:
     * both go on from where they stopped (specular.h). Whatever is left
     * stays owed, as the refresh would have traced it. */
    while (s->specular_owed && ps_now_seconds() < deadline) {
        if (ps_specular_update(s->spec, s->world, s->owed_view.eye, PS_SESSION_PREPARE_VERTICES) > 0)
            continue;
        if (s->owed_moving || ps_specular_update_pixels(s->spec, s->world, &s->cam, 0,
                                                        fmax(deadline - ps_now_seconds(), 1e-6)) == 0)
            s->specular_owed = false;
        break;
    }
}

ps_status ps_session_refresh(ps_session *s, const ps_camera_frame *cam, ps_session_frame *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    bool inc = incremental(s);
    if (!s->have_cam || !ps_camera_frame_equal(cam, &s->cam)) {
        /* A camera move (not the first view): draw the level of detail. */
        s->moving = inc && s->have_cam;
        s->cam = *cam;
        s->have_cam = true;
        s->view_dirty = true;
    } else if (s->moving) {
        /* Still again: the view starts over at full detail. */
        s->moving = false;
        s->catch_up = true;
        s->still_refreshes = 0;
        s->view_dirty = true;
    }
    /* An edit's first picture, unless it draws every photon (the edit then
     * came alone: the picture after it is as full as the one before), is
     * the level of detail as a moving camera's, with shadows; the full
     * view follows at the next refresh, as after a camera move. A drag's
     * edits are all drawn so. */
    if (s->edit_view && inc && s->have_cam && !s->moving) {
        if (!edit_draws_whole(s, s->edit_held)) {
            s->moving = true;
            s->view_dirty = true;
            out->edit_lod = true;
        }
    }
    out->moving = s->moving;
    /* The level of detail's fewer pixels (the camera's view, fewer of them:
     * the same aspect, so the picture scales up unchanged). The drawing
     * below is this view's; the camera itself is what is compared. */
    out->view = *cam;
    if (s->moving) {
        out->view.width = (cam->width + PS_SESSION_MOVING_SCALE - 1) / PS_SESSION_MOVING_SCALE;
        out->view.height = (cam->height + PS_SESSION_MOVING_SCALE - 1) / PS_SESSION_MOVING_SCALE;
    }
    const ps_camera_frame *still = cam;
    cam = &out->view;
    /* A repair's maps back in index order (feed.h) before a view that starts
     * over anyway: it then draws a prefix of index order, as a fresh trace's. */
    if (s->view_dirty) {
        ps_status mst = ps_feed_merge(s->feed, err);
        if (mst != PS_OK)
            return mst;
    }
    ps_feed_lock(s->feed);
    uint64_t gen = ps_feed_generation(s->feed);
    if (gen != s->feed_gen) {
        /* The feed put a map back in index order: a drawn prefix that was
         * not all of it is other photons now. */
        s->feed_gen = gen;
        s->maps_epoch++;
        for (int k = 0; k < PS_MAP_COUNT; k++)
            if (s->drawn[k] != ps_feed_maps(s->feed)[k].count)
                s->view_dirty = true;
        /* The illumination maps sum photons in the map's order, so even all
         * of them, summed in the repair's order, are not the bytes a fresh
         * trace's maps would give. */
        if (s->imap_emitted > 0) {
            forget_imap(s);
            s->view_dirty = true; /* the lobe splats with them */
        }
    }
    ps_feed_unlock(s->feed);
    if (s->lights_pending) {
        s->lights_pending = false;
        int side = s->built_side;
        ps_status lst = build_lights(s, err);
        if (lst != PS_OK)
            return lst;
        out->lights_changed = true;
        out->shadows_refined = s->built_side == side;
    }
    s->last_lit = out->lights_changed;
    out->new_view = s->view_dirty;
    if (s->view_dirty) {
        for (int k = 0; k < PS_MAP_COUNT; k++)
            s->drawn[k] = 0, s->drawn_emitted[k] = 0;
        s->view_dirty = false;
    }
    double t0 = ps_now_seconds();
    const ps_material *materials = ps_session_materials(s);
    double wanted = 0.0, lost = 0.0;
    size_t nmat;
    ps_scene_materials(s->scene, &nmat);
    /* The global photons' glossy lobes are the specular layer's while it
     * shows (specular_glossy.h); the caustic ones' are not (lights seen
     * through glass in a glossy surface: no cube map shows them). */
    bool spec_on = (s->set.layers & PS_LAYER_SPECULAR) && !s->illuminance;
    const ps_material *global_mats;
    ps_status st =
        ps_glossy_splat_materials(s->spec, &s->mesh, materials, nmat, spec_on, &s->nolobe_mats, &global_mats, err);
    if (st != PS_OK)
        return st;
    ps_feed_lock(s->feed);
    const ps_photon_map *maps = ps_feed_maps(s->feed);
    if (out->new_view)
        s->lobe_drawn = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        s->last_splats[k] = 0, s->budget_maps[k] = false;
    double growth[PS_MAP_COUNT]; /* the level of detail's radius growth */
    bool baked_draw[PS_MAP_COUNT] = {false, false}; /* the layer drawn from its baked textures */
    for (int k = 0; k < PS_MAP_COUNT; k++)
        growth[k] = 1.0;
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++) {
        if (k == PS_MAP_GLOBAL && s->imap) {
            if (s->set.layers & PS_LAYER_GLOBAL)
                st = imap_refresh(s, &maps[k], cam, out, err);
            else /* not shown: nothing waits (showing it is a new view) */
                s->drawn[k] = maps[k].count;
            continue;
        }
        ps_splat_batch *b = &s->batch[k];
        ps_splat_batch_clear(b);
        /* A whole refresh is built afresh, so its round-off carry starts at 0:
         * the same photons give the same picture. Incremental layers are
         * float, where nothing rounds. */
        ps_splat_batch_reset_carry(b);
        b->wanted = b->lost = 0.0;
        const ps_photon_map *m = &maps[k];
        const ps_material *kmats = k == PS_MAP_GLOBAL ? global_mats : materials;
        bake_check(s, k, kmats, out);
        if (s->baked[k].state == BAKE_DONE && (s->set.layers & ps_map_layer((ps_map_kind)k))) {
            /* The layer is the baked textures, whatever the view: drawn into
             * it again for a new one (a moving camera's too: no level of
             * detail needed), else kept. */
            s->drawn[k] = s->baked[k].laid;
            s->drawn_emitted[k] = s->baked[k].laid_emitted;
            out->emitted[k] = s->baked[k].laid_emitted;
            s->splat_radius[k] = s->baked[k].radius;
            baked_draw[k] = out->new_view;
            continue;
        }
        size_t from = inc ? s->drawn[k] : 0;
        uint64_t emitted;
        size_t end = prefix(s, k, from, inc ? s->drawn_emitted[k] : 0, &emitted);
        out->emitted[k] = emitted;
        s->drawn[k] = end;
        s->drawn_emitted[k] = emitted;
        /* A map whose next photons have not arrived is still the budget's:
         * its splats come with the next batch. */
        s->budget_maps[k] = (s->set.layers & ps_map_layer((ps_map_kind)k)) && m->count > 0 &&
                            emitted < ps_feed_cap(s->feed, (ps_map_kind)k);
        if (!(s->set.layers & ps_map_layer((ps_map_kind)k)) || end <= from || emitted == 0)
            continue;
        ps_splat_params p;
        memset(&p, 0, sizeof p);
        p.mode = s->set.splat;
        s->splat_radius[k] = radius_at(s, k, emitted);
        if (s->moving) {
            /* The level of detail: as many photons' worth of cover as have arrived. */
            size_t nm;
            const ps_feed_mark *mk = ps_feed_marks(s->feed, (ps_map_kind)k, &nm);
            double arrived = nm ? (double)mk[nm - 1].emitted : (double)emitted;
            growth[k] = fmin(PS_SESSION_MOVING_GROWTH_MAX, sqrt(fmax(1.0, arrived / (double)emitted)));
            s->splat_radius[k] *= growth[k];
        }
        p.radius = s->splat_radius[k];
        p.kernel_mean = s->kernel.mean;
        p.kernel_extent = s->kernel.extent;
        /* Powers are normalised for the cap N; n have been emitted so far.
         * Incremental layers sum stored powers and the composite scales. */
        p.scale = inc ? 1.0 : exposure(s) * (double)s->set.caps[k] / (double)emitted;
        p.point_size = s->set.point_size;
        p.precision = s->set.precision;
        p.levels = float_splats(s) ? 0 : 255;
        p.materials = kmats;
        p.objects = s->set.stencil_clip ? m->objects + from : NULL;
        p.cam = *cam;
        st = ps_splat_build(m->photons + from, m->materials + from, end - from, &p, b, err);
        wanted += b->wanted;
        lost += b->lost;
        out->splats += b->splats;
        s->last_splats[k] += b->splats;
    }
    /* Baking (settings.bake): once nothing more will arrive and a still
     * view shows every photon of the map, its textures are laid. */
    bool over = feed_over(s);
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++)
        if (over && !s->moving && bake_pending(s, k, &maps[k]) && s->drawn[k] >= maps[k].count)
            st = bake_step(s, k, &maps[k], k == PS_MAP_GLOBAL ? global_mats : materials, out, err);
    bool whole = true;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        whole = whole && s->drawn[k] >= maps[k].count;
    if (s->catch_up) { /* the view is whole again once every stored photon is drawn */
        s->catch_up = !whole && !s->moving;
        s->still_refreshes++;
    }
    bool merge = whole && ps_feed_merge_pending(s->feed);
    ps_feed_unlock(s->feed);
    /* Every photon of a repaired feed drawn: its maps back in index order
     * now costs the picture nothing (the next refresh sees the whole map
     * drawn, and keeps the layers). */
    if (merge && st == PS_OK)
        st = ps_feed_merge(s->feed, err);
    s->round_off = wanted > 0.0 ? lost / wanted : 0.0;
    s->last_build = ps_now_seconds() - t0;
    s->splat_seconds += s->last_build;
    s->refreshes++;
    s->edit_view = false;
    if (st != PS_OK)
        return st;
    /* The specular layer: its eye paths for this view, or owed while the
     * drawing side has nothing for them to look up (ps_session_set_specular_wait). */
    out->specular = (s->set.layers & PS_LAYER_SPECULAR) && !s->illuminance && ps_specular_range_count(s->spec) > 0;
    s->specular_owed = false;
    if (out->specular) {
        s->owed_view = *cam;
        s->owed_moving = out->moving;
        if (s->specular_wait)
            s->specular_owed = true;
        else
            trace_eye_paths(s, &s->owed_view, still, s->owed_moving);
    }
    ps_session_direct_view(s, &out->direct_exposure, &out->direct);
    out->direct_gain = inc ? exposure(s) : 1.0;
    out->splat = s->set.splat;
    out->point_size = s->set.point_size;
    out->round_off = s->round_off;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_session_layer *l = &out->map[k];
        bool shown = (s->set.layers & ps_map_layer((ps_map_kind)k)) && out->emitted[k] > 0;
        l->clear = !inc || baked_draw[k];
        l->baked = baked_draw[k];
        l->batch = &s->batch[k];
        l->radius = s->splat_radius[k];
        l->gain = !shown ? 0.0 : inc ? exposure(s) * (double)s->set.caps[k] / (double)out->emitted[k] : 1.0;
        /* Fewer pixels only for a moving camera (an edit's level of detail
         * is the picture of the edit), where the splats grew as much (their
         * pixels then as many as at full detail) and are triangles (points
         * and sprites are sized in pixels); not the illumination maps' lobes. */
        bool shrunk = out->moving && !out->edit_lod && k == PS_MAP_GLOBAL && !s->imap &&
                      s->set.splat == PS_SPLAT_TRIANGLES && growth[k] >= PS_SESSION_MOVING_GLOBAL_SHRINK;
        l->shrink = shrunk ? PS_SESSION_MOVING_GLOBAL_SHRINK : 1;
    }
    if (out->imap_colors && out->map[PS_MAP_GLOBAL].gain == 0.0)
        out->imap_colors = NULL;
    return PS_OK;
}

void ps_session_full_lights(ps_session *s)
{
    if (ps_session_lights_to_come(s) > 1.0) {
        s->area_side = PS_PREVIEW_AREA_SIDE;
        s->coarse_shadows = false;
        s->lights_pending = true;
    }
}

static bool has_area_lights(const ps_session *s)
{
    size_t n;
    const ps_light *L = ps_scene_lights(s->scene, &n);
    for (size_t i = 0; i < n; i++)
        if (L[i].type == PS_LIGHT_QUAD || L[i].type == PS_LIGHT_DISC || L[i].type == PS_LIGHT_MESH)
            return true;
    return false;
}

void ps_session_drawn(ps_session *s, double draw_seconds)
{
    /* A moving refresh's time is the level of detail's (grown splats, a new
     * direct layer): it would understate the rate the still view draws at.
     * So do the first (llvmpipe's first compiles: 4.5*10^4 splats a second)
     * and one with new lights (their shadow maps and direct layer: 2.3*10^4
     * against 4*10^5 for splats alone). From them, snap's float tracer
     * waited a few batches ahead of the picture (backlog_refreshes): the
     * area box's --time 2 at bench's caps showed 65 536 photons, 294 912
     * learning from neither. */
    if (incremental(s) && !s->moving && !s->last_lit && s->refreshes > 1) {
        ps_splat_cost_learn(&s->splat_cost, s->last_splats, s->last_build + draw_seconds);
        double count = ps_splat_cost_count(&s->splat_cost, s->budget_maps, s->set.tau * s->set.splat_share);
        if (count > 0.0)
            s->budget = fmax(PS_SESSION_BUDGET_MIN, count);
    }
    /* The tracer waits while the picture is far behind it (settings): a
     * bound the feed checks before every round, up to the next refresh. */
    if (incremental(s) && s->set.backlog_refreshes > 0.0 && s->feed) {
        size_t most[PS_MAP_COUNT];
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            double bound = (double)s->drawn[k] + s->set.backlog_refreshes * s->budget;
            most[k] = k == PS_MAP_GLOBAL && s->imap ? SIZE_MAX : bound < 0x1p62 ? (size_t)bound : SIZE_MAX;
        }
        ps_feed_set_ahead(s->feed, most);
    }
    /* Thesis 5.1: once a refresh loses this much to round-off, more photons
     * only add noise: stop shooting (until the next edit). */
    if (!float_splats(s) && s->set.precision == PS_PRECISION_COUNTER && !s->counter_stopped &&
        s->round_off > s->set.counter_threshold) {
        s->counter_stopped = true;
        s->counter_at = s->drawn_emitted[0] + s->drawn_emitted[1];
    }
    s->first_pending = false;
    apply_pause(s);
    /* Progressive lights: a refresh drawn, the next one a level further
     * (twice as many virtual lights a side where the scene has an area
     * light, the full shadow maps), until all. */
    if (!s->lights_held)
        ps_session_refine_lights(s);
}

void ps_session_hold_lights(ps_session *s, bool held) { s->lights_held = held; }

/* Whether the next level brings twice the virtual lights a side. */
static bool more_virtual_lights(const ps_session *s)
{
    return s->area_side < PS_PREVIEW_AREA_SIDE && has_area_lights(s);
}

double ps_session_lights_to_come(const ps_session *s)
{
    double shadows = s->coarse_shadows ? PS_SESSION_COARSE_SHADOW_COST : 1.0;
    if (!more_virtual_lights(s))
        return shadows;
    double ratio = (double)PS_PREVIEW_AREA_SIDE / (double)s->area_side;
    return shadows * ratio * ratio;
}

double ps_session_next_level_lights(const ps_session *s) { return more_virtual_lights(s) ? 4.0 : 1.0; }

double ps_session_next_level_cost(const ps_session *s)
{
    double cost = ps_session_next_level_lights(s);
    return s->coarse_shadows ? cost * PS_SESSION_COARSE_SHADOW_COST : cost;
}

bool ps_session_refine_lights(ps_session *s)
{
    if (ps_session_lights_to_come(s) <= 1.0)
        return false;
    /* The full shadows come with the first new virtual lights, in the same
     * level: a level of its own held an area light's next one back a refresh,
     * and that one starts the specular cubes' round over (gl_specular.c),
     * which the area box's 8-bit 1 s checkpoint then showed black. */
    if (more_virtual_lights(s))
        s->area_side *= 2;
    s->coarse_shadows = false;
    s->lights_pending = true;
    return true;
}

bool ps_session_catching_up(ps_session *s)
{
    /* A bake being laid: planned once the feed was over, so nothing is
     * traced meanwhile either. Only while its layer shows: a hidden one's
     * bake waits (refreshes back to back would lay nothing). */
    bool laying = false;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        laying = laying || (s->baked[k].state == BAKE_LAYING && (s->set.layers & ps_map_layer((ps_map_kind)k)));
    if (!(s->catch_up || laying) || !incremental(s))
        return false;
    if (!laying && (s->user_paused || s->counter_stopped))
        return true;
    ps_feed_lock(s->feed);
    bool ended = ps_feed_ended(s->feed);
    ps_feed_unlock(s->feed);
    return ended;
}

bool ps_session_tracing(ps_session *s)
{
    if (!incremental(s) || s->user_paused || s->counter_stopped)
        return false;
    ps_feed_lock(s->feed);
    bool ended = ps_feed_ended(s->feed);
    ps_feed_unlock(s->feed);
    return !ended;
}

bool ps_session_prepare_still(ps_session *s, size_t max_vertices)
{
    /* Only for the camera the last (moving) picture drew; an edit's level
     * of detail is followed by its full view at once, with no wait. */
    if (!s->moving || !s->have_cam || !incremental(s) || s->edited || s->illuminance ||
        !(s->set.layers & PS_LAYER_SPECULAR) || ps_specular_range_count(s->spec) == 0 || ps_session_tracing(s))
        return false;
    if (ps_specular_update(s->spec, s->world, s->cam.eye, max_vertices) > 0)
        return true;
    /* Then its per-pixel paths, for the camera at its full pixels (the
     * still refresh's trace_eye_paths goes on from where these stop). */
    return ps_specular_update_pixels(s->spec, s->world, &s->cam, 0, PS_SESSION_PREPARE_SECONDS) > 0;
}

double ps_session_next_refresh(const ps_session *s, double at)
{
    return at + (s->moving ? PS_SESSION_STILL_SHARE : 1.0) * s->set.tau;
}

bool ps_session_work_pending(ps_session *s)
{
    if (view_pending(s))
        return true;
    /* A bake is laid once the feed is over (ps_session_refresh). */
    ps_feed_lock(s->feed);
    bool pending = false, over = feed_over(s);
    for (int k = 0; k < PS_MAP_COUNT && over; k++)
        pending = pending || bake_pending(s, k, &ps_feed_maps(s->feed)[k]);
    ps_feed_unlock(s->feed);
    return pending;
}

bool ps_session_settled(ps_session *s)
{
    /* A moving camera's picture (or an edit's first) is a level of detail,
     * whatever it drew: the full view is still to come. */
    if (view_pending(s))
        return false;
    if (s->user_paused || s->counter_stopped)
        return true;
    ps_feed_lock(s->feed);
    bool over = feed_over(s);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        over = over && s->drawn[k] >= ps_feed_maps(s->feed)[k].count && !bake_pending(s, k, &ps_feed_maps(s->feed)[k]);
    ps_feed_unlock(s->feed);
    return over;
}

/* ---- settings ---------------------------------------------------------------------- */

const ps_session_settings *ps_session_get_settings(const ps_session *s) { return &s->set; }

void ps_session_set_layers(ps_session *s, unsigned layers)
{
    s->set.layers = layers & PS_LAYER_ALL;
    s->view_dirty = true;
}

void ps_session_set_splat(ps_session *s, ps_splat_mode mode)
{
    s->set.splat = mode;
    s->view_dirty = true;
}

ps_status ps_session_set_kernel(ps_session *s, ps_kernel kernel, ps_error *err)
{
    ps_kernel_texture t;
    ps_status st = make_kernel(float_splats(s), kernel, &t, err);
    if (st != PS_OK)
        return st;
    ps_kernel_texture_free(&s->kernel);
    s->kernel = t;
    s->set.kernel = kernel;
    s->view_dirty = true;
    if (s->imap) {
        ps_illummap_reset(s->imap, kernel);
        s->imap_emitted = 0;
    }
    return PS_OK;
}

void ps_session_set_precision(ps_session *s, ps_precision precision)
{
    s->set.precision = precision;
    s->view_dirty = true;
}

void ps_session_set_exposure(ps_session *s, double exposure)
{
    s->set.exposure = exposure;
    /* Whole refreshes hold exposed values; incremental ones only change gains. */
    if (!incremental(s))
        s->view_dirty = true;
}

void ps_session_set_radius(ps_session *s, ps_map_kind k, double radius)
{
    if (radius > 0.0) {
        s->set.radius[k] = radius;
        s->view_dirty = true;
    }
}

void ps_session_set_tau(ps_session *s, double tau) { s->set.tau = tau; }

void ps_session_set_whole_most(ps_session *s, const double most[PS_MAP_COUNT])
{
    for (int k = 0; k < PS_MAP_COUNT; k++)
        s->whole_most[k] = most && !(most[k] < 0.0) ? most[k] : HUGE_VAL;
}

void ps_session_set_budget_share(ps_session *s, double share)
{
    s->budget_share = share >= 0.0 && share <= 1.0 ? share : 1.0;
}

ps_status ps_session_set_global_layer(ps_session *s, ps_global_layer g, ps_error *err)
{
    if (g == PS_GLOBAL_MAPS && !s->imap) {
        ps_status st = imap_make(s, err);
        if (st != PS_OK)
            return st;
    }
    if (g == PS_GLOBAL_SPLATS) {
        /* The splats start over from photon 0 in the next view; the maps go. */
        ps_illummap_destroy(s->imap);
        s->imap = NULL;
    }
    s->set.global_layer = g;
    s->drawn[PS_MAP_GLOBAL] = 0;
    s->drawn_emitted[PS_MAP_GLOBAL] = 0;
    s->view_dirty = true;
    return PS_OK;
}

const ps_illummap *ps_session_illummap(const ps_session *s) { return s->imap; }

ps_status ps_session_set_illuminance(ps_session *s, bool on, ps_error *err)
{
    if (on == s->illuminance)
        return PS_OK;
    size_t n;
    const ps_material *m = ps_scene_materials(s->scene, &n);
    if (on && !s->white) {
        s->white = calloc(n ? n : 1, sizeof *s->white);
        if (!s->white)
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for %zu materials", ps_scene_path(s->scene), n);
        for (size_t i = 0; i < n; i++) {
            snprintf(s->white[i].name, sizeof s->white[i].name, "%s", m[i].name);
            s->white[i].type = PS_MAT_DIFFUSE;
            s->white[i].albedo = ps_rgb_make(1.0, 1.0, 1.0);
        }
    }
    ps_kernel_texture t;
    ps_status st = make_kernel(on || s->set.float_buffer, s->set.kernel, &t, err);
    if (st != PS_OK)
        return st;
    ps_kernel_texture_free(&s->kernel);
    s->kernel = t;
    s->illuminance = on;
    s->view_dirty = true;
    return PS_OK;
}

bool ps_session_illuminance(const ps_session *s) { return s->illuminance; }

const ps_material *ps_session_materials(const ps_session *s)
{
    size_t n;
    return s->illuminance ? s->white : ps_scene_materials(s->scene, &n);
}

/* ---- edits --------------------------------------------------------------------------- */

/* Before an edit changes the scene: the tracing thread reads it (the world's
 * triangles, the lights), so it is held between batches first, and stays
 * held until ps_session_update replaces it. */
static void hold_for_edit(ps_session *s)
{
    if (s->feed && !s->edited)
        ps_feed_hold_idle(s->feed);
}

static ps_status edited(ps_session *s, ps_status st, bool geometry)
{
    if (st == PS_OK) {
        s->edited = true;
        s->geometry_edited = s->geometry_edited || geometry;
        s->edits++;
    }
    apply_pause(s); /* a refused edit lets tracing go on */
    return st;
}

ps_status ps_session_move_light(ps_session *s, size_t light, ps_vec3 position, ps_error *err)
{
    hold_for_edit(s);
    return edited(s, ps_scene_set_light_position(s->scene, light, position, err), false);
}

ps_status ps_session_move_object(ps_session *s, size_t object, ps_vec3 delta, ps_error *err)
{
    hold_for_edit(s);
    return edited(s, ps_scene_translate_object(s->scene, object, delta, err), true);
}

ps_status ps_session_set_light_power(ps_session *s, size_t light, ps_rgb power, ps_error *err)
{
    hold_for_edit(s);
    return edited(s, ps_scene_set_light_power(s->scene, light, power, err), false);
}

ps_status ps_session_set_spot_angle(ps_session *s, size_t light, double degrees, ps_error *err)
{
    hold_for_edit(s);
    return edited(s, ps_scene_set_spot_angle(s->scene, light, degrees, err), false);
}

ps_status ps_session_restore_scene(ps_session *s, const ps_scene *snapshot, ps_error *err)
{
    bool geometry = false;
    hold_for_edit(s);
    ps_status st = ps_scene_restore(s->scene, snapshot, &geometry, err);
    return edited(s, st, geometry);
}

bool ps_session_edited(const ps_session *s) { return s->edited; }
void ps_session_set_dragging(ps_session *s, bool dragging) { s->dragging = dragging; }
uint64_t ps_session_edits(const ps_session *s) { return s->edits; }

ps_status ps_session_update(ps_session *s, ps_session_changes *changes, ps_error *err)
{
    changes->geometry = s->geometry_edited;
    /* The old maps and tracer stay until the repair has taken what the edits
     * left unchanged (repair.h); what it cannot, starts over from photon 0. */
    ps_feed *old = s->feed;
    ps_tracer *old_tracer = s->tracer;
    s->feed = NULL;
    s->tracer = NULL;
    ps_feed_stop_unmerged(old);
    /* Stopped, the old feed's repair is whole: its counts are final. */
    if (s->repaired) {
        ps_feed_repair_count rc = ps_feed_repair_counts(old);
        s->repairs_before++;
        for (int k = 0; k < PS_MAP_COUNT; k++)
            s->kept_before[k] += rc.kept[k], s->retraced_before[k] += rc.retraced[k];
    }
    ps_status st = PS_OK;
    if (s->geometry_edited) {
        /* The maps' samples are the fine mesh's vertices: made again with it. */
        ps_illummap_destroy(s->imap);
        s->imap = NULL;
        st = build_geometry(s, err);
        if (st == PS_OK && s->set.global_layer == PS_GLOBAL_MAPS)
            st = imap_make(s, err);
    }
    /* The first picture after the edit as soon as after loading (its shadow
     * maps at the side they have: faces the edit cannot reach are kept). */
    s->area_side = s->set.progressive_lights ? 1 : PS_PREVIEW_AREA_SIDE;
    s->lights_pending = false;
    if (st == PS_OK)
        st = build_lights(s, err);
    if (st == PS_OK)
        st = new_tracer(s, err);
    s->repaired = s->skip_prime = false;
    /* The photons the first picture could draw whole (prefix()). */
    uint64_t held = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        held += ps_feed_maps(old)[k].count;
    s->edit_held = held;
    if (st == PS_OK) {
        ps_feed *f = NULL;
        ps_error rerr;
        /* A repair that fails (out of memory) is a restart. */
        if (ps_repair_feed(old, old_tracer, s->tracer, &s->traced, s->scene, ps_world_epsilon(s->world), &f,
                           &s->repaired, &rerr) != PS_OK)
            s->repaired = false;
        if (s->repaired) {
            s->feed = f;
            /* The paths are tested and the kept photons copied as far as the
             * first picture draws (its budget's prefix of each map), the
             * rest by the thread: at 10^6 photons the whole repair was
             * 0.11-0.14 s of the first frame's wait. Maps the first picture
             * draws whole (whole refreshes, PS_SESSION_EDIT_SPLATS_WHOLE) are
             * repaired whole, so that their retrace can come first too. */
            bool whole = !incremental(s) || edit_draws_whole(s, held);
            size_t ahead[PS_MAP_COUNT];
            for (int k = 0; k < PS_MAP_COUNT; k++)
                ahead[k] = whole ? SIZE_MAX : (size_t)fmax(1.0, ceil(s->budget));
            st = ps_feed_repair_ahead(f, ahead, err);
            /* What the edit changed is retraced first: here when it is at
             * most settings.retrace_first photons (the default caps, or an
             * edit near few paths), so that the first picture has no hole
             * where the moved object was and the maps are in index order
             * from the start; else by the thread. */
            if (st == PS_OK && s->started)
                st = ps_feed_retrace_first(f, s->set.retrace_first, err);
            /* A map that has nothing yet gets its first batch before the
             * first picture, as after a restart; one that has photons shows
             * them at once (a map left empty by repair_ahead is repaired
             * whole, so its counts are known). */
            ps_feed_repair_count rc = ps_feed_repair_counts(f);
            bool all_maps_have = true;
            ps_feed_lock(f);
            for (int k = 0; k < PS_MAP_COUNT; k++)
                all_maps_have = all_maps_have && (ps_feed_maps(f)[k].count > 0 || rc.retraced[k] == 0);
            ps_feed_unlock(f);
            /* The priming round retraces only once no map has paths left to
             * test (feed.c's rounds): the other map's repair whole first. */
            if (!all_maps_have && st == PS_OK) {
                const size_t all[PS_MAP_COUNT] = {SIZE_MAX, SIZE_MAX};
                st = ps_feed_repair_ahead(f, all, err);
            }
            s->skip_prime = all_maps_have;
            forget_drawn(s);
        }
    }
    ps_feed_destroy(old);
    ps_tracer_destroy(old_tracer);
    if (st == PS_OK && !s->feed)
        st = new_feed(s, err);
    if (st == PS_OK) {
        ps_repair_state_free(&s->traced);
        st = ps_repair_state_take(s->scene, ps_world_epsilon(s->world), &s->traced, err);
    }
    s->edited = s->geometry_edited = false;
    s->edit_view = true;
    /* The first batch is traced here and the thread held until the first
     * refresh has drawn it: that refresh then has every core. */
    if (st == PS_OK && s->started)
        st = ps_session_start(s, true, err);
    return st;
}

/* ---- what it holds ------------------------------------------------------------------- */

const ps_scene *ps_session_scene(const ps_session *s) { return s->scene; }
const ps_world *ps_session_world(const ps_session *s) { return s->world; }
const ps_preview_mesh *ps_session_mesh(const ps_session *s) { return &s->mesh; }
const ps_preview_mesh *ps_session_coarse_mesh(const ps_session *s) { return &s->coarse; }
bool ps_session_lights_coarse(const ps_session *s) { return s->built_coarse; }

const ps_preview_mesh *ps_session_moving_mesh(const ps_session *s)
{
    return s->moving_mesh.vertex_count > 0 ? &s->moving_mesh : &s->mesh;
}
const ps_preview_lights *ps_session_lights(const ps_session *s) { return &s->lights; }
const ps_kernel_texture *ps_session_kernel(const ps_session *s) { return &s->kernel; }
const ps_tracer *ps_session_tracer(const ps_session *s) { return s->tracer; }
ps_specular *ps_session_specular(ps_session *s) { return s->spec; }

void ps_session_set_specular_centre(ps_session *s, int cube, ps_vec3 centre)
{
    ps_specular_set_lookup_centre(s->spec, cube, centre);
}
uint64_t ps_session_maps_epoch(const ps_session *s) { return s->maps_epoch; }

/* Under the feed's lock: the prefix of map k a cube face splats (at most
 * max_photons stored, ending at a feed mark: *end stored, *emitted emitted;
 * 0 when none or the layer is off) and their radius (ps_session_env_splats). */
static void env_prefix(ps_session *s, ps_map_kind k, size_t max_photons, size_t *end, uint64_t *emitted,
                       double *radius)
{
    *end = 0, *emitted = 0;
    *radius = s->splat_radius[k];
    if (!(s->set.layers & ps_map_layer(k)) || s->illuminance)
        return;
    size_t nm;
    const ps_feed_mark *mk = ps_feed_marks(s->feed, k, &nm);
    for (size_t i = 0; i < nm; i++) {
        if (*end > 0 && mk[i].stored > max_photons)
            break;
        *end = mk[i].stored;
        *emitted = mk[i].emitted;
    }
    if (*end == 0 || *emitted == 0)
        return;
    /* The level of detail's cover for the photons left out, grown by
     * sqrt(arrived / used) (at most PS_RADIUS_GROWTH_MAX), but never past
     * the larger of the two maps' own radii: a grown global splat would
     * fill much of a cube face, and the fill is what a face costs. */
    double arrived = (double)mk[nm - 1].emitted;
    double own = radius_at(s, k, *emitted);
    double grown = own * fmin(PS_RADIUS_GROWTH_MAX, sqrt(fmax(1.0, arrived / (double)*emitted)));
    double largest = fmax(s->splat_radius[PS_MAP_CAUSTIC], s->splat_radius[PS_MAP_GLOBAL]);
    *radius = fmax(own, fmin(grown, largest));
}

ps_status ps_session_env_splats(ps_session *s, ps_map_kind k, const ps_camera_frame *view, size_t max_photons,
                                ps_splat_batch *b, double *radius, ps_error *err)
{
    ps_splat_batch_clear(b);
    ps_splat_batch_reset_carry(b);
    ps_feed_lock(s->feed);
    size_t end;
    uint64_t emitted;
    env_prefix(s, k, max_photons, &end, &emitted, radius);
    ps_status st = PS_OK;
    if (end > 0 && emitted > 0) {
        const ps_photon_map *m = &ps_feed_maps(s->feed)[k];
        ps_splat_params p;
        memset(&p, 0, sizeof p);
        p.mode = PS_SPLAT_TRIANGLES;
        p.radius = *radius;
        p.kernel_mean = s->kernel.mean;
        p.kernel_extent = s->kernel.extent;
        p.scale = (double)s->set.caps[k] / (double)emitted; /* radiance: exposure 1 */
        p.point_size = 1.0;
        p.precision = PS_PRECISION_NONE;
        p.levels = 0;
        p.materials = ps_session_materials(s);
        p.objects = s->set.stencil_clip ? m->objects : NULL;
        p.cam = *view;
        p.threads = s->set.threads;
        st = ps_splat_build(m->photons, m->materials, end, &p, b, err);
    }
    ps_feed_unlock(s->feed);
    return st;
}

void ps_session_env_fill(ps_session *s, ps_vec3 centre, int face_side, const size_t max_photons[PS_MAP_COUNT],
                         double fill[6])
{
    for (int f = 0; f < 6; f++)
        fill[f] = 0.0;
    double side = (double)face_side, most = side * side;
    ps_feed_lock(s->feed);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        size_t end;
        uint64_t emitted;
        double radius;
        env_prefix(s, (ps_map_kind)k, max_photons[k], &end, &emitted, &radius);
        const ps_photon *ph = ps_feed_maps(s->feed)[k].photons;
        for (size_t i = 0; i < end && emitted > 0; i++) {
            /* The face is the direction's largest axis (cube map order
             * +x, -x, +y, -y, +z, -z); the disc's distance along it sets its
             * size there (the face's focal length is half its side). */
            ps_vec3 d = ps_v3_sub(ps_photon_position(&ph[i]), centre);
            double ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
            int f = ax >= ay && ax >= az ? (d.x >= 0.0 ? 0 : 1) : ay >= az ? (d.y >= 0.0 ? 2 : 3) : (d.z >= 0.0 ? 4 : 5);
            double z = fmax(fmax(ax, ay), az), px = z > 0.0 ? radius * 0.5 * side / z : HUGE_VAL;
            fill[f] += fmin(PS_PI * px * px, most);
        }
    }
    ps_feed_unlock(s->feed);
}
double ps_session_radius(const ps_session *s, ps_map_kind k) { return s->splat_radius[k]; }

void ps_session_get_counts(ps_session *s, ps_session_counts *out)
{
    memset(out, 0, sizeof *out);
    ps_feed_lock(s->feed);
    const ps_photon_map *maps = ps_feed_maps(s->feed);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        const ps_photon_map *m = &maps[k];
        out->map[k] = m->counters;
        out->map_bytes += (double)ps_photon_map_bytes(m);
    }
    out->store_limited = ps_feed_store_limited(s->feed);
    out->ended = ps_feed_ended(s->feed);
    out->trace_seconds = ps_feed_seconds(s->feed); /* written under the lock, as a round ends */
    /* The first round's thread writes these under the lock (prime_main);
     * refreshes, which write them too, are the caller's own. */
    out->splat_seconds = s->splat_seconds;
    out->ahead_seconds = s->ahead_seconds;
    out->refreshes = s->refreshes;
    ps_feed_unlock(s->feed);
}

const ps_photon_map *ps_session_maps(const ps_session *s) { return ps_feed_maps(s->feed); }

const ps_photon_map *ps_session_lock_maps(ps_session *s)
{
    /* In index order once tracing ended (a dump compares with a fresh
     * trace's); an error is the feed's status (ps_session_status). */
    ps_error err;
    (void)ps_feed_merge(s->feed, &err);
    ps_feed_lock(s->feed);
    return ps_feed_maps(s->feed);
}

void ps_session_unlock_maps(ps_session *s) { ps_feed_unlock(s->feed); }

void ps_session_repair_counts(const ps_session *s, bool *repaired, uint64_t kept[PS_MAP_COUNT],
                              uint64_t retraced[PS_MAP_COUNT])
{
    /* The feed the last repair made (zeros while its tests go on). */
    ps_feed_repair_count rc;
    memset(&rc, 0, sizeof rc);
    if (s->repaired)
        rc = ps_feed_repair_counts(s->feed);
    *repaired = s->repaired;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        kept[k] = rc.kept[k];
        retraced[k] = rc.retraced[k];
    }
}

void ps_session_repair_totals(const ps_session *s, uint64_t *repairs, uint64_t kept[PS_MAP_COUNT],
                              uint64_t retraced[PS_MAP_COUNT])
{
    bool now;
    ps_session_repair_counts(s, &now, kept, retraced);
    *repairs = s->repairs_before + (now ? 1 : 0);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        kept[k] += s->kept_before[k], retraced[k] += s->retraced_before[k];
}
