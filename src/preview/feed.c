/* feed.c: the background photon tracer of the progressive preview. */
#include "preview/feed.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/array.h"
#include "core/clock.h"
#include "core/jobs.h"

/* Map k's repair in progress: indices [next, end) are still to be tested
 * and copied. Under the lock only m->count, the marks and the counts
 * change; the photons are written past m->count, where nothing reads. */
typedef struct repair_work {
    bool active;
    bool in_place;              /* the kept photons at their own index: the old arrays are the map's */
    uint64_t next, end;
    ps_source_map *sources;     /* each index's old photon, found a step at a time */
    ps_photon_source *src;      /* ... for the step's indices (REPAIR_STEP_INDICES) */
    size_t *off;                /* where each old index's photons start in the old map */
    uint8_t *kept;              /* the keep tests' answers, an index of the step each */
    ps_photon_map old_map;      /* not in place: the old photons ... */
    ps_path_store old_paths;    /* ... and records (their vertex pool is the new store's) */
    size_t to;                  /* photons the map holds */
    size_t pending_cap;
} repair_work;

struct ps_feed {
    ps_tracer *tracer;
    uint64_t cap[PS_MAP_COUNT];
    bool active[PS_MAP_COUNT];
    pthread_mutex_t lock;
    pthread_cond_t wake;              /* signalled when pause or stop change */
    pthread_cond_t idle;              /* signalled when the thread waits paused, or ends */
    bool waiting;                     /* under lock: the thread waits paused between batches */
    ps_photon_map maps[PS_MAP_COUNT]; /* under lock: what has arrived */
    ps_feed_mark *marks[PS_MAP_COUNT];  /* under lock: batch ends */
    size_t mark_count[PS_MAP_COUNT], mark_cap[PS_MAP_COUNT];
    bool stop, paused, ended;         /* under lock */
    bool store_limited;               /* under lock: ended at max_stored */
    size_t max_stored;                /* 0: no limit */
    size_t ahead[PS_MAP_COUNT];       /* under lock: ps_feed_set_ahead's bounds */
    bool started;
    /* Set before the background thread starts: it leaves a repair's merge to
     * ps_feed_merge (the drawing side's moment), see feed_main. */
    bool threaded;
    uint64_t next[PS_MAP_COUNT]; /* the feeding thread's: first photon not yet traced */
    uint64_t round[PS_MAP_COUNT];   /* map k's rounds traced (round_end) */
    /* A map a repair could keep nothing of starts over from photon 0 (as a
     * fresh feed's): its indices below restart_end are traced as a repair
     * retraces, before the other maps go past theirs. */
    uint64_t restart_end[PS_MAP_COUNT];
    pthread_t thread;
    ps_status status;
    ps_error err;
    double seconds;
    /* Selective repair (ps_feed_create_repair). With the tracer's records,
     * paths[k] holds a record for every photon index below next[k] (records
     * false once they could not be kept: then edits restart). While
     * repairing, map k is in repair order: photons [0, kept_end[k]) of the
     * indices kept (index order), then those retraced (index order), then
     * those of indices from repair_end[k] on; a merge puts it back in index
     * order (generation counts merges). */
    bool records;
    ps_path_store paths[PS_MAP_COUNT];
    uint64_t *pending[PS_MAP_COUNT];  /* indices to retrace first, ascending */
    size_t pending_count[PS_MAP_COUNT], pending_done[PS_MAP_COUNT];
    size_t kept_end[PS_MAP_COUNT];
    uint64_t repair_end[PS_MAP_COUNT];
    bool repairing[PS_MAP_COUNT];
    /* A merge made ready by the thread at its end (prepare_map), swapped in
     * when the drawing side asks (commit_map): the copying off the next
     * edit's update, the swap when it costs the picture nothing
     * (ps_feed_merge). */
    bool prepared[PS_MAP_COUNT];
    ps_photon_map merged[PS_MAP_COUNT];
    ps_feed_mark *merged_marks[PS_MAP_COUNT];
    size_t merged_nmarks[PS_MAP_COUNT];
    ps_path_thr *merged_thr[PS_MAP_COUNT];
    uint64_t generation;            /* under lock */
    ps_feed_repair_count repair;    /* under lock: what the repair that made this feed kept */
    /* A repair's keep tests and copies still to do (repair_step): only the
     * indices the first picture draws are repaired before it, the rest by
     * the thread before it retraces anything. */
    repair_work work[PS_MAP_COUNT];
    ps_aabb *moved;                 /* the moved objects' boxes, old and new places */
    size_t moved_count;
    ps_path_quant quant;
};

/* Indices a keep job tests (a few milliseconds of path tests). */
#define KEEP_JOB_INDICES 65536
/* Indices the thread repairs between two looks at pause and stop: two keep
 * jobs, one a core (some 10 ms). */
#define REPAIR_STEP_INDICES (2 * KEEP_JOB_INDICES)

static void repair_work_free(repair_work *w);

/* Path record flags (ps_path_rec.flags). */
#define REC_PENDING 1u  /* to retrace: its photons are not in the map */
#define REC_RETRACED 2u /* retraced: its photons are in the retraced run */

ps_status ps_feed_create(ps_tracer *t, const uint64_t caps[PS_MAP_COUNT], const bool active[PS_MAP_COUNT],
                         ps_feed **out, ps_error *err)
{
    *out = NULL;
    ps_feed *f = calloc(1, sizeof *f);
    if (!f)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the photon feed");
    f->tracer = t;
    f->records = ps_tracer_records(t);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        f->cap[k] = caps[k];
        f->active[k] = active[k] && caps[k] > 0;
        ps_photon_map_init(&f->maps[k], (ps_map_kind)k);
        f->ahead[k] = SIZE_MAX;
    }
    pthread_mutex_init(&f->lock, NULL);
    pthread_cond_init(&f->wake, NULL);
    pthread_cond_init(&f->idle, NULL);
    *out = f;
    return PS_OK;
}

static ps_status hand_over(ps_feed *f, int k, ps_traced *traced, const uint64_t *idx, ps_error *err);
static ps_status merge(ps_feed *f, ps_error *err);
static ps_status repair_all(ps_feed *f, ps_error *err);
static ps_status prepare_map(ps_feed *f, int k, ps_error *err);

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
    return hand_over(f, k, traced, NULL, err);
}

/* Joins a traced range (idx NULL) or list of indices to map k, with their
 * path records, under the lock. */
static ps_status hand_over(ps_feed *f, int k, ps_traced *traced, const uint64_t *idx, ps_error *err)
{
    ps_status st = PS_OK;
    if (f->records) {
        ps_error perr;
        bool repairing = false;
        for (int j = 0; j < PS_MAP_COUNT; j++)
            repairing = repairing || f->repairing[j];
        if (ps_traced_join_paths(traced, &f->paths[k], idx, &perr) != PS_OK) {
            if (repairing) {
                /* A map in repair order needs its records to be put back in
                 * order: this is out of memory like the photons. */
                ps_traced_destroy(traced);
                *err = perr;
                return perr.status;
            }
            /* No room for the records: go on without them (edits restart). */
            pthread_mutex_lock(&f->lock);
            f->records = false;
            for (int j = 0; j < PS_MAP_COUNT; j++)
                ps_path_store_free(&f->paths[j]);
            pthread_mutex_unlock(&f->lock);
        }
    }
    pthread_mutex_lock(&f->lock);
    uint64_t emitted = f->maps[k].counters.emitted;
    if (!PS_RESERVE(f->marks[k], f->mark_cap[k], f->mark_count[k] + 1) ||
        ps_traced_join(traced, &f->maps[k], err) != PS_OK)
        st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for %llu more photons",
                          (unsigned long long)ps_traced_count(traced));
    if (st == PS_OK) {
        /* Retraced photons stand for indices already counted as emitted. */
        if (idx)
            f->maps[k].counters.emitted = emitted;
        ps_feed_mark m = {f->maps[k].count, f->maps[k].counters.emitted};
        f->marks[k][f->mark_count[k]++] = m;
    }
    pthread_mutex_unlock(&f->lock);
    ps_traced_destroy(traced);
    return st;
}

/* Map k's share of a round's PS_FEED_BATCH photons (of the largest cap):
 * maps keep pace with each other, as in round_once. */
static uint64_t batch_of(const ps_feed *f, int k)
{
    uint64_t biggest = 0;
    for (int j = 0; j < PS_MAP_COUNT; j++)
        if (f->active[j] && f->cap[j] > biggest)
            biggest = f->cap[j];
    double n = biggest ? (double)PS_FEED_BATCH * (double)f->cap[k] / (double)biggest : PS_FEED_BATCH;
    return n < 1.0 ? 1 : (uint64_t)n;
}

/* Map k's next round of indices, traced: round_end's share of them. */
static uint64_t round_end(const ps_feed *f, int k, uint64_t r, uint64_t prev_end);
static ps_status trace_round(ps_feed *f, int k, ps_error *err)
{
    uint64_t until = round_end(f, k, f->round[k], f->next[k]);
    ps_status st = batch(f, k, f->next[k], until - f->next[k], err);
    f->next[k] = until;
    f->round[k]++;
    return st;
}

/* The next batch of map k's pending indices, retraced. */
static ps_status retrace_batch(ps_feed *f, int k, ps_error *err)
{
    size_t from = f->pending_done[k], n = f->pending_count[k] - from;
    if (n > batch_of(f, k))
        n = (size_t)batch_of(f, k);
    const uint64_t *idx = f->pending[k] + from;
    ps_traced *traced;
    ps_status st = ps_tracer_trace_list(f->tracer, (ps_map_kind)k, idx, n, f->cap[k], f->maps[k].count, &traced,
                                        err);
    if (st == PS_ERR_LIMIT) {
        pthread_mutex_lock(&f->lock);
        f->store_limited = true;
        pthread_mutex_unlock(&f->lock);
        return PS_OK;
    }
    if (st == PS_OK)
        st = hand_over(f, k, traced, idx, err);
    if (st == PS_OK) {
        for (size_t j = 0; f->records && j < n; j++)
            f->paths[k].rec[idx[j]].flags = REC_RETRACED;
        f->pending_done[k] = from + n;
    }
    return st;
}

/* Where round r of map k ends (the index past its last photon), given where
 * the round before ended: its share of r + 1 rounds of PS_FEED_BATCH photons
 * of the largest cap, at least one more. */
static uint64_t round_end(const ps_feed *f, int k, uint64_t r, uint64_t prev_end)
{
    uint64_t biggest = 0;
    for (int j = 0; j < PS_MAP_COUNT; j++)
        if (f->active[j] && f->cap[j] > biggest)
            biggest = f->cap[j];
    double share = (double)(r + 1) * PS_FEED_BATCH / (double)biggest;
    uint64_t until = share >= 1.0 ? f->cap[k] : (uint64_t)((double)f->cap[k] * share);
    return until <= prev_end ? prev_end + 1 : until;
}

static bool repair_left(const ps_feed *f);
static ps_status repair_step(ps_feed *f, int k, uint64_t until, ps_error *err);

/* One round: each active map up to its share of the next PS_FEED_BATCH
 * photons of the largest cap, so that all maps finish together. False when
 * every map has reached its cap (or on an error, in *st). */
static bool round_once(ps_feed *f, ps_status *st, ps_error *err)
{
    /* A repair first tests and copies what the first picture did not need. */
    if (repair_left(f)) {
        for (int k = 0; k < PS_MAP_COUNT && *st == PS_OK; k++)
            if (f->work[k].active)
                *st = repair_step(f, k, f->work[k].next + REPAIR_STEP_INDICES, err);
        return *st == PS_OK;
    }
    /* Only this thread appends, so the counts can be read without the lock. */
    if (f->max_stored && f->maps[PS_MAP_CAUSTIC].count + f->maps[PS_MAP_GLOBAL].count >= f->max_stored) {
        pthread_mutex_lock(&f->lock);
        f->store_limited = true;
        pthread_mutex_unlock(&f->lock);
        return false;
    }
    /* A repair first retraces what the edit changed (a map that starts
     * over: up to where it was), then goes on. */
    bool repairing = false;
    for (int k = 0; k < PS_MAP_COUNT && *st == PS_OK; k++)
        if (f->pending_done[k] < f->pending_count[k]) {
            *st = retrace_batch(f, k, err);
            repairing = true;
        } else if (f->next[k] < f->restart_end[k]) {
            *st = trace_round(f, k, err);
            repairing = true;
        }
    if (repairing)
        return *st == PS_OK && !f->store_limited;
    bool more = false;
    for (int k = 0; k < PS_MAP_COUNT && *st == PS_OK; k++) {
        if (!f->active[k] || f->next[k] >= f->cap[k])
            continue;
        *st = trace_round(f, k, err);
        more = more || f->next[k] < f->cap[k];
    }
    /* Only this thread sets it, so it can be read without the lock. */
    return more && *st == PS_OK && !f->store_limited;
}

/* Under the lock: a map at its ps_feed_set_ahead bound (only the background
 * thread waits for one: ps_feed_run's caller draws nothing meanwhile). */
static bool too_far_ahead(const ps_feed *f)
{
    if (!f->threaded)
        return false;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (f->maps[k].count >= f->ahead[k])
            return true;
    return false;
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
        while ((f->paused || too_far_ahead(f)) && !f->stop) {
            f->waiting = true;
            pthread_cond_broadcast(&f->idle);
            pthread_cond_wait(&f->wake, &f->lock);
        }
        f->waiting = false;
        bool stop = f->stop;
        pthread_mutex_unlock(&f->lock);
        if (stop)
            break;
        more = round_once(f, &st, &err);
    }
    /* Every photon traced: the maps back in index order, as a fresh trace
     * of the edited scene has them. The background thread leaves the swap
     * to ps_feed_merge: a merge reorders what an incremental picture has drawn
     * only in part, which then starts over from one batch (a picture that
     * got worse a quarter of a second after an edit, and took seconds to
     * come back); the drawing side merges once it has drawn every photon,
     * or is starting over anyway. */
    pthread_mutex_lock(&f->lock);
    bool stopped = f->stop;
    pthread_mutex_unlock(&f->lock);
    if (st == PS_OK && !stopped && !f->threaded)
        st = merge(f, &err);
    /* ... but makes it ready, off the drawing side's time. */
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK && !stopped && f->threaded; k++)
        st = prepare_map(f, k, &err);
    pthread_mutex_lock(&f->lock);
    f->status = st;
    f->err = err;
    f->ended = true;
    f->seconds += ps_now_seconds() - t0;
    pthread_cond_broadcast(&f->idle);
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
    f->threaded = true;
    if (pthread_create(&f->thread, NULL, feed_main, f) != 0) {
        f->threaded = false;
        return ps_error_set(err, PS_ERR_NOMEM, "could not start the photon tracing thread");
    }
    f->started = true;
    return PS_OK;
}

static void stop_thread(ps_feed *f)
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

void ps_feed_stop(ps_feed *f)
{
    stop_thread(f);
    /* Stopped during a repair: the maps in index order all the same (the
     * photons not yet retraced are missing), as a dump must have them. */
    if (f->status == PS_OK) {
        ps_error err;
        ps_status st = merge(f, &err);
        if (st != PS_OK) {
            pthread_mutex_lock(&f->lock);
            f->status = st;
            f->err = err;
            pthread_mutex_unlock(&f->lock);
        }
    }
}

static ps_status repair_abandon(ps_feed *f, int k, ps_error *err);

void ps_feed_stop_unmerged(ps_feed *f)
{
    stop_thread(f);
    if (f->status == PS_OK) {
        ps_error err;
        ps_status st = PS_OK;
        for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++)
            st = repair_abandon(f, k, &err);
        if (st != PS_OK) {
            pthread_mutex_lock(&f->lock);
            f->status = st;
            f->err = err;
            pthread_mutex_unlock(&f->lock);
        }
    }
}

void ps_feed_pause(ps_feed *f, bool paused)
{
    pthread_mutex_lock(&f->lock);
    f->paused = paused;
    pthread_cond_broadcast(&f->wake);
    pthread_mutex_unlock(&f->lock);
}

void ps_feed_set_ahead(ps_feed *f, const size_t most[PS_MAP_COUNT])
{
    pthread_mutex_lock(&f->lock);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        f->ahead[k] = most[k];
    pthread_cond_broadcast(&f->wake);
    pthread_mutex_unlock(&f->lock);
}

void ps_feed_hold_idle(ps_feed *f)
{
    pthread_mutex_lock(&f->lock);
    f->paused = true;
    pthread_cond_broadcast(&f->wake);
    while (f->started && !f->ended && !f->waiting)
        pthread_cond_wait(&f->idle, &f->lock);
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
    stop_thread(f);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        ps_photon_map_free(&f->maps[k]);
        free(f->marks[k]);
        ps_path_store_free(&f->paths[k]);
        free(f->pending[k]);
        repair_work_free(&f->work[k]);
        if (f->prepared[k]) {
            ps_photon_map_free(&f->merged[k]);
            free(f->merged_marks[k]);
            free(f->merged_thr[k]);
        }
    }
    free(f->moved);
    pthread_cond_destroy(&f->wake);
    pthread_cond_destroy(&f->idle);
    pthread_mutex_destroy(&f->lock);
    free(f);
}

/* ---- selective repair ----------------------------------------------------------- */

static bool compact_paths(ps_path_store *p)
{
    size_t used = 0;
    for (size_t i = 0; i < p->count; i++)
        used += p->rec[i].vertices;
    return 2 * used >= p->vcount || ps_path_store_compact(p);
}

/* Map k back in index order, made ready beside the map: the kept run and
 * the retraced run interleaved by index (pending indices have no photons),
 * then the rest. Under the feed's thread or with it stopped, the map no
 * longer growing; it reads only. */
static ps_status prepare_map(ps_feed *f, int k, ps_error *err)
{
    if (!f->repairing[k] || f->prepared[k])
        return PS_OK;
    ps_photon_map *m = &f->maps[k];
    ps_photon_map out;
    ps_photon_map_init(&out, (ps_map_kind)k);
    if (!ps_photon_map_reserve_exact(&out, m->count ? m->count : 1))
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory reordering %zu photons", m->count);
    /* The marks made again where a fresh feed's rounds end (round_end), so
     * that whatever reads a prefix of the map by its marks (a refresh's
     * budget, the specular layer's cube maps) reads what it would from a
     * fresh trace: the repair's own marks stand for its order. */
    ps_feed_mark *marks = malloc((f->mark_count[k] + f->repair_end[k] / batch_of(f, k) + 2) * sizeof *marks);
    if (!marks) {
        ps_photon_map_free(&out);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory reordering %zu photons", m->count);
    }
    /* The throughputs go with the photons (path_record.h). */
    ps_path_thr *thr = malloc((m->count ? m->count : 1) * sizeof *thr);
    if (!thr) {
        free(marks);
        ps_photon_map_free(&out);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory reordering %zu photons", m->count);
    }
    const ps_path_thr *old_thr = f->paths[k].thr;
    size_t nmarks = 0;
    uint64_t r = 0, boundary = round_end(f, k, 0, 0);
    size_t kept = 0, re = f->kept_end[k];
    const ps_path_rec *rec = f->paths[k].rec;
    for (uint64_t i = 0; i < f->repair_end[k]; i++) {
        if (!(rec[i].flags & REC_PENDING)) {
            size_t *from = (rec[i].flags & REC_RETRACED) ? &re : &kept;
            size_t n = rec[i].stored;
            memcpy(out.photons + out.count, m->photons + *from, n * sizeof *m->photons);
            memcpy(out.materials + out.count, m->materials + *from, n * sizeof *m->materials);
            memcpy(out.objects + out.count, m->objects + *from, n * sizeof *m->objects);
            memcpy(thr + out.count, old_thr + *from, n * sizeof *thr);
            out.count += n;
            *from += n;
        }
        if (i + 1 == boundary) {
            marks[nmarks++] = (ps_feed_mark){out.count, boundary};
            boundary = round_end(f, k, ++r, boundary);
        }
    }
    /* Past the repair the feed's own rounds went on as a fresh one's (the
     * retraced first, so a mark there counts what index order counts). */
    for (size_t j = 0; j < f->mark_count[k]; j++)
        if (f->marks[k][j].emitted > f->repair_end[k])
            marks[nmarks++] = f->marks[k][j];
    /* Those traced past the repair follow in order. */
    size_t rest = m->count - re;
    memcpy(out.photons + out.count, m->photons + re, rest * sizeof *m->photons);
    memcpy(out.materials + out.count, m->materials + re, rest * sizeof *m->materials);
    memcpy(out.objects + out.count, m->objects + re, rest * sizeof *m->objects);
    memcpy(thr + out.count, old_thr + re, rest * sizeof *thr);
    out.count += rest;
    out.counters = m->counters;
    if (nmarks == 0 || marks[nmarks - 1].emitted != m->counters.emitted) /* stopped mid-round */
        marks[nmarks++] = (ps_feed_mark){m->count, m->counters.emitted};
    f->merged[k] = out;
    f->merged_marks[k] = marks;
    f->merged_nmarks[k] = nmarks;
    f->merged_thr[k] = thr;
    f->prepared[k] = true;
    return PS_OK;
}

/* The prepared map k swapped in (under the lock), its records made plain. */
static ps_status commit_map(ps_feed *f, int k, ps_error *err)
{
    if (!f->prepared[k])
        return PS_OK;
    ps_photon_map *m = &f->maps[k];
    free(f->paths[k].thr);
    f->paths[k].thr = f->merged_thr[k];
    f->paths[k].tcap = f->merged[k].count ? f->merged[k].count : 1;
    f->paths[k].tcount = f->merged[k].count;
    pthread_mutex_lock(&f->lock);
    ps_photon_map_free(m);
    *m = f->merged[k];
    free(f->marks[k]);
    f->marks[k] = f->merged_marks[k];
    f->mark_count[k] = f->mark_cap[k] = f->merged_nmarks[k];
    f->generation++;
    pthread_mutex_unlock(&f->lock);
    f->prepared[k] = false;
    f->merged_marks[k] = NULL;
    f->merged_thr[k] = NULL;
    for (uint64_t i = 0; i < f->repair_end[k]; i++)
        f->paths[k].rec[i].flags &= (uint8_t)~REC_RETRACED;
    if (!compact_paths(&f->paths[k]))
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for path records");
    f->kept_end[k] = m->count;
    f->repairing[k] = false;
    return PS_OK;
}

/* Puts map k back in index order now. */
static ps_status merge_map(ps_feed *f, int k, ps_error *err)
{
    ps_status st = prepare_map(f, k, err);
    return st == PS_OK ? commit_map(f, k, err) : st;
}

static ps_status merge(ps_feed *f, ps_error *err)
{
    /* Not on the feed's thread: it has ended, or was stopped, or not started. */
    ps_status st = repair_all(f, err);
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++)
        st = merge_map(f, k, err);
    return st;
}

ps_status ps_feed_retrace_first(ps_feed *f, uint64_t max_photons, ps_error *err)
{
    /* The pending count is known once every index is tested. */
    if (repair_left(f))
        return PS_OK;
    uint64_t pending = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        pending += f->pending_count[k] - f->pending_done[k] +
                   (f->next[k] < f->restart_end[k] ? f->restart_end[k] - f->next[k] : 0);
    /* All or nothing: a part would cost the first picture its time and
     * still leave a hole (and a merge) to the thread. */
    if (pending > max_photons)
        return PS_OK;
    double t0 = ps_now_seconds();
    ps_status st = PS_OK;
    /* Rounds as the thread's: a batch of each map's pending indices. */
    for (bool more = true; more && st == PS_OK && !f->store_limited;) {
        more = false;
        for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++)
            if (f->pending_done[k] < f->pending_count[k]) {
                st = retrace_batch(f, k, err);
                more = true;
            } else if (f->next[k] < f->restart_end[k]) {
                st = trace_round(f, k, err);
                more = true;
            }
    }
    bool left = false;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        left = left || f->pending_done[k] < f->pending_count[k] || f->next[k] < f->restart_end[k];
    /* Nothing left to retrace: in index order at once, so that the
     * picture never needs to start over for it. */
    if (st == PS_OK && !left)
        st = merge(f, err);
    f->seconds += ps_now_seconds() - t0;
    return st;
}

bool ps_feed_merge_pending(const ps_feed *f)
{
    if (!f->ended || f->status != PS_OK)
        return false;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (f->repairing[k])
            return true;
    return false;
}

ps_status ps_feed_merge(ps_feed *f, ps_error *err)
{
    pthread_mutex_lock(&f->lock);
    bool pending = ps_feed_merge_pending(f);
    pthread_mutex_unlock(&f->lock);
    if (!pending)
        return PS_OK;
    /* The thread has ended: nothing else touches the maps but under the
     * lock merge_map takes to swap them. */
    ps_status st = merge(f, err);
    if (st != PS_OK) {
        pthread_mutex_lock(&f->lock);
        f->status = st;
        f->err = *err;
        pthread_mutex_unlock(&f->lock);
    }
    return st;
}

bool ps_feed_repairable(const ps_feed *f)
{
    if (!f->records || f->status != PS_OK || f->store_limited || f->started || repair_left(f))
        return false;
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (f->active[k] && f->paths[k].count != f->next[k])
            return false;
    return true;
}

/* The keep tests of a repair (every kept source's path against the moved
 * boxes: most of an update's time at 10^6 photons), each job over a fixed
 * range of indices: a flag an index, the same whatever the thread count. */
typedef struct keep_job {
    const ps_feed *f;
    const ps_photon_source *src; /* src[i - from] */
    const ps_path_store *pool;  /* the vertices */
    const ps_path_rec *rec;     /* the old records */
    uint64_t from, to, end;
    uint8_t *kept;              /* kept[i - from] */
} keep_job;

static void keep_range(void *arg, size_t job)
{
    const keep_job *j = arg;
    const ps_feed *f = j->f;
    uint64_t from = j->from + (uint64_t)job * KEEP_JOB_INDICES;
    uint64_t to = from + KEEP_JOB_INDICES < j->to ? from + KEEP_JOB_INDICES : j->to;
    for (uint64_t i = from; i < to; i++) {
        uint64_t o = j->src[i - j->from].from;
        bool keep = o < j->end && !(j->rec[o].flags & REC_PENDING);
        for (size_t m = 0; keep && m < f->moved_count; m++)
            keep = !ps_path_meets(j->pool, &j->rec[o], &f->quant, f->moved[m]);
        j->kept[i - j->from] = keep;
    }
}

static void repair_work_free(repair_work *w)
{
    ps_source_map_destroy(w->sources);
    free(w->src), free(w->off), free(w->kept);
    w->sources = NULL, w->src = NULL, w->off = NULL, w->kept = NULL;
    if (!w->in_place) {
        ps_photon_map_free(&w->old_map);
        ps_path_store_free(&w->old_paths);
    }
    w->active = false;
}

/* Map k of the repaired feed f from the old one's (in index order, with
 * complete records): photon i of the edited scene will take the photons and
 * record of the old index its source names, when no segment of that path
 * meets a moved box, with their power set anew; the others' indices go to
 * the pending list. Here only the sources and the arrays: repair_step does
 * the rest, index range by index range. */
static ps_status repair_begin(ps_feed *f, ps_feed *old, int k, const ps_feed_repair_fns *fns, ps_error *err)
{
    ps_photon_map *om = &old->maps[k];
    ps_path_store *op = &old->paths[k];
    uint64_t end = old->next[k];
    f->next[k] = end;
    f->repair_end[k] = end;
    if (!f->active[k] || end == 0)
        return PS_OK;
    if (op->tcount != om->count || op->count != end)
        return ps_error_set(err, PS_ERR_NOMEM, "the %s map's path records are incomplete", ps_map_name((ps_map_kind)k));
    repair_work *w = &f->work[k];
    ps_source_map *sources;
    ps_status st = fns->sources(fns->ctx, (ps_map_kind)k, end, &sources, err);
    if (st != PS_OK)
        return st;
    if (ps_source_map_none(sources)) {
        /* Nothing to keep (every light of the map moved): the map starts
         * over from photon 0 as a fresh feed's, with no paths to test and
         * no list of indices to retrace, and in index order throughout. */
        ps_source_map_destroy(sources);
        f->next[k] = f->repair_end[k] = 0;
        f->restart_end[k] = end;
        f->round[k] = 0;
        f->repair.retraced[k] = end;
        return PS_OK;
    }
    w->sources = sources;
    size_t step = end < REPAIR_STEP_INDICES ? (size_t)end : REPAIR_STEP_INDICES;
    w->src = malloc(step * sizeof *w->src);
    w->off = malloc((end + 1) * sizeof *w->off);
    w->kept = malloc(step);
    if (!w->src || !w->off || !w->kept) {
        free(w->src), free(w->off), free(w->kept);
        w->src = NULL, w->off = NULL, w->kept = NULL;
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for a repair of %llu photons", (unsigned long long)end);
    }
    w->active = true;
    w->end = end;
    /* Every kept photon at its own index (the plans cut the same strata: a
     * diffuse object moved, a power edit of a lone light): compact in
     * place, as the map's kept photons only move down. Else gather into
     * new arrays. */
    w->in_place = ps_source_map_identity(w->sources) && !old->repairing[k];
    ps_photon_map *m = &f->maps[k];
    ps_path_store *np = &f->paths[k];
    size_t room = om->count ? om->count : 1;
    if (w->in_place) {
        *m = *om, *np = *op;
    } else {
        w->old_map = *om, w->old_paths = *op;
        if (!ps_photon_map_reserve_exact(m, room) || !ps_path_store_reserve(np, end) ||
            !PS_RESERVE(np->thr, np->tcap, room))
            st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for a repair of %llu photons", (unsigned long long)end);
        /* The kept records point into the old pool: take it whole; the pool
         * is rewritten once half of it is garbage, so it stays within twice
         * what the records use (the soak's memory stays flat over hundreds
         * of edits). */
        np->vert = op->vert, np->vcount = op->vcount, np->vcap = op->vcap;
        w->old_paths.vert = NULL, w->old_paths.vcount = w->old_paths.vcap = 0;
    }
    ps_photon_map_init(om, (ps_map_kind)k), ps_path_store_init(op);
    if (st != PS_OK)
        return st;
    const ps_path_rec *orec = w->in_place ? np->rec : w->old_paths.rec;
    if (!old->repairing[k]) {
        w->off[0] = 0;
        for (uint64_t i = 0; i < end; i++)
            w->off[i + 1] = w->off[i] + ((orec[i].flags & REC_PENDING) ? 0 : orec[i].stored);
    } else {
        /* The old map still in its own repair order (prepare_map's): the
         * kept run, the retraced run from kept_end, then what was traced
         * past its repair. Read where it lies, not merged first: the merge
         * was 0.01-0.03 s of an update at 10^6 photons. */
        size_t kept = 0, re = old->kept_end[k];
        for (uint64_t i = 0; i < end; i++) {
            size_t *at = i >= old->repair_end[k] || (orec[i].flags & REC_RETRACED) ? &re : &kept;
            w->off[i] = *at;
            if (!(orec[i].flags & REC_PENDING))
                *at += orec[i].stored;
        }
        if (kept != old->kept_end[k] || re != w->old_map.count)
            return ps_error_set(err, PS_ERR_NOMEM, "the %s map's path records are incomplete",
                                ps_map_name((ps_map_kind)k));
    }
    /* Counters: every index below `end` counts as emitted (the pending
     * ones are on their way); what the paths did is counted anew. */
    memset(&m->counters, 0, sizeof m->counters);
    m->counters.emitted = end;
    m->count = 0;
    return PS_OK;
}

/* The end of map k's repair: its records and counts. */
static ps_status repair_finish(ps_feed *f, int k, ps_error *err)
{
    repair_work *w = &f->work[k];
    ps_photon_map *m = &f->maps[k];
    ps_path_store *np = &f->paths[k];
    uint64_t end = w->end;
    size_t at = f->pending_count[k];
    np->count = end;
    np->tcount = w->to;
    repair_work_free(w);
    if (!compact_paths(np))
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for path records");
    pthread_mutex_lock(&f->lock);
    bool room = PS_RESERVE(f->marks[k], f->mark_cap[k], f->mark_count[k] + 1);
    if (room)
        f->marks[k][f->mark_count[k]++] = (ps_feed_mark){m->count, end};
    f->repair.kept[k] = end - at;
    f->repair.retraced[k] = at;
    f->repair.kept_photons[k] = m->count;
    f->kept_end[k] = m->count;
    f->repairing[k] = at > 0;
    pthread_mutex_unlock(&f->lock);
    return room ? PS_OK : ps_error_set(err, PS_ERR_NOMEM, "out of memory for the photon feed");
}

/* Map k's repair over indices up to `until` (at most its end): the keep
 * tests on every core (the window keeps one for drawing, but the first
 * picture after an edit waits for them: 0.04-0.05 s for the default scene's
 * 10^6 caustic paths on one core), then the kept photons copied, a mark
 * every batch of indices, handed over under the lock. */
static ps_status repair_step(ps_feed *f, int k, uint64_t until, ps_error *err)
{
    repair_work *w = &f->work[k];
    if (!w->active)
        return PS_OK;
    if (until > w->end)
        until = w->end;
    ps_photon_map *m = &f->maps[k];
    ps_path_store *np = &f->paths[k];
    const ps_photon_map *om = w->in_place ? m : &w->old_map;
    const ps_path_store *op = w->in_place ? np : &w->old_paths;
    const ps_path_rec *orec = op->rec;
    const size_t *off = w->off;
    size_t to = w->to, at = f->pending_count[k];
    uint64_t every = batch_of(f, k);
    ps_status st = PS_OK;
    /* REPAIR_STEP_INDICES at a time: the sources found, the paths tested,
     * the kept photons copied. */
    for (uint64_t from = w->next; from < until && st == PS_OK;) {
        uint64_t part = until - from < REPAIR_STEP_INDICES ? until - from : REPAIR_STEP_INDICES;
        ps_source_map_fill(w->sources, from, from + part, w->src);
        keep_job job = {f, w->src, np, orec, from, from + part, w->end, w->kept};
        ps_run_jobs((size_t)((part + KEEP_JOB_INDICES - 1) / KEEP_JOB_INDICES), ps_online_cores(), keep_range, &job);
        for (uint64_t i = from; i < from + part && st == PS_OK; i++) {
            const ps_photon_source *src = &w->src[i - from];
            uint64_t o = src->from;
            ps_path_rec *r = &np->rec[i];
            if (w->kept[i - from]) {
                size_t n = orec[o].stored;
                /* In place, source and destination may overlap (to <= off[o]). */
                if (n == 1) { /* most paths: plain copies, no calls */
                    m->photons[to] = om->photons[off[o]];
                    m->materials[to] = om->materials[off[o]];
                    m->objects[to] = om->objects[off[o]];
                    np->thr[to] = op->thr[off[o]];
                } else if (!w->in_place || to != off[o]) {
                    memmove(m->photons + to, om->photons + off[o], n * sizeof *m->photons);
                    memmove(m->materials + to, om->materials + off[o], n * sizeof *m->materials);
                    memmove(m->objects + to, om->objects + off[o], n * sizeof *m->objects);
                    memmove(np->thr + to, op->thr + off[o], n * sizeof *np->thr);
                }
                /* The same path, maybe of a light with another power, maybe one of
                 * more or fewer photons of its stratum: its power set anew, as
                 * the edited scene's trace sets it. */
                if (src->repower)
                    ps_tracer_repower(f->tracer, (ps_map_kind)k, src, np->thr + to, n, m->photons + to);
                if (r != &orec[o])
                    *r = orec[o];
                r->flags = 0;
                to += n;
            } else if (!PS_RESERVE(f->pending[k], w->pending_cap, at + 1)) {
                st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for a repair of %zu photons", at);
            } else {
                memset(r, 0, sizeof *r);
                r->flags = REC_PENDING;
                f->pending[k][at++] = i;
            }
            /* A mark every batch of indices: the kept photons of indices below
             * i + 1 stand for all of them, so a refresh that draws only its
             * budget draws a prefix of the kept ones, scaled right. */
            if ((i + 1) % every == 0 && i + 1 < w->end) {
                pthread_mutex_lock(&f->lock);
                bool room = PS_RESERVE(f->marks[k], f->mark_cap[k], f->mark_count[k] + 1);
                if (room) {
                    m->count = to;
                    m->counters.stored = to;
                    f->marks[k][f->mark_count[k]++] = (ps_feed_mark){to, i + 1};
                }
                pthread_mutex_unlock(&f->lock);
                if (!room)
                    st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for the photon feed");
            }
        }
        from += part;
    }
    f->pending_count[k] = at;
    w->to = to;
    w->next = until;
    pthread_mutex_lock(&f->lock);
    m->count = to;
    m->counters.stored = to;
    pthread_mutex_unlock(&f->lock);
    if (st == PS_OK && w->next == w->end)
        st = repair_finish(f, k, err);
    return st;
}

/* Map k's repair ended where it is: the indices not yet tested go to the
 * list to retrace, their old photons dropped. The next edit's update then
 * need not finish the tests first: 0.09-0.1 s at 10^6 photons when two
 * edits came 0.05 s apart (a drag's), where the retrace is the thread's. */
static ps_status repair_abandon(ps_feed *f, int k, ps_error *err)
{
    repair_work *w = &f->work[k];
    if (!w->active)
        return PS_OK;
    ps_path_store *np = &f->paths[k];
    size_t at = f->pending_count[k];
    if (!PS_RESERVE(f->pending[k], w->pending_cap, at + (size_t)(w->end - w->next)))
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for a repair of %zu photons", at);
    for (uint64_t i = w->next; i < w->end; i++) {
        memset(&np->rec[i], 0, sizeof np->rec[i]);
        np->rec[i].flags = REC_PENDING;
        f->pending[k][at++] = i;
    }
    f->pending_count[k] = at;
    w->next = w->end;
    return repair_finish(f, k, err);
}

/* Whether a map's repair has indices left to test and copy. */
static bool repair_left(const ps_feed *f)
{
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (f->work[k].active)
            return true;
    return false;
}

/* Every map's repair done on the calling thread (the thread stopped, or not started). */
static ps_status repair_all(ps_feed *f, ps_error *err)
{
    ps_status st = PS_OK;
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++)
        if (f->work[k].active)
            st = repair_step(f, k, f->work[k].end, err);
    return st;
}

ps_status ps_feed_repair_ahead(ps_feed *f, const size_t min_photons[PS_MAP_COUNT], ps_error *err)
{
    double t0 = ps_now_seconds();
    ps_status st = PS_OK;
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++) {
        repair_work *w = &f->work[k];
        /* A batch of indices at a time: a mark each, so the kept photons
         * come in the steps a picture's budget reads. */
        uint64_t every = batch_of(f, k);
        while (st == PS_OK && w->active && f->maps[k].count < min_photons[k])
            st = repair_step(f, k, (w->next / every + 1) * every, err);
    }
    f->seconds += ps_now_seconds() - t0;
    return st;
}

ps_status ps_feed_create_repair(ps_tracer *t, ps_feed *old, const ps_feed_repair_fns *fns, ps_feed **out,
                                ps_error *err)
{
    *out = NULL;
    /* Old's own repair done (its records whole: ps_feed_stop_unmerged has
     * ended it); a map the thread made ready in index order swapped in; one
     * still in repair order is read as it lies (repair_begin). */
    ps_status st = repair_all(old, err);
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++)
        st = commit_map(old, k, err);
    if (st != PS_OK)
        return st;
    ps_feed *f;
    st = ps_feed_create(t, old->cap, old->active, &f, err);
    if (st != PS_OK)
        return st;
    f->max_stored = old->max_stored;
    memcpy(f->round, old->round, sizeof f->round);
    f->seconds = old->seconds;
    f->quant = fns->quant;
    f->moved_count = fns->moved_count;
    f->moved = malloc((fns->moved_count ? fns->moved_count : 1) * sizeof *f->moved);
    if (!f->moved)
        st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for a repair");
    else if (fns->moved_count)
        memcpy(f->moved, fns->moved, fns->moved_count * sizeof *f->moved);
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++)
        st = repair_begin(f, old, k, fns, err);
    if (st != PS_OK) {
        ps_feed_destroy(f);
        return st;
    }
    *out = f;
    return PS_OK;
}

ps_feed_repair_count ps_feed_repair_counts(ps_feed *f)
{
    pthread_mutex_lock(&f->lock);
    ps_feed_repair_count c = f->repair;
    pthread_mutex_unlock(&f->lock);
    return c;
}

uint64_t ps_feed_generation(const ps_feed *f) { return f->generation; }
