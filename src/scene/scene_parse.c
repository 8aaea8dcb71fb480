/* scene_parse.c: the .scn reader. One statement per line; every problem is
 * reported as "file:line: problem" and nothing half-built escapes. */
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/memory.h"
#include "core/namemap.h"
#include "core/number.h"
#include "core/transform.h"
#include "core/photometry.h"
#include "scene/ies.h"
#include "scene/obj.h"
#include "scene/scene_internal.h"

#define SCN_MAX_BYTES ((size_t)64 << 20)
#define SCN_LINE_MAX 4096
#define SCN_MAX_TOKENS 64
#define SCN_MAX_KEYS 8
/* Values may exceed 1 by this much from rounding in a file (0.1 + 0.9). */
#define ALBEDO_SLACK 1e-9
/* A quad whose edges are this close to parallel (sine of the angle) is refused. */
#define QUAD_MIN_SINE 1e-9
#define MAX_IOR 100.0
#define MAX_PHONG_EXPONENT 1e6

/* Scene defaults when a file says nothing (documented in docs/scene-format.md):
 * image size as pbrt's default film, photon counts as the contract's example,
 * radii as fractions of the scene's bounding-box diagonal. */
#define DEFAULT_IMAGE_SIDE 512
#define DEFAULT_CAUSTIC_PHOTONS 200000
#define DEFAULT_GLOBAL_PHOTONS 50000
#define DEFAULT_CAUSTIC_RADIUS_FRACTION 0.005
#define DEFAULT_GLOBAL_RADIUS_FRACTION 0.025
#define DEFAULT_FOV_DEG 40.0
#define DEFAULT_ALBEDO 0.5

typedef struct parser {
    ps_scene *s;
    const char *name;     /* file name in messages */
    const char *base_dir; /* what relative paths are relative to */
    const ps_warn_sink *warn;
    ps_error *err;
    int line;
    char *tok[SCN_MAX_TOKENS];
    int ntok, pos;
    bool has_camera, has_image, has_photons, has_radius;
    int64_t default_material; /* index, or -1 until first needed */
    /* What the statement being read records for ps_scene_write (scene_internal.h). */
    ps_object_source pending_obj;
    ps_light_source pending_light;
    PS_VEC(ps_scene_edit) pending_edits; /* a mesh's or quad's `move` and `light-power` keys */
    ps_namemap *material_names; /* name -> index in s->materials; the first of a name wins */
} parser;

/* ---- tokens ---------------------------------------------------------------- */

/* Splits a line in place. Double quotes group a token with spaces ("my room.obj");
 * '#' outside quotes starts a comment. */
static ps_status tokenize(parser *p, char *s)
{
    p->ntok = p->pos = 0;
    for (;;) {
        while (*s == ' ' || *s == '\t' || *s == '\r')
            s++;
        if (!*s || *s == '#')
            return PS_OK;
        if (p->ntok == SCN_MAX_TOKENS)
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: too many words on one line", p->name, p->line);
        if (*s == '"') {
            char *close = strchr(s + 1, '"');
            if (!close)
                return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: unterminated quote", p->name, p->line);
            p->tok[p->ntok++] = s + 1;
            *close = '\0';
            s = close + 1;
            continue;
        }
        p->tok[p->ntok++] = s;
        while (*s && *s != ' ' && *s != '\t' && *s != '\r' && *s != '#')
            s++;
        if (*s == '#') {
            *s = '\0';
            return PS_OK;
        }
        if (*s)
            *s++ = '\0';
    }
}

static bool more(const parser *p) { return p->pos < p->ntok; }

static const char *next_word(parser *p, const char *what)
{
    if (!more(p)) {
        ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: missing %s", p->name, p->line, p->tok[0], what);
        return NULL;
    }
    return p->tok[p->pos++];
}

static ps_status read_numbers(parser *p, const char *what, int n, double *out)
{
    for (int k = 0; k < n; k++) {
        if (!more(p))
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: '%s' needs %d number%s, got %d", p->name, p->line,
                                p->tok[0], what, n, n > 1 ? "s" : "", k);
        const char *t = p->tok[p->pos++];
        if (!ps_parse_double(t, &out[k]))
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: '%s': '%s' is not a finite number", p->name,
                                p->line, p->tok[0], what, t);
    }
    return PS_OK;
}

/* ---- key/value statements ----------------------------------------------------- */

enum { ARITY_WORD = 0 };

typedef struct key_spec {
    const char *key;
    int arity; /* numbers that follow, or ARITY_WORD for one word */
    bool required;
} key_spec;

typedef struct key_vals {
    bool present;
    double v[4];
    const char *word;
} key_vals;

static ps_status parse_keys(parser *p, const char *stmt, const key_spec *spec, int nspec, key_vals *vals)
{
    memset(vals, 0, sizeof *vals * (size_t)nspec);
    while (more(p)) {
        const char *key = p->tok[p->pos++];
        int k = 0;
        while (k < nspec && strcmp(spec[k].key, key) != 0)
            k++;
        if (k == nspec) {
            char list[256] = "";
            for (int j = 0; j < nspec; j++) {
                size_t used = strlen(list);
                snprintf(list + used, sizeof list - used, "%s%s", j ? ", " : "", spec[j].key);
            }
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: unknown key '%s' (expected %s)", p->name, p->line,
                                stmt, key, list);
        }
        if (vals[k].present)
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: '%s' given twice", p->name, p->line, stmt, key);
        vals[k].present = true;
        if (spec[k].arity == ARITY_WORD) {
            if (!(vals[k].word = next_word(p, key)))
                return PS_ERR_PARSE;
        } else {
            ps_status st = read_numbers(p, key, spec[k].arity, vals[k].v);
            if (st != PS_OK)
                return st;
        }
    }
    for (int k = 0; k < nspec; k++)
        if (spec[k].required && !vals[k].present)
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: missing '%s'", p->name, p->line, stmt, spec[k].key);
    return PS_OK;
}

static ps_vec3 kv_vec3(const key_vals *kv) { return ps_v3(kv->v[0], kv->v[1], kv->v[2]); }
static ps_rgb kv_rgb(const key_vals *kv) { return ps_rgb_make(kv->v[0], kv->v[1], kv->v[2]); }

/* ---- checks ----------------------------------------------------------------- */

static ps_status check_unit_rgb(parser *p, const char *what, ps_rgb c)
{
    if (c.r < 0 || c.g < 0 || c.b < 0 || c.r > 1 || c.g > 1 || c.b > 1)
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: %s: '%s' components must be in [0, 1]", p->name, p->line,
                            p->tok[0], what);
    return PS_OK;
}

static ps_status check_power(parser *p, ps_rgb c)
{
    if (c.r < 0 || c.g < 0 || c.b < 0)
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: light: 'power' must not be negative", p->name, p->line);
    if (ps_rgb_max(c) > PS_SCENE_MAX_LIGHT_POWER)
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: light: 'power' %g W is above the %g W a light may have",
                            p->name, p->line, ps_rgb_max(c), PS_SCENE_MAX_LIGHT_POWER);
    if (ps_rgb_is_black(c))
        ps_warn(p->warn, "%s:%d: light has zero power and will emit nothing", p->name, p->line);
    return PS_OK;
}

static ps_status check_positive(parser *p, const char *what, double v)
{
    if (!(v > 0.0))
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: %s: '%s' must be positive", p->name, p->line, p->tok[0],
                            what);
    return PS_OK;
}

static ps_status check_direction(parser *p, const char *what, ps_vec3 d)
{
    if (ps_v3_len2(d) == 0.0)
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: %s: '%s' must not be the zero vector", p->name, p->line,
                            p->tok[0], what);
    return PS_OK;
}

/* A parallelogram from two edges: refuses zero area and parallel edges. */
static ps_status check_parallelogram(parser *p, ps_vec3 e1, ps_vec3 e2)
{
    double cross = ps_v3_len(ps_v3_cross(e1, e2));
    if (!(cross > QUAD_MIN_SINE * ps_v3_len(e1) * ps_v3_len(e2)))
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: %s: edge1 and edge2 span no area (zero or parallel)",
                            p->name, p->line, p->tok[0]);
    return PS_OK;
}

/* ---- materials ---------------------------------------------------------------- */

static bool valid_name(const char *n)
{
    size_t len = strlen(n);
    if (len == 0 || len >= PS_NAME_MAX)
        return false;
    for (; *n; n++) {
        char c = *n;
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
              c == '.'))
            return false;
    }
    return true;
}

/* A hash lookup: scanning the list made a file with many materials and
 * many references to them take minutes (found by fuzzing). */
static int64_t find_material(const parser *p, const char *name)
{
    return ps_namemap_find(p->material_names, name);
}

static ps_material *add_material(parser *p, const char *name)
{
    if (p->s->materials.count >= PS_SCENE_MAX_MATERIALS) {
        ps_error_set(p->err, PS_ERR_LIMIT, "%s:%d: more than %d materials", p->name, p->line, PS_SCENE_MAX_MATERIALS);
        return NULL;
    }
    ps_material *m = PS_VEC_PUSH(p->s->materials);
    if (!m) {
        ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        return NULL;
    }
    snprintf(m->name, sizeof m->name, "%s", name);
    if (!ps_namemap_put(p->material_names, m->name, (int64_t)(p->s->materials.count - 1), false)) {
        p->s->materials.count--;
        ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        return NULL;
    }
    m->transmittance = ps_rgb_gray(1.0);
    m->reflectance = ps_rgb_gray(1.0);
    return m;
}

/* The material surfaces get when none is named: grey Lambertian, as pbrt's. */
static int64_t default_material(parser *p)
{
    if (p->default_material < 0) {
        ps_material *m = add_material(p, PS_DEFAULT_MATERIAL_NAME);
        if (!m)
            return -1;
        m->type = PS_MAT_DIFFUSE;
        m->albedo = ps_rgb_gray(DEFAULT_ALBEDO);
        p->default_material = (int64_t)(p->s->materials.count - 1);
    }
    return p->default_material;
}

static ps_status parse_material(parser *p)
{
    const char *name = next_word(p, "name");
    if (!name)
        return PS_ERR_PARSE;
    if (!valid_name(name))
        return ps_error_set(p->err, PS_ERR_PARSE,
                            "%s:%d: material name '%s' must be 1-%d letters, digits, '_', '-' or '.'", p->name,
                            p->line, name, PS_NAME_MAX - 1);
    if (find_material(p, name) >= 0)
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: material '%s' is already defined", p->name, p->line, name);
    const char *type = next_word(p, "type (diffuse, glossy, mirror or dielectric)");
    if (!type)
        return PS_ERR_PARSE;
    ps_material m;
    memset(&m, 0, sizeof m);
    m.reflectance = ps_rgb_gray(1.0);
    m.transmittance = ps_rgb_gray(1.0);
    ps_status st;
    if (!strcmp(type, "diffuse")) {
        static const key_spec spec[] = {{"albedo", 3, true}};
        key_vals kv[1];
        if ((st = parse_keys(p, "material diffuse", spec, 1, kv)) != PS_OK)
            return st;
        m.type = PS_MAT_DIFFUSE;
        m.albedo = kv_rgb(&kv[0]);
        if ((st = check_unit_rgb(p, "albedo", m.albedo)) != PS_OK)
            return st;
    } else if (!strcmp(type, "glossy")) {
        static const key_spec spec[] = {{"albedo", 3, false}, {"specular", 3, true}, {"exponent", 1, true}};
        key_vals kv[3];
        if ((st = parse_keys(p, "material glossy", spec, 3, kv)) != PS_OK)
            return st;
        m.type = PS_MAT_GLOSSY;
        m.albedo = kv_rgb(&kv[0]);
        m.specular = kv_rgb(&kv[1]);
        m.exponent = kv[2].v[0];
        if ((st = check_unit_rgb(p, "albedo", m.albedo)) != PS_OK ||
            (st = check_unit_rgb(p, "specular", m.specular)) != PS_OK)
            return st;
        ps_rgb sum = ps_rgb_add(m.albedo, m.specular);
        if (ps_rgb_max(sum) > 1.0 + ALBEDO_SLACK)
            return ps_error_set(p->err, PS_ERR_RANGE,
                                "%s:%d: material glossy: albedo + specular exceeds 1 (the surface would create energy)",
                                p->name, p->line);
        if (m.exponent < 0.0 || m.exponent > MAX_PHONG_EXPONENT)
            return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: material glossy: 'exponent' must be in [0, %g]", p->name,
                                p->line, MAX_PHONG_EXPONENT);
    } else if (!strcmp(type, "mirror")) {
        static const key_spec spec[] = {{"reflectance", 3, false}};
        key_vals kv[1];
        if ((st = parse_keys(p, "material mirror", spec, 1, kv)) != PS_OK)
            return st;
        m.type = PS_MAT_MIRROR;
        if (kv[0].present)
            m.reflectance = kv_rgb(&kv[0]);
        if ((st = check_unit_rgb(p, "reflectance", m.reflectance)) != PS_OK)
            return st;
    } else if (!strcmp(type, "dielectric")) {
        static const key_spec spec[] = {{"ior", 1, true}, {"transmittance", 3, false}};
        key_vals kv[2];
        if ((st = parse_keys(p, "material dielectric", spec, 2, kv)) != PS_OK)
            return st;
        m.type = PS_MAT_DIELECTRIC;
        m.ior = kv[0].v[0];
        if (!(m.ior > 0.0 && m.ior <= MAX_IOR))
            return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: material dielectric: 'ior' must be in (0, %g]", p->name,
                                p->line, MAX_IOR);
        if (kv[1].present)
            m.transmittance = kv_rgb(&kv[1]);
        if ((st = check_unit_rgb(p, "transmittance", m.transmittance)) != PS_OK)
            return st;
    } else {
        return ps_error_set(p->err, PS_ERR_PARSE,
                            "%s:%d: material: unknown type '%s' (expected diffuse, glossy, mirror or dielectric)",
                            p->name, p->line, type);
    }
    ps_material *dst = add_material(p, name);
    if (!dst)
        return p->err->status;
    snprintf(m.name, sizeof m.name, "%s", name);
    *dst = m;
    return PS_OK;
}

/* The material named by a `material NAME` key, or the default. */
static ps_status resolve_material(parser *p, const key_vals *kv, uint32_t *out)
{
    int64_t m = kv->present ? find_material(p, kv->word) : default_material(p);
    if (m < 0 && kv->present)
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: material '%s' is not defined (define it above)",
                            p->name, p->line, p->tok[0], kv->word);
    if (m < 0)
        return p->err->status;
    *out = (uint32_t)m;
    return PS_OK;
}

/* ---- geometry ------------------------------------------------------------------ */

/* `move DX DY DZ` (meshes, quads) and `light-power K R G B` (meshes: the
 * statement's K-th emissive light), repeatable, in order from p->pos to the
 * end of the line: the edits ps_scene_write saves, replayed through the edit
 * functions once the statement is read (apply_edits), so that they give the
 * same numbers as when they were made. */
static ps_status parse_edits(parser *p, bool mesh)
{
    while (more(p)) {
        const char *key = p->tok[p->pos++];
        ps_scene_edit e = {0, PS_SOURCE_NONE, {0, 0, 0}};
        double v[4];
        ps_status st;
        if (!strcmp(key, "move")) {
            if ((st = read_numbers(p, "move", 3, v)) != PS_OK)
                return st;
            e.v = ps_v3(v[0], v[1], v[2]);
        } else if (mesh && !strcmp(key, "light-power")) {
            if ((st = read_numbers(p, "light-power", 4, v)) != PS_OK)
                return st;
            if (!(v[0] >= 0.0 && v[0] < PS_SCENE_MAX_LIGHTS && v[0] == floor(v[0])))
                return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: mesh: light-power: %g is not a light of the mesh",
                                    p->name, p->line, v[0]);
            e.light = (uint32_t)v[0];
            e.v = ps_v3(v[1], v[2], v[3]);
        } else {
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: unknown key '%s' after 'move' (expected %s)",
                                p->name, p->line, p->tok[0], key, mesh ? "move or light-power" : "move");
        }
        ps_scene_edit *slot = PS_VEC_PUSH(p->pending_edits);
        if (!slot)
            return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        *slot = e;
    }
    return PS_OK;
}

static ps_object *add_object(parser *p, ps_object_type type)
{
    if (p->s->objects.count >= PS_SCENE_MAX_OBJECTS) {
        ps_error_set(p->err, PS_ERR_LIMIT, "%s:%d: more than %d objects", p->name, p->line, PS_SCENE_MAX_OBJECTS);
        return NULL;
    }
    ps_object *o = PS_VEC_PUSH(p->s->objects);
    if (!o) {
        ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        return NULL;
    }
    o->type = type;
    o->line = p->line;
    o->first_triangle = (uint32_t)p->s->triangles.count;
    return o;
}

static ps_status reserve_geometry(parser *p, size_t positions, size_t normals, size_t triangles)
{
    ps_scene *s = p->s;
    if (s->triangles.count + triangles > PS_SCENE_MAX_TRIANGLES)
        return ps_error_set(p->err, PS_ERR_LIMIT, "%s:%d: the scene would have more than %d triangles", p->name,
                            p->line, PS_SCENE_MAX_TRIANGLES);
    char who[PS_ERROR_MSG_MAX / 2], what[64];
    snprintf(who, sizeof who, "%s:%d", p->name, p->line);
    snprintf(what, sizeof what, "a scene of %zu triangles", s->triangles.count + triangles);
    if (ps_memory_check((uint64_t)(s->triangles.count + triangles) * PS_SCENE_PLAN_TRIANGLE_BYTES, who, what,
                        p->err) != PS_OK)
        return PS_ERR_LIMIT;
    if (!PS_RESERVE(s->positions.items, s->positions.cap, s->positions.count + positions) ||
        !PS_RESERVE(s->normals.items, s->normals.cap, s->normals.count + normals) ||
        !PS_RESERVE(s->triangles.items, s->triangles.cap, s->triangles.count + triangles))
        return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
    return PS_OK;
}

static ps_status parse_quad(parser *p)
{
    static const key_spec spec[] = {{"corner", 3, true}, {"edge1", 3, true}, {"edge2", 3, true}, {"material", ARITY_WORD, false}};
    key_vals kv[4];
    /* Saved edits (`move`, repeatable) follow the keys. */
    int ntok = p->ntok, first_move = p->pos;
    while (first_move < ntok && strcmp(p->tok[first_move], "move") != 0)
        first_move++;
    p->ntok = first_move;
    ps_status st = parse_keys(p, "quad", spec, 4, kv);
    p->ntok = ntok;
    if (st != PS_OK || (st = parse_edits(p, false)) != PS_OK)
        return st;
    ps_vec3 c = kv_vec3(&kv[0]), e1 = kv_vec3(&kv[1]), e2 = kv_vec3(&kv[2]);
    p->pending_obj.corner = c;
    p->pending_obj.edge1 = e1;
    p->pending_obj.edge2 = e2;
    uint32_t mat;
    if ((st = check_parallelogram(p, e1, e2)) != PS_OK || (st = resolve_material(p, &kv[3], &mat)) != PS_OK ||
        (st = reserve_geometry(p, 4, 0, 2)) != PS_OK)
        return st;
    ps_object *o = add_object(p, PS_OBJ_QUAD);
    if (!o)
        return p->err->status;
    ps_scene *s = p->s;
    uint32_t base = (uint32_t)s->positions.count;
    s->positions.items[s->positions.count++] = c;
    s->positions.items[s->positions.count++] = ps_v3_add(c, e1);
    s->positions.items[s->positions.count++] = ps_v3_add(ps_v3_add(c, e1), e2);
    s->positions.items[s->positions.count++] = ps_v3_add(c, e2);
    /* Both triangles wind like (edge1, edge2), so their normal is edge1 x edge2. */
    static const uint32_t corners[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int t = 0; t < 2; t++) {
        ps_triangle *tr = &s->triangles.items[s->triangles.count++];
        for (int k = 0; k < 3; k++) {
            tr->v[k] = base + corners[t][k];
            tr->n[k] = -1;
        }
        tr->material = mat;
        tr->object = (uint32_t)(s->objects.count - 1);
    }
    o->triangle_count = 2;
    o->material = mat;
    return PS_OK;
}

static ps_status parse_sphere(parser *p)
{
    static const key_spec spec[] = {{"center", 3, true}, {"radius", 1, true}, {"material", ARITY_WORD, false}};
    key_vals kv[3];
    ps_status st = parse_keys(p, "sphere", spec, 3, kv);
    uint32_t mat;
    if (st != PS_OK || (st = check_positive(p, "radius", kv[1].v[0])) != PS_OK ||
        (st = resolve_material(p, &kv[2], &mat)) != PS_OK)
        return st;
    ps_object *o = add_object(p, PS_OBJ_SPHERE);
    if (!o)
        return p->err->status;
    o->center = kv_vec3(&kv[0]);
    o->radius = kv[1].v[0];
    o->material = mat;
    return PS_OK;
}

/* ---- meshes ------------------------------------------------------------------------ */

typedef struct warn_relay {
    const ps_warn_sink *to;
} warn_relay;

/* MTL → material, following the contract's mapping. Values the MTL format
 * allows but physics does not (Kd + Ks > 1) are scaled down with a warning:
 * files from other tools often carry them and refusing would be unhelpful. */
static void map_mtl(parser *p, const char *obj_path, const ps_obj_material *om, ps_material *m)
{
    ps_rgb kd = ps_rgb_make(om->kd[0], om->kd[1], om->kd[2]);
    ps_rgb ks = ps_rgb_make(om->ks[0], om->ks[1], om->ks[2]);
    m->emission = ps_rgb_make(om->ke[0], om->ke[1], om->ke[2]);
    m->reflectance = ps_rgb_gray(1.0);
    m->transmittance = ps_rgb_gray(1.0);
    if (om->illum == 3 || om->illum == 5) {
        m->type = PS_MAT_MIRROR;
        if (ps_rgb_max(ks) > 1.0)
            ps_warn(p->warn, "%s: material '%s': Ks above 1 clamped for a mirror", obj_path, om->name);
        m->reflectance = ps_rgb_make(fmin(ks.r, 1.0), fmin(ks.g, 1.0), fmin(ks.b, 1.0));
    } else if (om->illum == 4 || om->illum == 6 || om->illum == 7) {
        m->type = PS_MAT_DIELECTRIC;
        m->ior = om->has_ni ? om->ni : 1.5;
        if (!om->has_ni)
            ps_warn(p->warn, "%s: material '%s' is a dielectric without Ni; using 1.5 (glass)", obj_path, om->name);
        if (!(m->ior > 0.0 && m->ior <= MAX_IOR)) {
            ps_warn(p->warn, "%s: material '%s': Ni %g is out of range; using 1.5", obj_path, om->name, m->ior);
            m->ior = 1.5;
        }
    } else {
        bool glossy = ps_rgb_max(ks) > 0.0 && om->illum != 0 && om->illum != 1;
        m->type = glossy ? PS_MAT_GLOSSY : PS_MAT_DIFFUSE;
        if (!glossy)
            ks = ps_rgb_gray(0.0);
        double worst = ps_rgb_max(ps_rgb_add(kd, ks));
        if (worst > 1.0) {
            ps_warn(p->warn, "%s: material '%s': Kd + Ks = %g exceeds 1; scaled down to conserve energy", obj_path,
                    om->name, worst);
            kd = ps_rgb_scale(kd, 1.0 / worst);
            ks = ps_rgb_scale(ks, 1.0 / worst);
        }
        m->albedo = kd;
        m->specular = ks;
        m->exponent = om->has_ns ? fmin(fmax(om->ns, 0.0), MAX_PHONG_EXPONENT) : 1.0;
    }
}

/* Adds the mesh's faces with the transform applied; mats maps OBJ material
 * index (+1, so that -1 is slot 0) to scene material. */
static ps_status add_mesh_geometry(parser *p, const ps_obj_mesh *om, const ps_xform *xf, const uint32_t *mats,
                                   uint32_t object)
{
    ps_scene *s = p->s;
    ps_status st = reserve_geometry(p, om->position_count, om->normal_count, om->triangle_count);
    if (st != PS_OK)
        return st;
    uint32_t pbase = (uint32_t)s->positions.count, nbase = (uint32_t)s->normals.count;
    for (size_t i = 0; i < om->position_count; i++) {
        ps_vec3 v = ps_v3(om->positions[3 * i], om->positions[3 * i + 1], om->positions[3 * i + 2]);
        v = ps_xform_point(xf, v);
        if (!ps_v3_isfinite(v))
            return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: mesh: the transform takes a vertex out of range",
                                p->name, p->line);
        s->positions.items[s->positions.count++] = v;
    }
    for (size_t i = 0; i < om->normal_count; i++) {
        ps_vec3 n = ps_v3(om->normals[3 * i], om->normals[3 * i + 1], om->normals[3 * i + 2]);
        /* A zero normal stays zero; faces using it fall back to the face normal below. */
        s->normals.items[s->normals.count++] = ps_v3_len2(n) > 0.0 ? ps_xform_normal(xf, n) : ps_v3(0, 0, 0);
    }
    /* A mirroring transform reverses the winding; swap two corners so that the
     * geometric normal keeps pointing where it did (outward stays outward). */
    bool mirror = ps_xform_det(*xf) < 0.0;
    for (size_t t = 0; t < om->triangle_count; t++) {
        ps_triangle *tr = &s->triangles.items[s->triangles.count++];
        for (int c = 0; c < 3; c++) {
            int src = mirror && c > 0 ? 3 - c : c;
            tr->v[c] = pbase + (uint32_t)om->tri_v[3 * t + src];
            int32_t n = om->tri_n[3 * t + src];
            bool usable = n >= 0 && ps_v3_len2(s->normals.items[nbase + (uint32_t)n]) > 0.0;
            tr->n[c] = usable ? (int32_t)(nbase + (uint32_t)n) : -1;
        }
        /* A face with some corners lacking a normal uses the face normal throughout. */
        if (tr->n[0] < 0 || tr->n[1] < 0 || tr->n[2] < 0)
            tr->n[0] = tr->n[1] = tr->n[2] = -1;
        tr->material = mats[om->tri_mat[t] + 1];
        tr->object = object;
    }
    return PS_OK;
}

/* One PS_LIGHT_MESH per emissive material of the mesh: its faces, their area.
 * mats/nmats: the scene materials of the mesh's faces, UINT32_MAX for unused
 * slots (see parse_mesh). */
/* An emitting face of the mesh being added: what add_mesh_lights groups. */
typedef struct emit_face {
    uint32_t material, triangle;
} emit_face;

static int by_material_then_triangle(const void *a, const void *b)
{
    const emit_face *x = a, *y = b;
    if (x->material != y->material)
        return x->material < y->material ? -1 : 1;
    return x->triangle < y->triangle ? -1 : x->triangle > y->triangle;
}

/* One PS_LIGHT_MESH per distinct emissive material of the mesh, in OBJ
 * material order, its emitters in triangle order. The faces are sorted by
 * material once: scanning every face per material, and every earlier slot
 * per slot, made meshes with many materials quadratic (found by fuzzing). */
static ps_status add_mesh_lights(parser *p, const ps_object *o, uint32_t object, const uint32_t *mats, size_t nmats)
{
    ps_scene *s = p->s;
    emit_face *faces = NULL;
    size_t nfaces = 0, cap = 0;
    for (uint32_t t = o->first_triangle; t < o->first_triangle + o->triangle_count; t++) {
        uint32_t m = s->triangles.items[t].material;
        /* A zero-area face emits nothing and could not be sampled. */
        if (ps_rgb_is_black(s->materials.items[m].emission) || !(ps_scene_triangle_area(s, t) > 0.0))
            continue;
        if (!PS_RESERVE(faces, cap, nfaces + 1)) {
            free(faces);
            return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        }
        faces[nfaces++] = (emit_face){m, t};
    }
    if (nfaces == 0)
        return PS_OK;
    qsort(faces, nfaces, sizeof *faces, by_material_then_triangle);
    bool *done = calloc(s->materials.count, sizeof *done); /* a light was made for this material */
    if (!done) {
        free(faces);
        return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
    }
    ps_status st = PS_OK;
    for (size_t k = 0; st == PS_OK && k < nmats; k++) {
        uint32_t m = mats[k];
        if (m == UINT32_MAX || done[m])
            continue;
        done[m] = true;
        /* The first face of material m: a lower bound in the sorted faces. */
        size_t lo = 0, hi = nfaces;
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (faces[mid].material < m)
                lo = mid + 1;
            else
                hi = mid;
        }
        if (lo == nfaces || faces[lo].material != m)
            continue;
        if (s->lights.count >= PS_SCENE_MAX_LIGHTS) {
            st = ps_error_set(p->err, PS_ERR_LIMIT, "%s:%d: more than %d lights", p->name, p->line,
                              PS_SCENE_MAX_LIGHTS);
            break;
        }
        size_t first = s->emitters.count;
        double area = 0.0;
        for (size_t i = lo; st == PS_OK && i < nfaces && faces[i].material == m; i++) {
            uint32_t *e = PS_VEC_PUSH(s->emitters);
            if (!e)
                st = ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
            else
                *e = faces[i].triangle;
            area += ps_scene_triangle_area(s, faces[i].triangle);
        }
        ps_light *l = st == PS_OK ? PS_VEC_PUSH(s->lights) : NULL;
        if (st == PS_OK && !l)
            st = ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        if (st != PS_OK)
            break;
        const ps_material *mat = &s->materials.items[m];
        l->type = PS_LIGHT_MESH;
        l->line = p->line;
        l->first_emitter = (uint32_t)first;
        l->emitter_count = (uint32_t)(s->emitters.count - first);
        l->object = object;
        l->area = area;
        l->radiance = mat->emission;
        /* A one-sided Lambertian emitter of radiance L emits pi * L per unit area. */
        l->power = ps_rgb_scale(mat->emission, PS_PI * area);
        if (!(ps_rgb_max(l->power) <= PS_SCENE_MAX_LIGHT_POWER)) {
            st = ps_error_set(p->err, PS_ERR_RANGE,
                              "%s:%d: mesh: its emitting faces' power %g W is above the %g W a light may have",
                              p->name, p->line, ps_rgb_max(l->power), PS_SCENE_MAX_LIGHT_POWER);
            break; /* through the frees below */
        }
        l->position = ps_aabb_center(o->bounds);
    }
    free(done);
    free(faces);
    return st;
}

static ps_status parse_mesh(parser *p)
{
    const char *file = next_word(p, "OBJ file name");
    if (!file)
        return PS_ERR_PARSE;
    const char *override = NULL;
    ps_xform xf = ps_xform_identity();
    ps_status st;
    /* Transforms apply in the order written: "scale 2 translate 1 0 0" scales first. */
    while (more(p)) {
        const char *key = p->tok[p->pos++];
        double v[4];
        ps_xform step;
        if (!strcmp(key, "move") || !strcmp(key, "light-power")) {
            p->pos--;
            if ((st = parse_edits(p, true)) != PS_OK)
                return st;
            break;
        }
        if (!strcmp(key, "material")) {
            if (override)
                return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: mesh: 'material' given twice", p->name, p->line);
            if (!(override = next_word(p, "material name")))
                return PS_ERR_PARSE;
            continue;
        } else if (!strcmp(key, "scale")) {
            /* one factor, or three */
            int n = 0;
            while (n < 3 && more(p) && ps_parse_double(p->tok[p->pos], &v[n])) {
                n++;
                p->pos++;
            }
            if (n == 2 || n == 0)
                return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: mesh: 'scale' needs 1 or 3 finite numbers", p->name,
                                    p->line);
            if (n == 1)
                v[1] = v[2] = v[0];
            if (v[0] == 0.0 || v[1] == 0.0 || v[2] == 0.0)
                return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: mesh: 'scale' must not be zero", p->name, p->line);
            step = ps_xform_scale(ps_v3(v[0], v[1], v[2]));
        } else if (!strcmp(key, "rotate")) {
            if ((st = read_numbers(p, "rotate", 4, v)) != PS_OK)
                return st;
            if (ps_v3_len2(ps_v3(v[0], v[1], v[2])) == 0.0)
                return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: mesh: 'rotate' axis must not be zero", p->name,
                                    p->line);
            step = ps_xform_rotate(ps_v3(v[0], v[1], v[2]), v[3]);
        } else if (!strcmp(key, "translate")) {
            if ((st = read_numbers(p, "translate", 3, v)) != PS_OK)
                return st;
            step = ps_xform_translate(ps_v3(v[0], v[1], v[2]));
        } else {
            return ps_error_set(p->err, PS_ERR_PARSE,
                                "%s:%d: mesh: unknown key '%s' (expected material, scale, rotate, translate)", p->name,
                                p->line, key);
        }
        xf = ps_xform_compose(step, xf);
    }
    int64_t override_mat = -1;
    if (override && (override_mat = find_material(p, override)) < 0)
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: mesh: material '%s' is not defined (define it above)",
                            p->name, p->line, override);

    char path[4096];
    if (file[0] == '/' || !p->base_dir[0])
        snprintf(path, sizeof path, "%s", file);
    else
        snprintf(path, sizeof path, "%s/%s", p->base_dir, file);
    ps_obj_mesh om;
    ps_error oerr;
    st = ps_obj_load(path, &om, p->warn, &oerr);
    if (st == PS_OK) {
        /* The keys as written, without the edits, and the file by absolute
         * path: what ps_scene_write writes relative to a new place. */
        char keys[SCN_LINE_MAX] = "";
        size_t used = 0;
        for (int k = 2; k < p->ntok && strcmp(p->tok[k], "move") != 0 && strcmp(p->tok[k], "light-power") != 0; k++)
            used += (size_t)snprintf(keys + used, used < sizeof keys ? sizeof keys - used : 0, "%s%s", used ? " " : "",
                                     p->tok[k]);
        char *abs = ps_scene_abs_path(path);
        p->pending_obj.file = abs ? ps_scene_add_string(p->s, abs) : PS_SOURCE_NONE;
        p->pending_obj.keys = ps_scene_add_string(p->s, keys);
        p->pending_obj.first_light = (uint32_t)p->s->lights.count;
        free(abs);
        if (p->pending_obj.file == PS_SOURCE_NONE || p->pending_obj.keys == PS_SOURCE_NONE) {
            ps_obj_free(&om);
            return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        }
    }
    if (st != PS_OK) {
        /* An OBJ/MTL problem with a line of its own names that line first (and
         * the error keeps it); one without (a missing file) is the scene
         * line's problem. */
        if (oerr.line > 0) {
            ps_error_set(p->err, st, "%s (mesh at %s:%d)", oerr.msg, p->name, p->line);
            if (p->err)
                p->err->line = oerr.line;
            return st;
        }
        return ps_error_at(p->err, st, p->name, p->line, "mesh: %s", oerr.msg);
    }

    /* mats[k + 1]: scene material of OBJ material k; mats[0]: faces with none. */
    uint32_t *mats = calloc(om.material_count + 1, sizeof *mats);
    if (!mats) {
        ps_obj_free(&om);
        return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
    }
    /* Only the materials that faces use become scene materials (a library may
     * hold many more, and tinyobjloader adds an empty-named one of its own). */
    const char *base = strrchr(file, '/') ? strrchr(file, '/') + 1 : file;
    for (size_t k = 0; k <= om.material_count; k++)
        mats[k] = UINT32_MAX;
    for (size_t t = 0; st == PS_OK && t < om.triangle_count; t++) {
        size_t k = (size_t)(om.tri_mat[t] + 1);
        if (mats[k] != UINT32_MAX)
            continue;
        if (override_mat >= 0) {
            mats[k] = (uint32_t)override_mat;
        } else if (k == 0) {
            int64_t d = default_material(p);
            if (d < 0)
                st = p->err->status;
            else
                mats[0] = (uint32_t)d;
        } else {
            /* Scene-unique name for an MTL material: "file.obj/name". */
            char name[PS_NAME_MAX];
            snprintf(name, sizeof name, "%.30s/%.31s", base, om.materials[k - 1].name);
            ps_material *m = add_material(p, name);
            if (!m) {
                st = p->err->status;
            } else {
                map_mtl(p, path, &om.materials[k - 1], m);
                mats[k] = (uint32_t)(p->s->materials.count - 1);
            }
        }
    }
    ps_object *o = st == PS_OK ? add_object(p, PS_OBJ_MESH) : NULL;
    if (st == PS_OK && !o)
        st = p->err->status;
    if (st == PS_OK) {
        uint32_t object = (uint32_t)(p->s->objects.count - 1);
        st = add_mesh_geometry(p, &om, &xf, mats, object);
        if (st == PS_OK) {
            o = &p->s->objects.items[object];
            o->triangle_count = (uint32_t)om.triangle_count;
            o->material = override_mat >= 0 ? (uint32_t)override_mat : mats[om.tri_mat[0] + 1];
            ps_scene_update_object(p->s, object); /* its bounds place its lights */
            st = add_mesh_lights(p, o, object, mats, om.material_count + 1);
        }
    }
    free(mats);
    ps_obj_free(&om);
    return st;
}

/* ---- lights ---------------------------------------------------------------------- */

/* Every light type ends its keys with these four: exactly one of power,
 * lumens or candela (an ies light may give none: its file's candela), and a
 * colour for the photometric two (docs/scene-format.md). */
#define PHOTOMETRIC_KEYS {"power", 3, false}, {"lumens", 1, false}, {"candela", 1, false}, {"color", 3, false}
enum { PHOTOMETRIC_KEY_COUNT = 4 };

/* Sets l->power from the photometric keys kv[0..3] (power, lumens, candela,
 * color). peak_per_watt: the light's largest intensity per watt of its flux
 * (W/sr per W), what `candela` is the peak of; own_lumens > 0: what the light
 * emits when no key says (an ies file's table). */
static ps_status light_power(parser *p, ps_light *l, const char *stmt, const key_vals *kv, double peak_per_watt,
                             double own_lumens)
{
    int given = kv[0].present + kv[1].present + kv[2].present;
    if (given > 1)
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: give one of 'power', 'lumens' or 'candela', not %s",
                            p->name, p->line, stmt, given == 3 ? "all three" : "two");
    if (given == 0 && !(own_lumens > 0.0))
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: missing 'power' (or 'lumens' or 'candela')", p->name,
                            p->line, stmt);
    if (kv[0].present) {
        if (kv[3].present)
            return ps_error_set(p->err, PS_ERR_PARSE,
                                "%s:%d: %s: 'color' goes with 'lumens' or 'candela'; 'power' already gives the colour",
                                p->name, p->line, stmt);
        l->power = kv_rgb(&kv[0]);
        return check_power(p, l->power);
    }
    ps_rgb color = kv[3].present ? kv_rgb(&kv[3]) : ps_rgb_gray(1.0);
    if (color.r < 0 || color.g < 0 || color.b < 0 || !(ps_rgb_luminance(color) > 0.0))
        return ps_error_set(p->err, PS_ERR_RANGE,
                            "%s:%d: %s: 'color' must be non-negative with some luminance (0.2126 R + 0.7152 G + "
                            "0.0722 B > 0)",
                            p->name, p->line, stmt);
    double lumens = own_lumens;
    if (kv[1].present) {
        lumens = kv[1].v[0];
        if (lumens < 0.0)
            return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: %s: 'lumens' must not be negative", p->name, p->line,
                                stmt);
    } else if (kv[2].present) {
        if (kv[2].v[0] < 0.0)
            return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: %s: 'candela' must not be negative", p->name, p->line,
                                stmt);
        /* Peak intensity C cd = peak_per_watt * flux (in lm): flux = C / peak_per_watt. */
        lumens = kv[2].v[0] / peak_per_watt;
    }
    l->power = ps_radiometric(lumens, color);
    if (!ps_rgb_isfinite(l->power))
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: %s: %g lm is not a finite power", p->name, p->line, stmt,
                            lumens);
    return check_power(p, l->power);
}

/* `light ies FILE position X Y Z [aim X Y Z] [spin DEG] [lumens L | candela C | power R G B] [color R G B]`. */
static ps_status parse_ies_light(parser *p, ps_light *l)
{
    const char *file = next_word(p, "IES file name");
    if (!file)
        return PS_ERR_PARSE;
    static const key_spec spec[] = {{"position", 3, true}, {"aim", 3, false}, {"spin", 1, false}, PHOTOMETRIC_KEYS};
    key_vals kv[3 + PHOTOMETRIC_KEY_COUNT];
    ps_status st;
    if ((st = parse_keys(p, "light ies", spec, 3 + PHOTOMETRIC_KEY_COUNT, kv)) != PS_OK)
        return st;
    l->type = PS_LIGHT_IES;
    l->position = kv_vec3(&kv[0]);
    ps_vec3 aim = kv[1].present ? kv_vec3(&kv[1]) : ps_v3(0, -1, 0);
    if ((st = check_direction(p, "aim", aim)) != PS_OK)
        return st;
    p->pending_light.dir = aim;
    l->direction = ps_v3_norm(aim);
    l->spin_deg = kv[2].present ? kv[2].v[0] : 0.0;
    if (!(fabs(l->spin_deg) <= 360.0 * 1000.0))
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: light ies: 'spin' %g degrees is out of range", p->name,
                            p->line, l->spin_deg);
    /* Horizontal angle 0 before spin: world +x made perpendicular to the aim
     * (world +z when the aim is along x); 90 is axis0 x aim, which for the
     * default aim straight down is -z: counter-clockwise seen from above, as
     * LM-63 counts horizontal angles (and Radiance's ies2rad with z up). */
    ps_vec3 ref = fabs(l->direction.x) > 0.999 ? ps_v3(0, 0, 1) : ps_v3(1, 0, 0);
    ps_vec3 a0 = ps_v3_norm(ps_v3_sub(ref, ps_v3_scale(l->direction, ps_v3_dot(ref, l->direction))));
    ps_vec3 a90 = ps_v3_cross(a0, l->direction);
    double spin = l->spin_deg * (PS_PI / 180.0);
    l->axis0 = ps_v3_add(ps_v3_scale(a0, cos(spin)), ps_v3_scale(a90, sin(spin)));
    l->axis90 = ps_v3_cross(l->axis0, l->direction);

    char path[4096];
    if (file[0] == '/' || !p->base_dir[0])
        snprintf(path, sizeof path, "%s", file);
    else
        snprintf(path, sizeof path, "%s/%s", p->base_dir, file);
    ps_ies *ies = NULL;
    ps_error ierr;
    st = ps_ies_load(path, &ies, &ierr);
    if (st == PS_OK) {
        char *abs = ps_scene_abs_path(path);
        p->pending_light.file = abs ? ps_scene_add_string(p->s, abs) : PS_SOURCE_NONE;
        free(abs);
        if (p->pending_light.file == PS_SOURCE_NONE) {
            ps_ies_destroy(ies);
            return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        }
    }
    if (st != PS_OK) {
        /* As for meshes: a problem on a line of the IES file names that line. */
        const char *colon = strchr(ierr.msg, ':');
        bool has_line = colon && colon[1] >= '0' && colon[1] <= '9';
        for (const char *c = ierr.msg; has_line && c < colon; c++)
            has_line = *c != ' ';
        if (has_line)
            return ps_error_set(p->err, st, "%s (light ies at %s:%d)", ierr.msg, p->name, p->line);
        return ps_error_set(p->err, st, "%s:%d: light ies: %s", p->name, p->line, ierr.msg);
    }
    /* The file's flux as written, with its TILT factor for the aim's tilt
     * from straight down (the position it was measured in). */
    double tilt = acos(fmin(1.0, fmax(-1.0, -l->direction.y))) * (180.0 / PS_PI);
    double own = ps_ies_flux(ies) * ps_ies_tilt_factor(ies, tilt);
    if (!kv[3].present && !kv[4].present && !kv[5].present && !(own > 0.0)) {
        ps_ies_destroy(ies);
        return ps_error_set(p->err, PS_ERR_RANGE,
                            "%s:%d: light ies: %s emits nothing at this tilt (its TILT factor is 0); give 'lumens'",
                            p->name, p->line, file);
    }
    st = light_power(p, l, "light ies", kv + 3, ps_ies_peak(ies) / ps_ies_flux(ies), own > 0.0 ? own : 1.0);
    if (st == PS_OK && p->s->profiles.count >= PS_SCENE_MAX_LIGHTS)
        st = ps_error_set(p->err, PS_ERR_LIMIT, "%s:%d: more than %d IES lights", p->name, p->line,
                          PS_SCENE_MAX_LIGHTS);
    if (st == PS_OK) {
        ps_ies **slot = PS_VEC_PUSH(p->s->profiles);
        if (!slot)
            st = ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
        else
            *slot = ies;
    }
    if (st != PS_OK) {
        ps_ies_destroy(ies);
        return st;
    }
    l->profile = (uint32_t)(p->s->profiles.count - 1);
    return PS_OK;
}

static ps_status parse_light(parser *p)
{
    const char *type = next_word(p, "type (point, spot, quad, sphere, disc or ies)");
    if (!type)
        return PS_ERR_PARSE;
    if (p->s->lights.count >= PS_SCENE_MAX_LIGHTS)
        return ps_error_set(p->err, PS_ERR_LIMIT, "%s:%d: more than %d lights", p->name, p->line, PS_SCENE_MAX_LIGHTS);
    ps_light l;
    memset(&l, 0, sizeof l);
    l.line = p->line;
    key_vals kv[SCN_MAX_KEYS];
    ps_status st;
    const key_vals *photo = NULL; /* the four photometric keys */
    double peak = 0.0;            /* peak intensity per watt of flux, 1/sr */
    if (!strcmp(type, "point")) {
        static const key_spec spec[] = {{"position", 3, true}, PHOTOMETRIC_KEYS};
        if ((st = parse_keys(p, "light point", spec, 1 + PHOTOMETRIC_KEY_COUNT, kv)) != PS_OK)
            return st;
        l.type = PS_LIGHT_POINT;
        l.position = kv_vec3(&kv[0]);
        photo = kv + 1;
        peak = 1.0 / (4.0 * PS_PI);
    } else if (!strcmp(type, "spot")) {
        static const key_spec spec[] = {{"position", 3, true}, {"direction", 3, true}, {"angle", 1, true},
                                        PHOTOMETRIC_KEYS};
        if ((st = parse_keys(p, "light spot", spec, 3 + PHOTOMETRIC_KEY_COUNT, kv)) != PS_OK)
            return st;
        l.type = PS_LIGHT_SPOT;
        l.position = kv_vec3(&kv[0]);
        if ((st = check_direction(p, "direction", kv_vec3(&kv[1]))) != PS_OK)
            return st;
        p->pending_light.dir = kv_vec3(&kv[1]);
        l.direction = ps_v3_norm(kv_vec3(&kv[1]));
        l.angle_deg = kv[2].v[0];
        if (!(l.angle_deg > 0.0 && l.angle_deg <= 90.0))
            return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: light spot: 'angle' (the half-angle) must be in (0, 90]",
                                p->name, p->line);
        l.cos_angle = cos(l.angle_deg * (PS_PI / 180.0));
        photo = kv + 3;
        peak = 1.0 / (2.0 * PS_PI * (1.0 - l.cos_angle));
    } else if (!strcmp(type, "quad")) {
        static const key_spec spec[] = {{"corner", 3, true}, {"edge1", 3, true}, {"edge2", 3, true},
                                        PHOTOMETRIC_KEYS};
        if ((st = parse_keys(p, "light quad", spec, 3 + PHOTOMETRIC_KEY_COUNT, kv)) != PS_OK)
            return st;
        l.type = PS_LIGHT_QUAD;
        l.position = kv_vec3(&kv[0]);
        l.edge1 = kv_vec3(&kv[1]);
        l.edge2 = kv_vec3(&kv[2]);
        if ((st = check_parallelogram(p, l.edge1, l.edge2)) != PS_OK)
            return st;
        ps_vec3 c = ps_v3_cross(l.edge1, l.edge2);
        l.direction = ps_v3_norm(c);
        l.area = ps_v3_len(c);
        photo = kv + 3;
        peak = PS_INV_PI; /* Lambertian: I(normal) = L A = flux / pi */
    } else if (!strcmp(type, "sphere")) {
        static const key_spec spec[] = {{"center", 3, true}, {"radius", 1, true}, PHOTOMETRIC_KEYS};
        if ((st = parse_keys(p, "light sphere", spec, 2 + PHOTOMETRIC_KEY_COUNT, kv)) != PS_OK ||
            (st = check_positive(p, "radius", kv[1].v[0])) != PS_OK)
            return st;
        l.type = PS_LIGHT_SPHERE;
        l.position = kv_vec3(&kv[0]);
        l.radius = kv[1].v[0];
        l.area = 4.0 * PS_PI * l.radius * l.radius;
        photo = kv + 2;
        peak = 1.0 / (4.0 * PS_PI); /* L pi r^2 in every direction, flux 4 pi^2 r^2 L */
    } else if (!strcmp(type, "disc")) {
        static const key_spec spec[] = {{"center", 3, true}, {"normal", 3, true}, {"radius", 1, true},
                                        PHOTOMETRIC_KEYS};
        if ((st = parse_keys(p, "light disc", spec, 3 + PHOTOMETRIC_KEY_COUNT, kv)) != PS_OK ||
            (st = check_direction(p, "normal", kv_vec3(&kv[1]))) != PS_OK ||
            (st = check_positive(p, "radius", kv[2].v[0])) != PS_OK)
            return st;
        l.type = PS_LIGHT_DISC;
        l.position = kv_vec3(&kv[0]);
        p->pending_light.dir = kv_vec3(&kv[1]);
        l.direction = ps_v3_norm(kv_vec3(&kv[1]));
        l.radius = kv[2].v[0];
        l.area = PS_PI * l.radius * l.radius;
        photo = kv + 3;
        peak = PS_INV_PI;
    } else if (!strcmp(type, "ies")) {
        if ((st = parse_ies_light(p, &l)) != PS_OK)
            return st;
    } else {
        return ps_error_set(p->err, PS_ERR_PARSE,
                            "%s:%d: light: unknown type '%s' (expected point, spot, quad, sphere, disc or ies)",
                            p->name, p->line, type);
    }
    char stmt[32];
    snprintf(stmt, sizeof stmt, "light %s", type);
    if (photo && (st = light_power(p, &l, stmt, photo, peak, 0.0)) != PS_OK)
        return st;
    /* Lambertian area emitters: flux = pi * L * area. A size whose area
     * overflows (a sphere of radius 1e200) would give radiance 0 from an
     * infinite surface: refuse it. */
    if (!isfinite(l.area))
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: light %s: its area overflows (%g)", p->name, p->line, type,
                            l.area);
    if (l.area > 0.0)
        l.radiance = ps_rgb_scale(l.power, 1.0 / (PS_PI * l.area));
    ps_light *dst = PS_VEC_PUSH(p->s->lights);
    if (!dst)
        return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
    *dst = l;
    return PS_OK;
}

/* ---- camera, image, photons, radius ---------------------------------------------- */

static ps_status parse_camera(parser *p)
{
    static const key_spec spec[] = {{"eye", 3, true}, {"target", 3, true}, {"up", 3, false}, {"fov", 1, false}};
    key_vals kv[4];
    ps_status st = parse_keys(p, "camera", spec, 4, kv);
    if (st != PS_OK)
        return st;
    if (p->has_camera)
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: a second camera statement (only one is allowed)", p->name,
                            p->line);
    ps_camera c;
    c.eye = kv_vec3(&kv[0]);
    c.target = kv_vec3(&kv[1]);
    c.up = kv[2].present ? kv_vec3(&kv[2]) : ps_v3(0, 1, 0);
    c.fov_deg = kv[3].present ? kv[3].v[0] : DEFAULT_FOV_DEG;
    ps_vec3 dir = ps_v3_sub(c.target, c.eye);
    if (ps_v3_len2(dir) == 0.0)
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: camera: eye and target are the same point", p->name, p->line);
    if (ps_v3_len2(ps_v3_cross(ps_v3_norm(dir), ps_v3_norm(c.up))) < 1e-12)
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: camera: 'up' must not be parallel to the view direction",
                            p->name, p->line);
    if (!(c.fov_deg > 0.0 && c.fov_deg < 180.0))
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: camera: 'fov' must be in (0, 180) degrees", p->name, p->line);
    p->s->camera = c;
    p->has_camera = true;
    return PS_OK;
}

static ps_status read_int(parser *p, const char *what, int64_t lo, int64_t hi, int64_t *out)
{
    if (!more(p))
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: missing %s", p->name, p->line, p->tok[0], what);
    const char *t = p->tok[p->pos++];
    if (!ps_parse_int64(t, out))
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: %s '%s' is not a whole number", p->name, p->line,
                            p->tok[0], what, t);
    if (*out < lo || *out > hi)
        return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: %s: %s %s is outside [%lld, %lld]", p->name, p->line,
                            p->tok[0], what, t, (long long)lo, (long long)hi);
    return PS_OK;
}

static ps_status parse_image(parser *p)
{
    int64_t w, h;
    ps_status st;
    if ((st = read_int(p, "width", 1, PS_SCENE_MAX_IMAGE_SIDE, &w)) != PS_OK ||
        (st = read_int(p, "height", 1, PS_SCENE_MAX_IMAGE_SIDE, &h)) != PS_OK)
        return st;
    if (more(p))
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: image: unexpected '%s' after width and height", p->name,
                            p->line, p->tok[p->pos]);
    if (p->has_image)
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: a second image statement", p->name, p->line);
    p->has_image = true;
    p->s->defaults.width = (int)w;
    p->s->defaults.height = (int)h;
    return PS_OK;
}

/* `photons caustic N global N` and `radius caustic R global R`. */
static ps_status parse_per_map(parser *p, bool photons)
{
    const char *stmt = photons ? "photons" : "radius";
    bool *seen = photons ? &p->has_photons : &p->has_radius;
    if (*seen)
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: a second %s statement", p->name, p->line, stmt);
    bool got[2] = {false, false};
    if (!more(p))
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: expected 'caustic' and/or 'global' values", p->name,
                            p->line, stmt);
    while (more(p)) {
        const char *key = p->tok[p->pos++];
        int which = !strcmp(key, "caustic") ? 0 : !strcmp(key, "global") ? 1 : -1;
        if (which < 0)
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: unknown key '%s' (expected caustic, global)", p->name,
                                p->line, stmt, key);
        if (got[which])
            return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: %s: '%s' given twice", p->name, p->line, stmt, key);
        got[which] = true;
        ps_status st;
        if (photons) {
            int64_t n;
            if ((st = read_int(p, key, 0, PS_SCENE_MAX_PHOTONS, &n)) != PS_OK)
                return st;
            *(which ? &p->s->defaults.global_photons : &p->s->defaults.caustic_photons) = n;
        } else {
            double r;
            if ((st = read_numbers(p, key, 1, &r)) != PS_OK || (st = check_positive(p, key, r)) != PS_OK)
                return st;
            *(which ? &p->s->defaults.global_radius : &p->s->defaults.caustic_radius) = r;
        }
    }
    *seen = true;
    return PS_OK;
}

/* ---- the file -------------------------------------------------------------------- */

static ps_status parse_statement(parser *p)
{
    const char *kw = p->tok[p->pos++];
    if (!strcmp(kw, "camera"))
        return parse_camera(p);
    if (!strcmp(kw, "image"))
        return parse_image(p);
    if (!strcmp(kw, "material"))
        return parse_material(p);
    if (!strcmp(kw, "mesh"))
        return parse_mesh(p);
    if (!strcmp(kw, "sphere"))
        return parse_sphere(p);
    if (!strcmp(kw, "quad"))
        return parse_quad(p);
    if (!strcmp(kw, "light"))
        return parse_light(p);
    if (!strcmp(kw, "photons"))
        return parse_per_map(p, true);
    if (!strcmp(kw, "radius"))
        return parse_per_map(p, false);
    return ps_error_set(p->err, PS_ERR_PARSE,
                        "%s:%d: unknown statement '%s' (expected camera, image, material, mesh, sphere, quad, light, "
                        "photons or radius)",
                        p->name, p->line, kw);
}

static void apply_defaults(parser *p)
{
    ps_scene_defaults *d = &p->s->defaults;
    if (!p->has_image)
        d->width = d->height = DEFAULT_IMAGE_SIDE;
    /* Each value a statement leaves out keeps its default. */
    if (d->caustic_photons < 0)
        d->caustic_photons = DEFAULT_CAUSTIC_PHOTONS;
    if (d->global_photons < 0)
        d->global_photons = DEFAULT_GLOBAL_PHOTONS;
    double diag = ps_v3_len(ps_aabb_diag(p->s->bounds));
    if (!(diag > 0.0))
        diag = 1.0; /* a lone point light: no size to scale with */
    if (d->caustic_radius == 0.0)
        d->caustic_radius = DEFAULT_CAUSTIC_RADIUS_FRACTION * diag;
    if (d->global_radius == 0.0)
        d->global_radius = DEFAULT_GLOBAL_RADIUS_FRACTION * diag;
}

/* After a statement: what it made, in the source arrays ps_scene_write reads
 * (scene_internal.h), then its saved edits applied. */
static ps_status record_statement(parser *p, const char *kw, size_t materials, size_t objects, size_t lights)
{
    ps_scene *s = p->s;
    bool ok = true;
    if (!strcmp(kw, "material") && s->materials.count > materials) {
        ps_scene_stmt *st = PS_VEC_PUSH(s->stmts);
        if ((ok = st != NULL))
            *st = (ps_scene_stmt){PS_STMT_MATERIAL, (uint32_t)materials};
    }
    for (size_t o = objects; ok && o < s->objects.count; o++) {
        ps_scene_stmt *st = PS_VEC_PUSH(s->stmts);
        ps_object_source *src = st ? PS_VEC_PUSH(s->obj_src) : NULL;
        if ((ok = src != NULL)) {
            *st = (ps_scene_stmt){PS_STMT_OBJECT, (uint32_t)o};
            *src = p->pending_obj;
        }
    }
    for (size_t l = lights; ok && l < s->lights.count; l++) {
        bool own = !strcmp(kw, "light"); /* else a mesh's emissive faces */
        ps_scene_stmt *st = own ? PS_VEC_PUSH(s->stmts) : NULL;
        ps_light_source *src = !own || st ? PS_VEC_PUSH(s->light_src) : NULL;
        if ((ok = src != NULL)) {
            if (own)
                *st = (ps_scene_stmt){PS_STMT_LIGHT, (uint32_t)l};
            *src = own ? p->pending_light : (ps_light_source){PS_SOURCE_NONE, {0, 0, 0}};
        }
    }
    if (!ok)
        return ps_error_set(p->err, PS_ERR_NOMEM, "%s:%d: out of memory", p->name, p->line);
    for (size_t k = 0; k < p->pending_edits.count; k++) {
        const ps_scene_edit *e = &p->pending_edits.items[k];
        uint32_t object = (uint32_t)(s->objects.count - 1);
        ps_status st;
        if (e->light == PS_SOURCE_NONE) {
            st = ps_scene_translate_object(s, object, e->v, p->err);
        } else {
            size_t first = p->pending_obj.first_light, count = s->lights.count - lights;
            if (e->light >= count)
                return ps_error_set(p->err, PS_ERR_RANGE, "%s:%d: mesh: light-power %" PRIu32
                                    ": the mesh has %zu emissive light%s", p->name, p->line, e->light, count,
                                    count == 1 ? "" : "s");
            st = ps_scene_set_light_power(s, first + e->light, ps_rgb_make(e->v.x, e->v.y, e->v.z), p->err);
        }
        if (st != PS_OK)
            return st;
    }
    return PS_OK;
}

static ps_status parse_one_line(void *user, char *text)
{
    parser *p = user;
    ps_status st = tokenize(p, text);
    if (st != PS_OK || p->ntok == 0)
        return st;
    ps_scene *s = p->s;
    size_t materials = s->materials.count, objects = s->objects.count, lights = s->lights.count;
    memset(&p->pending_obj, 0, sizeof p->pending_obj);
    p->pending_obj.file = p->pending_obj.keys = p->pending_obj.first_light = PS_SOURCE_NONE;
    memset(&p->pending_light, 0, sizeof p->pending_light);
    p->pending_light.file = PS_SOURCE_NONE;
    p->pending_edits.count = 0;
    const char *kw = p->tok[0];
    st = parse_statement(p);
    return st == PS_OK ? record_statement(p, kw, materials, objects, lights) : st;
}

static ps_status parse_text(parser *p, const char *text, size_t len)
{
    (void)len; /* NUL-free (checked by the caller), so the text ends at its NUL */
    ps_status st = ps_text_lines(text, p->name, SCN_LINE_MAX - 1, parse_one_line, p, &p->line, p->err);
    if (st != PS_OK)
        return st;
    int last = p->line > 0 ? p->line : 1;
    if (!p->has_camera)
        return ps_error_set(p->err, PS_ERR_PARSE, "%s:%d: the scene has no camera statement", p->name, last);
    if (p->s->lights.count == 0)
        return ps_error_set(p->err, PS_ERR_PARSE,
                            "%s:%d: the scene has no light (add a light statement, or a mesh with Ke > 0 faces)",
                            p->name, last);
    /* Valid, but every photon escapes and every pixel is black: say why. */
    if (p->s->objects.count == 0)
        ps_warn(p->warn, "%s: scene has no geometry", p->name);
    ps_scene_finish(p->s);
    apply_defaults(p);
    return PS_OK;
}

/* Shared by both entry points; text has len bytes and a NUL after them. */
static ps_status load_text(const char *text, size_t len, const char *name, const char *base_dir,
                           const ps_scene_load_options *opts, ps_scene **out, ps_error *err)
{
    *out = NULL;
    ps_error local;
    if (!err)
        err = &local;
    ps_error_clear(err);
    parser p;
    memset(&p, 0, sizeof p);
    p.s = ps_scene_alloc();
    p.material_names = ps_namemap_create();
    size_t nlen = strlen(name);
    if (!p.s || !p.material_names || !(p.s->path = malloc(nlen + 1))) {
        ps_scene_destroy(p.s);
        ps_namemap_destroy(p.material_names);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", name);
    }
    memcpy(p.s->path, name, nlen + 1);
    static const ps_warn_sink to_stderr = {NULL, NULL};
    p.name = name;
    p.base_dir = base_dir ? base_dir : "";
    p.warn = opts ? &opts->warn : &to_stderr;
    p.err = err;
    p.default_material = -1;
    p.s->defaults.caustic_photons = p.s->defaults.global_photons = -1; /* unset */
    int bin = ps_text_nul_line(text, len);
    ps_status st = bin ? ps_error_set(err, PS_ERR_PARSE, "%s:%d: binary data (a NUL byte), not a scene file", name, bin)
                       : parse_text(&p, text, len);
    ps_namemap_destroy(p.material_names);
    free(p.pending_edits.items);
    if (st != PS_OK) {
        ps_scene_destroy(p.s);
        return st;
    }
    *out = p.s;
    return PS_OK;
}

ps_status ps_scene_load_text(const char *text, const char *name, const char *base_dir,
                             const ps_scene_load_options *opts, ps_scene **out, ps_error *err)
{
    return load_text(text, strlen(text), name, base_dir, opts, out, err);
}

ps_status ps_scene_load(const char *path, const ps_scene_load_options *opts, ps_scene **out, ps_error *err)
{
    *out = NULL;
    char *text = NULL;
    size_t len = 0;
    ps_status st = ps_read_file(path, SCN_MAX_BYTES, &text, &len, err);
    if (st != PS_OK)
        return st;
    char dir[4096];
    const char *slash = strrchr(path, '/');
    size_t dlen = slash ? (size_t)(slash - path) : 0;
    if (slash && dlen == 0)
        dlen = 1; /* "/scene.scn": the root */
    if (dlen >= sizeof dir)
        dlen = 0;
    memcpy(dir, path, dlen);
    dir[dlen] = '\0';
    st = load_text(text, len, path, dir, opts, out, err);
    free(text);
    return st;
}
