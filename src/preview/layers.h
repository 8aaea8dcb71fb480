/* layers.h: the preview's layers (thesis eq. 6's terms as it draws them):
 * their bits, their names, and the comma list that options and scripts give. */
#ifndef PS_PREVIEW_LAYERS_H
#define PS_PREVIEW_LAYERS_H

#include <stdbool.h>
#include <stddef.h>

#include "photon/photon.h"

/* specular: what mirrors and glass show of the other layers (preview/specular.h). */
enum { PS_LAYER_DIRECT = 1, PS_LAYER_CAUSTIC = 2, PS_LAYER_GLOBAL = 4, PS_LAYER_SPECULAR = 8, PS_LAYER_ALL = 15 };
#define PS_LAYER_COUNT 4

/* Bit k (1 << k) is ps_layer_names[k]; NULL-terminated. */
extern const char *const ps_layer_names[PS_LAYER_COUNT + 1];

/* Map k's layer bit. */
static inline unsigned ps_map_layer(ps_map_kind k) { return k == PS_MAP_CAUSTIC ? PS_LAYER_CAUSTIC : PS_LAYER_GLOBAL; }

/* "direct,caustic,global,specular": any non-empty subset, each name once, to bits.
 * False with the reason in why (no location: the caller's message adds it),
 * e.g. "'glossy' is not direct, caustic, global or specular". */
bool ps_layers_parse(const char *text, unsigned *out, char *why, size_t why_size);

#endif
