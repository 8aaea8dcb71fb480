/* tracer.h: the photon tracer (thesis 2.1, 4.1): emits photons from the
 * lights, follows them through the scene and fills the caustic and global maps.
 *
 * Photon i of a map is a pure function of (scene, seed, map, i) (thesis 4.1.3):
 * which light (and cone) emits it, where and in which direction come from the
 * Halton sequence at index i, Cranley-Patterson rotated by the seed; every
 * later choice comes from a PCG stream made from (seed, map, i). Tracing runs
 * on worker threads in fixed chunks whose results are joined in index order,
 * so the photon array is byte-identical for any thread count or batching.
 *
 * Departure from the thesis: it seeds a pseudo-random generator with the
 * photon number; we also use the quasi-random Halton point at that number for
 * emission (Keller's quasi-Monte Carlo photon map), which keeps the same
 * determinism and makes the maps visibly smoother for the same photon count. */
#ifndef PS_PHOTON_TRACER_H
#define PS_PHOTON_TRACER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "core/cancel.h"
#include "core/status.h"
#include "photon/photon.h"
#include "photon/world.h"

/* Paths longer than this many bounces end (their photons are counted as
 * truncated). Russian roulette ends almost every path long before. */
#define PS_PHOTON_MAX_BOUNCES 64
/* Photons are handed to threads in chunks of this many indices. It does not
 * change the result, only how finely work is shared. */
#define PS_PHOTON_CHUNK 1024
/* At most this many worker threads. */
#define PS_TRACER_MAX_THREADS 256

typedef struct ps_tracer_options {
    uint64_t seed;
    int threads;         /* 0: one per online core */
    bool caustic_cones;  /* aim caustic photons only at specular objects (default true) */
    bool first_hit_test; /* discard a cone's photon whose first hit is another object
                          * (default true; off only to show the double counting it prevents) */
    bool global_direct;  /* the global map also keeps each path's first diffuse hit, as
                          * Jensen's global map does (default false: the preview draws
                          * direct light itself). The reference renderer's precomputed
                          * irradiance for final gathering needs all of the light. */
    const ps_cancel_flag *cancel; /* NULL, or a flag that stops a trace between chunks
                                   * (PS_ERR_INTERRUPTED, the map left as it was) */
    uint64_t max_stored;          /* 0, or the most photons a map may hold: a trace that
                                   * would store more stops (PS_ERR_LIMIT, the map left as
                                   * it was) before the map grows past it */
} ps_tracer_options;

/* Bytes a stored photon takes in a map: the 20-byte record and the material
 * and object beside it. While a trace's chunks are joined they exist twice. */
#define PS_PHOTON_MAP_BYTES (sizeof(ps_photon) + sizeof(uint16_t) + sizeof(uint32_t))

/* Online cores, at least 1 and at most PS_TRACER_MAX_THREADS: the default
 * thread count. */
int ps_online_cores(void);

/* seed 0, all cores, cones and the first-hit test on. */
ps_tracer_options ps_tracer_default_options(void);

/* A stage the scene did not need, and why (contract: --stats "skipped"). */
#define PS_SKIP_REASON_MAX 200
typedef struct ps_skip {
    char pass[16];
    char reason[PS_SKIP_REASON_MAX];
} ps_skip;

/* What a trace did; counters add up over calls. */
typedef struct ps_trace_counters {
    uint64_t emitted;          /* photon indices traced (including those that carried nothing) */
    uint64_t stored;           /* photons written to the map */
    uint64_t rays;             /* rays cast against the scene */
    uint64_t escaped;          /* paths that left the scene */
    uint64_t absorbed;         /* paths ended by Russian roulette */
    uint64_t discarded;        /* caustic photons that were not caustic paths (first-hit test,
                                * or a diffuse first hit) */
    uint64_t truncated;        /* paths cut at PS_PHOTON_MAX_BOUNCES */
    uint64_t empty;            /* emitted samples that carried no power (outside a spot or behind a light) */
} ps_trace_counters;

/* The photons of one map, in index order, and beside each the material and
 * object of the surface it landed on (the splats need the BRDF there and clip
 * to the object's pixels; the 20-byte record has no room, and the kd-tree
 * does not need them: a query knows its own surface). */
typedef struct ps_photon_map {
    ps_map_kind kind;
    ps_photon *photons;
    uint16_t *materials;
    uint32_t *objects;
    size_t count, cap, mcap, ocap;
    ps_trace_counters counters;
} ps_photon_map;

void ps_photon_map_init(ps_photon_map *m, ps_map_kind kind);
void ps_photon_map_free(ps_photon_map *m); /* and reset to empty */
/* Appends src's photons (with their materials and objects) and counters to
 * dst; false, with dst unchanged, when out of memory. */
bool ps_photon_map_append(ps_photon_map *dst, const ps_photon_map *src);
/* Total power of all photons in the map. */
ps_rgb ps_photon_map_power(const ps_photon_map *m);

typedef struct ps_tracer ps_tracer;

/* Prepares the emission tables (lights, caustic cones) for world w, which
 * must outlive the tracer. opt may be NULL (defaults). */
ps_status ps_tracer_create(const ps_world *w, const ps_tracer_options *opt, ps_tracer **out, ps_error *err);
void ps_tracer_destroy(ps_tracer *t);

/* Whether the scene needs this map at all (see the skips for why not). */
bool ps_tracer_map_enabled(const ps_tracer *t, ps_map_kind kind);
/* The stages skipped, with reasons. */
const ps_skip *ps_tracer_skips(const ps_tracer *t, size_t *count);
/* Records one more skipped stage (a program's own reason, e.g. "0 photons
 * requested") so that all of them are reported together. */
ps_status ps_tracer_note_skip(ps_tracer *t, const char *pass, const char *reason);
/* Threads that ps_tracer_trace uses. */
int ps_tracer_threads(const ps_tracer *t);

/* Traces photons [first, first + count) of map `kind` and appends those stored
 * to m in index order. `total` is the number of photons the whole map will
 * have emitted (first + count <= total): photon powers are normalised so that
 * the total photons of each light and cone carry exactly its flux. Tracing the
 * same range in one call or in several gives the same bytes. A disabled map
 * traces nothing. */
ps_status ps_tracer_trace(ps_tracer *t, ps_map_kind kind, uint64_t first, uint64_t count, uint64_t total,
                          ps_photon_map *m, ps_error *err);

/* How many of photons [0, total) light l emits for map kind (all its cones
 * together): the tracer shares photons between lights in proportion to flux. */
uint64_t ps_tracer_light_photons(ps_tracer *t, ps_map_kind kind, uint32_t light, uint64_t total);

/* Writes every photon of m as one text line (contract, --dump-photons):
 * `map x y z r g b dx dy dz nx ny nz`, power in watts, d the direction of
 * travel (into the surface), n the surface normal on the side it arrived from. */
void ps_photon_map_write_text(FILE *f, const ps_photon_map *m);

#endif
