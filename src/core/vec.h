/* vec.h: vectors, colours, rays and boxes, passed by value, all static inline.
 *
 * Doubles throughout: scenes from 1e-4 m to 1e4 m must trace with the same
 * relative precision, and scalar double arithmetic costs the same as float on
 * the CPUs we target. Compact float/packed forms belong to storage (photons). */
#ifndef PS_CORE_VEC_H
#define PS_CORE_VEC_H

#include <math.h>
#include <stdbool.h>

typedef struct ps_vec3 { double x, y, z; } ps_vec3;

/* Linear RGB; radiance, power or reflectance depending on context. */
typedef struct ps_rgb { double r, g, b; } ps_rgb;

/* A ray o + t·d. d need not be unit length; users that need it normalise. */
typedef struct ps_ray { ps_vec3 o, d; } ps_ray;

/* An axis-aligned box; empty when any lo > hi (see ps_aabb_empty). */
typedef struct ps_aabb { ps_vec3 lo, hi; } ps_aabb;

#define PS_PI 3.14159265358979323846
#define PS_INV_PI 0.31830988618379067154

/* ---- vec3 ---------------------------------------------------------------- */

static inline ps_vec3 ps_v3(double x, double y, double z) { ps_vec3 v = {x, y, z}; return v; }
static inline ps_vec3 ps_v3_add(ps_vec3 a, ps_vec3 b) { return ps_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline ps_vec3 ps_v3_sub(ps_vec3 a, ps_vec3 b) { return ps_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline ps_vec3 ps_v3_mul(ps_vec3 a, ps_vec3 b) { return ps_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline ps_vec3 ps_v3_scale(ps_vec3 a, double s) { return ps_v3(a.x * s, a.y * s, a.z * s); }
static inline ps_vec3 ps_v3_neg(ps_vec3 a) { return ps_v3(-a.x, -a.y, -a.z); }
/* Bit for bit (a cache key, a place drawn from): no tolerance. */
static inline bool ps_v3_equal(ps_vec3 a, ps_vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
/* a + b·s, the most common step along a ray. */
static inline ps_vec3 ps_v3_madd(ps_vec3 a, ps_vec3 b, double s) { return ps_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline double ps_v3_dot(ps_vec3 a, ps_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline ps_vec3 ps_v3_cross(ps_vec3 a, ps_vec3 b)
{
    return ps_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double ps_v3_len2(ps_vec3 a) { return ps_v3_dot(a, a); }
static inline double ps_v3_len(ps_vec3 a) { return sqrt(ps_v3_dot(a, a)); }
/* Unit vector along a; the zero vector stays zero rather than becoming NaN.
 * Components so small (or large) that their squares under- or overflow are
 * rescaled first, so that any non-zero finite vector normalises. */
static inline ps_vec3 ps_v3_norm(ps_vec3 a)
{
    double l2 = ps_v3_dot(a, a);
    if (l2 > 1e-280 && l2 < 1e280)
        return ps_v3_scale(a, 1.0 / sqrt(l2));
    double m = fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
    if (!(m > 0.0) || !isfinite(m))
        return a;
    a = ps_v3_scale(a, 1.0 / m);
    return ps_v3_scale(a, 1.0 / sqrt(ps_v3_dot(a, a)));
}
static inline ps_vec3 ps_v3_min(ps_vec3 a, ps_vec3 b) { return ps_v3(fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z)); }
static inline ps_vec3 ps_v3_max(ps_vec3 a, ps_vec3 b) { return ps_v3(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)); }
static inline ps_vec3 ps_v3_lerp(ps_vec3 a, ps_vec3 b, double t) { return ps_v3_madd(a, ps_v3_sub(b, a), t); }
static inline double ps_v3_max_comp(ps_vec3 a) { return fmax(a.x, fmax(a.y, a.z)); }
static inline double ps_v3_max_abs(ps_vec3 a) { return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z))); }
static inline double ps_v3_get(ps_vec3 a, int axis) { return axis == 0 ? a.x : axis == 1 ? a.y : a.z; }
static inline bool ps_v3_isfinite(ps_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

/* An orthonormal basis (t, b) around unit n without branches on tiny values
 * (Duff et al. 2017); stable for n along any axis, which the splat basis needs. */
static inline void ps_v3_basis(ps_vec3 n, ps_vec3 *t, ps_vec3 *b)
{
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double c = n.x * n.y * a;
    *t = ps_v3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    *b = ps_v3(c, sign + n.y * n.y * a, -n.y);
}

/* ---- rgb ----------------------------------------------------------------- */

static inline ps_rgb ps_rgb_make(double r, double g, double b) { ps_rgb c = {r, g, b}; return c; }
static inline ps_rgb ps_rgb_gray(double v) { return ps_rgb_make(v, v, v); }
static inline ps_rgb ps_rgb_add(ps_rgb a, ps_rgb b) { return ps_rgb_make(a.r + b.r, a.g + b.g, a.b + b.b); }
static inline ps_rgb ps_rgb_mul(ps_rgb a, ps_rgb b) { return ps_rgb_make(a.r * b.r, a.g * b.g, a.b * b.b); }
static inline ps_rgb ps_rgb_scale(ps_rgb a, double s) { return ps_rgb_make(a.r * s, a.g * s, a.b * s); }
static inline double ps_rgb_max(ps_rgb a) { return fmax(a.r, fmax(a.g, a.b)); }
static inline double ps_rgb_sum(ps_rgb a) { return a.r + a.g + a.b; }
static inline double ps_rgb_mean(ps_rgb a) { return (a.r + a.g + a.b) / 3.0; }
static inline bool ps_rgb_is_black(ps_rgb a) { return a.r <= 0.0 && a.g <= 0.0 && a.b <= 0.0; }
static inline bool ps_rgb_isfinite(ps_rgb a) { return isfinite(a.r) && isfinite(a.g) && isfinite(a.b); }

/* ---- ray ----------------------------------------------------------------- */

static inline ps_ray ps_ray_make(ps_vec3 o, ps_vec3 d) { ps_ray r = {o, d}; return r; }
static inline ps_vec3 ps_ray_at(ps_ray r, double t) { return ps_v3_madd(r.o, r.d, t); }

/* ---- aabb ---------------------------------------------------------------- */

/* The empty box: the identity of ps_aabb_union. */
static inline ps_aabb ps_aabb_empty(void)
{
    ps_aabb b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    return b;
}
static inline bool ps_aabb_is_empty(ps_aabb b) { return b.lo.x > b.hi.x || b.lo.y > b.hi.y || b.lo.z > b.hi.z; }
static inline ps_aabb ps_aabb_point(ps_aabb b, ps_vec3 p)
{
    ps_aabb r = {ps_v3_min(b.lo, p), ps_v3_max(b.hi, p)};
    return r;
}
static inline ps_aabb ps_aabb_union(ps_aabb a, ps_aabb b)
{
    ps_aabb r = {ps_v3_min(a.lo, b.lo), ps_v3_max(a.hi, b.hi)};
    return r;
}
static inline ps_vec3 ps_aabb_center(ps_aabb b) { return ps_v3_scale(ps_v3_add(b.lo, b.hi), 0.5); }
static inline ps_vec3 ps_aabb_diag(ps_aabb b) { return ps_v3_sub(b.hi, b.lo); }
static inline double ps_aabb_area(ps_aabb b)
{
    if (ps_aabb_is_empty(b))
        return 0.0;
    ps_vec3 d = ps_aabb_diag(b);
    return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
}
static inline bool ps_aabb_contains(ps_aabb b, ps_vec3 p)
{
    return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y && p.z >= b.lo.z && p.z <= b.hi.z;
}
/* The largest coordinate magnitude in the box: what scene-scaled epsilons scale with. */
static inline double ps_aabb_extent(ps_aabb b)
{
    return ps_aabb_is_empty(b) ? 0.0 : fmax(ps_v3_max_abs(b.lo), ps_v3_max_abs(b.hi));
}

/* Slab test: the parametric interval [*t0, *t1] where r overlaps b, clipped to
 * [tmin, tmax]. inv_d is 1/r.d per component (±inf for zero components is
 * fine: the NaN from 0·inf on a slab face is discarded by fmin/fmax ordering). */
static inline bool ps_aabb_hit(ps_aabb b, ps_ray r, ps_vec3 inv_d, double tmin, double tmax, double *t0, double *t1)
{
    double tx0 = (b.lo.x - r.o.x) * inv_d.x, tx1 = (b.hi.x - r.o.x) * inv_d.x;
    double ty0 = (b.lo.y - r.o.y) * inv_d.y, ty1 = (b.hi.y - r.o.y) * inv_d.y;
    double tz0 = (b.lo.z - r.o.z) * inv_d.z, tz1 = (b.hi.z - r.o.z) * inv_d.z;
    double lo = fmax(fmax(fmin(tx0, tx1), fmin(ty0, ty1)), fmax(fmin(tz0, tz1), tmin));
    double hi = fmin(fmin(fmax(tx0, tx1), fmax(ty0, ty1)), fmin(fmax(tz0, tz1), tmax));
    if (t0) *t0 = lo;
    if (t1) *t1 = hi;
    return lo <= hi;
}

#endif
