/* namemap.c: open addressing with linear probing, 64-bit FNV-1a hashes. */
#include "core/namemap.h"

#include <stdlib.h>
#include <string.h>

/* Slots in a new map; always a power of two, so a mask picks the slot. */
#define INITIAL_SLOTS 64
/* FNV-1a, 64-bit variant. */
#define FNV_OFFSET 14695981039346656037ull
#define FNV_PRIME 1099511628211ull

typedef struct slot {
    char *name; /* NULL: empty (entries are never removed) */
    uint64_t hash;
    int64_t index;
} slot;

struct ps_namemap {
    slot *slots;
    size_t cap; /* power of two; at most half full, so probes stay short */
    size_t count;
};

static uint64_t hash_name(const char *s)
{
    uint64_t h = FNV_OFFSET;
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * FNV_PRIME;
    return h;
}

ps_namemap *ps_namemap_create(void)
{
    ps_namemap *m = malloc(sizeof *m);
    if (!m)
        return NULL;
    m->slots = calloc(INITIAL_SLOTS, sizeof *m->slots);
    if (!m->slots) {
        free(m);
        return NULL;
    }
    m->cap = INITIAL_SLOTS;
    m->count = 0;
    return m;
}

void ps_namemap_destroy(ps_namemap *m)
{
    if (!m)
        return;
    for (size_t i = 0; i < m->cap; i++)
        free(m->slots[i].name);
    free(m->slots);
    free(m);
}

/* The slot holding name, or the empty slot where it would go. */
static slot *probe(slot *slots, size_t cap, const char *name, uint64_t h)
{
    size_t i = (size_t)h & (cap - 1);
    while (slots[i].name && (slots[i].hash != h || strcmp(slots[i].name, name) != 0))
        i = (i + 1) & (cap - 1);
    return &slots[i];
}

int64_t ps_namemap_find(const ps_namemap *m, const char *name)
{
    slot *s = probe(m->slots, m->cap, name, hash_name(name));
    return s->name ? s->index : -1;
}

static bool grow(ps_namemap *m)
{
    if (m->cap > SIZE_MAX / 2 / sizeof *m->slots)
        return false;
    size_t cap = m->cap * 2;
    slot *slots = calloc(cap, sizeof *slots);
    if (!slots)
        return false;
    for (size_t i = 0; i < m->cap; i++)
        if (m->slots[i].name)
            *probe(slots, cap, m->slots[i].name, m->slots[i].hash) = m->slots[i];
    free(m->slots);
    m->slots = slots;
    m->cap = cap;
    return true;
}

bool ps_namemap_put(ps_namemap *m, const char *name, int64_t index, bool replace)
{
    uint64_t h = hash_name(name);
    slot *s = probe(m->slots, m->cap, name, h);
    if (s->name) {
        if (replace)
            s->index = index;
        return true;
    }
    if ((m->count + 1) * 2 > m->cap) {
        if (!grow(m))
            return false;
        s = probe(m->slots, m->cap, name, h);
    }
    size_t len = strlen(name);
    char *copy = malloc(len + 1);
    if (!copy)
        return false;
    memcpy(copy, name, len + 1);
    s->name = copy;
    s->hash = h;
    s->index = index;
    m->count++;
    return true;
}
