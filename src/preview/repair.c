/* repair.c: which photons an edit keeps (repair.h). */
#include "preview/repair.h"

#include <stdlib.h>
#include <string.h>

ps_status ps_repair_state_take(const ps_scene *scene, double epsilon, ps_repair_state *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    size_t nl, no;
    const ps_light *L = ps_scene_lights(scene, &nl);
    const ps_object *O = ps_scene_objects(scene, &no);
    out->lights = malloc((nl ? nl : 1) * sizeof *out->lights);
    out->bounds = malloc((no ? no : 1) * sizeof *out->bounds);
    if (!out->lights || !out->bounds) {
        ps_repair_state_free(out);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the repair's copy of the scene",
                            ps_scene_path(scene));
    }
    if (nl)
        memcpy(out->lights, L, nl * sizeof *L);
    for (size_t o = 0; o < no; o++)
        out->bounds[o] = O[o].bounds;
    out->light_count = nl;
    out->object_count = no;
    out->epsilon = epsilon;
    return PS_OK;
}

void ps_repair_state_free(ps_repair_state *st)
{
    free(st->lights);
    free(st->bounds);
    memset(st, 0, sizeof *st);
}

ps_aabb ps_repair_record_box(const ps_scene *scene)
{
    ps_aabb b = ps_scene_bounds(scene);
    ps_vec3 e = ps_v3_sub(b.hi, b.lo);
    double m = e.x > e.y ? e.x : e.y;
    m = m > e.z ? m : e.z;
    if (!(m > 0.0))
        m = 1.0;
    ps_vec3 w = ps_v3(m, m, m);
    ps_aabb r = {ps_v3_sub(b.lo, w), ps_v3_add(b.hi, w)};
    return r;
}

typedef struct keep_ctx {
    ps_tracer *old_tracer, *new_tracer;
    uint64_t cap[PS_MAP_COUNT];
    bool *resampled; /* lights whose emission changed other than by power */
    size_t light_count;
    ps_aabb *moved; /* old and new box of each moved object */
    size_t moved_count;
    ps_path_quant quant;
} keep_ctx;

static ps_status sources(void *arg, ps_map_kind k, uint64_t end, ps_source_map **out, ps_error *err)
{
    keep_ctx *c = arg;
    return ps_source_map_create(c->old_tracer, c->new_tracer, k, c->cap[k], end, c->resampled, c->light_count, out,
                                err);
}

/* Whether light a emits as b does but for its power: the same kind, place,
 * aim, shape and table (its power and the radiance that follows from it may
 * differ). */
static bool same_emission(const ps_light *a, const ps_light *b)
{
    ps_light x = *a, y = *b;
    x.power = y.power = (ps_rgb){0.0, 0.0, 0.0};
    x.radiance = y.radiance = (ps_rgb){0.0, 0.0, 0.0};
    x.line = y.line = 0;
    return memcmp(&x, &y, sizeof x) == 0;
}

static bool inside(ps_aabb b, ps_aabb box, double margin)
{
    return b.lo.x - margin >= box.lo.x && b.lo.y - margin >= box.lo.y && b.lo.z - margin >= box.lo.z &&
           b.hi.x + margin <= box.hi.x && b.hi.y + margin <= box.hi.y && b.hi.z + margin <= box.hi.z;
}

ps_status ps_repair_feed(ps_feed *old, ps_tracer *old_tracer, ps_tracer *new_tracer, const ps_repair_state *was,
                         const ps_scene *scene, double epsilon, ps_feed **out, bool *repaired, ps_error *err)
{
    *out = NULL;
    *repaired = false;
    size_t nl, no;
    const ps_light *L = ps_scene_lights(scene, &nl);
    const ps_object *O = ps_scene_objects(scene, &no);
    if (!old || !old_tracer || !ps_feed_repairable(old) || !ps_tracer_records(new_tracer) ||
        nl != was->light_count || no != was->object_count || epsilon != was->epsilon)
        return PS_OK;
    keep_ctx c;
    memset(&c, 0, sizeof c);
    c.old_tracer = old_tracer;
    c.new_tracer = new_tracer;
    c.quant = ps_tracer_path_quant(new_tracer);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        if (ps_tracer_map_enabled(old_tracer, (ps_map_kind)k) != ps_tracer_map_enabled(new_tracer, (ps_map_kind)k))
            return PS_OK;
        c.cap[k] = ps_feed_cap(old, (ps_map_kind)k);
    }
    c.resampled = calloc(nl ? nl : 1, sizeof *c.resampled);
    c.moved = malloc(2 * (no ? no : 1) * sizeof *c.moved);
    if (!c.resampled || !c.moved) {
        free(c.resampled);
        free(c.moved);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for a repair", ps_scene_path(scene));
    }
    c.light_count = nl;
    bool fits = true;
    for (size_t o = 0; o < no; o++) {
        if (memcmp(&O[o].bounds, &was->bounds[o], sizeof O[o].bounds) == 0)
            continue;
        c.moved[c.moved_count++] = was->bounds[o];
        c.moved[c.moved_count++] = O[o].bounds;
        fits = fits && inside(was->bounds[o], c.quant.box, c.quant.margin) &&
               inside(O[o].bounds, c.quant.box, c.quant.margin);
        /* A mesh light's faces move with its object: its emission changes. */
        for (size_t l = 0; l < nl; l++)
            if (L[l].type == PS_LIGHT_MESH && L[l].object == o)
                c.resampled[l] = true;
    }
    for (size_t l = 0; l < nl; l++)
        if (!same_emission(&L[l], &was->lights[l]))
            c.resampled[l] = true;
    ps_status st = PS_OK;
    if (fits) {
        ps_feed_repair_fns fns = {&c, sources, c.moved, c.moved_count, c.quant};
        st = ps_feed_create_repair(new_tracer, old, &fns, out, err);
        *repaired = st == PS_OK;
    }
    free(c.resampled);
    free(c.moved);
    return st;
}
