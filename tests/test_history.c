/* test_history.c: undo and redo (preview/history.h) through a session. The
 * oracle is the session itself: after three edits (a quad moved twice, which
 * the inverse move could not undo exactly, and a light's power), three undos
 * and the repair of the maps, the photon maps equal the first scene's byte
 * for byte; redo gives the edited scene's maps back; the scene equals its
 * snapshot in every array. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "preview/history.h"
#include "preview/session.h"
#include "scene/scene.h"

#define SCENE "data/scenes/cornell-caustic.scn"
#define CAUSTIC_CAP 20000
#define GLOBAL_CAP 5000

typedef struct maps_copy {
    size_t count[PS_MAP_COUNT];
    ps_photon *photons[PS_MAP_COUNT];
} maps_copy;

static maps_copy copy_maps(ps_session *s)
{
    ps_error err;
    if (ps_session_trace_all(s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    const ps_photon_map *m = ps_session_maps(s);
    maps_copy c;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        c.count[k] = m[k].count;
        c.photons[k] = malloc(m[k].count * sizeof *m[k].photons + 1);
        assert_non_null(c.photons[k]);
        memcpy(c.photons[k], m[k].photons, m[k].count * sizeof *m[k].photons);
    }
    return c;
}

static bool same_maps(const maps_copy *a, const maps_copy *b)
{
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (a->count[k] != b->count[k] || memcmp(a->photons[k], b->photons[k], a->count[k] * sizeof(ps_photon)))
            return false;
    return true;
}

static void free_maps(maps_copy *c)
{
    for (int k = 0; k < PS_MAP_COUNT; k++)
        free(c->photons[k]);
}

static void update(ps_session *s)
{
    ps_session_changes ch;
    ps_error err;
    if (ps_session_update(s, &ch, &err) != PS_OK)
        fail_msg("%s", err.msg);
}

static void ok(ps_status st, const ps_error *err)
{
    if (st != PS_OK)
        fail_msg("%s", err->msg);
}

static void same_positions(const ps_scene *a, const ps_scene *b)
{
    size_t na, nb;
    const ps_vec3 *pa = ps_scene_positions(a, &na), *pb = ps_scene_positions(b, &nb);
    assert_int_equal(na, nb);
    assert_memory_equal(pa, pb, na * sizeof *pa);
    const ps_light *la = ps_scene_lights(a, &na), *lb = ps_scene_lights(b, &nb);
    assert_int_equal(na, nb);
    assert_memory_equal(la, lb, na * sizeof *la);
    const ps_object *oa = ps_scene_objects(a, &na), *ob = ps_scene_objects(b, &nb);
    assert_int_equal(na, nb);
    assert_memory_equal(oa, ob, na * sizeof *oa);
}

static void undo_three_edits_gives_the_first_maps(void **state)
{
    (void)state;
    ps_scene *scene = NULL;
    ps_error err;
    ok(ps_scene_load(SCENE, NULL, &scene, &err), &err);
    ps_scene *first = NULL;
    ok(ps_scene_clone(scene, &first, &err), &err);
    ps_session_settings set = ps_session_default_settings(scene);
    set.caps[PS_MAP_CAUSTIC] = CAUSTIC_CAP;
    set.caps[PS_MAP_GLOBAL] = GLOBAL_CAP;
    set.seed = 5;
    set.threads = 2;
    ps_session *s = NULL;
    ok(ps_session_create(scene, &set, &s, &err), &err);
    ps_history *h = NULL;
    ok(ps_history_create(PS_HISTORY_DEFAULT_STEPS, PS_HISTORY_DEFAULT_BYTES, &h, &err), &err);
    maps_copy before = copy_maps(s);

    /* Three edits, each recorded first. The floor moves by 0.1 and then by
     * 0.2: 0 + 0.1 + 0.2 - 0.3 is not 0 in doubles. */
    ok(ps_history_record(h, ps_session_scene(s), &err), &err);
    ok(ps_session_move_object(s, 0, ps_v3(0.1, 0.0, 0.1), &err), &err);
    ok(ps_history_record(h, ps_session_scene(s), &err), &err);
    ok(ps_session_move_object(s, 0, ps_v3(0.2, 0.0, 0.2), &err), &err);
    ok(ps_history_record(h, ps_session_scene(s), &err), &err);
    ok(ps_session_set_light_power(s, 0, ps_rgb_make(50, 60, 70), &err), &err);
    /* A refused edit leaves no step. */
    ok(ps_history_record(h, ps_session_scene(s), &err), &err);
    assert_int_not_equal(ps_session_set_spot_angle(s, 0, 30.0, &err), PS_OK);
    ps_history_forget(h);
    assert_int_equal(ps_history_undo_steps(h), 3);
    update(s);
    maps_copy edited = copy_maps(s);
    assert_false(same_maps(&before, &edited));
    ps_scene *after = NULL;
    ok(ps_scene_clone(ps_session_scene(s), &after, &err), &err);

    for (int k = 0; k < 3; k++)
        ok(ps_history_undo(h, s, &err), &err);
    assert_int_not_equal(ps_history_undo(h, s, &err), PS_OK);
    assert_string_equal(err.msg, "nothing to undo");
    assert_int_equal(ps_history_redo_steps(h), 3);
    same_positions(ps_session_scene(s), first);
    update(s);
    maps_copy undone = copy_maps(s);
    assert_true(same_maps(&before, &undone));

    for (int k = 0; k < 3; k++)
        ok(ps_history_redo(h, s, &err), &err);
    same_positions(ps_session_scene(s), after);
    update(s);
    maps_copy redone = copy_maps(s);
    assert_true(same_maps(&edited, &redone));
    /* A new edit after an undo forgets the redo steps. */
    ok(ps_history_undo(h, s, &err), &err);
    ok(ps_history_record(h, ps_session_scene(s), &err), &err);
    assert_int_equal(ps_history_redo_steps(h), 0);

    free_maps(&before);
    free_maps(&edited);
    free_maps(&undone);
    free_maps(&redone);
    ps_history_destroy(h);
    ps_session_destroy(s);
    ps_scene_destroy(after);
    ps_scene_destroy(first);
    ps_scene_destroy(scene);
}

/* The limits: at most max_steps steps, the oldest forgotten. */
static void limits_forget_the_oldest(void **state)
{
    (void)state;
    ps_scene *scene = NULL;
    ps_error err;
    ok(ps_scene_load(SCENE, NULL, &scene, &err), &err);
    ps_history *h = NULL;
    ok(ps_history_create(2, PS_HISTORY_DEFAULT_BYTES, &h, &err), &err);
    for (int k = 0; k < 5; k++)
        ok(ps_history_record(h, scene, &err), &err);
    assert_int_equal(ps_history_undo_steps(h), 2);
    ps_history_destroy(h);
    ok(ps_history_create(100, ps_history_scene_bytes(scene) * 3, &h, &err), &err);
    for (int k = 0; k < 5; k++)
        ok(ps_history_record(h, scene, &err), &err);
    assert_int_equal(ps_history_undo_steps(h), 3);
    ps_history_destroy(h);
    ps_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(undo_three_edits_gives_the_first_maps),
        cmocka_unit_test(limits_forget_the_oldest),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
