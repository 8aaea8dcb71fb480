/* test_session.c: the preview's progressive policy (preview/session.h),
 * with no GL at all: which photons each refresh splats, with which gains,
 * when a view starts over, when the error counter stops shooting, what an
 * edit restarts, what a left-out layer skips, and the pixels the cube
 * faces' splats cover. */
#include "test.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/clock.h"
#include "photon/tracer.h"
#include "preview/feed.h"
#include "preview/session.h"
#include "preview/specular.h"
#include "scene/scene.h"
#include "specular_points.h"

#define SCENE "data/scenes/cornell-caustic.scn"
#define CAUSTIC_CAP 40000
#define GLOBAL_CAP 10000
#define EXPOSURE 0.3

#define AREA_SCENE "data/scenes/cornell-caustic-area.scn"

static ps_scene *load_path(const char *path)
{
    ps_scene *scene;
    ps_error err;
    if (ps_scene_load(path, NULL, &scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    return scene;
}

static ps_scene *load(void) { return load_path(SCENE); }

static ps_session_settings settings(const ps_scene *scene, bool incremental)
{
    ps_session_settings set = ps_session_default_settings(scene);
    set.caps[PS_MAP_CAUSTIC] = CAUSTIC_CAP;
    set.caps[PS_MAP_GLOBAL] = GLOBAL_CAP;
    set.seed = 5;
    set.threads = 2;
    set.exposure = EXPOSURE;
    set.float_buffer = incremental;
    set.incremental = incremental;
    return set;
}

/* Incremental, with progressive lights (the window's and snap's --time). */
static ps_session_settings progressive_settings(const ps_scene *scene)
{
    ps_session_settings set = settings(scene, true);
    set.progressive_lights = true;
    return set;
}

static ps_session *open_session(ps_scene *scene, const ps_session_settings *set)
{
    ps_session *s;
    ps_error err;
    if (ps_session_create(scene, set, &s, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    return s;
}

static ps_camera_frame camera(const ps_scene *scene)
{
    return ps_camera_frame_make(ps_scene_camera(scene), 64, 64);
}

static void refresh(ps_session *s, const ps_camera_frame *cam, ps_session_frame *f)
{
    ps_error err;
    if (ps_session_refresh(s, cam, f, &err) != PS_OK)
        fail_msg("refresh: %s", err.msg);
}

/* Sum of one colour channel over a batch's vertices. */
static double batch_sum(const ps_splat_batch *b)
{
    double sum = 0.0;
    for (size_t i = 0; i < b->vertex_count; i++)
        sum += b->colors[4 * i];
    return sum;
}

/* The red a batch asked for: what it sent (batch_sum, a splat's colour on
 * each of its vertices) and what error diffusion still carries. */
static double batch_wanted(const ps_splat_batch *b)
{
    double per = b->splats ? (double)b->vertex_count / (double)b->splats : 1.0;
    return batch_sum(b) + per * ps_splat_batch_carry(b, 0);
}

/* A session of set over scene, started in the background, and its first
 * refresh from the scene's camera (*cam) into *f. */
static ps_session *start_and_refresh(ps_scene *scene, const ps_session_settings *set, ps_camera_frame *cam,
                                     ps_session_frame *f)
{
    ps_session *s = open_session(scene, set);
    ps_error err;
    assert_int_equal(ps_session_start(s, true, &err), PS_OK);
    *cam = camera(scene);
    refresh(s, cam, f);
    return s;
}

/* Waits (at most `seconds`) until the feed has ended. */
static void wait_ended_within(ps_session *s, int seconds)
{
    ps_session_counts c;
    for (int i = 0; i < 200 * seconds; i++) {
        ps_session_get_counts(s, &c);
        if (c.ended)
            return;
        struct timespec ts = {0, 5000000};
        nanosleep(&ts, NULL);
    }
    fail_msg("the feed did not end within %d s", seconds);
}

static void wait_ended(ps_session *s) { wait_ended_within(s, 10); }

/* A session over scene whose caustic map holds cap_batches batches, all
 * traced, after a first refresh drawn at the rate (*rate) that makes the
 * caustic's budget budget_batches batches. tau is long, so that the budget
 * is a drawing time of seconds, against which building the splats (timed by
 * the session itself, and taken off: *built) is small even under the
 * sanitizers. */
static ps_session *at_budget(ps_scene *scene, int cap_batches, double budget_batches, ps_camera_frame *cam,
                             ps_session_frame *f, double *rate, double *built);

/* Tells the session the last refresh drew its splats at `rate` a second:
 * the drawing time that makes it, less the building the session timed
 * itself since *built (its splat_seconds then; updated). */
static void drawn_at_rate(ps_session *s, const ps_session_frame *f, double rate, double *built)
{
    ps_session_counts c;
    ps_session_get_counts(s, &c);
    ps_session_drawn(s, fmax(1e-3, (double)f->splats / rate - (c.splat_seconds - *built)));
    *built = c.splat_seconds;
}

static ps_session *at_budget(ps_scene *scene, int cap_batches, double budget_batches, ps_camera_frame *cam,
                             ps_session_frame *f, double *rate, double *built)
{
    ps_session_settings set = settings(scene, true);
    set.caps[PS_MAP_CAUSTIC] = (uint64_t)cap_batches * PS_FEED_BATCH;
    set.tau = 10.0;
    ps_session *s = start_and_refresh(scene, &set, cam, f);
    *rate = budget_batches * PS_FEED_BATCH * PS_MAP_COUNT / (set.tau * set.splat_share);
    *built = 0.0;
    drawn_at_rate(s, f, *rate, built);
    wait_ended(s);
    return s;
}

/* Whole refreshes: every photon, scaled by exposure N / n into layers cleared
 * first; the direct layer drawn at the exposure. */
static void whole_refresh_splats_everything(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, false);
    ps_session *s = open_session(scene, &set);
    ps_error err;
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    ps_camera_frame cam = camera(scene);
    ps_session_frame f;
    refresh(s, &cam, &f);
    assert_true(f.new_view);
    assert_true(f.direct);
    assert_near(f.direct_exposure, EXPOSURE, 0.0);
    assert_near(f.direct_gain, 1.0, 0.0);
    const ps_photon_map *maps = ps_session_maps(s);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_int_equal(f.emitted[k], set.caps[k]);
        assert_true(f.map[k].clear);
        assert_near(f.map[k].gain, 1.0, 0.0);
        assert_true(f.map[k].batch->splats > 0);
        assert_true(f.map[k].batch->splats <= maps[k].count);
    }
    /* The same camera: no new view, the same splats, built afresh. */
    double sum = batch_sum(f.map[PS_MAP_CAUSTIC].batch), wanted = batch_wanted(f.map[PS_MAP_CAUSTIC].batch);
    refresh(s, &cam, &f);
    assert_false(f.new_view);
    assert_near(batch_sum(f.map[PS_MAP_CAUSTIC].batch), sum, 0.0);
    /* Another camera: a new view. */
    cam.eye.x += 0.1;
    refresh(s, &cam, &f);
    assert_true(f.new_view);
    /* Exposure is in the splats: doubling it doubles them and redraws. */
    ps_session_set_exposure(s, 2.0 * EXPOSURE);
    refresh(s, &cam, &f);
    assert_true(f.new_view);
    assert_near(f.direct_exposure, 2.0 * EXPOSURE, 0.0);
    cam.eye.x -= 0.1;
    refresh(s, &cam, &f);
    /* 8-bit codes with error diffusion: what was sent and what is carried
     * add up to what was asked, twice the first (float rounding aside). */
    assert_near(batch_wanted(f.map[PS_MAP_CAUSTIC].batch), 2.0 * wanted, 1e-6 * wanted);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* A whole refresh's cap (photosplat-snap's checkpoints, app/pace.h): a
 * prefix of each map ending at a batch the feed handed over, scaled by N / n
 * for the photons it holds: the splats of a session whose caps were that
 * prefix, vertex for vertex (photon i is the same whatever the cap), and the
 * same colour within 10^-4 (a photon's power is 1 / its stratum's count,
 * which rounds differently for another cap: 2*10^-5 here). 1 again: every
 * photon. */
static void whole_cap_draws_a_prefix(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, false);
    set.float_buffer = true; /* whole, in float: the colours are the photons' own */
    ps_session *s = open_session(scene, &set);
    ps_error err;
    assert_int_equal(ps_session_start(s, false, &err), PS_OK);
    wait_ended(s);
    ps_camera_frame cam = camera(scene);
    ps_session_frame f;
    double half[PS_MAP_COUNT] = {0.5 * (double)set.caps[0], 0.5 * (double)set.caps[1]};
    ps_session_set_whole_most(s, half);
    refresh(s, &cam, &f);
    uint64_t part[PS_MAP_COUNT];
    double sums[PS_MAP_COUNT];
    size_t splats[PS_MAP_COUNT];
    float *where[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        part[k] = f.emitted[k];
        assert_true(part[k] > 0);
        assert_true(part[k] <= set.caps[k] / 2);
        sums[k] = batch_sum(f.map[k].batch);
        splats[k] = f.map[k].batch->splats;
        size_t bytes = sizeof(float) * 3 * f.map[k].batch->vertex_count;
        where[k] = malloc(bytes);
        assert_non_null(where[k]);
        memcpy(where[k], f.map[k].batch->positions, bytes);
        assert_true(sums[k] > 0.0);
    }
    /* A cap at exactly what it drew: that prefix again (a later checkpoint never shows fewer). */
    double again[PS_MAP_COUNT] = {(double)part[0], (double)part[1]};
    ps_session_set_whole_most(s, again);
    refresh(s, &cam, &f);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        assert_int_equal(f.emitted[k], part[k]);
    /* All of them again. */
    ps_session_set_whole_most(s, NULL);
    refresh(s, &cam, &f);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        assert_int_equal(f.emitted[k], set.caps[k]);
    ps_session_destroy(s);
    /* The same splats from a session traced to that prefix. */
    ps_session_settings cut = set;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        cut.caps[k] = part[k];
    s = open_session(scene, &cut);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    refresh(s, &cam, &f);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_int_equal(f.emitted[k], part[k]);
        assert_int_equal(f.map[k].batch->splats, splats[k]);
        assert_memory_equal(f.map[k].batch->positions, where[k], sizeof(float) * 3 * f.map[k].batch->vertex_count);
        assert_near(batch_sum(f.map[k].batch), sums[k], 1e-4 * sums[k]);
        free(where[k]);
    }
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* Incremental refreshes: the first shows the first round (the feed held
 * until it is drawn), later ones only batches not drawn yet, at stored power,
 * with the gain exposure N / n in the composite; together they splat every
 * photon exactly once, as one whole refresh would. */
static void incremental_refresh_splats_each_photon_once(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    ps_camera_frame cam;
    ps_session_frame f;
    ps_session *s = start_and_refresh(scene, &set, &cam, &f);
    assert_true(f.new_view);
    assert_near(f.direct_exposure, 1.0, 0.0);
    assert_near(f.direct_gain, EXPOSURE, 0.0);
    /* The first round: PS_FEED_BATCH photons of the larger map, the other in proportion. */
    assert_int_equal(f.emitted[PS_MAP_CAUSTIC], PS_FEED_BATCH);
    assert_int_equal(f.emitted[PS_MAP_GLOBAL], PS_FEED_BATCH / 4);
    assert_near(f.map[PS_MAP_CAUSTIC].gain, EXPOSURE * CAUSTIC_CAP / (double)PS_FEED_BATCH, 1e-12);
    assert_false(f.map[PS_MAP_CAUSTIC].clear);
    double sum[PS_MAP_COUNT];
    size_t splats[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        sum[k] = batch_sum(f.map[k].batch);
        splats[k] = f.map[k].batch->splats;
    }
    /* Held until drawn: nothing new arrives. */
    refresh(s, &cam, &f);
    assert_false(f.new_view);
    assert_int_equal(f.splats, 0);
    ps_session_drawn(s, 0.001);
    wait_ended(s);
    for (int i = 0; i < 1000 && !ps_session_settled(s); i++) {
        refresh(s, &cam, &f);
        ps_session_drawn(s, 0.001);
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            sum[k] += batch_sum(f.map[k].batch);
            splats[k] += f.map[k].batch->splats;
        }
    }
    assert_true(ps_session_settled(s));
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_int_equal(f.emitted[k], set.caps[k]);
        assert_near(f.map[k].gain, EXPOSURE, 1e-12);
    }
    ps_error err;
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);

    /* One whole refresh of the same photons (in float: the same smooth
     * kernel): the same splats, scaled by the exposure (N / n = 1 at the caps). */
    set = settings(scene, false);
    set.float_buffer = true;
    s = open_session(scene, &set);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    refresh(s, &cam, &f);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_int_equal(f.map[k].batch->splats, splats[k]);
        assert_near(batch_sum(f.map[k].batch), EXPOSURE * sum[k], 1e-4 * EXPOSURE * sum[k]);
    }
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* The budget: a refresh that took long makes the next draw one batch, not all. */
static void budget_bounds_a_refresh(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    set.caps[PS_MAP_CAUSTIC] = 4 * PS_FEED_BATCH;
    ps_camera_frame cam;
    ps_session_frame f;
    ps_session *s = start_and_refresh(scene, &set, &cam, &f);
    /* A second per splat: the budget falls to its floor, PS_SESSION_BUDGET_MIN. */
    ps_session_drawn(s, (double)f.splats);
    wait_ended(s);
    uint64_t before = f.emitted[PS_MAP_CAUSTIC];
    refresh(s, &cam, &f);
    /* One batch more, however many have arrived. */
    assert_int_equal(f.emitted[PS_MAP_CAUSTIC], before + PS_FEED_BATCH);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* ps_session_set_budget_share: the next refreshes draw that share of the
 * budget (at least a batch), until set again (photosplat-snap's float
 * checkpoints' frames: pace.h). */
static void budget_share_draws_a_share(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_camera_frame cam;
    ps_session_frame f;
    double rate, built;
    ps_session *s = at_budget(scene, 12, 4.8, &cam, &f, &rate, &built);
    uint64_t before = f.emitted[PS_MAP_CAUSTIC];
    ps_session_set_budget_share(s, 0.25); /* 1.2 batches: one */
    refresh(s, &cam, &f);
    assert_int_equal(f.emitted[PS_MAP_CAUSTIC], before + PS_FEED_BATCH);
    drawn_at_rate(s, &f, rate, &built);
    refresh(s, &cam, &f); /* still a share */
    assert_int_equal(f.emitted[PS_MAP_CAUSTIC], before + 2 * PS_FEED_BATCH);
    drawn_at_rate(s, &f, rate, &built);
    ps_session_set_budget_share(s, 1.0); /* the whole budget again: four */
    refresh(s, &cam, &f);
    assert_true(f.emitted[PS_MAP_CAUSTIC] >= before + 6 * PS_FEED_BATCH);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* Waits (at most 15 s: the sanitizers' batches, under a loaded suite) until
 * the caustic map holds the same photons for 0.2 s: the feed paused or
 * ended. Returns its stored count. */
static uint64_t wait_still(ps_session *s)
{
    ps_session_counts a, b;
    ps_session_get_counts(s, &a);
    for (int i = 0; i < 75; i++) {
        struct timespec ts = {0, 200000000};
        nanosleep(&ts, NULL);
        ps_session_get_counts(s, &b);
        if (b.map[PS_MAP_CAUSTIC].stored == a.map[PS_MAP_CAUSTIC].stored)
            return b.map[PS_MAP_CAUSTIC].stored;
        a = b;
    }
    fail_msg("the tracer did not wait within 15 s");
    return 0;
}

/* photosplat-snap's float layers (backlog_refreshes): the tracer waits while
 * a map holds more photons not drawn than that many refreshes' budgets, and
 * goes on as the refreshes draw them, to the cap. Without the setting it
 * runs to the cap however far behind the drawing is. The bound holds with
 * no refresh to look at it (it was looked at only as a refresh drew: in
 * one long refresh the mirror box's tracer ran 2*10^5 photons past it). */
static void backlog_holds_the_tracer(void **state)
{
    (void)state;
    ps_scene *scene = load();
    for (int held = 0; held < 2; held++) {
        ps_session_settings set = settings(scene, true);
        set.caps[PS_MAP_CAUSTIC] = 40 * PS_FEED_BATCH;
        /* A tenth of a budget: under one round's stored photons (the budget
         * starts at PS_SESSION_BUDGET_START; the first refresh, with
         * llvmpipe's compiles, teaches it nothing). */
        set.backlog_refreshes = held ? 0.1 : 0.0;
        ps_camera_frame cam;
        ps_session_frame f;
        ps_session *s = start_and_refresh(scene, &set, &cam, &f);
        /* From the next refresh on, a second per splat: the budget at its
         * floor, a batch a refresh. */
        ps_session_drawn(s, (double)f.splats);
        ps_session_counts c;
        if (!held) {
            wait_ended_within(s, 60); /* to the cap (the sanitizers' pace, a loaded suite) */
            ps_session_get_counts(s, &c);
            assert_int_equal(c.map[PS_MAP_CAUSTIC].emitted, set.caps[PS_MAP_CAUSTIC]);
        } else {
            /* The round that crosses the bound first (a round may take longer
             * than wait_still's 0.2 s under the sanitizers in a loaded suite:
             * still, seen too soon, at the first round's count) ... */
            for (int i = 0; i < 1500; i++) {
                ps_session_get_counts(s, &c);
                if (c.map[PS_MAP_CAUSTIC].emitted >= f.emitted[PS_MAP_CAUSTIC] + PS_FEED_BATCH)
                    break;
                struct timespec ts = {0, 10000000};
                nanosleep(&ts, NULL);
            }
            uint64_t still = wait_still(s);
            ps_session_get_counts(s, &c);
            /* ... then waiting, well short of the cap, with no refresh since:
             * the bound is under a round's photons past what was drawn, so
             * by that round alone ... */
            assert_false(c.ended);
            assert_int_equal(c.map[PS_MAP_CAUSTIC].emitted, f.emitted[PS_MAP_CAUSTIC] + PS_FEED_BATCH);
            /* ... and going on as the refreshes draw what waits (for up to
             * 60 s: 4000 refreshes were too few under the sanitizers beside
             * two busy loops). */
            double until = ps_now_seconds() + 60.0;
            while (!c.ended && ps_now_seconds() < until) {
                refresh(s, &cam, &f);
                ps_session_drawn(s, (double)f.splats);
                struct timespec ts = {0, 1000000};
                nanosleep(&ts, NULL);
                ps_session_get_counts(s, &c);
            }
            assert_true(c.ended);
            assert_true(c.map[PS_MAP_CAUSTIC].stored > still);
            assert_int_equal(c.map[PS_MAP_CAUSTIC].emitted, set.caps[PS_MAP_CAUSTIC]);
        }
        ps_session_destroy(s);
    }
    ps_scene_destroy(scene);
}

/* Tracing threads: those asked for; else every core, but one left to
 * drawing where refreshes draw while tracing goes on. */
static void tracing_threads_leave_a_core_to_drawing(void **state)
{
    (void)state;
    assert_int_equal(ps_session_tracing_threads(3, true), 3);
    assert_int_equal(ps_session_tracing_threads(3, false), 3);
    assert_int_equal(ps_session_tracing_threads(0, false), 0);
    int cores = ps_online_cores();
    assert_int_equal(ps_session_tracing_threads(0, true), cores > 1 ? cores - 1 : 0);
}

/* The error counter (thesis 5.1): in 8 bits, once a refresh loses more than
 * the threshold to round-off, tracing stops and says at how many photons. */
static void counter_stops_shooting(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, false);
    set.precision = PS_PRECISION_COUNTER;
    set.counter_threshold = 1e-6;
    ps_camera_frame cam;
    ps_session_frame f;
    ps_session *s = start_and_refresh(scene, &set, &cam, &f);
    assert_true(f.round_off > set.counter_threshold);
    uint64_t at = 0;
    assert_false(ps_session_counter_stopped(s, NULL));
    ps_session_drawn(s, 0.001);
    assert_true(ps_session_counter_stopped(s, &at));
    assert_int_equal(at, f.emitted[0] + f.emitted[1]);
    /* Stopped for good: settled, and nothing more is traced. */
    assert_true(ps_session_settled(s));
    struct timespec ts = {0, 50000000};
    nanosleep(&ts, NULL);
    ps_session_counts c;
    ps_session_get_counts(s, &c);
    assert_true(c.map[PS_MAP_CAUSTIC].emitted <= 2 * PS_FEED_BATCH); /* at most the batch under way */
    /* Diffusion keeps the light: the same refresh loses less, and goes on. */
    ps_session_set_precision(s, PS_PRECISION_DIFFUSION);
    refresh(s, &cam, &f);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* An edit restarts the maps from photon 0 with the edited scene; geometry
 * rebuilds the meshes, a light only the lights; a refused edit changes nothing. */
static void edits_restart_the_maps(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, false);
    set.repair = false; /* the restart; test_repair checks the selective repair */
    ps_session *s = open_session(scene, &set);
    ps_error err;
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    ps_camera_frame cam = camera(scene);
    ps_session_frame f;
    refresh(s, &cam, &f);
    assert_false(ps_session_edited(s));
    assert_int_equal(ps_session_move_light(s, 7, ps_v3(0, 1, 0), &err), PS_ERR_RANGE);
    assert_false(ps_session_edited(s));
    assert_int_equal(ps_session_move_light(s, 0, ps_v3(0.3, 1.8, 0), &err), PS_OK);
    assert_true(ps_session_edited(s));
    ps_session_changes ch;
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    assert_false(ch.geometry);
    assert_false(ps_session_edited(s));
    assert_int_equal(ps_session_edits(s), 1);
    assert_near(ps_session_lights(s)->lights[0].pos.x, 0.3, 0.0);
    ps_session_counts c;
    ps_session_get_counts(s, &c);
    assert_int_equal(c.map[PS_MAP_CAUSTIC].emitted, 0); /* freed: a new feed from photon 0 */
    refresh(s, &cam, &f);
    assert_true(f.new_view);
    assert_int_equal(f.splats, 0);
    /* The restarted maps are a fresh trace's of the edited scene. */
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    refresh(s, &cam, &f);
    assert_int_equal(f.emitted[PS_MAP_CAUSTIC], CAUSTIC_CAP);
    /* Moving an object rebuilds the meshes: the sphere's vertices move. */
    size_t nobj;
    (void)ps_scene_objects(ps_session_scene(s), &nobj);
    float x0 = ps_session_mesh(s)->positions[3 * (ps_session_mesh(s)->vertex_count - 1)];
    assert_int_equal(ps_session_move_object(s, nobj - 1, ps_v3(0.1, 0, 0), &err), PS_OK);
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    assert_true(ch.geometry);
    float x1 = ps_session_mesh(s)->positions[3 * (ps_session_mesh(s)->vertex_count - 1)];
    assert_near(x1 - x0, 0.1, 1e-5);
    assert_int_equal(ps_session_edits(s), 2);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* A layer left out is not traced when the session skips hidden layers (snap),
 * and says so; shown or not, the window traces it. */
static void hidden_layers_are_skipped(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, false);
    set.layers = PS_LAYER_CAUSTIC;
    set.skip_hidden = true;
    ps_session *s = open_session(scene, &set);
    ps_error err;
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    ps_session_counts c;
    ps_session_get_counts(s, &c);
    assert_int_equal(c.map[PS_MAP_GLOBAL].emitted, 0);
    assert_int_equal(c.map[PS_MAP_CAUSTIC].emitted, CAUSTIC_CAP);
    size_t n;
    const ps_skip *skips = ps_tracer_skips(ps_session_tracer(s), &n);
    int global = 0, direct = 0;
    for (size_t i = 0; i < n; i++) {
        global += strcmp(skips[i].pass, "global") == 0 && strstr(skips[i].reason, "--layers") != NULL;
        direct += strcmp(skips[i].pass, "direct") == 0;
    }
    assert_int_equal(global, 1);
    assert_int_equal(direct, 1);
    ps_camera_frame cam = camera(scene);
    ps_session_frame f;
    refresh(s, &cam, &f);
    assert_false(f.direct);
    assert_near(f.map[PS_MAP_GLOBAL].gain, 0.0, 0.0);
    ps_session_destroy(s);

    set.skip_hidden = false;
    s = open_session(scene, &set);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    ps_session_get_counts(s, &c);
    assert_int_equal(c.map[PS_MAP_GLOBAL].emitted, GLOBAL_CAP);
    refresh(s, &cam, &f);
    assert_near(f.map[PS_MAP_GLOBAL].gain, 0.0, 0.0); /* traced, not shown */
    assert_int_equal(f.map[PS_MAP_GLOBAL].batch->splats, 0);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* The radius schedule: fixed keeps r0; progressive shrinks it as photons arrive. */
static void radius_follows_the_schedule(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, false);
    set.radius_schedule = PS_RADIUS_PROGRESSIVE;
    ps_session *s = open_session(scene, &set);
    ps_error err;
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    ps_camera_frame cam = camera(scene);
    ps_session_frame f;
    refresh(s, &cam, &f);
    const ps_scene_defaults *d = ps_scene_get_defaults(scene);
    double want = ps_splat_radius_at(PS_RADIUS_PROGRESSIVE, set.radius[PS_MAP_CAUSTIC], (uint64_t)d->caustic_photons,
                                     CAUSTIC_CAP, set.radius_alpha);
    assert_near(ps_session_radius(s, PS_MAP_CAUSTIC), want, 1e-15);
    assert_near(f.map[PS_MAP_CAUSTIC].radius, want, 1e-15);
    /* A new r0 starts the view over. */
    ps_session_set_radius(s, PS_MAP_CAUSTIC, 2.0 * set.radius[PS_MAP_CAUSTIC]);
    refresh(s, &cam, &f);
    assert_true(f.new_view);
    assert_near(f.map[PS_MAP_CAUSTIC].radius, 2.0 * want, 1e-15);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* A moving camera (incremental): each refresh with a new camera is a level
 * of detail (a prefix of the budget's share, its radius grown for the
 * photons left out); the first refresh with the camera still starts over at
 * full detail. */
static void moving_camera_level_of_detail(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    set.caps[PS_MAP_CAUSTIC] = 4 * PS_FEED_BATCH;
    ps_camera_frame cam;
    ps_session_frame f;
    ps_session *s = start_and_refresh(scene, &set, &cam, &f);
    assert_false(f.moving); /* the first view is no move */
    ps_session_drawn(s, 100.0); /* slow: the budget at its floor, a batch a refresh */
    wait_ended(s);
    cam.eye.x += 0.05;
    refresh(s, &cam, &f);
    assert_true(f.moving);
    assert_true(f.new_view);
    /* Drawn at fewer pixels, the same view. */
    assert_int_equal(f.view.width, (cam.width + PS_SESSION_MOVING_SCALE - 1) / PS_SESSION_MOVING_SCALE);
    assert_int_equal(f.view.height, (cam.height + PS_SESSION_MOVING_SCALE - 1) / PS_SESSION_MOVING_SCALE);
    assert_true(f.view.width < cam.width);
    assert_memory_equal(&f.view.eye, &cam.eye, sizeof cam.eye);
    assert_true(f.view.aspect == cam.aspect && f.view.tan_half_fov == cam.tan_half_fov);
    /* One batch of the four that arrived: the radius grown by sqrt(4) = 2. */
    assert_int_equal(f.emitted[PS_MAP_CAUSTIC], PS_FEED_BATCH);
    assert_near(f.map[PS_MAP_CAUSTIC].radius, 2.0 * set.radius[PS_MAP_CAUSTIC], 1e-12);
    assert_near(f.map[PS_MAP_CAUSTIC].gain, EXPOSURE * 4.0, 1e-12);
    /* Still: full detail again, from a new view. */
    refresh(s, &cam, &f);
    assert_false(f.moving);
    assert_true(f.new_view);
    assert_memory_equal(&f.view, &cam, sizeof cam);
    assert_near(f.map[PS_MAP_CAUSTIC].radius, set.radius[PS_MAP_CAUSTIC], 1e-12);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* The level of detail's growth is held at PS_SESSION_MOVING_GROWTH_MAX: one
 * batch of nine that arrived asks for sqrt(9) = 3 r and gets 2 r (a grown
 * splat's pixels set a moving frame's time), still scaled by N / n; the
 * specular layer's vertices while moving are a share of the still ones. */
static void moving_growth_held(void **state)
{
    (void)state;
    assert_true(PS_SESSION_MOVING_GROWTH_MAX < 3.0 && PS_SESSION_MOVING_GROWTH_MAX >= 1.0);
    assert_true(PS_SESSION_SPECULAR_VERTICES_MOVING < PS_SESSION_SPECULAR_VERTICES);
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    set.caps[PS_MAP_CAUSTIC] = 9 * PS_FEED_BATCH;
    ps_camera_frame cam;
    ps_session_frame f;
    ps_session *s = start_and_refresh(scene, &set, &cam, &f);
    ps_session_drawn(s, 100.0); /* the budget at its floor: a batch a refresh */
    wait_ended(s);
    cam.eye.x += 0.05;
    refresh(s, &cam, &f);
    assert_true(f.moving);
    assert_int_equal(f.emitted[PS_MAP_CAUSTIC], PS_FEED_BATCH);
    assert_near(f.map[PS_MAP_CAUSTIC].radius, PS_SESSION_MOVING_GROWTH_MAX * set.radius[PS_MAP_CAUSTIC], 1e-12);
    assert_near(f.map[PS_MAP_CAUSTIC].gain, EXPOSURE * 9.0, 1e-12);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* While the camera moves the global map's layer is drawn at half the view's
 * pixels (ps_session_layer.shrink) where its triangle splats grew 2x (their
 * pixels then as many as a full-detail splat's), never the caustic layer;
 * not when the growth is less (few photons arrived: the level of detail
 * draws most of them), nor for points, nor once the camera is still. The
 * lit mesh while moving is the lighter one only in incremental sessions. */
static void moving_global_layer_shrunk(void **state)
{
    (void)state;
    ps_scene *scene = load();
    for (int pass = 0; pass < 3; pass++) {
        /* 0: triangles, 9 batches of global photons (sqrt(9) > 2); 1: the
         * same as points; 2: triangles, as many global photons as one
         * batch of the caustic's share draws (no growth). */
        ps_session_settings set = settings(scene, true);
        set.caps[PS_MAP_CAUSTIC] = 9 * PS_FEED_BATCH;
        set.caps[PS_MAP_GLOBAL] = pass == 2 ? 1024 : 9 * PS_FEED_BATCH;
        set.splat = pass == 1 ? PS_SPLAT_POINTS : PS_SPLAT_TRIANGLES;
        ps_camera_frame cam;
        ps_session_frame f;
        ps_session *s = start_and_refresh(scene, &set, &cam, &f);
        assert_true(ps_session_moving_mesh(s)->vertex_count < ps_session_mesh(s)->vertex_count);
        ps_session_drawn(s, 100.0);
        wait_ended(s);
        cam.eye.x += 0.05;
        refresh(s, &cam, &f);
        assert_true(f.moving && !f.edit_lod);
        double growth = f.map[PS_MAP_GLOBAL].radius / set.radius[PS_MAP_GLOBAL];
        assert_true(pass == 2 ? growth < PS_SESSION_MOVING_GLOBAL_SHRINK : growth >= PS_SESSION_MOVING_GLOBAL_SHRINK);
        assert_int_equal(f.map[PS_MAP_GLOBAL].shrink, pass == 0 ? PS_SESSION_MOVING_GLOBAL_SHRINK : 1);
        assert_int_equal(f.map[PS_MAP_CAUSTIC].shrink, 1);
        refresh(s, &cam, &f); /* still */
        assert_false(f.moving);
        assert_int_equal(f.map[PS_MAP_GLOBAL].shrink, 1);
        assert_int_equal(f.map[PS_MAP_CAUSTIC].shrink, 1);
        ps_session_destroy(s);
    }
    /* Whole refreshes of a fixed count draw no level of detail: no second
     * mesh. With progressive lights (snap's 8-bit --time) their coarse
     * levels draw it (ps_session_lights_coarse). */
    ps_session_settings set = settings(scene, false);
    ps_session *s = open_session(scene, &set);
    assert_ptr_equal(ps_session_moving_mesh(s), ps_session_mesh(s));
    ps_session_destroy(s);
    set.progressive_lights = true;
    s = open_session(scene, &set);
    assert_true(ps_session_moving_mesh(s)->vertex_count < ps_session_mesh(s)->vertex_count);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* A splat as bytes: its vertices' positions and its colour (the same on each
 * vertex), for comparing splat sets whatever their order. */
enum { SPLAT_RECORD_FLOATS = 3 * 3 + 4 };
typedef struct splat_records {
    float *v;
    size_t n, cap;
} splat_records;

static void records_add(splat_records *r, const ps_splat_batch *b)
{
    size_t per = b->splats ? b->vertex_count / b->splats : 1;
    assert_true(per >= 1 && per <= 3);
    for (size_t i = 0; i < b->splats; i++) {
        if (r->n == r->cap) {
            r->cap = r->cap ? 2 * r->cap : 4096;
            r->v = realloc(r->v, r->cap * SPLAT_RECORD_FLOATS * sizeof *r->v);
            assert_non_null(r->v);
        }
        float *out = r->v + r->n++ * SPLAT_RECORD_FLOATS;
        memset(out, 0, SPLAT_RECORD_FLOATS * sizeof *out);
        memcpy(out, b->positions + 3 * per * i, 3 * per * sizeof *out);
        memcpy(out + 9, b->colors + 4 * per * i, 4 * sizeof *out);
    }
}

static int cmp_record(const void *a, const void *b) { return memcmp(a, b, SPLAT_RECORD_FLOATS * sizeof(float)); }

/* After a camera move, the view starts over when the camera stops and is
 * drawn over several refreshes (a batch each here: the budget at its floor),
 * each showing what it has with the gain N / n; once settled, the refreshes
 * have splatted exactly the splats one whole refresh of every photon gives
 * for that view, byte for byte (exposure 1, so both scale by 1). */
static void after_the_stop_converges_to_the_whole_view(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    set.exposure = 1.0;
    ps_camera_frame cam;
    ps_session_frame f;
    ps_session *s = start_and_refresh(scene, &set, &cam, &f);
    ps_session_drawn(s, 100.0);
    wait_ended(s);
    cam.eye.x += 0.05;
    refresh(s, &cam, &f);
    assert_true(f.moving);
    ps_session_drawn(s, 100.0);
    splat_records got = {0}, want = {0};
    int refreshes = 0;
    for (int i = 0; i < 1000 && !ps_session_settled(s); i++) {
        refresh(s, &cam, &f);
        assert_false(f.moving);
        assert_true(f.new_view == (i == 0));
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            records_add(&got, f.map[k].batch);
            if (f.emitted[k] > 0) /* the partial sum's gain: N / n of what it shows */
                assert_near(f.map[k].gain, (double)set.caps[k] / (double)f.emitted[k], 1e-12);
        }
        ps_session_drawn(s, 100.0);
        refreshes++;
    }
    assert_true(ps_session_settled(s));
    assert_true(refreshes > 2); /* spread over refreshes, not one */
    ps_error err;
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);

    set = settings(scene, false);
    set.float_buffer = true;
    set.exposure = 1.0;
    s = open_session(scene, &set);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    refresh(s, &cam, &f);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        records_add(&want, f.map[k].batch);
    ps_session_destroy(s);
    assert_int_equal(got.n, want.n);
    qsort(got.v, got.n, SPLAT_RECORD_FLOATS * sizeof(float), cmp_record);
    qsort(want.v, want.n, SPLAT_RECORD_FLOATS * sizeof(float), cmp_record);
    assert_memory_equal(got.v, want.v, got.n * SPLAT_RECORD_FLOATS * sizeof(float));
    free(got.v);
    free(want.v);
    ps_scene_destroy(scene);
}


/* After a camera move, the first still refresh draws the budget (the camera
 * may only have paused between two steps), the next ones
 * PS_SESSION_CATCH_UP_GAIN times it, until the view is whole again. */
static void catch_up_after_the_first_still_refresh(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_camera_frame cam;
    ps_session_frame f;
    /* The caustic's budget 1.6 batches: one batch a refresh, 4.8 (four)
     * when caught up (two at the gain of 1.6). */
    double rate, built;
    ps_session *s = at_budget(scene, 8, 1.6, &cam, &f, &rate, &built);
    cam.eye.x += 0.05;
    refresh(s, &cam, &f);
    assert_true(f.moving);
    ps_session_drawn(s, 1.0);
    ps_session_counts c;
    ps_session_get_counts(s, &c);
    built = c.splat_seconds;
    refresh(s, &cam, &f); /* the same camera again: still */
    assert_false(f.moving);
    assert_true(f.new_view);
    assert_int_equal(f.emitted[PS_MAP_CAUSTIC], PS_FEED_BATCH);
    drawn_at_rate(s, &f, rate, &built);
    refresh(s, &cam, &f);
    assert_true(f.emitted[PS_MAP_CAUSTIC] >= 4 * PS_FEED_BATCH); /* the first and three more */
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* The refreshes after a stop wait for no tau (ps_session_catching_up) only
 * while the view is drawn again and nothing is traced: not while moving, not
 * once the view is whole, not while the tracer runs (unless paused). */
static void catching_up_only_when_nothing_is_traced(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_camera_frame cam;
    ps_session_frame f;
    double rate, built;
    ps_session *s = at_budget(scene, 8, 1.6, &cam, &f, &rate, &built); /* traced to the end */
    assert_false(ps_session_catching_up(s));
    cam.eye.x += 0.05;
    refresh(s, &cam, &f);
    assert_true(f.moving);
    assert_false(ps_session_catching_up(s));
    ps_session_drawn(s, 1.0);
    int refreshes = 0;
    for (; refreshes < 100 && !ps_session_settled(s); refreshes++) {
        refresh(s, &cam, &f); /* the same camera: still, the view drawn again */
        assert_false(f.moving);
        bool whole = ps_session_settled(s);
        assert_true(ps_session_catching_up(s) == !whole);
        drawn_at_rate(s, &f, rate, &built);
    }
    assert_true(refreshes > 1); /* it did catch up over refreshes */
    assert_false(ps_session_catching_up(s));
    ps_session_destroy(s);

    /* Still tracing: the tau schedule leaves the tracer its time. */
    ps_session_settings set = settings(scene, true);
    set.caps[PS_MAP_CAUSTIC] = 8000000; /* seconds of tracing: never ended by the checks below */
    set.caps[PS_MAP_GLOBAL] = 2000000;
    s = start_and_refresh(scene, &set, &cam, &f);
    ps_session_drawn(s, 1e3); /* drawn slowly: a budget of the least, one batch */
    cam.eye.x += 0.05;
    refresh(s, &cam, &f);
    ps_session_drawn(s, 1e3);
    ps_session_counts c;
    for (int i = 0; i < 2000; i++) { /* more stored than one still refresh draws */
        ps_session_get_counts(s, &c);
        if (c.map[PS_MAP_CAUSTIC].emitted >= 8 * PS_FEED_BATCH)
            break;
        struct timespec ts = {0, 5000000};
        nanosleep(&ts, NULL);
    }
    refresh(s, &cam, &f);
    assert_false(f.moving);
    assert_true(f.new_view);
    assert_false(ps_session_settled(s));
    assert_false(ps_session_catching_up(s));
    ps_session_set_paused(s, true); /* held: nothing traced meanwhile */
    assert_true(ps_session_catching_up(s));
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* After a moving camera's picture the next refresh is due sooner
 * (PS_SESSION_STILL_SHARE of tau), else a tau after the last; and a moving
 * picture is never the settled view, even one that drew every photon (maps
 * of one batch, their level of detail all of them). */
static void still_view_due_sooner_after_a_move(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    set.caps[PS_MAP_CAUSTIC] = PS_FEED_BATCH / 4;
    set.caps[PS_MAP_GLOBAL] = PS_FEED_BATCH / 4;
    ps_camera_frame cam;
    ps_session_frame f;
    ps_session *s = start_and_refresh(scene, &set, &cam, &f);
    ps_session_drawn(s, 0.01);
    wait_ended(s);
    for (int i = 0; i < 10 && !ps_session_settled(s); i++) {
        refresh(s, &cam, &f);
        ps_session_drawn(s, 0.01);
    }
    assert_true(ps_session_settled(s));
    assert_near(ps_session_next_refresh(s, 10.0), 10.0 + set.tau, 1e-12);
    cam.eye.x += 0.05;
    refresh(s, &cam, &f);
    ps_session_drawn(s, 0.01);
    assert_true(f.moving);
    ps_session_counts c;
    ps_session_get_counts(s, &c);
    assert_true(f.emitted[PS_MAP_CAUSTIC] == c.map[PS_MAP_CAUSTIC].emitted); /* all of them drawn */
    assert_false(ps_session_settled(s));
    assert_near(ps_session_next_refresh(s, 10.0), 10.0 + PS_SESSION_STILL_SHARE * set.tau, 1e-12);
    refresh(s, &cam, &f); /* still: the full view */
    ps_session_drawn(s, 0.01);
    assert_false(f.moving);
    assert_true(f.new_view);
    assert_true(ps_session_settled(s));
    assert_near(ps_session_next_refresh(s, 10.0), 10.0 + set.tau, 1e-12);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* While the program waits after a moving picture (ps_session_prepare_still),
 * the still view's specular lookups for that eye, then its per-pixel paths,
 * are traced a little a call, and are the ones the still refresh would have
 * traced: the same bytes as in a session that waited idle; nothing to do
 * while the camera is still, nor while photons are traced. */
static size_t lookup_vertices(ps_session *s)
{
    const struct ps_specular *sp = ps_session_specular(s);
    size_t nr = ps_specular_range_count(sp);
    assert_true(nr > 0);
    const ps_specular_range *r = &ps_specular_ranges(sp)[nr - 1];
    return r->offset + ps_session_mesh(s)->ranges[r->range].count;
}

/* The first round on threads of its own (settings.first_round_threads,
 * every core in both programs, where the tracing after it leaves one to the
 * drawing): the same photons, and the tracer's threads after it as set. */
static void first_round_on_its_own_threads(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    set.threads = 1;
    ps_session *s[2];
    ps_error err;
    for (int v = 0; v < 2; v++) {
        set.first_round_threads = v == 0 ? 1 : 2;
        s[v] = open_session(scene, &set);
        /* Held until a refresh is drawn: the maps are the first round. */
        assert_int_equal(ps_session_start(s[v], true, &err), PS_OK);
        assert_int_equal(ps_tracer_threads(ps_session_tracer(s[v])), 1);
    }
    const ps_photon_map *m[2];
    for (int v = 0; v < 2; v++)
        m[v] = ps_session_lock_maps(s[v]);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_true(m[0][k].count > 0);
        assert_int_equal(m[0][k].count, m[1][k].count);
        assert_memory_equal(m[0][k].photons, m[1][k].photons, m[0][k].count * sizeof(ps_photon));
    }
    for (int v = 0; v < 2; v++) {
        ps_session_unlock_maps(s[v]);
        ps_session_destroy(s[v]);
    }
    ps_scene_destroy(scene);
}

/* ps_session_start_beside's spare work runs after beside only while the
 * first round is still traced: at once behind a beside that returns at
 * once (the default box's round is 16 384 caustic paths), not behind one
 * that outlasts the round; and the round's photons are the same. */
typedef struct beside_calls {
    int beside, spare;
    ps_session *outlast; /* beside returns only once this session's round is stored */
} beside_calls;

static void count_beside(void *ctx)
{
    beside_calls *c = ctx;
    c->beside++;
    if (!c->outlast)
        return;
    /* Waits for the round itself, not a fixed time: the round is traced at
     * a low priority (nice 10), and beside a loaded suite's other test under
     * the sanitizers it outlasted the 1.5 s this once slept (and its caustic
     * photons, stored before the global map's, came before it ended). The
     * feed's time counts up as the round ends; then 0.2 s more, for the few
     * instructions from there to the round said done. */
    ps_session_counts n;
    double until = ps_now_seconds() + 60.0;
    do {
        struct timespec ts = {0, 5000000};
        nanosleep(&ts, NULL);
        ps_session_get_counts(c->outlast, &n);
    } while (!(n.trace_seconds > 0.0) && ps_now_seconds() < until);
    assert_true(n.trace_seconds > 0.0);
    struct timespec margin = {0, 200000000};
    nanosleep(&margin, NULL);
}

static void count_spare(void *ctx)
{
    beside_calls *c = ctx;
    assert_int_equal(c->beside, 1); /* after beside */
    c->spare++;
}

static void spare_work_only_while_the_round_is_traced(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    ps_error err;
    /* The round's photons however the caller's work went. */
    uint64_t counts[3];
    ps_photon last[3];
    for (int v = 0; v < 3; v++) {
        ps_session *s = open_session(scene, &set);
        beside_calls c = {0, 0, v == 1 ? s : NULL};
        assert_int_equal(ps_session_start_beside(s, true, count_beside, v < 2 ? count_spare : NULL, &c, &err),
                         PS_OK);
        assert_int_equal(c.beside, 1);
        assert_int_equal(c.spare, v == 0 ? 1 : 0);
        const ps_photon_map *m = ps_session_lock_maps(s);
        counts[v] = m[PS_MAP_CAUSTIC].count;
        assert_true(counts[v] > 0);
        last[v] = m[PS_MAP_CAUSTIC].photons[counts[v] - 1];
        ps_session_unlock_maps(s);
        ps_session_destroy(s);
    }
    for (int v = 1; v < 3; v++) {
        assert_int_equal(counts[v], counts[0]);
        assert_memory_equal(&last[v], &last[0], sizeof last[0]);
    }
    ps_scene_destroy(scene);
}

/* The specular layer's eye paths of two sessions (lookups and per-pixel
 * points) are the same bytes. */
static void assert_same_eye_paths(ps_session *a, ps_session *b)
{
    size_t n = lookup_vertices(a);
    assert_int_equal(n, lookup_vertices(b));
    for (int k = 0; k < PS_SPECULAR_TERMS; k++) {
        assert_memory_equal(ps_specular_weights(ps_session_specular(a), k),
                            ps_specular_weights(ps_session_specular(b), k), 3 * n * sizeof(float));
        assert_memory_equal(ps_specular_dirs(ps_session_specular(a), k), ps_specular_dirs(ps_session_specular(b), k),
                            3 * n * sizeof(float));
    }
    assert_points_equal(ps_specular_pixel_points(ps_session_specular(a)),
                        ps_specular_pixel_points(ps_session_specular(b)), 0);
}

static void eye_paths_owed_while_waiting(void **state)
{
    (void)state;
    ps_scene *scene = load();
    for (int inc = 0; inc < 2; inc++) {
        /* s[0] waits (a drawing side that shows no cube map yet); s[1]
         * traces them in its refresh, as before. */
        ps_session_settings set = settings(scene, inc != 0);
        ps_session *s[2];
        ps_camera_frame cam;
        ps_session_frame f;
        for (int v = 0; v < 2; v++) {
            set.specular_wait = v == 0;
            s[v] = start_and_refresh(scene, &set, &cam, &f);
            assert_true(f.specular);
        }
        const struct ps_specular *sp = ps_session_specular(s[0]);
        size_t rays = ps_specular_pixel_rays_left(ps_session_specular(s[0]), &cam);
        assert_false(ps_specular_pixel_points(sp).ready);
        assert_true(rays > 0);
        assert_true(ps_specular_pixel_points(ps_session_specular(s[1])).ready);
        /* A wait already over traces nothing. */
        ps_session_trace_specular_until(s[0], ps_now_seconds() - 1.0);
        assert_int_equal(ps_specular_pixel_rays_left(ps_session_specular(s[0]), &cam), rays);
        if (inc) {
            /* Ahead of need, with time to spare: all of them. */
            ps_session_trace_specular_until(s[0], ps_now_seconds() + 60.0);
        } else {
            ps_session_trace_specular(s[0]);
        }
        assert_same_eye_paths(s[0], s[1]);
        /* Nothing owed any more: tracing again changes nothing. */
        ps_session_trace_specular(s[0]);
        assert_same_eye_paths(s[0], s[1]);
        /* No longer waiting: the next refresh traces them itself (an
         * incremental session's moving view a slice of the lookups, the
         * rest kept from the last eye). */
        ps_session_set_specular_wait(s[0], false);
        cam.eye.x += 0.05;
        for (int v = 0; v < 2; v++)
            refresh(s[v], &cam, &f);
        assert_same_eye_paths(s[0], s[1]);
        for (int v = 0; v < 2; v++)
            ps_session_destroy(s[v]);
    }
    ps_scene_destroy(scene);
}

static void still_lookups_prepared_while_waiting(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, true);
    set.caps[PS_MAP_CAUSTIC] = PS_FEED_BATCH / 4;
    set.caps[PS_MAP_GLOBAL] = PS_FEED_BATCH / 4;
    ps_session *s[2];
    ps_camera_frame cam[2];
    ps_session_frame f;
    for (int v = 0; v < 2; v++) {
        s[v] = start_and_refresh(scene, &set, &cam[v], &f);
        ps_session_drawn(s[v], 0.01);
        wait_ended(s[v]);
        for (int i = 0; i < 10 && !ps_session_settled(s[v]); i++) {
            refresh(s[v], &cam[v], &f);
            ps_session_drawn(s[v], 0.01);
        }
        assert_true(ps_session_settled(s[v]));
        assert_false(ps_session_prepare_still(s[v], 64)); /* still: nothing to do */
        cam[v].eye.x += 0.05;
        refresh(s[v], &cam[v], &f);
        ps_session_drawn(s[v], 0.01);
        assert_true(f.moving);
    }
    size_t rays = ps_specular_pixel_rays_left(ps_session_specular(s[0]), &cam[0]);
    assert_true(rays > 0);
    int calls = 0;
    while (ps_session_prepare_still(s[0], 64))
        calls++;
    print_message("the still view's lookups and %zu pixel rays traced in %d calls while waiting\n", rays, calls);
    assert_true(calls >= 10);
    assert_false(ps_session_prepare_still(s[0], 64));
    /* Nothing left for the refresh to trace for this camera. */
    assert_int_equal(ps_specular_update(ps_session_specular(s[0]), ps_session_world(s[0]), cam[0].eye, 1), 0);
    assert_int_equal(ps_specular_pixel_rays_left(ps_session_specular(s[0]), &cam[0]), 0);
    assert_true(ps_specular_update(ps_session_specular(s[1]), ps_session_world(s[1]), cam[1].eye, 0) == 0);
    assert_int_equal(ps_specular_pixel_rays_left(ps_session_specular(s[1]), &cam[1]), rays);
    for (int v = 0; v < 2; v++) {
        refresh(s[v], &cam[v], &f);
        assert_false(f.moving);
    }
    assert_true(ps_specular_pixel_points(ps_session_specular(s[1])).ready);
    assert_same_eye_paths(s[0], s[1]);
    for (int v = 0; v < 2; v++)
        ps_session_destroy(s[v]);

    /* Still tracing: the tracer keeps the cores. */
    set.caps[PS_MAP_CAUSTIC] = 8000000;
    set.caps[PS_MAP_GLOBAL] = 2000000;
    ps_session *t = start_and_refresh(scene, &set, &cam[0], &f);
    ps_session_drawn(t, 1e3);
    cam[0].eye.x += 0.05;
    refresh(t, &cam[0], &f);
    assert_true(f.moving);
    assert_false(ps_session_prepare_still(t, 64));
    ps_session_destroy(t);
    ps_scene_destroy(scene);
}

/* Progressive area lights: the first refresh with one virtual light an area
 * light, then 2 x 2, then all 16, each change said (lights_changed); an
 * edit starts over at one; without the setting, 16 from the start. */
static void area_lights_refine(void **state)
{
    (void)state;
    ps_scene *scene = load_path(AREA_SCENE);
    ps_error err;
    ps_session_settings set = progressive_settings(scene);
    ps_session *s = open_session(scene, &set);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    ps_camera_frame cam = camera(scene);
    ps_session_frame f;
    const size_t want[3] = {1, 4, PS_PREVIEW_AREA_SAMPLES};
    /* The first level's shadow maps coarse, the full side with the next
     * virtual lights (the same level: no level of shadows alone). */
    const int side = PS_SHADOW_SIZE_DEFAULT, coarse = side / PS_SESSION_COARSE_SHADOW_DIVISOR;
    const int sides[3] = {coarse, side, side};
    for (int i = 0; i < 3; i++) {
        refresh(s, &cam, &f);
        assert_int_equal(f.lights_changed, i > 0);
        assert_false(f.shadows_refined);
        assert_int_equal(ps_session_lights(s)->count, want[i]);
        assert_int_equal(ps_session_lights(s)->shadow_size, sides[i]);
        assert_true(ps_session_lights_coarse(s) == (i < 2)); /* a level to come */
        ps_session_drawn(s, 0.001);
    }
    refresh(s, &cam, &f);
    assert_false(f.lights_changed);
    assert_int_equal(ps_session_lights(s)->count, PS_PREVIEW_AREA_SAMPLES);
    assert_int_equal(ps_session_move_light(s, 0, ps_v3(0.1, 1.9, 0.0), &err), PS_OK);
    ps_session_changes ch;
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    assert_int_equal(ps_session_lights(s)->count, 1);
    assert_int_equal(ps_session_lights(s)->shadow_size, side); /* the faces an edit leaves are kept */
    assert_true(ps_session_lights_coarse(s));                  /* its area lights refined again */
    ps_session_destroy(s);
    /* Held (photosplat-snap's 8-bit checkpoints): refreshes keep the level;
     * each ps_session_refine_lights brings the next, until all are there. */
    s = open_session(scene, &set);
    ps_session_hold_lights(s, true);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    for (int i = 0; i < 3; i++) {
        refresh(s, &cam, &f);
        assert_int_equal(ps_session_lights(s)->count, 1);
        ps_session_drawn(s, 0.001);
    }
    const double levels[2] = {4.0 * PS_SESSION_COARSE_SHADOW_COST, 4.0}; /* next_level_cost */
    for (int i = 1; i < 3; i++) {
        assert_true(ps_session_next_level_lights(s) == 4.0);
        assert_true(ps_session_next_level_cost(s) == levels[i - 1]);
        assert_true(ps_session_refine_lights(s));
        refresh(s, &cam, &f);
        assert_true(f.lights_changed);
        assert_int_equal(ps_session_lights(s)->count, want[i]);
        assert_int_equal(ps_session_lights(s)->shadow_size, side);
        ps_session_drawn(s, 0.001);
    }
    assert_true(ps_session_lights_to_come(s) == 1.0);
    assert_true(ps_session_next_level_cost(s) == 1.0);
    assert_false(ps_session_refine_lights(s));
    ps_session_destroy(s);
    set.progressive_lights = false;
    s = open_session(scene, &set);
    assert_int_equal(ps_session_lights(s)->count, PS_PREVIEW_AREA_SAMPLES);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* ps_session_work_pending: what a refresh has to do besides new photons
 * (photosplat-snap waits for photons only without it): the first camera's
 * view, lights refined and not yet rebuilt, an edit, a bake once the feed is
 * over; none once a refresh has drawn them. */
static void work_pending_besides_photons(void **state)
{
    (void)state;
    ps_scene *scene = load_path(AREA_SCENE);
    ps_error err;
    ps_session_settings set = progressive_settings(scene);
    ps_session *s = open_session(scene, &set);
    ps_session_hold_lights(s, true);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    ps_camera_frame cam = camera(scene);
    ps_session_frame f;
    assert_true(ps_session_work_pending(s)); /* no view yet */
    refresh(s, &cam, &f);
    ps_session_drawn(s, 0.001);
    assert_false(ps_session_work_pending(s));
    assert_true(ps_session_refine_lights(s));
    assert_true(ps_session_work_pending(s));
    refresh(s, &cam, &f);
    assert_true(f.lights_changed);
    ps_session_drawn(s, 0.001);
    assert_false(ps_session_work_pending(s));
    assert_int_equal(ps_session_move_light(s, 0, ps_v3(0.1, 1.9, 0.0), &err), PS_OK);
    assert_true(ps_session_work_pending(s));
    ps_session_destroy(s);
    /* Baking: pending while the bake is laid, one batch a refresh here
     * (the budget's share 0), once the feed is over. */
    set.progressive_lights = false;
    set.bake = true;
    set.splat = PS_SPLAT_TRIANGLES;
    s = open_session(scene, &set);
    ps_session_set_budget_share(s, 0.0);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    int laying = 0;
    for (int i = 0; i < 1000 && !ps_session_settled(s); i++) {
        refresh(s, &cam, &f);
        ps_session_drawn(s, 0.001);
        double p = ps_session_bake_progress(s, PS_MAP_CAUSTIC);
        if (p >= 0.0 && p < 1.0) {
            laying++;
            assert_true(ps_session_work_pending(s));
        }
    }
    assert_true(laying > 0);
    assert_true(ps_session_settled(s));
    assert_false(ps_session_work_pending(s));
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* A point light's progressive lights: the first picture's shadow maps at
 * PS_SESSION_COARSE_SHADOW_DIVISOR fewer texels a side, then the full side
 * as a level of its own (lights_changed with shadows_refined: the same
 * lights), a level a drawn refresh or, held, when asked; the last picture's
 * ps_session_full_lights brings it too. A side too small to halve, and
 * lights that are not progressive, start whole. */
static void coarse_shadows_first(void **state)
{
    (void)state;
    ps_scene *scene = load_path(SCENE);
    ps_error err;
    ps_camera_frame cam = camera(scene);
    ps_session_frame f;
    const int sides[3] = {1024, 512, PS_SESSION_COARSE_SHADOW_MIN};
    const int firsts[3] = {1024 / PS_SESSION_COARSE_SHADOW_DIVISOR, 512 / PS_SESSION_COARSE_SHADOW_DIVISOR,
                           PS_SESSION_COARSE_SHADOW_MIN};
    for (int k = 0; k < 3; k++) {
        ps_session_settings set = settings(scene, k != 1);
        set.progressive_lights = true;
        set.shadow_size = sides[k];
        for (int held = 0; held < 2; held++) {
            ps_session *s = open_session(scene, &set);
            ps_session_hold_lights(s, held != 0);
            assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
            refresh(s, &cam, &f);
            assert_int_equal(ps_session_lights(s)->count, 1);
            assert_int_equal(ps_session_lights(s)->shadow_size, firsts[k]);
            bool coarse = firsts[k] < sides[k];
            assert_true(ps_session_lights_to_come(s) == (coarse ? PS_SESSION_COARSE_SHADOW_COST : 1.0));
            assert_true(ps_session_lights_coarse(s) == coarse);
            assert_true(ps_session_next_level_lights(s) == 1.0); /* no area light */
            assert_true(ps_session_next_level_cost(s) == (coarse ? PS_SESSION_COARSE_SHADOW_COST : 1.0));
            ps_session_drawn(s, 0.001);
            if (held) { /* held: the level stays until asked for */
                refresh(s, &cam, &f);
                assert_false(f.lights_changed);
                assert_int_equal(ps_session_lights(s)->shadow_size, firsts[k]);
                assert_true(ps_session_refine_lights(s) == coarse);
                /* Asked for, not yet built: the lights drawn are still the coarse ones. */
                assert_true(ps_session_lights_coarse(s) == coarse);
            }
            refresh(s, &cam, &f);
            assert_true(f.lights_changed == coarse && f.shadows_refined == coarse);
            assert_int_equal(ps_session_lights(s)->shadow_size, sides[k]);
            assert_true(ps_session_lights_to_come(s) == 1.0);
            assert_false(ps_session_lights_coarse(s));
            assert_false(ps_session_refine_lights(s));
            ps_session_drawn(s, 0.001);
            refresh(s, &cam, &f);
            assert_false(f.lights_changed);
            ps_session_destroy(s);
        }
        /* The last picture's: every level at once. */
        ps_session *s = open_session(scene, &set);
        ps_session_hold_lights(s, true);
        assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
        refresh(s, &cam, &f);
        ps_session_full_lights(s);
        refresh(s, &cam, &f);
        assert_int_equal(ps_session_lights(s)->shadow_size, sides[k]);
        assert_false(ps_session_lights_coarse(s));
        ps_session_destroy(s);
        /* Not progressive: the full side from the first picture. */
        set.progressive_lights = false;
        s = open_session(scene, &set);
        assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
        refresh(s, &cam, &f);
        assert_int_equal(ps_session_lights(s)->shadow_size, sides[k]);
        assert_false(ps_session_lights_coarse(s));
        ps_session_destroy(s);
    }
    ps_scene_destroy(scene);
}

/* ps_session_env_fill against an oracle written another way: each photon
 * of the env splats' prefix (all of them here) on the cube face whose
 * forward axis its direction is most along (the largest dot with the six
 * axes, not the largest coordinate), a disc of the splats' radius seen at
 * its distance along that axis. Then in closed form: the same photons seen
 * from twice as far along one axis cover a quarter of the pixels. */
static void env_fill_counts_each_face(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = settings(scene, false);
    ps_session *s = open_session(scene, &set);
    ps_error err;
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    const size_t most[PS_MAP_COUNT] = {SIZE_MAX, SIZE_MAX};
    const int side = 128;
    const ps_vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const ps_vec3 centre = ps_v3(0.1, 0.9, -0.2);
    double want[6] = {0}, got[6];
    const ps_photon_map *maps = ps_session_maps(s);
    ps_camera_frame view = camera(scene);
    ps_splat_batch b;
    memset(&b, 0, sizeof b);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        double r;
        assert_int_equal(ps_session_env_splats(s, (ps_map_kind)k, &view, SIZE_MAX, &b, &r, &err), PS_OK);
        assert_true(maps[k].count > 1000);
        for (size_t i = 0; i < maps[k].count; i++) {
            ps_vec3 d = ps_v3_sub(ps_photon_position(&maps[k].photons[i]), centre);
            int best = 0;
            for (int f = 1; f < 6; f++)
                if (ps_v3_dot(d, axes[f]) > ps_v3_dot(d, axes[best]))
                    best = f;
            double px = r * side / (2.0 * ps_v3_dot(d, axes[best]));
            want[best] += fmin(PS_PI * px * px, (double)side * side);
        }
    }
    ps_splat_batch_free(&b);
    ps_session_env_fill(s, centre, side, most, got);
    double total = 0.0;
    for (int f = 0; f < 6; f++) {
        assert_true(fabs(got[f] - want[f]) <= 1e-9 * want[f] + 1e-9);
        total += got[f];
    }
    assert_true(total > 0.0);
    /* The box (0 <= y <= 2, |x|, |z| <= 1) seen from far above it, so that
     * every photon is on the down face: from 40 m, about a quarter of the
     * pixels of 20 m, and none elsewhere. */
    double near[6], far[6];
    ps_session_env_fill(s, ps_v3(0, 20, 0), side, most, near);
    ps_session_env_fill(s, ps_v3(0, 40, 0), side, most, far);
    assert_true(near[3] > 0.0);
    for (int f = 0; f < 6; f++)
        if (f != 3)
            assert_true(near[f] == 0.0 && far[f] == 0.0);
    /* A photon at height y is 20 - y and 40 - y away along -y: its pixels
     * from 20 m are ((40 - y) / (20 - y))^2 times those from 40 m, between
     * 4 (y = 0) and (38 / 18)^2 (y = 2). */
    assert_true(near[3] / far[3] >= 4.0 * (1.0 - 1e-12) && near[3] / far[3] <= pow(38.0 / 18.0, 2.0));
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(whole_refresh_splats_everything),
        cmocka_unit_test(whole_cap_draws_a_prefix),
        cmocka_unit_test(incremental_refresh_splats_each_photon_once),
        cmocka_unit_test(budget_bounds_a_refresh),
        cmocka_unit_test(budget_share_draws_a_share),
        cmocka_unit_test(backlog_holds_the_tracer),
        cmocka_unit_test(tracing_threads_leave_a_core_to_drawing),
        cmocka_unit_test(counter_stops_shooting),
        cmocka_unit_test(edits_restart_the_maps),
        cmocka_unit_test(hidden_layers_are_skipped),
        cmocka_unit_test(radius_follows_the_schedule),
        cmocka_unit_test(catch_up_after_the_first_still_refresh),
        cmocka_unit_test(catching_up_only_when_nothing_is_traced),
        cmocka_unit_test(still_view_due_sooner_after_a_move),
        cmocka_unit_test(still_lookups_prepared_while_waiting),
        cmocka_unit_test(eye_paths_owed_while_waiting),
        cmocka_unit_test(first_round_on_its_own_threads),
        cmocka_unit_test(env_fill_counts_each_face),
        cmocka_unit_test(area_lights_refine),
        cmocka_unit_test(work_pending_besides_photons),
        cmocka_unit_test(coarse_shadows_first),
        cmocka_unit_test(moving_camera_level_of_detail),
        cmocka_unit_test(moving_growth_held),
        cmocka_unit_test(moving_global_layer_shrunk),
        cmocka_unit_test(after_the_stop_converges_to_the_whole_view),
        cmocka_unit_test(spare_work_only_while_the_round_is_traced),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
