/* tracer.c: photon emission plans, the per-photon path, and the threads. */
#include "photon/tracer.h"

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/array.h"
#include "core/jobs.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "photon/emit.h"
#include "scene/bsdf.h"

/* Emission uses Halton dimensions 1..4 (dimension 0 picks the light and caustic cone). */
#define EMIT_DIMS 4
/* rank_of steps over at most this many indices one by one; a longer jump
 * counts below the index afresh (count_below: three passes over the index's
 * bits a stratum, about as long as this many stratum_of for a few strata). */
#define RANK_SCAN 32
/* Halton dimension 0 has this many bits: photon i's is the reversal of its
 * low 53 bits (van_der_corput). */
#define VDC_BITS 53

/* One way photons leave: a light, and for caustic photons the caustic cone
 * around one specular object. Photon indices are shared between strata in
 * proportion to `share` (the flux each is expected to carry).
 *
 * Each stratum has its own photon stream: its identity (light, target) and the
 * seed give `key`, and its j-th photon (the j-th index that falls to it) takes
 * its emission numbers from the Halton point j, shifted by `rotation`, and its
 * path from the PCG stream (key, map, j). So photon (stratum, j) does not
 * change when another stratum's share does (tests/test_tracer_strata.c). */
typedef struct stratum {
    uint32_t light;
    int64_t target; /* caustic: the object the caustic cone is aimed at; -1: none */
    bool has_caustic_cone;
    ps_caustic_cone caustic_cone;
    double share;
    double cdf; /* cumulative share, normalised; the last is 1 */
    ps_rgb power; /* the light's, when planned: stored power = T x power / count */
    uint64_t key;
    uint64_t dither_key;        /* its photons' RGBE dithers (photon_dither) */
    double rotation[EMIT_DIMS]; /* Cranley-Patterson shifts of its emission numbers */
} stratum;

typedef struct map_plan {
    bool enabled;
    uint32_t stream;
    stratum *strata;
    size_t count, cap;
    double rotation0; /* the shift of Halton dimension 0 (the stratum choice) */
    /* Where the stratum choice's cuts fall on the 53-bit reversal m of an
     * index (plan_cuts): stratum <= s for m in [0, below[s]) and [wrap,
     * above[s]). */
    uint64_t wrap;
    uint64_t *below, *above;
    /* Normalisation for `counted_total` photons: scale[s] = 1 / photons of s. */
    uint64_t counted_total;
    bool counted;
    uint64_t *counts;
    double *scale;
    /* With records (a session that repairs): each index's stratum, so that
     * a repair's photon sources read it instead of recomputing it. */
    uint8_t *seq;
} map_plan;

static void plan_cuts(map_plan *p);

struct ps_tracer {
    const ps_world *world;
    const ps_scene *scene;
    const ps_material *materials;
    ps_tracer_options opt;
    int threads;
    ps_light_sampler *lights;
    map_plan plans[PS_MAP_COUNT];
    ps_skip *skips;
    size_t skip_count, skip_cap;
    ps_path_quant quant; /* records: the vertices' quantisation */
};

ps_tracer_options ps_tracer_default_options(void)
{
    ps_tracer_options o = {0};
    o.caustic_cones = true;
    o.first_hit_test = true;
    return o;
}

/* ---- the plan: strata and skips ------------------------------------------ */

static ps_status add_skip(ps_tracer *t, const char *pass, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static ps_status add_skip(ps_tracer *t, const char *pass, const char *fmt, ...)
{
    if (!PS_RESERVE(t->skips, t->skip_cap, t->skip_count + 1))
        return PS_ERR_NOMEM;
    ps_skip *s = &t->skips[t->skip_count++];
    snprintf(s->pass, sizeof s->pass, "%s", pass);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->reason, sizeof s->reason, fmt, ap);
    va_end(ap);
    return PS_OK;
}

static bool add_stratum(map_plan *p, uint32_t light, int64_t target, const ps_caustic_cone *caustic_cone,
                        double share, ps_rgb power)
{
    if (!PS_RESERVE(p->strata, p->cap, p->count + 1))
        return false;
    stratum *s = &p->strata[p->count++];
    memset(s, 0, sizeof *s);
    s->light = light;
    s->target = target;
    s->has_caustic_cone = caustic_cone != NULL;
    if (caustic_cone)
        s->caustic_cone = *caustic_cone;
    s->share = share;
    s->power = power;
    return true;
}

/* Normalises the shares into a CDF; a plan whose shares are all zero is off. */
static void finish_plan(map_plan *p)
{
    double total = 0.0;
    for (size_t k = 0; k < p->count; k++)
        total += p->strata[k].share;
    if (!(total > 0.0) || !isfinite(total)) {
        p->enabled = false;
        return;
    }
    double run = 0.0;
    for (size_t k = 0; k < p->count; k++) {
        run += p->strata[k].share;
        p->strata[k].cdf = run / total;
    }
    p->strata[p->count - 1].cdf = 1.0;
}

/* The sphere around object o that its caustic cones are built on: exact for spheres,
 * around the box centre through the farthest vertex for meshes. */
static void object_sphere(const ps_scene *s, const ps_object *o, ps_vec3 *c, double *r)
{
    if (o->type == PS_OBJ_SPHERE) {
        *c = o->center;
        *r = o->radius;
        return;
    }
    size_t nt, np;
    const ps_triangle *tris = ps_scene_triangles(s, &nt);
    const ps_vec3 *pos = ps_scene_positions(s, &np);
    *c = ps_aabb_center(o->bounds);
    double r2 = 0.0;
    for (uint32_t k = 0; k < o->triangle_count; k++)
        for (int v = 0; v < 3; v++)
            r2 = fmax(r2, ps_v3_len2(ps_v3_sub(pos[tris[o->first_triangle + k].v[v]], *c)));
    *r = sqrt(r2);
}

static bool reflects_diffusely(const ps_material *m)
{
    if (m->type == PS_MAT_DIFFUSE)
        return ps_rgb_max(m->albedo) > 0.0;
    if (m->type == PS_MAT_GLOSSY)
        return ps_rgb_max(m->albedo) > 0.0 || ps_rgb_max(m->specular) > 0.0;
    return false;
}

static ps_status plan_maps(ps_tracer *t, ps_error *err)
{
    const ps_scene *s = t->scene;
    const char *path = ps_scene_path(s);
    size_t nl, no, nt, nm;
    const ps_light *lights = ps_scene_lights(s, &nl);
    const ps_object *objs = ps_scene_objects(s, &no);
    const ps_triangle *tris = ps_scene_triangles(s, &nt);
    (void)ps_scene_materials(s, &nm);
    map_plan *caustic = &t->plans[PS_MAP_CAUSTIC], *global = &t->plans[PS_MAP_GLOBAL];
    caustic->stream = PS_STREAM_CAUSTIC;
    global->stream = PS_STREAM_GLOBAL;
    caustic->enabled = global->enabled = true;
#define SKIP(pass, ...)                                                                                     \
    do {                                                                                                    \
        if (add_skip(t, pass, __VA_ARGS__) != PS_OK)                                                        \
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory planning the photon maps", path);     \
    } while (0)

    /* Does anything reflect diffusely? Only such surfaces store photons. */
    bool diffuse = false;
    for (size_t k = 0; k < nt && !diffuse; k++)
        diffuse = reflects_diffusely(&t->materials[tris[k].material]);
    for (size_t k = 0; k < no && !diffuse; k++)
        diffuse = objs[k].type == PS_OBJ_SPHERE && reflects_diffusely(&t->materials[objs[k].material]);
    bool lit = false;
    for (size_t l = 0; l < nl; l++)
        lit |= ps_rgb_max(lights[l].power) > 0.0;

    if (!lit) {
        SKIP("caustic", "no light emits any power");
        SKIP("global", "no light emits any power");
        caustic->enabled = global->enabled = false;
        return PS_OK;
    }
    if (!diffuse) {
        SKIP("caustic", "no diffuse reflectance anywhere: nothing can receive a caustic");
        SKIP("global", "no diffuse reflectance anywhere");
        caustic->enabled = global->enabled = false;
        return PS_OK;
    }

    /* Global map: every light, in proportion to its flux. */
    for (uint32_t l = 0; l < nl; l++)
        if (!add_stratum(global, l, -1, NULL, ps_rgb_sum(lights[l].power), lights[l].power))
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory planning the photon maps", path);
    finish_plan(global);

    /* Caustic map: only towards specular objects. */
    size_t specular = 0;
    for (size_t o = 0; o < no; o++)
        specular += objs[o].specular ? 1 : 0;
    if (specular == 0) {
        SKIP("caustic", "no specular (mirror or dielectric) object in the scene");
        caustic->enabled = false;
        return PS_OK;
    }
    for (uint32_t l = 0; l < nl; l++) {
        double flux = ps_rgb_sum(lights[l].power);
        if (!(flux > 0.0))
            continue;
        if (!t->opt.caustic_cones) {
            if (!add_stratum(caustic, l, -1, NULL, flux, lights[l].power))
                return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory planning the photon maps", path);
            continue;
        }
        size_t caustic_cones = 0;
        for (size_t o = 0; o < no; o++) {
            if (!objs[o].specular)
                continue;
            ps_vec3 c;
            double r;
            ps_caustic_cone caustic_cone;
            object_sphere(s, &objs[o], &c, &r);
            if (!ps_light_caustic_cone(t->lights, l, c, r, &caustic_cone))
                continue;
            double share = flux * ps_light_caustic_cone_share(t->lights, l, &caustic_cone);
            if (!add_stratum(caustic, l, (int64_t)o, &caustic_cone, share, lights[l].power))
                return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory planning the photon maps", path);
            caustic_cones++;
        }
        if (caustic_cones == 0)
            SKIP("caustic", "%s light %u (line %d): no specular object inside its emission", ps_light_type_name(lights[l].type),
                 l, lights[l].line);
    }
    if (caustic->count == 0) {
        caustic->enabled = false;
        return PS_OK;
    }
    finish_plan(caustic);
#undef SKIP
    return PS_OK;
}

int ps_online_cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > PS_TRACER_MAX_THREADS ? PS_TRACER_MAX_THREADS : (int)n;
}

ps_status ps_tracer_create(const ps_world *w, const ps_tracer_options *opt, ps_tracer **out, ps_error *err)
{
    *out = NULL;
    const ps_scene *s = ps_world_scene(w);
    ps_tracer *t = calloc(1, sizeof *t);
    if (!t)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the photon tracer", ps_scene_path(s));
    t->world = w;
    t->scene = s;
    size_t nm;
    t->materials = ps_scene_materials(s, &nm);
    t->opt = opt ? *opt : ps_tracer_default_options();
    t->quant = ps_path_quant_make(t->opt.record_box, ps_world_epsilon(w));
    ps_tracer_set_threads(t, t->opt.threads);
    ps_status st = ps_light_sampler_create(s, &t->lights, err);
    if (st == PS_OK)
        st = plan_maps(t, err);
    if (st != PS_OK) {
        ps_tracer_destroy(t);
        return st;
    }
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        map_plan *p = &t->plans[k];
        /* Independent shifts per map and seed: the maps never share samples;
         * and per stratum, from its identity only (not its place in the plan). */
        uint64_t h = ps_hash64(t->opt.seed ^ ps_hash64(p->stream));
        p->rotation0 = (double)(ps_hash64(h) >> 11) * (1.0 / 9007199254740992.0);
        for (size_t q = 0; q < p->count; q++) {
            stratum *sk = &p->strata[q];
            uint64_t id = ((uint64_t)sk->light + 1) << 32 ^ (uint64_t)(sk->target + 1);
            sk->key = ps_hash64(h ^ ps_hash64(id ^ 0x2545f4914f6cdd1dULL));
            sk->dither_key = ps_hash64(sk->key ^ 0x9fb21c651e98df25ULL);
            uint64_t r = sk->key;
            for (int d = 0; d < EMIT_DIMS; d++) {
                r = ps_hash64(r + (uint64_t)d + 1);
                sk->rotation[d] = (double)(r >> 11) * (1.0 / 9007199254740992.0);
            }
        }
        p->counts = calloc(p->count ? p->count : 1, sizeof *p->counts);
        p->scale = calloc(p->count ? p->count : 1, sizeof *p->scale);
        p->below = calloc(p->count ? p->count : 1, sizeof *p->below);
        p->above = calloc(p->count ? p->count : 1, sizeof *p->above);
        if (!p->counts || !p->scale || !p->below || !p->above) {
            ps_tracer_destroy(t);
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the photon tracer", ps_scene_path(s));
        }
        plan_cuts(p);
    }
    *out = t;
    return PS_OK;
}

void ps_tracer_destroy(ps_tracer *t)
{
    if (!t)
        return;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        free(t->plans[k].strata);
        free(t->plans[k].counts);
        free(t->plans[k].scale);
        free(t->plans[k].below);
        free(t->plans[k].above);
        free(t->plans[k].seq);
    }
    ps_light_sampler_destroy(t->lights);
    free(t->skips);
    free(t);
}

bool ps_tracer_map_enabled(const ps_tracer *t, ps_map_kind kind) { return t->plans[kind].enabled; }

const ps_skip *ps_tracer_skips(const ps_tracer *t, size_t *count)
{
    *count = t->skip_count;
    return t->skips;
}

int ps_tracer_threads(const ps_tracer *t) { return t->threads; }

void ps_tracer_set_threads(ps_tracer *t, int threads)
{
    t->threads = threads > 0 ? (threads < PS_TRACER_MAX_THREADS ? threads : PS_TRACER_MAX_THREADS) : ps_online_cores();
}

ps_status ps_tracer_note_skip(ps_tracer *t, const char *pass, const char *reason)
{
    return add_skip(t, pass, "%s", reason);
}

/* ---- which stratum photon i belongs to ----------------------------------- */

/* Photon i's coordinate in Halton dimension 0 (the base-2 radical inverse)
 * as an integer m: the reversal of i's low VDC_BITS bits; the coordinate is
 * m * 2^-53, exact. */
static uint64_t vdc_bits(uint64_t i)
{
    i = (i << 32) | (i >> 32);
    i = ((i & 0x0000ffff0000ffffULL) << 16) | ((i >> 16) & 0x0000ffff0000ffffULL);
    i = ((i & 0x00ff00ff00ff00ffULL) << 8) | ((i >> 8) & 0x00ff00ff00ff00ffULL);
    i = ((i & 0x0f0f0f0f0f0f0f0fULL) << 4) | ((i >> 4) & 0x0f0f0f0f0f0f0f0fULL);
    i = ((i & 0x3333333333333333ULL) << 2) | ((i >> 2) & 0x3333333333333333ULL);
    i = ((i & 0x5555555555555555ULL) << 1) | ((i >> 1) & 0x5555555555555555ULL);
    return i >> (64 - VDC_BITS);
}

/* A Cranley-Patterson shift: u + by wrapped into [0, 1). */
static double shift(double u, double by)
{
    u += by;
    return u < 1.0 ? u : u - 1.0;
}

/* The value that picks the stratum for m: the coordinate shifted by the
 * plan's rotation (Cranley-Patterson), wrapped into [0, 1). stratum_of and
 * the cuts (plan_cuts) both evaluate this one expression, so the counts
 * from the cuts agree with stratum_of at every index, roundings included. */
static double choice_of(const map_plan *p, uint64_t m)
{
    return shift((double)m * (1.0 / 9007199254740992.0), p->rotation0);
}

/* Low-discrepancy choice: any prefix of photon indices is shared between the
 * strata within a few photons of their shares, so each light's photon count is
 * proportional to its flux for every total, not just on average. */
static size_t stratum_of(const map_plan *p, uint64_t i)
{
    double u = choice_of(p, vdc_bits(i));
    size_t lo = 0, hi = p->count - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (p->strata[mid].cdf > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* The first m in [lo, hi) where `cdf > choice_of(m)` fails, or hi: along
 * [0, wrap) and along [wrap, 2^53) choice_of rises with m (a rounded sum
 * rises with its term), so the test holds, then fails. */
static uint64_t first_not_below(const map_plan *p, double cdf, uint64_t lo, uint64_t hi)
{
    while (lo < hi) {
        uint64_t mid = lo + (hi - lo) / 2;
        if (cdf > choice_of(p, mid))
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Where the cuts between strata fall in m, once a plan's shares and rotation
 * are set: wrap, the first m whose shifted coordinate wraps (shift's test,
 * on the same sum); stratum <= s (cdf_s > choice) on [0, below[s]) and [wrap, above[s]). */
static void plan_cuts(map_plan *p)
{
    uint64_t lo = 0, hi = (uint64_t)1 << VDC_BITS;
    while (lo < hi) {
        uint64_t mid = lo + (hi - lo) / 2;
        if ((double)mid * (1.0 / 9007199254740992.0) + p->rotation0 < 1.0)
            lo = mid + 1;
        else
            hi = mid;
    }
    p->wrap = lo;
    for (size_t k = 0; k < p->count; k++) {
        p->below[k] = first_not_below(p, p->strata[k].cdf, 0, p->wrap);
        p->above[k] = first_not_below(p, p->strata[k].cdf, p->wrap, (uint64_t)1 << VDC_BITS);
    }
}

/* Indices below n whose m is below cut, without visiting them. [0, n) is
 * aligned blocks, one per set bit t of n; in a block of 2^t indices from
 * `base` (its low t + 1 bits clear), m runs over the grid of step 2^(53-t)
 * offset by base's own m (below the step), so one division counts it. */
static uint64_t count_m_below(uint64_t n, uint64_t cut)
{
    uint64_t count = 0;
    for (int t = 63; t >= 0; t--) {
        if (!((n >> t) & 1))
            continue;
        if (t >= VDC_BITS) { /* every m, 2^(t-53) times */
            count += cut << (t - VDC_BITS);
            continue;
        }
        uint64_t base = (n >> t >> 1) << t << 1, block = (uint64_t)1 << t;
        int step = VDC_BITS - t;
        uint64_t o = vdc_bits(base);
        if (cut > o) {
            uint64_t j = (cut - o + ((uint64_t)1 << step) - 1) >> step;
            count += j < block ? j : block;
        }
    }
    return count;
}

/* Each stratum's photons below index n, in closed form. Counted over every
 * index below the cap instead, a snap run at the bench's caps (1-1.6*10^7
 * photons in both maps) drew its first picture 0.04-0.10 s later. */
static void count_below(const map_plan *p, uint64_t n, uint64_t *out)
{
    uint64_t wrapped = count_m_below(n, p->wrap), before = 0;
    for (size_t k = 0; k < p->count; k++) {
        uint64_t upto = count_m_below(n, p->below[k]) + count_m_below(n, p->above[k]) - wrapped;
        out[k] = upto - before;
        before = upto;
    }
}

/* Indices a job of the stratum sequence covers (records only). */
#define SEQ_JOB_INDICES ((uint64_t)1 << 19)

typedef struct seq_job {
    map_plan *p;
    uint64_t total;
} seq_job;

static void seq_range(void *arg, size_t job)
{
    const seq_job *c = arg;
    uint64_t from = (uint64_t)job * SEQ_JOB_INDICES;
    uint64_t to = from + SEQ_JOB_INDICES < c->total ? from + SEQ_JOB_INDICES : c->total;
    for (uint64_t i = from; i < to; i++)
        c->p->seq[i] = (uint8_t)stratum_of(c->p, i);
}

/* The plan's counts are those of `total` photons: each stratum's share of
 * the power, 1 / its count. */
static void set_counted(map_plan *p, uint64_t total)
{
    for (size_t k = 0; k < p->count; k++)
        p->scale[k] = p->counts[k] ? 1.0 / (double)p->counts[k] : 0.0;
    p->counted_total = total;
    p->counted = true;
}

/* Counts and normalisation for `total` photons; with keep_seq each index's
 * stratum too, in jobs on every core (the same for any thread count); false
 * when out of memory for it. */
static bool count_strata(map_plan *p, uint64_t total, bool keep_seq)
{
    if (p->counted && p->counted_total == total)
        return true;
    free(p->seq);
    p->seq = NULL;
    if (keep_seq && p->count <= UINT8_MAX + 1 && total <= SIZE_MAX) {
        p->seq = malloc(total ? (size_t)total : 1);
        if (!p->seq)
            return false;
        seq_job c = {p, total};
        ps_run_jobs((size_t)((total + SEQ_JOB_INDICES - 1) / SEQ_JOB_INDICES), ps_online_cores(), seq_range, &c);
    }
    count_below(p, total, p->counts);
    set_counted(p, total);
    return true;
}

/* Photon i's stratum and rank among that stratum's indices, for ascending
 * indices i: `counts` holds each stratum's photons below `at`. */
typedef struct rank_cursor {
    uint64_t at;
    uint64_t *counts;
    bool valid;
} rank_cursor;

static void rank_of(const map_plan *p, rank_cursor *c, uint64_t i, size_t *k, uint64_t *j)
{
    if (!c->valid || i < c->at || i - c->at > RANK_SCAN) {
        count_below(p, i, c->counts);
        c->at = i;
        c->valid = true;
    }
    for (; c->at < i; c->at++)
        c->counts[stratum_of(p, c->at)]++;
    *k = stratum_of(p, i);
    *j = c->counts[*k]++;
    c->at = i + 1;
}

uint64_t ps_tracer_light_photons(ps_tracer *t, ps_map_kind kind, uint32_t light, uint64_t total)
{
    map_plan *p = &t->plans[kind];
    if (!p->enabled || !count_strata(p, total, t->opt.records))
        return 0;
    uint64_t n = 0;
    for (size_t k = 0; k < p->count; k++)
        if (p->strata[k].light == light)
            n += p->counts[k];
    return n;
}

uint64_t ps_tracer_stratum_photons(ps_tracer *t, ps_map_kind kind, uint32_t light, int64_t target, uint64_t total)
{
    map_plan *p = &t->plans[kind];
    if (!p->enabled || !count_strata(p, total, t->opt.records))
        return 0;
    for (size_t k = 0; k < p->count; k++)
        if (p->strata[k].light == light && p->strata[k].target == target)
            return p->counts[k];
    return 0;
}

/* ---- one photon's path --------------------------------------------------- */

/* What one chunk of photon indices stored, with its counters, before it is
 * joined to the map: a photon map of its own. */
typedef struct chunk_out {
    ps_photon_map map;
    ps_path_store paths; /* records: one per emitted photon of the chunk */
    bool failed;
} chunk_out;

static void vertex(const ps_tracer *t, chunk_out *out, ps_vec3 p)
{
    if (t->opt.records)
        ps_path_add_vertex(&out->paths, ps_path_quantize(&t->quant, p));
}

/* A stored photon's power: its light-independent throughput T (rounded to
 * float once, as the path record keeps it) times the light's power times 1 /
 * the photons of its stratum. The tracer and ps_tracer_repower compute it the
 * same way, so a power or colour edit rescales kept photons bit for bit. */
static ps_rgb stored_power(const ps_path_thr *thr, ps_rgb light_power, double scale)
{
    ps_rgb T = {thr->t[0], thr->t[1], thr->t[2]};
    return ps_rgb_scale(ps_rgb_mul(T, light_power), scale);
}

/* The RGBE dither of the s-th photon (s < 256: trace_photon's limit) that
 * path j of a stratum stores: from the photon's own identity, not its PCG
 * stream, so that a repair can round its new power the same way without
 * retracing it. One SplitMix64 finaliser of (stratum, j, s) is uniform
 * enough for a dither. */
static double photon_dither(uint64_t dither_key, uint64_t j, unsigned s)
{
    uint64_t h = ps_hash64(dither_key ^ (j << 8 | (uint64_t)s));
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/* T rounded to float, once: the stored power is computed from the rounded
 * value, as ps_tracer_repower computes it from the record. Through a volatile:
 * GCC 12.2 at -O2 (its SLP vectoriser) otherwise multiplies the unrounded
 * double into the power of two channels while it stores the rounded one, and
 * a repair's power then differs in the last mantissa bit (found by
 * tests/test_repair.c). */
static ps_path_thr round_thr(ps_rgb T)
{
    volatile float v[3] = {(float)T.r, (float)T.g, (float)T.b};
    ps_path_thr r = {{v[0], v[1], v[2]}};
    return r;
}

/* One path's identity while it is traced. */
typedef struct path_ctx {
    const stratum *st;
    double scale;
    uint64_t j;
    unsigned stored;
} path_ctx;

static void store(const ps_tracer *t, chunk_out *out, path_ctx *pc, const ps_surface *sp, ps_rgb thr, ps_vec3 d,
                  ps_vec3 n)
{
    ps_path_thr T = round_thr(thr);
    ps_rgb power = stored_power(&T, pc->st->power, pc->scale);
    double dither = photon_dither(pc->st->dither_key, pc->j, pc->stored++);
    if (!ps_photon_map_push(&out->map, ps_photon_pack(sp->p, power, d, n, dither), (uint16_t)sp->material,
                            sp->object)) {
        out->failed = true;
        return;
    }
    if (t->opt.records)
        ps_path_add_thr(&out->paths, T);
    out->map.counters.stored++;
}

/* Photon i of the map, the j-th of stratum k. */
static void trace_path(const ps_tracer *t, ps_map_kind kind, size_t k, uint64_t j, chunk_out *out)
{
    const map_plan *plan = &t->plans[kind];
    const ps_world *w = t->world;
    ps_trace_counters *c = &out->map.counters;
    c->emitted++;

    /* Emission: the stratum is Halton dimension 0 of index i; the four
     * emission numbers are the Halton point of its rank j in the stratum,
     * shifted by the stratum's own rotation; the rest of the path draws from
     * the stratum's PCG stream at j. */
    const stratum *st = &plan->strata[k];
    double u[EMIT_DIMS];
    for (unsigned d = 0; d < EMIT_DIMS; d++)
        u[d] = shift(ps_halton(d + 1, j), st->rotation[d]);
    ps_emission e;
    if (!ps_light_emit(t->lights, st->light, st->has_caustic_cone ? &st->caustic_cone : NULL, u, &e) ||
        plan->scale[k] == 0.0) {
        c->empty++;
        return;
    }
    path_ctx pc = {st, plan->scale[k], j, 0};
    /* The throughput without the light's power: what the photon carries
     * of it (the power itself is multiplied in at the store). */
    ps_rgb power = {e.weight, e.weight, e.weight};
    ps_ray ray = e.ray;
    if (ps_v3_len2(e.normal) > 0.0) /* leave an emitting surface (mesh lights are geometry too) */
        ray.o = ps_v3_madd(ray.o, e.normal, ps_world_epsilon(w));
    vertex(t, out, ray.o);
    ps_rng rng = ps_rng_make(st->key, plan->stream, j);
    bool diffuse_seen = false;

    for (int bounce = 0;; bounce++) {
        if (bounce >= PS_PHOTON_MAX_BOUNCES) {
            c->truncated++;
            return;
        }
        ps_surface sp;
        c->rays++;
        if (!ps_world_intersect(w, ray, INFINITY, &sp)) {
            if (t->opt.records)
                vertex(t, out, ps_path_exit(&t->quant, ray.o, ray.d));
            c->escaped++;
            return;
        }
        vertex(t, out, sp.p);
        ps_material textured;
        const ps_material *m = ps_surface_material(ps_world_scene(w), t->materials, &sp, &textured);
        ps_vec3 d = ray.d;
        bool specular = ps_material_is_specular(m);
        if (kind == PS_MAP_CAUSTIC && bounce == 0) {
            /* The first-hit test (thesis 4.1.1): a photon aimed at one object
             * that first meets another is not that caustic cone's to carry; the
             * other object's own caustic cone carries it. Without it overlapping
             * caustic cones count the same caustic twice. And a first diffuse hit is no caustic. */
            bool other = st->target >= 0 && t->opt.first_hit_test && sp.object != (uint32_t)st->target;
            if (other || !specular) {
                c->discarded++;
                return;
            }
        }
        /* Surfaces are two-sided: work with the normals on the arriving side. */
        bool front = ps_v3_dot(d, sp.ng) < 0.0;
        ps_vec3 ns = front ? sp.ns : ps_v3_neg(sp.ns);
        ps_vec3 ng = front ? sp.ng : ps_v3_neg(sp.ng);
        ps_vec3 dir;

        switch (m->type) {
        case PS_MAT_DIFFUSE:
        case PS_MAT_GLOSSY: {
            if (kind == PS_MAP_CAUSTIC) { /* light, specular bounces, here: a caustic */
                store(t, out, &pc, &sp, power, d, ns);
                return;
            }
            if (diffuse_seen || t->opt.global_direct)
                store(t, out, &pc, &sp, power, d, ns);
            /* Russian roulette on the albedo: the expected power leaving is the
             * power arriving times the albedo, with no photon made heavier than
             * the albedo's colour ratio. */
            double pd = ps_rgb_mean(m->albedo);
            double pg = m->type == PS_MAT_GLOSSY ? ps_rgb_mean(m->specular) : 0.0;
            double x = ps_rng_uniform(&rng);
            double u1 = ps_rng_uniform(&rng), u2 = ps_rng_uniform(&rng);
            if (x < pd) {
                dir = ps_sample_cosine(u1, u2, ns);
                power = ps_rgb_scale(ps_rgb_mul(power, m->albedo), 1.0 / pd);
            } else if (x < pd + pg) {
                /* Lobe sampling: density (e+1)/(2 pi) cos^e; the BRDF's (e+2)/(2 pi)
                 * cos^e times the cosine at the surface leaves this weight. */
                dir = ps_sample_phong(u1, u2, ps_reflect(d, ns), m->exponent);
                double cos_out = ps_v3_dot(dir, ns);
                if (cos_out <= 0.0) {
                    c->absorbed++;
                    return;
                }
                double wgt = (m->exponent + 2.0) / (m->exponent + 1.0) * cos_out / pg;
                power = ps_rgb_scale(ps_rgb_mul(power, m->specular), wgt);
            } else {
                c->absorbed++;
                return;
            }
            diffuse_seen = true;
            break;
        }
        case PS_MAT_MIRROR: {
            double p = fmin(1.0, ps_rgb_max(m->reflectance));
            if (!(p > 0.0) || (p < 1.0 && ps_rng_uniform(&rng) >= p)) {
                c->absorbed++;
                return;
            }
            power = ps_rgb_scale(ps_rgb_mul(power, m->reflectance), 1.0 / p);
            dir = ps_reflect(d, ns);
            break;
        }
        case PS_MAT_DIELECTRIC:
        default: {
            double eta_i = front ? 1.0 : m->ior, eta_t = front ? m->ior : 1.0;
            double f = ps_fresnel_dielectric(-ps_v3_dot(d, ns), eta_i, eta_t);
            /* Choose reflection with probability F: no weight change, unbiased. */
            if (ps_rng_uniform(&rng) < f || !ps_refract(d, ns, eta_i / eta_t, &dir)) {
                dir = ps_reflect(d, ns);
            } else {
                power = ps_rgb_mul(power, m->transmittance);
            }
            break;
        }
        }
        /* An interpolated normal can send a diffuse bounce under the true
         * surface; such a photon would start inside the object. */
        if (!specular && ps_v3_dot(dir, ng) <= 0.0) {
            c->absorbed++;
            return;
        }
        ray = ps_world_spawn(w, &sp, dir);
    }
}

/* One photon, and with records its path's record. */
static void trace_photon(const ps_tracer *t, ps_map_kind kind, size_t k, uint64_t j, chunk_out *out)
{
    if (!t->opt.records) {
        trace_path(t, kind, k, j, out);
        return;
    }
    size_t before = out->map.count;
    ps_path_begin(&out->paths);
    trace_path(t, kind, k, j, out);
    if (out->paths.failed || out->map.count - before > UINT8_MAX) {
        out->failed = true;
        return;
    }
    out->paths.rec[out->paths.count - 1].stored = (uint8_t)(out->map.count - before);
}

/* ---- threads ------------------------------------------------------------- */

typedef struct trace_job {
    const ps_tracer *t;
    ps_map_kind kind;
    uint64_t first, count;
    const uint64_t *list; /* NULL: the range [first, first + count); else these count indices */
    size_t chunks;
    chunk_out *outs;
    atomic_size_t next;
    atomic_size_t done;           /* chunks traced to the end */
    atomic_uint_least64_t stored; /* photons the chunks hold so far */
    uint64_t room;                /* how many more the map may take (max_stored) */
    atomic_bool over;             /* stored would pass room: every worker stops */
} trace_job;

static void *worker(void *arg)
{
    trace_job *job = arg;
    const map_plan *plan = &job->t->plans[job->kind];
    rank_cursor cur = {0, malloc(plan->count * sizeof *cur.counts), false};
    for (;;) {
        /* Stop between chunks when asked to, or when the map is full. */
        if (ps_cancelled(job->t->opt.cancel) || atomic_load(&job->over)) {
            free(cur.counts);
            return NULL;
        }
        size_t k = atomic_fetch_add(&job->next, 1);
        if (k >= job->chunks) {
            free(cur.counts);
            return NULL;
        }
        uint64_t lo = job->first + (uint64_t)k * PS_PHOTON_CHUNK;
        uint64_t hi = lo + PS_PHOTON_CHUNK;
        if (hi > job->first + job->count)
            hi = job->first + job->count;
        if (!cur.counts)
            job->outs[k].failed = true;
        for (uint64_t i = lo; i < hi && !job->outs[k].failed; i++) {
            size_t s;
            uint64_t j;
            rank_of(plan, &cur, job->list ? job->list[i - job->first] : i, &s, &j);
            trace_photon(job->t, job->kind, s, j, &job->outs[k]);
        }
        size_t n = job->outs[k].map.count;
        uint64_t stored = atomic_fetch_add(&job->stored, n) + n;
        if (job->room && stored > job->room)
            atomic_store(&job->over, true);
        atomic_fetch_add(&job->done, 1);
    }
}

struct ps_traced {
    const char *path; /* the scene's, for messages */
    ps_map_kind kind;
    size_t chunks;
    chunk_out *outs; /* in index order */
    size_t count;    /* photons of all chunks */
};

void ps_traced_destroy(ps_traced *r)
{
    if (!r)
        return;
    for (size_t k = 0; k < r->chunks; k++) {
        ps_photon_map_free(&r->outs[k].map);
        ps_path_store_free(&r->outs[k].paths);
    }
    free(r->outs);
    free(r);
}

size_t ps_traced_count(const ps_traced *r) { return r ? r->count : 0; }

static ps_status trace_some(ps_tracer *t, ps_map_kind kind, uint64_t first, uint64_t count, const uint64_t *list,
                            uint64_t total, size_t stored, ps_traced **out, ps_error *err)
{
    *out = NULL;
    const char *path = ps_scene_path(t->scene);
    map_plan *plan = &t->plans[kind];
    if (!plan->enabled || count == 0)
        return PS_OK;
    if (!count_strata(plan, total, t->opt.records))
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory planning %llu photons", path,
                            (unsigned long long)total);

    trace_job job;
    memset(&job, 0, sizeof job);
    job.t = t;
    job.kind = kind;
    job.first = list ? 0 : first;
    job.count = count;
    job.list = list;
    job.chunks = (size_t)((count + PS_PHOTON_CHUNK - 1) / PS_PHOTON_CHUNK);
    atomic_init(&job.next, 0);
    atomic_init(&job.done, 0);
    atomic_init(&job.stored, 0);
    atomic_init(&job.over, false);
    uint64_t max_stored = t->opt.max_stored;
    if (max_stored && stored >= max_stored)
        return ps_error_set(err, PS_ERR_LIMIT,
                            "%s: the %s photon map is full: %llu photons, the most the memory budget allows", path,
                            ps_map_name(kind), (unsigned long long)stored);
    job.room = max_stored ? max_stored - stored : 0;
    ps_traced *r = calloc(1, sizeof *r);
    job.outs = r ? calloc(job.chunks, sizeof *job.outs) : NULL;
    if (!job.outs) {
        free(r);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory tracing %llu photons", path,
                            (unsigned long long)count);
    }
    r->path = path;
    r->kind = kind;
    r->chunks = job.chunks;
    r->outs = job.outs;
    for (size_t k = 0; k < job.chunks; k++)
        ps_photon_map_init(&job.outs[k].map, kind);

    int threads = t->threads < (int)job.chunks ? t->threads : (int)job.chunks;
    pthread_t tid[PS_TRACER_MAX_THREADS];
    int started = 0;
    for (; started < threads - 1; started++)
        if (pthread_create(&tid[started], NULL, worker, &job) != 0)
            break; /* fewer threads only makes it slower, never different */
    worker(&job);
    for (int k = 0; k < started; k++)
        pthread_join(tid[k], NULL);

    ps_status st = PS_OK;
    size_t done = atomic_load(&job.done);
    if (atomic_load(&job.over))
        st = ps_error_set(err, PS_ERR_LIMIT,
                          "%s: the %s photon map would hold more than %llu photons, the most the memory budget allows",
                          path, ps_map_name(kind), (unsigned long long)max_stored);
    else if (done < job.chunks)
        st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %.0f %% of the %s photons",
                          100.0 * ((double)job.first + (double)done * PS_PHOTON_CHUNK) / (double)total,
                          ps_map_name(kind));
    for (size_t k = 0; k < job.chunks && st == PS_OK; k++) {
        if (job.outs[k].failed || job.outs[k].map.count > SIZE_MAX - r->count)
            st = ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory storing photons", path);
        else
            r->count += job.outs[k].map.count;
    }
    if (st != PS_OK) {
        ps_traced_destroy(r);
        return st;
    }
    *out = r;
    return PS_OK;
}

ps_status ps_tracer_trace_range(ps_tracer *t, ps_map_kind kind, uint64_t first, uint64_t count, uint64_t total,
                                size_t stored, ps_traced **out, ps_error *err)
{
    *out = NULL;
    if (first > total || count > total - first)
        return ps_error_set(err, PS_ERR_RANGE, "%s: photons %llu..%llu lie beyond the map's total %llu",
                            ps_scene_path(t->scene), (unsigned long long)first, (unsigned long long)(first + count),
                            (unsigned long long)total);
    return trace_some(t, kind, first, count, NULL, total, stored, out, err);
}

ps_status ps_tracer_trace_list(ps_tracer *t, ps_map_kind kind, const uint64_t *idx, size_t n, uint64_t total,
                               size_t stored, ps_traced **out, ps_error *err)
{
    *out = NULL;
    for (size_t k = 0; k < n; k++)
        if (idx[k] >= total || (k > 0 && idx[k] <= idx[k - 1]))
            return ps_error_set(err, PS_ERR_RANGE, "%s: photon %llu out of order or beyond the map's total %llu",
                                ps_scene_path(t->scene), (unsigned long long)idx[k], (unsigned long long)total);
    return trace_some(t, kind, 0, n, idx, total, stored, out, err);
}

ps_status ps_traced_join_paths(ps_traced *r, ps_path_store *dst, const uint64_t *idx, ps_error *err)
{
    if (!r || !r->outs)
        return PS_OK;
    /* All or nothing: room first, then copies that cannot fail. */
    size_t nv = 0, nr = 0, nt = 0;
    for (size_t k = 0; k < r->chunks; k++)
        nv += r->outs[k].paths.vcount, nr += r->outs[k].paths.count, nt += r->outs[k].paths.tcount;
    if (nv > UINT32_MAX - dst->vcount || !PS_RESERVE(dst->vert, dst->vcap, dst->vcount + nv) ||
        !PS_RESERVE(dst->thr, dst->tcap, dst->tcount + nt) ||
        (!idx && !PS_RESERVE(dst->rec, dst->cap, dst->count + nr)))
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for path records", r->path);
    for (size_t k = 0; k < r->chunks; k++) {
        const ps_path_store *src = &r->outs[k].paths;
        if (idx) {
            (void)ps_path_store_put(dst, src, idx);
            idx += src->count;
        } else {
            (void)ps_path_store_append(dst, src);
        }
    }
    return PS_OK;
}

ps_path_quant ps_tracer_path_quant(const ps_tracer *t) { return t->quant; }
bool ps_tracer_records(const ps_tracer *t) { return t->opt.records; }

static bool same_sampling(const stratum *sa, const stratum *sb)
{
    if (sa->light != sb->light || sa->target != sb->target || sa->has_caustic_cone != sb->has_caustic_cone ||
        sa->key != sb->key || memcmp(sa->rotation, sb->rotation, sizeof sa->rotation) != 0)
        return false;
    return !sa->has_caustic_cone || memcmp(&sa->caustic_cone, &sb->caustic_cone, sizeof sa->caustic_cone) == 0;
}

/* Photon i's stratum: the kept sequence's, else found again. */
static size_t stratum_at(const map_plan *p, uint64_t i) { return p->seq ? (size_t)p->seq[i] : stratum_of(p, i); }

/* Indices a job of the photon sources' first pass covers (its counts below
 * its first index from count_below, as a pass from index 0 would reach). */
#define SOURCE_JOB_INDICES ((uint64_t)1 << 19)
/* Indices a job of ps_source_map_fill covers, and the jobs one call of it
 * runs at most (its counters are made once, with the map). */
#define FILL_JOB_INDICES ((uint64_t)1 << 15)
#define FILL_JOBS 16

/* Whether two plans cut the index line into the same strata: the same
 * stratum at every index (stratum_of reads only these). */
static bool same_cuts(const map_plan *pa, const map_plan *pb)
{
    if (pa->count != pb->count || memcmp(&pa->rotation0, &pb->rotation0, sizeof pa->rotation0) != 0)
        return false;
    for (size_t k = 0; k < pa->count; k++)
        if (memcmp(&pa->strata[k].cdf, &pb->strata[k].cdf, sizeof(double)) != 0)
            return false;
    return true;
}

/* b's counts and stratum sequence copied from a's (counted for total, with
 * the same cuts): what count_strata would find, without its pass over every
 * index for the sequence (an edit that keeps the shares: a power edit of a
 * lone light, a diffuse object moved). False when out of memory or a has no
 * sequence b needs. */
static bool copy_counts(map_plan *pb, const map_plan *pa, uint64_t total, bool keep_seq)
{
    if (keep_seq && !pa->seq)
        return false;
    free(pb->seq);
    pb->seq = NULL;
    if (keep_seq) {
        pb->seq = malloc(total ? (size_t)total : 1);
        if (!pb->seq)
            return false;
        memcpy(pb->seq, pa->seq, (size_t)total);
    }
    memcpy(pb->counts, pa->counts, pa->count * sizeof *pb->counts);
    set_counted(pb, total);
    return true;
}

struct ps_source_map {
    const map_plan *pb; /* the edited scene's plan (its tracer outlives the map) */
    uint64_t end;
    bool identity;      /* every source is its own index or none */
    bool none;          /* no index has a source */
    size_t *match;      /* b's stratum kb is a's match[kb] (SIZE_MAX: none) */
    bool *repower;      /* ... with another power or count */
    uint64_t *start;    /* a's photons below end: stratum ka's from start[ka] in byrank */
    uint64_t *byrank;   /* a's indices below end by stratum, then rank (not for identity) */
    uint64_t *scratch;  /* a counter per stratum per fill job */
    size_t width;
};

typedef struct source_job {
    const map_plan *pa;
    const ps_source_map *m;
    uint64_t *scratch;
    uint64_t from, to;  /* fill: the range; out[i - from] */
    ps_photon_source *out;
} source_job;

/* The first pass: a's indices below end by stratum and rank. */
static void byrank_range(void *arg, size_t job)
{
    const source_job *c = arg;
    const map_plan *pa = c->pa;
    const ps_source_map *m = c->m;
    uint64_t from = (uint64_t)job * SOURCE_JOB_INDICES;
    uint64_t to = from + SOURCE_JOB_INDICES < m->end ? from + SOURCE_JOB_INDICES : m->end;
    uint64_t *count = c->scratch + job * m->width;
    count_below(pa, from, count);
    for (uint64_t i = from; i < to; i++) {
        size_t ka = stratum_at(pa, i);
        m->byrank[m->start[ka] + count[ka]++] = i;
    }
}

/* The sources of indices [from, to): ranks counted on from those below
 * `from` (count_below), so any range gives what a pass from index 0 gives. */
static void fill_range(const ps_source_map *m, uint64_t from, uint64_t to, ps_photon_source *out,
                       uint64_t *count)
{
    const map_plan *pb = m->pb;
    if (!pb->enabled) {
        for (uint64_t i = from; i < to; i++)
            out[i - from] = (ps_photon_source){PS_SOURCE_NONE, 0, UINT32_MAX, false};
        return;
    }
    count_below(pb, from, count);
    for (uint64_t i = from; i < to; i++) {
        size_t kb = stratum_at(pb, i);
        uint64_t j = count[kb]++;
        ps_photon_source o = {PS_SOURCE_NONE, j, (uint32_t)kb, false};
        size_t ka = m->match[kb];
        if (ka != SIZE_MAX && (m->identity || j < m->start[ka + 1] - m->start[ka])) {
            /* The same cuts and stratum: a's j-th photon of it is index i. */
            o.from = m->identity ? i : m->byrank[m->start[ka] + j];
            o.repower = m->repower[kb];
        }
        out[i - from] = o;
    }
}

static void fill_job(void *arg, size_t job)
{
    const source_job *c = arg;
    uint64_t from = c->from + (uint64_t)job * FILL_JOB_INDICES;
    uint64_t to = from + FILL_JOB_INDICES < c->to ? from + FILL_JOB_INDICES : c->to;
    fill_range(c->m, from, to, c->out + (from - c->from), c->m->scratch + job * c->m->width);
}

void ps_source_map_destroy(ps_source_map *m)
{
    if (!m)
        return;
    free(m->match), free(m->repower), free(m->start), free(m->byrank), free(m->scratch);
    free(m);
}

ps_status ps_source_map_create(ps_tracer *a, ps_tracer *b, ps_map_kind kind, uint64_t total, uint64_t end,
                               const bool *resampled, size_t light_count, ps_source_map **out, ps_error *err)
{
    *out = NULL;
    const char *path = ps_scene_path(b->scene);
    map_plan *pa = &a->plans[kind], *pb = &b->plans[kind];
    ps_source_map *m = calloc(1, sizeof *m);
    if (!m)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory matching %llu photons", path,
                            (unsigned long long)end);
    m->pb = pb;
    m->end = end;
    m->none = true;
    if (!pb->enabled) {
        *out = m;
        return PS_OK;
    }
    if (pa->enabled && !count_strata(pa, total, a->opt.records))
        goto nomem;
    /* An edit that keeps the cuts keeps the rank table: copied, not counted. */
    bool copied = pa != pb && pa->enabled && !(pb->counted && pb->counted_total == total) && same_cuts(pa, pb) &&
                  copy_counts(pb, pa, total, b->opt.records);
    if (!copied && !count_strata(pb, total, b->opt.records))
        goto nomem;
    size_t na = pa->enabled ? pa->count : 0;
    m->width = pb->count > na ? pb->count : na;
    m->match = malloc(pb->count * sizeof *m->match);
    m->repower = calloc(pb->count, sizeof *m->repower);
    m->scratch = malloc(FILL_JOBS * m->width * sizeof *m->scratch);
    if (!m->match || !m->repower || !m->scratch)
        goto nomem;
    m->identity = pa->enabled && (pa == pb || same_cuts(pa, pb));
    for (size_t kb = 0; kb < pb->count; kb++) {
        m->match[kb] = SIZE_MAX;
        const stratum *sb = &pb->strata[kb];
        if (!pa->enabled || (sb->light < light_count && resampled[sb->light]))
            continue;
        for (size_t ka = 0; ka < pa->count; ka++)
            if (same_sampling(&pa->strata[ka], sb))
                m->match[kb] = ka;
        /* The same light power and count: the stored bytes are already those
         * of b's trace (the same T, dither and product). */
        size_t ka = m->match[kb];
        m->repower[kb] = ka != SIZE_MAX && (memcmp(&pa->strata[ka].power, &sb->power, sizeof(ps_rgb)) != 0 ||
                                            memcmp(&pa->scale[ka], &pb->scale[kb], sizeof(double)) != 0);
        m->none = m->none && ka == SIZE_MAX;
        m->identity = m->identity && (ka == SIZE_MAX || ka == kb);
    }
    if (m->none || m->identity || end == 0) {
        *out = m;
        return PS_OK;
    }
    /* a's photons below end, per stratum (count_below); then a's indices by rank, in jobs on every core (an edit's update
     * waits for it; the second pass, fill, is left to the repair's steps). */
    size_t jobs = (size_t)((end + SOURCE_JOB_INDICES - 1) / SOURCE_JOB_INDICES);
    m->start = calloc(na + 1, sizeof *m->start);
    m->byrank = malloc(end * sizeof *m->byrank);
    uint64_t *scratch = malloc(jobs * m->width * sizeof *scratch);
    if (!m->start || !m->byrank || !scratch) {
        free(scratch);
        goto nomem;
    }
    count_below(pa, end, m->start + 1);
    for (size_t ka = 0; ka < na; ka++)
        m->start[ka + 1] += m->start[ka];
    source_job c = {pa, m, scratch, 0, 0, NULL};
    ps_run_jobs(jobs, ps_online_cores(), byrank_range, &c);
    free(scratch);
    *out = m;
    return PS_OK;
nomem:
    ps_source_map_destroy(m);
    return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory matching %llu photons", path, (unsigned long long)end);
}

bool ps_source_map_identity(const ps_source_map *m) { return m->identity; }
bool ps_source_map_none(const ps_source_map *m) { return m->none; }

void ps_source_map_fill(const ps_source_map *m, uint64_t from, uint64_t to, ps_photon_source *out)
{
    if (to > m->end)
        to = m->end;
    while (from < to) {
        uint64_t n = to - from;
        if (n > FILL_JOBS * FILL_JOB_INDICES)
            n = FILL_JOBS * FILL_JOB_INDICES;
        source_job c = {NULL, m, NULL, from, from + n, out};
        ps_run_jobs((size_t)((n + FILL_JOB_INDICES - 1) / FILL_JOB_INDICES), ps_online_cores(), fill_job, &c);
        from += n;
        out += n;
    }
}

ps_status ps_tracer_photon_sources(ps_tracer *a, ps_tracer *b, ps_map_kind kind, uint64_t total, uint64_t end,
                                   const bool *resampled, size_t light_count, ps_photon_source *out,
                                   ps_error *err)
{
    ps_source_map *m;
    ps_status st = ps_source_map_create(a, b, kind, total, end, resampled, light_count, &m, err);
    if (st != PS_OK)
        return st;
    ps_source_map_fill(m, 0, end, out);
    ps_source_map_destroy(m);
    return PS_OK;
}

void ps_tracer_repower(ps_tracer *t, ps_map_kind kind, const ps_photon_source *src, const ps_path_thr *thr,
                       size_t n, ps_photon *ph)
{
    const map_plan *p = &t->plans[kind];
    const stratum *st = &p->strata[src->stratum];
    for (size_t s = 0; s < n; s++)
        ps_rgbe_encode(stored_power(&thr[s], st->power, p->scale[src->stratum]),
                       photon_dither(st->dither_key, src->rank, (unsigned)s), ph[s].rgbe);
}

bool ps_tracer_photon_rank(ps_tracer *t, ps_map_kind kind, uint64_t i, uint64_t total, uint32_t *in_stratum,
                           uint64_t *rank)
{
    map_plan *p = &t->plans[kind];
    if (!p->enabled || i >= total || !count_strata(p, total, t->opt.records))
        return false;
    uint64_t *counts = malloc(p->count * sizeof *counts);
    if (!counts)
        return false;
    rank_cursor c = {0, counts, false};
    size_t k;
    rank_of(p, &c, i, &k, rank);
    *in_stratum = (uint32_t)k;
    free(counts);
    return true;
}

uint32_t ps_tracer_photon_light(ps_tracer *t, ps_map_kind kind, uint64_t i, uint64_t total)
{
    map_plan *p = &t->plans[kind];
    if (!p->enabled || !count_strata(p, total, t->opt.records))
        return UINT32_MAX;
    return p->strata[stratum_of(p, i)].light;
}

ps_status ps_traced_join(ps_traced *r, ps_photon_map *m, ps_error *err)
{
    if (!r)
        return PS_OK;
    /* Join the chunks in index order: the array never depends on who traced what.
     * An empty map takes exactly what was traced: a map traced in one call
     * (the reference renderer's) then has no unused capacity, and a map that
     * grows batch by batch (the feed's) doubles from its first batch. */
    if (r->count > SIZE_MAX - m->count)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory storing photons", r->path);
    size_t need = m->count + r->count;
    if (!(m->count == 0 ? ps_photon_map_reserve_exact(m, need) : ps_photon_map_reserve(m, need)))
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory storing photons", r->path);
    for (size_t k = 0; k < r->chunks; k++) {
        /* Cannot fail: the room is reserved. */
        (void)ps_photon_map_append(m, &r->outs[k].map);
        ps_photon_map_free(&r->outs[k].map); /* each chunk goes as soon as it is in */
    }
    return PS_OK;
}

ps_status ps_tracer_trace(ps_tracer *t, ps_map_kind kind, uint64_t first, uint64_t count, uint64_t total,
                          ps_photon_map *m, ps_error *err)
{
    ps_traced *r;
    ps_status st = ps_tracer_trace_range(t, kind, first, count, total, m->count, &r, err);
    if (st == PS_OK)
        st = ps_traced_join(r, m, err);
    ps_traced_destroy(r);
    return st;
}


