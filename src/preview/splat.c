/* splat.c: kernel textures and the splat vertex arrays. */
#include "preview/splat.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/array.h"
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
    free(b->positions);
    free(b->colors);
    free(b->texcoords);
    free(b->group);
    free(b->order);
    free(b->order_tmp);
    memset(b, 0, sizeof *b);
}

void ps_splat_batch_clear(ps_splat_batch *b)
{
    b->vertex_count = 0;
    b->splats = 0;
    b->grouped = false;
}

/* Reorders the splats [first, splats) by stencil value (a stable counting
 * sort, so error diffusion's order within a group is kept) and records where
 * each group starts. */
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
    float *pos = malloc(n * per * 3 * sizeof *pos), *col = malloc(n * per * 4 * sizeof *col);
    float *tex = per == 3 ? malloc(n * per * 2 * sizeof *tex) : NULL;
    if (!pos || !col || (per == 3 && !tex)) {
        free(pos), free(col), free(tex);
        return false;
    }
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
    free(pos), free(col), free(tex);
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

/* The 8-bit handling of one colour channel: what is sent to GL. */
static double quantise(ps_splat_batch *b, const ps_splat_params *p, int ch, double c)
{
    if (p->levels <= 0 || p->precision == PS_PRECISION_NONE)
        return c;
    double L = p->levels;
    if (p->precision == PS_PRECISION_DIFFUSION) {
        double want = c + b->carry[ch];
        double q = to_steps(want, L);
        b->carry[ch] = want - q;
        return q;
    }
    /* Counter: send as is, and count what the buffer will round away. */
    b->wanted += c;
    b->lost += c - to_steps(c, L);
    return c;
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

static uint32_t z_order(double x, double y)
{
    uint32_t ix = x > 0.0 ? (x < 65535.0 ? (uint32_t)x : 65535u) : 0u;
    uint32_t iy = y > 0.0 ? (y < 65535.0 ? (uint32_t)y : 65535u) : 0u;
    return spread_bits(ix) | spread_bits(iy) << 1;
}

/* Error diffusion in screen order. Thesis departure: the thesis carries each
 * photon's round-off into the next photon in index order, which keeps the
 * sum but picks the faint photons that get a code at random over the
 * screen, a noise of its own. Carried along a Z-order curve over the splats'
 * pixels instead (as Riemersma's dither carries along a Hilbert curve), the
 * photons that carry a code lie evenly over the screen, and the round-off of
 * any region of it is under one code. The order is a stable sort of the
 * batch's splats by their keys (LSD radix on the key, the splat's place as
 * the tie-break), so the same photons always give the same picture. */
static void diffuse_in_screen_order(ps_splat_batch *b, const ps_splat_params *p, size_t first_splat, size_t per)
{
    size_t n = b->splats - first_splat;
    uint64_t *a = b->order, *t = b->order_tmp;
    for (int pass = 0; pass < 4; pass++) { /* the key is the upper 32 bits, 8 at a time */
        size_t count[257] = {0};
        int shift = 32 + 8 * pass;
        for (size_t i = 0; i < n; i++)
            count[((a[i] >> shift) & 0xff) + 1]++;
        for (int d = 0; d < 256; d++)
            count[d + 1] += count[d];
        for (size_t i = 0; i < n; i++)
            t[count[(a[i] >> shift) & 0xff]++] = a[i];
        uint64_t *swap = a;
        a = t;
        t = swap;
    }
    /* Four passes: the sorted keys are back in b->order. */
    size_t v0 = b->vertex_count - n * per;
    for (size_t i = 0; i < n; i++) {
        size_t v = v0 + (size_t)(a[i] & 0xffffffffu) * per;
        float *rgba = &b->colors[4 * v];
        for (int ch = 0; ch < 3; ch++)
            rgba[ch] = (float)quantise(b, p, ch, rgba[ch]);
        for (size_t k = 1; k < per; k++)
            memcpy(&b->colors[4 * (v + k)], rgba, 4 * sizeof *rgba);
    }
}

ps_status ps_splat_build(const ps_photon *photons, const uint16_t *materials, size_t count, const ps_splat_params *p,
                         ps_splat_batch *b, ps_error *err)
{
    size_t per = p->mode == PS_SPLAT_TRIANGLES ? 3 : 1;
    if (count > (SIZE_MAX / 4 - b->vertex_count) / per ||
        !PS_RESERVE(b->positions, b->cap_pos, 3 * (b->vertex_count + per * count)) ||
        !PS_RESERVE(b->colors, b->cap_col, 4 * (b->vertex_count + per * count)) ||
        (per == 3 && !PS_RESERVE(b->texcoords, b->cap_tex, 2 * (b->vertex_count + per * count))) ||
        (p->objects && !PS_RESERVE(b->group, b->cap_group, b->splats + count)))
        return ps_error_set(err, PS_ERR_NOMEM, "splats: out of memory for %zu photons", count);
    size_t first_splat = b->splats;
    const ps_camera_frame *cam = &p->cam;
    double r = p->radius;
    double disc = 1.0 / (p->kernel_mean * PS_PI * r * r);
    /* Whether the 8-bit handling does anything (hoisted: the loop is hot). */
    bool rounds = p->levels > 0 && p->precision != PS_PRECISION_NONE;
    bool diffuse = rounds && p->precision == PS_PRECISION_DIFFUSION;
    if (diffuse && (!PS_RESERVE(b->order, b->cap_order, count) || !PS_RESERVE(b->order_tmp, b->cap_order_tmp, count)))
        return ps_error_set(err, PS_ERR_NOMEM, "splats: out of memory for %zu photons", count);
    /* World size of one pixel at unit depth along the view axis. */
    double pixel = 2.0 * cam->tan_half_fov / cam->height;
    for (size_t i = 0; i < count; i++) {
        const ps_photon *ph = &photons[i];
        ps_vec3 pos = ps_photon_position(ph), n = ps_photon_normal(ph);
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
        const ps_material *mat = &p->materials[materials[i]];
        ps_rgb f = mat->type == PS_MAT_DIFFUSE ? ps_rgb_scale(mat->albedo, PS_INV_PI)
                                               : ps_bsdf_eval(mat, n, ps_photon_dir(ph), wo);
        ps_rgb c = ps_rgb_scale(ps_rgb_mul(f, ps_photon_power(ph)), p->scale);
        if (p->mode == PS_SPLAT_POINTS) {
            /* An unbiased one-pixel estimate: the power over the surface area
             * the point covers. Its square of (side * pixel) at unit depth
             * subtends side^2 pixel^2 cos^3(a) at angle a off the axis; at
             * distance dist = depth / cos(a) that is side^2 pixel^2 depth^2
             * cos(a) across the ray, and 1 / cos_v more along the surface. */
            double side = p->point_size * pixel * depth;
            double area = side * side * (depth / dist) / (cos_v > PS_SPLAT_MIN_COS ? cos_v : PS_SPLAT_MIN_COS);
            c = ps_rgb_scale(c, 1.0 / area);
        } else {
            c = ps_rgb_scale(c, disc);
            /* A sprite faces the eye: its disc covers 1 / cos more pixels than
             * the surface's disc would, so it carries cos of the colour. */
            if (p->mode == PS_SPLAT_SPRITES)
                c = ps_rgb_scale(c, cos_v);
        }
        double lift = PS_SPLAT_EYE_OFFSET * dist;
        if (p->mode == PS_SPLAT_SPRITES) {
            double tan_v = sqrt(fmax(0.0, 1.0 - cos_v * cos_v)) / cos_v;
            lift = fmax(lift, r * fmin(tan_v, PS_SPLAT_SPRITE_MAX_TAN));
        }
        ps_vec3 centre = ps_v3_madd(pos, wo, lift);
        /* GL sizes a sprite by its own distance: lifted, it grows by
         * dist / (dist - lift) a side, so its colour shrinks to match. */
        if (p->mode == PS_SPLAT_SPRITES)
            c = ps_rgb_scale(c, ((dist - lift) / dist) * ((dist - lift) / dist));
        float rgba[4] = {(float)c.r, (float)c.g, (float)c.b, 1.0f};
        if (rounds && !diffuse) {
            rgba[0] = (float)quantise(b, p, 0, c.r);
            rgba[1] = (float)quantise(b, p, 1, c.g);
            rgba[2] = (float)quantise(b, p, 2, c.b);
        } else if (diffuse) {
            /* Rounded below, in screen order; the exact colour till then. */
            double px = 0.0, py = 0.0;
            (void)ps_camera_project(cam, centre, &px, &py);
            b->order[b->splats - first_splat] =
                (uint64_t)z_order(px, py) << 32 | (uint64_t)(b->splats - first_splat);
        }
        size_t v = b->vertex_count;
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
            b->group[b->splats] = (uint8_t)ps_splat_stencil(p->objects[i]);
        b->vertex_count += per;
        b->splats++;
    }
    if (diffuse)
        diffuse_in_screen_order(b, p, first_splat, per);
    if (p->objects && !group_splats(b, first_splat, per))
        return ps_error_set(err, PS_ERR_NOMEM, "splats: out of memory grouping %zu photons", count);
    return PS_OK;
}

const char *ps_radius_schedule_name(ps_radius_schedule s)
{
    return (unsigned)s < PS_RADIUS_SCHEDULE_COUNT ? ps_radius_schedule_names[s] : "?";
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
