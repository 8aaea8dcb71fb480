/* test_workfile.c: the window's work files (app/workfile.h) and its edit
 * history around a session: the names for a scene and a model, Ctrl+S
 * keeping the previous file as NAME.scn~, the autosave after an edit holding
 * it, a newer autosave noticed, and undo through ps_work giving the scene
 * back as loaded. */
#include "test.h"

#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <time.h>

#include "app/workfile.h"
#include "core/fileio.h"
#include "preview/history.h"
#include "preview/session.h"
#include "scene/scene.h"

#define SCENE_TEXT                                                                                        \
    "camera eye 0 1 3 target 0 1 0\n"                                                                     \
    "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0\n"                                                       \
    "light point position 0 1.5 0 power 10 10 10\n"

static char *slurp(const char *path)
{
    char *text = NULL;
    size_t len;
    ps_error err;
    if (ps_read_file(path, 1 << 20, &text, &len, &err) != PS_OK)
        fail_msg("%s", err.msg);
    return text;
}

static void write_file(const char *path, const char *text)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
}

static void names(void **state)
{
    (void)state;
    ps_workfile w;
    ps_error err;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path(""));
    char scn[1100], obj[1100];
    snprintf(scn, sizeof scn, "%sroom.scn", dir);
    snprintf(obj, sizeof obj, "%schair.OBJ", dir);
    assert_int_equal(ps_workfile_names(scn, &w, &err), PS_OK);
    assert_string_equal(w.save, scn);
    assert_non_null(strstr(w.autosave, "/room.autosave.scn"));
    assert_int_equal(ps_workfile_names(obj, &w, &err), PS_OK);
    assert_non_null(strstr(w.save, "/chair.scn"));
    assert_non_null(strstr(w.autosave, "/chair.autosave.scn"));
}

static void save_autosave_undo(void **state)
{
    (void)state;
    char scn[1100];
    snprintf(scn, sizeof scn, "%s", test_path("lab.scn"));
    write_file(scn, SCENE_TEXT);
    ps_scene *scene = NULL;
    ps_error err;
    assert_int_equal(ps_scene_load(scn, NULL, &scene, &err), PS_OK);
    ps_session_settings set = ps_session_default_settings(scene);
    set.caps[PS_MAP_CAUSTIC] = 100;
    set.caps[PS_MAP_GLOBAL] = 1000;
    set.threads = 1;
    ps_session *s = NULL;
    assert_int_equal(ps_session_create(scene, &set, &s, &err), PS_OK);
    ps_work w;
    char notice[512];
    assert_int_equal(ps_work_open(&w, scn, ps_session_scene(s), notice, sizeof notice, &err), PS_OK);
    assert_string_equal(notice, "");
    assert_false(w.dirty);

    /* An edit as the window applies it: recorded, then an autosave due. */
    assert_int_equal(ps_session_move_light(s, 0, ps_v3(0.5, 1.25, 0.25), &err), PS_OK);
    ps_work_before_update(&w, ps_session_scene(s));
    ps_session_changes ch;
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    assert_int_equal(ps_work_after_update(&w, ps_session_scene(s), 10.0, &err), PS_OK);
    assert_true(w.dirty);
    assert_true(w.pending);
    assert_int_equal(ps_work_tick(&w, ps_session_scene(s), 10.0 + PS_WORK_AUTOSAVE_DELAY / 2, &err), PS_OK);
    assert_int_equal(access(w.names.autosave, F_OK), -1); /* not yet */
    assert_int_equal(ps_work_tick(&w, ps_session_scene(s), 10.0 + PS_WORK_AUTOSAVE_DELAY, &err), PS_OK);
    char *auto_text = slurp(w.names.autosave);
    assert_non_null(strstr(auto_text, "light point position 0.5 1.25 0.25"));
    free(auto_text);
    /* The autosave is newer than the scene. */
    struct timespec old[2] = {{1000000000, 0}, {1000000000, 0}};
    assert_int_equal(utimensat(AT_FDCWD, scn, old, 0), 0);
    assert_true(ps_workfile_autosave_newer(&w.names, scn));

    /* Ctrl+S: the file replaced, the previous kept as lab.scn~, no autosave left. */
    assert_int_equal(ps_work_save(&w, ps_session_scene(s), &err), PS_OK);
    assert_false(w.dirty);
    char backup[1200];
    snprintf(backup, sizeof backup, "%s~", scn);
    char *prev = slurp(backup), *now = slurp(scn);
    assert_string_equal(prev, SCENE_TEXT);
    assert_non_null(strstr(now, "light point position 0.5 1.25 0.25"));
    free(prev);
    free(now);
    assert_int_equal(access(w.names.autosave, F_OK), -1);

    /* Undo: the light back where the file had it, exactly. */
    assert_int_equal(ps_work_undo(&w, s, &err), PS_OK);
    ps_work_before_update(&w, ps_session_scene(s));
    assert_int_equal(ps_session_update(s, &ch, &err), PS_OK);
    assert_int_equal(ps_work_after_update(&w, ps_session_scene(s), 20.0, &err), PS_OK);
    size_t n;
    const ps_light *l = ps_scene_lights(ps_session_scene(s), &n);
    assert_true(l[0].position.x == 0.0 && l[0].position.y == 1.5 && l[0].position.z == 0.0);
    assert_int_not_equal(ps_work_undo(&w, s, &err), PS_OK); /* the undo was not a step of its own */
    assert_int_equal(ps_work_redo(&w, s, &err), PS_OK);
    assert_true(ps_scene_lights(ps_session_scene(s), &n)[0].position.x == 0.5);

    ps_work_close(&w);
    ps_session_destroy(s);
    ps_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(names),
        cmocka_unit_test(save_autosave_undo),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
