/* render.c: eye rays, the split rendering equation, tiles on threads. */
#include "render/render.h"

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
    int tiles_x, tiles;
    atomic_int next_tile, done_tiles;
    /* The irradiance cache: a record every `spacing` pixels (see render.h). */
    struct irr_record *cache;
    int cache_w, cache_h;
    atomic_int next_record;
    atomic_uint_least64_t rays;
} render_job;

/* Per-thread state: the radiance-estimate scratch and the ray count. */
typedef struct worker {
    render_job *job;
    ps_neighbor *scratch;
    uint64_t rays;
    double px, py; /* the image position of the eye sample being traced */
    bool reports;  /* the calling thread's: reports progress */
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
        const ps_material *m = &job->materials[sp.material];
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

/* Light from other surfaces reflected at sp towards wo. With final
 * gathering, the BRDF is split into its two terms and each is sampled with
 * its own rays (no weighting needed: the terms add): cosine-distributed rays
 * for albedo / pi, whose estimate is pi f_d L = albedo L, and rays in the
 * Phong lobe for the glossy term, whose estimate is f_s L cos / pdf =
 * specular (e + 2) / (e + 1) cos(theta) L. Both are stratified in their
 * first dimension. */
/* ---- the irradiance cache -------------------------------------------------- */

/* Indirect irradiance at one surface point, with Ward's validity radius: the
 * harmonic mean distance of what its gather rays met. */
typedef struct irr_record {
    ps_vec3 p, n;
    ps_rgb e;
    double r;
    bool valid;
} irr_record;

/* Indirect irradiance at sp (normal n) from `rays` cosine-distributed gather
 * rays: pi times their mean radiance; *r the harmonic mean hit distance. */
static ps_rgb gathered_irradiance(worker *wk, const ps_surface *sp, ps_vec3 n, int rays, ps_rng *rng, double *r)
{
    const render_job *job = wk->job;
    ps_rgb acc = ps_rgb_gray(0.0);
    double inv_t = 0.0;
    int counted = 0;
    for (int k = 0; k < rays; k++) {
        double u1 = (k + ps_rng_uniform(rng)) / rays, u2 = ps_rng_uniform(rng);
        ps_vec3 dir = ps_sample_cosine(u1, u2, n);
        if (ps_v3_dot(dir, sp->ng) * ps_v3_dot(n, sp->ng) <= 0.0)
            continue; /* an interpolated normal pointed it into the surface */
        double t = INFINITY;
        acc = ps_rgb_add(acc, gather_ray(wk, ps_world_spawn(job->world, sp, dir), rng, &t));
        inv_t += isfinite(t) && t > 0.0 ? 1.0 / t : 0.0;
        counted++;
    }
    *r = inv_t > 0.0 ? counted / inv_t : INFINITY;
    return ps_rgb_scale(acc, PS_PI / rays);
}

/* Record (gx, gy): the first diffuse or glossy surface its pixel centre sees. */
static void cache_record(worker *wk, int index)
{
    render_job *job = wk->job;
    const ps_render_options *o = job->o;
    irr_record *rec = &job->cache[index];
    rec->valid = false;
    int gx = index % job->cache_w, gy = index / job->cache_w;
    double k = o->cache_spacing;
    ps_ray ray = ps_camera_ray(&job->cam, (gx + 0.5) * k, (gy + 0.5) * k);
    ps_surface sp;
    wk->rays++;
    if (!ps_world_intersect(job->world, ray, INFINITY, &sp))
        return;
    const ps_material *m = &job->materials[sp.material];
    if (m->type != PS_MAT_DIFFUSE && m->type != PS_MAT_GLOSSY)
        return;
    bool front = ps_v3_dot(ray.d, sp.ng) < 0.0;
    rec->n = front ? sp.ns : ps_v3_neg(sp.ns);
    rec->p = sp.p;
    ps_rng rng = ps_rng_make(ps_hash64(o->seed ^ PS_RENDER_CACHE_KEY), PS_STREAM_PIXEL, (uint64_t)index);
    rec->e = gathered_irradiance(wk, &sp, rec->n, o->cache_rays, &rng, &rec->r);
    rec->valid = isfinite(rec->r) && rec->r > 0.0 && ps_rgb_isfinite(rec->e);
}

static void *cache_worker(void *arg)
{
    worker *wk = arg;
    render_job *job = wk->job;
    int n = job->cache_w * job->cache_h;
    for (int i; !ps_cancelled(job->o->cancel) && (i = atomic_fetch_add(&job->next_record, 1)) < n;)
        cache_record(wk, i);
    return NULL;
}

/* Ward's interpolation (without gradients) of the records around image
 * position (px, py): weight 1 / (|x - x_i| / R_i + sqrt(1 - n.n_i)), records
 * counted when the weight passes 1 / PS_RENDER_CACHE_ERROR. False when none
 * does (the caller gathers there instead). */
static bool cache_lookup(const render_job *job, double px, double py, ps_vec3 p, ps_vec3 n, ps_rgb *e)
{
    double k = job->o->cache_spacing;
    int gx0 = (int)floor(px / k - 0.5), gy0 = (int)floor(py / k - 0.5);
    double wsum = 0.0;
    ps_rgb acc = ps_rgb_gray(0.0);
    for (int gy = gy0 - 1; gy <= gy0 + 2; gy++)
        for (int gx = gx0 - 1; gx <= gx0 + 2; gx++) {
            if (gx < 0 || gy < 0 || gx >= job->cache_w || gy >= job->cache_h)
                continue;
            const irr_record *rec = &job->cache[gy * job->cache_w + gx];
            double c = ps_v3_dot(n, rec->n);
            if (!rec->valid || c <= 0.0)
                continue;
            double d = ps_v3_len(ps_v3_sub(p, rec->p)) / rec->r + sqrt(fmax(0.0, 1.0 - c));
            double w = d > 0.0 ? 1.0 / d : 1e30;
            if (w < 1.0 / PS_RENDER_CACHE_ERROR)
                continue;
            wsum += w;
            acc = ps_rgb_add(acc, ps_rgb_scale(rec->e, w));
        }
    if (!(wsum > 0.0))
        return false;
    *e = ps_rgb_scale(acc, 1.0 / wsum);
    return true;
}

static ps_rgb indirect_light(worker *wk, const ps_surface *sp, ps_vec3 n, ps_vec3 wo, const ps_material *m,
                             ps_rng *rng, bool primary)
{
    const render_job *job = wk->job;
    int g = job->o->gather;
    if (g == 0)
        return job->maps->global ? ps_photon_radiance(job->maps->global, m, sp->p, n, wo, &job->o->global, wk->scratch)
                                 : ps_rgb_gray(0.0);
    if (!job->maps->irradiance || !job->maps->full)
        return ps_rgb_gray(0.0);
    ps_rgb sum = ps_rgb_gray(0.0);
    ps_rgb cached;
    if (!ps_rgb_is_black(m->albedo) && primary && job->cache &&
        cache_lookup(job, wk->px, wk->py, sp->p, n, &cached)) {
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
        sum = ps_rgb_mul(m->albedo, ps_rgb_scale(acc, 1.0 / g));
    }
    if (m->type == PS_MAT_GLOSSY && !ps_rgb_is_black(m->specular)) {
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
        sum = ps_rgb_add(sum, ps_rgb_scale(indirect_light(wk, &sp, n, wo, &white, &rng, true), PS_PI));
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
    const ps_material *m = &job->materials[sp.material];
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
     * mirrors and glass they all count as `specular`. */
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
    if (wants(want, as_indirect)) {
        ps_rng rng = ps_rng_make(key, KEY_GATHER, 0);
        sum = ps_rgb_add(sum, indirect_light(wk, &sp, n, wo, m, &rng, depth == 0));
    }
    return sum;
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
                wk->px = px;
                wk->py = py;
                ps_rgb l = radiance(wk, ps_camera_ray(&job->cam, px, py), 0, false, key);
                if (ps_rgb_isfinite(l))
                    sum = ps_rgb_add(sum, l);
            }
            float *dst = ps_image_at(job->img, x, y);
            dst[0] = (float)(sum.r / o->spp);
            dst[1] = (float)(sum.g / o->spp);
            dst[2] = (float)(sum.b / o->spp);
        }
    }
    return true;
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
        int t = atomic_fetch_add(&job->next_tile, 1);
        if (t >= job->tiles)
            break;
        if (!render_tile(wk, t))
            break;
        int done = atomic_fetch_add(&job->done_tiles, 1) + 1;
        if (wk->reports && job->o->progress)
            job->o->progress(job->o->progress_user, (double)done / job->tiles);
    }
    atomic_fetch_add(&job->rays, wk->rays);
    return NULL;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

ps_status ps_render(const ps_world *w, const ps_light_sampler *ls, const ps_render_maps *maps,
                    const ps_render_options *o, ps_image *out, ps_render_stats *stats, ps_error *err)
{
    const ps_scene *s = ps_world_scene(w);
    ps_status st = ps_image_create(o->width, o->height, out, err);
    if (st != PS_OK)
        return st;
    double t0 = now();
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
    atomic_init(&job.rays, 0);

    int threads = o->threads < 1 ? 1 : o->threads > MAX_THREADS ? MAX_THREADS : o->threads;
    worker wk[MAX_THREADS];
    size_t k = max_k(o) + 1;
    for (int i = 0; i < threads; i++) {
        wk[i].job = &job;
        wk[i].rays = 0;
        wk[i].reports = i == 0;
        wk[i].scratch = malloc(k * sizeof *wk[i].scratch);
        if (!wk[i].scratch) {
            for (int j = 0; j < i; j++)
                free(wk[j].scratch);
            ps_image_destroy(out);
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for the renderer", ps_scene_path(s));
        }
    }
    pthread_t tid[MAX_THREADS];
    int started = 0;
    /* The irradiance cache first, when asked for and the indirect term is
     * wanted: every record is a pure function of its index, so the threads
     * may fill it in any order. */
    bool indirect = o->component == PS_COMPONENT_ALL || o->component == PS_COMPONENT_INDIRECT;
    if (o->cache_spacing > 0 && o->gather > 0 && indirect && maps->irradiance && maps->full) {
        job.cache_w = (o->width + o->cache_spacing - 1) / o->cache_spacing;
        job.cache_h = (o->height + o->cache_spacing - 1) / o->cache_spacing;
        job.cache = calloc((size_t)job.cache_w * (size_t)job.cache_h, sizeof *job.cache);
        atomic_init(&job.next_record, 0);
        if (job.cache) { /* without memory for it, gather everywhere: slower, not wrong */
            for (; started < threads - 1; started++)
                if (pthread_create(&tid[started], NULL, cache_worker, &wk[started + 1]) != 0)
                    break;
            cache_worker(&wk[0]);
            for (int i = 0; i < started; i++)
                pthread_join(tid[i], NULL);
            started = 0;
        }
    }
    for (; started < threads - 1; started++)
        if (pthread_create(&tid[started], NULL, render_worker, &wk[started + 1]) != 0)
            break;
    render_worker(&wk[0]);
    for (int i = 0; i < started; i++)
        pthread_join(tid[i], NULL);
    for (int i = 0; i < threads; i++)
        free(wk[i].scratch);
    free(job.cache);
    int done = atomic_load(&job.done_tiles);
    if (stats) {
        stats->rays = atomic_load(&job.rays);
        stats->seconds = now() - t0;
        stats->fraction = (double)done / job.tiles;
    }
    if (done < job.tiles) { /* only the cancel flag stops workers early */
        ps_image_destroy(out);
        return ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %.0f %% of the image",
                            100.0 * done / job.tiles);
    }
    return PS_OK;
}
