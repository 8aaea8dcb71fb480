/* feed.c: the background photon tracer of the progressive preview. */
#include "preview/feed.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/array.h"
#include "core/clock.h"

struct ps_feed {
    ps_tracer *tracer;
    uint64_t cap[PS_MAP_COUNT];
    bool active[PS_MAP_COUNT];
    pthread_mutex_t lock;
    pthread_cond_t wake;              /* signalled when pause or stop change */
    ps_photon_map maps[PS_MAP_COUNT]; /* under lock: what has arrived */
    ps_feed_mark *marks[PS_MAP_COUNT];  /* under lock: batch ends */
    size_t mark_count[PS_MAP_COUNT], mark_cap[PS_MAP_COUNT];
    bool stop, paused, ended;         /* under lock */
    bool store_limited;               /* under lock: ended at max_stored */
    size_t max_stored;                /* 0: no limit */
    bool started;
    uint64_t next[PS_MAP_COUNT]; /* the feeding thread's: first photon not yet traced */
    uint64_t round;
    pthread_t thread;
    ps_status status;
    ps_error err;
    double seconds;
};

ps_status ps_feed_create(ps_tracer *t, const uint64_t caps[PS_MAP_COUNT], const bool active[PS_MAP_COUNT],
                         ps_feed **out, ps_error *err)
{
    *out = NULL;
    ps_feed *f = calloc(1, sizeof *f);
    if (!f)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the photon feed");
    f->tracer = t;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        f->cap[k] = caps[k];
        f->active[k] = active[k] && caps[k] > 0;
        ps_photon_map_init(&f->maps[k], (ps_map_kind)k);
    }
    pthread_mutex_init(&f->lock, NULL);
    pthread_cond_init(&f->wake, NULL);
    *out = f;
    return PS_OK;
}

/* Traces photons [first, first + count) of map k outside the lock, then
 * joins them to the map under it: each photon is copied once, from the
 * tracer's chunk into the map the drawing thread reads. */
static ps_status batch(ps_feed *f, int k, uint64_t first, uint64_t count, ps_error *err)
{
    ps_traced *traced;
    /* Only this thread adds to the maps, so the count can be read without the lock. */
    ps_status st = ps_tracer_trace_range(f->tracer, (ps_map_kind)k, first, count, f->cap[k], f->maps[k].count,
                                         &traced, err);
    if (st == PS_ERR_LIMIT) {
        /* The map's share of the memory budget (the tracer's max_stored):
         * end here as at the store limit, the maps as they were before this
         * batch, still a correct picture of the photons emitted so far. */
        pthread_mutex_lock(&f->lock);
        f->store_limited = true;
        pthread_mutex_unlock(&f->lock);
        return PS_OK;
    }
    if (st != PS_OK)
        return st;
    pthread_mutex_lock(&f->lock);
    if (!PS_RESERVE(f->marks[k], f->mark_cap[k], f->mark_count[k] + 1) ||
        ps_traced_join(traced, &f->maps[k], err) != PS_OK)
        st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for %llu more photons",
                          (unsigned long long)ps_traced_count(traced));
    if (st == PS_OK) {
        ps_feed_mark m = {f->maps[k].count, f->maps[k].counters.emitted};
        f->marks[k][f->mark_count[k]++] = m;
    }
    pthread_mutex_unlock(&f->lock);
    ps_traced_destroy(traced);
    return st;
}

/* One round: each active map up to its share of the next PS_FEED_BATCH
 * photons of the largest cap, so that all maps finish together. False when
 * every map has reached its cap (or on an error, in *st). */
static bool round_once(ps_feed *f, ps_status *st, ps_error *err)
{
    /* Only this thread appends, so the counts can be read without the lock. */
    if (f->max_stored && f->maps[PS_MAP_CAUSTIC].count + f->maps[PS_MAP_GLOBAL].count >= f->max_stored) {
        pthread_mutex_lock(&f->lock);
        f->store_limited = true;
        pthread_mutex_unlock(&f->lock);
        return false;
    }
    uint64_t biggest = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (f->active[k] && f->cap[k] > biggest)
            biggest = f->cap[k];
    bool more = false;
    for (int k = 0; k < PS_MAP_COUNT && *st == PS_OK; k++) {
        if (!f->active[k] || f->next[k] >= f->cap[k])
            continue;
        double share = (double)(f->round + 1) * PS_FEED_BATCH / (double)biggest;
        uint64_t until = share >= 1.0 ? f->cap[k] : (uint64_t)((double)f->cap[k] * share);
        if (until <= f->next[k])
            until = f->next[k] + 1;
        *st = batch(f, k, f->next[k], until - f->next[k], err);
        f->next[k] = until;
        more = more || f->next[k] < f->cap[k];
    }
    f->round++;
    /* Only this thread sets it, so it can be read without the lock. */
    return more && *st == PS_OK && !f->store_limited;
}

static void *feed_main(void *arg)
{
    ps_feed *f = arg;
    double t0 = ps_now_seconds();
    ps_status st = f->status;
    ps_error err = f->err;
    bool more = st == PS_OK && !f->ended;
    while (more) {
        pthread_mutex_lock(&f->lock);
        while (f->paused && !f->stop)
            pthread_cond_wait(&f->wake, &f->lock);
        bool stop = f->stop;
        pthread_mutex_unlock(&f->lock);
        if (stop)
            break;
        more = round_once(f, &st, &err);
    }
    pthread_mutex_lock(&f->lock);
    f->status = st;
    f->err = err;
    f->ended = true;
    f->seconds += ps_now_seconds() - t0;
    pthread_mutex_unlock(&f->lock);
    return NULL;
}

ps_status ps_feed_prime(ps_feed *f, ps_error *err)
{
    double t0 = ps_now_seconds();
    ps_status st = PS_OK;
    ps_error_clear(&f->err);
    bool more = round_once(f, &st, &f->err);
    pthread_mutex_lock(&f->lock);
    f->status = st;
    f->ended = !more;
    f->seconds += ps_now_seconds() - t0;
    pthread_mutex_unlock(&f->lock);
    if (st != PS_OK && err)
        *err = f->err;
    return st;
}

ps_status ps_feed_run(ps_feed *f, ps_error *err)
{
    feed_main(f);
    if (f->status != PS_OK && err)
        *err = f->err;
    return f->status;
}

ps_status ps_feed_start(ps_feed *f, ps_error *err)
{
    if (pthread_create(&f->thread, NULL, feed_main, f) != 0)
        return ps_error_set(err, PS_ERR_NOMEM, "could not start the photon tracing thread");
    f->started = true;
    return PS_OK;
}

void ps_feed_stop(ps_feed *f)
{
    pthread_mutex_lock(&f->lock);
    f->stop = true;
    pthread_cond_broadcast(&f->wake);
    pthread_mutex_unlock(&f->lock);
    if (f->started) {
        pthread_join(f->thread, NULL);
        f->started = false;
    }
}

void ps_feed_pause(ps_feed *f, bool paused)
{
    pthread_mutex_lock(&f->lock);
    f->paused = paused;
    pthread_cond_broadcast(&f->wake);
    pthread_mutex_unlock(&f->lock);
}

void ps_feed_lock(ps_feed *f) { pthread_mutex_lock(&f->lock); }
void ps_feed_unlock(ps_feed *f) { pthread_mutex_unlock(&f->lock); }
const ps_photon_map *ps_feed_maps(const ps_feed *f) { return f->maps; }
bool ps_feed_ended(const ps_feed *f) { return f->ended; }
bool ps_feed_store_limited(const ps_feed *f) { return f->store_limited; }
void ps_feed_set_store_limit(ps_feed *f, size_t max_stored) { f->max_stored = max_stored; }

const ps_feed_mark *ps_feed_marks(const ps_feed *f, ps_map_kind k, size_t *count)
{
    *count = f->mark_count[k];
    return f->marks[k];
}

ps_status ps_feed_status(const ps_feed *f, ps_error *err)
{
    if (f->status != PS_OK && err)
        *err = f->err;
    return f->status;
}

double ps_feed_seconds(const ps_feed *f) { return f->seconds; }
uint64_t ps_feed_cap(const ps_feed *f, ps_map_kind k) { return f->cap[k]; }
bool ps_feed_active(const ps_feed *f, ps_map_kind k) { return f->active[k]; }

void ps_feed_destroy(ps_feed *f)
{
    if (!f)
        return;
    ps_feed_stop(f);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map_free(&f->maps[k]);
        free(f->marks[k]);
    }
    pthread_cond_destroy(&f->wake);
    pthread_mutex_destroy(&f->lock);
    free(f);
}
