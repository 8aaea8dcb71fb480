/* path_record.h: what the preview's selective repair keeps of each traced
 * photon path, so that after an edit it knows, exactly, which paths the edit
 * cannot have changed (issue 18).
 *
 * Photon i's path is a pure function of (scene, seed, i) (tracer.h). An edit
 * that moves object O can change path i only if one of its segments meets O's
 * bounds at the old or the new place: every other segment still ends at the
 * same surface, computed the same way. So each path keeps its vertices (the
 * emission point, every surface it met, and, when it escaped, where it left
 * record_box), quantised to 16 bits a coordinate inside a box fixed for the
 * whole session; a segment is tested against a box widened by the
 * quantisation step and the ray offset, so a test can only say "meets" too
 * often (a needless retrace), never too rarely.
 *
 * Cost: 8 bytes per emitted photon (ps_path_rec), 6 per vertex and 12 per
 * stored photon (its throughput, ps_path_thr). In the
 * default scene caustic paths have 3.65 vertices, global ones 3.44 (the
 * Russian roulette on albedos of 0.25-0.75): 29.9 and 28.7 bytes per emitted
 * photon, and 0.937 and 0.927 stored photons per emitted one, 11.2 and 11.1
 * bytes of throughputs (docs/repair.md); PS_PATH_PLAN_BYTES is what a photon
 * is planned at. */
#ifndef PS_PHOTON_PATH_RECORD_H
#define PS_PHOTON_PATH_RECORD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/vec.h"

typedef struct ps_path_rec {
    uint32_t first;   /* its first vertex in the store's pool */
    uint8_t vertices; /* how many (0: it carried nothing, no segment) */
    uint8_t stored;   /* photons the path stored in its map */
    uint8_t flags;    /* the owner's (the feed's repair state) */
    uint8_t spare;
} ps_path_rec;

typedef struct ps_path_vertex {
    uint16_t q[3];
} ps_path_vertex;

/* A stored photon's light-independent throughput T (emission weight times the
 * albedo ratios of its bounces), rounded to float: its power is T times its
 * light's power over its stratum's photon count (tracer.h), so a repair can
 * recompute it exactly after a power edit. */
typedef struct ps_path_thr {
    float t[3];
} ps_path_thr;

/* Bytes a photon's record is planned at in the memory budget: the record,
 * 4 vertices and the throughput of one stored photon (a path stores 0.93 on
 * average in both maps of the default scene, docs/repair.md). */
#define PS_PATH_PLAN_BYTES (sizeof(ps_path_rec) + 4 * sizeof(ps_path_vertex) + sizeof(ps_path_thr))

/* A path may have at most this many vertices (emission + every bounce + exit). */
#define PS_PATH_MAX_VERTICES 66

/* Records of consecutive (or, for a repair's list, chosen) photon indices and
 * their vertices. */
typedef struct ps_path_store {
    ps_path_rec *rec;
    size_t count, cap;
    ps_path_vertex *vert;
    size_t vcount, vcap;
    /* The stored photons' throughputs, parallel to the photons of the map
     * the records go with (in the map's order, not the records'). */
    ps_path_thr *thr;
    size_t tcount, tcap;
    bool failed; /* out of memory while filling */
} ps_path_store;

/* The quantisation: record_box divided into 65535 steps a side. */
typedef struct ps_path_quant {
    ps_aabb box;
    ps_vec3 step;
    double margin; /* what a segment test widens boxes by */
} ps_path_quant;

/* box: the session's record box; offset: the ray offset (ps_world_epsilon)
 * of the scene at its largest. */
ps_path_quant ps_path_quant_make(ps_aabb box, double offset);
ps_path_vertex ps_path_quantize(const ps_path_quant *q, ps_vec3 p);
ps_vec3 ps_path_dequantize(const ps_path_quant *q, ps_path_vertex v);
/* Where ray (o, d) leaves the quantisation box (o inside it). */
ps_vec3 ps_path_exit(const ps_path_quant *q, ps_vec3 o, ps_vec3 d);

void ps_path_store_init(ps_path_store *s);
void ps_path_store_free(ps_path_store *s);
/* Starts one more record (vertices added with ps_path_add_vertex). */
void ps_path_begin(ps_path_store *s);
void ps_path_add_vertex(ps_path_store *s, ps_path_vertex v);
/* One more stored photon's throughput. */
void ps_path_add_thr(ps_path_store *s, ps_path_thr t);
/* Room for `need` records; false when out of memory. */
bool ps_path_store_reserve(ps_path_store *s, size_t need);
/* Appends src's records, vertices and throughputs; false, dst unchanged, when out of memory. */
bool ps_path_store_append(ps_path_store *dst, const ps_path_store *src);
/* Records src's k-th path as dst's record idx[k] (idx[k] < dst->count), its
 * vertices appended to dst's pool (the old ones left unused until
 * ps_path_store_compact), its throughputs appended to dst's (as the
 * photons are to the map). */
bool ps_path_store_put(ps_path_store *dst, const ps_path_store *src, const uint64_t *idx);
/* Rewrites the pool in record order without unused vertices; false when out
 * of memory (nothing changed). */
bool ps_path_store_compact(ps_path_store *s);

/* Whether a segment of record r meets box b (widened by q's margin). */
bool ps_path_meets(const ps_path_store *s, const ps_path_rec *r, const ps_path_quant *q, ps_aabb b);
/* Whether segment a-b meets box (widened by margin). */
bool ps_segment_meets_box(ps_vec3 a, ps_vec3 b, ps_aabb box, double margin);

#endif
