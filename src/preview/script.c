/* script.c: the --script reader. One action a line; every problem is reported
 * as "file:line: problem" and nothing half-built escapes. */
#include "preview/script.h"

#include "preview/illummap.h"

#include <ctype.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/number.h"
#include "photon/estimate.h"
#include "preview/splat.h"

/* The longest action, "T move light I X Y Z", has 7 words; a line may hold
 * more (they are counted, so that "expected N numbers" can be said), but only
 * the first SCRIPT_MAX_WORDS are kept. */
#define SCRIPT_MAX_WORDS 16

struct ps_script {
    ps_script_action *actions; /* count of them, sorted by (time, line) */
    size_t count;
    char *paths; /* every screenshot path, NUL-terminated, back to back */
};

typedef struct parser {
    const char *name; /* file name in messages */
    ps_error *err;
    int line;
    char *word[SCRIPT_MAX_WORDS];
    int nword; /* words on the line, including any beyond SCRIPT_MAX_WORDS */
    ps_script_action *actions;
    size_t count, cap;
    /* Paths are copied here while parsing. Each path of L characters comes
     * from a line of more than L + 1 bytes ("T screenshot PATH"), so a pool of
     * the text's length + 1 never overflows and never moves. */
    char *pool;
    size_t pool_used;
} parser;

/* A word chosen from a fixed list; its index is the action's choice. */
typedef struct choice_list {
    const char *const *names;
    int count;
    const char *said; /* the list as a message says it */
} choice_list;

/* The enums' own name tables, so that a choice is the enum's value. */
static const char *const PAUSE_NAMES[] = {"off", "on"}; /* so that on = 1 */

static const choice_list SPLAT_CHOICES = {ps_splat_mode_names, PS_SPLAT_MODE_COUNT, "points, triangles or sprites"};
static const choice_list KERNEL_CHOICES = {ps_kernel_names, PS_KERNEL_COUNT, "box, cone, gauss or epanechnikov"};
static const choice_list PRECISION_CHOICES = {ps_precision_names, PS_PRECISION_COUNT, "none, diffusion or counter"};
static const choice_list PAUSE_CHOICES = {PAUSE_NAMES, 2, "on or off"};
static const choice_list GLOBAL_CHOICES = {ps_global_layer_names, PS_GLOBAL_LAYER_COUNT, "splats or maps"};

/* ---- words ------------------------------------------------------------------- */

/* Splits a line in place at spaces, tabs and carriage returns; '#' starts a
 * comment wherever it stands. */
static void split_words(parser *p, char *s)
{
    p->nword = 0;
    for (;;) {
        while (*s == ' ' || *s == '\t' || *s == '\r')
            s++;
        if (!*s || *s == '#')
            return;
        if (p->nword < SCRIPT_MAX_WORDS)
            p->word[p->nword] = s;
        p->nword++;
        while (*s && *s != ' ' && *s != '\t' && *s != '\r' && *s != '#')
            s++;
        if (*s == '#') {
            *s = '\0';
            return;
        }
        if (*s)
            *s++ = '\0';
    }
}

/* ---- values ------------------------------------------------------------------ */

static ps_status read_number(parser *p, const char *what, const char *w, double *out)
{
    if (!ps_parse_double(w, out))
        return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: '%s' is not a finite number", what, w);
    return PS_OK;
}

static ps_status read_positive(parser *p, const char *what, const char *w, double *out)
{
    if (!ps_parse_double(w, out) || !(*out > 0.0))
        return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: '%s' must be a number > 0", what, w);
    return PS_OK;
}

static ps_status read_index(parser *p, const char *what, const char *w, uint32_t *out)
{
    int64_t v;
    if (!ps_parse_int64(w, &v) || v < 0 || v > (int64_t)UINT32_MAX)
        return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: index '%s' must be an integer in [0, %lu]",
                           what, w, (unsigned long)UINT32_MAX);
    *out = (uint32_t)v;
    return PS_OK;
}

static ps_status read_choice(parser *p, const char *what, const choice_list *list, const char *w, int *out)
{
    for (int k = 0; k < list->count; k++)
        if (strcmp(list->names[k], w) == 0) {
            *out = k;
            return PS_OK;
        }
    return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: '%s' is not %s", what, w, list->said);
}

static ps_status wrong_count(parser *p, const char *what, const char *expected)
{
    return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: expected %s", what, expected);
}

/* ---- actions ----------------------------------------------------------------- */

/* "move light", "power light", ...: the word after the action names what it
 * acts on; objects only for move. Returns the phrase for messages. */
static const char *subject(parser *p, const char *action, bool objects_too, ps_script_kind *kind)
{
    const char *expected = objects_too ? "'light' or 'object'" : "'light'";
    if (p->nword < 3) {
        ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: expected %s", action, expected);
        return NULL;
    }
    const char *w = p->word[2];
    if (strcmp(w, "light") == 0)
        return "light";
    if (objects_too && strcmp(w, "object") == 0) {
        *kind = PS_SCRIPT_MOVE_OBJECT;
        return "object";
    }
    ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: expected %s, got '%s'", action, expected, w);
    return NULL;
}

/* move light|object INDEX X Y Z, power light INDEX R G B, angle light INDEX DEG. */
static ps_status parse_indexed(parser *p, ps_script_action *a, const char *action)
{
    const char *what_subject = subject(p, action, a->kind == PS_SCRIPT_MOVE_LIGHT, &a->kind);
    if (!what_subject)
        return PS_ERR_PARSE;
    char what[32];
    snprintf(what, sizeof what, "%s %s", action, what_subject);
    int nargs = p->nword - 3, need = a->kind == PS_SCRIPT_ANGLE ? 2 : 4;
    if (nargs != need)
        return wrong_count(p, what, need == 2 ? "2 numbers" : "4 numbers");
    char **arg = p->word + 3;
    ps_status st = read_index(p, what, arg[0], &a->index);
    if (st != PS_OK)
        return st;
    if (a->kind == PS_SCRIPT_ANGLE) {
        if (!ps_parse_double(arg[1], &a->number) || !(a->number > 0.0 && a->number <= 90.0))
            return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: '%s' must be a number in (0, 90]", what,
                               arg[1]);
        return PS_OK;
    }
    double v[3];
    for (int k = 0; k < 3; k++) {
        if (a->kind == PS_SCRIPT_POWER) {
            if (!ps_parse_double(arg[1 + k], &v[k]) || !(v[k] >= 0.0))
                return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: '%s' must be a number >= 0", what,
                                   arg[1 + k]);
        } else if ((st = read_number(p, what, arg[1 + k], &v[k])) != PS_OK) {
            return st;
        }
    }
    if (a->kind == PS_SCRIPT_POWER)
        a->power = ps_rgb_make(v[0] + 0.0, v[1] + 0.0, v[2] + 0.0); /* + 0.0: -0 becomes 0 */
    else
        a->v = ps_v3(v[0], v[1], v[2]);
    return PS_OK;
}

static ps_status parse_layers(parser *p, ps_script_action *a, const char *list)
{
    char why[PS_ERROR_MSG_MAX];
    if (!ps_layers_parse(list, &a->layers, why, sizeof why))
        return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "set layers: %s", why);
    return PS_OK;
}

static ps_status parse_set(parser *p, ps_script_action *a)
{
    static const char *const SETTINGS[] = {"splat",     "layers",   "kernel", "radius",     "tau",
                                           "precision", "exposure", "pause",  "false-color", "global-layer"};
    enum { SETTING_COUNT = sizeof SETTINGS / sizeof SETTINGS[0] };
    static const char *const SAID = "splat, layers, kernel, radius, tau, precision, exposure, pause, false-color or global-layer";
    if (p->nword < 3)
        return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "set: expected a setting (%s)", SAID);
    int k = 0;
    while (k < SETTING_COUNT && strcmp(SETTINGS[k], p->word[2]) != 0)
        k++;
    if (k == SETTING_COUNT)
        return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "set: unknown setting '%s' (expected %s)",
                           p->word[2], SAID);
    a->setting = (ps_script_setting)k;
    char what[32];
    snprintf(what, sizeof what, "set %s", SETTINGS[k]);
    int nargs = p->nword - 3;
    char **arg = p->word + 3;
    const choice_list *choices = NULL;
    switch (a->setting) {
    case PS_SET_SPLAT: choices = &SPLAT_CHOICES; break;
    case PS_SET_KERNEL: choices = &KERNEL_CHOICES; break;
    case PS_SET_PRECISION: choices = &PRECISION_CHOICES; break;
    case PS_SET_PAUSE:
    case PS_SET_FALSE_COLOR: choices = &PAUSE_CHOICES; break;
    case PS_SET_GLOBAL_LAYER: choices = &GLOBAL_CHOICES; break;
    case PS_SET_LAYERS:
        if (nargs != 1)
            return wrong_count(p, what, "one comma list of direct, caustic, global");
        return parse_layers(p, a, arg[0]);
    case PS_SET_RADIUS:
        if (nargs != 1 && nargs != 2)
            return wrong_count(p, what, "1 or 2 numbers");
        if (read_positive(p, what, arg[0], &a->number) != PS_OK)
            return PS_ERR_PARSE;
        return nargs == 2 ? read_positive(p, what, arg[1], &a->number2) : PS_OK;
    case PS_SET_TAU:
    case PS_SET_EXPOSURE:
        if (nargs != 1)
            return wrong_count(p, what, "1 number");
        return read_positive(p, what, arg[0], &a->number);
    }
    char expected[64];
    snprintf(expected, sizeof expected, "one of %s", choices->said);
    if (nargs != 1)
        return wrong_count(p, what, expected);
    return read_choice(p, what, choices, arg[0], &a->choice);
}

static ps_status parse_action(parser *p, ps_script_action *a)
{
    const char *action = p->word[1];
    int nargs = p->nword - 2;
    char **arg = p->word + 2;
    if (strcmp(action, "screenshot") == 0) {
        a->kind = PS_SCRIPT_SCREENSHOT;
        if (nargs != 1)
            return wrong_count(p, action, "1 path (without spaces)");
        size_t n = strlen(arg[0]);
        if (n > PS_SCRIPT_PATH_MAX)
            return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "screenshot: path longer than %d characters",
                               PS_SCRIPT_PATH_MAX);
        char *dst = p->pool + p->pool_used;
        memcpy(dst, arg[0], n + 1);
        p->pool_used += n + 1;
        a->path = dst;
        return PS_OK;
    }
    if (strcmp(action, "dump") == 0 || strcmp(action, "save") == 0) {
        /* "dump photons PATH", "save scene PATH": the session's maps or scene. */
        bool dump = action[0] == 'd';
        const char *what = dump ? "photons" : "scene";
        a->kind = dump ? PS_SCRIPT_DUMP_PHOTONS : PS_SCRIPT_SAVE_SCENE;
        if (nargs < 1 || strcmp(arg[0], what) != 0)
            return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: expected '%s %s PATH'", action, action,
                               what);
        if (nargs != 2)
            return wrong_count(p, dump ? "dump photons" : "save scene", "1 path (without spaces)");
        size_t n = strlen(arg[1]);
        if (n > PS_SCRIPT_PATH_MAX)
            return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "%s: path longer than %d characters", action,
                               PS_SCRIPT_PATH_MAX);
        char *dst = p->pool + p->pool_used;
        memcpy(dst, arg[1], n + 1);
        p->pool_used += n + 1;
        a->path = dst;
        return PS_OK;
    }
    if (strcmp(action, "move") == 0) {
        a->kind = PS_SCRIPT_MOVE_LIGHT; /* or MOVE_OBJECT, which subject() decides */
        return parse_indexed(p, a, action);
    }
    if (strcmp(action, "power") == 0) {
        a->kind = PS_SCRIPT_POWER;
        return parse_indexed(p, a, action);
    }
    if (strcmp(action, "angle") == 0) {
        a->kind = PS_SCRIPT_ANGLE;
        return parse_indexed(p, a, action);
    }
    if (strcmp(action, "set") == 0) {
        a->kind = PS_SCRIPT_SET;
        return parse_set(p, a);
    }
    if (strcmp(action, "orbit") == 0) {
        a->kind = PS_SCRIPT_ORBIT;
        if (nargs != 2)
            return wrong_count(p, action, "2 numbers");
        ps_status st = read_number(p, action, arg[0], &a->yaw);
        return st != PS_OK ? st : read_number(p, action, arg[1], &a->pitch);
    }
    if (strcmp(action, "wait") == 0) {
        /* One thing to wait for so far; the word leaves room for others. */
        a->kind = PS_SCRIPT_WAIT;
        if (nargs < 1)
            return wrong_count(p, action, "'done'");
        if (strcmp(arg[0], "done") != 0)
            return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "wait: expected 'done', got '%s'", arg[0]);
        return nargs != 1 ? wrong_count(p, "wait done", "no arguments") : PS_OK;
    }
    if (strcmp(action, "quit") == 0) {
        a->kind = PS_SCRIPT_QUIT;
        return nargs != 0 ? wrong_count(p, action, "no arguments") : PS_OK;
    }
    return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "unknown action '%s'", action);
}

/* One non-blank line: the time, then the action, appended to p->actions. */
static ps_status parse_line(parser *p)
{
    double t;
    if (!ps_parse_double(p->word[0], &t) || !(t >= 0.0))
        return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "time '%s' must be a number >= 0", p->word[0]);
    if (p->nword < 2)
        return ps_error_at(p->err, PS_ERR_PARSE, p->name, p->line, "missing action after the time");
    if (p->count == PS_SCRIPT_MAX_ACTIONS)
        return ps_error_at(p->err, PS_ERR_LIMIT, p->name, p->line, "more than %d actions", PS_SCRIPT_MAX_ACTIONS);
    if (p->count == p->cap) {
        size_t cap = p->cap ? p->cap * 2 : 64; /* bounded by PS_SCRIPT_MAX_ACTIONS: no overflow */
        ps_script_action *na = realloc(p->actions, cap * sizeof *na);
        if (!na)
            return ps_error_at(p->err, PS_ERR_NOMEM, p->name, p->line, "out of memory");
        p->actions = na;
        p->cap = cap;
    }
    ps_script_action *a = &p->actions[p->count];
    memset(a, 0, sizeof *a);
    a->time = t + 0.0; /* -0 becomes 0 */
    a->line = p->line;
    ps_status st = parse_action(p, a);
    if (st == PS_OK)
        p->count++;
    return st;
}

/* ---- text -------------------------------------------------------------------- */

static ps_status parse_one_line(void *user, char *text)
{
    parser *p = user;
    split_words(p, text);
    return p->nword > 0 ? parse_line(p) : PS_OK;
}

static ps_status parse_lines(parser *p, const char *text)
{
    return ps_text_lines(text, p->name, PS_SCRIPT_LINE_MAX, parse_one_line, p, &p->line, p->err);
}

/* Time order; the line breaks ties, so equal times keep file order (qsort
 * alone is not stable; lines are unique, one action a line). */
static int by_time(const void *pa, const void *pb)
{
    const ps_script_action *a = pa, *b = pb;
    if (a->time != b->time)
        return a->time < b->time ? -1 : 1;
    return (a->line > b->line) - (a->line < b->line);
}

/* Moves the parsed actions and a right-sized copy of the path pool into a script. */
static ps_status finish(parser *p, ps_script **out)
{
    ps_script *s = calloc(1, sizeof *s);
    char *paths = p->pool_used ? malloc(p->pool_used) : NULL;
    if (!s || (p->pool_used && !paths)) {
        free(s);
        free(paths);
        return ps_error_set(p->err, PS_ERR_NOMEM, "%s: out of memory", p->name);
    }
    if (p->pool_used) {
        memcpy(paths, p->pool, p->pool_used);
        for (size_t i = 0; i < p->count; i++)
            if (p->actions[i].path)
                p->actions[i].path = paths + (p->actions[i].path - p->pool);
    }
    if (p->count > 1)
        qsort(p->actions, p->count, sizeof *p->actions, by_time);
    s->actions = p->actions;
    s->count = p->count;
    s->paths = paths;
    p->actions = NULL;
    *out = s;
    return PS_OK;
}

/* Shared by both entry points; text has len bytes and a NUL after them. */
static ps_status parse_text(const char *text, size_t len, const char *name, ps_script **out, ps_error *err)
{
    *out = NULL;
    ps_error local;
    if (!err)
        err = &local;
    ps_error_clear(err);
    if (len > PS_SCRIPT_MAX_BYTES)
        return ps_error_set(err, PS_ERR_LIMIT, "%s: script larger than %zu bytes", name, PS_SCRIPT_MAX_BYTES);
    int bin = ps_text_nul_line(text, len);
    if (bin)
        return ps_error_at(err, PS_ERR_PARSE, name, bin, "binary data (a NUL byte), not a script");
    parser p;
    memset(&p, 0, sizeof p);
    p.name = name;
    p.err = err;
    p.pool = malloc(len + 1);
    if (!p.pool)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", name);
    ps_status st = parse_lines(&p, text);
    if (st == PS_OK)
        st = finish(&p, out);
    free(p.actions);
    free(p.pool);
    return st;
}

/* ---- public ------------------------------------------------------------------ */

ps_status ps_script_parse(const char *text, const char *name, ps_script **out, ps_error *err)
{
    return parse_text(text, strlen(text), name, out, err);
}

ps_status ps_script_load(const char *path, ps_script **out, ps_error *err)
{
    *out = NULL;
    char *text = NULL;
    size_t len = 0;
    ps_status st = ps_read_file(path, PS_SCRIPT_MAX_BYTES, &text, &len, err);
    if (st != PS_OK)
        return st;
    st = parse_text(text, len, path, out, err);
    free(text);
    return st;
}

void ps_script_destroy(ps_script *s)
{
    if (!s)
        return;
    free(s->actions);
    free(s->paths);
    free(s);
}

size_t ps_script_count(const ps_script *s) { return s ? s->count : 0; }

const ps_script_action *ps_script_at(const ps_script *s, size_t i)
{
    return s && i < s->count ? &s->actions[i] : NULL;
}

/* Either case, as ps_path_is_exr takes .EXR. */
static bool ends_with_nocase(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    if (n < m)
        return false;
    for (size_t i = 0; i < m; i++)
        if (tolower((unsigned char)s[n - m + i]) != tail[i])
            return false;
    return true;
}

bool ps_script_path_is_radiance(const char *path)
{
    return ends_with_nocase(path, ".pfm") || ends_with_nocase(path, ".exr");
}
