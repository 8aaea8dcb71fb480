/* scene.c: scene storage, accessors, derived quantities, edits and copies. */
#include "scene/scene_internal.h"

#include <math.h>

#include "core/photometry.h"
#include "scene/ies.h"

#include <inttypes.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

ps_scene *ps_scene_alloc(void)
{
    ps_scene *s = calloc(1, sizeof *s);
    if (s)
        s->bounds = ps_aabb_empty();
    return s;
}

void ps_scene_destroy(ps_scene *s)
{
    if (!s)
        return;
    free(s->path);
    free(s->materials.items);
    free(s->positions.items);
    free(s->normals.items);
    free(s->triangles.items);
    free(s->objects.items);
    free(s->lights.items);
    free(s->emitters.items);
    for (size_t k = 0; k < s->profiles.count; k++)
        ps_ies_destroy(s->profiles.items[k]);
    free(s->profiles.items);
    free(s->stmts.items);
    free(s->obj_src.items);
    free(s->light_src.items);
    free(s->edits.items);
    free(s->strings.items);
    free(s);
}

uint32_t ps_scene_add_string(ps_scene *s, const char *text)
{
    size_t len = strlen(text) + 1, at = s->strings.count;
    if (at + len >= PS_SOURCE_NONE || !PS_RESERVE(s->strings.items, s->strings.cap, at + len))
        return PS_SOURCE_NONE;
    memcpy(s->strings.items + at, text, len);
    s->strings.count += len;
    return (uint32_t)at;
}

/* Records an edit for ps_scene_write (scene_internal.h): room first, so that
 * an edit refused for memory changes nothing. */
static bool reserve_edit(ps_scene *s) { return PS_RESERVE(s->edits.items, s->edits.cap, s->edits.count + 1); }
static void record_edit(ps_scene *s, uint32_t object, uint32_t light, ps_vec3 v)
{
    s->edits.items[s->edits.count++] = (ps_scene_edit){object, light, v};
}

const char *ps_scene_path(const ps_scene *s) { return s->path; }
const ps_camera *ps_scene_camera(const ps_scene *s) { return &s->camera; }
const ps_scene_defaults *ps_scene_get_defaults(const ps_scene *s) { return &s->defaults; }
ps_aabb ps_scene_bounds(const ps_scene *s) { return s->bounds; }

#define VIEW(field)                                                                                       \
    do {                                                                                                  \
        if (count)                                                                                        \
            *count = s->field.count;                                                                      \
        return s->field.items;                                                                            \
    } while (0)

const ps_material *ps_scene_materials(const ps_scene *s, size_t *count) { VIEW(materials); }
const ps_vec3 *ps_scene_positions(const ps_scene *s, size_t *count) { VIEW(positions); }
const ps_vec3 *ps_scene_normals(const ps_scene *s, size_t *count) { VIEW(normals); }
const ps_triangle *ps_scene_triangles(const ps_scene *s, size_t *count) { VIEW(triangles); }
const ps_object *ps_scene_objects(const ps_scene *s, size_t *count) { VIEW(objects); }
const ps_light *ps_scene_lights(const ps_scene *s, size_t *count) { VIEW(lights); }
const uint32_t *ps_scene_emitters(const ps_scene *s, size_t *count) { VIEW(emitters); }

static ps_vec3 tri_cross(const ps_scene *s, uint32_t t)
{
    const ps_triangle *tr = &s->triangles.items[t];
    ps_vec3 p0 = s->positions.items[tr->v[0]];
    return ps_v3_cross(ps_v3_sub(s->positions.items[tr->v[1]], p0), ps_v3_sub(s->positions.items[tr->v[2]], p0));
}

double ps_scene_triangle_area(const ps_scene *s, uint32_t t) { return 0.5 * ps_v3_len(tri_cross(s, t)); }
ps_vec3 ps_scene_triangle_normal(const ps_scene *s, uint32_t t) { return ps_v3_norm(tri_cross(s, t)); }

ps_rgb ps_scene_total_power(const ps_scene *s)
{
    ps_rgb sum = ps_rgb_gray(0.0);
    for (size_t i = 0; i < s->lights.count; i++)
        sum = ps_rgb_add(sum, s->lights.items[i].power);
    return sum;
}

double ps_scene_total_lumens(const ps_scene *s) { return ps_photometric(ps_scene_total_power(s)); }

const ps_ies *ps_scene_ies_profile(const ps_scene *s, uint32_t profile) { return s->profiles.items[profile]; }
size_t ps_scene_ies_profile_count(const ps_scene *s) { return s->profiles.count; }

ps_vec3 ps_light_ies_direction(const ps_light *l, double theta, double phi)
{
    double st = sin(theta);
    ps_vec3 side = ps_v3_add(ps_v3_scale(l->axis0, cos(phi)), ps_v3_scale(l->axis90, sin(phi)));
    return ps_v3_add(ps_v3_scale(l->direction, cos(theta)), ps_v3_scale(side, st));
}

void ps_light_ies_angles(const ps_light *l, ps_vec3 d, double *theta, double *phi)
{
    double z = ps_v3_dot(d, l->direction), x = ps_v3_dot(d, l->axis0), y = ps_v3_dot(d, l->axis90);
    *theta = atan2(sqrt(x * x + y * y), z);
    *phi = atan2(y, x);
}

double ps_light_ies_density(const ps_scene *s, const ps_light *l, ps_vec3 d)
{
    const ps_ies *ies = s->profiles.items[l->profile];
    double theta, phi;
    ps_light_ies_angles(l, d, &theta, &phi);
    return ps_ies_candela(ies, theta, phi) / ps_ies_flux(ies);
}

static ps_aabb light_bounds(const ps_light *l)
{
    ps_aabb b = ps_aabb_point(ps_aabb_empty(), l->position);
    switch (l->type) {
    case PS_LIGHT_QUAD:
        b = ps_aabb_point(b, ps_v3_add(l->position, l->edge1));
        b = ps_aabb_point(b, ps_v3_add(l->position, l->edge2));
        b = ps_aabb_point(b, ps_v3_add(ps_v3_add(l->position, l->edge1), l->edge2));
        break;
    case PS_LIGHT_SPHERE:
    case PS_LIGHT_DISC: {
        ps_vec3 r = ps_v3(l->radius, l->radius, l->radius);
        b.lo = ps_v3_sub(l->position, r);
        b.hi = ps_v3_add(l->position, r);
        break;
    }
    default:
        break; /* point, spot: the position; mesh: covered by its object */
    }
    return b;
}

void ps_scene_update_object(ps_scene *s, uint32_t index)
{
    ps_object *obj = &s->objects.items[index];
    if (obj->type == PS_OBJ_SPHERE) {
        ps_vec3 r = ps_v3(obj->radius, obj->radius, obj->radius);
        obj->bounds.lo = ps_v3_sub(obj->center, r);
        obj->bounds.hi = ps_v3_add(obj->center, r);
        obj->specular = ps_material_is_specular(&s->materials.items[obj->material]);
        return;
    }
    obj->bounds = ps_aabb_empty();
    obj->specular = 0;
    for (uint32_t t = obj->first_triangle; t < obj->first_triangle + obj->triangle_count; t++) {
        const ps_triangle *tr = &s->triangles.items[t];
        for (int c = 0; c < 3; c++)
            obj->bounds = ps_aabb_point(obj->bounds, s->positions.items[tr->v[c]]);
        obj->specular |= ps_material_is_specular(&s->materials.items[tr->material]);
    }
}

/* The scene's box from the objects' (current) bounds and the lights. */
static ps_aabb scene_bounds(const ps_scene *s)
{
    ps_aabb all = ps_aabb_empty();
    for (size_t o = 0; o < s->objects.count; o++)
        all = ps_aabb_union(all, s->objects.items[o].bounds);
    for (size_t i = 0; i < s->lights.count; i++)
        all = ps_aabb_union(all, light_bounds(&s->lights.items[i]));
    return all;
}

void ps_scene_finish(ps_scene *s)
{
    for (size_t o = 0; o < s->objects.count; o++)
        ps_scene_update_object(s, (uint32_t)o);
    s->bounds = scene_bounds(s);
}

/* ---- editing ----------------------------------------------------------------------
 *
 * Every edit checks all it will write before writing anything, so that a
 * refused edit leaves the scene as it was, byte for byte; nothing is undone
 * (x + d - d need not be x). */

/* "file:line: light 3" + the rest (which brings its own ": " or " is ..."). */
static ps_status refuse(ps_error *err, const ps_scene *s, const char *what, size_t index, int line,
                        const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;

static ps_status refuse(ps_error *err, const ps_scene *s, const char *what, size_t index, int line,
                        const char *fmt, ...)
{
    char rest[PS_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(rest, sizeof rest, fmt, ap);
    va_end(ap);
    return ps_error_set(err, PS_ERR_RANGE, "%s:%d: %s %zu%s", s->path, line, what, index, rest);
}

static bool index_exists(const ps_scene *s, const char *what, size_t index, size_t count, ps_error *err)
{
    if (index < count)
        return true;
    ps_error_set(err, PS_ERR_RANGE, "%s: %s %zu does not exist (the scene has %zu %s%s)", s->path, what, index, count,
                 what, count == 1 ? "" : "s");
    return false;
}

static bool aabb_isfinite(ps_aabb b) { return ps_v3_isfinite(b.lo) && ps_v3_isfinite(b.hi); }

/* Area of triangle t with its corners moved by d, computed as
 * ps_scene_triangle_area computes it once they are stored there. */
static double moved_area(const ps_scene *s, uint32_t t, ps_vec3 d)
{
    const ps_triangle *tr = &s->triangles.items[t];
    ps_vec3 p0 = ps_v3_add(s->positions.items[tr->v[0]], d);
    ps_vec3 p1 = ps_v3_add(s->positions.items[tr->v[1]], d);
    ps_vec3 p2 = ps_v3_add(s->positions.items[tr->v[2]], d);
    return 0.5 * ps_v3_len(ps_v3_cross(ps_v3_sub(p1, p0), ps_v3_sub(p2, p0)));
}

/* An emissive mesh's area with its faces moved by d, summed in the loader's
 * order; 0 when a face would collapse (the loader keeps only faces of positive
 * area as emitters, and samples them by area). */
static double moved_mesh_light_area(const ps_scene *s, const ps_light *l, ps_vec3 d)
{
    double area = 0.0;
    for (uint32_t e = l->first_emitter; e < l->first_emitter + l->emitter_count; e++) {
        double a = moved_area(s, s->emitters.items[e], d);
        if (!(a > 0.0))
            return 0.0;
        area += a;
    }
    return area;
}

ps_status ps_scene_set_light_position(ps_scene *s, size_t light, ps_vec3 position, ps_error *err)
{
    if (!index_exists(s, "light", light, s->lights.count, err))
        return PS_ERR_RANGE;
    ps_light *l = &s->lights.items[light];
    if (l->type == PS_LIGHT_MESH)
        return refuse(err, s, "light", light, l->line, " is an emissive mesh: move its object (object %" PRIu32 ")",
                      l->object);
    if (!ps_v3_isfinite(position))
        return refuse(err, s, "light", light, l->line, ": position (%g %g %g) is not finite", position.x, position.y,
                      position.z);
    ps_light moved = *l;
    moved.position = position;
    if (!aabb_isfinite(light_bounds(&moved)))
        return refuse(err, s, "light", light, l->line, ": position (%g %g %g) takes the light out of range",
                      position.x, position.y, position.z);
    l->position = position;
    s->bounds = scene_bounds(s);
    ps_error_clear(err);
    return PS_OK;
}

ps_status ps_scene_set_light_power(ps_scene *s, size_t light, ps_rgb power, ps_error *err)
{
    if (!index_exists(s, "light", light, s->lights.count, err))
        return PS_ERR_RANGE;
    ps_light *l = &s->lights.items[light];
    if (!ps_rgb_isfinite(power))
        return refuse(err, s, "light", light, l->line, ": power (%g %g %g) is not finite", power.r, power.g, power.b);
    if (power.r < 0 || power.g < 0 || power.b < 0)
        return refuse(err, s, "light", light, l->line, ": power (%g %g %g) must not be negative", power.r, power.g,
                      power.b);
    ps_rgb radiance = l->radiance;
    if (l->area > 0.0) {
        /* As the loader: a Lambertian emitter's flux is pi * L * area. */
        radiance = ps_rgb_scale(power, 1.0 / (PS_PI * l->area));
        if (!ps_rgb_isfinite(radiance))
            return refuse(err, s, "light", light, l->line,
                          ": power (%g %g %g) is too large for its area %g (the radiance would not be finite)",
                          power.r, power.g, power.b, l->area);
    }
    if (ps_rgb_max(power) > PS_SCENE_MAX_LIGHT_POWER)
        return refuse(err, s, "light", light, l->line, ": power (%g %g %g) is above the %g W a light may have",
                      power.r, power.g, power.b, PS_SCENE_MAX_LIGHT_POWER);
    if (l->type == PS_LIGHT_MESH && !reserve_edit(s))
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", s->path);
    if (l->type == PS_LIGHT_MESH) {
        record_edit(s, l->object, (uint32_t)light, ps_v3(power.r, power.g, power.b));
        /* The faces are drawn and seen with their material's emission; that
         * MTL material was made for this mesh statement and emits only here. */
        uint32_t m = s->triangles.items[s->emitters.items[l->first_emitter]].material;
        s->materials.items[m].emission = radiance;
    }
    l->power = power;
    l->radiance = radiance;
    ps_error_clear(err);
    return PS_OK;
}

ps_status ps_scene_set_spot_angle(ps_scene *s, size_t light, double degrees, ps_error *err)
{
    if (!index_exists(s, "light", light, s->lights.count, err))
        return PS_ERR_RANGE;
    ps_light *l = &s->lights.items[light];
    if (l->type != PS_LIGHT_SPOT)
        return refuse(err, s, "light", light, l->line, " is a %s light, not a spot: only spots have an angle",
                      ps_light_type_name(l->type));
    if (!(degrees > 0.0 && degrees <= 90.0))
        return refuse(err, s, "light", light, l->line, ": angle %g is not in (0, 90]", degrees);
    l->angle_deg = degrees;
    l->cos_angle = cos(degrees * (PS_PI / 180.0));
    ps_error_clear(err);
    return PS_OK;
}

ps_status ps_scene_translate_object(ps_scene *s, size_t object, ps_vec3 delta, ps_error *err)
{
    if (!index_exists(s, "object", object, s->objects.count, err))
        return PS_ERR_RANGE;
    ps_object *o = &s->objects.items[object];
    if (!ps_v3_isfinite(delta))
        return refuse(err, s, "object", object, o->line, ": delta (%g %g %g) is not finite", delta.x, delta.y,
                      delta.z);

    /* Check the object at its new place: every coordinate finite, quads not
     * collapsed by rounding. Its vertices are one run [vlo, vhi] of positions
     * (scene.h), unreferenced OBJ vertices inside it included. */
    size_t vlo = SIZE_MAX, vhi = 0;
    ps_vec3 center = ps_v3_add(o->center, delta);
    ps_aabb moved = ps_aabb_empty();
    if (o->type == PS_OBJ_SPHERE) {
        ps_vec3 r = ps_v3(o->radius, o->radius, o->radius);
        moved.lo = ps_v3_sub(center, r);
        moved.hi = ps_v3_add(center, r);
    } else {
        for (uint32_t t = o->first_triangle; t < o->first_triangle + o->triangle_count; t++) {
            const ps_triangle *tr = &s->triangles.items[t];
            for (int c = 0; c < 3; c++) {
                vlo = tr->v[c] < vlo ? tr->v[c] : vlo;
                vhi = tr->v[c] > vhi ? tr->v[c] : vhi;
                moved = ps_aabb_point(moved, ps_v3_add(s->positions.items[tr->v[c]], delta));
            }
        }
        for (size_t v = vlo; v <= vhi && vlo != SIZE_MAX; v++)
            if (!ps_v3_isfinite(ps_v3_add(s->positions.items[v], delta)))
                return refuse(err, s, "object", object, o->line, ": moving by (%g %g %g) takes a vertex out of range",
                              delta.x, delta.y, delta.z);
        if (o->type == PS_OBJ_QUAD)
            for (uint32_t t = o->first_triangle; t < o->first_triangle + o->triangle_count; t++)
                if (!(moved_area(s, t, delta) > 0.0))
                    return refuse(err, s, "object", object, o->line,
                                  ": moving by (%g %g %g) would collapse it (coordinates too large for its size)",
                                  delta.x, delta.y, delta.z);
    }
    if (!ps_v3_isfinite(center) || !aabb_isfinite(moved))
        return refuse(err, s, "object", object, o->line, ": moving by (%g %g %g) takes it out of range", delta.x,
                      delta.y, delta.z);
    /* Its emissive mesh lights: faces still of positive area, their reference
     * point (the centre of the object's box, as loaded) and power finite. */
    for (size_t i = 0; i < s->lights.count; i++) {
        const ps_light *l = &s->lights.items[i];
        if (l->type != PS_LIGHT_MESH || l->object != object)
            continue;
        double area = moved_mesh_light_area(s, l, delta);
        if (!(area > 0.0))
            return refuse(err, s, "object", object, o->line,
                          ": moving by (%g %g %g) would collapse the emitting faces of light %zu (coordinates too "
                          "large for their size)",
                          delta.x, delta.y, delta.z, i);
        if (!ps_v3_isfinite(ps_aabb_center(moved)) || !ps_rgb_isfinite(ps_rgb_scale(l->radiance, PS_PI * area)))
            return refuse(err, s, "object", object, o->line, ": moving by (%g %g %g) takes light %zu out of range",
                          delta.x, delta.y, delta.z, i);
    }

    /* A sphere is written at its centre; meshes and quads replay their moves. */
    if (o->type != PS_OBJ_SPHERE && !reserve_edit(s))
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", s->path);
    /* Move it: the same sums as the checks, so the same results. */
    if (o->type == PS_OBJ_SPHERE)
        o->center = center;
    else
        record_edit(s, (uint32_t)object, PS_SOURCE_NONE, delta);
    for (size_t v = vlo; v <= vhi && vlo != SIZE_MAX; v++)
        s->positions.items[v] = ps_v3_add(s->positions.items[v], delta);
    ps_scene_update_object(s, (uint32_t)object);
    for (size_t i = 0; i < s->lights.count; i++) {
        ps_light *l = &s->lights.items[i];
        if (l->type != PS_LIGHT_MESH || l->object != object)
            continue;
        l->area = moved_mesh_light_area(s, l, ps_v3(0, 0, 0));
        l->power = ps_rgb_scale(l->radiance, PS_PI * l->area);
        l->position = ps_aabb_center(o->bounds);
    }
    s->bounds = scene_bounds(s);
    ps_error_clear(err);
    return PS_OK;
}

/* ---- copies ----------------------------------------------------------------------- */

/* A copy of count items of elem bytes; NULL for none, or when *ok is or turns false. */
static void *dup_items(const void *src, size_t count, size_t elem, bool *ok)
{
    if (!*ok || count == 0)
        return NULL;
    void *p = count <= SIZE_MAX / elem ? malloc(count * elem) : NULL;
    if (!p) {
        *ok = false;
        return NULL;
    }
    return memcpy(p, src, count * elem);
}

ps_status ps_scene_clone(const ps_scene *s, ps_scene **out, ps_error *err)
{
    *out = NULL;
    ps_scene *c = malloc(sizeof *c);
    if (!c)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", s->path);
    *c = *s; /* camera, defaults, bounds and the counts; every pointer replaced below */
    bool ok = true;
    c->path = dup_items(s->path, s->path ? strlen(s->path) + 1 : 0, 1, &ok);
#define DUP_VEC(f) (c->f.items = dup_items(s->f.items, s->f.count, sizeof *s->f.items, &ok), c->f.cap = s->f.count)
    DUP_VEC(materials);
    DUP_VEC(positions);
    DUP_VEC(normals);
    DUP_VEC(triangles);
    DUP_VEC(objects);
    DUP_VEC(lights);
    DUP_VEC(emitters);
    DUP_VEC(profiles);
    DUP_VEC(stmts);
    DUP_VEC(obj_src);
    DUP_VEC(light_src);
    DUP_VEC(edits);
    DUP_VEC(strings);
#undef DUP_VEC
    /* The tables themselves, so that a clone shares nothing with s; until
     * each is copied its slot is NULL (destroy frees only copies). */
    if (!c->profiles.items)
        c->profiles.count = 0;
    for (size_t k = 0; k < c->profiles.count; k++)
        c->profiles.items[k] = NULL;
    for (size_t k = 0; k < c->profiles.count && ok; k++) {
        ps_error ignored;
        ok = ps_ies_clone(s->profiles.items[k], &c->profiles.items[k], &ignored) == PS_OK;
    }
    if (!ok) {
        ps_scene_destroy(c); /* what was not copied is NULL */
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", s->path);
    }
    *out = c;
    ps_error_clear(err);
    return PS_OK;
}

const char *ps_material_type_name(ps_material_type t)
{
    switch (t) {
    case PS_MAT_DIFFUSE: return "diffuse";
    case PS_MAT_GLOSSY: return "glossy";
    case PS_MAT_MIRROR: return "mirror";
    case PS_MAT_DIELECTRIC: return "dielectric";
    }
    return "?";
}

const char *ps_light_type_name(ps_light_type t)
{
    switch (t) {
    case PS_LIGHT_POINT: return "point";
    case PS_LIGHT_SPOT: return "spot";
    case PS_LIGHT_QUAD: return "quad";
    case PS_LIGHT_SPHERE: return "sphere";
    case PS_LIGHT_DISC: return "disc";
    case PS_LIGHT_MESH: return "mesh";
    case PS_LIGHT_IES: return "ies";
    }
    return "?";
}
