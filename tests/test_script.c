/* test_script.c: the --script parser: the contract's example field by field,
 * every action and setting, time order, comments, and each malformed input
 * with its exact one-line "file:line: problem" message. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "photon/estimate.h"
#include "preview/script.h"
#include "preview/splat.h"

/* The contract's example, verbatim (the comment continues on a line of its own). */
static const char EXAMPLE[] =
    "    0.8  screenshot out/a.png          # PNG of the window as shown\n"
    "    0.9  move light 0  0.6 2 0         # light index (scene order) to a new position\n"
    "    1.0  move object 2  0 0.1 0        # object index (scene order) translated by a vector\n"
    "    1.2  set splat triangles           # any runtime setting: splat, layers, kernel, radius,\n"
    "                                       #   tau, precision, exposure, pause\n"
    "    1.3  orbit 15 -5                   # camera yaw/pitch in degrees about the target\n"
    "    1.7  quit\n";

static ps_script *parse_ok(const char *text)
{
    ps_script *s = NULL;
    ps_error err;
    ps_status st = ps_script_parse(text, "s.txt", &s, &err);
    if (st != PS_OK)
        fail_msg("parse failed: %s", err.msg);
    assert_non_null(s);
    return s;
}

/* Every field a kind does not use is zero. */
static void assert_rest_zero(const ps_script_action *a, bool path, bool index, bool v, bool power, bool orbit,
                             bool number, bool set)
{
    if (!path)
        assert_null(a->path);
    if (!index)
        assert_int_equal(a->index, 0);
    if (!v)
        assert_true(a->v.x == 0 && a->v.y == 0 && a->v.z == 0);
    if (!power)
        assert_true(a->power.r == 0 && a->power.g == 0 && a->power.b == 0);
    if (!orbit)
        assert_true(a->yaw == 0 && a->pitch == 0);
    if (!number)
        assert_true(a->number == 0 && a->number2 == 0);
    if (!set)
        assert_true(a->setting == 0 && a->choice == 0 && a->layers == 0);
}

static void check_example(const ps_script *s, int first_line)
{
    assert_int_equal(ps_script_count(s), 6);
    const ps_script_action *a = ps_script_at(s, 0);
    assert_near(a->time, 0.8, 0);
    assert_int_equal(a->line, first_line);
    assert_int_equal(a->kind, PS_SCRIPT_SCREENSHOT);
    assert_string_equal(a->path, "out/a.png");
    assert_rest_zero(a, true, false, false, false, false, false, false);

    a = ps_script_at(s, 1);
    assert_near(a->time, 0.9, 0);
    assert_int_equal(a->line, first_line + 1);
    assert_int_equal(a->kind, PS_SCRIPT_MOVE_LIGHT);
    assert_int_equal(a->index, 0);
    assert_near(a->v.x, 0.6, 0);
    assert_near(a->v.y, 2, 0);
    assert_near(a->v.z, 0, 0);
    assert_rest_zero(a, false, true, true, false, false, false, false);

    a = ps_script_at(s, 2);
    assert_near(a->time, 1.0, 0);
    assert_int_equal(a->line, first_line + 2);
    assert_int_equal(a->kind, PS_SCRIPT_MOVE_OBJECT);
    assert_int_equal(a->index, 2);
    assert_near(a->v.x, 0, 0);
    assert_near(a->v.y, 0.1, 0);
    assert_near(a->v.z, 0, 0);
    assert_rest_zero(a, false, true, true, false, false, false, false);

    a = ps_script_at(s, 3);
    assert_near(a->time, 1.2, 0);
    assert_int_equal(a->line, first_line + 3);
    assert_int_equal(a->kind, PS_SCRIPT_SET);
    assert_int_equal(a->setting, PS_SET_SPLAT);
    assert_int_equal(a->choice, 1);
    assert_int_equal(a->layers, 0);
    assert_rest_zero(a, false, false, false, false, false, false, true);

    a = ps_script_at(s, 4);
    assert_near(a->time, 1.3, 0);
    assert_int_equal(a->line, first_line + 5); /* after the comment-only line */
    assert_int_equal(a->kind, PS_SCRIPT_ORBIT);
    assert_near(a->yaw, 15, 0);
    assert_near(a->pitch, -5, 0);
    assert_rest_zero(a, false, false, false, false, true, false, false);

    a = ps_script_at(s, 5);
    assert_near(a->time, 1.7, 0);
    assert_int_equal(a->line, first_line + 6);
    assert_int_equal(a->kind, PS_SCRIPT_QUIT);
    assert_rest_zero(a, false, false, false, false, false, false, false);

    assert_null(ps_script_at(s, 6));
}

static void contract_example(void **state)
{
    (void)state;
    ps_script *s = parse_ok(EXAMPLE);
    check_example(s, 1);
    ps_script_destroy(s);

    /* The same as a file, after a one-line header comment. */
    ps_error err;
    assert_int_equal(ps_script_load("tests/data/script/example.txt", &s, &err), PS_OK);
    check_example(s, 2);
    ps_script_destroy(s);
}

static void every_action_and_setting(void **state)
{
    (void)state;
    ps_script *s = parse_ok("0 set splat points\n"
                            "1 set splat sprites\n"
                            "2 set layers direct\n"
                            "3 set layers global,caustic,direct\n"
                            "4 set layers caustic\n"
                            "5 set kernel box\n"
                            "6 set kernel cone\n"
                            "7 set kernel gauss\n"
                            "8 set kernel epanechnikov\n"
                            "9 set radius 0.02\n"
                            "10 set radius 0.02 0.1\n"
                            "11 set tau 0.5\n"
                            "12 set precision none\n"
                            "13 set precision diffusion\n"
                            "14 set precision counter\n"
                            "15 set exposure 0.3\n"
                            "16 set pause on\n"
                            "17 set pause off\n"
                            "18 power light 3 100 50.5 0\n"
                            "19 angle light 4294967295 90\n"
                            "20 angle light 1 1e-3\n"
                            "21 move object 0 -1 -2 -3\n"
                            "22 screenshot ../x/\xc3\xa9t\xc3\xa9.png\n"
                            "1e2 orbit -360 89.5\n"
                            "0x1p-1 quit\n"); /* strtod's hex floats are numbers too */
    assert_int_equal(ps_script_count(s), 25);
    const ps_script_action *a = ps_script_at(s, 0);
    assert_int_equal(a->kind, PS_SCRIPT_SET);
    assert_int_equal(a->setting, PS_SET_SPLAT);
    assert_int_equal(a->choice, 0);
    a = ps_script_at(s, 1); /* 0x1p-1 = 0.5 */
    assert_int_equal(a->kind, PS_SCRIPT_QUIT);
    assert_near(a->time, 0.5, 0);
    assert_int_equal(a->line, 25);
    assert_int_equal(ps_script_at(s, 2)->choice, 2);

    const ps_script_action *l = ps_script_at(s, 3);
    assert_int_equal(l->setting, PS_SET_LAYERS);
    assert_int_equal(l->layers, PS_LAYER_DIRECT);
    assert_int_equal(ps_script_at(s, 4)->layers, 7);
    assert_int_equal(ps_script_at(s, 5)->layers, PS_LAYER_CAUSTIC);
    for (int k = 0; k < 4; k++) {
        a = ps_script_at(s, (size_t)(6 + k));
        assert_int_equal(a->setting, PS_SET_KERNEL);
        assert_int_equal(a->choice, k);
    }
    a = ps_script_at(s, 10);
    assert_int_equal(a->setting, PS_SET_RADIUS);
    assert_near(a->number, 0.02, 0);
    assert_near(a->number2, 0, 0);
    a = ps_script_at(s, 11);
    assert_near(a->number, 0.02, 0);
    assert_near(a->number2, 0.1, 0);
    a = ps_script_at(s, 12);
    assert_int_equal(a->setting, PS_SET_TAU);
    assert_near(a->number, 0.5, 0);
    for (int k = 0; k < 3; k++) {
        a = ps_script_at(s, (size_t)(13 + k));
        assert_int_equal(a->setting, PS_SET_PRECISION);
        assert_int_equal(a->choice, k);
    }
    a = ps_script_at(s, 16);
    assert_int_equal(a->setting, PS_SET_EXPOSURE);
    assert_near(a->number, 0.3, 0);
    a = ps_script_at(s, 17);
    assert_int_equal(a->setting, PS_SET_PAUSE);
    assert_int_equal(a->choice, 1);
    a = ps_script_at(s, 18);
    assert_int_equal(a->setting, PS_SET_PAUSE);
    assert_int_equal(a->choice, 0);

    a = ps_script_at(s, 19);
    assert_int_equal(a->kind, PS_SCRIPT_POWER);
    assert_int_equal(a->index, 3);
    assert_near(a->power.r, 100, 0);
    assert_near(a->power.g, 50.5, 0);
    assert_near(a->power.b, 0, 0);
    assert_rest_zero(a, false, true, false, true, false, false, false);
    a = ps_script_at(s, 20);
    assert_int_equal(a->kind, PS_SCRIPT_ANGLE);
    assert_int_equal(a->index, UINT32_MAX);
    assert_near(a->number, 90, 0);
    assert_rest_zero(a, false, true, false, false, false, true, false);
    a = ps_script_at(s, 21);
    assert_int_equal(a->index, 1);
    assert_near(a->number, 1e-3, 0);
    a = ps_script_at(s, 22);
    assert_int_equal(a->kind, PS_SCRIPT_MOVE_OBJECT);
    assert_near(a->v.x, -1, 0);
    assert_near(a->v.z, -3, 0);
    a = ps_script_at(s, 23);
    assert_int_equal(a->kind, PS_SCRIPT_SCREENSHOT);
    assert_string_equal(a->path, "../x/\xc3\xa9t\xc3\xa9.png");
    a = ps_script_at(s, 24);
    assert_int_equal(a->kind, PS_SCRIPT_ORBIT);
    assert_near(a->time, 100, 0);
    assert_near(a->yaw, -360, 0);
    assert_near(a->pitch, 89.5, 0);
    ps_script_destroy(s);
}

/* The choice indices are the project's enums, whose names are the script's words. */
static void choices_match_enums(void **state)
{
    (void)state;
    ps_script *s = parse_ok("0 set splat points\n0 set splat triangles\n0 set splat sprites\n"
                            "0 set kernel box\n0 set kernel cone\n0 set kernel gauss\n0 set kernel epanechnikov\n"
                            "0 set precision none\n0 set precision diffusion\n0 set precision counter\n");
    static const char *const words[] = {"points", "triangles", "sprites", "box", "cone",
                                        "gauss", "epanechnikov", "none", "diffusion", "counter"};
    for (size_t i = 0; i < 10; i++) {
        const ps_script_action *a = ps_script_at(s, i);
        const char *name = a->setting == PS_SET_SPLAT    ? ps_splat_mode_name((ps_splat_mode)a->choice)
                           : a->setting == PS_SET_KERNEL ? ps_kernel_name((ps_kernel)a->choice)
                                                         : ps_precision_name((ps_precision)a->choice);
        assert_string_equal(name, words[i]);
    }
    ps_script_destroy(s);
    /* Every name of the enums' own tables, in table order, is its value. */
    struct {
        const char *setting;
        const char *const *names;
        int count;
    } tables[] = {{"splat", ps_splat_mode_names, PS_SPLAT_MODE_COUNT},
                  {"kernel", ps_kernel_names, PS_KERNEL_COUNT},
                  {"precision", ps_precision_names, PS_PRECISION_COUNT}};
    for (size_t t = 0; t < 3; t++) {
        char text[512] = "";
        for (int k = 0; k < tables[t].count; k++) {
            size_t used = strlen(text);
            snprintf(text + used, sizeof text - used, "0 set %s %s\n", tables[t].setting, tables[t].names[k]);
        }
        assert_null(tables[t].names[tables[t].count]);
        s = parse_ok(text);
        assert_int_equal(ps_script_count(s), tables[t].count);
        for (int k = 0; k < tables[t].count; k++)
            assert_int_equal(ps_script_at(s, (size_t)k)->choice, k);
        ps_script_destroy(s);
    }
}

static void sorted_by_time_stable(void **state)
{
    (void)state;
    ps_script *s = parse_ok("3 screenshot c.png\n"
                            "1 screenshot a1.png\n"
                            "2 screenshot b1.png\n"
                            "1 screenshot a2.png\n"
                            "0.0 quit\n"
                            "2.0 screenshot b2.png\n"
                            "1.00 screenshot a3.png\n"
                            "-0 screenshot z.png\n");
    static const char *const order[] = {NULL, "z.png", "a1.png", "a2.png", "a3.png", "b1.png", "b2.png", "c.png"};
    static const int lines[] = {5, 8, 2, 4, 7, 3, 6, 1};
    assert_int_equal(ps_script_count(s), 8);
    for (size_t i = 0; i < 8; i++) {
        const ps_script_action *a = ps_script_at(s, i);
        assert_int_equal(a->line, lines[i]);
        if (order[i])
            assert_string_equal(a->path, order[i]);
        else
            assert_int_equal(a->kind, PS_SCRIPT_QUIT);
        if (i > 0)
            assert_true(ps_script_at(s, i - 1)->time <= a->time);
    }
    assert_false(signbit(ps_script_at(s, 1)->time)); /* "-0" is time 0, not -0 */
    ps_script_destroy(s);
}

static void comments_and_blank_lines(void **state)
{
    (void)state;
    ps_script *s = parse_ok("\n"
                            "# a comment\n"
                            "   \t  \n"
                            "\t0.5\tquit#no space before the comment\r\n"
                            "  # indented comment\r\n"
                            "\r\n"
                            "1 screenshot shot.png# a comment ends the path\n"
                            "2 set layers direct,global #x\n"
                            "3 orbit 1 2"); /* no final newline */
    assert_int_equal(ps_script_count(s), 4);
    assert_int_equal(ps_script_at(s, 0)->kind, PS_SCRIPT_QUIT);
    assert_int_equal(ps_script_at(s, 0)->line, 4);
    assert_string_equal(ps_script_at(s, 1)->path, "shot.png");
    assert_int_equal(ps_script_at(s, 1)->line, 7);
    assert_int_equal(ps_script_at(s, 2)->layers, PS_LAYER_DIRECT | PS_LAYER_GLOBAL);
    assert_int_equal(ps_script_at(s, 3)->line, 9);
    assert_near(ps_script_at(s, 3)->pitch, 2, 0);
    ps_script_destroy(s);
}

/* wait done: the action alone, in time order among the others, every field
 * but its time and line zero. */
static void wait_done(void **state)
{
    (void)state;
    ps_script *s = parse_ok("2 quit\n"
                            "0.5 wait done # the caps reached\n"
                            "0.5\twait\tdone\r\n"
                            "1 screenshot b.png\n");
    assert_int_equal(ps_script_count(s), 4);
    static const ps_script_kind kinds[] = {PS_SCRIPT_WAIT, PS_SCRIPT_WAIT, PS_SCRIPT_SCREENSHOT, PS_SCRIPT_QUIT};
    static const int lines[] = {2, 3, 4, 1};
    for (size_t i = 0; i < 4; i++) {
        const ps_script_action *a = ps_script_at(s, i);
        assert_int_equal(a->kind, kinds[i]);
        assert_int_equal(a->line, lines[i]);
    }
    const ps_script_action *a = ps_script_at(s, 0);
    assert_near(a->time, 0.5, 0);
    assert_rest_zero(a, false, false, false, false, false, false, false);
    ps_script_destroy(s);
}

/* dump photons and save scene: their paths, in time order with the rest. */
static void dump_and_save(void **state)
{
    (void)state;
    ps_script *s = parse_ok("2 save scene out/e.scn\n"
                            "1 dump photons out/p.txt # the maps\n"
                            "1 wait done\n");
    assert_int_equal(ps_script_count(s), 3);
    const ps_script_action *a = ps_script_at(s, 0);
    assert_int_equal(a->kind, PS_SCRIPT_DUMP_PHOTONS);
    assert_string_equal(a->path, "out/p.txt");
    assert_int_equal(a->line, 2);
    assert_rest_zero(a, true, false, false, false, false, false, false);
    assert_int_equal(ps_script_at(s, 1)->kind, PS_SCRIPT_WAIT);
    a = ps_script_at(s, 2);
    assert_int_equal(a->kind, PS_SCRIPT_SAVE_SCENE);
    assert_string_equal(a->path, "out/e.scn");
    assert_near(a->time, 2.0, 0.0);
    ps_script_destroy(s);
}

static void empty_scripts(void **state)
{
    (void)state;
    static const char *const texts[] = {"", "\n\n", "# only a comment\n  # and another", " \t\r\n"};
    for (size_t i = 0; i < 4; i++) {
        ps_script *s = parse_ok(texts[i]);
        assert_int_equal(ps_script_count(s), 0);
        assert_null(ps_script_at(s, 0));
        ps_script_destroy(s);
    }
    ps_script_destroy(NULL);
    assert_int_equal(ps_script_count(NULL), 0);
    /* An empty file too. */
    FILE *fp = fopen(test_path("empty.txt"), "wb");
    assert_non_null(fp);
    fclose(fp);
    ps_script *s = NULL;
    ps_error err;
    assert_int_equal(ps_script_load(test_path("empty.txt"), &s, &err), PS_OK);
    assert_int_equal(ps_script_count(s), 0);
    ps_script_destroy(s);
}

typedef struct bad_case {
    const char *text;
    ps_status status;
    const char *msg; /* exact */
} bad_case;

static const bad_case BAD[] = {
    /* actions */
    {"0 jump\n", PS_ERR_PARSE, "s.txt:1: unknown action 'jump'"},
    {"0 Quit\n", PS_ERR_PARSE, "s.txt:1: unknown action 'Quit'"},
    {"\n\n0.5\n", PS_ERR_PARSE, "s.txt:3: missing action after the time"},
    {"quit\n", PS_ERR_PARSE, "s.txt:1: time 'quit' must be a number >= 0"},
    {"0 quit now\n", PS_ERR_PARSE, "s.txt:1: quit: expected no arguments"},
    {"0 screenshot\n", PS_ERR_PARSE, "s.txt:1: screenshot: expected 1 path (without spaces)"},
    {"0 screenshot my shot.png\n", PS_ERR_PARSE, "s.txt:1: screenshot: expected 1 path (without spaces)"},
    {"0 screenshot # no path\n", PS_ERR_PARSE, "s.txt:1: screenshot: expected 1 path (without spaces)"},
    {"0 dump photons\n", PS_ERR_PARSE, "s.txt:1: dump photons: expected 1 path (without spaces)"},
    {"0 dump photons a b\n", PS_ERR_PARSE, "s.txt:1: dump photons: expected 1 path (without spaces)"},
    {"0 dump scene a.txt\n", PS_ERR_PARSE, "s.txt:1: dump: expected 'dump photons PATH'"},
    {"0 save photons a.scn\n", PS_ERR_PARSE, "s.txt:1: save: expected 'save scene PATH'"},
    {"0 save\n", PS_ERR_PARSE, "s.txt:1: save: expected 'save scene PATH'"},
    /* times */
    {"0 quit\n1 quit\n\n# c\n-1 quit\n", PS_ERR_PARSE, "s.txt:5: time '-1' must be a number >= 0"},
    {"1.5x quit\n", PS_ERR_PARSE, "s.txt:1: time '1.5x' must be a number >= 0"},
    {"nan quit\n", PS_ERR_PARSE, "s.txt:1: time 'nan' must be a number >= 0"},
    {"inf quit\n", PS_ERR_PARSE, "s.txt:1: time 'inf' must be a number >= 0"},
    {"1e999 quit\n", PS_ERR_PARSE, "s.txt:1: time '1e999' must be a number >= 0"},
    {"-1e-300 quit\n", PS_ERR_PARSE, "s.txt:1: time '-1e-300' must be a number >= 0"},
    /* move */
    {"0 move\n", PS_ERR_PARSE, "s.txt:1: move: expected 'light' or 'object'"},
    {"0 move camera 0 1 2 3\n", PS_ERR_PARSE, "s.txt:1: move: expected 'light' or 'object', got 'camera'"},
    {"0 quit\n0 move light 0 1 2\n", PS_ERR_PARSE, "s.txt:2: move light: expected 4 numbers"},
    {"0 move light 0 1 2 3 4\n", PS_ERR_PARSE, "s.txt:1: move light: expected 4 numbers"},
    {"0 move object 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18\n", PS_ERR_PARSE,
     "s.txt:1: move object: expected 4 numbers"},
    {"0 move light 0 1.5x 2 0\n", PS_ERR_PARSE, "s.txt:1: move light: '1.5x' is not a finite number"},
    {"0 move light 0 1 nan 0\n", PS_ERR_PARSE, "s.txt:1: move light: 'nan' is not a finite number"},
    {"0 move object 1 0 0 -inf\n", PS_ERR_PARSE, "s.txt:1: move object: '-inf' is not a finite number"},
    {"0 move light -1 0 0 0\n", PS_ERR_PARSE, "s.txt:1: move light: index '-1' must be an integer in [0, 4294967295]"},
    {"0 move object 4294967296 0 0 0\n", PS_ERR_PARSE,
     "s.txt:1: move object: index '4294967296' must be an integer in [0, 4294967295]"},
    {"0 move object 1.0 0 0 0\n", PS_ERR_PARSE,
     "s.txt:1: move object: index '1.0' must be an integer in [0, 4294967295]"},
    {"0 move object 99999999999999999999 0 0 0\n", PS_ERR_PARSE,
     "s.txt:1: move object: index '99999999999999999999' must be an integer in [0, 4294967295]"},
    /* set */
    {"0 set\n", PS_ERR_PARSE,
     "s.txt:1: set: expected a setting (splat, layers, kernel, radius, tau, precision, exposure, pause, "
     "false-color or global-layer)"},
    {"0 set gamma 2\n", PS_ERR_PARSE,
     "s.txt:1: set: unknown setting 'gamma' (expected splat, layers, kernel, radius, tau, precision, exposure, "
     "pause, false-color or global-layer)"},
    {"0 set false-color maybe\n", PS_ERR_PARSE, "s.txt:1: set false-color: 'maybe' is not on or off"},
    {"0 set global-layer texels\n", PS_ERR_PARSE, "s.txt:1: set global-layer: 'texels' is not splats or maps"},
    {"0 quit\n0 quit\n0 quit\n0 set splat quads\n", PS_ERR_PARSE,
     "s.txt:4: set splat: 'quads' is not points, triangles or sprites"},
    {"0 set splat\n", PS_ERR_PARSE, "s.txt:1: set splat: expected one of points, triangles or sprites"},
    {"0 set splat points triangles\n", PS_ERR_PARSE, "s.txt:1: set splat: expected one of points, triangles or sprites"},
    {"0 set kernel gaussian\n", PS_ERR_PARSE, "s.txt:1: set kernel: 'gaussian' is not box, cone, gauss or epanechnikov"},
    {"0 set precision full\n", PS_ERR_PARSE, "s.txt:1: set precision: 'full' is not none, diffusion or counter"},
    {"0 set pause yes\n", PS_ERR_PARSE, "s.txt:1: set pause: 'yes' is not on or off"},
    {"0 set pause\n", PS_ERR_PARSE, "s.txt:1: set pause: expected one of on or off"},
    {"0 set layers\n", PS_ERR_PARSE, "s.txt:1: set layers: expected one comma list of direct, caustic, global"},
    {"0 set layers direct, global\n", PS_ERR_PARSE,
     "s.txt:1: set layers: expected one comma list of direct, caustic, global"},
    {"0 set layers ,\n", PS_ERR_PARSE, "s.txt:1: set layers: empty name in the list"},
    {"0 set layers direct,\n", PS_ERR_PARSE, "s.txt:1: set layers: empty name in the list"},
    {"0 set layers direct,,global\n", PS_ERR_PARSE, "s.txt:1: set layers: empty name in the list"},
    {"0 set layers direct,glossy\n", PS_ERR_PARSE, "s.txt:1: set layers: 'glossy' is not direct, caustic, global or specular"},
    {"0 set layers caustic,caustic\n", PS_ERR_PARSE, "s.txt:1: set layers: 'caustic' given twice"},
    {"0 set radius 0\n", PS_ERR_PARSE, "s.txt:1: set radius: '0' must be a number > 0"},
    {"0 set radius 0.1 -0.2\n", PS_ERR_PARSE, "s.txt:1: set radius: '-0.2' must be a number > 0"},
    {"0 set radius\n", PS_ERR_PARSE, "s.txt:1: set radius: expected 1 or 2 numbers"},
    {"0 set radius 1 2 3\n", PS_ERR_PARSE, "s.txt:1: set radius: expected 1 or 2 numbers"},
    {"0 set tau 0\n", PS_ERR_PARSE, "s.txt:1: set tau: '0' must be a number > 0"},
    {"0 set tau nan\n", PS_ERR_PARSE, "s.txt:1: set tau: 'nan' must be a number > 0"},
    {"0 set tau 1 2\n", PS_ERR_PARSE, "s.txt:1: set tau: expected 1 number"},
    {"0 set exposure -0.3\n", PS_ERR_PARSE, "s.txt:1: set exposure: '-0.3' must be a number > 0"},
    {"0 set exposure inf\n", PS_ERR_PARSE, "s.txt:1: set exposure: 'inf' must be a number > 0"},
    /* orbit */
    {"0 orbit 15\n", PS_ERR_PARSE, "s.txt:1: orbit: expected 2 numbers"},
    {"0 orbit 15 -5 0\n", PS_ERR_PARSE, "s.txt:1: orbit: expected 2 numbers"},
    {"0 orbit 15 -5deg\n", PS_ERR_PARSE, "s.txt:1: orbit: '-5deg' is not a finite number"},
    /* power */
    {"0 power\n", PS_ERR_PARSE, "s.txt:1: power: expected 'light'"},
    {"0 power object 0 1 1 1\n", PS_ERR_PARSE, "s.txt:1: power: expected 'light', got 'object'"},
    {"0 power light 0 1 1\n", PS_ERR_PARSE, "s.txt:1: power light: expected 4 numbers"},
    {"0 power light 0 1 -1 1\n", PS_ERR_PARSE, "s.txt:1: power light: '-1' must be a number >= 0"},
    {"0 power light 0 1 1 nan\n", PS_ERR_PARSE, "s.txt:1: power light: 'nan' must be a number >= 0"},
    {"0 power light x 1 1 1\n", PS_ERR_PARSE, "s.txt:1: power light: index 'x' must be an integer in [0, 4294967295]"},
    /* angle */
    {"0 angle light 0 0\n", PS_ERR_PARSE, "s.txt:1: angle light: '0' must be a number in (0, 90]"},
    {"0 angle light 0 91\n", PS_ERR_PARSE, "s.txt:1: angle light: '91' must be a number in (0, 90]"},
    {"0 angle light 0 90.0000001\n", PS_ERR_PARSE, "s.txt:1: angle light: '90.0000001' must be a number in (0, 90]"},
    {"0 angle light 0\n", PS_ERR_PARSE, "s.txt:1: angle light: expected 2 numbers"},
    {"0 angle object 0 45\n", PS_ERR_PARSE, "s.txt:1: angle: expected 'light', got 'object'"},
    /* wait */
    {"0 wait\n", PS_ERR_PARSE, "s.txt:1: wait: expected 'done'"},
    {"0 wait 5\n", PS_ERR_PARSE, "s.txt:1: wait: expected 'done', got '5'"},
    {"0 wait Done\n", PS_ERR_PARSE, "s.txt:1: wait: expected 'done', got 'Done'"},
    {"0 quit\n0 wait done 5\n", PS_ERR_PARSE, "s.txt:2: wait done: expected no arguments"},
};

static void malformed_inputs(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof BAD / sizeof BAD[0]; i++) {
        ps_script *s = (ps_script *)&s; /* anything but NULL: the parser must clear it */
        ps_error err;
        ps_status st = ps_script_parse(BAD[i].text, "s.txt", &s, &err);
        if (st != BAD[i].status || strcmp(err.msg, BAD[i].msg) != 0)
            fail_msg("case %zu '%s': got status %d '%s', expected %d '%s'", i, BAD[i].text, (int)st, err.msg,
                     (int)BAD[i].status, BAD[i].msg);
        assert_int_equal(err.status, st);
        assert_null(s);
        assert_null(strchr(err.msg, '\n'));
        /* The line the message names is the error's line too. */
        int line = 0;
        if (strncmp(BAD[i].msg, "s.txt:", 6) == 0 && BAD[i].msg[6] >= '1' && BAD[i].msg[6] <= '9')
            line = atoi(BAD[i].msg + 6);
        if (err.line != line)
            fail_msg("case %zu '%s': err.line %d, expected %d", i, BAD[i].text, err.line, line);
        /* A NULL err is allowed and changes nothing else. */
        s = (ps_script *)&s;
        assert_int_equal(ps_script_parse(BAD[i].text, "s.txt", &s, NULL), BAD[i].status);
        assert_null(s);
    }
    assert_true(sizeof BAD / sizeof BAD[0] >= 20);
}

/* Writes n copies of line, then tail, into a malloc'd string. */
static char *repeat(const char *line, size_t n, const char *tail)
{
    size_t ll = strlen(line), tl = strlen(tail);
    char *t = malloc(ll * n + tl + 1);
    assert_non_null(t);
    for (size_t i = 0; i < n; i++)
        memcpy(t + i * ll, line, ll);
    memcpy(t + ll * n, tail, tl + 1);
    return t;
}

static void limits(void **state)
{
    (void)state;
    ps_script *s;
    ps_error err;

    /* A line of PS_SCRIPT_LINE_MAX characters is fine (a long comment); one more is not. */
    char *line = malloc(PS_SCRIPT_LINE_MAX + 16);
    assert_non_null(line);
    memset(line, 'x', PS_SCRIPT_LINE_MAX + 1);
    memcpy(line, "0 quit #", 8);
    line[PS_SCRIPT_LINE_MAX] = '\0';
    char *text = malloc(PS_SCRIPT_LINE_MAX + 64);
    assert_non_null(text);
    snprintf(text, PS_SCRIPT_LINE_MAX + 64, "0 quit\n%s\n", line);
    assert_int_equal(ps_script_parse(text, "s.txt", &s, &err), PS_OK);
    assert_int_equal(ps_script_count(s), 2);
    ps_script_destroy(s);
    snprintf(text, PS_SCRIPT_LINE_MAX + 64, "0 quit\n%sx\n", line);
    s = (ps_script *)&s;
    assert_int_equal(ps_script_parse(text, "s.txt", &s, &err), PS_ERR_PARSE);
    assert_string_equal(err.msg, "s.txt:2: line longer than 8191 characters");
    assert_int_equal(err.line, 2);
    assert_null(s);

    /* Screenshot paths of up to PS_SCRIPT_PATH_MAX characters. */
    memset(line, 'p', PS_SCRIPT_PATH_MAX + 1);
    line[PS_SCRIPT_PATH_MAX] = '\0';
    snprintf(text, PS_SCRIPT_LINE_MAX + 64, "1 screenshot %s\n0 screenshot a.png\n", line);
    assert_int_equal(ps_script_parse(text, "s.txt", &s, &err), PS_OK);
    assert_string_equal(ps_script_at(s, 0)->path, "a.png");
    assert_string_equal(ps_script_at(s, 1)->path, line);
    ps_script_destroy(s);
    snprintf(text, PS_SCRIPT_LINE_MAX + 64, "1 screenshot %sp\n", line);
    s = (ps_script *)&s;
    assert_int_equal(ps_script_parse(text, "s.txt", &s, &err), PS_ERR_PARSE);
    assert_string_equal(err.msg, "s.txt:1: screenshot: path longer than 4095 characters");
    assert_null(s);
    free(line);
    free(text);

    /* PS_SCRIPT_MAX_ACTIONS actions, blank lines and comments not counted. */
    text = repeat("0 quit\n", PS_SCRIPT_MAX_ACTIONS, "\n# end\n");
    assert_int_equal(ps_script_parse(text, "s.txt", &s, &err), PS_OK);
    assert_int_equal(ps_script_count(s), PS_SCRIPT_MAX_ACTIONS);
    assert_int_equal(ps_script_at(s, PS_SCRIPT_MAX_ACTIONS - 1)->line, PS_SCRIPT_MAX_ACTIONS);
    ps_script_destroy(s);
    free(text);
    text = repeat("0 quit\n", PS_SCRIPT_MAX_ACTIONS, "\n2 screenshot a.png\n");
    s = (ps_script *)&s;
    assert_int_equal(ps_script_parse(text, "s.txt", &s, &err), PS_ERR_LIMIT);
    assert_string_equal(err.msg, "s.txt:100002: more than 100000 actions");
    assert_int_equal(err.line, 100002);
    assert_null(s);
    free(text);

    /* More than PS_SCRIPT_MAX_BYTES, as text and as a file. */
    text = repeat("# padding padding padding padding padding padding padding padding padding padding\n", 13000, "");
    assert_true(strlen(text) > PS_SCRIPT_MAX_BYTES);
    s = (ps_script *)&s;
    assert_int_equal(ps_script_parse(text, "s.txt", &s, &err), PS_ERR_LIMIT);
    assert_string_equal(err.msg, "s.txt: script larger than 1048576 bytes");
    assert_null(s);
    const char *big = test_path("big.txt");
    FILE *fp = fopen(big, "wb");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
    free(text);
    s = (ps_script *)&s;
    assert_int_equal(ps_script_load(big, &s, &err), PS_ERR_LIMIT);
    assert_non_null(strstr(err.msg, big));
    assert_null(s);
}

static void files(void **state)
{
    (void)state;
    ps_script *s = (ps_script *)&s;
    ps_error err;
    assert_int_equal(ps_script_load("tests/data/script/no-such.txt", &s, &err), PS_ERR_IO);
    assert_non_null(strstr(err.msg, "tests/data/script/no-such.txt: cannot open"));
    assert_null(s);
    s = (ps_script *)&s;
    assert_int_equal(ps_script_load("tests/data/script", &s, &err), PS_ERR_IO);
    assert_non_null(strstr(err.msg, "is a directory"));
    assert_null(s);

    /* A NUL byte: binary data, reported at its line. */
    static const char bin[] = "0 quit\n1 screenshot a\0b.png\n2 quit\n";
    const char *path = test_path("nul.txt");
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fwrite(bin, 1, sizeof bin - 1, fp);
    fclose(fp);
    s = (ps_script *)&s;
    assert_int_equal(ps_script_load(path, &s, &err), PS_ERR_PARSE);
    char expected[1200];
    snprintf(expected, sizeof expected, "%s:2: binary data (a NUL byte), not a script", path);
    assert_string_equal(err.msg, expected);
    assert_null(s);

    /* Errors in a file name it as given. */
    path = test_path("bad.txt");
    fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs("0 screenshot a.png\n\n0.1 set splat quads # no such mode\n", fp);
    fclose(fp);
    s = (ps_script *)&s;
    assert_int_equal(ps_script_load(path, &s, &err), PS_ERR_PARSE);
    snprintf(expected, sizeof expected, "%s:3: set splat: 'quads' is not points, triangles or sprites", path);
    assert_string_equal(err.msg, expected);
    assert_null(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(contract_example),
        cmocka_unit_test(every_action_and_setting),
        cmocka_unit_test(choices_match_enums),
        cmocka_unit_test(sorted_by_time_stable),
        cmocka_unit_test(comments_and_blank_lines),
        cmocka_unit_test(wait_done),
        cmocka_unit_test(dump_and_save),
        cmocka_unit_test(empty_scripts),
        cmocka_unit_test(malformed_inputs),
        cmocka_unit_test(limits),
        cmocka_unit_test(files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
