/* test_repair.c: the preview's selective repair after edits (preview/repair.h,
 * feed.h): after each kind of edit the session's maps, traced to their caps,
 * equal a fresh trace of the edited scene photon for photon; and the repair
 * keeps what it says it keeps: after moving one of two lights, exactly the
 * other light's global photons (the tracer's own count of them). */
#include "test.h"

#include <string.h>
#include <time.h>

#include "photon/tracer.h"
#include "photon/world.h"
#include "preview/feed.h"
#include "preview/repair.h"
#include "preview/session.h"
#include "preview/specular.h"
#include "scene/scene.h"
#include "two_lights.h"

#define CAUSTIC_CAP 12000
#define GLOBAL_CAP 6000
#define SEED 11

/* The default scene's box and spheres, a point light (0) and a spot (1). */
static const char SCENE_TEXT[] = TWO_LIGHTS_SCENE "60 50 40\n";

#define GLASS 5
#define MIRROR 6
#define FLOOR 0

static ps_scene *load(void)
{
    ps_scene *scene;
    ps_error err;
    if (ps_scene_load_text(SCENE_TEXT, "repair.scn", ".", NULL, &scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    return scene;
}

/* A repairing session's settings with these caps. */
static ps_session_settings repair_settings(const ps_scene *scene, uint64_t caustic_cap, uint64_t global_cap)
{
    ps_session_settings set = ps_session_default_settings(scene);
    set.caps[PS_MAP_CAUSTIC] = caustic_cap;
    set.caps[PS_MAP_GLOBAL] = global_cap;
    set.seed = SEED;
    set.threads = 2;
    set.repair = true;
    return set;
}

static ps_session *open_traced(ps_scene *scene)
{
    ps_session_settings set = repair_settings(scene, CAUSTIC_CAP, GLOBAL_CAP);
    ps_session *s;
    ps_error err;
    if (ps_session_create(scene, &set, &s, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    return s;
}

/* The maps of a fresh trace of scene (as photosplat-ref --photons-only). */
static void fresh_trace(const ps_scene *scene, ps_photon_map maps[PS_MAP_COUNT], uint64_t caustic_cap,
                        uint64_t global_cap)
{
    ps_world *w;
    ps_tracer *t;
    ps_error err;
    assert_int_equal(ps_world_create(scene, NULL, &w, &err), PS_OK);
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = SEED;
    o.threads = 2;
    assert_int_equal(ps_tracer_create(w, &o, &t, &err), PS_OK);
    const uint64_t caps[PS_MAP_COUNT] = {caustic_cap, global_cap};
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map_init(&maps[k], (ps_map_kind)k);
        assert_int_equal(ps_tracer_trace(t, (ps_map_kind)k, 0, caps[k], caps[k], &maps[k], &err), PS_OK);
    }
    ps_tracer_destroy(t);
    ps_world_destroy(w);
}

static void assert_same_maps(const ps_photon_map *a, const ps_photon_map *b)
{
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_int_equal(a[k].count, b[k].count);
        assert_int_equal(a[k].counters.emitted, b[k].counters.emitted);
        assert_int_equal(a[k].counters.stored, b[k].counters.stored);
        assert_memory_equal(a[k].photons, b[k].photons, a[k].count * sizeof *a[k].photons);
        assert_memory_equal(a[k].materials, b[k].materials, a[k].count * sizeof *a[k].materials);
        assert_memory_equal(a[k].objects, b[k].objects, a[k].count * sizeof *a[k].objects);
    }
}

/* maps against a fresh trace of scene to these caps: photon for photon. */
static void equals_fresh(const ps_photon_map *maps, const ps_scene *scene, uint64_t caustic_cap,
                         uint64_t global_cap)
{
    ps_photon_map fresh[PS_MAP_COUNT];
    fresh_trace(scene, fresh, caustic_cap, global_cap);
    assert_same_maps(maps, fresh);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_photon_map_free(&fresh[k]);
}

/* The session's maps, traced on to their caps, against a fresh trace of the
 * (edited) scene: photon for photon. */
static void traced_equals_fresh(ps_session *s, const ps_scene *scene)
{
    ps_error err;
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    equals_fresh(ps_session_maps(s), scene, CAUSTIC_CAP, GLOBAL_CAP);
}

typedef enum edit_kind { MOVE_POINT, MOVE_SPOT, MOVE_MIRROR, MOVE_GLASS, MOVE_FLOOR, POWER, ANGLE, EDIT_KINDS } edit_kind;

static void apply(ps_session *s, edit_kind e, int step)
{
    ps_error err;
    double d = 0.05 * (step + 1);
    ps_status st = PS_OK;
    switch (e) {
    case MOVE_POINT: st = ps_session_move_light(s, 0, ps_v3(-0.2 + d, 1.85, 0.1), &err); break;
    case MOVE_SPOT: st = ps_session_move_light(s, 1, ps_v3(0.4, 1.8, 0.3 - d), &err); break;
    case MOVE_MIRROR: st = ps_session_move_object(s, MIRROR, ps_v3(0.1, 0, 0), &err); break;
    case MOVE_GLASS: st = ps_session_move_object(s, GLASS, ps_v3(0, 0.05, -0.1), &err); break;
    /* Dyadic steps: the moved quad's vertices are then exactly those of the
     * quad written at the new place (for the cli test's .scn files). */
    case MOVE_FLOOR: st = ps_session_move_object(s, FLOOR, ps_v3(0, 0.125, 0), &err); break;
    case POWER: st = ps_session_set_light_power(s, step % 2, ps_rgb_make(80 + step, 90, 100), &err); break;
    case ANGLE: st = ps_session_set_spot_angle(s, 1, 30 + 5 * step, &err); break;
    default: break;
    }
    if (st != PS_OK)
        fail_msg("edit %d: %s", (int)e, err.msg);
}

static void update_caps(ps_session *s, uint64_t kept[PS_MAP_COUNT], uint64_t retraced[PS_MAP_COUNT],
                        uint64_t caustic_cap, uint64_t global_cap)
{
    ps_error err;
    ps_session_changes ch;
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    bool repaired;
    ps_session_repair_counts(s, &repaired, kept, retraced);
    assert_true(repaired);
    const uint64_t caps[PS_MAP_COUNT] = {caustic_cap, global_cap};
    for (int k = 0; k < PS_MAP_COUNT; k++)
        assert_int_equal(kept[k] + retraced[k], caps[k]); /* every index: one or the other */
}

/* An update that repaired; its counts are not asked for (a repair left to
 * the thread knows them only once it has tested every index). */
static void update_repaired(ps_session *s)
{
    ps_error err;
    ps_session_changes ch;
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    bool repaired;
    uint64_t kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
    ps_session_repair_counts(s, &repaired, kept, retraced);
    assert_true(repaired);
}

static void update(ps_session *s, uint64_t kept[PS_MAP_COUNT], uint64_t retraced[PS_MAP_COUNT])
{
    update_caps(s, kept, retraced, CAUSTIC_CAP, GLOBAL_CAP);
}

/* Each kind of edit, once and twice in a row, then traced to the caps. */
static void each_edit_equals_a_fresh_trace(void **state)
{
    (void)state;
    for (int e = 0; e < EDIT_KINDS; e++) {
        ps_scene *scene = load();
        ps_session *s = open_traced(scene);
        uint64_t kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
        for (int step = 0; step < 2; step++) {
            apply(s, (edit_kind)e, step);
            update(s, kept, retraced);
            traced_equals_fresh(s, scene);
        }
        ps_session_destroy(s);
        ps_scene_destroy(scene);
    }
}

/* Several edits before the maps are full, then the rest traced. */
static void edits_mid_repair(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session *s = open_traced(scene);
    uint64_t kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
    for (int e = 0; e < EDIT_KINDS; e++) {
        apply(s, (edit_kind)e, e);
        update(s, kept, retraced); /* nothing retraced yet: the next edit starts from what is kept */
    }
    traced_equals_fresh(s, scene);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* Photons of each stratum (light, target) of map k below its cap. */
typedef struct strata_counts {
    uint64_t n[2][8];
} strata_counts;

static strata_counts counts_of(ps_session *s, ps_map_kind k)
{
    strata_counts c;
    const uint64_t caps[PS_MAP_COUNT] = {CAUSTIC_CAP, GLOBAL_CAP};
    for (uint32_t l = 0; l < 2; l++)
        for (int64_t target = -1; target < 7; target++)
            c.n[l][target + 1] =
                ps_tracer_stratum_photons((ps_tracer *)ps_session_tracer(s), k, l, target, caps[k]);
    return c;
}

/* The photons a repair traces because strata grew: the sum of the growth of
 * each stratum that samples as before (`same`: per light). */
static uint64_t growth(const strata_counts *a, const strata_counts *b, const bool same[2])
{
    uint64_t g = 0;
    for (int l = 0; l < 2; l++)
        for (int t = 0; t < 8; t++)
            if (same[l] && b->n[l][t] > a->n[l][t])
                g += b->n[l][t] - a->n[l][t];
    return g;
}

static uint64_t kept_of(const strata_counts *a, const strata_counts *b, const bool same[2], int only_target)
{
    uint64_t g = 0;
    for (int l = 0; l < 2; l++)
        for (int t = 0; t < 8; t++)
            if (same[l] && (only_target < 0 || t == only_target + 1))
                g += a->n[l][t] < b->n[l][t] ? a->n[l][t] : b->n[l][t];
    return g;
}

/* What each edit keeps, against the tracer's own counts of each stratum:
 * moving the spot keeps exactly the point light's global photons and, of the
 * caustic ones, the point light's up to the fewer of its old and new counts
 * per caustic cone; a power edit and a colour edit keep every photon and
 * trace only the strata's growth; moving the mirror keeps the caustic
 * photons of the glass sphere's cones clear of the mirror's boxes (some,
 * never more than the fewer of their counts) and retraces all of the
 * mirror's; a moved floor keeps the caustic paths clear of it. */
static void repair_keeps_what_it_should(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session *s = open_traced(scene);
    uint64_t kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
    uint64_t point = ps_tracer_light_photons((ps_tracer *)ps_session_tracer(s), PS_MAP_GLOBAL, 0, GLOBAL_CAP);
    strata_counts c0 = counts_of(s, PS_MAP_CAUSTIC);
    apply(s, MOVE_SPOT, 0);
    update(s, kept, retraced);
    strata_counts c1 = counts_of(s, PS_MAP_CAUSTIC);
    const bool point_only[2] = {true, false}, both[2] = {true, true};
    assert_true(point > GLOBAL_CAP / 2 && point < GLOBAL_CAP);
    assert_int_equal(kept[PS_MAP_GLOBAL], point);
    assert_int_equal(retraced[PS_MAP_GLOBAL], GLOBAL_CAP - point);
    assert_int_equal(kept[PS_MAP_CAUSTIC], kept_of(&c0, &c1, point_only, -1));
    assert_true(kept[PS_MAP_CAUSTIC] > CAUSTIC_CAP / 10);
    fprintf(stderr, "move the spot: kept %llu of %d caustic, %llu of %d global photon paths\n",
            (unsigned long long)kept[PS_MAP_CAUSTIC], CAUSTIC_CAP, (unsigned long long)kept[PS_MAP_GLOBAL], GLOBAL_CAP);
    ps_error err;
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);

    /* Power: both maps' shares change (two lights), no photon's path. */
    strata_counts g0 = counts_of(s, PS_MAP_GLOBAL);
    c0 = counts_of(s, PS_MAP_CAUSTIC);
    apply(s, POWER, 0);
    update(s, kept, retraced);
    strata_counts g1 = counts_of(s, PS_MAP_GLOBAL);
    c1 = counts_of(s, PS_MAP_CAUSTIC);
    assert_true(memcmp(&g0, &g1, sizeof g0) != 0); /* the counts did change */
    assert_int_equal(retraced[PS_MAP_GLOBAL], growth(&g0, &g1, both));
    assert_int_equal(retraced[PS_MAP_CAUSTIC], growth(&c0, &c1, both));
    assert_true(retraced[PS_MAP_GLOBAL] > 0 && retraced[PS_MAP_GLOBAL] < GLOBAL_CAP / 10);
    fprintf(stderr, "power: traced %llu caustic, %llu global photon paths (the strata's growth)\n",
            (unsigned long long)retraced[PS_MAP_CAUSTIC], (unsigned long long)retraced[PS_MAP_GLOBAL]);
    traced_equals_fresh(s, scene);

    /* Colour with the same flux: the same shares, nothing retraced. */
    assert_int_equal(ps_session_set_light_power(s, 1, ps_rgb_make(40, 50, 60), &err), PS_OK);
    update(s, kept, retraced);
    assert_int_equal(retraced[PS_MAP_GLOBAL], 0);
    assert_int_equal(retraced[PS_MAP_CAUSTIC], 0);
    traced_equals_fresh(s, scene);

    c0 = counts_of(s, PS_MAP_CAUSTIC);
    apply(s, MOVE_MIRROR, 0);
    update(s, kept, retraced);
    c1 = counts_of(s, PS_MAP_CAUSTIC);
    uint64_t glass = kept_of(&c0, &c1, both, GLASS), mirror = c1.n[0][MIRROR + 1] + c1.n[1][MIRROR + 1];
    assert_true(mirror > 0);
    assert_true(kept[PS_MAP_CAUSTIC] > glass / 2 && kept[PS_MAP_CAUSTIC] <= glass);
    assert_true(retraced[PS_MAP_CAUSTIC] >= mirror);
    fprintf(stderr, "move the mirror: kept %llu caustic (of %llu the glass sphere's cones keep), %llu global\n",
            (unsigned long long)kept[PS_MAP_CAUSTIC], (unsigned long long)glass, (unsigned long long)kept[PS_MAP_GLOBAL]);
    assert_true(kept[PS_MAP_GLOBAL] > GLOBAL_CAP / 2 && kept[PS_MAP_GLOBAL] < GLOBAL_CAP);
    traced_equals_fresh(s, scene);

    /* A diffuse wall moved: the caustic cones stay, the caustic paths clear of it stay. */
    apply(s, MOVE_FLOOR, 0);
    update(s, kept, retraced);
    assert_true(kept[PS_MAP_CAUSTIC] > 0 && kept[PS_MAP_CAUSTIC] < CAUSTIC_CAP);
    traced_equals_fresh(s, scene);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* What reads the maps by their batch marks (a refresh's budget, the specular
 * layer's cube maps: ps_session_env_splats) reads what it would after a
 * fresh trace: the repair's end puts the marks back where a fresh feed's
 * rounds end. Caps of several rounds (PS_FEED_BATCH), a prefix of a round. */
static void marks_after_a_repair_are_a_fresh_feeds(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_session_settings set = ps_session_default_settings(scene);
    set.caps[PS_MAP_CAUSTIC] = 3 * PS_FEED_BATCH;
    set.caps[PS_MAP_GLOBAL] = PS_FEED_BATCH;
    set.seed = SEED;
    set.threads = 2;
    ps_session *s;
    ps_error err;
    assert_int_equal(ps_session_create(scene, &set, &s, &err), PS_OK);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    apply(s, MOVE_MIRROR, 0);
    ps_session_changes ch;
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    assert_int_equal(ps_session_trace_all(s, &err), PS_OK);
    ps_scene *copy;
    assert_int_equal(ps_scene_clone(scene, &copy, &err), PS_OK);
    ps_session *fresh;
    assert_int_equal(ps_session_create(copy, &set, &fresh, &err), PS_OK);
    assert_int_equal(ps_session_trace_all(fresh, &err), PS_OK);
    ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(scene), 64, 64);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_splat_batch a, b;
        ps_splat_batch_init(&a);
        ps_splat_batch_init(&b);
        double ra, rb;
        assert_int_equal(ps_session_env_splats(s, (ps_map_kind)k, &cam, PS_FEED_BATCH, &a, &ra, &err), PS_OK);
        assert_int_equal(ps_session_env_splats(fresh, (ps_map_kind)k, &cam, PS_FEED_BATCH, &b, &rb, &err), PS_OK);
        assert_true(a.splats > 0 && a.splats < ps_session_maps(s)[k].count); /* a prefix */
        assert_int_equal(a.vertex_count, b.vertex_count);
        assert_true(ra == rb);
        assert_memory_equal(a.positions, b.positions, 3 * a.vertex_count * sizeof(float));
        assert_memory_equal(a.colors, b.colors, 4 * a.vertex_count * sizeof(float));
        ps_splat_batch_free(&a);
        ps_splat_batch_free(&b);
    }
    ps_session_destroy(fresh);
    ps_scene_destroy(copy);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* ---- a started session: what the picture sees of a repair ------------------------ */

/* The window's session (incremental float layers, a tracing thread) of the
 * two-light scene, with caps of several batches (so that a picture draws a
 * map over several refreshes at the least budget); an edit's photons are
 * retraced before its first picture when at most retrace_first. */
#define SHOWN_CAUSTIC_CAP (4 * PS_FEED_BATCH)
#define SHOWN_GLOBAL_CAP PS_FEED_BATCH
static ps_session *open_shown_whole(ps_scene *scene, uint64_t retrace_first, uint64_t edit_splats_whole,
                                    ps_camera_frame *cam)
{
    ps_session_settings set = repair_settings(scene, SHOWN_CAUSTIC_CAP, SHOWN_GLOBAL_CAP);
    set.edit_splats_whole = edit_splats_whole;
    set.float_buffer = set.incremental = true;
    set.layers = PS_LAYER_DIRECT | PS_LAYER_CAUSTIC | PS_LAYER_GLOBAL;
    set.retrace_first = retrace_first;
    set.tau = 1e-9; /* the least budget: a map over several refreshes */
    ps_session *s;
    ps_error err;
    if (ps_session_create(scene, &set, &s, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    assert_int_equal(ps_session_start(s, true, &err), PS_OK);
    *cam = ps_camera_frame_make(ps_scene_camera(scene), 64, 64);
    return s;
}

static ps_session *open_shown(ps_scene *scene, uint64_t retrace_first, ps_camera_frame *cam)
{
    return open_shown_whole(scene, retrace_first, PS_SESSION_EDIT_SPLATS_WHOLE, cam);
}

/* Refreshes (each said drawn at once) until everything is shown; how many
 * of them after the first started the view over (but for the full view that
 * follows an edit's level of detail). With wait_end, tracing ends after the
 * first (before the picture has drawn everything). */
static int refresh_until_settled(ps_session *s, const ps_camera_frame *cam, bool wait_end)
{
    int restarts = 0, i = 0;
    bool lod = false;
    for (; i < 100000 && !ps_session_settled(s); i++) {
        ps_session_frame f;
        ps_error err;
        if (ps_session_refresh(s, cam, &f, &err) != PS_OK)
            fail_msg("refresh: %s", err.msg);
        restarts += i > 0 && f.new_view && !(i == 1 && lod);
        if (i == 0)
            lod = f.edit_lod;
        ps_session_drawn(s, 1e-4);
        ps_session_counts c;
        do {
            struct timespec ts = {0, 200000};
            nanosleep(&ts, NULL);
            ps_session_get_counts(s, &c);
        } while (i == 0 && wait_end && !c.ended);
        if (i == 0 && wait_end) /* the edit's refresh drew a prefix of the kept run, not all */
            assert_true(f.emitted[PS_MAP_CAUSTIC] < SHOWN_CAUSTIC_CAP);
    }
    assert_true(ps_session_settled(s));
    return restarts;
}

/* The maps a picture may read now (in index order once tracing ended)
 * against a fresh trace of scene. */
static void shown_equals_fresh(ps_session *s, const ps_scene *scene)
{
    equals_fresh(ps_session_lock_maps(s), scene, SHOWN_CAUSTIC_CAP, SHOWN_GLOBAL_CAP);
    ps_session_unlock_maps(s);
}

/* A repair left to the tracing thread (retrace_first 0: as one of more than
 * PS_SESSION_RETRACE_FIRST photons, and edit_splats_whole 0: of more than
 * PS_SESSION_EDIT_SPLATS_WHOLE) while the picture draws a little each
 * refresh: the thread's end used to put the maps back in index order at
 * once, which started the view over from one batch (the picture got worse
 * a quarter of a second after an edit); now the merge waits until every
 * photon is drawn, so only the edit's own refresh starts a view, and the
 * maps shown at the end are a fresh trace's. */
/* The shown session whose repairs are left to the thread (retrace_first 0,
 * edit_splats_whole 0), its first picture settled. */
static ps_session *open_background(ps_scene **scene, ps_camera_frame *cam)
{
    *scene = load();
    ps_session *s = open_shown_whole(*scene, 0, 0, cam);
    assert_int_equal(refresh_until_settled(s, cam, false), 0);
    return s;
}

static void a_background_repair_keeps_the_view(void **state)
{
    (void)state;
    ps_scene *scene;
    ps_camera_frame cam;
    ps_session *s = open_background(&scene, &cam);
    for (int e = 0; e < 3; e++) {
        apply(s, e == 0 ? MOVE_MIRROR : e == 1 ? MOVE_SPOT : MOVE_FLOOR, e);
        update_repaired(s);
        /* Only the first picture's share was tested before it: the counts
         * come when the thread has tested the rest. */
        bool repaired;
        uint64_t kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
        ps_session_repair_counts(s, &repaired, kept, retraced);
        assert_true(kept[PS_MAP_CAUSTIC] + retraced[PS_MAP_CAUSTIC] < SHOWN_CAUSTIC_CAP);
        assert_int_equal(refresh_until_settled(s, &cam, true), 0);
        ps_session_repair_counts(s, &repaired, kept, retraced);
        assert_int_equal(kept[PS_MAP_CAUSTIC] + retraced[PS_MAP_CAUSTIC], SHOWN_CAUSTIC_CAP);
        assert_int_equal(kept[PS_MAP_GLOBAL] + retraced[PS_MAP_GLOBAL], SHOWN_GLOBAL_CAP);
        assert_true(retraced[PS_MAP_CAUSTIC] + retraced[PS_MAP_GLOBAL] > 0);
        shown_equals_fresh(s, scene);
    }
    ps_error err;
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* Edits that come while a repair left to the thread is still testing
 * paths (edit_splats_whole 0: only the first picture's share is tested
 * before it): the next update ends that repair where it is, the untested
 * indices retraced (ps_feed_stop_unmerged), so after every
 * kind of edit in a row, some with a refresh between them (the thread goes
 * on for a while), the maps are a fresh trace's. */
static void edits_mid_background_repair(void **state)
{
    (void)state;
    ps_scene *scene;
    ps_camera_frame cam;
    ps_session *s = open_background(&scene, &cam);
    ps_error err;
    for (int e = 0; e < EDIT_KINDS; e++) {
        apply(s, (edit_kind)e, e);
        update_repaired(s);
        if (e % 2) {
            ps_session_frame f;
            assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
            ps_session_drawn(s, 1e-4);
        }
    }
    (void)refresh_until_settled(s, &cam, false);
    shown_equals_fresh(s, scene);
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* A repair within PS_SESSION_RETRACE_FIRST: every changed photon is
 * retraced in the update, so the maps are a fresh trace's before
 * the first picture after the edit (no hole where the mirror was), and no
 * refresh after it starts over. */
static void a_small_repair_is_done_before_the_first_picture(void **state)
{
    (void)state;
    ps_scene *scene = load();
    ps_camera_frame cam;
    ps_session *s = open_shown(scene, PS_SESSION_RETRACE_FIRST, &cam);
    assert_int_equal(refresh_until_settled(s, &cam, false), 0);
    apply(s, MOVE_MIRROR, 0);
    uint64_t kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
    update_caps(s, kept, retraced, SHOWN_CAUSTIC_CAP, SHOWN_GLOBAL_CAP);
    assert_true(retraced[PS_MAP_CAUSTIC] > 0 && retraced[PS_MAP_GLOBAL] > 0);
    shown_equals_fresh(s, scene); /* before any refresh */
    assert_int_equal(refresh_until_settled(s, &cam, false), 0);
    ps_error err;
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* The first refresh after an edit (the maps full, the least budget: a
 * batch a refresh; a 64^2 view) draws every stored photon when they number
 * at most edit_splats_whole at 256^2, so a sixteenth of that here; else
 * (and during a drag) the budget's prefix, as the level of detail (*lod). */
static uint64_t first_edit_refresh_draws_lod(uint64_t edit_splats_whole, bool dragging, bool *lod)
{
    ps_scene *scene = load();
    ps_camera_frame cam;
    ps_session *s = open_shown_whole(scene, PS_SESSION_RETRACE_FIRST, edit_splats_whole, &cam);
    ps_error err;
    assert_int_equal(refresh_until_settled(s, &cam, false), 0);
    ps_session_set_dragging(s, dragging);
    apply(s, MOVE_MIRROR, 0);
    update_repaired(s);
    ps_session_frame f;
    assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
    assert_true(f.new_view);
    uint64_t drawn = f.emitted[PS_MAP_CAUSTIC];
    ps_session_drawn(s, 1e-4);
    /* A picture that does not draw every photon is the level of detail (a
     * moving camera's: half the pixels a side), the full view next. */
    *lod = f.edit_lod;
    assert_true(f.moving == f.edit_lod);
    assert_int_equal(f.view.width, f.edit_lod ? (cam.width + 1) / 2 : cam.width);
    assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
    assert_false(f.moving || f.edit_lod);
    assert_int_equal(f.view.width, cam.width);
    assert_true(f.new_view == *lod);
    ps_session_drawn(s, 1e-4);
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
    return drawn;
}

static uint64_t first_edit_refresh_draws(uint64_t edit_splats_whole, bool dragging)
{
    bool lod;
    uint64_t drawn = first_edit_refresh_draws_lod(edit_splats_whole, dragging, &lod);
    assert_true(lod == (drawn < SHOWN_CAUSTIC_CAP));
    return drawn;
}

static void an_edit_picture_draws_every_photon(void **state)
{
    (void)state;
    /* Both maps' stored photons at 64^2 against the count at 256^2: 16
     * times as many. */
    ps_scene *scene = load();
    ps_camera_frame cam;
    ps_session *s = open_shown(scene, PS_SESSION_RETRACE_FIRST, &cam);
    assert_int_equal(refresh_until_settled(s, &cam, false), 0);
    const ps_photon_map *maps = ps_session_lock_maps(s);
    uint64_t held = maps[PS_MAP_CAUSTIC].count + maps[PS_MAP_GLOBAL].count;
    ps_session_unlock_maps(s);
    ps_error err;
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
    uint64_t at_256 = held * 64 * 64 / PS_SESSION_EDIT_WHOLE_PIXELS;
    if (at_256 * PS_SESSION_EDIT_WHOLE_PIXELS < held * 64 * 64)
        at_256++; /* the least count that draws them whole */
    assert_int_equal(first_edit_refresh_draws(PS_SESSION_EDIT_SPLATS_WHOLE, false), SHOWN_CAUSTIC_CAP);
    assert_int_equal(first_edit_refresh_draws(at_256, false), SHOWN_CAUSTIC_CAP);
    assert_true(first_edit_refresh_draws(at_256 - 1, false) < SHOWN_CAUSTIC_CAP);
    assert_true(first_edit_refresh_draws(0, false) < SHOWN_CAUSTIC_CAP);
    assert_true(first_edit_refresh_draws(PS_SESSION_EDIT_SPLATS_WHOLE, true) < SHOWN_CAUSTIC_CAP);
}

/* The specular layer after the mirror moves, camera still (256^2: its spheres
 * take some 7*10^4 eye rays): the edit's first refresh traces the per-pixel
 * paths whole (PS_SESSION_PIXEL_RAYS_WHOLE), where a budget a refresh left
 * that picture with per-vertex lookups (pixel_rays_whole 0; tau tiny: one
 * chunk of rays a refresh). */
static bool first_edit_picture_has_pixel_paths(uint64_t pixel_rays_whole)
{
    ps_scene *scene = load();
    ps_session_settings set = repair_settings(scene, SHOWN_CAUSTIC_CAP, SHOWN_GLOBAL_CAP);
    set.float_buffer = set.incremental = true;
    set.layers = PS_LAYER_DIRECT | PS_LAYER_CAUSTIC | PS_LAYER_GLOBAL | PS_LAYER_SPECULAR;
    set.tau = 1e-9;
    set.pixel_rays_whole = pixel_rays_whole;
    ps_session *s;
    ps_error err;
    if (ps_session_create(scene, &set, &s, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    assert_int_equal(ps_session_start(s, true, &err), PS_OK);
    ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(scene), 256, 256);
    ps_session_frame f;
    for (int i = 0; i < 1000 && !ps_specular_pixel_points(ps_session_specular(s)).ready; i++) {
        assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
        ps_session_drawn(s, 1e-4);
    }
    assert_true(ps_specular_pixel_points(ps_session_specular(s)).ready);
    apply(s, MOVE_MIRROR, 0);
    ps_session_changes ch;
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    assert_true(ch.geometry);
    assert_false(ps_specular_pixel_points(ps_session_specular(s)).ready);
    size_t rays = ps_specular_pixel_rays_left(ps_session_specular(s), &cam);
    assert_true(rays > PS_SPECULAR_PIXEL_RAYS && rays <= PS_SESSION_PIXEL_RAYS_WHOLE);
    assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
    assert_true(f.specular);
    bool ready = ps_specular_pixel_points(ps_session_specular(s)).ready;
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
    return ready;
}

static void an_edit_picture_has_pixel_paths(void **state)
{
    (void)state;
    assert_true(first_edit_picture_has_pixel_paths(PS_SESSION_PIXEL_RAYS_WHOLE));
    assert_false(first_edit_picture_has_pixel_paths(0));
}

/* The two-light scene without its spot: one light, whose move changes
 * every photon of both maps. */
static ps_scene *load_lone_light(void)
{
    char text[sizeof SCENE_TEXT];
    snprintf(text, sizeof text, "%s", SCENE_TEXT);
    *strstr(text, "light spot") = '\0';
    ps_scene *scene;
    ps_error err;
    if (ps_scene_load_text(text, "lone.scn", ".", NULL, &scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    return scene;
}

/* A lone light moved: nothing of either map can be kept, so each starts
 * over from photon 0 as a fresh feed's, with no paths to test and no list
 * to retrace: right after the update the maps hold nothing and count
 * nothing emitted (a repair would count every old index emitted, its
 * photons on their way), the counts say every index retraced, and the maps
 * traced on are a fresh trace's; so are they after a move in the middle of
 * such a restart (the picture's thread traced part of it) and another once
 * it is shown. */
static void a_lone_light_move_starts_over(void **state)
{
    (void)state;
    ps_scene *scene = load_lone_light();
    ps_session *s = open_traced(scene);
    ps_error err;
    assert_int_equal(ps_session_move_light(s, 0, ps_v3(0.3, 1.85, -0.2), &err), PS_OK);
    uint64_t kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
    update(s, kept, retraced);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_int_equal(kept[k], 0);
        assert_int_equal(ps_session_maps(s)[k].count, 0);
        assert_int_equal(ps_session_maps(s)[k].counters.emitted, 0);
    }
    traced_equals_fresh(s, scene);
    ps_session_destroy(s);
    ps_scene_destroy(scene);

    scene = load_lone_light();
    ps_camera_frame cam;
    s = open_shown_whole(scene, 0, 0, &cam);
    assert_int_equal(refresh_until_settled(s, &cam, false), 0);
    for (int step = 0; step < 3; step++) {
        assert_int_equal(ps_session_move_light(s, 0, ps_v3(0.1 * step, 1.85, 0.1), &err), PS_OK);
        update_repaired(s);
        ps_session_frame f;
        assert_int_equal(ps_session_refresh(s, &cam, &f, &err), PS_OK);
        assert_true(f.emitted[PS_MAP_CAUSTIC] > 0); /* the first picture has photons */
        ps_session_drawn(s, 1e-4);
        if (step == 1)
            (void)refresh_until_settled(s, &cam, false);
    }
    (void)refresh_until_settled(s, &cam, false);
    shown_equals_fresh(s, scene);
    assert_int_equal(ps_session_stop(s, &err), PS_OK);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

/* One stage of a hand-made session: the scene's world and tracer as the
 * session makes them (records in the scene's box). */
typedef struct stage {
    ps_world *world;
    ps_tracer *tracer;
} stage;

static stage stage_make(const ps_scene *scene)
{
    stage g;
    ps_error err;
    assert_int_equal(ps_world_create(scene, NULL, &g.world, &err), PS_OK);
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = SEED;
    o.threads = 2;
    o.records = true;
    o.record_box = ps_repair_record_box(scene);
    assert_int_equal(ps_tracer_create(g.world, &o, &g.tracer, &err), PS_OK);
    return g;
}

static void stage_free(stage *g)
{
    ps_tracer_destroy(g->tracer);
    ps_world_destroy(g->world);
}

/* The mirror moved on scene, and old (stopped, unmerged) repaired onto the
 * edited scene's new stage. */
static ps_feed *edit_and_repair(ps_scene *scene, ps_feed *old, const stage *was_stage, stage *now, ps_vec3 delta)
{
    ps_error err;
    ps_repair_state was;
    assert_int_equal(ps_repair_state_take(scene, ps_world_epsilon(was_stage->world), &was, &err), PS_OK);
    assert_int_equal(ps_scene_translate_object(scene, MIRROR, delta, &err), PS_OK);
    *now = stage_make(scene);
    ps_feed_stop_unmerged(old);
    ps_feed *f = NULL;
    bool repaired = false;
    assert_int_equal(ps_repair_feed(old, was_stage->tracer, now->tracer, &was, scene, ps_world_epsilon(now->world),
                                    &f, &repaired, &err),
                     PS_OK);
    assert_true(repaired);
    ps_repair_state_free(&was);
    return f;
}

/* Feed f traced on to its caps against a fresh trace of scene (the shown caps). */
static void run_equals_fresh(ps_feed *f, const ps_scene *scene)
{
    ps_error err;
    assert_int_equal(ps_feed_run(f, &err), PS_OK);
    equals_fresh(ps_feed_maps(f), scene, SHOWN_CAUSTIC_CAP, SHOWN_GLOBAL_CAP);
}

/* A feed of the shown caps traced `rounds` rounds (all: -1), then the
 * mirror moved 10 cm and that feed repaired onto the edited scene's stage g1. */
static ps_feed *first_repair(ps_scene *scene, int rounds, stage *g1)
{
    stage g0 = stage_make(scene);
    const uint64_t caps[PS_MAP_COUNT] = {SHOWN_CAUSTIC_CAP, SHOWN_GLOBAL_CAP};
    const bool active[PS_MAP_COUNT] = {true, true};
    ps_feed *f0;
    ps_error err;
    assert_int_equal(ps_feed_create(g0.tracer, caps, active, &f0, &err), PS_OK);
    if (rounds < 0)
        assert_int_equal(ps_feed_run(f0, &err), PS_OK);
    for (int r = 0; r < rounds; r++)
        assert_int_equal(ps_feed_prime(f0, &err), PS_OK);
    ps_feed *f1 = edit_and_repair(scene, f0, &g0, g1, ps_v3(0.1, 0, 0));
    ps_feed_destroy(f0);
    stage_free(&g0);
    return f1;
}

/* The mirror moved again and f1 repaired onto it; traced on, a fresh
 * trace's. Frees everything, the scene too. */
static void second_repair_equals_fresh(ps_scene *scene, ps_feed *f1, stage *g1)
{
    stage g2;
    ps_feed *f2 = edit_and_repair(scene, f1, g1, &g2, ps_v3(-0.05, 0, 0.05));
    ps_feed_destroy(f1);
    stage_free(g1);
    run_equals_fresh(f2, scene);
    ps_feed_destroy(f2);
    stage_free(&g2);
    ps_scene_destroy(scene);
}

/* An edit while the last repair's map is still in its repair order (kept
 * run, retraced run, then photons traced past the repair: nothing merged,
 * as ps_feed_stop_unmerged leaves it for an update): the repair reads each
 * old photon where it lies, and the maps traced on are a fresh trace's. */
static void a_repair_reads_the_repair_order(void **state)
{
    (void)state;
    ps_scene *scene = load();
    stage g1;
    ps_feed *f1 = first_repair(scene, 2, &g1); /* half the caps: the repair has indices past it to trace */
    ps_error err;
    const size_t all[PS_MAP_COUNT] = {SIZE_MAX, SIZE_MAX};
    assert_int_equal(ps_feed_repair_ahead(f1, all, &err), PS_OK);
    ps_feed_repair_count rc = ps_feed_repair_counts(f1);
    assert_true(rc.retraced[PS_MAP_CAUSTIC] > 0 && rc.kept[PS_MAP_CAUSTIC] > 0);
    /* The retrace (a round each map), then a round past the repair. */
    size_t before = ps_feed_maps(f1)[PS_MAP_CAUSTIC].count;
    for (int r = 0; r < 3; r++)
        assert_int_equal(ps_feed_prime(f1, &err), PS_OK);
    assert_true(ps_feed_maps(f1)[PS_MAP_CAUSTIC].count > before);
    second_repair_equals_fresh(scene, f1, &g1);
}

/* A second edit before the thread has tested the first repair's paths (a
 * drag's edits, 0.05 s apart): the update does not finish those tests, the
 * indices left go to the list to retrace (ps_feed_stop_unmerged), the
 * counts say so, and the maps traced on are a fresh trace's. */
static void an_edit_mid_repair_retraces_the_untested(void **state)
{
    (void)state;
    ps_scene *scene = load();
    stage g1;
    ps_feed *f1 = first_repair(scene, -1, &g1);
    ps_error err;
    /* Only the first batch of indices tested, as for a first picture. */
    const size_t ahead[PS_MAP_COUNT] = {1, 1};
    assert_int_equal(ps_feed_repair_ahead(f1, ahead, &err), PS_OK);
    size_t tested_photons = ps_feed_maps(f1)[PS_MAP_CAUSTIC].count;
    assert_true(tested_photons > 0);
    /* Stopped as an update stops it: every untested index retraced, the
     * kept photons only the tested ones'. */
    ps_feed_stop_unmerged(f1);
    ps_feed_repair_count rc = ps_feed_repair_counts(f1);
    assert_int_equal(rc.kept[PS_MAP_CAUSTIC] + rc.retraced[PS_MAP_CAUSTIC], SHOWN_CAUSTIC_CAP);
    assert_true(rc.retraced[PS_MAP_CAUSTIC] >= SHOWN_CAUSTIC_CAP - PS_FEED_BATCH);
    assert_int_equal(rc.kept_photons[PS_MAP_CAUSTIC], tested_photons);
    second_repair_equals_fresh(scene, f1, &g1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(each_edit_equals_a_fresh_trace),
        cmocka_unit_test(edits_mid_repair),
        cmocka_unit_test(repair_keeps_what_it_should),
        cmocka_unit_test(marks_after_a_repair_are_a_fresh_feeds),
        cmocka_unit_test(a_background_repair_keeps_the_view),
        cmocka_unit_test(edits_mid_background_repair),
        cmocka_unit_test(a_small_repair_is_done_before_the_first_picture),
        cmocka_unit_test(an_edit_picture_has_pixel_paths),
        cmocka_unit_test(an_edit_picture_draws_every_photon),
        cmocka_unit_test(a_lone_light_move_starts_over),
        cmocka_unit_test(a_repair_reads_the_repair_order),
        cmocka_unit_test(an_edit_mid_repair_retraces_the_untested),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
