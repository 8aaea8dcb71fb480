/* tracer.h: the photon tracer (thesis 2.1, 4.1): emits photons from the
 * lights, follows them through the scene and fills the caustic and global maps.
 *
 * Photon i of a map is a pure function of (scene, seed, map, i) (thesis 4.1.3):
 * which light (and caustic cone: its stratum) emits it comes from the Halton
 * sequence at index i, Cranley-Patterson rotated by the seed. Where and in
 * which direction come from the Halton point at its rank j among the indices
 * of its stratum, rotated by the stratum's identity (light, target) and the
 * seed; every later choice from a PCG stream made from (seed, map, stratum
 * identity, j). So photon (stratum, j) does not change when another
 * stratum's share changes, only where it falls in the map (issue 18). Its
 * power is its light-independent throughput T, rounded to float, times the
 * light's power over the stratum's photon count, multiplied in last, and
 * rounded to RGBE with a dither from (stratum, j): a power edit is an exact
 * rescale (ps_tracer_repower). Tracing runs
 * on worker threads in fixed chunks whose results are joined in index order,
 * so the photon array is byte-identical for any thread count or batching.
 *
 * Departure from the thesis: it seeds a pseudo-random generator with the
 * photon number; we also use a quasi-random Halton point for emission
 * (Keller's quasi-Monte Carlo photon map), which keeps the same determinism
 * and makes the maps visibly smoother for the same photon count. Departure
 * from Keller: one Halton sequence per stratum, at the photon's rank in it,
 * not one for the whole map at the photon's index (so that an edit of one
 * stratum's share leaves the others' photons as they were; docs/repair.md). */
#ifndef PS_PHOTON_TRACER_H
#define PS_PHOTON_TRACER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "core/cancel.h"
#include "core/status.h"
#include "photon/photon.h"
#include "photon/path_record.h"
#include "photon/photon_map.h"
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
    bool first_hit_test; /* discard a caustic cone's photon whose first hit is another object
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
    /* Path records (photon/path_record.h) for the preview's selective repair:
     * when records is set, each traced range also gives every emitted photon's
     * path, its vertices quantised in record_box (which must hold the scene). */
    bool records;
    ps_aabb record_box;
} ps_tracer_options;

/* Online cores, at least 1 and at most PS_TRACER_MAX_THREADS: the default
 * thread count. */
int ps_online_cores(void);

/* seed 0, all cores, caustic cones and the first-hit test on. */
ps_tracer_options ps_tracer_default_options(void);

/* A stage the scene did not need, and why (contract: --stats "skipped"). */
#define PS_SKIP_REASON_MAX 200
typedef struct ps_skip {
    char pass[16];
    char reason[PS_SKIP_REASON_MAX];
} ps_skip;

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
/* Sets them (0: one per online core), between calls only: the photons are
 * the same for any count, only sooner or later. */
void ps_tracer_set_threads(ps_tracer *t, int threads);

/* Traces photons [first, first + count) of map `kind` and appends those stored
 * to m in index order. `total` is the number of photons the whole map will
 * have emitted (first + count <= total): photon powers are normalised so that
 * the total photons of each light and caustic cone carry exactly its flux. Tracing the
 * same range in one call or in several gives the same bytes. A disabled map
 * traces nothing. */
ps_status ps_tracer_trace(ps_tracer *t, ps_map_kind kind, uint64_t first, uint64_t count, uint64_t total,
                          ps_photon_map *m, ps_error *err);

/* ps_tracer_trace in two steps, for a caller whose map is read by another
 * thread (the preview's feed): trace outside its lock, join under it. Each
 * photon is copied once, from the chunk that traced it into the map; while
 * they are joined, the chunks and the map exist at once (PS_PHOTON_PLAN_BYTES
 * counts each entry twice for this).
 *
 * ps_tracer_trace_range traces the range as ps_tracer_trace does into a map
 * that already holds `stored` photons (the max_stored check counts them), and
 * on PS_OK gives the result in *out (NULL when nothing was traced: a disabled
 * map or count 0). On an error nothing is kept. */
typedef struct ps_traced ps_traced;
ps_status ps_tracer_trace_range(ps_tracer *t, ps_map_kind kind, uint64_t first, uint64_t count, uint64_t total,
                                size_t stored, ps_traced **out, ps_error *err);
/* Photons the traced range stored. */
size_t ps_traced_count(const ps_traced *r);
/* Appends the traced photons, in index order, and their counters to m (PS_OK
 * with nothing to do when r is NULL); PS_ERR_NOMEM, with m unchanged, when m
 * cannot grow. */
ps_status ps_traced_join(ps_traced *r, ps_photon_map *m, ps_error *err);
/* Frees the chunks; accepts NULL. */
void ps_traced_destroy(ps_traced *r);

/* ps_tracer_trace_range for the n photon indices idx (ascending, each below
 * total) instead of a range: the photons a selective repair retraces. */
ps_status ps_tracer_trace_list(ps_tracer *t, ps_map_kind kind, const uint64_t *idx, size_t n, uint64_t total,
                               size_t stored, ps_traced **out, ps_error *err);

/* With ps_tracer_options.records: the traced photons' path records, in index
 * order, appended to dst (idx NULL: a range, dst holding the records of every
 * index before it) or put at dst's records idx[0..] (a list). PS_ERR_NOMEM,
 * dst unchanged, when out of memory. Without records: nothing. */
ps_status ps_traced_join_paths(ps_traced *r, ps_path_store *dst, const uint64_t *idx, ps_error *err);
/* Whether the tracer records paths (ps_tracer_options.records). */
bool ps_tracer_records(const ps_tracer *t);
/* The quantisation the tracer records paths with. */
ps_path_quant ps_tracer_path_quant(const ps_tracer *t);

/* After an edit: which photon of tracer a's map each photon of tracer b's is
 * (both planned for `total` photons). Photon i of a map is the rank-th
 * photon of its stratum (light, caustic cone); b's photon (stratum, rank) is
 * a's photon of the same rank in the stratum of the same light and target
 * when that stratum samples the same way (the same caustic cone, the light not
 * in `resampled`: moved, turned, its spot angle or mesh changed; its power may
 * differ) and a emitted it below `end`: then `from` is its index in a's map,
 * else PS_SOURCE_NONE. out[i] for i < end. PS_ERR_NOMEM when out of memory
 * for the tables (end indices). */
#define PS_SOURCE_NONE UINT64_MAX
typedef struct ps_photon_source {
    uint64_t from;    /* a's index, or PS_SOURCE_NONE */
    uint64_t rank;    /* its rank in b's stratum */
    uint32_t stratum; /* b's stratum */
    bool repower;     /* its power differs in b (the light's power or the
                       * stratum's count changed): ps_tracer_repower */
} ps_photon_source;
ps_status ps_tracer_photon_sources(ps_tracer *a, ps_tracer *b, ps_map_kind kind, uint64_t total, uint64_t end,
                                   const bool *resampled, size_t light_count, ps_photon_source *out,
                                   ps_error *err);
/* The same in parts, for a repair that finds the sources of a range of
 * indices as it gets to them (an edit's first picture waits only for the
 * ones it draws): create does the tables (the plans' counts, a's indices by
 * rank; b's counts copied from a's when the edit kept the shares), fill
 * writes out[i - from] for i in [from, to) (to at most end), as
 * ps_tracer_photon_sources would, on every core. The map reads b's plan:
 * tracer b outlives it; a may go once it is made. */
typedef struct ps_source_map ps_source_map;
ps_status ps_source_map_create(ps_tracer *a, ps_tracer *b, ps_map_kind kind, uint64_t total, uint64_t end,
                               const bool *resampled, size_t light_count, ps_source_map **out, ps_error *err);
void ps_source_map_fill(const ps_source_map *m, uint64_t from, uint64_t to, ps_photon_source *out);
/* Every source is its own index or none (a kept photon stays where it is). */
bool ps_source_map_identity(const ps_source_map *m);
/* No index has a source: nothing of the map can be kept. */
bool ps_source_map_none(const ps_source_map *m);
void ps_source_map_destroy(ps_source_map *m);
/* The n photons a path of source src (from ps_tracer_photon_sources on t as
 * b) stored, with throughputs thr (its path record's), given t's power: their
 * RGBE set exactly as t's trace sets it (the light's power and 1 / the
 * stratum's count, multiplied in last). */
void ps_tracer_repower(ps_tracer *t, ps_map_kind kind, const ps_photon_source *src, const ps_path_thr *thr,
                       size_t n, ps_photon *ph);
/* Photon i's stratum and rank among that stratum's photons of [0, total),
 * as the trace finds them (the stratum's indices below i, counted in closed
 * form); false when the map is off, i >= total or out of memory. */
bool ps_tracer_photon_rank(ps_tracer *t, ps_map_kind kind, uint64_t i, uint64_t total, uint32_t *in_stratum,
                           uint64_t *rank);
/* The light photon i of map kind leaves (UINT32_MAX when the map is off). */
uint32_t ps_tracer_photon_light(ps_tracer *t, ps_map_kind kind, uint64_t i, uint64_t total);

/* How many of photons [0, total) light l emits for map kind (all its caustic cones
 * together): the tracer shares photons between lights in proportion to flux. */
uint64_t ps_tracer_light_photons(ps_tracer *t, ps_map_kind kind, uint32_t light, uint64_t total);

/* How many of photons [0, total) the stratum of light `light` and caustic
 * target `target` (an object index; -1: the global map's, or caustic photons
 * without cones) has: 0 when there is none. */
uint64_t ps_tracer_stratum_photons(ps_tracer *t, ps_map_kind kind, uint32_t light, int64_t target, uint64_t total);

#endif
