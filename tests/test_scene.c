/* test_scene.c: the .scn parser on good scenes (exact derived values) and on
 * the malformed corpus in tests/data/bad (each: one-line "file:line: problem"). */
#include "test.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "scene/obj.h"
#include "scene/scene.h"

static ps_scene *load_ok(const char *path)
{
    ps_scene *s = NULL;
    ps_error err;
    ps_status st = ps_scene_load(path, NULL, &s, &err);
    if (st != PS_OK)
        fail_msg("%s: %s", path, err.msg);
    return s;
}

static ps_status load_text(const char *text, ps_scene **s, ps_error *err, warn_log *log)
{
    ps_scene_load_options opts = {{log_warning, log}};
    return ps_scene_load_text(text, "inline.scn", "tests/data/good", &opts, s, err);
}

static void default_scene(void **state)
{
    (void)state;
    ps_scene *s = load_ok("data/scenes/cornell-caustic.scn");
    size_t nmat, nobj, ntri, nlight, npos;
    const ps_material *m = ps_scene_materials(s, &nmat);
    const ps_object *o = ps_scene_objects(s, &nobj);
    const ps_light *l = ps_scene_lights(s, &nlight);
    (void)ps_scene_triangles(s, &ntri);
    (void)ps_scene_positions(s, &npos);
    assert_int_equal(nmat, 5);
    assert_int_equal(nobj, 7);
    assert_int_equal(ntri, 10); /* five walls, two triangles each; spheres are analytic */
    assert_int_equal(npos, 20);
    assert_int_equal(nlight, 1);
    assert_string_equal(m[0].name, "white");
    assert_near(m[0].albedo.g, 0.75, 0);
    assert_int_equal(m[3].type, PS_MAT_DIELECTRIC);
    assert_near(m[3].ior, 1.5, 0);
    assert_int_equal(m[4].type, PS_MAT_MIRROR);
    /* The glass and the mirror spheres, exactly as the issue places them. */
    assert_int_equal(o[5].type, PS_OBJ_SPHERE);
    assert_near(o[5].center.x, 0.35, 0);
    assert_near(o[5].radius, 0.4, 0);
    assert_true(o[5].specular && o[6].specular && !o[0].specular);
    assert_near(o[6].center.z, -0.4, 0);
    assert_int_equal(l[0].type, PS_LIGHT_POINT);
    assert_near(l[0].position.y, 1.9, 0);
    assert_near(ps_scene_total_power(s).r, 100, 0);
    ps_aabb b = ps_scene_bounds(s);
    assert_near(b.lo.x, -1, 0);
    assert_near(b.lo.y, 0, 0);
    assert_near(b.hi.y, 2, 0);
    assert_near(b.hi.z, 1, 0);
    const ps_camera *c = ps_scene_camera(s);
    assert_near(c->eye.z, 3.4, 0);
    assert_near(c->fov_deg, 40, 0);
    const ps_scene_defaults *d = ps_scene_get_defaults(s);
    assert_int_equal(d->width, 512);
    assert_int_equal(d->caustic_photons, 200000);
    assert_int_equal(d->global_photons, 50000);
    assert_near(d->caustic_radius, 0.02, 0);
    assert_near(d->global_radius, 0.1, 0);
    /* Every wall faces into the box: its normal points toward the centre (0,1,0). */
    for (uint32_t t = 0; t < ntri; t++) {
        ps_vec3 n = ps_scene_triangle_normal(s, t);
        const ps_triangle *tr = &ps_scene_triangles(s, NULL)[t];
        ps_vec3 p = ps_scene_positions(s, NULL)[tr->v[0]];
        assert_true(ps_v3_dot(n, ps_v3_sub(ps_v3(0, 1, 0), p)) > 0.0);
        assert_near(ps_scene_triangle_area(s, t), 2.0, 1e-12);
    }
    ps_scene_destroy(s);
}

static void area_light_variant(void **state)
{
    (void)state;
    ps_scene *s = load_ok("data/scenes/cornell-caustic-area.scn");
    size_t n;
    const ps_light *l = ps_scene_lights(s, &n);
    assert_int_equal(n, 1);
    assert_int_equal(l[0].type, PS_LIGHT_QUAD);
    assert_near(l[0].area, 0.25, 1e-15);
    /* Emits down into the room, with L = flux / (pi * area). */
    assert_near(l[0].direction.y, -1.0, 1e-15);
    assert_near(l[0].radiance.r, 100.0 / (PS_PI * 0.25), 1e-9);
    assert_near(l[0].position.y, 1.999, 0);
    ps_scene_destroy(s);
}

static void every_light_type(void **state)
{
    (void)state;
    ps_scene *s;
    ps_error err;
    warn_log log = {0, ""};
    const char *text = "camera eye 0 1 3 target 0 1 0\n"
                       "light point  position 0 1.9 0  power 100 50 25\n"
                       "light spot   position 0 1.9 0  direction 0 -2 0  angle 30  power 50 50 50\n"
                       "light quad   corner -0.25 1.999 -0.25  edge1 0.5 0 0  edge2 0 0 0.5  power 100 100 100\n"
                       "light sphere center 0 1.8 0  radius 0.05  power 100 100 100\n"
                       "light disc   center 0 1.99 0  normal 0 -3 0  radius 0.2  power 100 100 100\n"
                       "light point  position 0 1 0  power 0 0 0\n"
                       "sphere center 0 0 0 radius 0.5\n"; /* something to light */
    assert_int_equal(load_text(text, &s, &err, &log), PS_OK);
    size_t n;
    const ps_light *l = ps_scene_lights(s, &n);
    assert_int_equal(n, 6);
    assert_near(l[0].power.g, 50, 0);
    assert_near(l[1].direction.y, -1, 1e-15); /* normalised */
    assert_near(l[1].cos_angle, sqrt(3.0) / 2.0, 1e-15);
    assert_near(l[2].area, 0.25, 1e-15);
    assert_near(l[2].direction.y, -1, 1e-15);
    assert_near(l[3].area, 4 * PS_PI * 0.05 * 0.05, 1e-15);
    assert_near(l[3].radiance.r, 100 / (PS_PI * 4 * PS_PI * 0.0025), 1e-9);
    assert_near(l[4].area, PS_PI * 0.04, 1e-15);
    assert_near(l[4].direction.y, -1, 1e-15);
    assert_near(ps_scene_total_power(s).r, 100 + 50 + 300, 1e-12);
    /* The zero-power light loads with a warning naming its line. */
    assert_int_equal(log.count, 1);
    assert_non_null(strstr(log.last, "inline.scn:7: light has zero power"));
    ps_scene_destroy(s);
}

static void defaults_when_absent(void **state)
{
    (void)state;
    ps_scene *s;
    ps_error err;
    warn_log log = {0, ""};
    const char *text = "camera eye 0 0 5 target 0 0 0\n"
                       "sphere center 0 0 0 radius 1\n"
                       "light point position 0 3 0 power 1 1 1\n";
    assert_int_equal(load_text(text, &s, &err, &log), PS_OK);
    const ps_scene_defaults *d = ps_scene_get_defaults(s);
    assert_int_equal(d->width, 512);
    assert_int_equal(d->height, 512);
    assert_int_equal(d->caustic_photons, 200000);
    assert_int_equal(d->global_photons, 50000);
    /* Bounds (-1,-1,-1)..(1,3,1): diagonal sqrt(4+16+4) */
    double diag = sqrt(24.0);
    assert_near(d->caustic_radius, 0.005 * diag, 1e-15);
    assert_near(d->global_radius, 0.025 * diag, 1e-15);
    const ps_camera *c = ps_scene_camera(s);
    assert_near(c->up.y, 1, 0);
    assert_near(c->fov_deg, 40, 0);
    /* A sphere without a material gets pbrt's grey default. */
    size_t nmat;
    const ps_material *m = ps_scene_materials(s, &nmat);
    assert_int_equal(nmat, 1);
    assert_string_equal(m[0].name, "(default)");
    assert_near(m[0].albedo.r, 0.5, 0);
    assert_int_equal(log.count, 0);
    ps_scene_destroy(s);
}

/* Comments, blank lines, CRLF endings, tabs, quoted paths and keys in any order. */
static void lexical_details(void **state)
{
    (void)state;
    ps_scene *s;
    ps_error err;
    warn_log log = {0, ""};
    const char *text = "# a comment\r\n"
                       "\r\n"
                       "camera\tfov 30 target 0 0 0 eye 0 0 5   # trailing comment\r\n"
                       "material m glossy exponent 20 specular 0.2 0.2 0.2 albedo 0.8 0.8 0.8\r\n"
                       "mesh \"tri.obj\" material m translate 0 0 1\r\n"
                       "photons global 7\r\n"
                       "light point power 1 1 1 position 0 1 0\r\n";
    if (load_text(text, &s, &err, &log) != PS_OK)
        fail_msg("%s", err.msg);
    size_t n;
    const ps_material *m = ps_scene_materials(s, &n);
    assert_int_equal(m[0].type, PS_MAT_GLOSSY);
    assert_near(m[0].exponent, 20, 0);
    assert_near(ps_scene_camera(s)->fov_deg, 30, 0);
    const ps_scene_defaults *d = ps_scene_get_defaults(s);
    assert_int_equal(d->global_photons, 7);
    assert_int_equal(d->caustic_photons, 200000); /* what a statement leaves out keeps its default */
    const ps_vec3 *p = ps_scene_positions(s, &n);
    assert_int_equal(n, 3);
    assert_near(p[1].x, 1, 0);
    assert_near(p[1].z, 1, 0);
    ps_scene_destroy(s);
}

/* Splits "# expect: LINE: FRAGMENT" from a bad scene's first line. */
static void read_expectation(const char *path, int *line, char *fragment, size_t n)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    char buf[512];
    assert_non_null(fgets(buf, sizeof buf, fp));
    fclose(fp);
    char *colon;
    assert_int_equal(strncmp(buf, "# expect: ", 10), 0);
    *line = (int)strtol(buf + 10, &colon, 10);
    assert_true(colon[0] == ':' && colon[1] == ' ');
    snprintf(fragment, n, "%s", colon + 2);
    fragment[strcspn(fragment, "\n")] = '\0';
}

static int by_name(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* Every malformed scene fails with one line: "<scene>:<line>: ..." holding the
 * expected fragment, or for a broken OBJ "<obj>:<line>: ... (mesh at <scene>:N)". */
static void malformed_corpus(void **state)
{
    (void)state;
    const char *dir = "tests/data/bad";
    DIR *d = opendir(dir);
    assert_non_null(d);
    char *names[128];
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d)) && count < 128)
        if (strstr(e->d_name, ".scn"))
            names[count++] = strdup(e->d_name);
    closedir(d);
    qsort(names, (size_t)count, sizeof *names, by_name);
    assert_true(count >= 25);
    for (int i = 0; i < count; i++) {
        char path[512], fragment[256], prefix[600];
        int line;
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        read_expectation(path, &line, fragment, sizeof fragment);
        ps_scene *s = (ps_scene *)1;
        ps_error err;
        ps_scene_load_options quiet = {{log_warning, &(warn_log){0, ""}}};
        ps_status st = ps_scene_load(path, &quiet, &s, &err);
        if (st == PS_OK)
            fail_msg("%s: loaded, but should have failed", path);
        assert_null(s);
        assert_null(strchr(err.msg, '\n'));
        snprintf(prefix, sizeof prefix, "%s:%d: ", path, line);
        bool located = strncmp(err.msg, prefix, strlen(prefix)) == 0;
        if (!located) { /* a broken OBJ names its own file and line, then the scene's */
            char at[600], linetag[32];
            snprintf(at, sizeof at, "(mesh at %s:", path);
            snprintf(linetag, sizeof linetag, ":%d: ", line);
            located = strstr(err.msg, at) && strstr(err.msg, linetag);
        }
        if (!located || !strstr(err.msg, fragment))
            fail_msg("%s: message '%s' lacks '%s' or '%s'", names[i], err.msg, prefix, fragment);
        free(names[i]);
    }
}

/* Lights and nothing for them to fall on: valid, but every photon escapes,
 * so the loader says so, naming the file; any geometry at all silences it. */
static void no_geometry_warning(void **state)
{
    (void)state;
    const char *lights_only = "camera eye 0 1 3 target 0 1 0\n"
                              "light point position 0 1.9 0 power 10 10 10\n"
                              "light quad corner -0.25 1.999 -0.25 edge1 0.5 0 0 edge2 0 0 0.5 power 10 10 10\n";
    const char *with_mesh = "camera eye 0 1 3 target 0 1 0\n"
                            "light point position 0 1.9 0 power 10 10 10\n"
                            "mesh tri.obj\n";
    ps_scene *s;
    ps_error err;
    warn_log log = {0, ""};
    assert_int_equal(load_text(lights_only, &s, &err, &log), PS_OK);
    assert_int_equal(log.count, 1);
    assert_string_equal(log.last, "inline.scn: scene has no geometry");
    size_t n;
    (void)ps_scene_objects(s, &n);
    assert_int_equal(n, 0);
    ps_scene_destroy(s);
    warn_log quiet = {0, ""};
    assert_int_equal(load_text(with_mesh, &s, &err, &quiet), PS_OK);
    assert_int_equal(quiet.count, 0);
    ps_scene_destroy(s);
    /* From a file, the warning names it as given. */
    const char *path = test_path("lights-only.scn");
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs(lights_only, fp);
    fclose(fp);
    warn_log from_file = {0, ""};
    ps_scene_load_options opts = {{log_warning, &from_file}};
    assert_int_equal(ps_scene_load(path, &opts, &s, &err), PS_OK);
    char want[1100];
    snprintf(want, sizeof want, "%s: scene has no geometry", path);
    assert_int_equal(from_file.count, 1);
    assert_string_equal(from_file.last, want);
    ps_scene_destroy(s);
}

/* An OBJ's own problem keeps its line in the error (err.line, the OBJ's line,
 * the one the message starts with), also where the path has a space; a mesh
 * that cannot be read at all is the scene line's problem (its line). The
 * scene loader decides between them from err.line, not from the text. */
static void mesh_error_lines(void **state)
{
    (void)state;
    char dir[1100], obj[1200], scn[1200], want[2600];
    snprintf(dir, sizeof dir, "%s", test_path("with space"));
    mkdir(dir, 0777);
    snprintf(obj, sizeof obj, "%s/bad.obj", dir);
    snprintf(scn, sizeof scn, "%s/bad.scn", dir);
    FILE *fp = fopen(obj, "wb");
    assert_non_null(fp);
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n", fp);
    fclose(fp);
    fp = fopen(scn, "wb");
    assert_non_null(fp);
    fputs("camera eye 0 1 3 target 0 1 0\nlight point position 0 1.9 0 power 1 1 1\nmesh bad.obj\n", fp);
    fclose(fp);
    ps_scene *s;
    ps_error err;
    assert_int_equal(ps_scene_load(scn, NULL, &s, &err), PS_ERR_PARSE);
    assert_int_equal(err.line, 3);
    snprintf(want, sizeof want, "%s:3: 'v': 'x' is not a finite number (mesh at %s:3)", obj, scn);
    assert_string_equal(err.msg, want);
    /* The OBJ loader itself. */
    ps_obj_mesh om;
    assert_int_equal(ps_obj_load(obj, &om, NULL, &err), PS_ERR_PARSE);
    assert_int_equal(err.line, 3);
    snprintf(want, sizeof want, "%s:3: 'v': 'x' is not a finite number", obj);
    assert_string_equal(err.msg, want);
    /* A missing OBJ: no line of its own, the scene's line 4 instead. */
    fp = fopen(scn, "wb");
    assert_non_null(fp);
    fputs("camera eye 0 1 3 target 0 1 0\nlight point position 0 1.9 0 power 1 1 1\n\nmesh gone.obj\n", fp);
    fclose(fp);
    assert_int_equal(ps_scene_load(scn, NULL, &s, &err), PS_ERR_IO);
    assert_int_equal(err.line, 4);
    snprintf(want, sizeof want, "%s:4: mesh: ", scn);
    assert_int_equal(strncmp(err.msg, want, strlen(want)), 0);
}

static void missing_and_unreadable_files(void **state)
{
    (void)state;
    ps_scene *s;
    ps_error err;
    assert_int_equal(ps_scene_load("tests/data/no-such.scn", NULL, &s, &err), PS_ERR_IO);
    assert_non_null(strstr(err.msg, "tests/data/no-such.scn: cannot open"));
    assert_int_equal(ps_scene_load("tests/data", NULL, &s, &err), PS_ERR_IO);
    assert_non_null(strstr(err.msg, "is a directory"));
    assert_int_equal(ps_scene_load("/dev/null", NULL, &s, &err), PS_ERR_IO);
    assert_non_null(strstr(err.msg, "not a regular file"));
    /* An empty file is a scene without camera: an error at line 1. */
    FILE *fp = fopen(test_path("empty.scn"), "wb");
    fclose(fp);
    assert_int_equal(ps_scene_load(test_path("empty.scn"), NULL, &s, &err), PS_ERR_PARSE);
    assert_non_null(strstr(err.msg, "empty.scn:1: the scene has no camera"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(default_scene),
        cmocka_unit_test(area_light_variant),
        cmocka_unit_test(every_light_type),
        cmocka_unit_test(defaults_when_absent),
        cmocka_unit_test(lexical_details),
        cmocka_unit_test(malformed_corpus),
        cmocka_unit_test(missing_and_unreadable_files),
        cmocka_unit_test(no_geometry_warning),
        cmocka_unit_test(mesh_error_lines),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
