/* latency.h: where the time goes between an edit and its first refreshed
 * frame (the window's and photosplat-snap --script's --stats), phase by
 * phase, summed over the edits of a run.
 *
 * An edit's clock starts just before the first edit call since the last
 * refresh (the call itself holds the tracing thread between batches,
 * ps_feed_hold_idle, and that wait counts) and stops when the first refresh
 * after the update has been drawn and shown. */
#ifndef PS_APP_LATENCY_H
#define PS_APP_LATENCY_H

#include <stdbool.h>
#include <stdint.h>

#include "app/stats.h"

typedef enum ps_lat_phase {
    PS_LAT_HOLD,     /* the edit calls: waiting for the tracing thread's batch in flight */
    PS_LAT_UPDATE,   /* ps_session_update (world, meshes, lights, tracer, repair, a first batch) and the renderer's new scene */
    PS_LAT_SESSION,  /* ps_session_refresh: the batch's splats sorted and sent */
    PS_LAT_SPECULAR, /* the specular layer's cube faces in this refresh */
    PS_LAT_SHADOWS,  /* shadow-cube faces rendered (part of the layers' drawing) */
    PS_LAT_DRAW,     /* the layers' drawing less the shadow faces: depth prepass, direct light, splats */
    PS_LAT_SHOW,     /* the composite shown (and the specular layer added) */
    PS_LAT_OTHER,    /* the rest of the refresh (overlay, waiting on the loop) */
    PS_LAT_COUNT
} ps_lat_phase;

typedef struct ps_latency {
    double start;                /* the pending edit's clock start, 0: none pending */
    double cur[PS_LAT_COUNT];    /* the pending edit's phases so far */
    double sum[PS_LAT_COUNT];    /* over committed edits */
    double total_sum, total_max;
    unsigned shadow_faces_sum;   /* shadow-cube faces rendered in the edits' first refreshes */
    unsigned shadow_faces_cur;
    uint64_t count;
    /* The full view after an edit whose first picture was the level of
     * detail (ps_session_frame.edit_lod): from the same clock start. */
    double full_start;           /* the pending full view's clock start, 0: none pending */
    double full_sum, full_max;
    uint64_t full_count;
} ps_latency;

/* The clock starts at `now` unless an edit is already pending. */
void ps_latency_begin(ps_latency *l, double now);
bool ps_latency_pending(const ps_latency *l);
/* Seconds into a phase of the pending edit (ignored when none is pending). */
void ps_latency_add(ps_latency *l, ps_lat_phase p, double seconds);
void ps_latency_add_faces(ps_latency *l, unsigned faces);
/* The pending edit's first refresh is done at `now`: its total and phases
 * join the sums (the rest of the total goes to PS_LAT_OTHER). lod: it was
 * the level of detail, the full view is still to come (ps_latency_full). */
void ps_latency_commit(ps_latency *l, double now, bool lod);
/* A refresh at full detail done at `now`: the end of the last edit's wait
 * for its full view, if it is pending (an edit whose first picture was full
 * counts that picture). */
void ps_latency_full(ps_latency *l, double now);
/* edit_to_frame_seconds_mean/_max and edit_<phase>_seconds_mean,
 * edit_shadow_faces_mean; edit_to_full_frame_seconds_mean/_max. */
void ps_latency_stats(const ps_latency *l, ps_run_stats *rs);
const char *ps_lat_phase_name(ps_lat_phase p);

#endif
