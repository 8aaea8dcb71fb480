/* test_fuzz_replay.c: replays the fuzz seeds and every saved finding
 * (tests/data/fuzz/TARGET/) through the fuzz target bodies (fuzz/targets.c),
 * compiled here by gcc, so a fixed crash stays fixed without clang.
 *
 * The bodies abort on a broken promise (an error that is not one line naming
 * the input, an accepted scene with out-of-range data); on top of that this
 * test checks each input's outcome: seeds load, malformed scenes fail at the
 * line their "# expect:" comment names, and a finding's file name starts with
 * the status it must now give ("parse-", "ok-", ...: see expected_status). */
#include "test.h"

#include <dirent.h>
#include <stdbool.h>
#include <time.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "fuzz_targets.h"

#define MAX_FILES 256
#define MAX_INPUT_BYTES ((size_t)1 << 20)
#define EXPECT_TAG "# expect: "
/* The many-names inputs: sizes at which the quadratic lookups found while
 * fuzzing took about 45 s (scene) and 25 s (OBJ) in the release build, and a
 * bound between those and the linear code (about 1 s and 2.5 s release, 2 s
 * and 5 s under ASan, on an idle machine) with room for a busy one. */
#define MANY_MATERIALS 60000
#define MANY_REFERENCES 200000
#define MANY_MTL_MATERIALS 40000
#define MANY_NAMES_MAX_SECONDS 15.0

typedef ps_status (*target_fn)(const uint8_t *data, size_t size, const char *path, ps_error *err);

static ps_status run_scene(const uint8_t *data, size_t size, const char *path, ps_error *err)
{
    /* Meshes resolve beside the scene, as ps_scene_load does. */
    char dir[1024];
    snprintf(dir, sizeof dir, "%.1000s", path);
    char *slash = strrchr(dir, '/');
    if (slash)
        *slash = '\0';
    else
        dir[0] = '\0';
    return ps_fuzz_scene(data, size, path, dir, err);
}
static ps_status run_obj(const uint8_t *data, size_t size, const char *path, ps_error *err)
{
    (void)path;
    return ps_fuzz_obj(data, size, err);
}
static ps_status run_png(const uint8_t *data, size_t size, const char *path, ps_error *err)
{
    (void)path;
    return ps_fuzz_png(data, size, err);
}
static ps_status run_pfm(const uint8_t *data, size_t size, const char *path, ps_error *err)
{
    (void)path;
    return ps_fuzz_pfm(data, size, err);
}

static ps_status run_exr(const uint8_t *data, size_t size, const char *path, ps_error *err)
{
    (void)path;
    return ps_fuzz_exr(data, size, err);
}
static ps_status run_ies(const uint8_t *data, size_t size, const char *path, ps_error *err)
{
    return ps_fuzz_ies(data, size, path, err);
}

static int by_name(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* The regular files in dir whose names end in suffix ("" for all), sorted;
 * the caller frees each name. A missing folder has none. */
static int list_files(const char *dir, const char *suffix, char *names[MAX_FILES])
{
    int count = 0;
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    struct dirent *e;
    while ((e = readdir(d)) && count < MAX_FILES) {
        size_t n = strlen(e->d_name), k = strlen(suffix);
        if (e->d_name[0] == '.' || n < k || strcmp(e->d_name + n - k, suffix) != 0)
            continue;
        char path[1024];
        struct stat sb;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (stat(path, &sb) == 0 && S_ISREG(sb.st_mode))
            names[count++] = strdup(e->d_name);
    }
    closedir(d);
    qsort(names, (size_t)count, sizeof *names, by_name);
    return count;
}

static uint8_t *read_all(const char *path, size_t *size)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    uint8_t *buf = malloc(MAX_INPUT_BYTES);
    assert_non_null(buf);
    *size = fread(buf, 1, MAX_INPUT_BYTES, fp);
    assert_true(feof(fp)); /* the whole file fitted */
    fclose(fp);
    return buf;
}

/* Runs every file of dir (ending in suffix) through fn and checks that it
 * gives `want`; returns how many there were. */
static int replay_dir(const char *dir, const char *suffix, target_fn fn, ps_status want)
{
    char *names[MAX_FILES];
    int count = list_files(dir, suffix, names);
    for (int i = 0; i < count; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        size_t size;
        uint8_t *data = read_all(path, &size);
        ps_error err;
        ps_status st = fn(data, size, path, &err);
        if (st != want)
            fail_msg("%s: status %s (%s), expected %s", path, ps_status_name(st), st ? err.msg : "",
                     ps_status_name(want));
        free(data);
        free(names[i]);
    }
    return count;
}

static void good_scenes_load(void **state)
{
    (void)state;
    assert_true(replay_dir("data/scenes", ".scn", run_scene, PS_OK) >= 2);
    assert_true(replay_dir("tests/data/good", ".scn", run_scene, PS_OK) >= 2);
}

/* Each malformed scene fails with a message at the line its first line names
 * ("# expect: LINE: ..."): "<scene>:LINE: " or, for a broken OBJ, the OBJ's
 * line and then "(mesh at <scene>:N)". A scene with a NUL byte is read from a
 * scratch file named fuzz.scn (fuzz_targets.h), so that name is expected. */
static void bad_scenes_refused_at_their_line(void **state)
{
    (void)state;
    const char *dir = "tests/data/bad";
    char *names[MAX_FILES];
    int count = list_files(dir, ".scn", names);
    assert_true(count >= 40);
    for (int i = 0; i < count; i++) {
        char path[1024], where[1100];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        size_t size;
        uint8_t *data = read_all(path, &size);
        size_t tag = strlen(EXPECT_TAG);
        assert_true(size > tag && memcmp(data, EXPECT_TAG, tag) == 0);
        int line = atoi((const char *)data + tag);
        assert_true(line >= 1);
        ps_error err;
        ps_status st = run_scene(data, size, path, &err);
        if (st == PS_OK)
            fail_msg("%s: loaded, but should have failed", path);
        /* Malformed text, a bad value, a missing mesh file or an over-long line. */
        assert_true(st == PS_ERR_PARSE || st == PS_ERR_RANGE || st == PS_ERR_IO || st == PS_ERR_LIMIT);
        bool binary = memchr(data, '\0', size) != NULL;
        snprintf(where, sizeof where, "%s:%d: ", binary ? "fuzz.scn" : path, line);
        char at[1100], obj_line[32];
        snprintf(at, sizeof at, "(mesh at %s:", path);
        snprintf(obj_line, sizeof obj_line, ":%d: ", line);
        /* The scratch file's folder comes before "fuzz.scn". */
        bool located = binary ? strstr(err.msg, where) != NULL : strncmp(err.msg, where, strlen(where)) == 0;
        if (!located && !(strstr(err.msg, at) && strstr(err.msg, obj_line)))
            fail_msg("%s: message '%s' lacks '%s' or '%s' with '%s'", path, err.msg, where, at, obj_line);
        free(data);
        free(names[i]);
    }
}

/* The seeds written for the fuzzers (fuzz/seeds/) and the repository's own
 * images are valid; so is the test OBJ, and its NaN sibling is refused. */
static void seeds_load(void **state)
{
    (void)state;
    assert_true(replay_dir("fuzz/seeds/obj", "", run_obj, PS_OK) >= 2);
    assert_int_equal(replay_dir("tests/data/good", "tri.obj", run_obj, PS_OK), 1);
    assert_int_equal(replay_dir("tests/data/good", "nan-vertex.obj", run_obj, PS_ERR_PARSE), 1);
    assert_true(replay_dir("fuzz/seeds/png", "", run_png, PS_OK) >= 5);
    assert_true(replay_dir("tests/data/golden", ".png", run_png, PS_OK) >= 1);
    assert_true(replay_dir("fuzz/seeds/pfm", "", run_pfm, PS_OK) >= 3);
    assert_true(replay_dir("tests/data/golden", ".pfm", run_pfm, PS_OK) >= 1);
    assert_int_equal(replay_dir("fuzz/seeds/exr", "", run_exr, PS_OK), 3);
    /* The LM-63 target: the bundled and good files load, the bad corpus is
     * refused (test_ies checks each message's line). */
    assert_int_equal(replay_dir("data/ies", ".ies", run_ies, PS_OK), 3);
    assert_int_equal(replay_dir("tests/data/ies-good", ".ies", run_ies, PS_OK), 6);
    char *names[MAX_FILES];
    int count = list_files("tests/data/ies-bad", ".ies", names);
    assert_true(count >= 20);
    for (int i = 0; i < count; i++) {
        char path[1024];
        snprintf(path, sizeof path, "tests/data/ies-bad/%s", names[i]);
        size_t size;
        uint8_t *data = read_all(path, &size);
        ps_error err;
        if (run_ies(data, size, path, &err) == PS_OK)
            fail_msg("%s: accepted, but should have been refused", path);
        free(data);
        free(names[i]);
    }
}

/* A growable text buffer for generated inputs. */
typedef struct text_buf {
    char *s;
    size_t len, cap;
} text_buf;

static void append(text_buf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void append(text_buf *b, const char *fmt, ...)
{
    va_list ap;
    for (;;) {
        va_start(ap, fmt);
        int n = vsnprintf(b->s + b->len, b->cap - b->len, fmt, ap);
        va_end(ap);
        assert_true(n >= 0);
        if ((size_t)n < b->cap - b->len) {
            b->len += (size_t)n;
            return;
        }
        b->cap = b->cap ? b->cap * 2 : 1 << 16;
        b->s = realloc(b->s, b->cap);
        assert_non_null(b->s);
    }
}

static double seconds_since(double t0) { return ps_now_seconds() - t0; }

/* Many materials, each referenced from many spheres: looked up by a scan of
 * the list, this took 51 s; with the hash about one. */
static void many_scene_materials_load_quickly(void **state)
{
    (void)state;
    text_buf b = {0};
    append(&b, "camera eye 0 0 5 target 0 0 0\nlight point position 0 3 0 power 1 1 1\n");
    for (int i = 0; i < MANY_MATERIALS; i++)
        append(&b, "material m%d diffuse albedo 0.5 0.5 0.5\n", i);
    for (int i = 0; i < MANY_REFERENCES; i++)
        append(&b, "sphere center 0 0 0 radius 1 material m%d\n", MANY_MATERIALS - 1 - i % MANY_MATERIALS);
    double t0 = ps_now_seconds();
    ps_error err;
    ps_status st = ps_fuzz_scene((const uint8_t *)b.s, b.len, "many.scn", "", &err);
    double took = seconds_since(t0);
    free(b.s);
    print_message("%d materials, %d references: %.2f s\n", MANY_MATERIALS, MANY_REFERENCES, took);
    if (st != PS_OK)
        fail_msg("%s", err.msg);
    if (took > MANY_NAMES_MAX_SECONDS)
        fail_msg("%d materials, %d references: %.1f s", MANY_MATERIALS, MANY_REFERENCES, took);
}

/* A mesh with many emissive MTL materials, one face each: the usemtl check,
 * the Ns/Ni matching and the per-material face scan for mesh lights were
 * each quadratic in the number of materials. */
static void many_mtl_materials_load_quickly(void **state)
{
    (void)state;
    text_buf b = {0};
    append(&b, "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for (int i = 0; i < MANY_MTL_MATERIALS; i++)
        append(&b, "usemtl m%d\nf 1 2 3\n", i);
    append(&b, "%s", PS_FUZZ_MTL_SEPARATOR);
    for (int i = 0; i < MANY_MTL_MATERIALS; i++)
        append(&b, "newmtl m%d\nKd 0.5 0.5 0.5\nKe 1 1 1\nNs 10\n", i);
    double t0 = ps_now_seconds();
    ps_error err;
    ps_status st = ps_fuzz_obj((const uint8_t *)b.s, b.len, &err);
    double took = seconds_since(t0);
    free(b.s);
    print_message("%d MTL materials: %.2f s\n", MANY_MTL_MATERIALS, took);
    if (st != PS_OK)
        fail_msg("%s", err.msg);
    if (took > MANY_NAMES_MAX_SECONDS)
        fail_msg("%d MTL materials: %.1f s", MANY_MTL_MATERIALS, took);
}

/* What a finding's file name says it must give now. */
static const struct {
    const char *prefix;
    ps_status status;
} expected_status[] = {
    {"ok-", PS_OK},         {"io-", PS_ERR_IO},       {"parse-", PS_ERR_PARSE}, {"format-", PS_ERR_FORMAT},
    {"range-", PS_ERR_RANGE}, {"limit-", PS_ERR_LIMIT},
};

/* Each finding of the target replays to the status its name starts with;
 * a name without such a prefix is a mistake in the corpus. */
static void replay_findings(const char *target, target_fn fn)
{
    char dir[256];
    snprintf(dir, sizeof dir, "tests/data/fuzz/%s", target);
    char *names[MAX_FILES];
    int count = list_files(dir, "", names);
    for (int i = 0; i < count; i++) {
        size_t k = 0, n = sizeof expected_status / sizeof expected_status[0];
        while (k < n && strncmp(names[i], expected_status[k].prefix, strlen(expected_status[k].prefix)) != 0)
            k++;
        if (k == n)
            fail_msg("%s/%s: the name must start with ok-, io-, parse-, format-, range- or limit-", dir, names[i]);
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        size_t size;
        uint8_t *data = read_all(path, &size);
        ps_error err;
        ps_status st = fn(data, size, path, &err);
        if (st != expected_status[k].status)
            fail_msg("%s: status %s (%s), expected %s", path, ps_status_name(st), st ? err.msg : "",
                     ps_status_name(expected_status[k].status));
        free(data);
        free(names[i]);
    }
}

static void scene_findings(void **state)
{
    (void)state;
    replay_findings("scene", run_scene);
}
static void obj_findings(void **state)
{
    (void)state;
    replay_findings("obj", run_obj);
}
static void png_findings(void **state)
{
    (void)state;
    replay_findings("png", run_png);
}
static void pfm_findings(void **state)
{
    (void)state;
    replay_findings("pfm", run_pfm);
}
static void exr_findings(void **state)
{
    (void)state;
    replay_findings("exr", run_exr);
}
static void ies_findings(void **state)
{
    (void)state;
    replay_findings("ies", run_ies);
}

int main(void)
{
    /* The bodies write their scratch files under $TMPDIR: keep them in build/. */
    const char *scratch = test_path("fuzz");
    mkdir(scratch, 0777);
    setenv("TMPDIR", scratch, 1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(good_scenes_load),
        cmocka_unit_test(bad_scenes_refused_at_their_line),
        cmocka_unit_test(seeds_load),
        cmocka_unit_test(many_scene_materials_load_quickly),
        cmocka_unit_test(many_mtl_materials_load_quickly),
        cmocka_unit_test(scene_findings),
        cmocka_unit_test(obj_findings),
        cmocka_unit_test(png_findings),
        cmocka_unit_test(pfm_findings),
        cmocka_unit_test(ies_findings),
        cmocka_unit_test(exr_findings),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    rmdir(scratch);
    return failed;
}
