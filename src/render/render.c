/* render.c: eye rays, the split rendering equation, tiles on threads. */
#include "render/render.h"
#include "core/clock.h"
#include "render/irrcache.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "scene/bsdf.h"
#include "scene/camera.h"

/* Pixels are rendered in square tiles handed to threads in order. */
#define TILE 16
#define MAX_THREADS 256

static const char *const component_names[PS_COMPONENT_COUNT] = {"all", "direct", "caustic", "indirect", "specular"};

const char *ps_component_name(ps_component c) { return component_names[c]; }

typedef struct render_job {
    const ps_world *world;
    const ps_scene *scene;
    const ps_material *materials;
    const ps_light *lights;
    size_t light_count;
    const ps_light_sampler *ls;
    const ps_render_maps *maps;
    const ps_render_options *o;
    ps_camera_frame cam;
    ps_image *img;
    float *accum; /* the pixel filter's tile buffers (NULL: the box) */
    int halo;
    int tiles_x, tiles;
    atomic_int next_tile, done_tiles;
    atomic_int taken_tiles; /* shared (ps_render_share): tiles this process took */
    /* The irradiance cache (see render.h) and, while it is made, the level
     * (grid spacing) and chunk of positions being worked on. */
    ps_irrcache *irr;
    double footprint; /* a pixel's width at unit distance */
    int cache_level, cache_cols;
    int64_t cache_total, cache_stride, chunk_begin, chunk_end;
    ps_irr_record *chunk;
    bool *chunk_ok;
    atomic_int_least64_t next_record;
    atomic_uint_least64_t rays;
} render_job;

/* Per-thread state: the radiance-estimate scratch and the ray count. */
typedef struct worker {
    render_job *job;
    ps_neighbor *scratch;
    ps_irr_sample *samples; /* a cache record's gather rays */
    uint64_t rays;
    bool reports;  /* the calling thread's: reports progress */
    float *tile;   /* shared (ps_render_share): a finished tile's buffer */
} worker;

static size_t max_k(const ps_render_options *o) { return o->caustic.k > o->global.k ? o->caustic.k : o->global.k; }

/* ---- direct light ---------------------------------------------------------- */

static bool visible(worker *wk, const ps_surface *sp, ps_vec3 dir, double dist)
{
    wk->rays++;
    const ps_world *w = wk->job->world;
    ps_ray r = ps_world_spawn(w, sp, dir);
    /* Stop short of the light by the offset: a mesh light's own face is geometry. */
    return !ps_world_occluded(w, r, dist - 2.0 * ps_world_epsilon(w));
}

/* Radiance at sp towards wo from IES light L (a point luminaire): exact, one
 * shadow ray; its intensity towards sp is power * candela / flux there. */
static ps_rgb direct_from_ies(worker *wk, const ps_light *L, const ps_surface *sp, ps_vec3 n, ps_vec3 wo,
                              const ps_material *m)
{
    ps_vec3 to = ps_v3_sub(L->position, sp->p);
    double d2 = ps_v3_len2(to), d = sqrt(d2);
    if (!(d > 0.0))
        return ps_rgb_gray(0.0);
    ps_vec3 wi = ps_v3_scale(to, 1.0 / d);
    double cos_x = ps_v3_dot(wi, n);
    if (cos_x <= 0.0)
        return ps_rgb_gray(0.0);
    double density = ps_light_ies_density(wk->job->scene, L, ps_v3_neg(wi)); /* 1/sr */
    if (!(density > 0.0) || !visible(wk, sp, wi, d))
        return ps_rgb_gray(0.0);
    ps_rgb f = ps_bsdf_eval(m, n, ps_v3_neg(wi), wo);
    return ps_rgb_scale(ps_rgb_mul(f, L->power), density * cos_x / d2);
}

/* Radiance at sp towards wo from every light, by shadow rays. n: the shading
 * normal on wo's side. */
static ps_rgb direct_light(worker *wk, const ps_surface *sp, ps_vec3 n, ps_vec3 wo, const ps_material *m, ps_rng *rng)
{
    const render_job *job = wk->job;
    ps_rgb sum = ps_rgb_gray(0.0);
    for (size_t l = 0; l < job->light_count; l++) {
        const ps_light *L = &job->lights[l];
        if (L->type == PS_LIGHT_IES) {
            sum = ps_rgb_add(sum, direct_from_ies(wk, L, sp, n, wo, m));
            continue;
        }
        if (L->type == PS_LIGHT_POINT || L->type == PS_LIGHT_SPOT) {
            ps_vec3 to = ps_v3_sub(L->position, sp->p);
            double d2 = ps_v3_len2(to), d = sqrt(d2);
            if (!(d > 0.0))
                continue;
            ps_vec3 wi = ps_v3_scale(to, 1.0 / d);
            double cos_x = ps_v3_dot(wi, n);
            if (cos_x <= 0.0)
                continue;
            double intensity; /* W/sr */
            if (L->type == PS_LIGHT_POINT) {
                intensity = 1.0 / (4.0 * PS_PI);
            } else {
                if (-ps_v3_dot(wi, L->direction) < L->cos_angle)
                    continue;
                intensity = 1.0 / ps_cone_solid_angle(L->cos_angle);
            }
            if (!visible(wk, sp, wi, d))
                continue;
            ps_rgb f = ps_bsdf_eval(m, n, ps_v3_neg(wi), wo);
            sum = ps_rgb_add(sum, ps_rgb_scale(ps_rgb_mul(f, L->power), intensity * cos_x / d2));
            continue;
        }
        /* Area lights: points uniform over the area (density 1/A), radiance
         * L_e = power / (pi A) from the emitting side. */
        int n_samples = job->o->light_samples;
        ps_rgb acc = ps_rgb_gray(0.0);
        for (int s = 0; s < n_samples; s++) {
            ps_vec3 q, nl;
            double u0 = (s + ps_rng_uniform(rng)) / n_samples, u1 = ps_rng_uniform(rng);
            ps_light_sample_point(job->ls, (uint32_t)l, u0, u1, &q, &nl);
            ps_vec3 to = ps_v3_sub(q, sp->p);
            double d2 = ps_v3_len2(to), d = sqrt(d2);
            if (!(d > 0.0))
                continue;
            ps_vec3 wi = ps_v3_scale(to, 1.0 / d);
            double cos_x = ps_v3_dot(wi, n), cos_l = -ps_v3_dot(wi, nl);
            if (cos_x <= 0.0 || cos_l <= 0.0)
                continue;
            if (!visible(wk, sp, wi, d))
                continue;
            ps_rgb f = ps_bsdf_eval(m, n, ps_v3_neg(wi), wo);
            acc = ps_rgb_add(acc, ps_rgb_scale(f, cos_x * cos_l / d2));
        }
        /* L_e * A / samples = power / (pi samples). */
        sum = ps_rgb_add(sum, ps_rgb_scale(ps_rgb_mul(acc, L->power), PS_INV_PI / n_samples));
    }
    return sum;
}

/* ---- indirect light ------------------------------------------------------- */

/* Follows a gather ray to the first diffuse or glossy surface (through a few
 * mirror/glass bounces) and returns the radiance it sends back, from the
 * precomputed irradiance there: albedo / pi * E (Christensen's approximation:
 * the diffuse part only). */
static ps_rgb gather_ray(worker *wk, ps_ray r, ps_rng *rng, double *first_t)
{
    const render_job *job = wk->job;
    ps_rgb beta = ps_rgb_gray(1.0);
    for (int bounce = 0; bounce <= PS_RENDER_GATHER_SPECULAR; bounce++) {
        ps_surface sp;
        wk->rays++;
        if (!ps_world_intersect(job->world, r, INFINITY, &sp)) {
            if (first_t && bounce == 0)
                *first_t = INFINITY;
            return ps_rgb_gray(0.0);
        }
        if (first_t && bounce == 0)
            *first_t = sp.t;
        ps_material textured;
        const ps_material *m = ps_surface_material(job->scene, job->materials, &sp, &textured);
        bool front = ps_v3_dot(r.d, sp.ng) < 0.0;
        ps_vec3 n = front ? sp.ns : ps_v3_neg(sp.ns);
        ps_vec3 dir;
        if (m->type == PS_MAT_MIRROR) {
            beta = ps_rgb_mul(beta, m->reflectance);
            dir = ps_reflect(r.d, n);
        } else if (m->type == PS_MAT_DIELECTRIC) {
            double eta_i = front ? 1.0 : m->ior, eta_t = front ? m->ior : 1.0;
            double f = ps_fresnel_dielectric(-ps_v3_dot(r.d, n), eta_i, eta_t);
            if (ps_rng_uniform(rng) < f || !ps_refract(r.d, n, eta_i / eta_t, &dir))
                dir = ps_reflect(r.d, n);
            else
                beta = ps_rgb_mul(beta, m->transmittance);
        } else {
            /* Where no precomputed value lies near enough (a corner, a thin
             * object), estimate it here from the full map instead. */
            ps_rgb e;
            if (!ps_irradiance_lookup(job->maps->irradiance, sp.p, n, job->o->irradiance_radius, &e))
                e = ps_photon_irradiance(job->maps->full, sp.p, n, &job->o->global, wk->scratch);
            return ps_rgb_mul(beta, ps_rgb_scale(ps_rgb_mul(e, m->albedo), PS_INV_PI));
        }
        r = ps_world_spawn(job->world, &sp, dir);
    }
    return ps_rgb_gray(0.0);
}

/* ---- the irradiance cache -------------------------------------------------- */

static bool emitter_hit(const render_job *job, ps_ray r, double tmax, ps_rgb *le);

/* Records are made before the image, at the diffuse surfaces that eye rays
 * through pixel positions reach, directly or through mirrors and glass, on
 * ever finer grids of positions: PS_RENDER_CACHE_COARSE pixels apart, then
 * half that, down to o->cache_spacing. A position gets a record only where
 * the records made so far do not reach, so records lie as densely as their
 * own validity radii ask (Ward's placement, made deterministic): each grid's
 * positions are taken in chunks of CACHE_CHUNK, every position of a chunk
 * looks at the cache as the earlier chunks left it, the chunk's records are
 * made in parallel and then added in position order. A chunk's positions are
 * spread over the image (a golden-ratio stride through the grid), so two of
 * them rarely ask for the same record. */
#define CACHE_CHUNK 1024
/* The diffuse surfaces one position's eye path may reach (both branches at
 * the first glass surfaces, then the likelier one). */
#define CACHE_HITS 8
#define CACHE_SPLIT_DEPTH 3

typedef struct cache_hit {
    ps_surface sp;
    ps_vec3 n;        /* the shading normal on the side the path came from */
    double footprint; /* how far apart the surface points of neighbouring pixels are there */
    double length_footprint; /* a pixel's width at the eye path's length (no curvature) */
} cache_hit;

/* The diffuse or glossy surfaces the eye ray r reaches through mirrors and
 * glass. Beside it goes the ray `off` of the pixel position one pixel
 * further along both axes, making the same choices (a ray differential by
 * finite differences, Igehy 1999): where both land on the same surface, the
 * distance between their points, over sqrt 2, is the pixel's footprint
 * there, minified or magnified by every curved mirror and lens on the way.
 * Where the offset ray leaves the path, the footprint is the eye path's
 * length times a pixel's width at unit distance (flat mirrors). */
static int cache_path(worker *wk, ps_ray r, ps_ray off, bool has_off, double dist, int depth, cache_hit *hits,
                      int count)
{
    const render_job *job = wk->job;
    ps_surface sp, so;
    wk->rays++;
    if (count >= CACHE_HITS || depth > PS_RENDER_MAX_SPECULAR || !ps_world_intersect(job->world, r, INFINITY, &sp))
        return count;
    ps_rgb le;
    if (emitter_hit(job, r, sp.t, &le))
        return count;
    if (has_off) {
        wk->rays++;
        has_off = ps_world_intersect(job->world, off, INFINITY, &so) && so.material == sp.material;
    }
    ps_material textured;
    const ps_material *m = ps_surface_material(job->scene, job->materials, &sp, &textured);
    bool front = ps_v3_dot(r.d, sp.ng) < 0.0;
    ps_vec3 n = front ? sp.ns : ps_v3_neg(sp.ns);
    ps_vec3 no = has_off ? (ps_v3_dot(off.d, so.ng) < 0.0 ? so.ns : ps_v3_neg(so.ns)) : n;
    dist += sp.t;
    if (m->type == PS_MAT_MIRROR) {
        ps_ray ro = has_off ? ps_world_spawn(job->world, &so, ps_reflect(off.d, no)) : off;
        return cache_path(wk, ps_world_spawn(job->world, &sp, ps_reflect(r.d, n)), ro, has_off, dist, depth + 1, hits,
                          count);
    }
    if (m->type == PS_MAT_DIELECTRIC) {
        double eta_i = front ? 1.0 : m->ior, eta_t = front ? m->ior : 1.0;
        double f = ps_fresnel_dielectric(-ps_v3_dot(r.d, n), eta_i, eta_t);
        ps_vec3 refr, refr_o;
        bool can_refract = ps_refract(r.d, n, eta_i / eta_t, &refr);
        ps_ray refl = ps_world_spawn(job->world, &sp, ps_reflect(r.d, n));
        ps_ray refl_o = has_off ? ps_world_spawn(job->world, &so, ps_reflect(off.d, no)) : off;
        if (!can_refract)
            return cache_path(wk, refl, refl_o, has_off, dist, depth + 1, hits, count);
        bool off_refracts = has_off && ps_refract(off.d, no, eta_i / eta_t, &refr_o);
        ps_ray tr = ps_world_spawn(job->world, &sp, refr);
        ps_ray tr_o = off_refracts ? ps_world_spawn(job->world, &so, refr_o) : off;
        if (depth < CACHE_SPLIT_DEPTH) {
            count = cache_path(wk, tr, tr_o, off_refracts, dist, depth + 1, hits, count);
            return cache_path(wk, refl, refl_o, has_off, dist, depth + 1, hits, count);
        }
        if (f > 0.5)
            return cache_path(wk, refl, refl_o, has_off, dist, depth + 1, hits, count);
        return cache_path(wk, tr, tr_o, off_refracts, dist, depth + 1, hits, count);
    }
    if (ps_rgb_is_black(m->albedo))
        return count;
    hits[count].sp = sp;
    hits[count].n = n;
    hits[count].footprint = hits[count].length_footprint = job->footprint * dist;
    if (has_off)
        hits[count].footprint = fmax(hits[count].footprint, ps_v3_len(ps_v3_sub(so.p, sp.p)) / sqrt(2.0));
    return count + 1;
}

/* A record at hit h from o->cache_rays stratified gather rays (numbers from
 * `index` alone), its radius clamped to [MIN_PX x the finest grid spacing,
 * MAX_PX] pixel footprints there. False when it is not usable. */
static bool cache_record(worker *wk, const cache_hit *h, uint64_t index, ps_irr_record *rec)
{
    const render_job *job = wk->job;
    const ps_render_options *o = job->o;
    ps_rng rng = ps_rng_make(ps_hash64(o->seed ^ PS_RENDER_CACHE_KEY), PS_STREAM_PIXEL, index);
    int m, n;
    ps_irr_strata(o->cache_rays, &m, &n);
    ps_vec3 t, b;
    ps_v3_basis(h->n, &t, &b);
    for (int j = 0; j < m; j++)
        for (int k = 0; k < n; k++) {
            double u1 = ps_rng_uniform(&rng), u2 = ps_rng_uniform(&rng);
            ps_vec3 dir = ps_irr_stratum_direction(t, b, h->n, m, n, j, k, u1, u2);
            ps_irr_sample *s = &wk->samples[j * n + k];
            s->l = ps_rgb_gray(0.0);
            s->t = INFINITY;
            if (ps_v3_dot(dir, h->sp.ng) * ps_v3_dot(h->n, h->sp.ng) <= 0.0)
                continue; /* an interpolated normal pointed it into the surface */
            s->l = gather_ray(wk, ps_world_spawn(job->world, &h->sp, dir), &rng, &s->t);
        }
    ps_irr_record_from_samples(h->sp.p, t, b, h->n, m, n, wk->samples, rec);
    /* The clamps from the footprint, but the lower one no larger than at
     * the path's length: behind a convex mirror neighbouring pixels see
     * points far apart, and a contact shadow there would otherwise spread
     * over all of them (the extra records cost few pixels). */
    double lo = PS_RENDER_CACHE_MIN_PX * o->cache_spacing * fmin(h->footprint, h->length_footprint);
    double hi = PS_RENDER_CACHE_MAX_PX * h->footprint;
    /* The split-sphere radius, but reaching (a R) no further than the
     * nearest thing its rays met: the harmonic mean of a floor's record
     * beside a sphere is long, and without this its value spread into the
     * sphere's contact shadow, where no record was then made (placement
     * found it covered). And no longer than where the translational
     * gradient would change E by all of it (Krivanek et al. 2006's
     * gradient limit). Then clamped to the footprints. */
    double r = fmin(rec->r_harmonic, PS_RENDER_CACHE_NEAREST * rec->t_min);
    for (int c = 0; c < 3; c++) {
        double e = c == 0 ? rec->e.r : c == 1 ? rec->e.g : rec->e.b, g = ps_v3_len(rec->grad_t[c]);
        if (g > 0.0 && e > 0.0)
            r = fmin(r, e / g);
    }
    double unclamped = r;
    r = fmin(fmax(r, lo), hi);
    if (r > unclamped) {
        /* Near a corner the gradients are steep over the short harmonic
         * radius; extrapolated over the longer clamped one they would
         * overshoot, so they shrink with it (Tabellion & Lamorlette 2004). */
        double s = unclamped / r;
        for (int c = 0; c < 3; c++)
            rec->grad_t[c] = ps_v3_scale(rec->grad_t[c], s);
    }
    rec->r = r;
    /* A record whose rays met something (nearly) where it stands lies on
     * an edge: half its hemisphere is the other wall, where the photon
     * maps' estimates are biased low, and its value would spread over the
     * floor radius; rounding decides whether a position hits it, so it
     * would also make the image depend on the scene's scale. Not made: its
     * neighbours reach there, or the point gathers. */
    if (rec->t_min < PS_RENDER_CACHE_EDGE * lo)
        return false;
    bool ok = isfinite(r) && r > 0.0 && ps_rgb_isfinite(rec->e);
    for (int c = 0; c < 3 && ok; c++)
        ok = isfinite(ps_v3_len2(rec->grad_r[c])) && isfinite(ps_v3_len2(rec->grad_t[c]));
    return ok;
}

/* The grid position of a level's i-th position, i-th in the golden-ratio order. */
static void cache_position(const render_job *job, int64_t i, double *px, double *py)
{
    int64_t g = (i * job->cache_stride) % job->cache_total;
    int spacing = job->cache_level;
    *px = fmin((double)(g % job->cache_cols) * spacing + 0.5 * spacing, job->o->width - 0.5);
    *py = fmin((double)(g / job->cache_cols) * spacing + 0.5 * spacing, job->o->height - 0.5);
}

/* Takes the chunk's positions until none are left: the records each needs. */
static void *cache_worker(void *arg)
{
    worker *wk = arg;
    render_job *job = wk->job;
    /* Shared with other processes, this one takes every parts-th position. */
    const ps_render_share *sh = job->o->share;
    int64_t part = sh ? sh->part : 0, parts = sh ? sh->parts : 1;
    for (int64_t i; !ps_cancelled(job->o->cancel) &&
                    (i = job->chunk_begin + part + parts * atomic_fetch_add(&job->next_record, 1)) < job->chunk_end;) {
        int64_t slot = (i - job->chunk_begin) * CACHE_HITS;
        double px, py;
        cache_position(job, i, &px, &py);
        cache_hit hits[CACHE_HITS];
        int nh = cache_path(wk, ps_camera_ray(&job->cam, px, py), ps_camera_ray(&job->cam, px + 1.0, py + 1.0), true,
                            0.0, 0, hits, 0);
        for (int h = 0; h < CACHE_HITS; h++)
            job->chunk_ok[slot + h] = false;
        for (int h = 0; h < nh; h++) {
            if (ps_irrcache_covered(job->irr, hits[h].sp.p, hits[h].n, PS_RENDER_CACHE_PLACE))
                continue;
            uint64_t index = ((uint64_t)job->cache_level << 48) ^ ((uint64_t)i * CACHE_HITS + (uint64_t)h);
            job->chunk_ok[slot + h] = cache_record(wk, &hits[h], index, &job->chunk[slot + h]);
        }
    }
    return NULL;
}

/* Fills job->irr level by level, chunk by chunk (see above). */
static ps_status cache_build(render_job *job, worker *wk, int threads, ps_error *err)
{
    const ps_render_options *o = job->o;
    job->chunk = malloc(CACHE_CHUNK * CACHE_HITS * sizeof *job->chunk);
    job->chunk_ok = malloc(CACHE_CHUNK * CACHE_HITS * sizeof *job->chunk_ok);
    if (!job->chunk || !job->chunk_ok)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the irradiance cache");
    int coarse = o->cache_spacing;
    while (coarse * 2 <= PS_RENDER_CACHE_COARSE)
        coarse *= 2;
    ps_status st = PS_OK;
    for (int level = coarse; st == PS_OK; level /= 2) {
        job->cache_level = level;
        job->cache_cols = (o->width + level - 1) / level;
        job->cache_total = (int64_t)job->cache_cols * ((o->height + level - 1) / level);
        int64_t stride = (int64_t)(0.6180339887498949 * (double)job->cache_total) | 1;
        while (stride > 1) { /* coprime with the total: every position once */
            int64_t x = stride, y = job->cache_total;
            while (y) {
                int64_t t = x % y;
                x = y;
                y = t;
            }
            if (x == 1)
                break;
            stride += 2;
        }
        job->cache_stride = stride % job->cache_total ? stride % job->cache_total : 1;
        for (int64_t begin = 0; begin < job->cache_total && st == PS_OK; begin += CACHE_CHUNK) {
            job->chunk_begin = begin;
            job->chunk_end = begin + CACHE_CHUNK < job->cache_total ? begin + CACHE_CHUNK : job->cache_total;
            atomic_store(&job->next_record, 0);
            if (o->share) /* the slots of other processes' positions stay empty until the exchange */
                memset(job->chunk_ok, 0, CACHE_CHUNK * CACHE_HITS * sizeof *job->chunk_ok);
            pthread_t tid[MAX_THREADS];
            int started = 0;
            for (; started < threads - 1; started++)
                if (pthread_create(&tid[started], NULL, cache_worker, &wk[started + 1]) != 0)
                    break;
            cache_worker(&wk[0]);
            for (int i = 0; i < started; i++)
                pthread_join(tid[i], NULL);
            if (o->share)
                st = o->share->cache_exchange(o->share->user, job->chunk, job->chunk_ok,
                                              (size_t)(job->chunk_end - begin) * CACHE_HITS, ps_cancelled(o->cancel), err);
            if (st != PS_OK)
                return st;
            if (ps_cancelled(o->cancel))
                return PS_OK; /* the tiles stop at once and report it */
            for (int64_t s = 0; s < (job->chunk_end - begin) * CACHE_HITS && st == PS_OK; s++)
                if (job->chunk_ok[s])
                    st = ps_irrcache_add(job->irr, &job->chunk[s], err);
        }
        if (level / 2 < o->cache_spacing)
            break;
    }
    return st;
}

/* Light from other surfaces reflected at sp towards wo. With final
 * gathering, the BRDF is split into its two terms and each is sampled with
 * its own rays (no weighting needed: the terms add): cosine-distributed rays
 * for albedo / pi, whose estimate is pi f_d L = albedo L, and rays in the
 * Phong lobe for the glossy term, whose estimate is f_s L cos / pdf =
 * specular (e + 2) / (e + 1) cos(theta) L. Both are stratified in their
 * first dimension. Without gathering, the global map's estimate with the
 * BRDF, or with one of its terms.
 *
 * `diffuse` and `glossy` select the terms: at a glossy surface seen directly
 * the lobe's part is the `specular` component, the diffuse part `indirect`
 * (render.h). Both together are computed exactly as one sum, so `all` is
 * the same bytes as before the split. The lobe's rays take their numbers
 * from rng after the diffuse rays: where the diffuse term is not wanted but
 * gathers (no cache record reaches), its rays are still traced, only to
 * leave rng where it would be (how many numbers a gather ray takes depends
 * on the glass it meets), so the components of one sample add up to the
 * whole exactly. */
static ps_rgb indirect_light(worker *wk, const ps_surface *sp, ps_vec3 n, ps_vec3 wo, const ps_material *m,
                             ps_rng *rng, bool diffuse, bool glossy)
{
    const render_job *job = wk->job;
    int g = job->o->gather;
    bool has_lobe = m->type == PS_MAT_GLOSSY && !ps_rgb_is_black(m->specular);
    glossy = glossy && has_lobe;
    if (!diffuse && !glossy)
        return ps_rgb_gray(0.0);
    if (g == 0) {
        if (!job->maps->global)
            return ps_rgb_gray(0.0);
        ps_material part = *m;
        if (!glossy) { /* albedo / pi alone: the irradiance estimate times it */
            part.type = PS_MAT_DIFFUSE;
        } else if (!diffuse) {
            part.albedo = ps_rgb_gray(0.0);
        }
        return ps_photon_radiance(job->maps->global, diffuse && glossy ? m : &part, sp->p, n, wo, &job->o->global,
                                  wk->scratch);
    }
    if (!job->maps->irradiance || !job->maps->full)
        return ps_rgb_gray(0.0);
    ps_rgb sum = ps_rgb_gray(0.0);
    ps_rgb cached;
    if (!ps_rgb_is_black(m->albedo) && job->irr && ps_irrcache_lookup(job->irr, sp->p, n, &cached, NULL)) {
        if (diffuse)
            sum = ps_rgb_scale(ps_rgb_mul(m->albedo, cached), PS_INV_PI);
    } else if (!ps_rgb_is_black(m->albedo)) {
        ps_rgb acc = ps_rgb_gray(0.0);
        for (int k = 0; k < g; k++) {
            double u1 = (k + ps_rng_uniform(rng)) / g, u2 = ps_rng_uniform(rng);
            ps_vec3 dir = ps_sample_cosine(u1, u2, n);
            if (ps_v3_dot(dir, sp->ng) * ps_v3_dot(n, sp->ng) <= 0.0)
                continue; /* an interpolated normal pointed it into the surface */
            acc = ps_rgb_add(acc, gather_ray(wk, ps_world_spawn(job->world, sp, dir), rng, NULL));
        }
        if (diffuse)
            sum = ps_rgb_mul(m->albedo, ps_rgb_scale(acc, 1.0 / g));
    }
    if (glossy) {
        ps_vec3 mirror = ps_reflect(ps_v3_neg(wo), n);
        ps_rgb acc = ps_rgb_gray(0.0);
        for (int k = 0; k < g; k++) {
            double u1 = (k + ps_rng_uniform(rng)) / g, u2 = ps_rng_uniform(rng);
            ps_vec3 dir = ps_sample_phong(u1, u2, mirror, m->exponent);
            double cos_t = ps_v3_dot(dir, n);
            if (cos_t <= 0.0 || ps_v3_dot(dir, sp->ng) * ps_v3_dot(n, sp->ng) <= 0.0)
                continue; /* the lobe reaches below the surface: no light from there */
            acc = ps_rgb_add(acc, ps_rgb_scale(gather_ray(wk, ps_world_spawn(job->world, sp, dir), rng, NULL), cos_t));
        }
        double lobe = (m->exponent + 2.0) / (m->exponent + 1.0) / g;
        sum = ps_rgb_add(sum, ps_rgb_mul(m->specular, ps_rgb_scale(acc, lobe)));
    }
    return sum;
}

/* ---- emitters seen directly ---------------------------------------------- */

/* The radiance of the nearest area light (quad, disc, sphere) that ray r meets
 * before tmax on its emitting side. These lights are not geometry: they cast
 * no shadows and photons pass through them, as in the tracer; only eye rays
 * see them. Mesh lights (MTL Ke) are geometry and shade as their material. */
static bool emitter_hit(const render_job *job, ps_ray r, double tmax, ps_rgb *le)
{
    bool found = false;
    for (size_t l = 0; l < job->light_count; l++) {
        const ps_light *L = &job->lights[l];
        double t = INFINITY;
        if (L->type == PS_LIGHT_QUAD || L->type == PS_LIGHT_DISC) {
            ps_vec3 n = L->type == PS_LIGHT_QUAD ? ps_v3_cross(L->edge1, L->edge2) : L->direction;
            double dn = ps_v3_dot(r.d, n);
            if (!(dn < 0.0)) /* parallel, or its back: emits from one side only */
                continue;
            ps_vec3 v = ps_v3_sub(L->position, r.o);
            t = ps_v3_dot(v, n) / dn;
            ps_vec3 q = ps_v3_sub(ps_ray_at(r, t), L->position);
            if (L->type == PS_LIGHT_QUAD) {
                /* q = a edge1 + b edge2 with n = edge1 x edge2. */
                double nn = ps_v3_dot(n, n);
                double a = ps_v3_dot(ps_v3_cross(q, L->edge2), n) / nn;
                double b = ps_v3_dot(ps_v3_cross(L->edge1, q), n) / nn;
                if (!(a >= 0.0 && a <= 1.0 && b >= 0.0 && b <= 1.0))
                    continue;
            } else if (!(ps_v3_len2(q) <= L->radius * L->radius)) {
                continue;
            }
        } else if (L->type == PS_LIGHT_SPHERE) {
            /* The nearer root of |o + t d - c|^2 = R^2 (d unit), from outside. */
            ps_vec3 oc = ps_v3_sub(r.o, L->position);
            double b = ps_v3_dot(oc, r.d), c = ps_v3_len2(oc) - L->radius * L->radius;
            double disc = b * b - c;
            if (!(c > 0.0 && disc >= 0.0))
                continue;
            t = -b - sqrt(disc);
        } else {
            continue; /* points and spots have no area; mesh lights are geometry */
        }
        if (t > 0.0 && t < tmax) {
            tmax = t;
            *le = L->radiance;
            found = true;
        }
    }
    return found;
}

/* ---- eye paths ------------------------------------------------------------ */

static bool wants(ps_component want, ps_component term) { return want == PS_COMPONENT_ALL || want == term; }

/* Every node of an eye path makes its random numbers from its own key, and
 * its children's keys from that key: a term that is not wanted (or a branch
 * cut short) then never shifts the numbers of another, so the components of
 * one pixel are computed from the same samples and add up to the whole. */
enum { KEY_REFLECT = 1, KEY_REFRACT, KEY_CHOICE, KEY_DIRECT, KEY_GATHER };

static uint64_t child_key(uint64_t key, uint64_t what) { return ps_hash64(key ^ ps_hash64(what)); }

/* ---- illuminance --------------------------------------------------------- */

/* The selected component of the irradiance at the first surface r meets
 * (render.h, `illuminance`): the split equation's terms for a white
 * Lambertian surface there, times pi; the caustic term straight from the map. */
static ps_rgb illuminance_at(worker *wk, ps_ray r, uint64_t key)
{
    const render_job *job = wk->job;
    ps_component want = job->o->component;
    ps_surface sp;
    wk->rays++;
    if (!ps_world_intersect(job->world, r, INFINITY, &sp))
        return ps_rgb_gray(0.0);
    ps_material white;
    memset(&white, 0, sizeof white);
    white.type = PS_MAT_DIFFUSE;
    white.albedo = ps_rgb_gray(1.0);
    bool front = ps_v3_dot(r.d, sp.ng) < 0.0;
    ps_vec3 n = front ? sp.ns : ps_v3_neg(sp.ns);
    ps_vec3 wo = ps_v3_neg(r.d);
    ps_rgb sum = ps_rgb_gray(0.0);
    if (wants(want, PS_COMPONENT_DIRECT)) {
        ps_rng rng = ps_rng_make(key, KEY_DIRECT, 0);
        sum = ps_rgb_add(sum, ps_rgb_scale(direct_light(wk, &sp, n, wo, &white, &rng), PS_PI));
    }
    if (wants(want, PS_COMPONENT_CAUSTIC) && job->maps->caustic)
        sum = ps_rgb_add(sum, ps_photon_irradiance(job->maps->caustic, sp.p, n, &job->o->caustic, wk->scratch));
    if (wants(want, PS_COMPONENT_INDIRECT)) {
        ps_rng rng = ps_rng_make(key, KEY_GATHER, 0);
        sum = ps_rgb_add(sum, ps_rgb_scale(indirect_light(wk, &sp, n, wo, &white, &rng, true, false), PS_PI));
    }
    return sum;
}

/* ---- eye paths (continued) ------------------------------------------------ */

/* The selected component of the radiance arriving along r. `through`: the
 * path has met a mirror or glass already (so all it sees is specular). */
static ps_rgb radiance(worker *wk, ps_ray r, int depth, bool through, uint64_t key)
{
    const render_job *job = wk->job;
    ps_component want = job->o->component;
    if (job->o->illuminance && depth == 0)
        return illuminance_at(wk, r, key);
    if (depth > PS_RENDER_MAX_SPECULAR || (through && !wants(want, PS_COMPONENT_SPECULAR)))
        return ps_rgb_gray(0.0);
    ps_surface sp;
    wk->rays++;
    bool hit = ps_world_intersect(job->world, r, INFINITY, &sp);
    /* Area lights are seen as what they are (pbrt's area lights are shapes):
     * their radiance counts as direct light, or specular seen through glass. */
    ps_rgb le;
    if (emitter_hit(job, r, hit ? sp.t : INFINITY, &le))
        return wants(want, through ? PS_COMPONENT_SPECULAR : PS_COMPONENT_DIRECT) ? le : ps_rgb_gray(0.0);
    if (!hit)
        return ps_rgb_gray(0.0); /* no environment: black */
    ps_material textured;
    const ps_material *m = ps_surface_material(job->scene, job->materials, &sp, &textured);
    bool front = ps_v3_dot(r.d, sp.ng) < 0.0;
    ps_vec3 n = front ? sp.ns : ps_v3_neg(sp.ns);
    ps_vec3 wo = ps_v3_neg(r.d);

    if (m->type == PS_MAT_MIRROR) {
        ps_rgb li = radiance(wk, ps_world_spawn(job->world, &sp, ps_reflect(r.d, n)), depth + 1, true,
                             child_key(key, KEY_REFLECT));
        return ps_rgb_mul(m->reflectance, li);
    }
    if (m->type == PS_MAT_DIELECTRIC) {
        double eta_i = front ? 1.0 : m->ior, eta_t = front ? m->ior : 1.0;
        double f = ps_fresnel_dielectric(-ps_v3_dot(r.d, n), eta_i, eta_t);
        ps_vec3 refl = ps_reflect(r.d, n), refr;
        bool can_refract = ps_refract(r.d, n, eta_i / eta_t, &refr);
        if (!can_refract)
            f = 1.0;
        uint64_t kr = child_key(key, KEY_REFLECT), kt = child_key(key, KEY_REFRACT);
        if (depth < PS_RENDER_SPLIT_DEPTH) {
            ps_rgb sum = ps_rgb_gray(0.0);
            if (f > 0.0)
                sum = ps_rgb_scale(radiance(wk, ps_world_spawn(job->world, &sp, refl), depth + 1, true, kr), f);
            if (f < 1.0) {
                ps_rgb t = radiance(wk, ps_world_spawn(job->world, &sp, refr), depth + 1, true, kt);
                sum = ps_rgb_add(sum, ps_rgb_scale(ps_rgb_mul(m->transmittance, t), 1.0 - f));
            }
            return sum;
        }
        ps_rng choice = ps_rng_make(key, KEY_CHOICE, 0);
        if (ps_rng_uniform(&choice) < f)
            return radiance(wk, ps_world_spawn(job->world, &sp, refl), depth + 1, true, kr);
        return ps_rgb_mul(m->transmittance, radiance(wk, ps_world_spawn(job->world, &sp, refr), depth + 1, true, kt));
    }

    /* A diffuse or glossy surface: the terms of the split equation. Through
     * mirrors and glass they all count as `specular`; seen directly, so does
     * the glossy lobe's reflection of the other surfaces (the preview's
     * specular layer draws it; the lobe's caustic and direct light stay
     * in those terms, as the preview keeps them). */
    ps_rgb sum = ps_rgb_gray(0.0);
    ps_component as_direct = through ? PS_COMPONENT_SPECULAR : PS_COMPONENT_DIRECT;
    ps_component as_caustic = through ? PS_COMPONENT_SPECULAR : PS_COMPONENT_CAUSTIC;
    ps_component as_indirect = through ? PS_COMPONENT_SPECULAR : PS_COMPONENT_INDIRECT;
    if (wants(want, as_direct)) {
        if (front && !ps_rgb_is_black(m->emission))
            sum = ps_rgb_add(sum, m->emission); /* an MTL Ke face seen directly */
        ps_rng rng = ps_rng_make(key, KEY_DIRECT, 0);
        sum = ps_rgb_add(sum, direct_light(wk, &sp, n, wo, m, &rng));
    }
    if (wants(want, as_caustic) && job->maps->caustic)
        sum = ps_rgb_add(sum, ps_photon_radiance(job->maps->caustic, m, sp.p, n, wo, &job->o->caustic, wk->scratch));
    bool diffuse = wants(want, as_indirect), lobe = through ? diffuse : wants(want, PS_COMPONENT_SPECULAR);
    if (diffuse || lobe) {
        ps_rng rng = ps_rng_make(key, KEY_GATHER, 0);
        sum = ps_rgb_add(sum, indirect_light(wk, &sp, n, wo, m, &rng, diffuse, lobe));
    }
    return sum;
}

/* ---- the pixel filter ------------------------------------------------------ */

/* pbrt's filters: Mitchell-Netravali (B = C = 1/3, radius 2 pixels) and a
 * Gaussian (alpha 2, radius 1.5, shifted to reach 0 there), both separable.
 * A sample adds f(dx) f(dy) times its radiance, and that weight, to every
 * pixel whose centre lies within the radius; a pixel is the one sum over the
 * other. With the box, each pixel is its own samples' mean, as before. */
#define MITCHELL_B (1.0 / 3.0)
#define MITCHELL_C (1.0 / 3.0)
#define GAUSS_ALPHA 2.0

static const char *const filter_names[PS_FILTER_COUNT] = {"box", "mitchell", "gaussian"};

const char *ps_filter_name(ps_filter f) { return filter_names[f]; }

static double filter_1d(ps_filter f, double x);

static double filter_radius(ps_filter f) { return f == PS_FILTER_MITCHELL ? 2.0 : f == PS_FILTER_GAUSSIAN ? 1.5 : 0.5; }

double ps_filter_eval(ps_filter f, double dx) { return filter_1d(f, dx); }

static double filter_1d(ps_filter f, double x)
{
    x = fabs(x);
    if (f == PS_FILTER_MITCHELL) {
        const double b = MITCHELL_B, c = MITCHELL_C;
        if (x >= 2.0)
            return 0.0;
        if (x > 1.0)
            return ((-b - 6 * c) * x * x * x + (6 * b + 30 * c) * x * x + (-12 * b - 48 * c) * x + (8 * b + 24 * c)) /
                   6.0;
        return ((12 - 9 * b - 6 * c) * x * x * x + (-18 + 12 * b + 6 * c) * x * x + (6 - 2 * b)) / 6.0;
    }
    if (f == PS_FILTER_GAUSSIAN) {
        double r = filter_radius(f);
        return x >= r ? 0.0 : exp(-GAUSS_ALPHA * x * x) - exp(-GAUSS_ALPHA * r * r);
    }
    return x < 0.5 ? 1.0 : 0.0;
}

/* Each tile splats into its own buffer, the tile grown by the filter's halo
 * on every side (r, g, b, weight a pixel); once every tile is done the
 * buffers are summed in tile order, so the image is the same for any thread
 * count. */
static int filter_halo(ps_filter f) { return (int)ceil(filter_radius(f)); }

static float *tile_buffer(const render_job *job, int tile)
{
    size_t side = (size_t)(TILE + 2 * job->halo);
    return job->accum + (size_t)tile * side * side * 4;
}

static void splat(render_job *job, int tile, int x0, int y0, double px, double py, ps_rgb l)
{
    ps_filter f = job->o->filter;
    double r = filter_radius(f);
    int side = TILE + 2 * job->halo;
    float *buf = tile_buffer(job, tile);
    int ya = (int)ceil(py - r - 0.5), yb = (int)floor(py + r - 0.5);
    int xa = (int)ceil(px - r - 0.5), xb = (int)floor(px + r - 0.5);
    for (int y = ya; y <= yb; y++) {
        if (y < 0 || y >= job->o->height)
            continue;
        double wy = filter_1d(f, y + 0.5 - py);
        for (int x = xa; x <= xb; x++) {
            if (x < 0 || x >= job->o->width)
                continue;
            double w = wy * filter_1d(f, x + 0.5 - px);
            float *d = buf + 4 * ((size_t)(y - y0 + job->halo) * (size_t)side + (size_t)(x - x0 + job->halo));
            d[0] += (float)(w * l.r);
            d[1] += (float)(w * l.g);
            d[2] += (float)(w * l.b);
            d[3] += (float)w;
        }
    }
}

/* Every pixel from the buffers of the tiles around it, in tile order. */
static void resolve_filter(render_job *job)
{
    int side = TILE + 2 * job->halo, tiles_y = job->tiles / job->tiles_x;
    for (int y = 0; y < job->o->height; y++)
        for (int x = 0; x < job->o->width; x++) {
            double sum[4] = {0, 0, 0, 0};
            int ty0 = (y - job->halo) / TILE, ty1 = (y + job->halo) / TILE;
            int tx0 = (x - job->halo) / TILE, tx1 = (x + job->halo) / TILE;
            for (int ty = ty0 < 0 ? 0 : ty0; ty <= ty1 && ty < tiles_y; ty++)
                for (int tx = tx0 < 0 ? 0 : tx0; tx <= tx1 && tx < job->tiles_x; tx++) {
                    int lx = x - tx * TILE + job->halo, ly = y - ty * TILE + job->halo;
                    if (lx < 0 || ly < 0 || lx >= side || ly >= side)
                        continue;
                    const float *d = tile_buffer(job, ty * job->tiles_x + tx) + 4 * ((size_t)ly * (size_t)side + (size_t)lx);
                    for (int c = 0; c < 4; c++)
                        sum[c] += d[c];
                }
            float *dst = ps_image_at(job->img, x, y);
            /* Mitchell's negative lobes can leave a pixel's weights near 0
             * only with a sample or so per pixel; it stays black then. */
            double inv = sum[3] > 1e-6 ? 1.0 / sum[3] : 0.0;
            for (int c = 0; c < 3; c++)
                dst[c] = (float)(sum[c] * inv);
        }
}

/* ---- quality presets ---------------------------------------------------- */

static const char *const quality_names[PS_QUALITY_COUNT] = {"draft", "default", "final"};

const char *ps_quality_name(ps_quality q) { return quality_names[q]; }

ps_render_preset ps_render_quality(ps_quality q)
{
    static const ps_render_preset presets[PS_QUALITY_COUNT] = {
        /* draft: at one sample a pixel Mitchell's negative lobes make a
         * pixel's ratio of sums noisy (9 % off a smooth closed form in
         * test_render, against 1.7 % at 4); the Gaussian has none. */
        {1, 8, 4, 256, 0.5, PS_FILTER_GAUSSIAN},
        {4, 16, 2, 1024, 1.0, PS_FILTER_MITCHELL}, /* default */
        {16, 32, 1, 2048, 2.0, PS_FILTER_MITCHELL} /* final */
    };
    return presets[q];
}

/* ---- pixels, tiles, threads ---------------------------------------------- */

/* Renders one tile; false when the cancel flag stopped it partway (checked
 * every row, so that a tile of many samples still stops within moments). */
static bool render_tile(worker *wk, int tile)
{
    render_job *job = wk->job;
    const ps_render_options *o = job->o;
    int tx = tile % job->tiles_x, ty = tile / job->tiles_x;
    int x0 = tx * TILE, y0 = ty * TILE;
    int x1 = x0 + TILE < o->width ? x0 + TILE : o->width, y1 = y0 + TILE < o->height ? y0 + TILE : o->height;
    /* spp samples stratified on a grid as square as spp allows. */
    int sx = (int)floor(sqrt((double)o->spp));
    while (o->spp % sx)
        sx--;
    int sy = o->spp / sx;
    for (int y = y0; y < y1; y++) {
        if (ps_cancelled(o->cancel))
            return false;
        for (int x = x0; x < x1; x++) {
            ps_rng rng = ps_rng_make(o->seed, PS_STREAM_PIXEL, (uint64_t)y * (uint64_t)o->width + (uint64_t)x);
            ps_rgb sum = ps_rgb_gray(0.0);
            for (int s = 0; s < o->spp; s++) {
                double px = x + ((s % sx) + ps_rng_uniform(&rng)) / sx;
                double py = y + ((s / sx) + ps_rng_uniform(&rng)) / sy;
                uint64_t key = ((uint64_t)ps_rng_u32(&rng) << 32) | ps_rng_u32(&rng);
                ps_rgb l = radiance(wk, ps_camera_ray(&job->cam, px, py), 0, false, key);
                if (!ps_rgb_isfinite(l))
                    continue;
                if (job->accum)
                    splat(job, tile, x0, y0, px, py, l);
                else
                    sum = ps_rgb_add(sum, l);
            }
            if (job->accum)
                continue;
            float *dst = ps_image_at(job->img, x, y);
            dst[0] = (float)(sum.r / o->spp);
            dst[1] = (float)(sum.g / o->spp);
            dst[2] = (float)(sum.b / o->spp);
        }
    }
    return true;
}

/* Floats a tile's buffer holds for ps_render_share: the filter's buffer,
 * or the box's pixels (TILE x TILE x 3, rows cut at the image's edge). */
static size_t tile_floats(const render_job *job)
{
    size_t side = (size_t)(TILE + 2 * job->halo);
    return job->accum ? side * side * 4 : (size_t)TILE * TILE * 3;
}

/* A tile's buffer copied out (to non-NULL `out`) or in (from `in`). */
static void tile_copy(render_job *job, int tile, float *out, const float *in)
{
    if (job->accum) {
        float *buf = tile_buffer(job, tile);
        memcpy(out ? out : buf, out ? buf : in, tile_floats(job) * sizeof *buf);
        return;
    }
    int x0 = tile % job->tiles_x * TILE, y0 = tile / job->tiles_x * TILE;
    int w = x0 + TILE < job->o->width ? TILE : job->o->width - x0;
    for (int y = y0; y < y0 + TILE && y < job->o->height; y++) {
        float *px = ps_image_at(job->img, x0, y);
        size_t at = (size_t)(y - y0) * TILE * 3;
        memcpy(out ? out + at : px, out ? px : in + at, (size_t)w * 3 * sizeof *px);
    }
}

/* Takes tiles until none are left. The calling thread's worker (`reports`)
 * also reports progress between its tiles. */
static void *render_worker(void *arg)
{
    worker *wk = arg;
    render_job *job = wk->job;
    for (;;) {
        if (ps_cancelled(job->o->cancel))
            break; /* between tiles: every finished tile is whole */
        const ps_render_share *sh = job->o->share;
        int t = sh ? sh->next_tile(sh->user) : atomic_fetch_add(&job->next_tile, 1);
        if (t < 0 || t >= job->tiles)
            break;
        if (sh)
            atomic_fetch_add(&job->taken_tiles, 1);
        if (!render_tile(wk, t))
            break;
        int done = atomic_fetch_add(&job->done_tiles, 1) + 1;
        if (sh) { /* the share reports the progress of every process */
            tile_copy(job, t, wk->tile, NULL);
            sh->tile_done(sh->user, t, wk->tile);
        } else if (wk->reports && job->o->progress)
            job->o->progress(job->o->progress_user, (double)done / job->tiles);
    }
    atomic_fetch_add(&job->rays, wk->rays);
    return NULL;
}

ps_status ps_render(const ps_world *w, const ps_light_sampler *ls, const ps_render_maps *maps,
                    const ps_render_options *o, ps_image *out, ps_render_stats *stats, ps_error *err)
{
    const ps_scene *s = ps_world_scene(w);
    ps_status st = ps_image_create(o->width, o->height, out, err);
    if (st != PS_OK)
        return st;
    double t0 = ps_now_seconds();
    render_job job;
    memset(&job, 0, sizeof job);
    job.world = w;
    job.scene = s;
    size_t n;
    job.materials = ps_scene_materials(s, &n);
    job.lights = ps_scene_lights(s, &job.light_count);
    job.ls = ls;
    job.maps = maps;
    job.o = o;
    job.cam = ps_camera_frame_make(ps_scene_camera(s), o->width, o->height);
    job.img = out;
    job.tiles_x = (o->width + TILE - 1) / TILE;
    job.tiles = job.tiles_x * ((o->height + TILE - 1) / TILE);
    atomic_init(&job.next_tile, 0);
    atomic_init(&job.done_tiles, 0);
    atomic_init(&job.taken_tiles, 0);
    atomic_init(&job.rays, 0);
    if (o->filter != PS_FILTER_BOX) {
        job.halo = filter_halo(o->filter);
        size_t side = (size_t)(TILE + 2 * job.halo);
        job.accum = calloc((size_t)job.tiles * side * side * 4, sizeof *job.accum);
        if (!job.accum) {
            ps_image_destroy(out);
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the pixel filter", ps_scene_path(s));
        }
    }

    int threads = o->threads < 1 ? 1 : o->threads > MAX_THREADS ? MAX_THREADS : o->threads;
    worker wk[MAX_THREADS];
    size_t k = max_k(o) + 1;
    for (int i = 0; i < threads; i++) {
        wk[i].job = &job;
        wk[i].rays = 0;
        wk[i].reports = i == 0;
        wk[i].scratch = malloc(k * sizeof *wk[i].scratch);
        wk[i].samples = malloc((size_t)(o->cache_rays > 0 ? o->cache_rays : 1) * sizeof *wk[i].samples);
        wk[i].tile = o->share ? calloc(tile_floats(&job), sizeof *wk[i].tile) : NULL; /* edge tiles send zeros */
        if (!wk[i].scratch || !wk[i].samples || (o->share && !wk[i].tile)) {
            for (int j = 0; j <= i; j++) {
                free(wk[j].scratch);
                free(wk[j].samples);
                free(wk[j].tile);
            }
            free(job.accum);
            ps_image_destroy(out);
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the renderer", ps_scene_path(s));
        }
    }
    pthread_t tid[MAX_THREADS];
    int started = 0;
    /* The irradiance cache first, when asked for and the indirect term is
     * wanted, directly or through mirrors and glass. It is the same for
     * every such component, so that they still add up to `all` (`specular`
     * needs it also where it only tells a glossy surface's lobe whether the
     * diffuse rays before it were gathered: indirect_light). */
    bool indirect = o->component == PS_COMPONENT_ALL || o->component == PS_COMPONENT_INDIRECT ||
                    o->component == PS_COMPONENT_SPECULAR;
    st = PS_OK;
    double t_cache = ps_now_seconds();
    if (o->cache_spacing > 0 && o->cache_rays > 0 && o->gather > 0 && indirect && maps->irradiance && maps->full) {
        job.footprint = 2.0 * job.cam.tan_half_fov / o->height;
        st = ps_irrcache_create(ps_scene_bounds(s), PS_RENDER_CACHE_ERROR, &job.irr, err);
        if (st == PS_OK)
            st = cache_build(&job, wk, threads, err);
        free(job.chunk);
        free(job.chunk_ok);
    }
    t_cache = ps_now_seconds() - t_cache;
    if (st == PS_OK && o->share)
        st = o->share->tiles_begin(o->share->user, o, job.tiles, tile_floats(&job), err);
    if (st != PS_OK) {
        for (int i = 0; i < threads; i++) {
            free(wk[i].scratch);
            free(wk[i].samples);
            free(wk[i].tile);
        }
        ps_irrcache_destroy(job.irr);
        free(job.accum);
        ps_image_destroy(out);
        return st;
    }
    for (; started < threads - 1; started++)
        if (pthread_create(&tid[started], NULL, render_worker, &wk[started + 1]) != 0)
            break;
    render_worker(&wk[0]);
    for (int i = 0; i < started; i++)
        pthread_join(tid[i], NULL);
    for (int i = 0; i < threads; i++) {
        free(wk[i].scratch);
        free(wk[i].samples);
        free(wk[i].tile);
    }
    int done = atomic_load(&job.done_tiles);
    uint64_t rays = atomic_load(&job.rays);
    if (o->share) {
        /* Every tile this process took is done unless it was stopped; the
         * share says whether all of them are, everywhere. */
        bool complete = done == atomic_load(&job.taken_tiles) && !ps_cancelled(o->cancel);
        st = o->share->tiles_end(o->share->user, complete, &rays, err);
        if (st == PS_OK && o->share->assemble)
            for (int t = 0; t < job.tiles; t++) {
                const float *data = o->share->tile_data(o->share->user, t);
                if (data)
                    tile_copy(&job, t, NULL, data);
            }
        done = st == PS_OK ? job.tiles : 0;
    }
    if (stats) {
        stats->cache_records = job.irr ? ps_irrcache_count(job.irr) : 0;
        stats->cache_seconds = t_cache;
        stats->rays = rays;
        stats->seconds = ps_now_seconds() - t0;
        stats->fraction = (double)done / job.tiles;
    }
    ps_irrcache_destroy(job.irr);
    if (job.accum && done == job.tiles && (!o->share || o->share->assemble))
        resolve_filter(&job);
    free(job.accum);
    if (st != PS_OK) { /* a shared render: another process stopped or failed */
        ps_image_destroy(out);
        return st;
    }
    if (done < job.tiles) { /* only the cancel flag stops workers early */
        ps_image_destroy(out);
        return ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %.0f %% of the image",
                            100.0 * done / job.tiles);
    }
    return PS_OK;
}
