/* illummap.c: the global map as irradiance on the fine mesh's vertices (illummap.h). */
#include "preview/illummap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/array.h"
#include "core/memory.h"

const char *const ps_global_layer_names[PS_GLOBAL_LAYER_COUNT + 1] = {"splats", "maps", NULL};

const char *ps_global_layer_name(ps_global_layer g)
{
    return (unsigned)g < PS_GLOBAL_LAYER_COUNT ? ps_global_layer_names[g] : "?";
}

#define NO_SAMPLE UINT32_MAX
/* Both sides' irradiance, rgb each. */
#define SUMS 6

struct ps_illummap {
    const ps_preview_mesh *mesh;
    const ps_material *scene_materials;
    size_t material_count;
    ps_kernel kernel;
    /* Samples: position, normal (unit), object, area, and both sides' sums. */
    size_t samples;
    float *pos, *nrm;
    uint32_t *obj;
    double *area;
    double *sum;
    uint32_t *vsample; /* fine-mesh vertex -> sample, or NO_SAMPLE (no diffuse reflection) */
    float *front, *back;
    /* The grid: cubic cells of side `radius`, hashed into `buckets` (a power
     * of two) lists; first[b]..first[b + 1] index items. */
    size_t buckets;
    uint32_t *first, *items;
    double radius;      /* the level the sums are at; 0: empty */
    size_t count;       /* photons added */
    bool changed;
    double longest_edge;
    ps_rgb lost;
    /* The lobe list. */
    ps_photon *lobe_ph;
    uint16_t *lobe_mat;
    uint32_t *lobe_obj;
    size_t lobe_n, cap_ph, cap_mat, cap_obj;
    /* Scratch: one photon's samples (side in the top bit) and weights. */
    uint32_t *nb;
    double *nbw;
    size_t cap_nb, cap_nbw;
};

ps_rgb ps_illummap_albedo(const ps_material *mat)
{
    if (mat->type == PS_MAT_DIFFUSE || mat->type == PS_MAT_GLOSSY)
        return mat->albedo;
    return ps_rgb_gray(0.0);
}

static bool reflects_diffusely(const ps_material *mat) { return mat->type == PS_MAT_DIFFUSE || mat->type == PS_MAT_GLOSSY; }

/* ---- welding -------------------------------------------------------------------- */

typedef struct weld_key {
    int64_t q[6];
    uint32_t obj;
} weld_key;

static weld_key key_of(const float *p, const float *n, uint32_t obj, double step)
{
    weld_key k;
    for (int a = 0; a < 3; a++) {
        k.q[a] = (int64_t)llround(p[a] / step);
        k.q[3 + a] = (int64_t)llround(n[a] / PS_ILLUM_WELD_NORMAL);
    }
    k.obj = obj;
    return k;
}

static uint64_t hash_key(const weld_key *k)
{
    uint64_t h = 1469598103934665603ull ^ k->obj;
    for (int a = 0; a < 6; a++) {
        h ^= (uint64_t)k->q[a];
        h *= 1099511628211ull;
        h ^= h >> 29;
    }
    return h;
}

static bool same_key(const weld_key *a, const weld_key *b) { return a->obj == b->obj && !memcmp(a->q, b->q, sizeof a->q); }

static size_t pow2_at_least(size_t n)
{
    size_t p = 16;
    while (p < n)
        p *= 2;
    return p;
}

/* Welds the vertices of ranges with diffuse reflection into samples. */
static ps_status weld(ps_illummap *m, double step, ps_error *err)
{
    const ps_preview_mesh *mesh = m->mesh;
    size_t nv = mesh->vertex_count;
    size_t tsize = pow2_at_least(2 * nv + 1);
    uint32_t *table = malloc(tsize * sizeof *table);
    weld_key *keys = malloc((nv ? nv : 1) * sizeof *keys);
    if (!table || !keys) {
        free(table);
        free(keys);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory welding the illumination maps' samples");
    }
    for (size_t i = 0; i < tsize; i++)
        table[i] = NO_SAMPLE;
    size_t n = 0;
    for (size_t r = 0; r < mesh->range_count; r++) {
        const ps_mesh_range *rg = &mesh->ranges[r];
        bool diffuse = rg->material < m->material_count && reflects_diffusely(&m->scene_materials[rg->material]);
        for (size_t v = rg->first; v < rg->first + rg->count; v++) {
            m->vsample[v] = NO_SAMPLE;
            if (!diffuse)
                continue;
            const float *p = mesh->positions + 3 * v, *nn = mesh->normals + 3 * v;
            weld_key k = key_of(p, nn, rg->object, step);
            size_t h = (size_t)hash_key(&k) & (tsize - 1);
            while (table[h] != NO_SAMPLE && !same_key(&keys[table[h]], &k))
                h = (h + 1) & (tsize - 1);
            if (table[h] == NO_SAMPLE) {
                table[h] = (uint32_t)n;
                keys[n] = k;
                memcpy(m->pos + 3 * n, p, 3 * sizeof *p);
                memcpy(m->nrm + 3 * n, nn, 3 * sizeof *nn);
                m->obj[n] = rg->object;
                m->area[n] = 0.0;
                n++;
            }
            m->vsample[v] = table[h];
        }
    }
    free(table);
    free(keys);
    m->samples = n;
    /* Areas: a third of each triangle to each of its corners' samples. */
    m->longest_edge = 0.0;
    for (size_t v = 0; v + 2 < nv; v += 3) {
        if (m->vsample[v] == NO_SAMPLE)
            continue;
        ps_vec3 q[3];
        for (int c = 0; c < 3; c++) {
            const float *p = mesh->positions + 3 * (v + (size_t)c);
            q[c] = ps_v3(p[0], p[1], p[2]);
        }
        double a = 0.5 * ps_v3_len(ps_v3_cross(ps_v3_sub(q[1], q[0]), ps_v3_sub(q[2], q[0])));
        for (int c = 0; c < 3; c++) {
            m->area[m->vsample[v + (size_t)c]] += a / 3.0;
            m->longest_edge = fmax(m->longest_edge, ps_v3_len(ps_v3_sub(q[(c + 1) % 3], q[c])));
        }
    }
    return PS_OK;
}

ps_status ps_illummap_create(const ps_scene *scene, const ps_preview_mesh *mesh, ps_kernel kernel, ps_illummap **out,
                             ps_error *err)
{
    *out = NULL;
    size_t nv = mesh->vertex_count;
    if (nv > PS_ILLUM_MAX_SAMPLES)
        return ps_error_set(err, PS_ERR_LIMIT,
                            "%s: the illumination maps' %zu vertices exceed their cap of %zu (use --global-layer splats)",
                            ps_scene_path(scene), nv, (size_t)PS_ILLUM_MAX_SAMPLES);
    char what[96];
    snprintf(what, sizeof what, "the illumination maps of %zu vertices", nv);
    ps_status st = ps_memory_check(ps_memory_mul(nv, PS_ILLUM_PLAN_VERTEX_BYTES), ps_scene_path(scene), what, err);
    if (st != PS_OK)
        return st;
    ps_illummap *m = calloc(1, sizeof *m);
    if (!m)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the illumination maps", ps_scene_path(scene));
    m->mesh = mesh;
    m->scene_materials = ps_scene_materials(scene, &m->material_count);
    m->kernel = kernel;
    size_t n1 = nv ? nv : 1;
    m->pos = malloc(3 * n1 * sizeof *m->pos);
    m->nrm = malloc(3 * n1 * sizeof *m->nrm);
    m->obj = malloc(n1 * sizeof *m->obj);
    m->area = malloc(n1 * sizeof *m->area);
    m->vsample = malloc(n1 * sizeof *m->vsample);
    m->front = calloc(4 * n1, sizeof *m->front);
    m->back = calloc(4 * n1, sizeof *m->back);
    st = m->pos && m->nrm && m->obj && m->area && m->vsample && m->front && m->back ? PS_OK : PS_ERR_NOMEM;
    if (st != PS_OK)
        ps_error_set(err, st, "%s: out of memory for the illumination maps", ps_scene_path(scene));
    double diag = ps_v3_len(ps_aabb_diag(ps_scene_bounds(scene)));
    double step = (diag > 0.0 && isfinite(diag) ? diag : 1.0) * PS_ILLUM_WELD_FRACTION;
    if (st == PS_OK)
        st = weld(m, step, err);
    if (st == PS_OK) {
        size_t ns = m->samples ? m->samples : 1;
        m->buckets = pow2_at_least(ns);
        m->sum = calloc(SUMS * ns, sizeof *m->sum);
        m->first = malloc((m->buckets + 1) * sizeof *m->first);
        m->items = malloc(ns * sizeof *m->items);
        if (!m->sum || !m->first || !m->items)
            st = ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the illumination maps", ps_scene_path(scene));
    }
    if (st != PS_OK) {
        ps_illummap_destroy(m);
        return st;
    }
    *out = m;
    return PS_OK;
}

void ps_illummap_destroy(ps_illummap *m)
{
    if (!m)
        return;
    free(m->pos);
    free(m->nrm);
    free(m->obj);
    free(m->area);
    free(m->sum);
    free(m->vsample);
    free(m->front);
    free(m->back);
    free(m->first);
    free(m->items);
    free(m->lobe_ph);
    free(m->lobe_mat);
    free(m->lobe_obj);
    free(m->nb);
    free(m->nbw);
    free(m);
}

void ps_illummap_reset(ps_illummap *m, ps_kernel kernel)
{
    m->kernel = kernel;
    memset(m->sum, 0, SUMS * (m->samples ? m->samples : 1) * sizeof *m->sum);
    m->count = 0;
    m->radius = 0.0;
    m->lobe_n = 0;
    m->lost = ps_rgb_gray(0.0);
    m->changed = true;
}

double ps_illummap_level_radius(const ps_illummap *m, double r0, double r)
{
    double level = r;
    if (r0 > 0.0 && r > 0.0 && isfinite(r)) {
        /* r0 * 2^(j/2), j the smallest integer giving at least r. */
        double j = ceil(2.0 * log2(r / r0));
        level = r0 * exp2(0.5 * j);
        if (level < r)
            level = r0 * exp2(0.5 * (j + 1.0));
    }
    return fmax(level, m->longest_edge);
}

/* ---- the grid -------------------------------------------------------------------- */

typedef struct cell3 {
    int64_t x, y, z;
} cell3;

static cell3 cell_of(double x, double y, double z, double inv)
{
    cell3 c = {(int64_t)floor(x * inv), (int64_t)floor(y * inv), (int64_t)floor(z * inv)};
    return c;
}

static size_t bucket_of(cell3 c, size_t buckets)
{
    uint64_t h = (uint64_t)c.x * 73856093ull ^ (uint64_t)c.y * 19349663ull ^ (uint64_t)c.z * 83492791ull;
    h ^= h >> 31;
    h *= 0x9e3779b97f4a7c15ull;
    return (size_t)(h >> 20) & (buckets - 1);
}

/* Cells of side radius: every sample within radius of a point lies in the
 * 27 cells around the point's. */
static void build_grid(ps_illummap *m, double radius)
{
    double inv = 1.0 / radius;
    memset(m->first, 0, (m->buckets + 1) * sizeof *m->first);
    for (size_t s = 0; s < m->samples; s++) {
        const float *p = m->pos + 3 * s;
        m->first[bucket_of(cell_of(p[0], p[1], p[2], inv), m->buckets) + 1]++;
    }
    for (size_t b = 0; b < m->buckets; b++)
        m->first[b + 1] += m->first[b];
    /* Filled in sample order, each bucket's list ascending: a fixed order. */
    for (size_t s = 0; s < m->samples; s++) {
        const float *p = m->pos + 3 * s;
        size_t b = bucket_of(cell_of(p[0], p[1], p[2], inv), m->buckets);
        m->items[m->first[b]++] = (uint32_t)s;
    }
    /* first[b] now holds the end of bucket b: shift back. */
    for (size_t b = m->buckets; b > 0; b--)
        m->first[b] = m->first[b - 1];
    m->first[0] = 0;
}

/* ---- adding photons --------------------------------------------------------------- */

static ps_status add_photon(ps_illummap *m, const ps_photon *ph, uint32_t object, ps_error *err)
{
    double r = m->radius, r2 = r * r, inv = 1.0 / r;
    ps_vec3 p = ps_photon_position(ph), n = ps_photon_normal(ph);
    cell3 c = cell_of(p.x, p.y, p.z, inv);
    size_t k = 0;
    double total = 0.0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                cell3 cc = {c.x + dx, c.y + dy, c.z + dz};
                size_t b = bucket_of(cc, m->buckets);
                for (uint32_t i = m->first[b]; i < m->first[b + 1]; i++) {
                    uint32_t s = m->items[i];
                    if (m->obj[s] != object)
                        continue;
                    const float *q = m->pos + 3 * s;
                    double ex = q[0] - p.x, ey = q[1] - p.y, ez = q[2] - p.z;
                    double d2 = ex * ex + ey * ey + ez * ez;
                    if (d2 >= r2)
                        continue;
                    /* Other cells sharing this bucket: each sample counts in its own cell only. */
                    cell3 sc = cell_of(q[0], q[1], q[2], inv);
                    if (sc.x != cc.x || sc.y != cc.y || sc.z != cc.z)
                        continue;
                    const float *sn = m->nrm + 3 * s;
                    double cs = sn[0] * n.x + sn[1] * n.y + sn[2] * n.z;
                    if (fabs(cs) < PS_ILLUM_MIN_COS)
                        continue;
                    double g = ps_kernel_profile(m->kernel, sqrt(d2) * inv);
                    if (!(g > 0.0))
                        continue;
                    if (!PS_RESERVE(m->nb, m->cap_nb, k + 1) || !PS_RESERVE(m->nbw, m->cap_nbw, k + 1))
                        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the illumination maps' estimate");
                    m->nb[k] = s | (cs < 0.0 ? 0x80000000u : 0u);
                    m->nbw[k] = g;
                    total += g * m->area[s];
                    k++;
                }
            }
    ps_rgb power = ps_photon_power(ph);
    if (!(total > 0.0)) {
        m->lost = ps_rgb_add(m->lost, power);
        return PS_OK;
    }
    /* E_s += Phi w_s / A_s = Phi g_s / sum_t g_t A_t. */
    double scale = 1.0 / total;
    for (size_t j = 0; j < k; j++) {
        uint32_t s = m->nb[j] & 0x7fffffffu;
        double *e = m->sum + SUMS * s + ((m->nb[j] & 0x80000000u) ? 3 : 0);
        double w = m->nbw[j] * scale;
        e[0] += power.r * w;
        e[1] += power.g * w;
        e[2] += power.b * w;
    }
    return PS_OK;
}

ps_status ps_illummap_update(ps_illummap *m, const ps_photon *photons, const uint16_t *materials,
                             const uint32_t *objects, size_t count, double radius, size_t *added, ps_error *err)
{
    *added = 0;
    if (radius != m->radius || count < m->count) {
        ps_illummap_reset(m, m->kernel);
        m->radius = radius;
        if (radius > 0.0)
            build_grid(m, radius);
    }
    if (!(m->radius > 0.0))
        return PS_OK;
    for (size_t i = m->count; i < count; i++) {
        uint16_t mat = materials[i];
        ps_status st = add_photon(m, &photons[i], objects[i], err);
        if (st == PS_OK && mat < m->material_count && m->scene_materials[mat].type == PS_MAT_GLOSSY) {
            size_t need = m->lobe_n + 1;
            if (!PS_RESERVE(m->lobe_ph, m->cap_ph, need) || !PS_RESERVE(m->lobe_mat, m->cap_mat, need) ||
                !PS_RESERVE(m->lobe_obj, m->cap_obj, need))
                st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for the illumination maps' glossy photons");
            else {
                m->lobe_ph[m->lobe_n] = photons[i];
                m->lobe_mat[m->lobe_n] = mat;
                m->lobe_obj[m->lobe_n] = objects[i];
                m->lobe_n++;
            }
        }
        if (st != PS_OK) {
            ps_illummap_reset(m, m->kernel);
            return st;
        }
        (*added)++;
    }
    m->count = count > m->count ? count : m->count;
    if (*added)
        m->changed = true;
    return PS_OK;
}

size_t ps_illummap_count(const ps_illummap *m) { return m->count; }
double ps_illummap_radius(const ps_illummap *m) { return m->radius; }
bool ps_illummap_changed(const ps_illummap *m) { return m->changed; }
size_t ps_illummap_sample_count(const ps_illummap *m) { return m->samples; }
ps_rgb ps_illummap_lost(const ps_illummap *m) { return m->lost; }

ps_rgb ps_illummap_irradiance(const ps_illummap *m, size_t s, int side, ps_vec3 *pos, ps_vec3 *normal, double *area)
{
    const float *p = m->pos + 3 * s, *n = m->nrm + 3 * s;
    if (pos)
        *pos = ps_v3(p[0], p[1], p[2]);
    if (normal)
        *normal = ps_v3(n[0], n[1], n[2]);
    if (area)
        *area = m->area[s];
    const double *e = m->sum + SUMS * s + (side ? 3 : 0);
    return ps_rgb_make(e[0], e[1], e[2]);
}

void ps_illummap_colors(ps_illummap *m, const ps_material *materials, double scale, const float **front,
                        const float **back)
{
    const ps_preview_mesh *mesh = m->mesh;
    for (size_t r = 0; r < mesh->range_count; r++) {
        const ps_mesh_range *rg = &mesh->ranges[r];
        ps_rgb a = ps_rgb_scale(ps_illummap_albedo(&materials[rg->material]), scale * PS_INV_PI);
        for (size_t v = rg->first; v < rg->first + rg->count; v++) {
            float *f = m->front + 4 * v, *b = m->back + 4 * v;
            uint32_t s = m->vsample[v];
            const double *e = s == NO_SAMPLE ? NULL : m->sum + SUMS * s;
            f[0] = e ? (float)(e[0] * a.r) : 0.0f;
            f[1] = e ? (float)(e[1] * a.g) : 0.0f;
            f[2] = e ? (float)(e[2] * a.b) : 0.0f;
            b[0] = e ? (float)(e[3] * a.r) : 0.0f;
            b[1] = e ? (float)(e[4] * a.g) : 0.0f;
            b[2] = e ? (float)(e[5] * a.b) : 0.0f;
            f[3] = b[3] = 1.0f;
        }
    }
    m->changed = false;
    *front = m->front;
    *back = m->back;
}

void ps_illummap_colors_last(const ps_illummap *m, const float **front, const float **back)
{
    *front = m->front;
    *back = m->back;
}

size_t ps_illummap_lobe(const ps_illummap *m, const ps_photon **photons, const uint16_t **materials,
                        const uint32_t **objects)
{
    *photons = m->lobe_ph;
    *materials = m->lobe_mat;
    *objects = m->lobe_obj;
    return m->lobe_n;
}

void ps_illummap_lobe_materials(const ps_material *materials, size_t n, ps_material *out)
{
    for (size_t i = 0; i < n; i++) {
        out[i] = materials[i];
        if (out[i].type == PS_MAT_GLOSSY)
            out[i].albedo = ps_rgb_gray(0.0);
    }
}
