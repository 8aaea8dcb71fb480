/* illummap.c: the global map as irradiance on the fine mesh's vertices (illummap.h). */
#include "preview/illummap.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/array.h"
#include "core/memory.h"
#include "photon/tracer.h"

const char *const ps_global_layer_names[PS_GLOBAL_LAYER_COUNT + 1] = {"splats", "maps", NULL};

const char *ps_global_layer_name(ps_global_layer g)
{
    return (unsigned)g < PS_GLOBAL_LAYER_COUNT ? ps_global_layer_names[g] : "?";
}

#define NO_SAMPLE UINT32_MAX
/* Both sides' irradiance, rgb each. */
#define SUMS 6

/* What the search reads of a sample, in bucket order. */
typedef struct grid_item {
    float pos[3], nrm[3];
    uint32_t obj, sample;
    uint64_t cell; /* the cell's packed coordinates */
} grid_item;

/* One photon's shares: entries [first, first + count) of its worker's list. */
typedef struct photon_shares {
    size_t first;
    uint32_t count;
    bool lost;
} photon_shares;

/* A worker of the gather: photons [begin, end) of the chunk, each photon's
 * samples (side in the top bit) and weights g_s / sum_t g_t A_t. */
typedef struct gather {
    struct ps_illummap *m;
    const ps_photon *photons;
    const uint32_t *objects;
    size_t begin, end;
    photon_shares *shares;
    size_t cap_shares;
    uint32_t *sample;
    double *weight;
    size_t count, cap_sample, cap_weight;
    bool failed;
} gather;

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
    ps_illum_span *spans; /* the vertices with samples (ps_illummap_spans) */
    size_t span_count;
    float *front, *back, *view;
    /* The grid: cubic cells of side `radius`, hashed into `buckets` (a power
     * of two) lists; first[b]..first[b + 1] index items, which copy what the
     * search reads of each sample, bucket by bucket, so that one bucket's
     * candidates lie together in memory. */
    size_t buckets;
    uint32_t *first;
    struct grid_item *items;
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
    /* The gather's workers (one a thread) and its chunk's per-photon results. */
    int threads;
    struct gather *workers;
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
    m->span_count = 0;
    for (size_t r = 0; r < mesh->range_count; r++) {
        const ps_mesh_range *rg = &mesh->ranges[r];
        bool diffuse = rg->material < m->material_count && reflects_diffusely(&m->scene_materials[rg->material]);
        if (diffuse && rg->count > 0) {
            ps_illum_span *last = m->span_count ? &m->spans[m->span_count - 1] : NULL;
            if (last && last->first + last->count == rg->first)
                last->count += rg->count;
            else
                m->spans[m->span_count++] = (ps_illum_span){rg->first, rg->count};
        }
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
    m->view = calloc(4 * n1, sizeof *m->view);
    m->spans = malloc((mesh->range_count ? mesh->range_count : 1) * sizeof *m->spans);
    st = m->pos && m->nrm && m->obj && m->area && m->vsample && m->front && m->back && m->view && m->spans
             ? PS_OK
             : PS_ERR_NOMEM;
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
    if (st == PS_OK)
        st = ps_illummap_set_threads(m, 0, err);
    if (st != PS_OK) {
        ps_illummap_destroy(m);
        return st;
    }
    *out = m;
    return PS_OK;
}

static void free_workers(ps_illummap *m)
{
    for (int t = 0; m->workers && t < m->threads; t++) {
        free(m->workers[t].shares);
        free(m->workers[t].sample);
        free(m->workers[t].weight);
    }
    free(m->workers);
    m->workers = NULL;
}

ps_status ps_illummap_set_threads(ps_illummap *m, int threads, ps_error *err)
{
    if (threads <= 0)
        threads = ps_online_cores();
    threads = threads < 1 ? 1 : threads > PS_ILLUM_MAX_THREADS ? PS_ILLUM_MAX_THREADS : threads;
    gather *w = calloc((size_t)threads, sizeof *w);
    if (!w)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the illumination maps' threads");
    free_workers(m);
    m->workers = w;
    m->threads = threads;
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
    free(m->view);
    free(m->spans);
    free(m->first);
    free(m->items);
    free(m->lobe_ph);
    free(m->lobe_mat);
    free(m->lobe_obj);
    free_workers(m);
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

/* 21 bits a coordinate: a scene 10^6 radii across before two cells share a key. */
static uint64_t cell_key(cell3 c)
{
    const uint64_t mask = (1u << 21) - 1;
    return ((uint64_t)c.x & mask) << 42 | ((uint64_t)c.y & mask) << 21 | ((uint64_t)c.z & mask);
}

static size_t bucket_of(uint64_t key, size_t buckets)
{
    uint64_t h = key * 0x9e3779b97f4a7c15ull;
    h ^= h >> 29;
    h *= 0xbf58476d1ce4e5b9ull;
    return (size_t)(h >> 32) & (buckets - 1);
}

/* Cells of side radius: every sample within radius of a point lies in the
 * 27 cells around the point's. Items bucket by bucket, in sample order
 * within one: a fixed order. */
static void build_grid(ps_illummap *m, double radius)
{
    double inv = 1.0 / radius;
    memset(m->first, 0, (m->buckets + 1) * sizeof *m->first);
    for (size_t s = 0; s < m->samples; s++) {
        const float *p = m->pos + 3 * s;
        m->first[bucket_of(cell_key(cell_of(p[0], p[1], p[2], inv)), m->buckets) + 1]++;
    }
    for (size_t b = 0; b < m->buckets; b++)
        m->first[b + 1] += m->first[b];
    for (size_t s = 0; s < m->samples; s++) {
        const float *p = m->pos + 3 * s;
        uint64_t key = cell_key(cell_of(p[0], p[1], p[2], inv));
        grid_item *it = &m->items[m->first[bucket_of(key, m->buckets)]++];
        memcpy(it->pos, p, sizeof it->pos);
        memcpy(it->nrm, m->nrm + 3 * s, sizeof it->nrm);
        it->obj = m->obj[s];
        it->sample = (uint32_t)s;
        it->cell = key;
    }
    /* first[b] now holds the end of bucket b: shift back. */
    for (size_t b = m->buckets; b > 0; b--)
        m->first[b] = m->first[b - 1];
    m->first[0] = 0;
}

/* ---- adding photons --------------------------------------------------------------- */

/* One photon's shares into its worker's lists (false: out of memory). */
static bool gather_photon(gather *g, const ps_photon *ph, uint32_t object, photon_shares *out)
{
    const ps_illummap *m = g->m;
    double r = m->radius, r2 = r * r, inv = 1.0 / r;
    ps_vec3 p = ps_photon_position(ph), n = ps_photon_normal(ph);
    cell3 c = cell_of(p.x, p.y, p.z, inv);
    out->first = g->count;
    out->count = 0;
    out->lost = false;
    double total = 0.0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                cell3 cc = {c.x + dx, c.y + dy, c.z + dz};
                uint64_t key = cell_key(cc);
                size_t b = bucket_of(key, m->buckets);
                for (uint32_t i = m->first[b]; i < m->first[b + 1]; i++) {
                    const grid_item *it = &m->items[i];
                    /* Other cells sharing this bucket: each sample counts in its own cell only. */
                    if (it->obj != object || it->cell != key)
                        continue;
                    double ex = it->pos[0] - p.x, ey = it->pos[1] - p.y, ez = it->pos[2] - p.z;
                    double d2 = ex * ex + ey * ey + ez * ez;
                    if (d2 >= r2)
                        continue;
                    double cs = it->nrm[0] * n.x + it->nrm[1] * n.y + it->nrm[2] * n.z;
                    if (fabs(cs) < PS_ILLUM_MIN_COS)
                        continue;
                    double w = ps_kernel_profile(m->kernel, sqrt(d2) * inv);
                    if (!(w > 0.0))
                        continue;
                    size_t k = g->count;
                    if (!PS_RESERVE(g->sample, g->cap_sample, k + 1) || !PS_RESERVE(g->weight, g->cap_weight, k + 1))
                        return false;
                    g->sample[k] = it->sample | (cs < 0.0 ? 0x80000000u : 0u);
                    g->weight[k] = w;
                    total += w * m->area[it->sample];
                    g->count++;
                    out->count++;
                }
            }
    if (!(total > 0.0)) {
        g->count = out->first;
        out->count = 0;
        out->lost = true;
        return true;
    }
    /* w_s / A_s = g_s / sum_t g_t A_t. */
    double scale = 1.0 / total;
    for (size_t j = out->first; j < g->count; j++)
        g->weight[j] *= scale;
    return true;
}

static void *gather_range(void *arg)
{
    gather *g = arg;
    g->count = 0;
    g->failed = !PS_RESERVE(g->shares, g->cap_shares, g->end - g->begin + 1);
    for (size_t i = g->begin; i < g->end && !g->failed; i++)
        g->failed = !gather_photon(g, &g->photons[i], g->objects[i], &g->shares[i - g->begin]);
    return NULL;
}

/* One photon's shares (of worker g's lists) added to the sums. */
static void add_shares(ps_illummap *m, const gather *g, const photon_shares *sh, ps_rgb power)
{
    if (sh->lost) {
        m->lost = ps_rgb_add(m->lost, power);
        return;
    }
    for (size_t j = sh->first; j < sh->first + sh->count; j++) {
        uint32_t s = g->sample[j] & 0x7fffffffu;
        double *e = m->sum + SUMS * s + ((g->sample[j] & 0x80000000u) ? 3 : 0);
        double w = g->weight[j];
        e[0] += power.r * w;
        e[1] += power.g * w;
        e[2] += power.b * w;
    }
}

/* Photons [begin, end) added: their shares gathered on the workers, each a
 * contiguous range, then summed here in photon order, so that the sums are
 * the same bytes for any number of threads. */
static ps_status add_photons(ps_illummap *m, const ps_photon *photons, const uint32_t *objects, size_t begin,
                             size_t end, ps_error *err)
{
    size_t n = end - begin;
    int threads = m->threads;
    if ((size_t)threads > n / PS_ILLUM_MIN_PHOTONS_A_THREAD)
        threads = (int)(n / PS_ILLUM_MIN_PHOTONS_A_THREAD);
    if (threads <= 1) {
        /* On one thread each photon is summed as soon as it is gathered, so
         * its lists hold one photon's shares and stay in cache, where a
         * chunk's would be megabytes written once: the default box's first
         * gathering (3 972 photons, 85 877 shares) took 0.009-0.016 s with
         * fresh lists against 0.003 s with lists already written
         * (docs/preview.md). The same sums in the same order: the same bytes. */
        gather *g = &m->workers[0];
        g->m = m;
        photon_shares sh;
        for (size_t i = begin; i < end; i++) {
            g->count = 0;
            if (!gather_photon(g, &photons[i], objects[i], &sh))
                return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the illumination maps' estimate");
            add_shares(m, g, &sh, ps_photon_power(&photons[i]));
        }
        return PS_OK;
    }
    pthread_t tid[PS_ILLUM_MAX_THREADS];
    bool started[PS_ILLUM_MAX_THREADS] = {false};
    for (int t = 0; t < threads; t++) {
        gather *g = &m->workers[t];
        g->m = m;
        g->photons = photons;
        g->objects = objects;
        g->begin = begin + n * (size_t)t / (size_t)threads;
        g->end = begin + n * (size_t)(t + 1) / (size_t)threads;
        if (t > 0)
            started[t] = pthread_create(&tid[t], NULL, gather_range, g) == 0;
    }
    gather_range(&m->workers[0]);
    for (int t = 1; t < threads; t++) {
        if (started[t])
            pthread_join(tid[t], NULL);
        else
            gather_range(&m->workers[t]); /* no thread to be had: here */
    }
    for (int t = 0; t < threads; t++)
        if (m->workers[t].failed)
            return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the illumination maps' estimate");
    for (int t = 0; t < threads; t++) {
        const gather *g = &m->workers[t];
        for (size_t i = g->begin; i < g->end; i++)
            add_shares(m, g, &g->shares[i - g->begin], ps_photon_power(&photons[i]));
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
    /* Chunk by chunk: the workers' lists stay a chunk's size. */
    for (size_t i = m->count; i < count; i += PS_ILLUM_CHUNK) {
        size_t e = count - i > PS_ILLUM_CHUNK ? i + PS_ILLUM_CHUNK : count;
        ps_status st = add_photons(m, photons, objects, i, e, err);
        for (size_t j = i; j < e && st == PS_OK; j++) {
            uint16_t mat = materials[j];
            if (mat >= m->material_count || m->scene_materials[mat].type != PS_MAT_GLOSSY)
                continue;
            size_t need = m->lobe_n + 1;
            if (!PS_RESERVE(m->lobe_ph, m->cap_ph, need) || !PS_RESERVE(m->lobe_mat, m->cap_mat, need) ||
                !PS_RESERVE(m->lobe_obj, m->cap_obj, need))
                st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for the illumination maps' glossy photons");
            else {
                m->lobe_ph[m->lobe_n] = photons[j];
                m->lobe_mat[m->lobe_n] = mat;
                m->lobe_obj[m->lobe_n] = objects[j];
                m->lobe_n++;
            }
        }
        if (st != PS_OK) {
            ps_illummap_reset(m, m->kernel);
            return st;
        }
        *added += e - i;
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

const float *ps_illummap_view_colors(ps_illummap *m, ps_vec3 eye)
{
    const ps_preview_mesh *mesh = m->mesh;
    for (size_t i = 0; i < m->span_count; i++) {
        const ps_illum_span *sp = &m->spans[i];
        /* Ranges are whole triangles, so a span is too. */
        for (size_t v = sp->first; v + 2 < sp->first + sp->count; v += 3) {
            const float *p = mesh->positions + 3 * v;
            ps_vec3 p0 = ps_v3(p[0], p[1], p[2]), p1 = ps_v3(p[3], p[4], p[5]), p2 = ps_v3(p[6], p[7], p[8]);
            ps_vec3 n = ps_v3_cross(ps_v3_sub(p1, p0), ps_v3_sub(p2, p0));
            const float *src = ps_v3_dot(ps_v3_sub(eye, p0), n) > 0.0 ? m->front : m->back;
            memcpy(m->view + 4 * v, src + 4 * v, 12 * sizeof *src);
        }
    }
    return m->view;
}

size_t ps_illummap_spans(const ps_illummap *m, const ps_illum_span **spans)
{
    *spans = m->spans;
    return m->span_count;
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
