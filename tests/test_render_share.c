/* test_render_share.c: a render shared between processes (render.h's
 * ps_render_share, what photosplat-ref-mpi's ranks use) gives the same image,
 * rays and cache as one process. The two "processes" are two threads here,
 * joined by an in-memory hub instead of MPI: the irradiance cache's chunks
 * split by position and exchanged, the tiles handed out in reverse order
 * (so that order cannot matter), the second part's tile buffers assembled
 * by the first. */
#include "test.h"
#include "render_rig.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "render/irrcache.h"
#include "render/render.h"

#define PARTS 2

typedef struct hub {
    pthread_mutex_t lock;
    pthread_barrier_t barrier;
    int tiles, made_by_1;
    size_t floats;
    float *store;
    bool *have;
    ps_irr_record *chunk[PARTS];
    bool *ok[PARTS];
    uint64_t rays[PARTS];
    int exchanges;
} hub;

typedef struct end {
    hub *h;
    int part, next;
    ps_render_share share;
    /* the thread's render */
    render_rig *rig;
    ps_render_options o;
    ps_image img;
    ps_render_stats st;
    ps_status status;
} end;

static ps_status exchange(void *user, ps_irr_record *chunk, bool *ok, size_t slots, bool cancelled, ps_error *err)
{
    (void)cancelled;
    (void)err;
    end *e = user;
    hub *h = e->h;
    int other = 1 - e->part;
    h->chunk[e->part] = chunk;
    h->ok[e->part] = ok;
    pthread_barrier_wait(&h->barrier);
    /* Read the other's records first, write them after a second barrier. */
    size_t *take = malloc(slots * sizeof *take), n = 0;
    assert_non_null(take);
    for (size_t s = 0; s < slots; s++)
        if (h->ok[other][s]) {
            assert_false(ok[s]); /* every slot is one part's */
            take[n++] = s;
        }
    ps_irr_record *copy = malloc((n ? n : 1) * sizeof *copy);
    assert_non_null(copy);
    for (size_t i = 0; i < n; i++)
        copy[i] = h->chunk[other][take[i]];
    pthread_barrier_wait(&h->barrier);
    for (size_t i = 0; i < n; i++) {
        chunk[take[i]] = copy[i];
        ok[take[i]] = true;
    }
    if (e->part == 0)
        h->exchanges++;
    free(take);
    free(copy);
    return PS_OK;
}

static ps_status tiles_begin(void *user, const ps_render_options *o, int tiles, size_t floats, ps_error *err)
{
    (void)o;
    (void)err;
    end *e = user;
    hub *h = e->h;
    pthread_mutex_lock(&h->lock);
    if (!h->store) {
        h->tiles = tiles;
        h->floats = floats;
        h->store = calloc((size_t)tiles * floats, sizeof *h->store);
        h->have = calloc((size_t)tiles, sizeof *h->have);
    }
    pthread_mutex_unlock(&h->lock);
    assert_non_null(h->store);
    pthread_barrier_wait(&h->barrier);
    return PS_OK;
}

/* Part p takes the tiles t with t mod 2 == p, last first: both parts make
 * tiles whatever the threads' timing. */
static int next_tile(void *user)
{
    end *e = user;
    hub *h = e->h;
    pthread_mutex_lock(&h->lock);
    int t = h->tiles - 1 - 2 * e->next - ((h->tiles - 1 - e->part) % 2);
    if (t >= 0)
        e->next++;
    pthread_mutex_unlock(&h->lock);
    return t < 0 ? -1 : t;
}

static void tile_done(void *user, int tile, const float *data)
{
    end *e = user;
    hub *h = e->h;
    if (e->part == 0)
        return; /* part 0 assembles: its own tiles are already in place */
    pthread_mutex_lock(&h->lock);
    memcpy(h->store + (size_t)tile * h->floats, data, h->floats * sizeof *data);
    h->have[tile] = true;
    h->made_by_1++;
    pthread_mutex_unlock(&h->lock);
}

static ps_status tiles_end(void *user, bool complete, uint64_t *rays, ps_error *err)
{
    (void)err;
    end *e = user;
    hub *h = e->h;
    assert_true(complete);
    h->rays[e->part] = *rays;
    pthread_barrier_wait(&h->barrier);
    *rays = h->rays[0] + h->rays[1];
    return PS_OK;
}

static const float *tile_data(void *user, int tile)
{
    hub *h = ((end *)user)->h;
    return h->have[tile] ? h->store + (size_t)tile * h->floats : NULL;
}

static void *run_part(void *arg)
{
    end *e = arg;
    render_rig *r = e->rig;
    ps_render_maps maps = {r->trees[PS_MAP_CAUSTIC], r->trees[PS_MAP_GLOBAL], r->full_tree, r->irr};
    ps_error err;
    e->status = ps_render(r->world, r->ls, &maps, &e->o, &e->img, &e->st, &err);
    return NULL;
}

static void shared_equals_single(ps_filter filter)
{
    const char *text = "camera eye 0 1 3.4 target 0 1 0 up 0 1 0 fov 40\n"
                       "material white diffuse albedo 0.75 0.75 0.75\n"
                       "material red diffuse albedo 0.75 0.25 0.25\n"
                       "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"
                       "quad corner -1 0 -1 edge1 2 0 0 edge2 0 2 0 material white\n"
                       "quad corner -1 0 -1 edge1 0 2 0 edge2 0 0 2 material red\n"
                       "sphere center 0.3 0.4 0 radius 0.4 material white\n"
                       "light point position 0 1.9 0 power 100 100 100\n";
    ps_estimate_options est = {50, 0.1, PS_KERNEL_CONE};
    render_rig r = render_rig_make(text, 0, 20000, &est, true);
    ps_render_options o = options(56, 40, 1, PS_COMPONENT_ALL, &est, 8);
    o.filter = filter;
    o.cache_spacing = 4;
    o.cache_rays = 64;
    o.threads = 1;
    ps_render_maps maps = {r.trees[PS_MAP_CAUSTIC], r.trees[PS_MAP_GLOBAL], r.full_tree, r.irr};
    ps_image single;
    ps_render_stats st;
    ps_error err;
    assert_int_equal(ps_render(r.world, r.ls, &maps, &o, &single, &st, &err), PS_OK);
    assert_true(st.cache_records > 0);

    hub h;
    memset(&h, 0, sizeof h);
    pthread_mutex_init(&h.lock, NULL);
    pthread_barrier_init(&h.barrier, NULL, PARTS);
    end ends[PARTS];
    pthread_t tid[PARTS];
    for (int p = 0; p < PARTS; p++) {
        memset(&ends[p], 0, sizeof ends[p]);
        ends[p].h = &h;
        ends[p].part = p;
        ends[p].rig = &r;
        ends[p].share = (ps_render_share){&ends[p], p, PARTS, p == 0, exchange, tiles_begin, next_tile,
                                          tile_done, tiles_end, tile_data};
        ends[p].o = o;
        ends[p].o.share = &ends[p].share;
        assert_int_equal(pthread_create(&tid[p], NULL, run_part, &ends[p]), 0);
    }
    for (int p = 0; p < PARTS; p++)
        pthread_join(tid[p], NULL);
    for (int p = 0; p < PARTS; p++) {
        assert_int_equal(ends[p].status, PS_OK);
        assert_int_equal(ends[p].st.cache_records, st.cache_records); /* every part holds the whole cache */
        assert_int_equal(ends[p].st.rays, st.rays);                  /* the rays of all parts */
    }
    assert_true(h.exchanges > 0);
    assert_int_equal(h.made_by_1, h.tiles / 2); /* part 1 made every other tile */
    assert_int_equal(ends[0].img.width, single.width);
    assert_memory_equal(ends[0].img.rgb, single.rgb, (size_t)single.width * single.height * 3 * sizeof(float));
    for (int p = 0; p < PARTS; p++)
        ps_image_destroy(&ends[p].img);
    ps_image_destroy(&single);
    free(h.store);
    free(h.have);
    pthread_barrier_destroy(&h.barrier);
    pthread_mutex_destroy(&h.lock);
    render_rig_free(&r);
}

static void shared_mitchell(void **state)
{
    (void)state;
    shared_equals_single(PS_FILTER_MITCHELL);
}

static void shared_box(void **state)
{
    (void)state;
    shared_equals_single(PS_FILTER_BOX);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(shared_mitchell), cmocka_unit_test(shared_box)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
