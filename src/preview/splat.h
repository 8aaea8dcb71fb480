/* splat.h: photons as splats (thesis 3.2.2, 4.2): the vertex arrays the GL
 * module draws, the kernel texture, and the 8-bit precision handling (5.1).
 * GL-free: everything here is tested without a context.
 *
 * A splat shows a photon's share of the radiance estimate (thesis eq. 13):
 *     colour = dPhi * f(w_p, w_view) * scale / (C pi r^2)
 * spread over a disc of radius r with the kernel's weights, C the mean weight
 * of the kernel as rasterised. `scale` is the exposure times N / n: photon
 * powers are normalised for the map's cap N, and n photons have been emitted
 * so far (progressive refinement shows the estimate of the n it has). The
 * BRDF uses the photon's own incoming direction and the direction to the eye,
 * so glossy surfaces show the Phong lobe (Stuerzlinger) and a moved camera
 * needs new colours, not new photons. */
#ifndef PS_PREVIEW_SPLAT_H
#define PS_PREVIEW_SPLAT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "photon/estimate.h"
#include "photon/photon.h"
#include "scene/camera.h"
#include "scene/scene.h"

typedef enum ps_splat_mode {
    PS_SPLAT_POINTS,    /* one glPoint a photon: the rough preview */
    PS_SPLAT_TRIANGLES, /* a kernel-textured triangle in the surface's plane: the accurate one */
    PS_SPLAT_SPRITES,   /* a kernel-textured point sprite sized by distance */
    PS_SPLAT_MODE_COUNT
} ps_splat_mode;

typedef enum ps_precision {
    PS_PRECISION_NONE,      /* colours as computed: an 8-bit buffer rounds faint ones away */
    PS_PRECISION_DIFFUSION, /* each photon's round-off carried into the next, per channel, in screen order */
    PS_PRECISION_COUNTER,   /* count what rounds away; the caller stops shooting past a threshold */
    PS_PRECISION_COUNT
} ps_precision;

/* The colour buffer splats are summed in: the thesis' 8 bits a channel, or
 * float (no round-off, so no precision handling). */
typedef enum ps_color_depth {
    PS_COLOR_DEPTH_8,
    PS_COLOR_DEPTH_FLOAT,
    PS_COLOR_DEPTH_COUNT
} ps_color_depth;

/* Names in enum order, NULL-terminated (options, scripts, stats), and the
 * name of one value ("?" out of range). */
extern const char *const ps_splat_mode_names[PS_SPLAT_MODE_COUNT + 1];   /* points, triangles, sprites */
extern const char *const ps_precision_names[PS_PRECISION_COUNT + 1];     /* none, diffusion, counter */
extern const char *const ps_color_depth_names[PS_COLOR_DEPTH_COUNT + 1]; /* 8, float */
const char *ps_splat_mode_name(ps_splat_mode m);
const char *ps_precision_name(ps_precision p);
const char *ps_color_depth_name(ps_color_depth d);

/* The kernel as an alpha texture: size x size texels over the square
 * [-extent, extent]^2 around the unit disc, extent = size / (size - 2), so
 * that the outermost texels lie wholly outside the disc and are 0: GL clamps
 * texture coordinates beyond the square to those edge texels, and the
 * triangle's corners reach well beyond. C is measured from the stored 8-bit
 * texels, not the formula, so that the texture GL draws is what is
 * normalised. */
typedef struct ps_kernel_texture {
    int size;
    double extent; /* half the square's side, in units of the radius */
    uint8_t *alpha;
    double mean;   /* C */
    bool halftone; /* texels 0 or 255 only, to be sampled nearest (below) */
} ps_kernel_texture;

#define PS_KERNEL_TEXTURE_SIZE 64

ps_status ps_kernel_texture_make(ps_kernel k, int size, ps_kernel_texture *out, ps_error *err);

/* The kernel as a halftone for 8-bit colour buffers (thesis departure, 5.1).
 * With a smooth alpha, GL adds colour * alpha to the buffer and rounds each
 * fragment to a whole code, so a kernel's faint tails round away however
 * exact the colour (error diffusion keeps the colour a whole number of codes,
 * not its product with alpha): measured 9 % (the scene's photons) to 25 %
 * (5 million) too dark. A halftone's texels are 0 or 255, each on with the
 * probability the kernel's weight gives it (a fixed hash of the texel, a
 * threshold in [0, 1)), and sampled nearest, so every fragment adds the
 * photon's colour exactly or nothing: the carry of error diffusion stays
 * exact, and what the kernel spreads is kept on average. Its price is a
 * dither: a pixel's sum is made of whole codes. C is measured from the
 * binary texels as for the smooth texture. PS_KERNEL_HALFTONE_SIZE texels a
 * side keep the dither finer than a large splat's pixels. */
#define PS_KERNEL_HALFTONE_SIZE 256
ps_status ps_kernel_texture_make_halftone(ps_kernel k, int size, ps_kernel_texture *out, ps_error *err);
void ps_kernel_texture_free(ps_kernel_texture *t);

typedef struct ps_splat_params {
    ps_splat_mode mode;
    double radius;      /* r, scene units (> 0) */
    double kernel_mean;   /* C of the kernel texture (triangles and sprites) */
    double kernel_extent; /* its half side in radii (texture coordinates of triangles) */
    double scale;       /* exposure * N / n */
    double point_size;  /* points: their side in pixels */
    ps_precision precision;
    int levels;         /* the colour buffer's steps per unit: 255 for 8 bits, 0 for float */
    const ps_material *materials; /* the scene's, indexed by the photons' material ids */
    /* The photons' object ids, or NULL. Given, the splats come out grouped by
     * stencil value (ps_splat_stencil) so that GL can clip each object's
     * splats to that object's pixels: the cure for photon haze (thesis 5.2),
     * where a flat splat on a curved or cornered surface would show on
     * whatever lies behind its edge. */
    const uint32_t *objects;
    ps_camera_frame cam;
    /* Lay the splats on their surfaces, not lifted toward the eye: drawn
     * into a surface's own texture (preview/bake.h), where cam only chooses
     * the side and the lift would shift them along it. */
    bool surface;
    int threads;        /* building threads; 0: one a core (the same bytes either way) */
} ps_splat_params;

/* Stencil values 1..255 stand for objects (0 is "no object"); with more than
 * 255 objects some share a value, and clipping then only keeps a splat to
 * either of them. */
#define PS_SPLAT_GROUPS 256
static inline unsigned ps_splat_stencil(uint32_t object) { return object % (PS_SPLAT_GROUPS - 1) + 1; }

/* Points: at grazing view the footprint 1 / cos grows without bound; past
 * this cosine it is held (a bias only where a surface is seen edge-on). */
#define PS_SPLAT_MIN_COS 0.05
/* Splats move this fraction of their distance toward the eye so that the
 * depth test against their own surface never flickers (thesis 4.2). */
#define PS_SPLAT_EYE_OFFSET 1e-3
/* A sprite faces the eye, so on a surface seen at angle theta half of it
 * would lie behind the surface; it moves r tan(theta) toward the eye instead,
 * tan held at this much (beyond, the surface is nearly edge-on). */
#define PS_SPLAT_SPRITE_MAX_TAN 10.0

/* Error diffusion carries round-off along a Z-order curve over the screen,
 * in 2^PS_SPLAT_DIFFUSION_REGION_BITS tiles (16 x 16), each with a carry of
 * its own (splat.c): enough that the cores share even a caustic that covers
 * a few tiles. */
#define PS_SPLAT_DIFFUSION_REGION_BITS 8
#define PS_SPLAT_DIFFUSION_REGIONS (1 << PS_SPLAT_DIFFUSION_REGION_BITS)

/* Vertex arrays for glDrawArrays, and the precision bookkeeping of the photons
 * that went in. The carry persists across batches of the same map (clear it
 * when the map restarts); wanted/lost add up until cleared. */
typedef struct ps_splat_batch {
    /* The vertex arrays from 4 MiB up in 2 MiB pages (core/memory.h), for
     * batches that grow with the maps: a whole refresh's, every photon drawn
     * again, where a refresh with more photons than any before wrote its
     * splats into pages never touched. Set after ps_splat_batch_init, before
     * the first build. */
    bool large_pages;
    size_t vertex_count; /* 3 a photon for triangles, 1 otherwise */
    float *positions;    /* xyz */
    float *colors;       /* rgba, a = 1 */
    float *texcoords;    /* uv (triangles only) */
    size_t cap_pos, cap_col, cap_tex;
    size_t splats;       /* photons drawn (those facing the eye) */
    /* With objects given: vertices [group_first[g], group_first[g + 1]) carry
     * stencil value g (valid for the splats of the last build call). */
    bool grouped;
    size_t group_first[PS_SPLAT_GROUPS + 1];
    uint8_t *group;      /* scratch: each splat's stencil value */
    size_t cap_group;
    uint64_t *order, *order_tmp; /* scratch: the diffusion's screen order (splat.c) */
    size_t cap_order, cap_order_tmp;
    ps_vec3 *normals;    /* scratch: every photon normal code decoded, made once (splat.c) */
    double carry[PS_SPLAT_DIFFUSION_REGIONS][3]; /* diffusion: each tile's round-off not yet added */
    double wanted, lost; /* counter: colour asked for, and what rounding took (summed over channels) */
} ps_splat_batch;

void ps_splat_batch_init(ps_splat_batch *b);
void ps_splat_batch_free(ps_splat_batch *b);
/* Empties the arrays; keeps carry and the counters. */
void ps_splat_batch_clear(ps_splat_batch *b);
/* Diffusion: forgets the round-off carried (a map that starts over). */
void ps_splat_batch_reset_carry(ps_splat_batch *b);
/* Diffusion: the round-off carried in channel ch, summed over the tiles
 * (what the codes sent so far fall short of what was asked). */
double ps_splat_batch_carry(const ps_splat_batch *b, int ch);

/* Appends the splats of photons[0, count) (materials beside them). Photons on
 * a surface facing away from the eye are skipped: two-sided surfaces keep
 * photons on both faces at the same depth, and only the visible face's may
 * show. */
ps_status ps_splat_build(const ps_photon *photons, const uint16_t *materials, size_t count, const ps_splat_params *p,
                         ps_splat_batch *b, ps_error *err);

/* The splat radius as photons accumulate.
 *
 * Thesis departure: the thesis splats every photon with one fixed radius, so
 * the preview's error falls with the noise but stops at the kernel's bias
 * (a blur of width r). Progressive photon mapping (Hachisuka et al. 2008)
 * shrinks the radius as photons arrive, r^2 proportional to n^(alpha - 1)
 * with 0 < alpha < 1: the bias (ratio r^2) and the noise (ratio 1 / (n r^2))
 * both go to zero. Here the given radius r0 holds at n0 photons (the scene's
 * photon count, for which it was chosen): fewer photons get a larger radius,
 * smoother at first, more a smaller one. The growth is capped so that the
 * very first frames do not flood the fill rate with huge splats. */
typedef enum ps_radius_schedule {
    PS_RADIUS_FIXED,       /* r0 whatever n: the thesis */
    PS_RADIUS_PROGRESSIVE, /* r0 (n / n0)^((alpha - 1) / 2) */
    PS_RADIUS_SCHEDULE_COUNT
} ps_radius_schedule;

/* Hachisuka et al.'s alpha: keeps 2/3 of the photons' density gain for noise. */
#define PS_RADIUS_ALPHA_DEFAULT (2.0 / 3.0)
/* The most the progressive radius may exceed r0 (few photons, early frames). */
#define PS_RADIUS_GROWTH_MAX 4.0

extern const char *const ps_radius_schedule_names[PS_RADIUS_SCHEDULE_COUNT + 1]; /* fixed, progressive */
const char *ps_radius_schedule_name(ps_radius_schedule s);
/* The radius for n photons emitted (n0 > 0 the reference count, alpha in
 * (0, 1]); n = 0 gives the largest, r0 * PS_RADIUS_GROWTH_MAX. */
double ps_splat_radius_at(ps_radius_schedule s, double r0, uint64_t n0, uint64_t n, double alpha);

/* A refresh's time is taken as at least this (a clock's tick: the rate
 * from a refresh timed at 0 would be infinite). */
#define PS_SPLAT_COST_MIN_SECONDS 1e-6

/* What a splat of each map costs to build and draw, for the incremental
 * layers' budget (session.h): seconds a splat, learned from refreshes whose
 * splats of each map and time are known. The maps' splats differ: the
 * default box's global splats (radius 0.1) cover 25 times a caustic one's
 * pixels. One rate for all of them, learned from a refresh whose new photons
 * were all caustic (the global map's next batch not yet traced), was 2-8
 * times what the refreshes drawing both achieved: the area box's float
 * 0.1 s checkpoint frame then drew 2.4-3.1*10^4 splats where 7*10^3 were
 * meant, took 0.042-0.066 s and came at 0.13-0.15 s. */
typedef struct ps_splat_cost {
    double seconds[PS_MAP_COUNT]; /* a splat of map k; 0: not known yet */
} ps_splat_cost;

/* After a refresh that drew splats[k] of map k in `seconds`: a map drawn
 * alone takes the whole time. Maps drawn together keep the ratio their
 * costs had, scaled to the time; where one is not known yet, it takes the
 * time the others' known costs leave, at least the refresh's mean, and they
 * keep theirs. Nothing drawn: nothing learned. */
void ps_splat_cost_learn(ps_splat_cost *c, const size_t splats[PS_MAP_COUNT], double seconds);

/* The splats a map each refresh may draw within `seconds`, for the maps
 * `drawing` (those with photons still to draw or to bake): the count that
 * PS_MAP_COUNT maps at their mean cost draw in that time. With both maps
 * drawing, their splats together take it; with one (the other done, not
 * shown, or the illumination maps', which have their own share), half of it,
 * as a single rate gave. 0 when a map drawing has no known cost, or none is
 * drawing: the budget stays as it was. */
double ps_splat_cost_count(const ps_splat_cost *c, const bool drawing[PS_MAP_COUNT], double seconds);

/* The thesis' numerically stable basis (Fig. 11): X perpendicular to unit n
 * from n's two larger components (the smallest is zeroed), Y = n x X so that
 * (X, Y, n) is right-handed (the figure's X x N is its mirror image); both unit. */
void ps_splat_basis(ps_vec3 n, ps_vec3 *x, ps_vec3 *y);

#endif
