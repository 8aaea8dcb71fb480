/* dist.c: photosplat-ref's hooks on MPI (see dist.h). */
#include "dist/dist.h"

#include <fcntl.h>
#include <limits.h>
#include <mpi.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "core/clock.h"

/* Message tags of the tile phase. A finished tile's buffer goes with tag
 * TAG_TILE + its index, so the message is the floats alone. */
enum { TAG_REQUEST = 1, TAG_REPLY = 2, TAG_DONE = 3, TAG_TILE = 16 };
/* Rank 0's tile server polls for messages, sleeping between empty polls
 * from POLL_MIN_NS doubling up to POLL_MAX_NS: the other ranks keep their
 * requests ahead of their work, so the latency costs them nothing, and an
 * idle server takes no core from rank 0's own workers (a blocking receive
 * would spin on one). */
#define POLL_MIN_NS 20000L
#define POLL_MAX_NS 1000000L
/* A rank waiting for a collective or a reply polls the same way, up to
 * WAIT_MAX_NS: Open MPI's blocking calls spin, and on a machine with more
 * ranks than cores the spinning rank takes the core of the rank it waits
 * for (measured: the cache's exchanges took 3.8 s of a 13 s cache on 2
 * cores). */
#define WAIT_MAX_NS 200000L

_Static_assert(sizeof(ps_trace_counters) == 8 * sizeof(uint64_t), "the counters are summed as 8 uint64_t");

/* A cache record with its slot in the chunk, as exchanged. */
typedef struct slot_record {
    ps_irr_record rec;
    uint64_t slot;
} slot_record;

typedef struct dist {
    int rank, size;
    MPI_Comm comm;
    MPI_Datatype photon_type, record_type;
    int tag_ub;
    FILE *errlog; /* a non-root rank's stderr */
    bool failed;  /* an agreement failed: no more communication */
    ps_error failure;
    ps_ref_dist hooks;
    ps_render_share share;
    /* Figures for --stats. */
    double trace_seconds, merge_seconds, last_map_seconds, cache_exchange_seconds, cache_wait_seconds;
    double tiles_wait_seconds;
    uint64_t cache_chunks, cache_bytes;
    /* The cache exchange's buffers, kept between chunks. */
    slot_record *send, *recv;
    size_t record_cap;
    int *counts, *displs;
    /* The tile phase. */
    pthread_mutex_t lock;
    const ps_render_options *ro;
    int tiles;
    size_t floats;
    int next, done;     /* rank 0: tiles handed out, finished (all ranks) */
    bool stop;          /* rank 0: hand out no more (a rank stopped) */
    float *store;       /* rank 0: the other ranks' tile buffers */
    bool *have;         /* rank 0: which tiles store holds */
    int ranks_done;     /* rank 0: ranks that said they are done */
    pthread_t server;
    bool serving;
    int depth, head;    /* other ranks: requests kept in flight */
    MPI_Request *reqs;
    int *replies;
    bool finished;      /* other ranks: rank 0 has no more tiles */
    MPI_Request *sends; /* other ranks: tile buffers on their way */
    float **send_bufs;
    size_t send_count, send_cap;
} dist;

static void nap(long ns)
{
    struct timespec ts = {0, ns};
    nanosleep(&ts, NULL);
}

/* Completes a non-blocking operation without spinning (WAIT_MAX_NS). */
static void finish(MPI_Request *req)
{
    long wait = POLL_MIN_NS / 4;
    for (;;) {
        int flag = 0;
        MPI_Test(req, &flag, MPI_STATUS_IGNORE);
        if (flag)
            return;
        nap(wait);
        wait = wait * 2 > WAIT_MAX_NS ? WAIT_MAX_NS : wait * 2;
    }
}

/* The collectives used here, each completed by finish(). */
static void allreduce(dist *d, const void *in, void *out, int n, MPI_Datatype type, MPI_Op op)
{
    MPI_Request req;
    MPI_Iallreduce(in, out, n, type, op, d->comm, &req);
    finish(&req);
}

static void bcast(dist *d, void *buf, int n, MPI_Datatype type, int root)
{
    MPI_Request req;
    MPI_Ibcast(buf, n, type, root, d->comm, &req);
    finish(&req);
}

static void allgather(dist *d, const void *in, void *out, int n, MPI_Datatype type)
{
    MPI_Request req;
    MPI_Iallgather(in, n, type, out, n, type, d->comm, &req);
    finish(&req);
}

static void allgatherv(dist *d, const void *in, int n, void *out, const int *counts, const int *displs,
                       MPI_Datatype type)
{
    MPI_Request req;
    MPI_Iallgatherv(in, n, type, out, counts, displs, type, d->comm, &req);
    finish(&req);
}

/* ---- agreement ------------------------------------------------------------ */

/* Every rank's st: PS_OK when all succeeded, else the lowest failing rank's
 * error on every rank (prefixed with its rank when not 0). After a failure
 * there is no more communication: every rank leaves by the same path. */
static ps_status agree(dist *d, ps_status st, ps_error *err)
{
    if (d->failed) {
        if (err)
            *err = d->failure;
        return d->failure.status;
    }
    int mine = st != PS_OK ? d->rank : d->size, first = d->size;
    allreduce(d, &mine, &first, 1, MPI_INT, MPI_MIN);
    if (first == d->size)
        return PS_OK;
    ps_error e;
    ps_error_clear(&e);
    if (d->rank == first) {
        if (err)
            e = *err;
        e.status = st;
    }
    bcast(d, &e, (int)sizeof e, MPI_BYTE, first);
    if (first != 0) {
        char msg[PS_ERROR_MSG_MAX];
        snprintf(msg, sizeof msg, "%s", e.msg);
        ps_status s = e.status;
        ps_error_set(&e, s, "rank %d: %s", first, msg);
    }
    d->failed = true;
    d->failure = e;
    if (err)
        *err = e;
    return e.status;
}

static ps_status hook_agree(void *user, ps_status st, ps_error *err) { return agree(user, st, err); }

/* ---- photons ---------------------------------------------------------------- */

/* The start of rank r's share of [0, total): equal shares, the first
 * total mod N ranks one more. */
static uint64_t share_start(uint64_t total, int r, int n)
{
    uint64_t q = total / (uint64_t)n, rem = total % (uint64_t)n;
    return q * (uint64_t)r + ((uint64_t)r < rem ? (uint64_t)r : rem);
}

/* Every rank's part joined in rank order into m (empty), on every rank. */
static ps_status merge(dist *d, const ps_photon_map *part, uint64_t max_stored, ps_photon_map *m, ps_error *err)
{
    uint64_t n = part->count, *all = malloc((size_t)d->size * sizeof *all);
    ps_status st = all && d->counts ? PS_OK : ps_error_set(err, PS_ERR_NOMEM, "out of memory joining the photon maps");
    if ((st = agree(d, st, err)) != PS_OK) {
        free(all);
        return st;
    }
    allgather(d, &n, all, 1, MPI_UINT64_T);
    uint64_t sum = 0;
    for (int r = 0; r < d->size; r++) {
        d->displs[r] = (int)sum;
        d->counts[r] = (int)all[r];
        sum += all[r];
    }
    free(all);
    /* The same figures on every rank: the same answer, no agreement needed. */
    if (max_stored && sum > max_stored)
        return ps_error_set(err, PS_ERR_LIMIT,
                            "the %s photon map would hold more than %llu photons, the most the memory budget allows",
                            ps_map_name(part->kind), (unsigned long long)max_stored);
    if (sum > INT_MAX)
        return ps_error_set(err, PS_ERR_LIMIT, "the %s photon map holds %llu photons, more than MPI joins (%d)",
                            ps_map_name(part->kind), (unsigned long long)sum, INT_MAX);
    st = ps_photon_map_reserve_exact(m, (size_t)sum) ? PS_OK
                                                      : ps_error_set(err, PS_ERR_NOMEM, "out of memory joining the photon maps");
    if ((st = agree(d, st, err)) != PS_OK)
        return st;
    allgatherv(d, part->photons, (int)n, m->photons, d->counts, d->displs, d->photon_type);
    allgatherv(d, part->materials, (int)n, m->materials, d->counts, d->displs, MPI_UINT16_T);
    allgatherv(d, part->objects, (int)n, m->objects, d->counts, d->displs, MPI_UINT32_T);
    m->count = (size_t)sum;
    ps_trace_counters c = part->counters;
    allreduce(d, MPI_IN_PLACE, &c, 8, MPI_UINT64_T, MPI_SUM);
    ps_trace_counters_add(&m->counters, &c);
    return PS_OK;
}

static ps_status hook_trace(void *user, ps_tracer *t, ps_map_kind kind, uint64_t total, uint64_t max_stored,
                            ps_photon_map *m, ps_error *err)
{
    dist *d = user;
    double t0 = ps_now_seconds();
    uint64_t first = share_start(total, d->rank, d->size), end = share_start(total, d->rank + 1, d->size);
    ps_photon_map part;
    ps_photon_map_init(&part, kind);
    ps_status st = ps_tracer_trace(t, kind, first, end - first, total, &part, err);
    double t1 = ps_now_seconds();
    if (st == PS_OK && m->count != 0)
        st = ps_error_set(err, PS_ERR_RANGE, "a distributed trace fills an empty map");
    st = agree(d, st, err);
    if (st == PS_OK)
        st = merge(d, &part, max_stored, m, err);
    ps_photon_map_free(&part);
    double t2 = ps_now_seconds();
    d->trace_seconds += t1 - t0;
    d->merge_seconds += t2 - t1;
    d->last_map_seconds = t2 - t0;
    return st;
}

/* ---- the irradiance cache ----------------------------------------------------- */

static ps_status hook_cache_exchange(void *user, ps_irr_record *chunk, bool *ok, size_t slots, bool cancelled,
                                     ps_error *err)
{
    dist *d = user;
    double t0 = ps_now_seconds();
    ps_status st = PS_OK;
    if (cancelled)
        st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted while making the irradiance cache");
    if (st == PS_OK && slots > d->record_cap) {
        free(d->send);
        free(d->recv);
        d->send = malloc(slots * sizeof *d->send);
        d->recv = malloc(slots * sizeof *d->recv);
        d->record_cap = d->send && d->recv ? slots : 0;
        if (!d->record_cap)
            st = ps_error_set(err, PS_ERR_NOMEM, "out of memory exchanging the irradiance cache");
    }
    int mine = 0;
    for (size_t s = 0; st == PS_OK && s < slots; s++)
        if (ok[s]) {
            d->send[mine].rec = chunk[s];
            d->send[mine++].slot = s;
        }
    st = agree(d, st, err);
    double t1 = ps_now_seconds();
    d->cache_wait_seconds += t1 - t0;
    if (st != PS_OK)
        return st;
    allgather(d, &mine, d->counts, 1, MPI_INT);
    int sum = 0;
    for (int r = 0; r < d->size; r++) {
        d->displs[r] = sum;
        sum += d->counts[r];
    }
    allgatherv(d, d->send, mine, d->recv, d->counts, d->displs, d->record_type);
    for (int i = 0; i < sum; i++)
        if (d->recv[i].slot < slots) {
            chunk[d->recv[i].slot] = d->recv[i].rec;
            ok[d->recv[i].slot] = true;
        }
    d->cache_chunks++;
    d->cache_bytes += (uint64_t)sum * sizeof(slot_record);
    d->cache_exchange_seconds += ps_now_seconds() - t0;
    return PS_OK;
}

/* ---- tiles ------------------------------------------------------------------------ */

static void report_progress(dist *d)
{
    if (d->ro->progress)
        d->ro->progress(d->ro->progress_user, (double)d->done / d->tiles);
}

/* Rank 0: a tile for whoever asks, or -1. Under d->lock. */
static int hand_out(dist *d) { return d->stop || d->next >= d->tiles ? -1 : d->next++; }

/* Rank 0: answers requests and takes tile buffers until every other rank
 * is done. The only thread of rank 0 that calls MPI while it runs. */
static void *serve(void *arg)
{
    dist *d = arg;
    long wait = POLL_MIN_NS;
    while (d->ranks_done < d->size - 1) {
        if (ps_cancelled(d->ro->cancel)) {
            pthread_mutex_lock(&d->lock);
            d->stop = true;
            pthread_mutex_unlock(&d->lock);
        }
        int flag = 0;
        MPI_Status ms;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, d->comm, &flag, &ms);
        if (!flag) {
            nap(wait);
            wait = wait * 2 > POLL_MAX_NS ? POLL_MAX_NS : wait * 2;
            continue;
        }
        wait = POLL_MIN_NS;
        int src = ms.MPI_SOURCE, tag = ms.MPI_TAG;
        if (tag == TAG_REQUEST) {
            MPI_Recv(NULL, 0, MPI_INT, src, tag, d->comm, MPI_STATUS_IGNORE);
            pthread_mutex_lock(&d->lock);
            int t = hand_out(d);
            pthread_mutex_unlock(&d->lock);
            MPI_Send(&t, 1, MPI_INT, src, TAG_REPLY, d->comm);
        } else if (tag == TAG_DONE) {
            int complete = 0;
            MPI_Recv(&complete, 1, MPI_INT, src, tag, d->comm, MPI_STATUS_IGNORE);
            pthread_mutex_lock(&d->lock);
            d->ranks_done++;
            if (!complete)
                d->stop = true;
            pthread_mutex_unlock(&d->lock);
        } else if (tag >= TAG_TILE && tag - TAG_TILE < d->tiles) {
            int t = tag - TAG_TILE;
            MPI_Recv(d->store + (size_t)t * d->floats, (int)d->floats, MPI_FLOAT, src, tag, d->comm,
                     MPI_STATUS_IGNORE);
            pthread_mutex_lock(&d->lock);
            if (!d->have[t]) {
                d->have[t] = true;
                d->done++;
                report_progress(d);
            }
            pthread_mutex_unlock(&d->lock);
        } else { /* nothing this protocol sends: take it and carry on */
            MPI_Recv(NULL, 0, MPI_BYTE, src, tag, d->comm, MPI_STATUS_IGNORE);
        }
    }
    return NULL;
}

/* Another rank: one more request to rank 0 in ring slot k. */
static void ask(dist *d, int k)
{
    MPI_Irecv(&d->replies[k], 1, MPI_INT, 0, TAG_REPLY, d->comm, &d->reqs[k]);
    MPI_Send(NULL, 0, MPI_INT, 0, TAG_REQUEST, d->comm);
}

static void free_tiles(dist *d)
{
    free(d->store);
    free(d->have);
    free(d->reqs);
    free(d->replies);
    free(d->sends);
    free(d->send_bufs);
    d->store = NULL;
    d->have = NULL;
    d->reqs = NULL;
    d->replies = NULL;
    d->sends = NULL;
    d->send_bufs = NULL;
    d->send_count = d->send_cap = 0;
}

static ps_status hook_tiles_begin(void *user, const ps_render_options *o, int tiles, size_t tile_floats,
                                  ps_error *err)
{
    dist *d = user;
    free_tiles(d); /* a previous render's */
    d->ro = o;
    d->tiles = tiles;
    d->floats = tile_floats;
    d->next = d->done = d->ranks_done = 0;
    d->stop = d->finished = d->serving = false;
    d->head = 0;
    ps_status st = PS_OK;
    if (tiles > d->tag_ub - TAG_TILE || tile_floats > INT_MAX)
        st = ps_error_set(err, PS_ERR_LIMIT, "%d tiles are more than this MPI's message tags count (%d)", tiles,
                          d->tag_ub - TAG_TILE);
    if (st == PS_OK && d->rank == 0) {
        d->store = malloc((size_t)tiles * tile_floats * sizeof *d->store);
        d->have = calloc((size_t)tiles, sizeof *d->have);
        if (!d->store || !d->have)
            st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for the other ranks' tiles");
    } else if (st == PS_OK) {
        d->depth = o->threads < 1 ? 1 : o->threads;
        d->reqs = malloc((size_t)d->depth * sizeof *d->reqs);
        d->replies = malloc((size_t)d->depth * sizeof *d->replies);
        if (!d->reqs || !d->replies)
            st = ps_error_set(err, PS_ERR_NOMEM, "out of memory for the tile requests");
    }
    if ((st = agree(d, st, err)) != PS_OK) {
        free_tiles(d);
        return st;
    }
    if (d->rank == 0)
        /* Without the thread, rank 0 serves after its own tiles: slower, never different. */
        d->serving = pthread_create(&d->server, NULL, serve, d) == 0;
    else
        for (int k = 0; k < d->depth; k++)
            ask(d, k);
    return PS_OK;
}

static int hook_next_tile(void *user)
{
    dist *d = user;
    pthread_mutex_lock(&d->lock);
    int t = -1;
    if (d->rank == 0) {
        t = hand_out(d);
    } else if (!d->finished) {
        double t0 = ps_now_seconds();
        finish(&d->reqs[d->head]);
        d->tiles_wait_seconds += ps_now_seconds() - t0;
        t = d->replies[d->head];
        if (t >= 0) {
            ask(d, d->head);
            d->head = (d->head + 1) % d->depth;
        } else {
            /* Every later answer is -1 too: collect them. */
            d->finished = true;
            for (int k = 1; k < d->depth; k++)
                finish(&d->reqs[(d->head + k) % d->depth]);
        }
    }
    pthread_mutex_unlock(&d->lock);
    return t;
}

static void hook_tile_done(void *user, int tile, const float *data)
{
    dist *d = user;
    pthread_mutex_lock(&d->lock);
    if (d->rank == 0) {
        d->done++;
        report_progress(d);
        pthread_mutex_unlock(&d->lock);
        return;
    }
    /* Sent from a copy, so the worker goes on at once; finished sends are
     * freed as later ones go out. */
    for (size_t k = 0; k < d->send_count;) {
        int flag = 0;
        MPI_Test(&d->sends[k], &flag, MPI_STATUS_IGNORE);
        if (flag) {
            free(d->send_bufs[k]);
            d->sends[k] = d->sends[--d->send_count];
            d->send_bufs[k] = d->send_bufs[d->send_count];
        } else {
            k++;
        }
    }
    float *copy = malloc(d->floats * sizeof *copy);
    if (copy && d->send_count == d->send_cap) {
        size_t cap = d->send_cap ? 2 * d->send_cap : 16;
        MPI_Request *r = realloc(d->sends, cap * sizeof *r);
        if (r)
            d->sends = r;
        float **b = r ? realloc(d->send_bufs, cap * sizeof *b) : NULL;
        if (b) {
            d->send_bufs = b;
            d->send_cap = cap;
        }
    }
    if (copy && d->send_count < d->send_cap) {
        memcpy(copy, data, d->floats * sizeof *copy);
        MPI_Isend(copy, (int)d->floats, MPI_FLOAT, 0, TAG_TILE + tile, d->comm, &d->sends[d->send_count]);
        d->send_bufs[d->send_count++] = copy;
    } else { /* no memory for a copy: wait for this one to go */
        free(copy);
        MPI_Send(data, (int)d->floats, MPI_FLOAT, 0, TAG_TILE + tile, d->comm);
    }
    pthread_mutex_unlock(&d->lock);
}

static ps_status hook_tiles_end(void *user, bool complete, uint64_t *rays, ps_error *err)
{
    dist *d = user;
    double t0 = ps_now_seconds();
    if (d->rank == 0) {
        if (d->serving)
            pthread_join(d->server, NULL);
        else
            serve(d);
        complete = complete && !d->stop && d->done == d->tiles;
    } else {
        /* A stopped rank may still have requests out: rank 0 answers them all. */
        if (!d->finished)
            for (int k = 0; k < d->depth; k++)
                finish(&d->reqs[(d->head + k) % d->depth]);
        for (size_t k = 0; k < d->send_count; k++) {
            finish(&d->sends[k]);
            free(d->send_bufs[k]);
        }
        d->send_count = 0;
        int c = complete;
        MPI_Send(&c, 1, MPI_INT, 0, TAG_DONE, d->comm);
    }
    d->tiles_wait_seconds += ps_now_seconds() - t0;
    ps_status st = PS_OK;
    if (!complete)
        st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %.0f %% of the image",
                          d->rank == 0 ? 100.0 * d->done / d->tiles : 0.0);
    if ((st = agree(d, st, err)) != PS_OK) {
        free_tiles(d);
        return st;
    }
    allreduce(d, MPI_IN_PLACE, rays, 1, MPI_UINT64_T, MPI_SUM);
    if (d->rank != 0)
        free_tiles(d);
    return PS_OK;
}

static const float *hook_tile_data(void *user, int tile)
{
    dist *d = user;
    /* The buffers stay until the next render's tiles_begin or the end. */
    return d->have && d->have[tile] ? d->store + (size_t)tile * d->floats : NULL;
}

/* ---- figures, start and end ---------------------------------------------------------- */

static void hook_add_stats(void *user, ps_run_stats *rs)
{
    dist *d = user;
    ps_stats_add(rs, "ranks", d->size);
    ps_stats_add(rs, "dist_trace_seconds", d->trace_seconds);
    ps_stats_add(rs, "dist_merge_seconds", d->merge_seconds);
    ps_stats_add(rs, "dist_last_map_seconds", d->last_map_seconds);
    ps_stats_add(rs, "dist_cache_exchange_seconds", d->cache_exchange_seconds);
    ps_stats_add(rs, "dist_cache_wait_seconds", d->cache_wait_seconds);
    ps_stats_add(rs, "dist_cache_chunks", (double)d->cache_chunks);
    ps_stats_add(rs, "dist_cache_bytes", (double)d->cache_bytes);
    ps_stats_add(rs, "dist_tiles_wait_seconds", d->tiles_wait_seconds);
}

/* The last line a rank wrote on its stderr (its error message), or "". */
static void last_line(FILE *f, char *out, size_t size)
{
    out[0] = '\0';
    if (!f)
        return;
    fflush(stderr);
    rewind(f);
    char line[PS_ERROR_MSG_MAX];
    while (fgets(line, sizeof line, f))
        if (line[0] != '\n') {
            line[strcspn(line, "\n")] = '\0';
            snprintf(out, size, "%s", line);
        }
}

int ps_dist_main(int argc, char **argv, ps_dist_program program)
{
    int provided = MPI_THREAD_SINGLE;
    if (MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
        fprintf(stderr, "photosplat-ref-mpi: MPI did not start\n");
        return 2;
    }
    dist *d = calloc(1, sizeof *d);
    if (!d) {
        fprintf(stderr, "photosplat-ref-mpi: out of memory\n");
        MPI_Abort(MPI_COMM_WORLD, 2);
        return 2;
    }
    MPI_Comm_dup(MPI_COMM_WORLD, &d->comm);
    MPI_Comm_rank(d->comm, &d->rank);
    MPI_Comm_size(d->comm, &d->size);
    if (provided < MPI_THREAD_SERIALIZED) {
        if (d->rank == 0)
            fprintf(stderr, "photosplat-ref-mpi: this MPI gives no thread support (MPI_THREAD_SERIALIZED)\n");
        MPI_Comm_free(&d->comm);
        free(d);
        MPI_Finalize();
        return 2;
    }
    int *ub = NULL, has_ub = 0;
    MPI_Comm_get_attr(MPI_COMM_WORLD, MPI_TAG_UB, &ub, &has_ub);
    d->tag_ub = has_ub && ub ? *ub : 32767; /* the least the standard allows */
    MPI_Type_contiguous((int)sizeof(ps_photon), MPI_BYTE, &d->photon_type);
    MPI_Type_commit(&d->photon_type);
    MPI_Type_contiguous((int)sizeof(slot_record), MPI_BYTE, &d->record_type);
    MPI_Type_commit(&d->record_type);
    d->counts = malloc((size_t)d->size * sizeof *d->counts);
    d->displs = malloc((size_t)d->size * sizeof *d->displs);
    pthread_mutex_init(&d->lock, NULL);
    if (d->rank != 0) {
        /* One report of everything every rank shares: rank 0's. */
        int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, STDOUT_FILENO);
            close(null);
        }
        d->errlog = tmpfile();
        if (d->errlog)
            dup2(fileno(d->errlog), STDERR_FILENO);
    }
    d->share = (ps_render_share){.user = d,
                                 .part = d->rank,
                                 .parts = d->size,
                                 .assemble = d->rank == 0,
                                 .cache_exchange = hook_cache_exchange,
                                 .tiles_begin = hook_tiles_begin,
                                 .next_tile = hook_next_tile,
                                 .tile_done = hook_tile_done,
                                 .tiles_end = hook_tiles_end,
                                 .tile_data = hook_tile_data};
    d->hooks = (ps_ref_dist){.user = d,
                             .root = d->rank == 0,
                             .ranks = d->size,
                             .trace = hook_trace,
                             .agree = hook_agree,
                             .add_stats = hook_add_stats,
                             .share = &d->share};

    int rc = program(argc, argv, &d->hooks);

    /* A rank that stopped before the others (bad arguments, a scene it
     * could not read) meets them here or at their next agreement. */
    if (!d->failed) {
        ps_error e;
        ps_error_clear(&e);
        ps_status st = PS_OK;
        if (rc != 0) {
            char line[PS_ERROR_MSG_MAX];
            last_line(d->errlog, line, sizeof line);
            st = rc > 128 ? PS_ERR_INTERRUPTED : PS_ERR_IO;
            ps_error_set(&e, st, "%s", line[0] ? line : "failed");
        }
        st = agree(d, st, &e);
        if (st != PS_OK && rc == 0)
            rc = st == PS_ERR_INTERRUPTED ? 130 : 2;
        if (st != PS_OK && d->rank == 0 && strncmp(e.msg, "rank ", 5) == 0)
            fprintf(stderr, "photosplat-ref-mpi: %s\n", e.msg);
    }
    free_tiles(d);
    free(d->send);
    free(d->recv);
    free(d->counts);
    free(d->displs);
    pthread_mutex_destroy(&d->lock);
    MPI_Type_free(&d->photon_type);
    MPI_Type_free(&d->record_type);
    MPI_Comm_free(&d->comm);
    if (d->errlog)
        fclose(d->errlog);
    free(d);
    MPI_Finalize();
    return rc;
}
