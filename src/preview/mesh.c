/* mesh.c: subdividing the scene's triangles and tessellating its spheres. */
#include "preview/mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/array.h"
#include "core/hash.h"
#include "core/memory.h"
#include "scene/tessellate.h"

/* The default: a 64th of the scene's diagonal keeps Gouraud lighting of a
 * point light within about 0.1 % (see mesh.h) at a few hundred thousand
 * triangles for a room. */
#define MESH_EDGE_FRACTION (1.0 / 64.0)

typedef struct builder {
    ps_preview_mesh *m;
    size_t cap_pos, cap_nrm, cap_ranges, cap_uv;
    bool uv; /* the scene has textures: keep texture coordinates */
} builder;

ps_mesh_options ps_mesh_default_options(const ps_scene *s)
{
    ps_mesh_options o;
    double diag = ps_v3_len(ps_aabb_diag(ps_scene_bounds(s)));
    o.max_edge = diag > 0.0 && isfinite(diag) ? diag * MESH_EDGE_FRACTION : 1.0;
    o.sphere_tolerance = PS_SPHERE_DEFAULT_TOLERANCE;
    return o;
}

ps_mesh_options ps_mesh_moving_options(const ps_mesh_options *fine)
{
    ps_mesh_options o = *fine;
    o.max_edge *= PS_MESH_MOVING_EDGE_SCALE;
    return o;
}

static bool reserve(builder *b, size_t vertices)
{
    size_t need = b->m->vertex_count + vertices;
    if (need > SIZE_MAX / 3)
        return false;
    return PS_RESERVE(b->m->positions, b->cap_pos, 3 * need) && PS_RESERVE(b->m->normals, b->cap_nrm, 3 * need) &&
           (!b->uv || PS_RESERVE(b->m->texcoords, b->cap_uv, 2 * need));
}

/* How many pieces add_triangle cuts each side of a triangle into. */
static int split_count(const ps_vec3 p[3], double max_edge)
{
    double longest = fmax(ps_v3_len(ps_v3_sub(p[1], p[0])),
                          fmax(ps_v3_len(ps_v3_sub(p[2], p[1])), ps_v3_len(ps_v3_sub(p[0], p[2]))));
    double want = ceil(longest / max_edge);
    return !(want >= 1.0) ? 1 : want > PS_MESH_MAX_SPLIT ? PS_MESH_MAX_SPLIT : (int)want;
}

/* The vertices the mesh will have, counted before anything is allocated
 * (a room of huge quads or a million spheres must be refused, not built). */
static uint64_t count_vertices(const ps_scene *s, const ps_mesh_options *o, double max_edge)
{
    size_t nobj, ntri, npos;
    const ps_object *objects = ps_scene_objects(s, &nobj);
    const ps_triangle *tris = ps_scene_triangles(s, &ntri);
    const ps_vec3 *pos = ps_scene_positions(s, &npos);
    uint64_t n = 0;
    for (size_t i = 0; i < nobj; i++) {
        const ps_object *obj = &objects[i];
        if (obj->type == PS_OBJ_SPHERE) {
            n += 3 * (uint64_t)ps_sphere_triangle_count(o->sphere_tolerance);
            continue;
        }
        for (uint32_t t = obj->first_triangle; t < obj->first_triangle + obj->triangle_count; t++) {
            ps_vec3 p[3] = {pos[tris[t].v[0]], pos[tris[t].v[1]], pos[tris[t].v[2]]};
            uint64_t split = (uint64_t)split_count(p, max_edge);
            n += 3 * split * split;
        }
    }
    return n;
}

static void put(builder *b, ps_vec3 p, ps_vec3 n, ps_uv uv)
{
    if (b->uv) {
        b->m->texcoords[2 * b->m->vertex_count] = (float)uv.u;
        b->m->texcoords[2 * b->m->vertex_count + 1] = (float)(1.0 - uv.v);
    }
    size_t k = 3 * b->m->vertex_count++;
    b->m->positions[k] = (float)p.x;
    b->m->positions[k + 1] = (float)p.y;
    b->m->positions[k + 2] = (float)p.z;
    b->m->normals[k] = (float)n.x;
    b->m->normals[k + 1] = (float)n.y;
    b->m->normals[k + 2] = (float)n.z;
}

/* Opens a range for (object, material) unless the last one is the same. */
static bool begin_range(builder *b, uint32_t object, uint32_t material)
{
    ps_preview_mesh *m = b->m;
    if (m->range_count) {
        ps_mesh_range *last = &m->ranges[m->range_count - 1];
        if (last->object == object && last->material == material)
            return true;
    }
    if (!PS_RESERVE(m->ranges, b->cap_ranges, m->range_count + 1))
        return false;
    ps_mesh_range r = {object, material, m->vertex_count, 0};
    m->ranges[m->range_count++] = r;
    return true;
}

static void end_range(builder *b)
{
    ps_mesh_range *r = &b->m->ranges[b->m->range_count - 1];
    r->count = b->m->vertex_count - r->first;
}

/* Barycentric point (a, b) of triangle (p0, p1, p2) with its interpolated
 * unit normal and texture coordinates. */
static void corner(const ps_vec3 p[3], const ps_vec3 n[3], const ps_uv t[3], double a, double c, ps_vec3 *pos,
                   ps_vec3 *nrm, ps_uv *uv)
{
    double w0 = 1.0 - a - c;
    *uv = (ps_uv){w0 * t[0].u + a * t[1].u + c * t[2].u, w0 * t[0].v + a * t[1].v + c * t[2].v};
    *pos = ps_v3_add(ps_v3_add(ps_v3_scale(p[0], w0), ps_v3_scale(p[1], a)), ps_v3_scale(p[2], c));
    *nrm = ps_v3_norm(ps_v3_add(ps_v3_add(ps_v3_scale(n[0], w0), ps_v3_scale(n[1], a)), ps_v3_scale(n[2], c)));
}

/* Cuts triangle (p, n) into split^2 similar triangles, same winding. */
static bool add_triangle(builder *b, const ps_vec3 p[3], const ps_vec3 n[3], const ps_uv t[3], double max_edge)
{
    int split = split_count(p, max_edge);
    if (!reserve(b, 3 * (size_t)split * (size_t)split))
        return false;
    double inv = 1.0 / split;
    for (int i = 0; i < split; i++)
        for (int j = 0; i + j < split; j++) {
            /* The upright cell (i, j), and the inverted one beside it. */
            ps_vec3 q[4], m[4];
            ps_uv w[4];
            corner(p, n, t, i * inv, j * inv, &q[0], &m[0], &w[0]);
            corner(p, n, t, (i + 1) * inv, j * inv, &q[1], &m[1], &w[1]);
            corner(p, n, t, i * inv, (j + 1) * inv, &q[2], &m[2], &w[2]);
            put(b, q[0], m[0], w[0]);
            put(b, q[1], m[1], w[1]);
            put(b, q[2], m[2], w[2]);
            if (i + j + 1 < split) {
                corner(p, n, t, (i + 1) * inv, (j + 1) * inv, &q[3], &m[3], &w[3]);
                put(b, q[1], m[1], w[1]);
                put(b, q[3], m[3], w[3]);
                put(b, q[2], m[2], w[2]);
            }
        }
    return true;
}

static bool add_sphere(builder *b, const ps_object *o, double tolerance, ps_error *err, ps_status *st)
{
    ps_trimesh tm;
    *st = ps_sphere_tessellate(o->center, o->radius, tolerance, &tm, err);
    if (*st != PS_OK)
        return false;
    bool ok = reserve(b, 3 * (size_t)tm.triangle_count);
    for (uint32_t t = 0; ok && t < tm.triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = tm.indices[3 * t + k];
            put(b, tm.positions[v], tm.normals[v], (ps_uv){0.0, 0.0});
        }
    ps_trimesh_free(&tm);
    if (!ok)
        *st = PS_ERR_NOMEM;
    return ok;
}

/* Vertex v's position and normal bits. */
static void vertex_key(const ps_preview_mesh *m, size_t v, uint32_t key[6])
{
    memcpy(key, m->positions + 3 * v, 3 * sizeof(float));
    memcpy(key + 3, m->normals + 3 * v, 3 * sizeof(float));
}

/* m->shared (mesh.h), range by range, with an open-addressing table of
 * twice the range's size. */
static bool share_vertices(ps_preview_mesh *m)
{
    m->shared = malloc((m->vertex_count ? m->vertex_count : 1) * sizeof *m->shared);
    size_t largest = 0;
    for (size_t r = 0; r < m->range_count; r++)
        largest = m->ranges[r].count > largest ? m->ranges[r].count : largest;
    size_t cap = 16;
    while (cap < 2 * largest)
        cap *= 2;
    uint32_t *table = malloc(cap * sizeof *table);
    if (!m->shared || !table || m->vertex_count > UINT32_MAX) {
        free(table);
        return false;
    }
    for (size_t r = 0; r < m->range_count; r++) {
        const ps_mesh_range *rg = &m->ranges[r];
        memset(table, 0xff, cap * sizeof *table);
        for (size_t v = rg->first; v < rg->first + rg->count; v++) {
            uint32_t key[6], other[6];
            vertex_key(m, v, key);
            size_t slot = (size_t)ps_hash_words(key, 6, r) & (cap - 1);
            for (;;) {
                uint32_t u = table[slot];
                if (u == UINT32_MAX) {
                    table[slot] = (uint32_t)v;
                    m->shared[v] = (uint32_t)v;
                    break;
                }
                vertex_key(m, u, other);
                if (memcmp(key, other, sizeof key) == 0) {
                    m->shared[v] = u;
                    break;
                }
                slot = (slot + 1) & (cap - 1);
            }
        }
    }
    free(table);
    return true;
}

uint64_t ps_preview_mesh_vertex_count(const ps_scene *s, const ps_mesh_options *o)
{
    return count_vertices(s, o, o->max_edge > 0.0 ? o->max_edge : 1.0);
}

ps_status ps_preview_mesh_build(const ps_scene *s, const ps_mesh_options *o, ps_preview_mesh *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    builder b = {out, 0, 0, 0, 0, ps_scene_texture_count(s) > 0};
    size_t nuv;
    const ps_uv *uvs = ps_scene_texcoords(s, &nuv);
    size_t nobj, ntri, npos, nnrm;
    const ps_object *objects = ps_scene_objects(s, &nobj);
    const ps_triangle *tris = ps_scene_triangles(s, &ntri);
    const ps_vec3 *pos = ps_scene_positions(s, &npos);
    const ps_vec3 *nrm = ps_scene_normals(s, &nnrm);
    double max_edge = o->max_edge > 0.0 ? o->max_edge : 1.0;
    uint64_t vertices = count_vertices(s, o, max_edge);
    char what[96];
    snprintf(what, sizeof what, "the preview mesh of %llu triangles", (unsigned long long)(vertices / 3));
    ps_status st = ps_memory_check(
        ps_memory_mul(vertices, PS_MESH_PLAN_VERTEX_BYTES + (b.uv ? PS_MESH_PLAN_UV_BYTES : 0)), ps_scene_path(s), what,
        err);
    if (st != PS_OK)
        return st;
    for (size_t i = 0; i < nobj && st == PS_OK; i++) {
        const ps_object *obj = &objects[i];
        if (obj->type == PS_OBJ_SPHERE) {
            if (!begin_range(&b, (uint32_t)i, obj->material)) {
                st = PS_ERR_NOMEM;
                break;
            }
            if (!add_sphere(&b, obj, o->sphere_tolerance, err, &st))
                break;
            end_range(&b);
            continue;
        }
        for (uint32_t t = obj->first_triangle; t < obj->first_triangle + obj->triangle_count; t++) {
            const ps_triangle *tri = &tris[t];
            ps_vec3 p[3], n[3], face = ps_scene_triangle_normal(s, t);
            ps_uv uv[3];
            for (int k = 0; k < 3; k++) {
                p[k] = pos[tri->v[k]];
                uv[k] = tri->t[k] >= 0 ? uvs[tri->t[k]] : (ps_uv){0.0, 0.0};
                n[k] = tri->n[k] >= 0 ? nrm[tri->n[k]] : face;
                /* Normals on the winding's side, as the ray tracers use them. */
                if (ps_v3_dot(n[k], face) < 0.0)
                    n[k] = ps_v3_neg(n[k]);
            }
            if (!begin_range(&b, (uint32_t)i, tri->material) || !add_triangle(&b, p, n, uv, max_edge)) {
                st = PS_ERR_NOMEM;
                break;
            }
            end_range(&b);
        }
    }
    if (st == PS_OK && !share_vertices(out))
        st = PS_ERR_NOMEM;
    if (st != PS_OK) {
        ps_preview_mesh_free(out);
        if (st == PS_ERR_NOMEM)
            ps_error_set(err, st, "%s: out of memory for the preview mesh", ps_scene_path(s));
        return st;
    }
    return PS_OK;
}

void ps_preview_mesh_free(ps_preview_mesh *m)
{
    if (!m)
        return;
    free(m->positions);
    free(m->normals);
    free(m->texcoords);
    free(m->shared);
    free(m->ranges);
    ps_mesh_tiling_free(&m->tiles);
    memset(m, 0, sizeof *m);
}

/* ---- tiles --------------------------------------------------------------------------- */

/* Axes shorter than this share of the longest are flat: not cut. */
#define TILE_FLAT_SHARE 1e-3

static ps_vec3 vertex_at(const ps_preview_mesh *m, size_t j, uint32_t *index)
{
    *index = m->shared ? m->shared[j] : (uint32_t)j;
    const float *q = m->positions + 3 * (size_t)*index;
    return ps_v3(q[0], q[1], q[2]);
}

/* Range rg's grid: cells a side (1 on flat axes) for about `cells` cells. */
static void tile_grid(ps_aabb b, double cells, int n[3])
{
    double e[3] = {b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z};
    double longest = fmax(e[0], fmax(e[1], e[2]));
    double volume = 1.0;
    int dims = 0;
    for (int a = 0; a < 3; a++)
        if (e[a] > TILE_FLAT_SHARE * longest)
            volume *= e[a], dims++;
    double side = dims > 0 ? pow(volume / fmax(cells, 1.0), 1.0 / dims) : 1.0;
    for (int a = 0; a < 3; a++) {
        double k = e[a] > TILE_FLAT_SHARE * longest && side > 0.0 ? floor(e[a] / side + 0.5) : 1.0;
        n[a] = (int)fmin(fmax(k, 1.0), 64.0);
    }
}

static int grid_cell(double v, double lo, double hi, int n)
{
    if (n <= 1 || !(hi > lo))
        return 0;
    int c = (int)((v - lo) / (hi - lo) * n);
    return c < 0 ? 0 : c >= n ? n - 1 : c;
}

ps_status ps_mesh_make_tiles(const ps_preview_mesh *m, size_t triangles_per_tile, ps_mesh_tiling *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    size_t per = triangles_per_tile > 0 ? triangles_per_tile : 1;
    size_t most_cells = 0, total_tiles = 0;
    int (*grids)[3] = calloc(m->range_count ? m->range_count : 1, sizeof *grids);
    out->range_tiles = calloc(m->range_count + 1, sizeof *out->range_tiles);
    out->indices = malloc((m->vertex_count ? m->vertex_count : 1) * sizeof *out->indices);
    ps_aabb *bounds = malloc((m->range_count ? m->range_count : 1) * sizeof *bounds);
    if (!grids || !out->range_tiles || !out->indices || !bounds) {
        free(grids), free(bounds);
        ps_mesh_tiling_free(out);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory tiling the preview mesh");
    }
    out->range_count = m->range_count;
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_mesh_range *rg = &m->ranges[i];
        ps_aabb b = ps_aabb_empty();
        uint32_t v;
        for (size_t j = rg->first; j < rg->first + rg->count; j++)
            b = ps_aabb_point(b, vertex_at(m, j, &v));
        bounds[i] = b;
        size_t tris = rg->count / 3;
        if (tris > per)
            tile_grid(b, (double)tris / (double)per, grids[i]);
        else
            grids[i][0] = grids[i][1] = grids[i][2] = 1;
        size_t cells = (size_t)grids[i][0] * (size_t)grids[i][1] * (size_t)grids[i][2];
        most_cells = cells > most_cells ? cells : most_cells;
        total_tiles += cells < tris ? cells : tris > 0 ? tris : 1;
    }
    out->tiles = malloc(total_tiles * sizeof *out->tiles);
    size_t *start = calloc(most_cells + 1, sizeof *start);
    uint32_t *cell_of = malloc((m->vertex_count / 3 + 1) * sizeof *cell_of);
    if (!out->tiles || !start || !cell_of) {
        free(grids), free(bounds), free(start), free(cell_of);
        ps_mesh_tiling_free(out);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory tiling the preview mesh");
    }
    size_t written = 0;
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_mesh_range *rg = &m->ranges[i];
        const int *n = grids[i];
        size_t cells = (size_t)n[0] * (size_t)n[1] * (size_t)n[2], tris = rg->count / 3;
        ps_aabb b = bounds[i];
        out->range_tiles[i] = out->tile_count;
        /* A counting sort by cell: stable, so each cell keeps the
         * triangles' order (and GL's vertex cache its reuse). */
        memset(start, 0, (cells + 1) * sizeof *start);
        for (size_t t = 0; t < tris; t++) {
            ps_vec3 c = ps_v3(0, 0, 0);
            uint32_t v;
            for (int k = 0; k < 3; k++)
                c = ps_v3_add(c, vertex_at(m, rg->first + 3 * t + (size_t)k, &v));
            c = ps_v3_scale(c, 1.0 / 3.0);
            size_t cell = (size_t)grid_cell(c.x, b.lo.x, b.hi.x, n[0]) +
                          (size_t)n[0] * ((size_t)grid_cell(c.y, b.lo.y, b.hi.y, n[1]) +
                                          (size_t)n[1] * (size_t)grid_cell(c.z, b.lo.z, b.hi.z, n[2]));
            cell_of[t] = (uint32_t)cell;
            start[cell + 1]++;
        }
        for (size_t c = 0; c < cells; c++)
            start[c + 1] += start[c];
        for (size_t c = 0; c < cells; c++)
            if (start[c + 1] > start[c]) {
                ps_mesh_tile *tile = &out->tiles[out->tile_count++];
                tile->first = written + 3 * start[c];
                tile->count = 3 * (start[c + 1] - start[c]);
                tile->bounds = ps_aabb_empty();
            }
        /* start[c] now walks cell c's slots. */
        for (size_t t = 0; t < tris; t++) {
            size_t slot = start[cell_of[t]]++;
            for (int k = 0; k < 3; k++) {
                uint32_t v;
                vertex_at(m, rg->first + 3 * t + (size_t)k, &v);
                out->indices[written + 3 * slot + (size_t)k] = v;
            }
        }
        for (size_t x = out->range_tiles[i]; x < out->tile_count; x++) {
            ps_mesh_tile *tile = &out->tiles[x];
            for (size_t j = tile->first; j < tile->first + tile->count; j++) {
                const float *q = m->positions + 3 * (size_t)out->indices[j];
                tile->bounds = ps_aabb_point(tile->bounds, ps_v3(q[0], q[1], q[2]));
            }
        }
        written += 3 * tris;
    }
    out->range_tiles[m->range_count] = out->tile_count;
    free(grids), free(bounds), free(start), free(cell_of);
    return PS_OK;
}

void ps_mesh_tiling_free(ps_mesh_tiling *t)
{
    if (!t)
        return;
    free(t->tiles);
    free(t->indices);
    free(t->range_tiles);
    memset(t, 0, sizeof *t);
}
