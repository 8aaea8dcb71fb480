/* namemap.h: a string -> index map for readers that look names up per line
 * (scene materials, MTL materials), so that a file with many names costs
 * linear time rather than quadratic (found by fuzzing: docs/fuzzing.md). */
#ifndef PS_CORE_NAMEMAP_H
#define PS_CORE_NAMEMAP_H

#include <stdbool.h>
#include <stdint.h>

/* Opaque: an open-addressing hash table that owns copies of its names. */
typedef struct ps_namemap ps_namemap;

/* An empty map, or NULL when out of memory. */
ps_namemap *ps_namemap_create(void);
void ps_namemap_destroy(ps_namemap *m); /* accepts NULL */

/* The index stored for name, or -1 when there is none. */
int64_t ps_namemap_find(const ps_namemap *m, const char *name);

/* Stores name -> index. A name already present keeps its old index unless
 * `replace`. False only when out of memory (the map is then unchanged). */
bool ps_namemap_put(ps_namemap *m, const char *name, int64_t index, bool replace);

#endif
