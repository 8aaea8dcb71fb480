/* specular.c: the specular layer's per-vertex lookups (specular.h). */
#include "preview/specular.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/hash.h"
#include "core/jobs.h"
#include "preview/specular_glossy.h"
#include "scene/bsdf.h"

/* A path that meets nothing is looked up this many scene diagonals away
 * along its last direction: far enough to stand for "at infinity" when
 * interpolated against neighbouring vertices' finite points. */
#define FAR_DIAGONALS 1000.0

ps_vec3 ps_specular_term_dir(const ps_specular_term *t, ps_vec3 centre)
{
    return t->scale > 0.0 ? ps_v3_scale(ps_v3_sub(t->end, centre), t->scale) : t->end;
}

static void store_dir(float *out, ps_vec3 d) { out[0] = (float)d.x, out[1] = (float)d.y, out[2] = (float)d.z; }

/* Points of the per-pixel layer (specular.h), each with its path's end and
 * scale (ps_specular_term) to re-aim it from another centre. */
typedef struct point_set {
    float *xy, *dirs, *weights;
    int *cube;
    double *ends, *scales;
    size_t count, cap;
} point_set;

static void point_set_free(point_set *p)
{
    free(p->xy), free(p->dirs), free(p->weights), free(p->cube), free(p->ends), free(p->scales);
    memset(p, 0, sizeof *p);
}

/* *p grown to n elements of elem bytes; kept as it was when realloc fails. */
static bool grow(void **p, size_t n, size_t elem)
{
    void *q = realloc(*p, n * elem);
    if (!q)
        return false;
    *p = q;
    return true;
}
#define GROW(ptr, n) grow((void **)&(ptr), (n), sizeof *(ptr))

static bool point_set_reserve(point_set *p, size_t n)
{
    if (n <= p->cap)
        return true;
    size_t cap = p->cap ? p->cap : 4096;
    while (cap < n)
        cap *= 2;
    /* Every array tried (each kept at its old size or grown): the capacity
     * moves only when all grew. */
    bool ok = GROW(p->xy, 2 * cap) & GROW(p->dirs, 3 * cap) & GROW(p->weights, 3 * cap) & GROW(p->cube, cap) &
              GROW(p->ends, 3 * cap) & GROW(p->scales, cap);
    if (ok)
        p->cap = cap;
    return ok;
}

/* Path term t of pixel (x, y), looked up in `cube` from `lookup`. */
static bool point_set_add(point_set *p, float x, float y, const ps_specular_term *t, ps_rgb w, int cube,
                          ps_vec3 lookup)
{
    if (!point_set_reserve(p, p->count + 1))
        return false;
    size_t i = p->count++;
    p->xy[2 * i] = x, p->xy[2 * i + 1] = y;
    store_dir(p->dirs + 3 * i, ps_specular_term_dir(t, lookup));
    p->weights[3 * i] = (float)w.r, p->weights[3 * i + 1] = (float)w.g, p->weights[3 * i + 2] = (float)w.b;
    p->cube[i] = cube;
    p->ends[3 * i] = t->end.x, p->ends[3 * i + 1] = t->end.y, p->ends[3 * i + 2] = t->end.z;
    p->scales[i] = t->scale;
    return true;
}

/* src's points after dst's. */
static bool point_set_append(point_set *dst, const point_set *src)
{
    if (src->count == 0) /* its arrays may be NULL, which memcpy may not be given */
        return true;
    if (!point_set_reserve(dst, dst->count + src->count))
        return false;
    size_t n = src->count, at = dst->count;
    memcpy(dst->xy + 2 * at, src->xy, 2 * n * sizeof *src->xy);
    memcpy(dst->dirs + 3 * at, src->dirs, 3 * n * sizeof *src->dirs);
    memcpy(dst->weights + 3 * at, src->weights, 3 * n * sizeof *src->weights);
    memcpy(dst->cube + at, src->cube, n * sizeof *src->cube);
    memcpy(dst->ends + 3 * at, src->ends, 3 * n * sizeof *src->ends);
    memcpy(dst->scales + at, src->scales, n * sizeof *src->scales);
    dst->count += n;
    return true;
}

/* The points of `cube` looked up from `lookup` instead. */
static void point_set_reaim(point_set *p, int cube, ps_vec3 lookup)
{
    for (size_t i = 0; i < p->count; i++) {
        if (p->cube[i] != cube)
            continue;
        ps_specular_term t;
        t.end = ps_v3(p->ends[3 * i], p->ends[3 * i + 1], p->ends[3 * i + 2]);
        t.scale = p->scales[i];
        store_dir(p->dirs + 3 * i, ps_specular_term_dir(&t, lookup));
    }
}

/* A unique vertex's kept paths, to re-aim its lookups (ps_specular_term). */
typedef struct vertex_ends {
    ps_vec3 end[PS_SPECULAR_TERMS];
    double scale[PS_SPECULAR_TERMS];
    int count;
} vertex_ends;

struct ps_specular {
    const ps_preview_mesh *mesh;
    const ps_material *materials;
    ps_specular_range *ranges;
    size_t range_count;
    ps_vec3 centre[PS_SPECULAR_MAX_CUBES];
    /* Where each cube's lookups look from: the centre its shown map was
     * rendered from (ps_specular_set_lookup_centre), the centre until then. */
    ps_vec3 lookup_centre[PS_SPECULAR_MAX_CUBES];
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
    int *unique_cube;     /* the cube each unique vertex looks up */
    vertex_ends *ends;    /* each unique vertex's paths (re-aiming) */
    /* Progress for the current eye. */
    bool have_eye, changed;
    ps_vec3 eye;
    size_t next_unique;
    /* Per-pixel paths: each listed range's vertex box, the camera frame being
     * traced, its pixel rectangles and the cursor over them (range, pixel),
     * the pixels done or left out (ranges' rectangles overlap; pixels near
     * none of the triangles, unless pix_boxes), the points being built
     * and those of the last frame traced whole (ready: that frame is the
     * current one). */
    ps_aabb *range_box;
    bool pix_have_cam, pix_ready;
    ps_camera_frame pix_cam;
    int (*rect)[4];
    size_t pix_range, pix_next;
    unsigned char *pix_seen;
    size_t pix_seen_cap;
    bool pix_boxes;
    point_set pix_build, pix_done;
    /* Tracing them on `threads` threads: the pixels of a chunk and each
     * job's points (joined in job order). */
    int threads;
    int *pix_list;
    size_t pix_list_cap;
    point_set job_points[PS_JOBS_MAX_THREADS];
};

static size_t range_of(const ps_specular *sp, size_t k);

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

/* A position's bits, hashed with its object. */
static uint64_t hash_bits(const float *p, uint32_t object)
{
    uint32_t b[3];
    memcpy(b, p, sizeof b);
    return ps_hash_words(b, 3, object);
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
        sp->centre[c] = sp->lookup_centre[c] = ps_aabb_center(box[c]);
    size_t nr = sp->range_count ? sp->range_count : 1;
    sp->range_box = malloc(nr * sizeof *sp->range_box);
    sp->rect = malloc(nr * sizeof *sp->rect);
    if (!sp->range_box || !sp->rect) {
        ps_specular_destroy(sp);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer");
    }
    for (size_t i = 0; i < sp->range_count; i++) {
        const ps_mesh_range *rg = &mesh->ranges[sp->ranges[i].range];
        sp->range_box[i] = ps_aabb_empty();
        for (size_t v = 0; v < rg->count; v++)
            sp->range_box[i] = ps_aabb_point(sp->range_box[i], vertex_pos(mesh, rg->first + v));
    }
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
    size_t nu = sp->unique_count ? sp->unique_count : 1;
    sp->unique_cube = malloc(nu * sizeof *sp->unique_cube);
    sp->ends = calloc(nu, sizeof *sp->ends);
    if (!sp->unique_cube || !sp->ends) {
        ps_specular_destroy(sp);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer's %zu vertices", n);
    }
    for (size_t u = 0; u < sp->unique_count; u++)
        sp->unique_cube[u] = sp->ranges[range_of(sp, sp->first_of[u])].cube;
    sp->threads = 1;
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
    free(sp->range_box);
    free(sp->rect);
    free(sp->pix_seen);
    point_set_free(&sp->pix_build);
    point_set_free(&sp->pix_done);
    free(sp->unique_cube);
    free(sp->ends);
    free(sp->pix_list);
    for (int t = 0; t < PS_JOBS_MAX_THREADS; t++)
        point_set_free(&sp->job_points[t]);
    free(sp);
}

size_t ps_specular_range_count(const ps_specular *sp) { return sp->range_count; }
const ps_specular_range *ps_specular_ranges(const ps_specular *sp) { return sp->ranges; }
int ps_specular_cube_count(const ps_specular *sp) { return sp->cube_count; }
ps_vec3 ps_specular_cube_centre(const ps_specular *sp, int cube) { return sp->centre[cube]; }
ps_vec3 ps_specular_lookup_centre(const ps_specular *sp, int cube) { return sp->lookup_centre[cube]; }

/* Unique vertex u's lookup directions from its cube's lookup centre (its
 * weights stay): what tracing it now would write. */
static void write_dirs(ps_specular *sp, size_t u)
{
    const vertex_ends *e = &sp->ends[u];
    ps_vec3 lookup = sp->lookup_centre[sp->unique_cube[u]];
    for (int j = 0; j < PS_SPECULAR_TERMS; j++) {
        float dv[3] = {0, 0, 1};
        if (j < e->count) {
            ps_specular_term t;
            t.end = e->end[j];
            t.scale = e->scale[j];
            store_dir(dv, ps_specular_term_dir(&t, lookup));
        }
        for (size_t i = sp->order_first[u]; i < sp->order_first[u + 1]; i++)
            memcpy(sp->dirs[j] + 3 * (size_t)sp->order[i], dv, sizeof dv);
    }
}

bool ps_specular_set_lookup_centre(ps_specular *sp, int cube, ps_vec3 centre)
{
    if (cube < 0 || cube >= sp->cube_count || ps_v3_equal(centre, sp->lookup_centre[cube]))
        return false;
    sp->lookup_centre[cube] = centre;
    for (size_t u = 0; u < sp->unique_count; u++)
        if (sp->unique_cube[u] == cube)
            write_dirs(sp, u);
    point_set_reaim(&sp->pix_build, cube, centre);
    point_set_reaim(&sp->pix_done, cube, centre);
    sp->changed = true;
    return true;
}

void ps_specular_set_pixel_boxes(ps_specular *sp, bool boxes)
{
    sp->pix_boxes = boxes;
    sp->pix_have_cam = false;
}

void ps_specular_set_threads(ps_specular *sp, int threads)
{
    sp->threads = threads < 1 ? 1 : threads > PS_JOBS_MAX_THREADS ? PS_JOBS_MAX_THREADS : threads;
}
const float *ps_specular_dirs(const ps_specular *sp, int k) { return sp->dirs[k]; }
const float *ps_specular_weights(const ps_specular *sp, int k) { return sp->weights[k]; }

size_t ps_specular_weighted_triangles(const float *weights, size_t vertices, unsigned *out)
{
    size_t n = 0;
    for (size_t t = 0; t + 3 <= vertices; t += 3) {
        bool lit = false;
        for (size_t i = 3 * t; i < 3 * (t + 3) && !lit; i++)
            lit = weights[i] != 0.0f;
        if (lit)
            for (size_t v = t; v < t + 3; v++)
                out[n++] = (unsigned)v;
    }
    return n;
}

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
    /* A path that meets nothing is black, as in photosplat-ref (no
     * environment), rather than looked up far away along its direction:
     * from the cube's centre that direction may meet a wall the path itself
     * passed by (the open front of the default box seen in the mirror sphere
     * grew by a pixel or two into the floor). Per-pixel paths only: the
     * per-vertex ones interpolate a lookup toward it. */
    bool escape_black;
} path_ctx;

static double weight_of(ps_rgb w) { return fmax(w.r, fmax(w.g, w.b)); }

/* A path ending at `end` with `scale` (ps_specular_term), looked up from
 * the context's centre. */
static void add_path(path_ctx *c, ps_vec3 end, double scale, ps_rgb w)
{
    if (c->count < PS_SPECULAR_MAX_PATHS) {
        ps_specular_term *t = &c->paths[c->count];
        t->end = end;
        t->scale = scale;
        t->dir = ps_specular_term_dir(t, c->centre);
        t->weight = w;
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
        if (c->escape_black)
            return;
        add_path(c, ps_v3_scale(r.d, c->far), 0.0, w);
        return;
    }
    const ps_material *m = &c->materials[sp.material];
    length += sp.t;
    if (!ps_material_is_specular(m)) {
        add_path(c, sp.p, c->first / length, w);
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
    c.escape_black = false;
    int k = trace_point(&c, m, eye, p, n, out);
    if (dropped)
        *dropped = c.dropped;
    return k;
}

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

/* Unique vertices a job of ps_specular_update traces. */
#define VERTICES_PER_JOB 256

/* Unique vertices [first, end) for eye `eye`, job j taking its
 * VERTICES_PER_JOB of them: each writes only its own vertex's slots. */
typedef struct vertex_chunk {
    ps_specular *sp;
    const ps_world *world;
    ps_vec3 eye;
    size_t first, end;
} vertex_chunk;

static void vertex_job(void *ctx, size_t job)
{
    const vertex_chunk *ch = ctx;
    ps_specular *sp = ch->sp;
    const ps_world *world = ch->world;
    path_ctx c;
    c.world = world;
    c.materials = ps_scene_materials(ps_world_scene(world), &(size_t){0});
    c.far = scene_far(world);
    c.escape_black = false;
    size_t from = ch->first + job * VERTICES_PER_JOB;
    size_t to = from + VERTICES_PER_JOB < ch->end ? from + VERTICES_PER_JOB : ch->end;
    for (size_t u = from; u < to; u++) {
        size_t k = sp->first_of[u];
        const ps_specular_range *lr = &sp->ranges[range_of(sp, k)];
        size_t v = sp->mesh->ranges[lr->range].first + (k - lr->offset);
        const float *nn = sp->mesh->normals + 3 * v;
        /* From the cube's own centre, looked up from the lookup centre. */
        c.centre = sp->centre[lr->cube];
        ps_specular_term t[PS_SPECULAR_TERMS];
        const ps_material *m = range_material(sp, lr->range);
        int count = ps_glossy_wants(m) /* the lobe's lookup (specular_glossy.h) */
                        ? ps_glossy_trace_point(world, c.materials, m, ch->eye, vertex_pos(sp->mesh, v),
                                                ps_v3(nn[0], nn[1], nn[2]), c.centre, t, NULL)
                        : trace_point(&c, m, ch->eye, vertex_pos(sp->mesh, v), ps_v3(nn[0], nn[1], nn[2]), t);
        vertex_ends *e = &sp->ends[u];
        e->count = count;
        for (int j = 0; j < PS_SPECULAR_TERMS; j++) {
            float wv[3] = {0, 0, 0};
            if (j < count) {
                e->end[j] = t[j].end, e->scale[j] = t[j].scale;
                wv[0] = (float)t[j].weight.r, wv[1] = (float)t[j].weight.g, wv[2] = (float)t[j].weight.b;
            }
            for (size_t i = sp->order_first[u]; i < sp->order_first[u + 1]; i++)
                memcpy(sp->weights[j] + 3 * (size_t)sp->order[i], wv, sizeof wv);
        }
        write_dirs(sp, u);
    }
}

size_t ps_specular_update(ps_specular *sp, const ps_world *world, ps_vec3 eye, size_t max_vertices)
{
    if (!sp->have_eye || !ps_v3_equal(eye, sp->eye)) {
        sp->have_eye = true;
        sp->eye = eye;
        sp->next_unique = 0;
    }
    if (sp->next_unique >= sp->unique_count)
        return 0;
    size_t end = max_vertices == 0 ? sp->unique_count : sp->next_unique + max_vertices;
    if (end > sp->unique_count)
        end = sp->unique_count;
    /* On the per-pixel paths' threads (a moving camera's 2048 vertices took
     * 8 ms on one, a sixth of its frame). */
    vertex_chunk ch = {sp, world, eye, sp->next_unique, end};
    ps_run_jobs((end - sp->next_unique + VERTICES_PER_JOB - 1) / VERTICES_PER_JOB, sp->threads, vertex_job, &ch);
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
    sp->pix_have_cam = false;
    sp->pix_ready = false;
}

/* ---- per-pixel paths ----------------------------------------------------------- */

/* A vertex box's projection is widened by this many pixels: the exact
 * surface bulges past the mesh's chords, and a sample's pixel may lie just
 * outside the box's projected corners. */
#define PIXEL_MARGIN 2
/* ... and a triangle's by this share of its projected size besides: a
 * sphere's exact surface bulges past its chords by sqrt(t / 8) of a chord
 * when tessellated to sagitta / radius t (0.011 at the preview's 10^-3),
 * some pixels where a chord spans hundreds (a view zoomed in far). A guard:
 * no view tried needed either (test_specular: the same points with both
 * at 0; the box's margin is needed, the design room's and the gallery's
 * points at 256^2 differ without it). */
#define PIXEL_CHORD_BULGE 0.05
/* A range with more triangles than this many a pixel of its box traces the
 * whole box: a triangle projected and its rectangle cleared cost about
 * 0.1 us here (the default box's 2*10^4 at 256^2 in 1.5-2 ms, the ring's
 * 10^4 in 0.9-1.1 ms), a pixel's four rays some 3 us. */
#define PIXEL_TRIANGLES_MAX 16

/* The pixel rectangle [x0, x1) x [y0, y1) of `count` points projected,
 * PIXEL_MARGIN and `bulge` of its larger side wider; false when one lies
 * behind the eye (no rectangle). */
static bool points_rect(const ps_vec3 *p, int count, const ps_camera_frame *cam, double bulge, int r[4])
{
    double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
    for (int k = 0; k < count; k++) {
        double x, y;
        if (!ps_camera_project(cam, p[k], &x, &y) || !isfinite(x) || !isfinite(y))
            return false;
        x0 = fmin(x0, x), x1 = fmax(x1, x), y0 = fmin(y0, y), y1 = fmax(y1, y);
    }
    double grow = PIXEL_MARGIN + bulge * fmax(x1 - x0, y1 - y0);
    double lo[2] = {floor(x0 - grow), floor(y0 - grow)}, hi[2] = {ceil(x1 + grow), ceil(y1 + grow)};
    double size[2] = {cam->width, cam->height};
    for (int a = 0; a < 2; a++) {
        r[a] = (int)fmin(fmax(lo[a], 0.0), size[a]);
        r[a + 2] = (int)fmin(fmax(hi[a], 0.0), size[a]);
        if (r[a + 2] < r[a])
            r[a + 2] = r[a];
    }
    return true;
}

/* Range i's pixel rectangle: its box's eight corners projected; the whole
 * image when a corner lies behind the eye. */
static void range_rect(const ps_aabb *b, const ps_camera_frame *cam, int r[4])
{
    ps_vec3 corner[8];
    for (int k = 0; k < 8; k++)
        corner[k] = ps_v3(k & 1 ? b->hi.x : b->lo.x, k & 2 ? b->hi.y : b->lo.y, k & 4 ? b->hi.z : b->lo.z);
    if (!points_rect(corner, 8, cam, 0.0, r))
        r[0] = 0, r[1] = 0, r[2] = cam->width, r[3] = cam->height;
}

/* Rectangle r's pixels cleared in `mask` (`width` bytes a row). */
static void clear_rect(unsigned char *mask, int width, const int r[4])
{
    for (int y = r[1]; y < r[3]; y++)
        memset(mask + (size_t)y * (size_t)width + r[0], 0, (size_t)(r[2] - r[0]));
}

/* The cube of the listed range of scene object `object`; -1: none. */
static int cube_of_object(const ps_specular *sp, uint32_t object)
{
    for (size_t i = 0; i < sp->range_count; i++)
        if (sp->mesh->ranges[sp->ranges[i].range].object == object)
            return sp->ranges[i].cube;
    return -1;
}

/* Pixel (x, y)'s samples into `out`: each eye ray that meets an object of
 * the layer first is traced as the vertices' rays are (scatter, follow),
 * from the exact surface point it meets and the cube's own centre. */
static bool trace_pixel(const ps_specular *sp, path_ctx *c, const ps_camera_frame *cam, int x, int y,
                        point_set *out)
{
    const int n = PS_SPECULAR_PIXEL_SAMPLES;
    const double share = 1.0 / (n * n);
    for (int j = 0; j < n; j++) {
        for (int i = 0; i < n; i++) {
            ps_ray ray = ps_camera_ray(cam, x + (i + 0.5) / n, y + (j + 0.5) / n);
            ps_surface hit;
            if (!ps_world_intersect(c->world, ray, INFINITY, &hit))
                continue;
            const ps_material *m = &c->materials[hit.material];
            int cube = ps_material_is_specular(m) ? cube_of_object(sp, hit.object) : -1;
            if (cube < 0)
                continue;
            c->count = 0;
            c->dropped = 0.0;
            c->centre = sp->centre[cube];
            c->first = hit.t;
            scatter(c, &hit, m, ray.d, ps_rgb_gray(1.0), 0, hit.t);
            ps_specular_term t[PS_SPECULAR_TERMS];
            int k = keep_heaviest(c, t);
            for (int q = 0; q < k; q++)
                if (!point_set_add(out, (float)x, (float)y, &t[q], ps_rgb_scale(t[q].weight, share), cube,
                                   sp->lookup_centre[cube]))
                    return false;
        }
    }
    return true;
}

/* Pixels a job traces between looks at the clock. */
#define PIXELS_PER_JOB 128

/* A chunk of pixels (sp->pix_list, x y pairs) on the threads: job j traces
 * pixels [j * PIXELS_PER_JOB, ...) into sp->job_points[j]. */
typedef struct pixel_chunk {
    ps_specular *sp;
    const ps_world *world;
    const ps_camera_frame *cam;
    size_t pixels;
    bool failed[PS_JOBS_MAX_THREADS];
} pixel_chunk;

static void pixel_job(void *ctx, size_t job)
{
    pixel_chunk *ch = ctx;
    ps_specular *sp = ch->sp;
    point_set *out = &sp->job_points[job];
    out->count = 0;
    path_ctx c;
    c.world = ch->world;
    c.materials = ps_scene_materials(ps_world_scene(ch->world), &(size_t){0});
    c.far = scene_far(ch->world);
    c.escape_black = true;
    size_t end = (job + 1) * PIXELS_PER_JOB < ch->pixels ? (job + 1) * PIXELS_PER_JOB : ch->pixels;
    for (size_t i = job * PIXELS_PER_JOB; i < end; i++)
        if (!trace_pixel(sp, &c, ch->cam, sp->pix_list[2 * i], sp->pix_list[2 * i + 1], out)) {
            ch->failed[job] = true;
            return;
        }
}

/* A new camera frame: its rectangles, nothing traced yet. */
static bool start_pixels(ps_specular *sp, const ps_camera_frame *cam)
{
    if (sp->pix_have_cam && ps_camera_frame_equal(cam, &sp->pix_cam))
        return true;
    size_t pixels = (size_t)cam->width * (size_t)cam->height;
    if (sp->pix_seen_cap < pixels) {
        unsigned char *seen = realloc(sp->pix_seen, pixels);
        if (!seen) {
            sp->pix_have_cam = sp->pix_ready = false;
            return false; /* out of memory: the per-vertex lookups stay */
        }
        sp->pix_seen = seen;
        sp->pix_seen_cap = pixels;
    }
    /* Only pixels near a range's triangles are traced (the others are
     * marked seen): a box's rectangle holds many that no triangle of its
     * covers, whose rays meet something else (the ring's 1.3*10^5 rays at
     * 256^2 gave 2.9*10^4 points, 0.10 s on one core; 0.046 s so). Each
     * triangle's rectangle is wider by PIXEL_MARGIN, as the box's is, and
     * by PIXEL_CHORD_BULGE of itself. */
    memset(sp->pix_seen, 1, pixels);
    sp->pix_have_cam = true;
    sp->pix_ready = false;
    sp->pix_cam = *cam;
    sp->pix_range = sp->pix_next = 0;
    sp->pix_build.count = 0;
    for (size_t i = 0; i < sp->range_count; i++) {
        range_rect(&sp->range_box[i], cam, sp->rect[i]);
        /* Glossy ranges keep their per-vertex lobe lookups (the GL draws
         * them beside the points): no pixel of theirs is traced. */
        if (ps_glossy_wants(range_material(sp, sp->ranges[i].range))) {
            sp->rect[i][2] = sp->rect[i][0], sp->rect[i][3] = sp->rect[i][1];
            continue;
        }
        const ps_mesh_range *rg = &sp->mesh->ranges[sp->ranges[i].range];
        const int *box = sp->rect[i];
        size_t box_pixels = (size_t)(box[2] - box[0]) * (size_t)(box[3] - box[1]);
        /* Many triangles a pixel: its box (projecting them would cost more
         * than the rays it saves). */
        if (sp->pix_boxes || rg->count / 3 > PIXEL_TRIANGLES_MAX * box_pixels) {
            clear_rect(sp->pix_seen, cam->width, box);
            continue;
        }
        for (size_t v = 0; v + 2 < rg->count; v += 3) {
            ps_vec3 tri[3] = {vertex_pos(sp->mesh, rg->first + v), vertex_pos(sp->mesh, rg->first + v + 1),
                              vertex_pos(sp->mesh, rg->first + v + 2)};
            int r[4];
            if (!points_rect(tri, 3, cam, PIXEL_CHORD_BULGE, r)) { /* behind the eye: the box's whole rectangle */
                clear_rect(sp->pix_seen, cam->width, box);
                break;
            }
            clear_rect(sp->pix_seen, cam->width, r);
        }
    }
    return true;
}

/* Rays left for the frame: the rest of this rectangle and the whole of the
 * others (an upper bound; pixels seen in earlier rectangles are skipped). */
static size_t rays_left(const ps_specular *sp)
{
    if (!sp->pix_have_cam || sp->pix_range >= sp->range_count)
        return 0;
    size_t left = 0;
    for (size_t i = sp->pix_range; i < sp->range_count; i++) {
        const int *r = sp->rect[i];
        left += (size_t)(r[2] - r[0]) * (size_t)(r[3] - r[1]);
    }
    left -= sp->pix_next;
    return left * PS_SPECULAR_PIXEL_SAMPLES * PS_SPECULAR_PIXEL_SAMPLES + (left == 0);
}

size_t ps_specular_pixel_rays_left(ps_specular *sp, const ps_camera_frame *cam)
{
    if (sp->range_count == 0 || cam->width <= 0 || cam->height <= 0 || !start_pixels(sp, cam))
        return 0;
    return sp->pix_ready ? 0 : rays_left(sp);
}

/* The next pixels of the frame not seen yet, at most `max` of them, into
 * sp->pix_list: how many. */
static size_t next_pixels(ps_specular *sp, size_t max)
{
    size_t n = 0;
    while (n < max && sp->pix_range < sp->range_count) {
        const int *r = sp->rect[sp->pix_range];
        size_t w = (size_t)(r[2] - r[0]), count = w * (size_t)(r[3] - r[1]);
        if (sp->pix_next >= count) {
            sp->pix_range++, sp->pix_next = 0;
            continue;
        }
        int x = r[0] + (int)(sp->pix_next % w), y = r[1] + (int)(sp->pix_next / w);
        sp->pix_next++;
        size_t at = (size_t)y * (size_t)sp->pix_cam.width + (size_t)x;
        if (sp->pix_seen[at])
            continue;
        sp->pix_seen[at] = 1;
        sp->pix_list[2 * n] = x, sp->pix_list[2 * n + 1] = y;
        n++;
    }
    return n;
}

size_t ps_specular_update_pixels(ps_specular *sp, const ps_world *world, const ps_camera_frame *cam,
                                 size_t max_rays, double max_seconds)
{
    if (sp->range_count == 0 || cam->width <= 0 || cam->height <= 0 || !start_pixels(sp, cam))
        return 0;
    if (sp->pix_range >= sp->range_count)
        return 0;
    const size_t per_pixel = (size_t)PS_SPECULAR_PIXEL_SAMPLES * PS_SPECULAR_PIXEL_SAMPLES;
    size_t chunk = (size_t)sp->threads * PIXELS_PER_JOB;
    if (sp->pix_list_cap < chunk) {
        int *list = realloc(sp->pix_list, 2 * chunk * sizeof *list);
        if (!list) {
            sp->pix_have_cam = sp->pix_ready = false; /* out of memory: the per-vertex lookups stay */
            return 0;
        }
        sp->pix_list = list;
        sp->pix_list_cap = chunk;
    }
    size_t rays = 0;
    double t0 = max_seconds > 0.0 ? ps_now_seconds() : 0.0;
    while (sp->pix_range < sp->range_count && (max_rays == 0 || rays < max_rays)) {
        size_t want = chunk;
        if (max_rays > 0 && (max_rays - rays + per_pixel - 1) / per_pixel < want)
            want = (max_rays - rays + per_pixel - 1) / per_pixel;
        pixel_chunk ch = {.sp = sp, .world = world, .cam = cam};
        ch.pixels = next_pixels(sp, want);
        if (ch.pixels == 0)
            continue; /* the rectangles ended: the loop ends */
        size_t jobs = (ch.pixels + PIXELS_PER_JOB - 1) / PIXELS_PER_JOB;
        ps_run_jobs(jobs, sp->threads, pixel_job, &ch);
        for (size_t j = 0; j < jobs; j++)
            if (ch.failed[j] || !point_set_append(&sp->pix_build, &sp->job_points[j])) {
                sp->pix_have_cam = sp->pix_ready = false; /* out of memory: the per-vertex lookups stay */
                return 0;
            }
        rays += ch.pixels * per_pixel;
        if (max_seconds > 0.0 && ps_now_seconds() - t0 >= max_seconds)
            break;
    }
    if (sp->pix_range < sp->range_count)
        return rays_left(sp);
    point_set t = sp->pix_done;
    sp->pix_done = sp->pix_build;
    sp->pix_build = t;
    sp->pix_build.count = 0;
    sp->pix_ready = true;
    sp->changed = true;
    return 0;
}

ps_specular_points ps_specular_pixel_points(const ps_specular *sp)
{
    ps_specular_points p;
    memset(&p, 0, sizeof p);
    if (!sp->pix_ready)
        return p;
    p.ready = true;
    p.count = sp->pix_done.count;
    p.xy = sp->pix_done.xy;
    p.dirs = sp->pix_done.dirs;
    p.weights = sp->pix_done.weights;
    p.cube = sp->pix_done.cube;
    return p;
}
