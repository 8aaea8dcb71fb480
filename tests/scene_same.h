/* scene_same.h: two scenes compared bit for bit, every field of every array
 * (test_scene_edit: an edited scene against the scene written at the edit's
 * result; test_scene_write: a saved and reloaded scene against the one
 * saved). Include after test.h. */
#ifndef PS_TESTS_SCENE_SAME_H
#define PS_TESTS_SCENE_SAME_H

#include <string.h>

#include "scene/ies.h"
#include "scene/scene.h"

/* Bit for bit: -0 differs from 0, and a NaN fails. */
static inline void assert_same_double(double a, double b)
{
    if (memcmp(&a, &b, sizeof a) != 0)
        fail_msg("%.17g differs from %.17g", a, b);
}
static inline void assert_same_vec(ps_vec3 a, ps_vec3 b)
{
    assert_same_double(a.x, b.x);
    assert_same_double(a.y, b.y);
    assert_same_double(a.z, b.z);
}
static inline void assert_same_rgb(ps_rgb a, ps_rgb b)
{
    assert_same_double(a.r, b.r);
    assert_same_double(a.g, b.g);
    assert_same_double(a.b, b.b);
}
static inline void assert_same_box(ps_aabb a, ps_aabb b)
{
    assert_same_vec(a.lo, b.lo);
    assert_same_vec(a.hi, b.hi);
}

static inline void assert_same_material(const ps_material *a, const ps_material *b)
{
    assert_string_equal(a->name, b->name);
    assert_int_equal(a->type, b->type);
    assert_same_rgb(a->albedo, b->albedo);
    assert_same_rgb(a->specular, b->specular);
    assert_same_double(a->exponent, b->exponent);
    assert_same_rgb(a->reflectance, b->reflectance);
    assert_same_double(a->ior, b->ior);
    assert_same_rgb(a->transmittance, b->transmittance);
    assert_same_rgb(a->emission, b->emission);
}

/* lines: the statements' lines too (not for a scene written anew). */
static inline void assert_same_light(const ps_light *a, const ps_light *b, bool lines)
{
    assert_int_equal(a->type, b->type);
    if (lines)
        assert_int_equal(a->line, b->line);
    assert_same_rgb(a->power, b->power);
    assert_same_vec(a->position, b->position);
    assert_same_vec(a->direction, b->direction);
    assert_same_vec(a->edge1, b->edge1);
    assert_same_vec(a->edge2, b->edge2);
    assert_same_double(a->radius, b->radius);
    assert_same_double(a->angle_deg, b->angle_deg);
    assert_same_double(a->cos_angle, b->cos_angle);
    assert_same_double(a->area, b->area);
    assert_same_rgb(a->radiance, b->radiance);
    assert_int_equal(a->first_emitter, b->first_emitter);
    assert_int_equal(a->emitter_count, b->emitter_count);
    assert_int_equal(a->object, b->object);
    assert_int_equal(a->profile, b->profile);
    assert_same_double(a->spin_deg, b->spin_deg);
    assert_same_vec(a->axis0, b->axis0);
    assert_same_vec(a->axis90, b->axis90);
}

static inline void assert_same_object(const ps_object *a, const ps_object *b, bool lines)
{
    assert_int_equal(a->type, b->type);
    if (lines)
        assert_int_equal(a->line, b->line);
    assert_int_equal(a->first_triangle, b->first_triangle);
    assert_int_equal(a->triangle_count, b->triangle_count);
    assert_int_equal(a->material, b->material);
    assert_same_vec(a->center, b->center);
    assert_same_double(a->radius, b->radius);
    assert_same_box(a->bounds, b->bounds);
    assert_int_equal(a->specular, b->specular);
}

/* Every field of every array, the camera, the defaults, the bounds and the
 * total power. */
/* What else to compare: the statements' lines (not for a scene written
 * anew), the camera and the defaults (not for an edited scene against one
 * loaded at the edit's result, whose default radii follow its own bounds). */
enum { SCENE_SAME_LINES = 1, SCENE_SAME_SETTINGS = 2 };
static inline void assert_same_scene(const ps_scene *a, const ps_scene *b, unsigned what)
{
    bool lines = (what & SCENE_SAME_LINES) != 0;
    if (what & SCENE_SAME_SETTINGS) {
        const ps_camera *ca = ps_scene_camera(a), *cb = ps_scene_camera(b);
        assert_same_vec(ca->eye, cb->eye);
        assert_same_vec(ca->target, cb->target);
        assert_same_vec(ca->up, cb->up);
        assert_same_double(ca->fov_deg, cb->fov_deg);
        const ps_scene_defaults *da = ps_scene_get_defaults(a), *db = ps_scene_get_defaults(b);
        assert_int_equal(da->width, db->width);
        assert_int_equal(da->height, db->height);
        assert_int_equal(da->caustic_photons, db->caustic_photons);
        assert_int_equal(da->global_photons, db->global_photons);
        assert_same_double(da->caustic_radius, db->caustic_radius);
        assert_same_double(da->global_radius, db->global_radius);
    }
    size_t na, nb;
    const ps_material *ma = ps_scene_materials(a, &na), *mb = ps_scene_materials(b, &nb);
    assert_int_equal(na, nb);
    for (size_t i = 0; i < na; i++)
        assert_same_material(&ma[i], &mb[i]);
    const ps_light *la = ps_scene_lights(a, &na), *lb = ps_scene_lights(b, &nb);
    assert_int_equal(na, nb);
    for (size_t i = 0; i < na; i++)
        assert_same_light(&la[i], &lb[i], lines);
    const ps_object *oa = ps_scene_objects(a, &na), *ob = ps_scene_objects(b, &nb);
    assert_int_equal(na, nb);
    for (size_t i = 0; i < na; i++)
        assert_same_object(&oa[i], &ob[i], lines);
    const ps_vec3 *pa = ps_scene_positions(a, &na), *pb = ps_scene_positions(b, &nb);
    assert_int_equal(na, nb);
    assert_memory_equal(pa, pb, na * sizeof *pa);
    const ps_vec3 *qa = ps_scene_normals(a, &na), *qb = ps_scene_normals(b, &nb);
    assert_int_equal(na, nb);
    if (na)
        assert_memory_equal(qa, qb, na * sizeof *qa);
    const ps_triangle *ta = ps_scene_triangles(a, &na), *tb = ps_scene_triangles(b, &nb);
    assert_int_equal(na, nb);
    assert_memory_equal(ta, tb, na * sizeof *ta);
    const uint32_t *ea = ps_scene_emitters(a, &na), *eb = ps_scene_emitters(b, &nb);
    assert_int_equal(na, nb);
    if (na)
        assert_memory_equal(ea, eb, na * sizeof *ea);
    assert_int_equal(ps_scene_ies_profile_count(a), ps_scene_ies_profile_count(b));
    for (size_t k = 0; k < ps_scene_ies_profile_count(a); k++)
        assert_same_double(ps_ies_flux(ps_scene_ies_profile(a, (uint32_t)k)),
                           ps_ies_flux(ps_scene_ies_profile(b, (uint32_t)k)));
    assert_same_box(ps_scene_bounds(a), ps_scene_bounds(b));
    assert_same_rgb(ps_scene_total_power(a), ps_scene_total_power(b));
}

#endif
