/* splat.c: kernel textures and the splat vertex arrays. */
#include "preview/splat.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/array.h"
#include "core/jobs.h"
#include "photon/tracer.h"
#include "scene/bsdf.h"

const char *const ps_splat_mode_names[PS_SPLAT_MODE_COUNT + 1] = {"points", "triangles", "sprites", NULL};
const char *const ps_precision_names[PS_PRECISION_COUNT + 1] = {"none", "diffusion", "counter", NULL};
const char *const ps_color_depth_names[PS_COLOR_DEPTH_COUNT + 1] = {"8", "float", NULL};
const char *const ps_radius_schedule_names[PS_RADIUS_SCHEDULE_COUNT + 1] = {"fixed", "progressive", NULL};

const char *ps_splat_mode_name(ps_splat_mode m)
{
    return (unsigned)m < PS_SPLAT_MODE_COUNT ? ps_splat_mode_names[m] : "?";
}
const char *ps_precision_name(ps_precision p) { return (unsigned)p < PS_PRECISION_COUNT ? ps_precision_names[p] : "?"; }
const char *ps_color_depth_name(ps_color_depth d)
{
    return (unsigned)d < PS_COLOR_DEPTH_COUNT ? ps_color_depth_names[d] : "?";
}

/* ---- the kernel texture --------------------------------------------------- */

/* A threshold in [0, 1) for texel (i, j) of a halftone: a fixed integer hash
 * (Murmur3's finaliser), so that the dither is white noise, with no pattern
 * of its own for overlapping splats to beat against. */
static double halftone_threshold(int i, int j)
{
    uint32_t h = (uint32_t)i * 0x9E3779B1u ^ (uint32_t)j * 0x85EBCA77u;
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    h ^= h >> 16;
    return (double)(h >> 8) / 16777216.0;
}

static ps_status make_texture(ps_kernel k, int size, bool halftone, ps_kernel_texture *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    if (size < 3 || size > 4096) /* extent = size / (size - 2) needs 3 */
        return ps_error_set(err, PS_ERR_RANGE, "kernel texture: size %d out of range", size);
    out->alpha = malloc((size_t)size * (size_t)size);
    if (!out->alpha)
        return ps_error_set(err, PS_ERR_NOMEM, "kernel texture: out of memory");
    out->size = size;
    out->extent = (double)size / (double)(size - 2);
    out->halftone = halftone;
    double sum = 0.0;
    for (int j = 0; j < size; j++)
        for (int i = 0; i < size; i++) {
            /* Texel centres over [-extent, extent]^2, in units of the radius. */
            double x = out->extent * (2.0 * (i + 0.5) / size - 1.0), y = out->extent * (2.0 * (j + 0.5) / size - 1.0);
            double a = fmin(fmax(ps_kernel_profile(k, sqrt(x * x + y * y)), 0.0), 1.0);
            uint8_t code = halftone ? (a > halftone_threshold(i, j) ? 255 : 0) : (uint8_t)lround(255.0 * a);
            out->alpha[(size_t)j * (size_t)size + (size_t)i] = code;
            sum += code / 255.0;
        }
    /* C: the stored weights' integral over the square, (2 extent / size)^2
     * per texel, divided by the unit disc's area. */
    double texel = 2.0 * out->extent / size;
    out->mean = sum * texel * texel / PS_PI;
    return PS_OK;
}

ps_status ps_kernel_texture_make(ps_kernel k, int size, ps_kernel_texture *out, ps_error *err)
{
    return make_texture(k, size, false, out, err);
}

ps_status ps_kernel_texture_make_halftone(ps_kernel k, int size, ps_kernel_texture *out, ps_error *err)
{
    return make_texture(k, size, true, out, err);
}

void ps_kernel_texture_free(ps_kernel_texture *t)
{
    if (!t)
        return;
    free(t->alpha);
    memset(t, 0, sizeof *t);
}

/* ---- batches -------------------------------------------------------------- */

void ps_splat_batch_init(ps_splat_batch *b) { memset(b, 0, sizeof *b); }

void ps_splat_batch_free(ps_splat_batch *b)
{
    if (!b)
        return;
    if (b->large_pages) {
        ps_memory_large_free(b->positions, b->cap_pos * sizeof *b->positions);
        ps_memory_large_free(b->colors, b->cap_col * sizeof *b->colors);
        ps_memory_large_free(b->texcoords, b->cap_tex * sizeof *b->texcoords);
    } else {
        free(b->positions);
        free(b->colors);
        free(b->texcoords);
    }
    free(b->group);
    free(b->order);
    free(b->order_tmp);
    free(b->normals);
    memset(b, 0, sizeof *b);
}

void ps_splat_batch_clear(ps_splat_batch *b)
{
    b->vertex_count = 0;
    b->splats = 0;
    b->grouped = false;
}

void ps_splat_batch_reset_carry(ps_splat_batch *b) { memset(b->carry, 0, sizeof b->carry); }

double ps_splat_batch_carry(const ps_splat_batch *b, int ch)
{
    double sum = 0.0;
    for (int g = 0; g < PS_SPLAT_DIFFUSION_REGIONS; g++)
        sum += b->carry[g][ch];
    return sum;
}

/* Reorders the splats [first, splats) by stencil value (a stable counting
 * sort, so error diffusion's order within a group is kept) and records where
 * each group starts. The copy it sorts from is as large as the splats'
 * arrays (108 bytes a triangle splat), made for each call and freed after
 * it: with large_pages in 2 MiB pages too, as its pages are all new each
 * time. (Kept in the batch instead, the window held some 40 MiB more.) */
static bool group_splats(ps_splat_batch *b, size_t first, size_t per)
{
    size_t n = b->splats - first;
    size_t count[PS_SPLAT_GROUPS + 1] = {0};
    b->grouped = true;
    if (n == 0) { /* nothing drawn: every group empty */
        for (int g = 0; g <= PS_SPLAT_GROUPS; g++)
            b->group_first[g] = first * per;
        return true;
    }
    for (size_t i = 0; i < n; i++)
        count[b->group[first + i] + 1]++;
    for (int g = 0; g < PS_SPLAT_GROUPS; g++)
        count[g + 1] += count[g];
    size_t nv = n * per, bytes = nv * (per == 3 ? 9 : 7) * sizeof(float);
    float *pos = b->large_pages ? ps_memory_large_realloc(NULL, 0, bytes) : malloc(bytes);
    if (!pos)
        return false;
    float *col = pos + 3 * nv, *tex = per == 3 ? col + 4 * nv : NULL;
    size_t v0 = first * per;
    memcpy(pos, b->positions + 3 * v0, n * per * 3 * sizeof *pos);
    memcpy(col, b->colors + 4 * v0, n * per * 4 * sizeof *col);
    if (tex)
        memcpy(tex, b->texcoords + 2 * v0, n * per * 2 * sizeof *tex);
    size_t next[PS_SPLAT_GROUPS];
    for (int g = 0; g < PS_SPLAT_GROUPS; g++) {
        next[g] = count[g];
        b->group_first[g] = v0 + count[g] * per;
    }
    b->group_first[PS_SPLAT_GROUPS] = v0 + n * per;
    for (size_t i = 0; i < n; i++) {
        size_t to = v0 + next[b->group[first + i]]++ * per, from = i * per;
        memcpy(b->positions + 3 * to, pos + 3 * from, per * 3 * sizeof *pos);
        memcpy(b->colors + 4 * to, col + 4 * from, per * 4 * sizeof *col);
        if (tex)
            memcpy(b->texcoords + 2 * to, tex + 2 * from, per * 2 * sizeof *tex);
    }
    if (b->large_pages)
        ps_memory_large_free(pos, bytes);
    else
        free(pos);
    b->grouped = true;
    return true;
}

void ps_splat_basis(ps_vec3 n, ps_vec3 *x, ps_vec3 *y)
{
    /* Zero the smallest component and swap the other two with one negated:
     * perpendicular to n, and never near zero length for a unit n. */
    double ax = fabs(n.x), ay = fabs(n.y), az = fabs(n.z);
    ps_vec3 v;
    if (ax <= ay && ax <= az)
        v = ps_v3(0.0, -n.z, n.y);
    else if (ay <= az)
        v = ps_v3(-n.z, 0.0, n.x);
    else
        v = ps_v3(-n.y, n.x, 0.0);
    *x = ps_v3_norm(v);
    *y = ps_v3_norm(ps_v3_cross(n, *x));
}

/* Beyond this many steps a colour is far past the buffer's range: nothing to
 * round (and the integer conversion below stays defined). */
#define QUANTISE_MAX_STEPS 1e15

/* x * L rounded to a whole number of steps, over L, for x >= 0: a truncating
 * conversion instead of round(), which is a library call on x86-64's base
 * instruction set and showed in the splat build's profile. */
static double to_steps(double x, double L)
{
    double steps = x * L;
    if (!(steps > 0.0))
        return 0.0;
    if (steps >= QUANTISE_MAX_STEPS)
        return x;
    return (double)(int64_t)(steps + 0.5) / L;
}

/* A step count rounded to the nearest whole number (ties to even), at least
 * 0, for the diffusion's carry: adding and taking away 1.5 * 2^52 leaves no
 * bits below the units (x86-64's base instruction set has no rounding
 * instruction, and the integer conversions to_steps makes are the slowest
 * link of the carry's chain). It needs the IEEE arithmetic the build asks
 * for: -ffast-math would fold the two away. Past QUANTISE_MAX_STEPS the
 * count is kept as it is, as to_steps keeps it; a NaN gives 0, as to_steps
 * does. */
#define ROUND_MAGIC 6755399441055744.0 /* 1.5 * 2^52 */
static double round_steps(double steps)
{
    if (steps >= QUANTISE_MAX_STEPS)
        return steps;
    double q = (steps + ROUND_MAGIC) - ROUND_MAGIC;
    /* Faint photons round to 0 at random, so a branch here mispredicts:
     * SSE2's max (unordered, it gives the 0: a NaN gives 0). */
#if defined(__SSE2__)
    return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(q), _mm_setzero_pd()));
#else
    return q > 0.0 ? q : 0.0;
#endif
}

/* Where a splat's centre falls on the screen, as a Z-order (Morton) key of
 * its pixel: interleaved bits of x and y, so that splats near each other on
 * the screen are near each other in the key's order. */
static uint32_t spread_bits(uint32_t v)
{
    v &= 0xffff;
    v = (v | (v << 8)) & 0x00ff00ff;
    v = (v | (v << 4)) & 0x0f0f0f0f;
    v = (v | (v << 2)) & 0x33333333;
    v = (v | (v << 1)) & 0x55555555;
    return v;
}

static uint32_t z_order(double x, double y, uint32_t side)
{
    double top = (double)(side - 1);
    uint32_t ix = x > 0.0 ? (x < top ? (uint32_t)x : side - 1) : 0u;
    uint32_t iy = y > 0.0 ? (y < top ? (uint32_t)y : side - 1) : 0u;
    return spread_bits(ix) | spread_bits(iy) << 1;
}

/* The Z-order keys' square: the smallest power of two covering the image
 * (at most 2^16); splats off the image clamp to its edge. Its bits, twice
 * its side's, are all the radix sort below needs to look at. */
static uint32_t z_side(const ps_camera_frame *cam, int *key_bits)
{
    int side_bits = 0;
    int m = cam->width > cam->height ? cam->width : cam->height;
    while (side_bits < 16 && (1 << side_bits) < m)
        side_bits++;
    *key_bits = 2 * side_bits;
    return 1u << side_bits;
}

/* Error diffusion in screen order. Thesis departure: the thesis carries each
 * photon's round-off into the next photon in index order, which keeps the
 * sum but picks the faint photons that get a code at random over the
 * screen, a noise of its own. Carried along a Z-order curve over the splats'
 * pixels instead (as Riemersma's dither carries along a Hilbert curve), the
 * photons that carry a code lie evenly over the screen, and the round-off of
 * any stretch of the curve is under one code: the screen is carried as
 * PS_SPLAT_DIFFUSION_REGIONS tiles, each on its own curve and carry, so that
 * the tiles run on the cores (below). */
/* Radix digits of the sort: 11 bits a pass. */
#define SORT_PREFETCH 32
#if defined(__GNUC__)
#define PS_PREFETCH_WRITE(addr) __builtin_prefetch((addr), 1, 0)
#else
#define PS_PREFETCH_WRITE(addr) ((void)(addr))
#endif
#define SORT_DIGIT_BITS 11
/* The screen's tiles are the Z-order's first bits (splat.h). */
#define REGION_BITS PS_SPLAT_DIFFUSION_REGION_BITS

/* Jobs 0..count-1 on up to `threads` threads (0: one a core), dealt
 * round-robin; what a job does never depends on which thread runs it. */
static void run_jobs(size_t count, int threads, ps_job_fn fn, void *ctx)
{
    ps_run_jobs(count, threads <= 0 ? ps_online_cores() : threads, fn, ctx);
}

/* The diffusion's shared state: the sorted keys go from `a` to `t`, a region
 * at a time (its splats' slice [start[g], start[g + 1]) of both). */
typedef struct diffusion {
    ps_splat_batch *b;
    const ps_splat_params *p;
    size_t per, v0;
    int key_bits, region_bits;
    uint64_t *a, *t;
    size_t start[PS_SPLAT_DIFFUSION_REGIONS + 1];
    /* Per build range: its splats' slice of `a` and where each region's of
     * them go in `t` (the stable bucket pass). */
    size_t ranges;
    const size_t *range_at, *range_n;
    size_t (*range_base)[PS_SPLAT_DIFFUSION_REGIONS];
} diffusion;

static unsigned region_of(const diffusion *d, uint64_t entry)
{
    return (unsigned)((entry >> 32) >> (d->key_bits - d->region_bits));
}

/* Bucket pass, one build range: its splats into their regions' slices of t,
 * in order (stable), each key joined by the splat's final place. */
static void bucket_range(void *ctx, size_t k)
{
    diffusion *d = ctx;
    size_t base[PS_SPLAT_DIFFUSION_REGIONS];
    memcpy(base, d->range_base[k], sizeof base);
    size_t at = d->range_at[k];
    const uint64_t *a = d->a + at;
    for (size_t i = 0; i < d->range_n[k]; i++) /* with its place, the sort's tie-break */
        d->t[base[region_of(d, a[i])]++] = a[i] | (uint64_t)(at + i);
}

/* One region: the rest of the key sorted (LSD radix, stable), then each
 * splat's round-off carried into the next along the curve. */
static void diffuse_region(void *ctx, size_t g)
{
    diffusion *d = ctx;
    size_t n = d->start[g + 1] - d->start[g];
    if (n == 0)
        return;
    uint64_t *a = d->t + d->start[g], *t = d->a + d->start[g];
    size_t count[(1 << SORT_DIGIT_BITS) + 1]; /* 16 KiB of stack */
    int low_bits = d->key_bits - d->region_bits;
    for (int shift = 32; shift < 32 + low_bits; shift += SORT_DIGIT_BITS) { /* the key: the upper 32 bits */
        int bits = 32 + low_bits - shift < SORT_DIGIT_BITS ? 32 + low_bits - shift : SORT_DIGIT_BITS;
        const uint64_t mask = ((uint64_t)1 << bits) - 1;
        memset(count, 0, sizeof count);
        for (size_t i = 0; i < n; i++)
            count[((a[i] >> shift) & mask) + 1]++;
        for (size_t v = 0; v < mask + 1; v++)
            count[v + 1] += count[v];
        for (size_t i = 0; i < n; i++)
            t[count[(a[i] >> shift) & mask]++] = a[i];
        uint64_t *swap = a;
        a = t;
        t = swap;
    }
    ps_splat_batch *b = d->b;
    double c0 = b->carry[g][0], c1 = b->carry[g][1], c2 = b->carry[g][2], L = d->p->levels, inv_L = 1.0 / L;
    size_t per = d->per, v0 = d->v0;
    for (size_t i = 0; i < n; i++) {
        /* The colours are read in screen order, scattered over the array:
         * ask for one a few dozen ahead, so that the wait overlaps (it is
         * most of this loop's time otherwise). */
        if (i + SORT_PREFETCH < n)
            PS_PREFETCH_WRITE(&b->colors[4 * (v0 + (size_t)(a[i + SORT_PREFETCH] & 0xffffffffu) * per)]);
        size_t v = v0 + (size_t)(a[i] & 0xffffffffu) * per;
        float *rgba = &b->colors[4 * v];
        /* The round-off carried into the next splat, per channel. The carry
         * is the loop's dependency chain, so only adds and multiplies lie on
         * it (the step count rounded by round_steps), the division that
         * turns the count into a colour off it; the channels are written
         * out so that the carries stay in registers. */
        double s0 = (rgba[0] + c0) * L, s1 = (rgba[1] + c1) * L, s2 = (rgba[2] + c2) * L;
        double q0 = round_steps(s0), q1 = round_steps(s1), q2 = round_steps(s2);
        c0 = (s0 - q0) * inv_L;
        c1 = (s1 - q1) * inv_L;
        c2 = (s2 - q2) * inv_L;
        rgba[0] = (float)(q0 / L);
        rgba[1] = (float)(q1 / L);
        rgba[2] = (float)(q2 / L);
        for (size_t k = 1; k < per; k++)
            memcpy(&b->colors[4 * (v + k)], rgba, 4 * sizeof *rgba);
    }
    b->carry[g][0] = c0;
    b->carry[g][1] = c1;
    b->carry[g][2] = c2;
}

/* The order is a stable sort of the splats by their keys (the splat's place
 * as the tie-break), so the same photons always give the same picture. It is
 * sorted a region at a time: a stable bucket pass on the key's first
 * REGION_BITS (each build range's splats on a thread), then each region's
 * rest of the key and its carry on a thread. Each region carries its own
 * round-off (b->carry[g]): the regions are fixed by the screen, not the
 * threads, so the bytes are the same for any thread count. */
static void diffuse_in_screen_order(ps_splat_batch *b, const ps_splat_params *p, size_t first_splat, size_t per,
                                    const size_t *range_at, const size_t *range_n,
                                    size_t (*range_count)[PS_SPLAT_DIFFUSION_REGIONS], size_t ranges)
{
    diffusion d;
    memset(&d, 0, sizeof d);
    d.b = b;
    d.p = p;
    d.per = per;
    size_t n = b->splats - first_splat;
    d.v0 = b->vertex_count - n * per;
    (void)z_side(&p->cam, &d.key_bits);
    d.region_bits = d.key_bits < REGION_BITS ? d.key_bits : REGION_BITS;
    d.a = b->order;
    d.t = b->order_tmp;
    d.ranges = ranges;
    d.range_at = range_at;
    d.range_n = range_n;
    d.range_base = range_count; /* turned into bases in place */
    size_t regions = (size_t)1 << d.region_bits;
    /* Region g's slice starts after every region before it; range k's
     * share of it after the ranges before k. */
    size_t at = 0;
    for (size_t g = 0; g < regions; g++) {
        d.start[g] = at;
        for (size_t k = 0; k < ranges; k++) {
            size_t c = range_count[k][g];
            range_count[k][g] = at;
            at += c;
        }
    }
    for (size_t g = regions; g <= PS_SPLAT_DIFFUSION_REGIONS; g++)
        d.start[g] = at;
    run_jobs(ranges, p->threads, bucket_range, &d);
    run_jobs(regions, p->threads, diffuse_region, &d);
}

/* Photons are built in ranges of this many, on as many threads as there are
 * cores: a range's splats are written where its first photon would put them
 * and then moved down in range order, and its round-off counts are added in
 * range order, so the result is the same bytes for any number of threads. */
#define BUILD_RANGE 65536

typedef struct build_range {
    const ps_photon *photons;
    const uint16_t *materials;
    const ps_splat_params *p;
    ps_splat_batch *b;
    size_t first, end;     /* photons [first, end) */
    size_t first_splat;    /* the batch's splats before this build */
    size_t splats;         /* written by this range */
    double wanted, lost;   /* the counter's sums over this range */
    size_t regions[PS_SPLAT_DIFFUSION_REGIONS]; /* diffusion: its splats in each screen tile */
} build_range;

/* The counter: send as is, and count what the buffer will round away. */
static double count_round_off(build_range *R, double L, double c)
{
    R->wanted += c;
    R->lost += c - to_steps(c, L);
    return c;
}

/* The photon's normal code: bits 0-13 of normal_flags (photon.h). */
#define NORMAL_CODE_BITS 14
#define NORMAL_CODE_MASK ((1u << NORMAL_CODE_BITS) - 1u)

static void build_splats_of(build_range *R)
{
    const ps_splat_params *p = R->p;
    ps_splat_batch *b = R->b;
    size_t per = p->mode == PS_SPLAT_TRIANGLES ? 3 : 1;
    size_t first_splat = R->first_splat;
    /* Where this range writes: as if every photon before it made a splat. */
    size_t s0 = first_splat + R->first, v0 = b->vertex_count + R->first * per;
    const ps_camera_frame *cam = &p->cam;
    double r = p->radius;
    double disc = 1.0 / (p->kernel_mean * PS_PI * r * r);
    bool rounds = p->levels > 0 && p->precision != PS_PRECISION_NONE;
    bool diffuse = rounds && p->precision == PS_PRECISION_DIFFUSION;
    double L = p->levels;
    int key_bits;
    uint32_t zside = z_side(cam, &key_bits);
    int region_bits = key_bits < REGION_BITS ? key_bits : REGION_BITS;
    /* World size of one pixel at unit depth along the view axis. */
    double pixel = 2.0 * cam->tan_half_fov / cam->height;
    const ps_vec3 *normals = b->normals;
    /* The projection to pixels (diffusion's screen order). */
    double half_w = 0.5 * cam->width, half_h = 0.5 * cam->height;
    double to_px = half_w / (cam->tan_half_fov * cam->aspect), to_py = half_h / cam->tan_half_fov;
    for (size_t i = R->first; i < R->end; i++) {
        const ps_photon *ph = &R->photons[i];
        ps_vec3 pos = ps_photon_position(ph), n = normals[ph->normal_flags & NORMAL_CODE_MASK];
        ps_vec3 to_eye = ps_v3_sub(cam->eye, pos);
        double dist = ps_v3_len(to_eye);
        if (!(dist > 0.0))
            continue;
        ps_vec3 wo = ps_v3_scale(to_eye, 1.0 / dist);
        double cos_v = ps_v3_dot(wo, n);
        if (cos_v <= 0.0)
            continue; /* the other face of a two-sided surface */
        /* Behind the eye or in its plane: GL clips it anyway, and its point
         * footprint would be negative or zero (a NaN or negative carry). */
        double depth = -ps_v3_dot(to_eye, cam->forward);
        if (!(depth > 0.0))
            continue;
        /* A diffuse BRDF needs no direction (and decoding one is half the
         * cost of a point splat). */
        const ps_material *mat = &p->materials[R->materials[i]];
        ps_rgb f = mat->type == PS_MAT_DIFFUSE ? ps_rgb_scale(mat->albedo, PS_INV_PI)
                                               : ps_bsdf_eval(mat, n, ps_photon_dir(ph), wo);
        ps_rgb c = ps_rgb_scale(ps_rgb_mul(f, ps_photon_power(ph)), p->scale);
        if (p->mode == PS_SPLAT_POINTS) {
            /* An unbiased one-pixel estimate: the power over the surface area
             * the point covers. Its square of (side * pixel) at unit depth
             * subtends side^2 pixel^2 cos^3(a) at angle a off the axis; at
             * distance dist = depth / cos(a) that is side^2 pixel^2 depth^2
             * cos(a) across the ray, and 1 / cos_v more along the surface. */
            /* One division, not three: they were a chain of the point's
             * latency. */
            double side = p->point_size * pixel * depth;
            double cos_held = cos_v > PS_SPLAT_MIN_COS ? cos_v : PS_SPLAT_MIN_COS;
            c = ps_rgb_scale(c, cos_held * dist / (side * side * depth));
        } else {
            c = ps_rgb_scale(c, disc);
            /* A sprite faces the eye: its disc covers 1 / cos more pixels than
             * the surface's disc would, so it carries cos of the colour. */
            if (p->mode == PS_SPLAT_SPRITES)
                c = ps_rgb_scale(c, cos_v);
        }
        double lift = p->surface ? 0.0 : PS_SPLAT_EYE_OFFSET * dist;
        if (p->mode == PS_SPLAT_SPRITES) {
            double tan_v = sqrt(fmax(0.0, 1.0 - cos_v * cos_v)) / cos_v;
            lift = fmax(lift, r * fmin(tan_v, PS_SPLAT_SPRITE_MAX_TAN));
        }
        ps_vec3 centre = ps_v3_madd(pos, wo, lift);
        /* GL sizes a sprite by its own distance: lifted, it grows by
         * dist / (dist - lift) a side, so its colour shrinks to match. */
        if (p->mode == PS_SPLAT_SPRITES)
            c = ps_rgb_scale(c, ((dist - lift) / dist) * ((dist - lift) / dist));
        size_t sp = s0 + R->splats; /* its place until compaction */
        float rgba[4] = {(float)c.r, (float)c.g, (float)c.b, 1.0f};
        if (rounds && !diffuse) {
            rgba[0] = (float)count_round_off(R, L, c.r);
            rgba[1] = (float)count_round_off(R, L, c.g);
            rgba[2] = (float)count_round_off(R, L, c.b);
        } else if (diffuse) {
            /* Rounded below, in screen order; the exact colour till then. */
            /* ps_camera_project's pixel, with one division (it showed in
             * the build's profile); off the eye's front, the corner. */
            ps_vec3 e = ps_v3_sub(centre, cam->eye);
            double z = ps_v3_dot(e, cam->forward), px = 0.0, py = 0.0;
            if (z > 0.0) {
                double inv_z = 1.0 / z;
                px = half_w + to_px * ps_v3_dot(e, cam->right) * inv_z;
                py = half_h - to_py * ps_v3_dot(e, cam->up) * inv_z;
            }
            uint32_t key = z_order(px, py, zside);
            b->order[sp - first_splat] = (uint64_t)key << 32; /* the place: when compacted */
            R->regions[key >> (key_bits - region_bits)]++;
        }
        size_t v = v0 + R->splats * per;
        if (p->mode == PS_SPLAT_TRIANGLES) {
            /* The equilateral triangle around the disc of radius r: corners
             * at 2r, at 90, 210 and 330 degrees; the texture's unit square
             * spans [-extent r, extent r]^2, so texcoords run 0.5 + cos / extent. */
            double tex = p->kernel_extent > 0.0 ? 1.0 / p->kernel_extent : 1.0;
            static const double cs[3][2] = {{0.0, 1.0}, {-0.86602540378443865, -0.5}, {0.86602540378443865, -0.5}};
            ps_vec3 x, y;
            ps_splat_basis(n, &x, &y);
            for (int k = 0; k < 3; k++) {
                ps_vec3 q = ps_v3_add(centre, ps_v3_add(ps_v3_scale(x, 2.0 * r * cs[k][0]),
                                                         ps_v3_scale(y, 2.0 * r * cs[k][1])));
                b->positions[3 * (v + k)] = (float)q.x;
                b->positions[3 * (v + k) + 1] = (float)q.y;
                b->positions[3 * (v + k) + 2] = (float)q.z;
                b->texcoords[2 * (v + k)] = (float)(0.5 + cs[k][0] * tex);
                b->texcoords[2 * (v + k) + 1] = (float)(0.5 + cs[k][1] * tex);
                memcpy(&b->colors[4 * (v + k)], rgba, sizeof rgba);
            }
        } else {
            b->positions[3 * v] = (float)centre.x;
            b->positions[3 * v + 1] = (float)centre.y;
            b->positions[3 * v + 2] = (float)centre.z;
            memcpy(&b->colors[4 * v], rgba, sizeof rgba);
        }
        if (p->objects)
            b->group[sp] = (uint8_t)ps_splat_stencil(p->objects[i]);
        R->splats++;
    }
}

static void build_range_job(void *ctx, size_t k) { build_splats_of(&((build_range *)ctx)[k]); }

/* The photon's normal is an octahedral code (NORMAL_CODE_BITS): decoded once for every code into the batch, so
 * that a splat looks its normal up instead of decoding it (two divisions, a
 * square root: a sixth of a point splat's build). The table is
 * ps_photon_normal's own results, so the splats are the same bits. */
static bool decode_normals(ps_splat_batch *b)
{
    if (b->normals)
        return true;
    b->normals = malloc(((size_t)1 << NORMAL_CODE_BITS) * sizeof *b->normals);
    if (!b->normals)
        return false;
    ps_photon ph;
    memset(&ph, 0, sizeof ph);
    for (uint32_t code = 0; code <= NORMAL_CODE_MASK; code++) {
        ph.normal_flags = (uint16_t)code;
        b->normals[code] = ps_photon_normal(&ph);
    }
    return true;
}

/* Room for count more splats of per vertices each. */
static bool reserve_vertices(ps_splat_batch *b, size_t per, size_t count)
{
    size_t n = b->vertex_count + per * count;
    bool large = b->large_pages;
    return PS_RESERVE_AS(b->positions, b->cap_pos, 3 * n, large) && PS_RESERVE_AS(b->colors, b->cap_col, 4 * n, large) &&
           (per != 3 || PS_RESERVE_AS(b->texcoords, b->cap_tex, 2 * n, large));
}

ps_status ps_splat_build(const ps_photon *photons, const uint16_t *materials, size_t count, const ps_splat_params *p,
                         ps_splat_batch *b, ps_error *err)
{
    size_t per = p->mode == PS_SPLAT_TRIANGLES ? 3 : 1;
    if (count > (SIZE_MAX / 4 - b->vertex_count) / per ||
        !reserve_vertices(b, per, count) ||
        (p->objects && !PS_RESERVE(b->group, b->cap_group, b->splats + count)) || (count && !decode_normals(b)))
        return ps_error_set(err, PS_ERR_NOMEM, "splats: out of memory for %zu photons", count);
    size_t first_splat = b->splats;
    bool diffuse = p->levels > 0 && p->precision == PS_PRECISION_DIFFUSION;
    if (diffuse && (!PS_RESERVE(b->order, b->cap_order, count) || !PS_RESERVE(b->order_tmp, b->cap_order_tmp, count)))
        return ps_error_set(err, PS_ERR_NOMEM, "splats: out of memory for %zu photons", count);
    size_t ranges = count ? (count + BUILD_RANGE - 1) / BUILD_RANGE : 0;
    build_range *R = ranges ? calloc(ranges, sizeof *R) : NULL;
    if (ranges && !R)
        return ps_error_set(err, PS_ERR_NOMEM, "splats: out of memory for %zu photons", count);
    for (size_t k = 0; k < ranges; k++) {
        R[k].photons = photons;
        R[k].materials = materials;
        R[k].p = p;
        R[k].b = b;
        R[k].first = k * BUILD_RANGE;
        R[k].end = k + 1 < ranges ? (k + 1) * BUILD_RANGE : count;
        R[k].first_splat = first_splat;
    }
    size_t *range_at = NULL, *range_n = NULL;
    size_t(*range_regions)[PS_SPLAT_DIFFUSION_REGIONS] = NULL;
    if (diffuse && ranges &&
        (!(range_at = calloc(ranges, sizeof *range_at)) || !(range_n = calloc(ranges, sizeof *range_n)) ||
         !(range_regions = calloc(ranges, sizeof *range_regions)))) {
        free(R), free(range_at), free(range_n), free(range_regions);
        return ps_error_set(err, PS_ERR_NOMEM, "splats: out of memory for %zu photons", count);
    }
    run_jobs(ranges, p->threads, build_range_job, R);
    /* Compaction: each range's splats down to where the ranges before it
     * ended, in order; the diffusion order's places become final. */
    size_t at = first_splat;
    for (size_t k = 0; k < ranges; k++) {
        size_t from = first_splat + R[k].first, n = R[k].splats;
        if (from != at && n) {
            memmove(b->positions + 3 * (b->vertex_count + (at - first_splat) * per),
                    b->positions + 3 * (b->vertex_count + R[k].first * per), n * per * 3 * sizeof *b->positions);
            memmove(b->colors + 4 * (b->vertex_count + (at - first_splat) * per),
                    b->colors + 4 * (b->vertex_count + R[k].first * per), n * per * 4 * sizeof *b->colors);
            if (per == 3)
                memmove(b->texcoords + 2 * (b->vertex_count + (at - first_splat) * per),
                        b->texcoords + 2 * (b->vertex_count + R[k].first * per), n * per * 2 * sizeof *b->texcoords);
            if (p->objects)
                memmove(b->group + at, b->group + from, n);
            if (diffuse)
                memmove(b->order + (at - first_splat), b->order + (from - first_splat), n * sizeof *b->order);
        }
        if (diffuse) {
            range_at[k] = at - first_splat;
            range_n[k] = n;
            memcpy(range_regions[k], R[k].regions, sizeof R[k].regions);
        }
        b->wanted += R[k].wanted;
        b->lost += R[k].lost;
        at += n;
    }
    free(R);
    b->vertex_count += (at - first_splat) * per;
    b->splats = at;
    if (diffuse)
        diffuse_in_screen_order(b, p, first_splat, per, range_at, range_n, range_regions, ranges);
    free(range_at), free(range_n), free(range_regions);
    if (p->objects && !group_splats(b, first_splat, per))
        return ps_error_set(err, PS_ERR_NOMEM, "splats: out of memory grouping %zu photons", count);
    return PS_OK;
}

const char *ps_radius_schedule_name(ps_radius_schedule s)
{
    return (unsigned)s < PS_RADIUS_SCHEDULE_COUNT ? ps_radius_schedule_names[s] : "?";
}

void ps_splat_cost_learn(ps_splat_cost *c, const size_t splats[PS_MAP_COUNT], double seconds)
{
    double n = 0.0, known = 0.0, unknown = 0.0; /* splats; seconds of the known; splats of the others */
    int drew = 0, alone = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        if (splats[k] == 0)
            continue;
        drew++;
        alone = k;
        n += (double)splats[k];
        if (c->seconds[k] > 0.0)
            known += c->seconds[k] * (double)splats[k];
        else
            unknown += (double)splats[k];
    }
    if (drew == 0)
        return;
    seconds = fmax(seconds, PS_SPLAT_COST_MIN_SECONDS);
    if (drew == 1) {
        c->seconds[alone] = seconds / n;
        return;
    }
    /* Together: the known keep their ratio, scaled to the time. A map not
     * known yet takes what the known ones leave, but at least the mean: the
     * rest of a noisy time can be near 0, and too low a cost is what makes
     * a refresh late. */
    double each = unknown > 0.0 ? fmax((seconds - known) / unknown, seconds / n) : 0.0;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        if (splats[k] == 0)
            continue;
        if (unknown == 0.0)
            c->seconds[k] *= seconds / known;
        else if (!(c->seconds[k] > 0.0))
            c->seconds[k] = each;
    }
}

double ps_splat_cost_count(const ps_splat_cost *c, const bool drawing[PS_MAP_COUNT], double seconds)
{
    double sum = 0.0;
    int maps = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        if (!drawing[k])
            continue;
        if (!(c->seconds[k] > 0.0))
            return 0.0;
        sum += c->seconds[k];
        maps++;
    }
    return maps > 0 ? seconds * maps / (PS_MAP_COUNT * sum) : 0.0;
}

double ps_splat_radius_at(ps_radius_schedule s, double r0, uint64_t n0, uint64_t n, double alpha)
{
    if (s != PS_RADIUS_PROGRESSIVE || n0 == 0)
        return r0;
    if (n == 0)
        return r0 * PS_RADIUS_GROWTH_MAX;
    double f = pow((double)n / (double)n0, 0.5 * (alpha - 1.0));
    return r0 * fmin(f, PS_RADIUS_GROWTH_MAX);
}
