/* layers.c: layer names and lists (layers.h). */
#include "preview/layers.h"

#include <stdio.h>
#include <string.h>

const char *const ps_layer_names[PS_LAYER_COUNT + 1] = {"direct", "caustic", "global", "specular", NULL};

bool ps_layers_parse(const char *text, unsigned *out, char *why, size_t why_size)
{
    *out = 0;
    for (const char *item = text;;) {
        const char *comma = strchr(item, ',');
        size_t len = comma ? (size_t)(comma - item) : strlen(item);
        if (len == 0) {
            snprintf(why, why_size, "empty name in the list");
            return false;
        }
        int k = 0;
        while (k < PS_LAYER_COUNT && !(strlen(ps_layer_names[k]) == len && strncmp(item, ps_layer_names[k], len) == 0))
            k++;
        if (k == PS_LAYER_COUNT) {
            snprintf(why, why_size, "'%.*s' is not direct, caustic, global or specular", (int)len, item);
            return false;
        }
        if (*out & (1u << k)) {
            snprintf(why, why_size, "'%.*s' given twice", (int)len, item);
            return false;
        }
        *out |= 1u << k;
        if (!comma)
            return true;
        item = comma + 1;
    }
}
