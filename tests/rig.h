/* rig.h: a scene, its world and a tracer, made together for the tests that
 * trace photons (test_tracer, test_stress, test_feed). Any failure fails the
 * test with the message. Include after test.h. */
#ifndef PS_TESTS_RIG_H
#define PS_TESTS_RIG_H

#include <string.h>

#include "photon/tracer.h"
#include "photon/world.h"
#include "scene/scene.h"

typedef struct rig {
    ps_scene *scene;
    ps_world *world;
    ps_tracer *tracer;
} rig;

/* The world and tracer of a loaded scene (which the rig then owns). */
static inline rig rig_of_scene(ps_scene *scene, const ps_accel_options *aopt, const ps_tracer_options *opt)
{
    rig r;
    memset(&r, 0, sizeof r);
    r.scene = scene;
    ps_error err;
    if (ps_world_create(r.scene, aopt, &r.world, &err) != PS_OK)
        fail_msg("world: %s", err.msg);
    if (ps_tracer_create(r.world, opt, &r.tracer, &err) != PS_OK)
        fail_msg("tracer: %s", err.msg);
    return r;
}

/* A scene's text (meshes found under base_dir), with the given accelerator. */
static inline rig rig_make(const char *text, const char *base_dir, const ps_tracer_options *opt, ps_accel_kind kind)
{
    ps_scene *scene;
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", base_dir, NULL, &scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_accel_options aopt = {0};
    aopt.kind = kind;
    return rig_of_scene(scene, &aopt, opt);
}

static inline void rig_free(rig *r)
{
    ps_tracer_destroy(r->tracer);
    ps_world_destroy(r->world);
    ps_scene_destroy(r->scene);
}

/* Photons 0..n-1 of one map, traced as one batch. */
static inline ps_photon_map rig_trace(rig *r, ps_map_kind kind, uint64_t n)
{
    ps_photon_map m;
    ps_photon_map_init(&m, kind);
    ps_error err;
    if (ps_tracer_trace(r->tracer, kind, 0, n, n, &m, &err) != PS_OK)
        fail_msg("trace: %s", err.msg);
    return m;
}

#endif
