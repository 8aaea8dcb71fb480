/* render.h: the reference renderer's image: a Monte Carlo ray tracer over
 * the photon maps (thesis 2.2, eq. 6), the truth the preview is judged by.
 *
 * At the first diffuse or glossy surface an eye ray meets, the radiance is
 * split as in the thesis: direct light (shadow rays to every light; point and
 * spot exact, area lights sampled), caustics (the caustic map's radiance
 * estimate), and indirect diffuse light (final gathering on precomputed
 * irradiance, Christensen 1999, or the global map's estimate directly), its
 * diffuse part. Eye rays that meet mirrors and glass first are followed
 * (Fresnel) and all they then see is the `specular` term, and so is a glossy
 * surface's lobe reflecting the other surfaces (the preview's specular layer
 * draws it from the cube maps). The four terms partition the image:
 * all = direct + caustic + indirect + specular. An irradiance cache with
 * gradients (irrcache.h) serves the diffuse indirect light wherever a path
 * meets a diffuse surface, and a pixel filter (Mitchell, Gaussian or box)
 * makes pixels from the eye samples. */
#ifndef PS_RENDER_RENDER_H
#define PS_RENDER_RENDER_H

#include <stdint.h>

#include "core/cancel.h"
#include "core/status.h"
#include "image/image.h"
#include "photon/emit.h"
#include "photon/estimate.h"
#include "photon/kdtree.h"
#include "photon/world.h"
#include "render/irrcache.h"

typedef enum ps_component {
    PS_COMPONENT_ALL,
    PS_COMPONENT_DIRECT,   /* lights seen by the first diffuse/glossy surface (and emitters seen directly) */
    PS_COMPONENT_CAUSTIC,  /* light through mirrors and glass onto that surface */
    PS_COMPONENT_INDIRECT, /* light from other surfaces reflected by its diffuse part */
    /* Everything seen through mirrors and glass, and, at a glossy surface
     * seen directly, its lobe's reflection of the other surfaces (the
     * Phong-lobe gather, or the global photons' glossy BRDF): what the
     * preview's specular layer shows. The lobe's caustic stays `caustic`,
     * its highlights of the lights `direct`. */
    PS_COMPONENT_SPECULAR,
    PS_COMPONENT_COUNT
} ps_component;

const char *ps_component_name(ps_component c);

/* How eye samples make pixels: the box (each pixel the mean of its own
 * samples), or a wider filter as in pbrt (render.c). */
typedef enum ps_filter { PS_FILTER_BOX, PS_FILTER_MITCHELL, PS_FILTER_GAUSSIAN, PS_FILTER_COUNT } ps_filter;

const char *ps_filter_name(ps_filter f);
/* The filter's 1-D profile at dx pixels from a pixel's centre (separable:
 * a sample's weight is f(dx) f(dy)); 0 beyond its radius. */
double ps_filter_eval(ps_filter f, double dx);

/* Eye paths end after this many mirror/glass bounces. */
#define PS_RENDER_MAX_SPECULAR 16
/* Through the first this many glass surfaces an eye ray follows both the
 * reflected and the refracted ray (weighted by Fresnel); deeper, one of them
 * chosen with those probabilities. Splitting where the weight is largest
 * takes most of the noise out of glass for little cost. */
#define PS_RENDER_SPLIT_DEPTH 2
/* Cache records count where |x - x_i| / R_i + sqrt(1 - n.n_i) is below this
 * (Ward's a; the smaller, the more records). */
#define PS_RENDER_CACHE_ERROR 0.5
/* A record's validity radius (the harmonic mean distance of what its rays
 * met) is clamped to between MIN_PX times the finest grid's spacing and
 * MAX_PX pixel footprints there: not so small that corners fill with records
 * or that records leave holes between the grid's positions (it reaches
 * a MIN_PX = 1.25 spacings), not so large that one record's noise spreads
 * over a wall. */
#define PS_RENDER_CACHE_MIN_PX 2.5
#define PS_RENDER_CACHE_MAX_PX 48.0
/* No record is made where its nearest hit is below this share of that floor
 * (it stands on an edge; render.c). */
#define PS_RENDER_CACHE_EDGE 0.05
/* ... and, before that clamp, to this many times the nearest hit of its rays
 * (with a = 0.5, a record then reaches no further than the nearest object). */
#define PS_RENDER_CACHE_NEAREST 2.0
/* A position asks for a record unless one has eps_i below this share of a:
 * records overlap, so that every point between the positions is reached,
 * and each point averages several records' noise. */
#define PS_RENDER_CACHE_PLACE 0.5
/* The coarsest grid of positions asking for records, in pixels. */
#define PS_RENDER_CACHE_COARSE 64
/* Mixed into the seed for the records' random numbers. */
#define PS_RENDER_CACHE_KEY 0x6361636865ULL
/* Final gather rays that meet mirrors or glass follow at most this many bounces. */
#define PS_RENDER_GATHER_SPECULAR 4

typedef struct ps_render_maps {
    const ps_kdtree *caustic;    /* NULL: no caustic term */
    const ps_kdtree *global;     /* the global map, for gather == 0 */
    const ps_kdtree *full;       /* the global map with direct hits too, for gather > 0 */
    const ps_kdtree *irradiance; /* irradiance precomputed at the full map's photons */
} ps_render_maps;

typedef struct ps_render_options ps_render_options;

/* A render shared with other processes (a distributed run: src/dist supplies
 * these; NULL in one process). The image is the same bytes as one process
 * makes, because every piece is made by the same code from the same inputs
 * and joined in the same order:
 * - the irradiance cache: each chunk's positions are split, position i of a
 *   chunk to process (i - begin) mod parts == part; cache_exchange then gives
 *   every process every process's records of the chunk (ok[s] marks a record
 *   in slot s), and each adds them in slot order as one process does;
 * - the tiles: handed out by next_tile; a finished one's buffer (tile_floats
 *   floats) goes to tile_done; where `assemble`, after tiles_end, tile_data
 *   gives the buffer of every tile made elsewhere (NULL: made here), and only
 *   there is the image whole on return.
 * Every hook but next_tile and tile_done is called from the render's calling
 * thread; those two from any worker thread, so they must be thread-safe. */
typedef struct ps_render_share {
    void *user;
    int part, parts;
    bool assemble;
    /* After this process's positions of a chunk; `cancelled`: this process
     * was stopped. PS_ERR_INTERRUPTED (or another process's error) ends the
     * render on every process. */
    ps_status (*cache_exchange)(void *user, ps_irr_record *chunk, bool *ok, size_t slots, bool cancelled,
                                ps_error *err);
    /* Before the tiles; progress and cancel come from o. */
    ps_status (*tiles_begin)(void *user, const ps_render_options *o, int tiles, size_t tile_floats, ps_error *err);
    int (*next_tile)(void *user); /* -1: none left for this process */
    void (*tile_done)(void *user, int tile, const float *data);
    /* After this process's workers: `complete` when every tile it took is
     * done; *rays in: this process's rays, out: every process's. */
    ps_status (*tiles_end)(void *user, bool complete, uint64_t *rays, ps_error *err);
    const float *(*tile_data)(void *user, int tile);
} ps_render_share;

struct ps_render_options {
    int width, height;
    int spp;                 /* eye samples per pixel (stratified) */
    int light_samples;       /* shadow rays per area light per eye sample */
    int gather;              /* final gather rays per indirect estimate; 0: the global map directly */
    uint64_t seed;
    int threads;             /* >= 1 */
    ps_component component;
    ps_filter filter;
    ps_estimate_options caustic, global;
    double irradiance_radius; /* how far a gather ray's hit may be from a precomputed irradiance */
    /* An irradiance cache (Ward 1988, with Ward & Heckbert's gradients;
     * src/render/irrcache.h) for the diffuse indirect term wherever an eye
     * path meets a diffuse surface, directly or through mirrors and glass:
     * records of cache_rays gather rays, made before the image where eye
     * paths through grids of pixel positions, PS_RENDER_CACHE_COARSE apart
     * down to cache_spacing (0: no cache), find no record reaching; in a
     * fixed order, so it does not depend on the thread count. Where no record
     * reaches at render time, gathering as usual. */
    int cache_spacing;
    int cache_rays;
    /* Instead of radiance, the irradiance (W/m^2 per channel) arriving at the
     * surface each eye ray meets first, whatever its material: that surface
     * is taken as white Lambertian (albedo 1, so E = pi L) and emitters seen
     * directly are looked through. `component` selects its terms as for
     * radiance (specular: none). Lux is core/photometry.h's ps_photometric of it. */
    bool illuminance;
    /* Called now and then from one thread with the fraction done (may be NULL). */
    void (*progress)(void *user, double fraction);
    void *progress_user;
    /* NULL, or a flag that stops the render between tiles: PS_ERR_INTERRUPTED,
     * *out destroyed, stats->fraction the part finished. */
    const ps_cancel_flag *cancel;
    /* NULL, or the other processes this render is shared with (above). */
    const ps_render_share *share;
};

typedef struct ps_render_stats {
    uint64_t rays;
    size_t cache_records;
    double cache_seconds; /* making the cache, part of seconds */
    double seconds;
    double fraction; /* of the tiles finished: 1 unless interrupted */
} ps_render_stats;

/* Quality presets: eye samples, gather rays, the cache's finest grid and
 * rays a record, photons as a multiple of the scene's, and the pixel filter,
 * set together (times and errors measured in docs/reference-renderer.md). */
typedef enum ps_quality { PS_QUALITY_DRAFT, PS_QUALITY_DEFAULT, PS_QUALITY_FINAL, PS_QUALITY_COUNT } ps_quality;

typedef struct ps_render_preset {
    int spp, gather, cache_spacing, cache_rays;
    double photon_factor;
    ps_filter filter;
} ps_render_preset;

const char *ps_quality_name(ps_quality q);
ps_render_preset ps_render_quality(ps_quality q);

/* Renders the image into out (created here; the caller destroys it). Pixel
 * (x, y) depends only on (scene, maps, options, seed, x, y): the image is the
 * same for any thread count. */
ps_status ps_render(const ps_world *w, const ps_light_sampler *ls, const ps_render_maps *maps,
                    const ps_render_options *o, ps_image *out, ps_render_stats *stats, ps_error *err);

#endif
