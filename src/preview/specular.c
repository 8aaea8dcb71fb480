/* specular.c: the specular layer's per-vertex lookups (specular.h). */
#include "preview/specular.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "preview/specular_glossy.h"
#include "scene/bsdf.h"

/* A path that meets nothing is looked up this many scene diagonals away
 * along its last direction: far enough to stand for "at infinity" when
 * interpolated against neighbouring vertices' finite points. */
#define FAR_DIAGONALS 1000.0

struct ps_specular {
    const ps_preview_mesh *mesh;
    const ps_material *materials;
    ps_specular_range *ranges;
    size_t range_count;
    ps_vec3 centre[PS_SPECULAR_MAX_CUBES];
    int cube_count;
    /* The lookup arrays: one entry a vertex of the listed ranges. */
    size_t vertex_count;
    float *dirs[PS_SPECULAR_TERMS], *weights[PS_SPECULAR_TERMS];
    /* Distinct vertices (the mesh repeats each for every triangle): unique
     * index of each lookup vertex, and one lookup vertex of each unique. */
    uint32_t *unique_of;
    uint32_t *first_of;
    size_t unique_count;
    uint32_t *order;      /* lookup vertices sorted by unique index */
    size_t *order_first;  /* unique u's run in order[]: [order_first[u], order_first[u + 1]) */
    /* Progress for the current eye. */
    bool have_eye, changed;
    ps_vec3 eye;
    size_t next_unique;
};

static const ps_material *range_material(const ps_specular *sp, size_t r)
{
    return &sp->materials[sp->mesh->ranges[r].material];
}

static ps_vec3 vertex_pos(const ps_preview_mesh *m, size_t v)
{
    const float *p = m->positions + 3 * v;
    return ps_v3(p[0], p[1], p[2]);
}

/* ---- building ------------------------------------------------------------------ */

static uint64_t hash_bits(const float *p, uint32_t object)
{
    uint32_t b[3];
    memcpy(b, p, sizeof b);
    uint64_t h = 1469598103934665603ull ^ object;
    for (int i = 0; i < 3; i++) {
        h ^= b[i];
        h *= 1099511628211ull;
        h ^= h >> 29;
    }
    return h;
}

/* Unique vertices by exact position within an object (their lookups depend
 * on nothing else), with an open-addressing table of twice the size. */
static ps_status find_unique(ps_specular *sp, ps_error *err)
{
    size_t n = sp->vertex_count, cap = 16;
    while (cap < 2 * n)
        cap *= 2;
    uint32_t *table = malloc(cap * sizeof *table);
    sp->unique_of = malloc((n ? n : 1) * sizeof *sp->unique_of);
    sp->first_of = malloc((n ? n : 1) * sizeof *sp->first_of);
    uint32_t *objects = malloc((n ? n : 1) * sizeof *objects);
    const float **pos = malloc((n ? n : 1) * sizeof *pos);
    if (!table || !sp->unique_of || !sp->first_of || !objects || !pos) {
        free(table), free(objects), free(pos);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer's %zu vertices", n);
    }
    memset(table, 0xff, cap * sizeof *table);
    for (size_t i = 0; i < sp->range_count; i++) {
        const ps_mesh_range *rg = &sp->mesh->ranges[sp->ranges[i].range];
        for (size_t v = 0; v < rg->count; v++) {
            size_t k = sp->ranges[i].offset + v;
            objects[k] = rg->object;
            pos[k] = sp->mesh->positions + 3 * (rg->first + v);
        }
    }
    sp->unique_count = 0;
    for (size_t k = 0; k < n; k++) {
        size_t slot = (size_t)hash_bits(pos[k], objects[k]) & (cap - 1);
        for (;;) {
            uint32_t u = table[slot];
            if (u == UINT32_MAX) {
                table[slot] = (uint32_t)sp->unique_count;
                sp->first_of[sp->unique_count] = (uint32_t)k;
                sp->unique_of[k] = (uint32_t)sp->unique_count++;
                break;
            }
            uint32_t f = sp->first_of[u];
            if (objects[f] == objects[k] && memcmp(pos[f], pos[k], 3 * sizeof(float)) == 0) {
                sp->unique_of[k] = u;
                break;
            }
            slot = (slot + 1) & (cap - 1);
        }
    }
    free(table), free(objects), free(pos);
    /* Each unique vertex's copies, by counting sort. */
    sp->order = malloc((n ? n : 1) * sizeof *sp->order);
    sp->order_first = calloc(sp->unique_count + 1, sizeof *sp->order_first);
    if (!sp->order || !sp->order_first)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer's %zu vertices", n);
    for (size_t k = 0; k < n; k++)
        sp->order_first[sp->unique_of[k] + 1]++;
    for (size_t u = 0; u < sp->unique_count; u++)
        sp->order_first[u + 1] += sp->order_first[u];
    size_t *fill = calloc(sp->unique_count + 1, sizeof *fill);
    if (!fill)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer's %zu vertices", n);
    for (size_t k = 0; k < n; k++) {
        uint32_t u = sp->unique_of[k];
        sp->order[sp->order_first[u] + fill[u]++] = (uint32_t)k;
    }
    free(fill);
    return PS_OK;
}

ps_status ps_specular_create(const ps_preview_mesh *mesh, const ps_material *materials, ps_specular **out,
                             ps_error *err)
{
    *out = NULL;
    ps_specular *sp = calloc(1, sizeof *sp);
    if (!sp)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer");
    sp->mesh = mesh;
    sp->materials = materials;
    sp->ranges = calloc(mesh->range_count ? mesh->range_count : 1, sizeof *sp->ranges);
    if (!sp->ranges) {
        ps_specular_destroy(sp);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer");
    }
    /* Objects in order of first appearance, each with its bounding box. */
    uint32_t objects[PS_SPECULAR_MAX_CUBES];
    ps_aabb box[PS_SPECULAR_MAX_CUBES];
    for (size_t r = 0; r < mesh->range_count; r++) {
        const ps_mesh_range *rg = &mesh->ranges[r];
        if (!ps_specular_wants(&materials[rg->material]) || rg->count == 0)
            continue;
        ps_aabb b = ps_aabb_empty();
        for (size_t v = 0; v < rg->count; v++)
            b = ps_aabb_point(b, vertex_pos(mesh, rg->first + v));
        int c = 0;
        while (c < sp->cube_count && objects[c] != rg->object)
            c++;
        if (c == sp->cube_count && sp->cube_count < PS_SPECULAR_MAX_CUBES) {
            objects[c] = rg->object;
            box[c] = b;
            sp->cube_count++;
        } else if (c == sp->cube_count) {
            /* Out of cubes: the one whose centre lies nearest. */
            ps_vec3 centre = ps_aabb_center(b);
            double best = HUGE_VAL;
            for (int k = 0; k < sp->cube_count; k++) {
                double d = ps_v3_len(ps_v3_sub(ps_aabb_center(box[k]), centre));
                if (d < best)
                    best = d, c = k;
            }
        } else {
            box[c] = ps_aabb_union(box[c], b);
        }
        sp->ranges[sp->range_count].range = r;
        sp->ranges[sp->range_count].offset = sp->vertex_count;
        sp->ranges[sp->range_count].cube = c;
        sp->range_count++;
        sp->vertex_count += rg->count;
    }
    for (int c = 0; c < sp->cube_count; c++)
        sp->centre[c] = ps_aabb_center(box[c]);
    size_t n = sp->vertex_count ? sp->vertex_count : 1;
    for (int k = 0; k < PS_SPECULAR_TERMS; k++) {
        sp->dirs[k] = calloc(3 * n, sizeof(float));
        sp->weights[k] = calloc(3 * n, sizeof(float));
        if (!sp->dirs[k] || !sp->weights[k]) {
            ps_specular_destroy(sp);
            return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer's %zu vertices", n);
        }
    }
    ps_status st = find_unique(sp, err);
    if (st != PS_OK) {
        ps_specular_destroy(sp);
        return st;
    }
    *out = sp;
    return PS_OK;
}

void ps_specular_destroy(ps_specular *sp)
{
    if (!sp)
        return;
    for (int k = 0; k < PS_SPECULAR_TERMS; k++) {
        free(sp->dirs[k]);
        free(sp->weights[k]);
    }
    free(sp->ranges);
    free(sp->unique_of);
    free(sp->first_of);
    free(sp->order);
    free(sp->order_first);
    free(sp);
}

size_t ps_specular_range_count(const ps_specular *sp) { return sp->range_count; }
const ps_specular_range *ps_specular_ranges(const ps_specular *sp) { return sp->ranges; }
int ps_specular_cube_count(const ps_specular *sp) { return sp->cube_count; }
ps_vec3 ps_specular_cube_centre(const ps_specular *sp, int cube) { return sp->centre[cube]; }
const float *ps_specular_dirs(const ps_specular *sp, int k) { return sp->dirs[k]; }
const float *ps_specular_weights(const ps_specular *sp, int k) { return sp->weights[k]; }

/* ---- tracing ------------------------------------------------------------------- */

typedef struct path_ctx {
    const ps_world *world;
    const ps_material *materials;
    ps_vec3 centre;
    double far;
    double first;  /* the eye's distance to the vertex */
    ps_specular_term paths[PS_SPECULAR_MAX_PATHS];
    int count;
    double dropped;
} path_ctx;

static double weight_of(ps_rgb w) { return fmax(w.r, fmax(w.g, w.b)); }

static void add_path(path_ctx *c, ps_vec3 dir, ps_rgb w)
{
    if (c->count < PS_SPECULAR_MAX_PATHS) {
        c->paths[c->count].dir = dir;
        c->paths[c->count].weight = w;
        c->count++;
    } else {
        c->dropped += weight_of(w);
    }
}

static void follow(path_ctx *c, ps_ray r, ps_rgb w, int depth, double length);

/* At a mirror or glass surface point sp (normal n on the winding's side,
 * front: the ray came from that side), as the reference's eye paths
 * (render.c, radiance): reflect, or split by Fresnel into both branches. */
static void scatter(path_ctx *c, const ps_surface *sp, const ps_material *m, ps_vec3 d, ps_rgb w, int depth,
                    double length)
{
    bool front = ps_v3_dot(d, sp->ng) < 0.0;
    ps_vec3 n = front ? sp->ns : ps_v3_neg(sp->ns);
    if (m->type == PS_MAT_MIRROR) {
        follow(c, ps_world_spawn(c->world, sp, ps_reflect(d, n)), ps_rgb_mul(w, m->reflectance), depth + 1, length);
        return;
    }
    double eta_i = front ? 1.0 : m->ior, eta_t = front ? m->ior : 1.0;
    double f = ps_fresnel_dielectric(-ps_v3_dot(d, n), eta_i, eta_t);
    ps_vec3 refr;
    if (!ps_refract(d, n, eta_i / eta_t, &refr))
        f = 1.0; /* total internal reflection */
    if (f > 0.0)
        follow(c, ps_world_spawn(c->world, sp, ps_reflect(d, n)), ps_rgb_scale(w, f), depth + 1, length);
    if (f < 1.0)
        follow(c, ps_world_spawn(c->world, sp, refr), ps_rgb_scale(ps_rgb_mul(w, m->transmittance), 1.0 - f),
               depth + 1, length);
}

/* A path's lookup is P - centre scaled by first / length, the eye's
 * distance to the vertex over the whole path's: the same direction, but a
 * length that makes GL's interpolation of it over a triangle exact for a
 * planar mirror and a plane beyond (from the eye's mirror image E', the
 * point seen through surface point m is E' + s (m - E') with s = length /
 * first, and (E' - centre) / s + m - E' is affine in m), where interpolating
 * P - centre itself would follow the floor's perspective only to second
 * order: 4.5 % off across a mirror's triangles in test_gl_specular. */
static void follow(path_ctx *c, ps_ray r, ps_rgb w, int depth, double length)
{
    if (weight_of(w) < PS_SPECULAR_MIN_WEIGHT || depth >= PS_SPECULAR_MAX_DEPTH) {
        c->dropped += weight_of(w);
        return;
    }
    ps_surface sp;
    if (!ps_world_intersect(c->world, r, INFINITY, &sp)) {
        add_path(c, ps_v3_scale(r.d, c->far), w);
        return;
    }
    const ps_material *m = &c->materials[sp.material];
    length += sp.t;
    if (!ps_material_is_specular(m)) {
        add_path(c, ps_v3_scale(ps_v3_sub(sp.p, c->centre), c->first / length), w);
        return;
    }
    scatter(c, &sp, m, r.d, w, depth, length);
}

static double cosine(ps_vec3 a, ps_vec3 b)
{
    double la = ps_v3_len(a), lb = ps_v3_len(b);
    return la > 0.0 && lb > 0.0 ? ps_v3_dot(a, b) / (la * lb) : -1.0;
}

/* The heaviest PS_SPECULAR_TERMS paths, each of the others added to the
 * kept one nearest in direction. */
static int keep_heaviest(path_ctx *c, ps_specular_term out[PS_SPECULAR_TERMS])
{
    /* Selection by weight (few paths): stable, so ties keep path order. */
    bool used[PS_SPECULAR_MAX_PATHS] = {false};
    int kept = 0;
    int index[PS_SPECULAR_TERMS];
    while (kept < PS_SPECULAR_TERMS && kept < c->count) {
        int best = -1;
        for (int i = 0; i < c->count; i++)
            if (!used[i] && (best < 0 || weight_of(c->paths[i].weight) > weight_of(c->paths[best].weight)))
                best = i;
        used[best] = true;
        index[kept] = best;
        out[kept++] = c->paths[best];
    }
    for (int i = 0; i < c->count; i++) {
        if (used[i])
            continue;
        int near = 0;
        double best = -2.0;
        for (int k = 0; k < kept; k++) {
            double cs = cosine(c->paths[i].dir, c->paths[index[k]].dir);
            if (cs > best)
                best = cs, near = k;
        }
        out[near].weight = ps_rgb_add(out[near].weight, c->paths[i].weight);
    }
    return kept;
}

static double scene_far(const ps_world *world)
{
    double diag = ps_v3_len(ps_aabb_diag(ps_scene_bounds(ps_world_scene(world))));
    return FAR_DIAGONALS * (diag > 0.0 && isfinite(diag) ? diag : 1.0);
}

/* The first surface is the mesh vertex itself, so that a vertex hidden from
 * the eye still gets its own lookups, which Gouraud shading blends into its
 * visible neighbours. The vertex (in floats) may lie a rounding error inside
 * the exact surface, where a ray leaving it would meet that surface again
 * from within: the point is snapped to the world's own surface by a ray
 * along the eye's direction through a short stretch of SNAP_DIAGONALS of
 * the scene about it, and only where that finds nothing of the same
 * material is the vertex pushed off along its normal by as much. */
#define SNAP_DIAGONALS 1e-4

static int trace_point(path_ctx *c, const ps_material *m, ps_vec3 eye, ps_vec3 p, ps_vec3 n,
                       ps_specular_term out[PS_SPECULAR_TERMS])
{
    c->count = 0;
    c->dropped = 0.0;
    ps_vec3 d = ps_v3_sub(p, eye);
    double len = ps_v3_len(d);
    if (!(len > 0.0))
        return 0;
    d = ps_v3_scale(d, 1.0 / len);
    double delta = SNAP_DIAGONALS * c->far / FAR_DIAGONALS;
    ps_ray probe = {ps_v3_madd(p, d, -delta), d};
    ps_surface sp;
    if (!ps_world_intersect(c->world, probe, 2.0 * delta, &sp) || &c->materials[sp.material] != m) {
        memset(&sp, 0, sizeof sp);
        sp.t = len;
        sp.ng = sp.ns = n;
        sp.p = ps_v3_madd(p, n, ps_v3_dot(d, n) < 0.0 ? delta : -delta);
    }
    c->first = len;
    scatter(c, &sp, m, d, ps_rgb_gray(1.0), 0, len);
    return keep_heaviest(c, out);
}

int ps_specular_trace_point(const ps_world *world, const ps_material *materials, const ps_material *m, ps_vec3 eye,
                            ps_vec3 p, ps_vec3 n, ps_vec3 centre, ps_specular_term out[PS_SPECULAR_TERMS],
                            double *dropped)
{
    path_ctx c;
    c.world = world;
    c.materials = materials;
    c.centre = centre;
    c.far = scene_far(world);
    int k = trace_point(&c, m, eye, p, n, out);
    if (dropped)
        *dropped = c.dropped;
    return k;
}

static bool same_vec(ps_vec3 a, ps_vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* Which listed range holds lookup vertex k (ranges are in offset order). */
static size_t range_of(const ps_specular *sp, size_t k)
{
    size_t lo = 0, hi = sp->range_count;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (sp->ranges[mid].offset <= k)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

size_t ps_specular_update(ps_specular *sp, const ps_world *world, ps_vec3 eye, size_t max_vertices)
{
    if (!sp->have_eye || !same_vec(eye, sp->eye)) {
        sp->have_eye = true;
        sp->eye = eye;
        sp->next_unique = 0;
    }
    if (sp->next_unique >= sp->unique_count)
        return 0;
    size_t end = max_vertices == 0 ? sp->unique_count : sp->next_unique + max_vertices;
    if (end > sp->unique_count)
        end = sp->unique_count;
    path_ctx c;
    c.world = world;
    c.materials = ps_scene_materials(ps_world_scene(world), &(size_t){0});
    c.far = scene_far(world);
    for (size_t u = sp->next_unique; u < end; u++) {
        size_t k = sp->first_of[u];
        const ps_specular_range *lr = &sp->ranges[range_of(sp, k)];
        size_t v = sp->mesh->ranges[lr->range].first + (k - lr->offset);
        const float *nn = sp->mesh->normals + 3 * v;
        c.centre = sp->centre[lr->cube];
        ps_specular_term t[PS_SPECULAR_TERMS];
        const ps_material *m = range_material(sp, lr->range);
        int count = ps_glossy_wants(m) /* the lobe's lookup (specular_glossy.h) */
                        ? ps_glossy_trace_point(world, c.materials, m, eye, vertex_pos(sp->mesh, v),
                                                ps_v3(nn[0], nn[1], nn[2]), c.centre, t, NULL)
                        : trace_point(&c, m, eye, vertex_pos(sp->mesh, v), ps_v3(nn[0], nn[1], nn[2]), t);
        for (int j = 0; j < PS_SPECULAR_TERMS; j++) {
            float dv[3] = {0, 0, 1}, wv[3] = {0, 0, 0};
            if (j < count) {
                dv[0] = (float)t[j].dir.x, dv[1] = (float)t[j].dir.y, dv[2] = (float)t[j].dir.z;
                wv[0] = (float)t[j].weight.r, wv[1] = (float)t[j].weight.g, wv[2] = (float)t[j].weight.b;
            }
            for (size_t i = sp->order_first[u]; i < sp->order_first[u + 1]; i++) {
                memcpy(sp->dirs[j] + 3 * (size_t)sp->order[i], dv, sizeof dv);
                memcpy(sp->weights[j] + 3 * (size_t)sp->order[i], wv, sizeof wv);
            }
        }
    }
    sp->next_unique = end;
    sp->changed = true;
    return sp->unique_count - end;
}

bool ps_specular_take_changed(ps_specular *sp)
{
    bool c = sp->changed;
    sp->changed = false;
    return c;
}

void ps_specular_invalidate(ps_specular *sp)
{
    sp->have_eye = false;
    sp->next_unique = 0;
}
