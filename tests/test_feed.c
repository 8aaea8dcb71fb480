/* test_feed.c: the progressive preview's photon feed (preview/feed.h): it
 * stops at the caps, and with a store limit it stops at that many stored
 * photons instead, between batches, holding exactly the first photons of the
 * capped maps (photon i depends only on scene, seed and i), so that memory is
 * bounded for any scene and the picture stays a correct estimate. */
#include "test.h"
#include "rig.h"

#include <stdint.h>
#include <string.h>
#include <time.h>

#include "photon/tracer.h"
#include "photon/world.h"
#include "preview/feed.h"
#include "scene/scene.h"

#define SCENE "data/scenes/cornell-caustic.scn"
/* Two rounds of PS_FEED_BATCH caustic photons (and a quarter as many global
 * ones) store about 38 000 photons in this scene, one round about 19 000. */
#define CAUSTIC_CAP 40000
#define GLOBAL_CAP 10000
#define STORE_LIMIT 25000

static rig feed_rig(void)
{
    ps_scene *scene;
    ps_error err;
    if (ps_scene_load(SCENE, NULL, &scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 3;
    o.threads = 2;
    return rig_of_scene(scene, NULL, &o);
}

/* A feed of both maps run to its end on this thread, with store limit `limit`. */
static ps_feed *run_feed(rig *r, size_t limit)
{
    const uint64_t caps[PS_MAP_COUNT] = {CAUSTIC_CAP, GLOBAL_CAP};
    const bool active[PS_MAP_COUNT] = {true, true};
    ps_feed *f = NULL;
    ps_error err;
    if (ps_feed_create(r->tracer, caps, active, &f, &err) != PS_OK)
        fail_msg("feed: %s", err.msg);
    ps_feed_set_store_limit(f, limit);
    if (ps_feed_run(f, &err) != PS_OK)
        fail_msg("run: %s", err.msg);
    return f;
}

static size_t stored(const ps_feed *f)
{
    const ps_photon_map *m = ps_feed_maps(f);
    return m[PS_MAP_CAUSTIC].count + m[PS_MAP_GLOBAL].count;
}

/* No limit: every map traced to its cap, and the last mark says so. */
static void ends_at_the_caps(void **state)
{
    (void)state;
    rig r = feed_rig();
    ps_feed *f = run_feed(&r, 0);
    assert_true(ps_feed_ended(f));
    assert_false(ps_feed_store_limited(f));
    const ps_photon_map *m = ps_feed_maps(f);
    assert_int_equal(m[PS_MAP_CAUSTIC].counters.emitted, CAUSTIC_CAP);
    assert_int_equal(m[PS_MAP_GLOBAL].counters.emitted, GLOBAL_CAP);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        size_t n;
        const ps_feed_mark *marks = ps_feed_marks(f, (ps_map_kind)k, &n);
        assert_true(n >= 2);
        assert_int_equal(marks[n - 1].stored, m[k].count);
        assert_int_equal(marks[n - 1].emitted, m[k].counters.emitted);
        /* Grown batch by batch from the first batch's exact size: never more
         * than twice what it holds (the memory plan's two entries a photon). */
        assert_true(m[k].cap >= m[k].count && m[k].cap <= 2 * m[k].count);
        assert_int_equal(ps_photon_map_bytes(&m[k]), m[k].cap * PS_PHOTON_MAP_BYTES);
    }
    assert_true(stored(f) > STORE_LIMIT); /* else the limit below would not bite */
    ps_feed_destroy(f);
    rig_free(&r);
}

/* A store limit ends the feed at the first batch boundary at or past it: the
 * maps hold at least the limit, the round before held less, fewer photons
 * than the caps were emitted, and those stored are the capped maps' first
 * photons, byte for byte. */
static void ends_at_the_store_limit(void **state)
{
    (void)state;
    rig r = feed_rig();
    ps_feed *full = run_feed(&r, 0);
    ps_feed *f = run_feed(&r, STORE_LIMIT);
    assert_true(ps_feed_ended(f));
    assert_true(ps_feed_store_limited(f));
    assert_true(stored(f) >= STORE_LIMIT);
    size_t before = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        size_t n;
        const ps_feed_mark *marks = ps_feed_marks(f, (ps_map_kind)k, &n);
        assert_true(n >= 2);
        before += marks[n - 2].stored;
    }
    assert_true(before < STORE_LIMIT);
    const ps_photon_map *m = ps_feed_maps(f), *all = ps_feed_maps(full);
    assert_true(m[PS_MAP_CAUSTIC].counters.emitted < CAUSTIC_CAP);
    assert_true(m[PS_MAP_GLOBAL].counters.emitted < GLOBAL_CAP);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        assert_true(m[k].count > 0 && m[k].count < all[k].count);
        assert_memory_equal(m[k].photons, all[k].photons, m[k].count * sizeof *m[k].photons);
        assert_memory_equal(m[k].objects, all[k].objects, m[k].count * sizeof *m[k].objects);
    }
    ps_feed_destroy(f);
    ps_feed_destroy(full);
    rig_free(&r);
}

/* A map's share of the memory budget (the tracer's max_stored) ends the feed
 * the same quiet way: no error, the maps as they were before the batch that
 * would have passed it, a prefix of the uncapped maps. */
static void ends_at_the_map_memory_cap(void **state)
{
    (void)state;
    rig full_rig = feed_rig();
    ps_feed *full = run_feed(&full_rig, 0);
    ps_scene *scene;
    ps_error err;
    if (ps_scene_load(SCENE, NULL, &scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 3;
    o.threads = 2;
    o.max_stored = 20000; /* the caustic map stores about 15 000 a round */
    rig r = rig_of_scene(scene, NULL, &o);
    ps_feed *f = run_feed(&r, 0);
    assert_int_equal(ps_feed_status(f, &err), PS_OK);
    assert_true(ps_feed_ended(f));
    assert_true(ps_feed_store_limited(f));
    const ps_photon_map *m = ps_feed_maps(f), *all = ps_feed_maps(full);
    assert_true(m[PS_MAP_CAUSTIC].count > 0 && m[PS_MAP_CAUSTIC].count <= 20000);
    assert_true(m[PS_MAP_CAUSTIC].counters.emitted < CAUSTIC_CAP);
    assert_memory_equal(m[PS_MAP_CAUSTIC].photons, all[PS_MAP_CAUSTIC].photons,
                        m[PS_MAP_CAUSTIC].count * sizeof *m[PS_MAP_CAUSTIC].photons);
    ps_feed_destroy(f);
    ps_feed_destroy(full);
    rig_free(&r);
    rig_free(&full_rig);
}

/* The limit holds from the background thread too (start, then wait for the end). */
static void background_thread_stops(void **state)
{
    (void)state;
    rig r = feed_rig();
    const uint64_t caps[PS_MAP_COUNT] = {CAUSTIC_CAP, GLOBAL_CAP};
    const bool active[PS_MAP_COUNT] = {true, true};
    ps_feed *f = NULL;
    ps_error err;
    assert_int_equal(ps_feed_create(r.tracer, caps, active, &f, &err), PS_OK);
    ps_feed_set_store_limit(f, STORE_LIMIT);
    assert_int_equal(ps_feed_prime(f, &err), PS_OK);
    assert_int_equal(ps_feed_start(f, &err), PS_OK);
    bool ended = false;
    while (!ended) {
        ps_feed_lock(f);
        ended = ps_feed_ended(f);
        ps_feed_unlock(f);
        if (!ended) {
            struct timespec ms = {0, 1000000};
            nanosleep(&ms, NULL);
        }
    }
    ps_feed_stop(f);
    assert_int_equal(ps_feed_status(f, &err), PS_OK);
    assert_true(ps_feed_store_limited(f));
    assert_true(stored(f) >= STORE_LIMIT);
    assert_true(ps_feed_maps(f)[PS_MAP_CAUSTIC].counters.emitted < CAUSTIC_CAP);
    ps_feed_destroy(f);
    rig_free(&r);
}

static uint64_t emitted(ps_feed *f, int k)
{
    ps_feed_lock(f);
    uint64_t n = ps_feed_maps(f)[k].counters.emitted;
    ps_feed_unlock(f);
    return n;
}

static void sleep_ms(long ms)
{
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000};
    nanosleep(&ts, NULL);
}

/* ps_feed_set_ahead: the thread holds before a round while a map holds its
 * bound, without anyone calling again (snap's tracer ran 2*10^5 photons past
 * a bound looked at only as refreshes drew), goes on a round at a time as
 * the bound rises, to the cap when lifted; ps_feed_run on the calling thread
 * ignores it (nothing would raise it). */
static void ahead_bound_holds_the_thread(void **state)
{
    (void)state;
    rig r = feed_rig();
    const uint64_t caps[PS_MAP_COUNT] = {6 * PS_FEED_BATCH, PS_FEED_BATCH};
    const bool active[PS_MAP_COUNT] = {true, true};
    ps_feed *f = NULL;
    ps_error err;
    assert_int_equal(ps_feed_create(r.tracer, caps, active, &f, &err), PS_OK);
    assert_int_equal(ps_feed_prime(f, &err), PS_OK);
    assert_int_equal(emitted(f, PS_MAP_CAUSTIC), PS_FEED_BATCH);
    ps_feed_lock(f);
    size_t first = ps_feed_maps(f)[PS_MAP_CAUSTIC].count;
    ps_feed_unlock(f);
    size_t most[PS_MAP_COUNT] = {first, SIZE_MAX};
    ps_feed_set_ahead(f, most);
    assert_int_equal(ps_feed_start(f, &err), PS_OK);
    sleep_ms(300); /* a round takes some 10 ms (more under the sanitizers) */
    assert_int_equal(emitted(f, PS_MAP_CAUSTIC), PS_FEED_BATCH);
    /* One photon more allowed: the next round, and no other. */
    most[PS_MAP_CAUSTIC] = first + 1;
    ps_feed_set_ahead(f, most);
    for (int i = 0; i < 3000 && emitted(f, PS_MAP_CAUSTIC) < 2 * PS_FEED_BATCH; i++)
        sleep_ms(5);
    sleep_ms(300);
    assert_int_equal(emitted(f, PS_MAP_CAUSTIC), 2 * PS_FEED_BATCH);
    /* Lifted: to the caps. */
    most[PS_MAP_CAUSTIC] = SIZE_MAX;
    ps_feed_set_ahead(f, most);
    bool ended = false;
    for (int i = 0; i < 6000 && !ended; i++) {
        ps_feed_lock(f);
        ended = ps_feed_ended(f);
        ps_feed_unlock(f);
        if (!ended)
            sleep_ms(5);
    }
    assert_true(ended);
    ps_feed_stop(f);
    assert_int_equal(emitted(f, PS_MAP_CAUSTIC), caps[PS_MAP_CAUSTIC]);
    ps_feed_destroy(f);

    /* On the calling thread: to the caps, bound or not. */
    assert_int_equal(ps_feed_create(r.tracer, caps, active, &f, &err), PS_OK);
    const size_t one[PS_MAP_COUNT] = {1, 1};
    ps_feed_set_ahead(f, one);
    assert_int_equal(ps_feed_run(f, &err), PS_OK);
    assert_int_equal(emitted(f, PS_MAP_CAUSTIC), caps[PS_MAP_CAUSTIC]);
    assert_int_equal(emitted(f, PS_MAP_GLOBAL), caps[PS_MAP_GLOBAL]);
    ps_feed_destroy(f);
    rig_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(ends_at_the_caps),
        cmocka_unit_test(ends_at_the_store_limit),
        cmocka_unit_test(ends_at_the_map_memory_cap),
        cmocka_unit_test(background_thread_stops),
        cmocka_unit_test(ahead_bound_holds_the_thread),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
