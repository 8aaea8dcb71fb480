/* history.c: undo and redo by snapshots (history.h). */
#include "preview/history.h"

#include <stdlib.h>
#include <string.h>

#include "core/array.h"

/* A stack of scene snapshots, oldest first. */
typedef struct stack {
    ps_scene **items;
    size_t count, cap;
} stack;

struct ps_history {
    size_t max_steps;
    uint64_t max_bytes;
    stack undo, redo;
};

ps_status ps_history_create(size_t max_steps, uint64_t max_bytes, ps_history **out, ps_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the edit history");
    (*out)->max_steps = max_steps > 0 ? max_steps : 1;
    (*out)->max_bytes = max_bytes;
    return PS_OK;
}

static void clear(stack *st)
{
    for (size_t k = 0; k < st->count; k++)
        ps_scene_destroy(st->items[k]);
    st->count = 0;
}

void ps_history_destroy(ps_history *h)
{
    if (!h)
        return;
    clear(&h->undo);
    clear(&h->redo);
    free(h->undo.items);
    free(h->redo.items);
    free(h);
}

uint64_t ps_history_scene_bytes(const ps_scene *s)
{
    size_t n[8];
    ps_scene_materials(s, &n[0]);
    ps_scene_positions(s, &n[1]);
    ps_scene_normals(s, &n[2]);
    ps_scene_triangles(s, &n[3]);
    ps_scene_objects(s, &n[4]);
    ps_scene_lights(s, &n[5]);
    ps_scene_emitters(s, &n[6]);
    ps_scene_texcoords(s, &n[7]);
    return (uint64_t)n[0] * sizeof(ps_material) + (uint64_t)(n[1] + n[2]) * sizeof(ps_vec3) +
           (uint64_t)n[3] * sizeof(ps_triangle) + (uint64_t)n[4] * sizeof(ps_object) +
           (uint64_t)n[5] * sizeof(ps_light) + (uint64_t)n[6] * sizeof(uint32_t) + (uint64_t)n[7] * sizeof(ps_uv);
}

static ps_status push(stack *st, ps_scene *s, ps_error *err)
{
    if (!PS_RESERVE(st->items, st->cap, st->count + 1)) {
        ps_scene_destroy(s);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the edit history");
    }
    st->items[st->count++] = s;
    return PS_OK;
}

static ps_scene *pop(stack *st) { return st->count ? st->items[--st->count] : NULL; }

/* Forgets the oldest undo steps beyond the limits (always keeping the newest). */
static void trim(ps_history *h, uint64_t step_bytes)
{
    while (h->undo.count > 1 &&
           (h->undo.count > h->max_steps || (uint64_t)h->undo.count * step_bytes > h->max_bytes)) {
        ps_scene_destroy(h->undo.items[0]);
        memmove(h->undo.items, h->undo.items + 1, (h->undo.count - 1) * sizeof *h->undo.items);
        h->undo.count--;
    }
}

ps_status ps_history_take(ps_history *h, ps_scene *snapshot, ps_error *err)
{
    uint64_t bytes = ps_history_scene_bytes(snapshot);
    ps_status st = push(&h->undo, snapshot, err); /* frees it on failure */
    if (st != PS_OK)
        return st;
    clear(&h->redo);
    trim(h, bytes);
    return PS_OK;
}

ps_status ps_history_record(ps_history *h, const ps_scene *before, ps_error *err)
{
    ps_scene *copy = NULL;
    ps_status st = ps_scene_clone(before, &copy, err);
    return st == PS_OK ? ps_history_take(h, copy, err) : st;
}

void ps_history_forget(ps_history *h) { ps_scene_destroy(pop(&h->undo)); }

size_t ps_history_undo_steps(const ps_history *h) { return h->undo.count; }
size_t ps_history_redo_steps(const ps_history *h) { return h->redo.count; }

/* The scene now onto `to`, the top of `from` into the session. */
static ps_status step(stack *from, stack *to, ps_session *s, const char *what, ps_error *err)
{
    if (!from->count)
        return ps_error_set(err, PS_ERR_RANGE, "nothing to %s", what);
    ps_scene *now = NULL;
    ps_status st = ps_scene_clone(ps_session_scene(s), &now, err);
    if (st != PS_OK)
        return st;
    st = ps_session_restore_scene(s, from->items[from->count - 1], err);
    if (st != PS_OK) {
        ps_scene_destroy(now);
        return st;
    }
    ps_scene_destroy(pop(from));
    return push(to, now, err);
}

ps_status ps_history_undo(ps_history *h, ps_session *s, ps_error *err) { return step(&h->undo, &h->redo, s, "undo", err); }
ps_status ps_history_redo(ps_history *h, ps_session *s, ps_error *err) { return step(&h->redo, &h->undo, s, "redo", err); }
