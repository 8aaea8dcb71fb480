/* bake.c: a complete map's splats on its quads' textures (bake.h). */
#include "preview/bake.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/array.h"

struct ps_bake {
    ps_bake_target *targets;
    size_t count, cap;
    ps_splat_batch *batches; /* one a target (as many as cap) */
    int32_t *target_of;      /* 2 an object (its sides): the target, or -1 */
    ps_vec3 *normal_of;      /* an object: its quad's edge1 x edge2, once a photon met it */
    size_t objects;
    /* The build's scratch: each photon's target, and the photons regrouped
     * by target. */
    int32_t *slot;
    ps_photon *photons;
    uint16_t *ids;
    size_t cap_slot, cap_photons, cap_ids;
    size_t *first;           /* count + 1: where each target's photons start */
    size_t cap_first;
    size_t splats;
};

ps_status ps_bake_create(ps_bake **out, ps_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the baked maps");
    return PS_OK;
}

static void free_targets(ps_bake *b)
{
    for (size_t t = 0; t < b->cap; t++)
        ps_splat_batch_free(&b->batches[t]);
    free(b->batches);
    free(b->targets);
    b->batches = NULL;
    b->targets = NULL;
    b->count = b->cap = 0;
}

void ps_bake_destroy(ps_bake *b)
{
    if (!b)
        return;
    free_targets(b);
    free(b->target_of);
    free(b->normal_of);
    free(b->slot);
    free(b->photons);
    free(b->ids);
    free(b->first);
    free(b);
}

size_t ps_bake_target_count(const ps_bake *b) { return b->count; }
const ps_bake_target *ps_bake_targets(const ps_bake *b) { return b->targets; }
const ps_splat_batch *ps_bake_batch(const ps_bake *b, size_t t) { return &b->batches[t]; }
size_t ps_bake_splats(const ps_bake *b) { return b->splats; }

size_t ps_bake_texels(const ps_bake *b)
{
    size_t n = 0;
    for (size_t t = 0; t < b->count; t++)
        n += (size_t)b->targets[t].width * (size_t)b->targets[t].height;
    return n;
}

/* A quad's corner and edges from its two triangles as the parser made them
 * (corner, corner + edge1, corner + edge1 + edge2; corner, ..., corner +
 * edge2), where the object is now. */
static void quad_frame(const ps_scene *scene, const ps_object *o, ps_vec3 *corner, ps_vec3 *e1, ps_vec3 *e2)
{
    const ps_triangle *tri = ps_scene_triangles(scene, NULL) + o->first_triangle;
    const ps_vec3 *pos = ps_scene_positions(scene, NULL);
    *corner = pos[tri[0].v[0]];
    *e1 = ps_v3_sub(pos[tri[0].v[1]], *corner);
    *e2 = ps_v3_sub(pos[tri[1].v[2]], *corner);
}

/* Texels along an edge of this length: r / PS_BAKE_TEXELS_PER_RADIUS each,
 * at least PS_BAKE_MIN_SIDE; 0 past PS_BAKE_MAX_SIDE (coarser texels would
 * blur the splats: the map is not baked). */
static int texels_along(double length, double radius)
{
    double n = ceil(length * PS_BAKE_TEXELS_PER_RADIUS / radius);
    return n < PS_BAKE_MIN_SIDE ? PS_BAKE_MIN_SIDE : n > PS_BAKE_MAX_SIDE ? 0 : (int)n;
}

/* Photon ph's target: its object's side that its normal is on (-1: none). */
static int32_t target_of_photon(const ps_bake *b, uint32_t object, const ps_photon *ph)
{
    if (object >= b->objects || (b->target_of[2 * object] < 0 && b->target_of[2 * object + 1] < 0))
        return -1;
    int side = ps_v3_dot(ps_photon_normal(ph), b->normal_of[object]) >= 0.0 ? 0 : 1;
    return b->target_of[2 * object + (uint32_t)side];
}

ps_status ps_bake_plan(ps_bake *b, const ps_scene *scene, const ps_material *materials, const ps_photon *photons,
                       const uint16_t *ids, const uint32_t *objects, size_t count, double radius, bool *covered,
                       ps_error *err)
{
    *covered = false;
    free_targets(b);
    size_t nobj;
    const ps_object *obj = ps_scene_objects(scene, &nobj);
    if (nobj > b->objects) {
        int32_t *p = realloc(b->target_of, 2 * nobj * sizeof *p);
        if (p)
            b->target_of = p;
        ps_vec3 *q = p ? realloc(b->normal_of, nobj * sizeof *q) : NULL;
        if (!q)
            return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the baked maps");
        b->normal_of = q;
        b->objects = nobj;
    }
    for (size_t i = 0; i < 2 * nobj; i++)
        b->target_of[i] = -1;
    if (!(radius > 0.0))
        return PS_OK;
    /* One pass: every photon on a diffuse quad, each side met a target. */
    for (size_t i = 0; i < count; i++) {
        uint32_t o = objects[i];
        if (o >= nobj || obj[o].type != PS_OBJ_QUAD || materials[ids[i]].type != PS_MAT_DIFFUSE) {
            free_targets(b);
            return PS_OK;
        }
        bool met = b->target_of[2 * o] >= 0 || b->target_of[2 * o + 1] >= 0;
        if (!met) {
            ps_vec3 c, e1, e2;
            quad_frame(scene, &obj[o], &c, &e1, &e2);
            b->normal_of[o] = ps_v3_cross(e1, e2);
        }
        int side = ps_v3_dot(ps_photon_normal(&photons[i]), b->normal_of[o]) >= 0.0 ? 0 : 1;
        if (b->target_of[2 * o + (uint32_t)side] >= 0)
            continue;
        ps_bake_target t = {0};
        t.object = o;
        t.side = side;
        quad_frame(scene, &obj[o], &t.corner, &t.edge1, &t.edge2);
        t.width = texels_along(ps_v3_len(t.edge1), radius);
        t.height = texels_along(ps_v3_len(t.edge2), radius);
        if (t.width == 0 || t.height == 0) {
            free_targets(b);
            return PS_OK;
        }
        if (b->count == b->cap) {
            size_t cap = b->cap ? 2 * b->cap : 8;
            ps_bake_target *nt = realloc(b->targets, cap * sizeof *nt);
            if (nt)
                b->targets = nt;
            ps_splat_batch *nb = nt ? realloc(b->batches, cap * sizeof *nb) : NULL;
            if (!nb) {
                free_targets(b);
                return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the baked maps");
            }
            b->batches = nb;
            for (size_t k = b->cap; k < cap; k++)
                ps_splat_batch_init(&b->batches[k]);
            b->cap = cap;
        }
        b->target_of[2 * o + (uint32_t)side] = (int32_t)b->count;
        b->targets[b->count++] = t;
    }
    if (ps_bake_texels(b) > PS_BAKE_MAX_TEXELS) {
        free_targets(b);
        return PS_OK;
    }
    *covered = true;
    return PS_OK;
}

/* A camera that sees target t's side square on from afar: it keeps that
 * side's photons (splat.c culls the other face) and, with the surface's
 * splats not lifted, decides nothing else. */
static ps_camera_frame side_camera(const ps_bake_target *t)
{
    ps_vec3 n = ps_v3_norm(ps_v3_cross(t->edge1, t->edge2));
    if (t->side)
        n = ps_v3_scale(n, -1.0);
    ps_vec3 centre = ps_v3_add(t->corner, ps_v3_scale(ps_v3_add(t->edge1, t->edge2), 0.5));
    double far = 1.0 + 10.0 * ps_v3_len(ps_v3_add(t->edge1, t->edge2));
    ps_camera_frame c;
    memset(&c, 0, sizeof c);
    c.eye = ps_v3_madd(centre, n, far);
    c.forward = ps_v3_scale(n, -1.0);
    c.right = ps_v3_norm(t->edge1);
    c.up = ps_v3_cross(c.right, c.forward);
    c.tan_half_fov = 1.0;
    c.aspect = 1.0;
    c.width = c.height = 64;
    return c;
}

ps_status ps_bake_build(ps_bake *b, const ps_photon *photons, const uint16_t *ids, const uint32_t *objects,
                        size_t from, size_t to, const ps_splat_params *p, ps_error *err)
{
    b->splats = 0;
    size_t n = to > from ? to - from : 0;
    if (!PS_RESERVE(b->first, b->cap_first, b->count + 1) || !PS_RESERVE(b->slot, b->cap_slot, n) ||
        !PS_RESERVE(b->photons, b->cap_photons, n) || !PS_RESERVE(b->ids, b->cap_ids, n))
        return ps_error_set(err, PS_ERR_NOMEM, "baked maps: out of memory for %zu photons", n);
    /* Regrouped by target, in index order within each (a counting sort). */
    memset(b->first, 0, (b->count + 1) * sizeof *b->first);
    for (size_t i = from; i < to; i++) {
        int32_t t = target_of_photon(b, objects[i], &photons[i]);
        if (t < 0)
            return ps_error_set(err, PS_ERR_RANGE, "baked maps: photon %zu is on no planned quad", i);
        b->slot[i - from] = t;
        b->first[t + 1]++;
    }
    for (size_t t = 0; t < b->count; t++)
        b->first[t + 1] += b->first[t];
    for (size_t i = from; i < to; i++) {
        size_t at = b->first[b->slot[i - from]]++;
        b->photons[at] = photons[i];
        b->ids[at] = ids[i];
    }
    /* first[t] is now where target t + 1 starts. */
    for (size_t t = b->count; t > 0; t--)
        b->first[t] = b->first[t - 1];
    b->first[0] = 0;
    ps_splat_params q = *p;
    q.surface = true;
    q.objects = NULL;
    q.levels = 0;
    for (size_t t = 0; t < b->count; t++) {
        ps_splat_batch *batch = &b->batches[t];
        ps_splat_batch_clear(batch);
        size_t m = b->first[t + 1] - b->first[t];
        if (m == 0)
            continue;
        q.cam = side_camera(&b->targets[t]);
        ps_status st = ps_splat_build(b->photons + b->first[t], b->ids + b->first[t], m, &q, batch, err);
        if (st != PS_OK)
            return st;
        b->splats += batch->splats;
    }
    return PS_OK;
}

/* ---- the direct light on diffuse quads -------------------------------------------- */

/* Whether object o's direct light is the same from any eye on a plane. */
static bool diffuse_quad(const ps_object *o, const ps_material *materials)
{
    return o->type == PS_OBJ_QUAD && materials[o->material].type == PS_MAT_DIFFUSE;
}

ps_status ps_bake_direct_targets(const ps_scene *scene, const ps_material *materials, ps_bake_target **out,
                                 size_t *count, ps_error *err)
{
    *out = NULL;
    *count = 0;
    size_t nobj, n = 0;
    const ps_object *obj = ps_scene_objects(scene, &nobj);
    for (size_t o = 0; o < nobj; o++)
        n += diffuse_quad(&obj[o], materials) ? 2 : 0;
    if (n == 0)
        return PS_OK;
    ps_bake_target *t = malloc(n * sizeof *t);
    if (!t)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the baked direct light");
    double diag = ps_v3_len(ps_aabb_diag(ps_scene_bounds(scene)));
    double texel = diag > 0.0 && isfinite(diag) ? diag / PS_BAKE_DIRECT_TEXELS_PER_DIAG : 1.0;
    size_t k = 0, texels = 0;
    for (size_t o = 0; o < nobj; o++) {
        if (!diffuse_quad(&obj[o], materials))
            continue;
        for (int side = 0; side < 2; side++) {
            ps_bake_target *q = &t[k++];
            q->object = (uint32_t)o;
            q->side = side;
            quad_frame(scene, &obj[o], &q->corner, &q->edge1, &q->edge2);
            double along[2] = {ceil(ps_v3_len(q->edge1) / texel), ceil(ps_v3_len(q->edge2) / texel)};
            int sides[2];
            for (int a = 0; a < 2; a++)
                sides[a] = along[a] < PS_BAKE_MIN_SIDE   ? PS_BAKE_MIN_SIDE
                           : along[a] > PS_BAKE_MAX_SIDE ? PS_BAKE_MAX_SIDE
                                                         : (int)along[a];
            q->width = sides[0], q->height = sides[1];
            texels += (size_t)q->width * (size_t)q->height;
        }
    }
    if (texels > PS_BAKE_MAX_TEXELS) {
        free(t);
        return PS_OK;
    }
    *out = t;
    *count = n;
    return PS_OK;
}
