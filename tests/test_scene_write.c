/* test_scene_write.c: ps_scene_write. The oracle is the loader: a scene,
 * edited through the edit functions, written and read back must equal the
 * edited scene in every field of every array, bit for bit (only the line
 * numbers, which name lines of the new file, differ); writing the reloaded
 * scene again gives the same bytes; the files it names are found from the new
 * directory. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "scene/ies.h"
#include "scene/scene.h"
#include "scene_same.h"

static void write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
}

static char *read_text(const char *path)
{
    char *text = NULL;
    size_t len;
    ps_error err;
    if (ps_read_file(path, 1 << 20, &text, &len, &err) != PS_OK)
        fail_msg("%s", err.msg);
    return text;
}

/* A scene of every statement: materials of each type (and the default one,
 * made by a quad naming none), a lamp OBJ with an emitting face (MTL Ke),
 * moved and scaled, quads, spheres, lights of every type given by power,
 * lumens and candela; photon and radius defaults left to the loader. */
static const char *make_scene(void)
{
    char dir[1024], path[1100];
    snprintf(dir, sizeof dir, "%s", test_path("orig"));
    mkdir(dir, 0777);
    snprintf(path, sizeof path, "%s/lamp.obj", dir);
    write_text(path, "mtllib lamp.mtl\n"
                     "v -0.5 2 -0.5\nv 0.5 2 -0.5\nv 0.5 2 0.5\nv -0.5 2 0.5\n"
                     "v 1 0 0\nv 2 0 0\nv 1 1 0\n"
                     "vn 0 -1 0\nvn 0 0 1\n"
                     "usemtl glow\nf 1//1 2//1 3//1 4//1\n"
                     "usemtl body\nf 5//2 6//2 7//2\n");
    snprintf(path, sizeof path, "%s/lamp.mtl", dir);
    write_text(path, "newmtl glow\nKd 0 0 0\nKe 2 2 2\nnewmtl body\nKd 0.5 0.5 0.5\n");
    static char scn[1100];
    snprintf(scn, sizeof scn, "%s/room.scn", dir);
    /* build/test-tmp/PID/orig/ is four levels below the repository. */
    write_text(scn, "camera eye 0.1 1.3 3.7 target 0 0.9 0 up 0 1 0.1 fov 37.5\n"
                    "image 320 240\n"
                    "material wall diffuse albedo 0.7 0.6 0.1\n"
                    "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material wall\n"
                    "material shiny glossy albedo 0.3 0.3 0.3 specular 0.2 0.1 0.3 exponent 33.3\n"
                    "quad corner -1 0 -1 edge1 2 0 0 edge2 0 2 0\n"
                    "material mirror mirror reflectance 0.9 0.8 0.7\n"
                    "material glass dielectric ior 1.33 transmittance 0.9 1 0.95\n"
                    "mesh lamp.obj scale 0.3 rotate 0 1 0 17 translate 0.1 0.2 0.3\n"
                    "mesh lamp.obj material shiny scale 0.5 0.25 0.5\n"
                    "sphere center 0.35 0.4 0.2 radius 0.4 material glass\n"
                    "sphere center -0.35 0.3 0.1 radius 0.3 material mirror\n"
                    "light point position 0 1.9 0 power 100 90 80\n"
                    "light spot position 0.1 1.9 0 direction 0.1 -1 0.2 angle 30 lumens 800 color 1 0.9 0.8\n"
                    "light quad corner -0.25 1.999 -0.25 edge1 0.5 0 0 edge2 0 0 0.5 power 10 10 10\n"
                    "light sphere center 0 1.8 0 radius 0.05 candela 100\n"
                    "light disc center 0 1.99 0 normal 0.3 -1 0 radius 0.2 power 5 6 7\n"
                    "light ies ../../../../tests/data/ies-good/1986-rotational.ies position 0 2.5 0 aim 0 -1 0.1 "
                    "spin 12 lumens 1200 color 1 0.9 0.8\n");
    return scn;
}

static ps_scene *load_file(const char *path)
{
    ps_scene *s = NULL;
    ps_error err;
    warn_log log = {0, ""};
    ps_scene_load_options opts = {{log_warning, &log}};
    if (ps_scene_load(path, &opts, &s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    return s;
}

static void edit_ok(ps_status st, const ps_error *err)
{
    if (st != PS_OK)
        fail_msg("%s", err->msg);
}

/* Moves of every object kind (two per mesh and quad: x + a + b is not x + (a + b)),
 * positions, powers and an angle of lights, the emissive mesh's power. */
static void edit(ps_scene *s)
{
    ps_error err;
    edit_ok(ps_scene_translate_object(s, 0, ps_v3(0.1, 0, 0.3), &err), &err);
    edit_ok(ps_scene_translate_object(s, 0, ps_v3(0.7, 0.01, -0.3), &err), &err);
    edit_ok(ps_scene_translate_object(s, 2, ps_v3(0.123, 0.456, 0.789), &err), &err);
    edit_ok(ps_scene_translate_object(s, 2, ps_v3(-0.3, 0.1, 0.2), &err), &err);
    edit_ok(ps_scene_translate_object(s, 4, ps_v3(1.0 / 3, 0, 0), &err), &err);
    size_t nl;
    const ps_light *l = ps_scene_lights(s, &nl);
    size_t mesh_light = nl;
    for (size_t i = 0; i < nl; i++)
        if (l[i].type == PS_LIGHT_MESH && mesh_light == nl)
            mesh_light = i;
    assert_true(mesh_light < nl);
    edit_ok(ps_scene_set_light_power(s, mesh_light, ps_rgb_make(3.1, 2.2, 1.3), &err), &err);
    edit_ok(ps_scene_translate_object(s, 2, ps_v3(0.01, 0.02, 0.03), &err), &err);
    for (size_t i = 0; i < nl; i++) {
        if (l[i].type == PS_LIGHT_MESH)
            continue;
        edit_ok(ps_scene_set_light_position(s, i, ps_v3(0.1 * (double)i, 1.7 + 0.01 * (double)i, 1.0 / 7), &err),
                &err);
        edit_ok(ps_scene_set_light_power(s, i, ps_rgb_make(1.0 / 3 + (double)i, 2.0 / 3, 0.1), &err), &err);
        if (l[i].type == PS_LIGHT_SPOT)
            edit_ok(ps_scene_set_spot_angle(s, i, 41.3, &err), &err);
    }
}

static void save_ok(const ps_scene *s, const char *path)
{
    ps_error err;
    if (ps_scene_write(s, path, &err) != PS_OK)
        fail_msg("%s", err.msg);
}

/* Unedited and edited, written to another directory (with a blank in its
 * name) and read back: the same scene; written again: the same bytes. */
static void test_save_load_same_scene(void **state)
{
    (void)state;
    const char *scn = make_scene();
    char outdir[1024], out[1100], again[1100];
    snprintf(outdir, sizeof outdir, "%s", test_path("saved here"));
    mkdir(outdir, 0777);
    snprintf(out, sizeof out, "%s/edited.scn", outdir);
    snprintf(again, sizeof again, "%s/again.scn", outdir);
    for (int edited = 0; edited < 2; edited++) {
        ps_scene *s = load_file(scn);
        if (edited)
            edit(s);
        save_ok(s, out);
        ps_scene *back = load_file(out);
        assert_same_scene(s, back, SCENE_SAME_SETTINGS);
        /* and a clone carries what the writer needs */
        ps_scene *copy = NULL;
        ps_error err;
        assert_int_equal(ps_scene_clone(back, &copy, &err), PS_OK);
        save_ok(copy, again);
        char *a = read_text(out), *b = read_text(again);
        /* the first line names the scene it was saved from */
        assert_string_equal(strchr(a, '\n'), strchr(b, '\n'));
        /* paths relative to the new directory */
        assert_non_null(strstr(a, " ../orig/lamp.obj"));
        assert_non_null(strstr(a, " ../../../../tests/data/ies-good/1986-rotational.ies"));
        if (edited) {
            assert_non_null(strstr(a, "move "));
            assert_non_null(strstr(a, "light-power 0 3.1000000000000001 2.2000000000000002 1.3"));
        }
        free(a);
        free(b);
        ps_scene_destroy(copy);
        ps_scene_destroy(back);
        ps_scene_destroy(s);
    }
}

/* Saved beside the original directory: its files by a relative path, none
 * absolute. */
static void test_paths_relative_beside(void **state)
{
    (void)state;
    const char *scn = make_scene();
    ps_scene *s = load_file(scn);
    char out[1100];
    snprintf(out, sizeof out, "%s/abs.scn", test_path(""));
    save_ok(s, out);
    char *text = read_text(out);
    assert_non_null(strstr(text, "orig/lamp.obj")); /* relative: "orig/lamp.obj" */
    assert_null(strstr(text, " /"));                /* nothing absolute when a relative path exists */
    free(text);
    ps_scene_destroy(s);
}

/* A place that cannot take the file: an error naming it, nothing written. */
static void test_write_refused(void **state)
{
    (void)state;
    ps_scene *s = load_file(make_scene());
    char out[1100];
    snprintf(out, sizeof out, "%s/no/such/dir/x.scn", test_path(""));
    ps_error err;
    assert_int_not_equal(ps_scene_write(s, out, &err), PS_OK);
    assert_non_null(strstr(err.msg, "x.scn"));
    assert_int_equal(access(out, F_OK), -1);
    ps_scene_destroy(s);
}

/* Saved edits in a hand-written file are checked like any key. */
static void test_saved_edits_checked(void **state)
{
    (void)state;
    const char *base = "camera eye 0 1 3 target 0 1 0\nlight point position 0 1 0 power 1 1 1\n";
    const char *bad[] = {"quad corner 0 0 0 edge1 1 0 0 edge2 0 0 1 move 1 2\n",
                         "quad corner 0 0 0 edge1 1 0 0 edge2 0 0 1 move 1 2 3 bogus\n",
                         "mesh orig/lamp.obj light-power 5 1 1 1\n", "mesh orig/lamp.obj light-power -1 1 1 1\n"};
    make_scene();
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path(""));
    dir[strlen(dir) - 1] = '\0';
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        char text[1024];
        snprintf(text, sizeof text, "%s%s", base, bad[k]);
        ps_scene *s = NULL;
        ps_error err;
        warn_log log = {0, ""};
        ps_scene_load_options opts = {{log_warning, &log}};
        assert_int_not_equal(ps_scene_load_text(text, "e.scn", dir, &opts, &s, &err), PS_OK);
        assert_null(s);
        assert_non_null(strstr(err.msg, "e.scn:3:"));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_save_load_same_scene),
        cmocka_unit_test(test_paths_relative_beside),
        cmocka_unit_test(test_write_refused),
        cmocka_unit_test(test_saved_edits_checked),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
