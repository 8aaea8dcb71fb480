/* photon.h: the compact photon record both maps store (thesis 2.4.1).
 *
 * Layout, 20 bytes:
 *     float    pos[3]   12  where it landed (single precision: 1e-7 relative,
 *                           far below any splat or search radius)
 *     uint8_t  rgbe[4]   4  power in watts, Ward's shared-exponent RGBE
 *     uint16_t dir       2  direction of travel (into the surface), octahedral 8+8 bits
 *     uint16_t normal_flags 2  bits 0-13: surface normal on the side the photon
 *                           came from, octahedral 7+7 bits; bits 14-15: flags
 *                           (the kd-tree keeps a node's split axis there, as
 *                           the thesis' photon keeps it in its flag field)
 *
 * Departure from the thesis: it packs directions as 8-bit (theta, phi); we use
 * the octahedral map (Meyer et al. 2010), whose error is nearly uniform over
 * the sphere instead of crowding at the poles: at most 0.75 degrees for the
 * direction (8+8 bits, used by glossy estimates) and 1.5 degrees for the
 * normal (7+7 bits, used to orient splats and to reject photons of a surface
 * facing the other way). RGBE mantissas are rounded with a per-photon dither: photons of
 * one light often carry identical power, and plain rounding would bias all of
 * them the same way (up to 0.2 %); dithered, the error of each photon is below
 * 1/256 of its largest channel and the expected stored power is exact. */
#ifndef PS_PHOTON_PHOTON_H
#define PS_PHOTON_PHOTON_H

#include <stdint.h>

#include "core/vec.h"

typedef struct ps_photon {
    float pos[3];
    uint8_t rgbe[4];
    uint16_t dir;
    uint16_t normal_flags;
} ps_photon;

#define PS_OCT_DIR_BITS 8

_Static_assert(sizeof(ps_photon) <= 20, "the photon record must stay within 20 bytes");

/* The two maps of the thesis (2.1). */
typedef enum ps_map_kind {
    PS_MAP_CAUSTIC, /* light, one or more specular bounces, then a diffuse surface */
    PS_MAP_GLOBAL,  /* stored at diffuse surfaces after at least one diffuse bounce */
    PS_MAP_COUNT
} ps_map_kind;

/* The maps' names in enum order, NULL-terminated: "caustic", "global". */
extern const char *const ps_map_names[PS_MAP_COUNT + 1];
const char *ps_map_name(ps_map_kind k); /* ps_map_names[k], "?" out of range */

/* power: non-negative watts (negative or NaN channels are stored as 0);
 * dir and normal: unit vectors; dither in [0, 1) (0.5: plain rounding). */
ps_photon ps_photon_pack(ps_vec3 pos, ps_rgb power, ps_vec3 dir, ps_vec3 normal, double dither);

static inline ps_vec3 ps_photon_position(const ps_photon *p) { return ps_v3(p->pos[0], p->pos[1], p->pos[2]); }
ps_rgb ps_photon_power(const ps_photon *p);
ps_vec3 ps_photon_dir(const ps_photon *p);
ps_vec3 ps_photon_normal(const ps_photon *p);
/* Two bits of flags, 0 when packed. */
unsigned ps_photon_flags(const ps_photon *p);
void ps_photon_set_flags(ps_photon *p, unsigned flags);

/* The encodings on their own, for tests and the GL module. */
/* Mantissas are floor(value + dither) in units of the shared exponent. */
void ps_rgbe_encode(ps_rgb c, double dither, uint8_t out[4]);
ps_rgb ps_rgbe_decode(const uint8_t in[4]);
/* Octahedral codes of `bits` bits per coordinate (2 <= bits <= 8); the
 * encoder picks, of the four codes around v, the one decoding closest to it. */
uint16_t ps_oct_encode_bits(ps_vec3 unit, int bits);
ps_vec3 ps_oct_decode_bits(uint16_t code, int bits);

#endif
