/* irrcache.c: irradiance records, their gradients, a loose octree of them. */
#include "render/irrcache.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

/* A record lying more than this share of its radius in front of the lookup
 * point (along the mean normal) is not used there: it sees a different
 * neighbourhood (Ward 1988's d_i test). */
#define IRR_FRONT 0.02
/* Octree depth cap: 2^-40 of the scene is far below any radius the renderer makes. */
#define IRR_MAX_DEPTH 40
/* Grows the root cube around the scene's bounds, so that records on its faces fall inside. */
#define IRR_ROOT_MARGIN 1.01

typedef struct irr_node {
    ps_vec3 centre;
    double half;     /* half the cube's side */
    int32_t child;   /* index of the first of 8 children; -1: a leaf */
    int32_t first;   /* the first record here; -1: none */
} irr_node;

struct ps_irrcache {
    double a;
    ps_irr_record *recs;
    int32_t *next; /* the next record of the same node */
    size_t count, cap;
    irr_node *nodes;
    size_t node_count, node_cap;
};

void ps_irr_strata(int rays, int *m, int *n)
{
    int mm = (int)lround(sqrt((double)rays / PS_PI));
    if (mm < 1)
        mm = 1;
    int nn = rays / mm;
    if (nn < 1)
        nn = 1;
    *m = mm;
    *n = nn;
}

static ps_vec3 plane_dir(ps_vec3 t, ps_vec3 b, double phi)
{
    return ps_v3_add(ps_v3_scale(t, cos(phi)), ps_v3_scale(b, sin(phi)));
}

ps_vec3 ps_irr_stratum_direction(ps_vec3 t, ps_vec3 b, ps_vec3 nrm, int m, int n, int j, int k, double u1, double u2)
{
    double s2 = (j + u1) / m; /* sin^2 theta: cosine-weighted (Malley) */
    double phi = 2.0 * PS_PI * (k + u2) / n;
    double st = sqrt(s2), ct = sqrt(fmax(0.0, 1.0 - s2));
    return ps_v3_add(ps_v3_scale(plane_dir(t, b, phi), st), ps_v3_scale(nrm, ct));
}

static double channel(ps_rgb c, int i) { return i == 0 ? c.r : i == 1 ? c.g : c.b; }

/* 1 / min(t1, t2), 0 when neither ray met anything. */
static double inv_min(double t1, double t2)
{
    double t = fmin(t1, t2);
    return isfinite(t) && t > 0.0 ? 1.0 / t : 0.0;
}

/* The gradients, derived for cosine-weighted strata as Ward & Heckbert did
 * for theirs: the irradiance is pi / (M N) times the sum of the strata's
 * radiance, and moving or turning the point moves the strata's boundaries
 * over the surfaces they see.
 *   Rotation: dE/dalpha = integral of L (n x w) dw, estimated as
 *   pi / (M N) sum L tan(theta) v, v = n x u_k. Ward takes tan(theta) and v
 *   at the stratum's centre (at the jittered direction, tan(theta) near the
 *   horizon would give the estimate infinite variance); here both are their
 *   means over the stratum, which is exact for radiance constant within
 *   each stratum, where the centre's tan underestimates the last stratum's
 *   (by 11 % in all at M = 18).
 *   Translation: a boundary between two strata moves by the motion across it
 *   over the nearer of their hit distances (the nearer surface's edge is what
 *   moves). A boundary of constant theta_j- between strata (j-1, k) and
 *   (j, k) spans 2 pi / N in phi and moves by cos(theta) (u . u_k) / r in
 *   theta; its projected solid angle per radian is sin cos, giving
 *       u_k 2pi/N sin(theta_j-) cos^2(theta_j-) (L_jk - L_j-1,k) / min r.
 *   A boundary of constant phi_k- between (j, k-1) and (j, k) moves by
 *   (u . v_k-) / (r sin theta); over its theta span the projected solid
 *   angle per radian of phi is sin cos dtheta, so the sin cancels and
 *       v_k- (sin theta_j+ - sin theta_j-) (L_jk - L_j,k-1) / min r.
 *   (Ward & Heckbert's paper has the uniform-in-cos form; this is the same
 *   construction for Malley's strata.) */
/* The mean of tan(theta) over stratum j of m (sin^2 theta uniform in
 * [j/m, (j+1)/m]): with u = sin^2 phi, the integral of sqrt(u / (1 - u)) du
 * is phi - sin phi cos phi, finite up to the horizon. */
static double mean_tan(int j, int m)
{
    double p0 = asin(sqrt((double)j / m)), p1 = asin(sqrt((double)(j + 1) / m));
    return m * ((p1 - sin(p1) * cos(p1)) - (p0 - sin(p0) * cos(p0)));
}

void ps_irr_record_from_samples(ps_vec3 p, ps_vec3 t, ps_vec3 b, ps_vec3 nrm, int m, int n, const ps_irr_sample *s,
                                ps_irr_record *rec)
{
    rec->p = p;
    rec->n = nrm;
    double sum[3] = {0, 0, 0}, inv_t = 0.0, t_min = INFINITY;
    ps_vec3 gr[3], gt[3];
    for (int c = 0; c < 3; c++)
        gr[c] = gt[c] = ps_v3(0, 0, 0);
    /* The mean of v over a stratum's phi span is v at its centre times this. */
    double half = PS_PI / n, sinc_phi = sin(half) / half;
    for (int k = 0; k < n; k++) {
        double phi_c = 2.0 * PS_PI * (k + 0.5) / n, phi_b = 2.0 * PS_PI * k / n;
        ps_vec3 uk = plane_dir(t, b, phi_c), vk = ps_v3_cross(nrm, uk);
        ps_vec3 vb = ps_v3_cross(nrm, plane_dir(t, b, phi_b));
        int kp = (k + n - 1) % n;
        for (int j = 0; j < m; j++) {
            const ps_irr_sample *cur = &s[j * n + k];
            if (isfinite(cur->t) && cur->t > 0.0) {
                inv_t += 1.0 / cur->t;
                t_min = fmin(t_min, cur->t);
            }
            double tan_c = mean_tan(j, m) * sinc_phi;
            double sin_lo = sqrt((double)j / m), sin_hi = sqrt((double)(j + 1) / m);
            /* phi boundary with stratum k-1 */
            const ps_irr_sample *left = &s[j * n + kp];
            double wphi = (sin_hi - sin_lo) * inv_min(cur->t, left->t);
            /* theta boundary with stratum j-1 */
            const ps_irr_sample *below = j > 0 ? &s[(j - 1) * n + k] : NULL;
            double wth = below ? 2.0 * PS_PI / n * sin_lo * (1.0 - sin_lo * sin_lo) * inv_min(cur->t, below->t) : 0.0;
            for (int c = 0; c < 3; c++) {
                double l = channel(cur->l, c);
                sum[c] += l;
                gr[c] = ps_v3_add(gr[c], ps_v3_scale(vk, l * tan_c));
                gt[c] = ps_v3_add(gt[c], ps_v3_scale(vb, wphi * (l - channel(left->l, c))));
                if (below)
                    gt[c] = ps_v3_add(gt[c], ps_v3_scale(uk, wth * (l - channel(below->l, c))));
            }
        }
    }
    double w = PS_PI / ((double)m * n);
    rec->e = ps_rgb_make(sum[0] * w, sum[1] * w, sum[2] * w);
    for (int c = 0; c < 3; c++) {
        rec->grad_r[c] = ps_v3_scale(gr[c], w);
        rec->grad_t[c] = gt[c];
    }
    rec->r_harmonic = inv_t > 0.0 ? (double)m * n / inv_t : INFINITY;
    rec->t_min = t_min;
    rec->r = rec->r_harmonic;
}

/* ---- the octree ------------------------------------------------------------ */

static bool new_children(ps_irrcache *c, size_t parent)
{
    if (c->node_count + 8 > c->node_cap) {
        size_t cap = c->node_cap * 2;
        irr_node *nodes = realloc(c->nodes, cap * sizeof *nodes);
        if (!nodes)
            return false;
        c->nodes = nodes;
        c->node_cap = cap;
    }
    irr_node *pn = &c->nodes[parent];
    double h = pn->half / 2;
    for (int i = 0; i < 8; i++) {
        irr_node *ch = &c->nodes[c->node_count + (size_t)i];
        ch->centre = ps_v3(pn->centre.x + (i & 1 ? h : -h), pn->centre.y + (i & 2 ? h : -h),
                           pn->centre.z + (i & 4 ? h : -h));
        ch->half = h;
        ch->child = -1;
        ch->first = -1;
    }
    pn->child = (int32_t)c->node_count;
    c->node_count += 8;
    return true;
}

static int octant(const irr_node *nd, ps_vec3 p)
{
    return (p.x >= nd->centre.x ? 1 : 0) | (p.y >= nd->centre.y ? 2 : 0) | (p.z >= nd->centre.z ? 4 : 0);
}

static bool inside(const irr_node *nd, ps_vec3 p, double grow)
{
    double h = nd->half * grow;
    return fabs(p.x - nd->centre.x) <= h && fabs(p.y - nd->centre.y) <= h && fabs(p.z - nd->centre.z) <= h;
}

ps_status ps_irrcache_create(ps_aabb bounds, double a, ps_irrcache **out, ps_error *err)
{
    *out = NULL;
    ps_irrcache *c = calloc(1, sizeof *c);
    if (!c)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the irradiance cache");
    c->a = a;
    c->node_cap = 64;
    c->nodes = malloc(c->node_cap * sizeof *c->nodes);
    if (!c->nodes) {
        free(c);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the irradiance cache");
    }
    if (ps_aabb_is_empty(bounds))
        bounds.lo = bounds.hi = ps_v3(0, 0, 0);
    ps_vec3 ext = ps_v3_sub(bounds.hi, bounds.lo);
    double half = 0.5 * fmax(ext.x, fmax(ext.y, ext.z)) * IRR_ROOT_MARGIN;
    c->nodes[0].centre = ps_v3_scale(ps_v3_add(bounds.lo, bounds.hi), 0.5);
    c->nodes[0].half = half > 0.0 ? half : 1.0;
    c->nodes[0].child = -1;
    c->nodes[0].first = -1;
    c->node_count = 1;
    *out = c;
    return PS_OK;
}

void ps_irrcache_destroy(ps_irrcache *c)
{
    if (!c)
        return;
    free(c->recs);
    free(c->next);
    free(c->nodes);
    free(c);
}

size_t ps_irrcache_count(const ps_irrcache *c) { return c->count; }

ps_status ps_irrcache_add(ps_irrcache *c, const ps_irr_record *rec, ps_error *err)
{
    if (c->count == c->cap) {
        size_t cap = c->cap ? c->cap * 2 : 256;
        if (cap > INT32_MAX)
            return ps_error_set(err, PS_ERR_LIMIT, "the irradiance cache is full (%zu records)", c->count);
        ps_irr_record *recs = realloc(c->recs, cap * sizeof *recs);
        if (!recs)
            return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the irradiance cache");
        c->recs = recs;
        int32_t *next = realloc(c->next, cap * sizeof *next);
        if (!next)
            return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the irradiance cache");
        c->next = next;
        c->cap = cap;
    }
    /* The deepest node holding the centre whose half-size still covers the reach. */
    double reach = c->a * rec->r;
    size_t node = 0;
    for (int depth = 0; depth < IRR_MAX_DEPTH && inside(&c->nodes[node], rec->p, 1.0); depth++) {
        if (c->nodes[node].half / 2 < reach)
            break;
        if (c->nodes[node].child < 0 && !new_children(c, node))
            return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the irradiance cache");
        node = (size_t)c->nodes[node].child + (size_t)octant(&c->nodes[node], rec->p);
    }
    size_t i = c->count++;
    c->recs[i] = *rec;
    c->next[i] = c->nodes[node].first;
    c->nodes[node].first = (int32_t)i;
    return PS_OK;
}

/* The error term eps of record r at (p, n), or INFINITY where it does not count at all. */
static double record_error(const ps_irrcache *c, const ps_irr_record *r, ps_vec3 p, ps_vec3 n)
{
    double cosn = ps_v3_dot(n, r->n);
    if (cosn <= 0.0)
        return INFINITY;
    ps_vec3 d = ps_v3_sub(p, r->p);
    double eps = ps_v3_len(d) / r->r + sqrt(fmax(0.0, 1.0 - cosn));
    if (eps >= c->a || ps_v3_dot(d, ps_v3_add(n, r->n)) * 0.5 < -IRR_FRONT * r->r)
        return INFINITY;
    return eps;
}

bool ps_irrcache_covered(const ps_irrcache *c, ps_vec3 p, ps_vec3 n, double share)
{
    int32_t stack[8 * IRR_MAX_DEPTH + 8];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const irr_node *nd = &c->nodes[stack[--top]];
        for (int32_t i = nd->first; i >= 0; i = c->next[i])
            if (record_error(c, &c->recs[i], p, n) < share * c->a)
                return true;
        if (nd->child >= 0)
            for (int k = 0; k < 8; k++)
                if (inside(&c->nodes[nd->child + k], p, 2.0))
                    stack[top++] = nd->child + k;
    }
    return false;
}

bool ps_irrcache_lookup(const ps_irrcache *c, ps_vec3 p, ps_vec3 n, ps_rgb *e, double *weight)
{
    double inv_a = 1.0 / c->a, wsum = 0.0;
    double acc[3] = {0, 0, 0};
    int32_t stack[8 * IRR_MAX_DEPTH + 8];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const irr_node *nd = &c->nodes[stack[--top]];
        for (int32_t i = nd->first; i >= 0; i = c->next[i]) {
            const ps_irr_record *r = &c->recs[i];
            double eps = record_error(c, r, p, n);
            if (!isfinite(eps))
                continue;
            ps_vec3 d = ps_v3_sub(p, r->p);
            double w = 1.0 / fmax(eps, 1e-9) - inv_a;
            ps_vec3 turn = ps_v3_cross(r->n, n);
            for (int k = 0; k < 3; k++) {
                double v = channel(r->e, k) + ps_v3_dot(turn, r->grad_r[k]) + ps_v3_dot(d, r->grad_t[k]);
                acc[k] += w * fmax(0.0, v);
            }
            wsum += w;
        }
        if (nd->child >= 0)
            for (int k = 0; k < 8; k++) {
                int32_t ch = nd->child + k;
                if (inside(&c->nodes[ch], p, 2.0))
                    stack[top++] = ch;
            }
    }
    if (weight)
        *weight = wsum;
    if (!(wsum > 0.0))
        return false;
    *e = ps_rgb_make(acc[0] / wsum, acc[1] / wsum, acc[2] / wsum);
    return true;
}
