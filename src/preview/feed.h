/* feed.h: photons for the progressive preview (thesis 4.1.4): a thread that
 * traces both maps in rounds and hands each batch over under a lock, while
 * the drawing thread takes what has arrived every tau.
 *
 * Photon i is the same whatever the timing (tracer.h), so the photons a
 * frame shows are always a prefix of each map's index range: the picture
 * after n photons is the same picture, however fast they came. Powers are
 * normalised for each map's cap N; a frame that has n of them scales by N/n. */
#ifndef PS_PREVIEW_FEED_H
#define PS_PREVIEW_FEED_H

#include <stdbool.h>
#include <stdint.h>

#include "core/status.h"
#include <stddef.h>
#include "photon/tracer.h"

/* Photons traced per round for the larger map (the other in proportion):
 * enough to keep the tracer's threads busy, few enough that a refresh every
 * tau sees recent ones. */
#define PS_FEED_BATCH 16384

typedef struct ps_feed ps_feed;

/* A feed of tracer t (which must outlive it) for caps[k] photons of each map
 * whose active[k] is set. Nothing is traced until run or start. */
ps_status ps_feed_create(ps_tracer *t, const uint64_t caps[PS_MAP_COUNT], const bool active[PS_MAP_COUNT],
                         ps_feed **out, ps_error *err);
/* Stops (and joins) a started feed first. Accepts NULL. */
void ps_feed_destroy(ps_feed *f);

/* A bound on memory as well as on photons: tracing ends once the maps store
 * max_stored photons together (0: no bound, the default), even before the
 * caps. The caps bound photons emitted; stored photons per emitted one depend
 * on the scene (up to PS_PHOTON_MAX_BOUNCES in the global map of a white
 * room), so this is the bound that holds for any scene. It is checked between
 * batches: the maps may pass it by one batch's photons. A feed ended here
 * still shows a correct picture, scaled by N/n for the n emitted (thesis 5.1:
 * more photons would refine it, not change it). Call before run, prime or
 * start. */
void ps_feed_set_store_limit(ps_feed *f, size_t max_stored);

/* Traces everything on the calling thread. */
ps_status ps_feed_run(ps_feed *f, ps_error *err);
/* Traces the first round (PS_FEED_BATCH photons of the largest map, the
 * others in proportion) on the calling thread, so that a picture can show
 * photons at once; run or start go on from there. */
ps_status ps_feed_prime(ps_feed *f, ps_error *err);
/* Traces in a background thread until done, stopped, or an error. */
ps_status ps_feed_start(ps_feed *f, ps_error *err);
/* Asks the thread to stop after its current batch and waits for it. */
void ps_feed_stop(ps_feed *f);
/* The same, but a map in repair order stays so (no merge), and a repair
 * the thread has not finished testing ends there, the indices left joining
 * those to retrace: for a feed an edit replaces, which
 * ps_feed_create_repair reads as it lies. Its repair counts are final. */
void ps_feed_stop_unmerged(ps_feed *f);
/* Holds the thread between batches (true) or lets it go on. */
void ps_feed_pause(ps_feed *f, bool paused);
/* Holds the thread between batches while some map k stores at least most[k]
 * photons (SIZE_MAX each, the default: no bound), so that it never runs far
 * ahead of a picture that draws what it traces (ps_session_settings'
 * backlog_refreshes). Checked before each round, however long the drawing
 * side takes to call again: a flag set at each refresh let the mirror box's
 * tracer run 2x10^5 photons past it while one long refresh was drawn. */
void ps_feed_set_ahead(ps_feed *f, const size_t most[PS_MAP_COUNT]);
/* Holds the thread and waits until it is between batches (or done), so that
 * the scene it traces may change (an edit, before ps_feed_stop). */
void ps_feed_hold_idle(ps_feed *f);

/* Between lock and unlock the maps do not change or move. */
void ps_feed_lock(ps_feed *f);
void ps_feed_unlock(ps_feed *f);
/* Under the lock: both maps as they stand, and whether the feed has ended
 * (every cap reached, stopped, or failed). */
const ps_photon_map *ps_feed_maps(const ps_feed *f);
bool ps_feed_ended(const ps_feed *f);
/* Under the lock: whether it ended at the store limit (or at a map's share
 * of the memory budget, the tracer's max_stored), not at the caps. */
bool ps_feed_store_limited(const ps_feed *f);

/* Under the lock: where each handed-over batch of map k ended, as (stored
 * photons, emitted photons) pairs in order. A frame that draws a prefix of
 * the map ending at one of them knows the n to scale by: emitted. */
typedef struct ps_feed_mark {
    size_t stored;
    uint64_t emitted;
} ps_feed_mark;
const ps_feed_mark *ps_feed_marks(const ps_feed *f, ps_map_kind k, size_t *count);

/* After the feed has ended: how it ended (an error from the tracer, or
 * PS_OK), and the seconds it spent tracing. */
ps_status ps_feed_status(const ps_feed *f, ps_error *err);
double ps_feed_seconds(const ps_feed *f);
uint64_t ps_feed_cap(const ps_feed *f, ps_map_kind k);
bool ps_feed_active(const ps_feed *f, ps_map_kind k);

/* ---- selective repair (issue 18) ------------------------------------------------
 * With the tracer's path records (ps_tracer_options.records) a feed can go on
 * after an edit from what it has: ps_feed_create_repair takes a stopped
 * feed's maps and records, keeps every photon the edit cannot have changed
 * (put at its index under the edited scene's plan, its power set anew),
 * and retraces the others first (PS_FEED_BATCH at
 * a time, in index order), before tracing on from where the old feed was.
 * Until then a map is in repair order (kept, then retraced, then new
 * photons), each batch still a mark whose emitted count is the whole range
 * (the kept photons stand for all of it, the retraced fill in); when tracing
 * ends the map is put back in index order, equal photon for photon to a
 * fresh trace of the edited scene, and the generation counts up. */

/* What a repair asks its caller (repair.c): */
typedef struct ps_feed_repair_fns {
    void *ctx;
    /* Which old photon each of map k's indices [0, end) is under the edited
     * scene's tracer, as a source map the feed fills a step at a time and
     * destroys (ps_source_map_create). Called by ps_feed_create_repair only. */
    ps_status (*sources)(void *ctx, ps_map_kind k, uint64_t end, ps_source_map **out, ps_error *err);
    /* An old photon is kept when no segment of its path meets one of these
     * boxes (path_record.h, in quant): the moved objects' old and new
     * places. Copied: the feed tests most paths after the call. */
    const ps_aabb *moved;
    size_t moved_count;
    ps_path_quant quant;
} ps_feed_repair_fns;
/* Whether a stopped feed can be repaired: its records are complete, it did
 * not fail or end at the store limit. */
bool ps_feed_repairable(const ps_feed *f);
/* The new feed, on tracer t (the edited scene's), from old (stopped and
 * repairable, its maps in index order or in a repair's order; left empty,
 * to be destroyed): photon i of the edited scene is the old photon its
 * source names when its path is clear of the moved boxes (its power set
 * anew, ps_tracer_repower), else retraced; a map none of whose photons has
 * a source starts over from photon 0. The call makes the sources' tables
 * only: the sources are found, the paths tested and the kept photons
 * copied by ps_feed_repair_ahead for what the first picture draws, the
 * rest by the thread (or run, or a merge) before it retraces anything. On
 * an error old's maps may be lost: start a new feed from photon 0. */
ps_status ps_feed_create_repair(ps_tracer *t, ps_feed *old, const ps_feed_repair_fns *fns, ps_feed **out,
                                ps_error *err);
/* Before run, prime or start: map k's repair carried on, a batch of indices
 * at a time, until the map holds at least min_photons[k] photons or its
 * repair is done (SIZE_MAX: done). */
ps_status ps_feed_repair_ahead(ps_feed *f, const size_t min_photons[PS_MAP_COUNT], ps_error *err);
/* What the repair that made f did, per map: photon indices kept and to
 * retrace, and the stored photons kept (zeros until every index is tested
 * and copied). */
typedef struct ps_feed_repair_count {
    uint64_t kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
    uint64_t kept_photons[PS_MAP_COUNT];
} ps_feed_repair_count;
ps_feed_repair_count ps_feed_repair_counts(ps_feed *f);
/* Under the lock: how many times a map was reordered (a drawn prefix of it
 * is then not the same photons). */
uint64_t ps_feed_generation(const ps_feed *f);
/* A feed traced by its background thread (ps_feed_start) does not put its
 * maps back in index order when it ends: the drawing side does, with
 * ps_feed_merge, when a reorder costs its picture nothing (every photon
 * drawn, or a new view). ps_feed_run and ps_feed_stop merge themselves.
 * Under the lock: whether the feed has ended with a map still in repair
 * order. */
bool ps_feed_merge_pending(const ps_feed *f);
/* Before run, prime or start of a repaired feed: when its retrace (the
 * pending indices of both maps) is at most max_photons, all of it on the
 * calling thread, as the thread's rounds would, and the maps put in index
 * order at once; else nothing, the thread's. A count, not a
 * time: what the first picture after an edit shows does not depend on the
 * machine's load. */
ps_status ps_feed_retrace_first(ps_feed *f, uint64_t max_photons, ps_error *err);
/* Not under the lock: once the feed has ended, its maps in index order (a
 * no-op when none is in repair order); counts a generation per map
 * reordered. On an error (out of memory) the feed's status is it. */
ps_status ps_feed_merge(ps_feed *f, ps_error *err);

#endif
