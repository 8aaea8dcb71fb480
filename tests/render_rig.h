/* render_rig.h: a scene with its photon maps, kd-trees and the reference
 * renderer's options, made together for the tests that render images
 * (test_render, test_illuminance). Any failure fails the test with the
 * message. Include after test.h. */
#ifndef PS_TESTS_RENDER_RIG_H
#define PS_TESTS_RENDER_RIG_H

#include <string.h>

#include "photon/emit.h"
#include "photon/estimate.h"
#include "photon/kdtree.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "render/render.h"
#include "scene/scene.h"

typedef struct render_rig {
    ps_scene *scene;
    ps_world *world;
    ps_tracer *tracer, *full_tracer;
    ps_light_sampler *ls;
    ps_photon_map maps[PS_MAP_COUNT], full;
    ps_kdtree *trees[PS_MAP_COUNT], *full_tree, *irr;
} render_rig;

/* Scene, both maps (and the full map with its irradiance when gathering). */
static inline render_rig render_rig_make(const char *text, uint64_t caustic, uint64_t global, const ps_estimate_options *est, bool gather)
{
    render_rig r;
    memset(&r, 0, sizeof r);
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &r.scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    assert_int_equal(ps_world_create(r.scene, NULL, &r.world, &err), PS_OK);
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 3;
    assert_int_equal(ps_tracer_create(r.world, &o, &r.tracer, &err), PS_OK);
    assert_int_equal(ps_light_sampler_create(r.scene, &r.ls, &err), PS_OK);
    uint64_t n[PS_MAP_COUNT] = {caustic, global};
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map_init(&r.maps[k], (ps_map_kind)k);
        assert_int_equal(ps_tracer_trace(r.tracer, (ps_map_kind)k, 0, n[k], n[k], &r.maps[k], &err), PS_OK);
        assert_int_equal(ps_kdtree_build(r.maps[k].photons, r.maps[k].count, &r.trees[k], &err), PS_OK);
    }
    ps_photon_map_init(&r.full, PS_MAP_GLOBAL);
    if (gather) {
        o.global_direct = true;
        assert_int_equal(ps_tracer_create(r.world, &o, &r.full_tracer, &err), PS_OK);
        assert_int_equal(ps_tracer_trace(r.full_tracer, PS_MAP_GLOBAL, 0, global, global, &r.full, &err), PS_OK);
        assert_int_equal(ps_kdtree_build(r.full.photons, r.full.count, &r.full_tree, &err), PS_OK);
        assert_int_equal(ps_irradiance_precompute(r.full_tree, est, 4, 2, NULL, &r.irr, &err), PS_OK);
    }
    return r;
}

static inline void render_rig_free(render_rig *r)
{
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map_free(&r->maps[k]);
        ps_kdtree_destroy(r->trees[k]);
    }
    ps_photon_map_free(&r->full);
    ps_kdtree_destroy(r->full_tree);
    ps_kdtree_destroy(r->irr);
    ps_light_sampler_destroy(r->ls);
    ps_tracer_destroy(r->full_tracer);
    ps_tracer_destroy(r->tracer);
    ps_world_destroy(r->world);
    ps_scene_destroy(r->scene);
}

static inline ps_render_options options(int w, int h, int spp, ps_component c, const ps_estimate_options *est, int gather)
{
    ps_render_options o;
    memset(&o, 0, sizeof o);
    o.width = w;
    o.height = h;
    o.spp = spp;
    o.light_samples = 1;
    o.gather = gather;
    o.seed = 5;
    o.threads = 2;
    o.component = c;
    o.caustic = o.global = *est;
    o.irradiance_radius = est->max_radius;
    return o;
}

static inline ps_image render(render_rig *r, const ps_render_options *o)
{
    ps_render_maps maps = {r->trees[PS_MAP_CAUSTIC], r->trees[PS_MAP_GLOBAL], r->full_tree, r->irr};
    ps_image img;
    ps_error err;
    ps_render_stats st;
    if (ps_render(r->world, r->ls, &maps, o, &img, &st, &err) != PS_OK)
        fail_msg("render: %s", err.msg);
    assert_true(st.rays > 0);
    return img;
}

#endif
