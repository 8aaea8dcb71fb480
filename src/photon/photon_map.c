/* photon_map.c: the parallel arrays of a photon map, and its text dump. */
#include "photon/photon_map.h"

#include <stdlib.h>
#include <string.h>

void ps_trace_counters_add(ps_trace_counters *a, const ps_trace_counters *b)
{
    a->emitted += b->emitted;
    a->stored += b->stored;
    a->rays += b->rays;
    a->escaped += b->escaped;
    a->absorbed += b->absorbed;
    a->discarded += b->discarded;
    a->truncated += b->truncated;
    a->empty += b->empty;
}

void ps_photon_map_init(ps_photon_map *m, ps_map_kind kind)
{
    memset(m, 0, sizeof *m);
    m->kind = kind;
}

void ps_photon_map_free(ps_photon_map *m)
{
    ps_map_kind kind = m->kind;
    free(m->photons);
    free(m->materials);
    free(m->objects);
    ps_photon_map_init(m, kind);
}

/* Grows one array to n entries of elem bytes; false, with *p untouched, on failure. */
static bool grow(void **p, size_t n, size_t elem)
{
    void *q = realloc(*p, n * elem);
    if (!q)
        return false;
    *p = q;
    return true;
}

/* Grows all three arrays to n entries (n > cap). */
static bool resize(ps_photon_map *m, size_t n)
{
    if (n > SIZE_MAX / sizeof *m->photons)
        return false;
    /* An array grown before a later one fails keeps its larger block: every
     * array still holds at least cap entries, which is all cap promises. */
    if (!grow((void **)&m->photons, n, sizeof *m->photons) || !grow((void **)&m->materials, n, sizeof *m->materials) ||
        !grow((void **)&m->objects, n, sizeof *m->objects))
        return false;
    m->cap = n;
    return true;
}

bool ps_photon_map_reserve(ps_photon_map *m, size_t need)
{
    if (need <= m->cap)
        return true;
    size_t n = m->cap ? m->cap : 16;
    while (n < need) {
        if (n > SIZE_MAX / 2)
            return false;
        n *= 2;
    }
    return resize(m, n);
}

bool ps_photon_map_reserve_exact(ps_photon_map *m, size_t need) { return need <= m->cap || resize(m, need); }

bool ps_photon_map_push(ps_photon_map *m, ps_photon p, uint16_t material, uint32_t object)
{
    if (m->count == SIZE_MAX || !ps_photon_map_reserve(m, m->count + 1))
        return false;
    m->photons[m->count] = p;
    m->materials[m->count] = material;
    m->objects[m->count] = object;
    m->count++;
    return true;
}

bool ps_photon_map_append(ps_photon_map *dst, const ps_photon_map *src)
{
    if (src->count > SIZE_MAX - dst->count || !ps_photon_map_reserve(dst, dst->count + src->count))
        return false;
    if (src->count) {
        memcpy(dst->photons + dst->count, src->photons, src->count * sizeof *dst->photons);
        memcpy(dst->materials + dst->count, src->materials, src->count * sizeof *dst->materials);
        memcpy(dst->objects + dst->count, src->objects, src->count * sizeof *dst->objects);
    }
    dst->count += src->count;
    ps_trace_counters_add(&dst->counters, &src->counters);
    return true;
}

size_t ps_photon_map_bytes(const ps_photon_map *m) { return m->cap * PS_PHOTON_MAP_BYTES; }

ps_rgb ps_photon_map_power(const ps_photon_map *m)
{
    ps_rgb sum = ps_rgb_gray(0.0);
    for (size_t i = 0; i < m->count; i++)
        sum = ps_rgb_add(sum, ps_photon_power(&m->photons[i]));
    return sum;
}

void ps_photon_map_write_text(FILE *f, const ps_photon_map *m)
{
    const char *name = ps_map_name(m->kind);
    for (size_t i = 0; i < m->count; i++) {
        const ps_photon *p = &m->photons[i];
        ps_rgb c = ps_photon_power(p);
        ps_vec3 d = ps_photon_dir(p), n = ps_photon_normal(p);
        /* %.9g round-trips the single-precision position exactly. */
        fprintf(f, "%s %.9g %.9g %.9g %.9g %.9g %.9g %.6f %.6f %.6f %.6f %.6f %.6f\n", name, p->pos[0], p->pos[1],
                p->pos[2], c.r, c.g, c.b, d.x, d.y, d.z, n.x, n.y, n.z);
    }
}
