/* estimate.c: kernels, the radiance and irradiance estimates, and
 * Christensen's precomputed irradiance. */
#include "photon/estimate.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>

#include "scene/bsdf.h"

/* The Gaussian's width: exp(-beta s^2 / 2) is a normal of sigma = r / 2.
 * Departure from Jensen's book (Pavicic's alpha = 0.918, beta = 1.953): that
 * form is still 0.27 at s = 1, so its splats would show a rim; ours is shifted
 * down to reach 0 at the edge and normalised exactly through C. */
#define GAUSS_BETA 4.0
/* Precomputation works through the sample photons in chunks of this many. */
#define IRR_CHUNK 256
#define IRR_MAX_THREADS 256

const char *const ps_kernel_names[PS_KERNEL_COUNT + 1] = {"box", "cone", "gauss", "epanechnikov", NULL};

const char *ps_kernel_name(ps_kernel k) { return (unsigned)k < PS_KERNEL_COUNT ? ps_kernel_names[k] : "?"; }

double ps_kernel_profile(ps_kernel k, double s)
{
    if (!(s >= 0.0 && s <= 1.0))
        return 0.0;
    switch (k) {
    case PS_KERNEL_CONE:
        return 1.0 - s;
    case PS_KERNEL_GAUSS: {
        double edge = exp(-0.5 * GAUSS_BETA);
        return (exp(-0.5 * GAUSS_BETA * s * s) - edge) / (1.0 - edge);
    }
    case PS_KERNEL_EPANECHNIKOV:
        return 1.0 - s * s;
    default:
        return 1.0;
    }
}

double ps_kernel_mean(ps_kernel k)
{
    /* C = 2 int_0^1 g(s) s ds = int_0^1 g(sqrt(u)) du. */
    switch (k) {
    case PS_KERNEL_CONE:
        return 1.0 / 3.0;
    case PS_KERNEL_GAUSS: {
        double edge = exp(-0.5 * GAUSS_BETA);
        return ((2.0 / GAUSS_BETA) * (1.0 - edge) - edge) / (1.0 - edge);
    }
    case PS_KERNEL_EPANECHNIKOV:
        return 0.5;
    default:
        return 1.0;
    }
}

/* The neighbours of p facing n, and 1 / (C pi r^2) for them; 0 found: none.
 *
 * Departure from the thesis' eq. 9 (and Jensen's code): when k photons were
 * found, r is the distance to the k-th, which lies on the boundary. Counting
 * it overestimates by k / (k - 1) (for a Poisson density, pi lambda r_k^2 is
 * Gamma(k) distributed, and E[1 / Gamma(k)] = 1 / (k - 1)), 1 % at k = 100.
 * The smooth kernels give it weight g(1) = 0 anyway; with the box kernel we
 * drop it (out[0], the heap's farthest), which makes the estimate unbiased
 * where the density is uniform. */
static size_t gather(const ps_kdtree *map, ps_vec3 p, ps_vec3 n, const ps_estimate_options *o, ps_neighbor *scratch,
                     double *r2, double *norm)
{
    ps_kdtree_query q = {p, o->k, o->max_radius, n, PS_ESTIMATE_MIN_COS};
    size_t found = ps_kdtree_knn(map, &q, scratch, r2);
    if (found == 0 || !(*r2 > 0.0))
        return 0;
    if (found == o->k && o->kernel == PS_KERNEL_BOX && found > 1) {
        scratch[0] = scratch[found - 1];
        found--;
    }
    *norm = 1.0 / (ps_kernel_mean(o->kernel) * PS_PI * *r2);
    return found;
}

static double weight(const ps_estimate_options *o, double d2, double r2)
{
    return o->kernel == PS_KERNEL_BOX ? 1.0 : ps_kernel_profile(o->kernel, sqrt(d2 / r2));
}

ps_rgb ps_photon_irradiance(const ps_kdtree *map, ps_vec3 p, ps_vec3 n, const ps_estimate_options *o,
                            ps_neighbor *scratch)
{
    double r2, norm;
    size_t found = gather(map, p, n, o, scratch, &r2, &norm);
    ps_rgb sum = ps_rgb_gray(0.0);
    const ps_photon *ph = ps_kdtree_photons(map);
    for (size_t i = 0; i < found; i++)
        sum = ps_rgb_add(sum, ps_rgb_scale(ps_photon_power(&ph[scratch[i].index]), weight(o, scratch[i].d2, r2)));
    return found ? ps_rgb_scale(sum, norm) : sum;
}

ps_rgb ps_photon_radiance(const ps_kdtree *map, const ps_material *m, ps_vec3 p, ps_vec3 n, ps_vec3 wo,
                          const ps_estimate_options *o, ps_neighbor *scratch)
{
    if (m->type == PS_MAT_DIFFUSE) /* f = albedo / pi for every photon: factor it out */
        return ps_rgb_scale(ps_rgb_mul(m->albedo, ps_photon_irradiance(map, p, n, o, scratch)), PS_INV_PI);
    if (m->type != PS_MAT_GLOSSY)
        return ps_rgb_gray(0.0);
    double r2, norm;
    size_t found = gather(map, p, n, o, scratch, &r2, &norm);
    ps_rgb sum = ps_rgb_gray(0.0);
    const ps_photon *ph = ps_kdtree_photons(map);
    for (size_t i = 0; i < found; i++) {
        const ps_photon *q = &ph[scratch[i].index];
        ps_rgb f = ps_bsdf_eval(m, n, ps_photon_dir(q), wo);
        sum = ps_rgb_add(sum, ps_rgb_scale(ps_rgb_mul(f, ps_photon_power(q)), weight(o, scratch[i].d2, r2)));
    }
    return found ? ps_rgb_scale(sum, norm) : sum;
}

/* ---- precomputed irradiance ---------------------------------------------- */

typedef struct irr_job {
    const ps_kdtree *map;
    const ps_estimate_options *o;
    size_t stride, samples;
    ps_photon *out;
    size_t next; /* next chunk, under lock */
    pthread_mutex_t lock;
    bool nomem;
    const ps_cancel_flag *cancel;
    bool cancelled; /* under lock */
} irr_job;

static void *irr_worker(void *arg)
{
    irr_job *job = arg;
    ps_neighbor *scratch = malloc(job->o->k * sizeof *scratch);
    const ps_photon *ph = ps_kdtree_photons(job->map);
    for (;;) {
        pthread_mutex_lock(&job->lock);
        size_t first = job->next;
        job->next += IRR_CHUNK;
        if (!scratch)
            job->nomem = true;
        if (ps_cancelled(job->cancel))
            job->cancelled = true;
        bool stop = !scratch || job->cancelled || first >= job->samples;
        pthread_mutex_unlock(&job->lock);
        if (stop)
            break;
        size_t last = first + IRR_CHUNK < job->samples ? first + IRR_CHUNK : job->samples;
        for (size_t s = first; s < last; s++) {
            const ps_photon *src = &ph[s * job->stride];
            ps_vec3 n = ps_photon_normal(src);
            ps_rgb e = ps_photon_irradiance(job->map, ps_photon_position(src), n, job->o, scratch);
            ps_photon p = *src;
            /* Dither 0.5: plain rounding; each sample is looked up on its own,
             * so there is no shared bias to spread. */
            ps_rgbe_encode(e, 0.5, p.rgbe);
            job->out[s] = p;
        }
    }
    free(scratch);
    return NULL;
}

ps_status ps_irradiance_precompute(const ps_kdtree *map, const ps_estimate_options *o, size_t stride, int threads,
                                   const ps_cancel_flag *cancel, ps_kdtree **out, ps_error *err)
{
    *out = NULL;
    if (stride < 1)
        stride = 1;
    irr_job job = {map, o, stride, (ps_kdtree_count(map) + stride - 1) / stride, NULL, 0,
                   PTHREAD_MUTEX_INITIALIZER, false, cancel, false};
    job.out = malloc((job.samples ? job.samples : 1) * sizeof *job.out);
    if (!job.out)
        return ps_error_set(err, PS_ERR_NOMEM, "irradiance: out of memory for %zu samples", job.samples);
    threads = threads < 1 ? 1 : threads > IRR_MAX_THREADS ? IRR_MAX_THREADS : threads;
    pthread_t tid[IRR_MAX_THREADS];
    int started = 0;
    for (; started < threads - 1; started++)
        if (pthread_create(&tid[started], NULL, irr_worker, &job) != 0)
            break;
    irr_worker(&job);
    for (int i = 0; i < started; i++)
        pthread_join(tid[i], NULL);
    pthread_mutex_destroy(&job.lock);
    ps_status st = job.nomem       ? ps_error_set(err, PS_ERR_NOMEM, "irradiance: out of memory")
                   : job.cancelled ? ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted while precomputing irradiance")
                                   : ps_kdtree_build(job.out, job.samples, out, err);
    free(job.out);
    return st;
}

bool ps_irradiance_lookup(const ps_kdtree *irr, ps_vec3 p, ps_vec3 n, double radius, ps_rgb *e)
{
    ps_neighbor nb;
    ps_kdtree_query q = {p, 1, radius, n, PS_IRRADIANCE_MIN_COS};
    if (ps_kdtree_knn(irr, &q, &nb, NULL) == 0)
        return false;
    *e = ps_photon_power(&ps_kdtree_photons(irr)[nb.index]);
    return true;
}
