/* irrcache.h: an irradiance cache (Ward, Rubinstein & Clear 1988) with
 * irradiance gradients (Ward & Heckbert 1992), in world space: records are
 * view-independent, so a lookup works wherever a path meets a diffuse
 * surface, through any number of mirrors and glass.
 *
 * A record is made from M x N gather rays stratified in (sin^2 theta, phi)
 * around its normal (each stratum an equal share of the cosine-weighted
 * hemisphere): its irradiance E, the rotational and translational gradients
 * of E, and its validity radius R (the harmonic mean distance of what the
 * rays met, the split-sphere model), clamped by the caller. A lookup at
 * (x, n) takes every record with
 *     eps_i = |x - x_i| / R_i + sqrt(1 - n . n_i) < a
 * that does not lie in front of x, and returns the average of
 *     E_i + (n_i x n) . grad_r E_i + (x - x_i) . grad_t E_i
 * weighted by 1 / eps_i - 1 / a. That weight (not Ward's 1 / eps_i) falls to
 * 0 where a record stops counting, so the interpolation is continuous at the
 * edge of every record's reach and shows no circles. Records live in a loose
 * octree: one of reach a R sits in the deepest node whose half-size is at
 * least a R and that holds its centre; a node's records then all reach no
 * further than its box grown by its half-size on every side.
 *
 * Records are added from one thread, in an order the caller fixes; lookups
 * only read, from any number of threads, so a cache built in a fixed order
 * gives the same answers for any thread count. */
#ifndef PS_RENDER_IRRCACHE_H
#define PS_RENDER_IRRCACHE_H

#include <stdbool.h>
#include <stddef.h>

#include "core/status.h"
#include "core/vec.h"

typedef struct ps_irr_record {
    ps_vec3 p, n;         /* position, unit normal */
    ps_rgb e;             /* irradiance, W m^-2 */
    ps_vec3 grad_r[3];    /* rotational gradient per channel: dE = (n_i x n) . grad_r */
    ps_vec3 grad_t[3];    /* translational gradient per channel: dE = (x - x_i) . grad_t */
    double r;             /* validity radius (scene units) */
    double r_harmonic;    /* the harmonic mean hit distance before any clamp (INFINITY: nothing met) */
    double t_min;         /* the nearest hit of its rays (INFINITY: nothing met) */
} ps_irr_record;

/* One gather ray of a record: the radiance it brought back and how far it
 * went (INFINITY: it met nothing). */
typedef struct ps_irr_sample {
    ps_rgb l;
    double t;
} ps_irr_sample;

/* Strata of a record of about `rays` rays: m in theta, n in phi with n close
 * to pi m (Ward & Heckbert's choice, strata near square in solid angle). */
void ps_irr_strata(int rays, int *m, int *n);

/* The direction of stratum (j, k) of m x n at jitter (u1, u2) in [0,1)^2,
 * around unit normal nrm in the frame (t, b, nrm): sin^2 theta = (j + u1) / m,
 * phi = 2 pi (k + u2) / n. */
ps_vec3 ps_irr_stratum_direction(ps_vec3 t, ps_vec3 b, ps_vec3 nrm, int m, int n, int j, int k, double u1, double u2);

/* A record at (p, nrm) from the m x n samples s[j * n + k] of
 * ps_irr_stratum_direction's strata in the frame (t, b, nrm). r is left at
 * the harmonic mean distance (INFINITY when no ray met anything). */
void ps_irr_record_from_samples(ps_vec3 p, ps_vec3 t, ps_vec3 b, ps_vec3 nrm, int m, int n, const ps_irr_sample *s,
                                ps_irr_record *rec);

typedef struct ps_irrcache ps_irrcache;

/* An empty cache over bounds (records outside are still kept, in the root),
 * counting records where eps_i < a (a > 0). */
ps_status ps_irrcache_create(ps_aabb bounds, double a, ps_irrcache **out, ps_error *err);
void ps_irrcache_destroy(ps_irrcache *c);

/* Adds a copy of *rec (r > 0 and finite). Not thread-safe. */
ps_status ps_irrcache_add(ps_irrcache *c, const ps_irr_record *rec, ps_error *err);

size_t ps_irrcache_count(const ps_irrcache *c);

/* The interpolated irradiance at (p, unit n); false where no record counts.
 * *weight (may be NULL): the weights' sum. */
bool ps_irrcache_lookup(const ps_irrcache *c, ps_vec3 p, ps_vec3 n, ps_rgb *e, double *weight);

/* Whether some record has eps_i below share * a at (p, unit n) and does not
 * lie in front of it: where a new record is not needed. */
bool ps_irrcache_covered(const ps_irrcache *c, ps_vec3 p, ps_vec3 n, double share);

#endif
