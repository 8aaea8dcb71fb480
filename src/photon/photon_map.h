/* photon_map.h: one photon map: the photons of one map in index order, and
 * beside each the material and object of the surface it landed on (the
 * splats need the BRDF there and clip to the object's pixels; the 20-byte
 * record has no room, and the kd-tree does not need them: a query knows its
 * own surface).
 *
 * The three arrays are parallel: one count and one capacity for all of them,
 * grown together, so that entry i of each is always there for i < cap. The
 * tracer fills a map chunk by chunk (tracer.h); the feed, the reference
 * renderer and the tests read the arrays directly. */
#ifndef PS_PHOTON_PHOTON_MAP_H
#define PS_PHOTON_PHOTON_MAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "photon/photon.h"

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

void ps_trace_counters_add(ps_trace_counters *a, const ps_trace_counters *b);

typedef struct ps_photon_map {
    ps_map_kind kind;
    ps_photon *photons;
    uint16_t *materials; /* parallel to photons */
    uint32_t *objects;   /* parallel to photons */
    size_t count;        /* entries in use */
    size_t cap;          /* entries allocated, in each of the three arrays */
    ps_trace_counters counters;
} ps_photon_map;

/* Bytes one entry of a map takes: the 20-byte record and the material and
 * object beside it. */
#define PS_PHOTON_MAP_BYTES (sizeof(ps_photon) + sizeof(uint16_t) + sizeof(uint32_t))

void ps_photon_map_init(ps_photon_map *m, ps_map_kind kind);
void ps_photon_map_free(ps_photon_map *m); /* and reset to empty */
/* Room for at least `need` entries (capacity grown geometrically, doubling
 * from 16). False, with m unchanged in count and capacity, when out of memory. */
bool ps_photon_map_reserve(ps_photon_map *m, size_t need);
/* Room for at least `need` entries, growing to exactly `need` when it must
 * grow: for a map filled once (the reference renderer's), which then holds no
 * unused capacity. */
bool ps_photon_map_reserve_exact(ps_photon_map *m, size_t need);
/* Appends one photon with its material and object (counters untouched);
 * false, with m unchanged, when out of memory. */
bool ps_photon_map_push(ps_photon_map *m, ps_photon p, uint16_t material, uint32_t object);
/* Appends src's photons (with their materials and objects) and counters to
 * dst; false, with dst unchanged, when out of memory. */
bool ps_photon_map_append(ps_photon_map *dst, const ps_photon_map *src);
/* Bytes the map has allocated: cap * PS_PHOTON_MAP_BYTES. */
size_t ps_photon_map_bytes(const ps_photon_map *m);
/* Total power of all photons in the map. */
ps_rgb ps_photon_map_power(const ps_photon_map *m);

/* Writes every photon of m as one text line (contract, --dump-photons):
 * `map x y z r g b dx dy dz nx ny nz`, power in watts, d the direction of
 * travel (into the surface), n the surface normal on the side it arrived from. */
void ps_photon_map_write_text(FILE *f, const ps_photon_map *m);

#endif
