/* ref_dist.h: what photosplat-ref asks of a distributed run (the MPI
 * program, photosplat-ref-mpi, supplies it from src/dist; the plain program
 * has none). The header needs no MPI: the hooks are plain functions.
 *
 * Every rank runs the whole program on the same arguments and scene. The
 * hooks split the two parallel stages (photons by index range, the image
 * and the irradiance cache through the render's share) and keep the ranks
 * in step: each collective hook first agrees on a status, so that an error
 * on any rank ends the run on every rank, with the first failing rank's
 * message, and the same exit status. Rank 0 alone writes and reports. */
#ifndef PS_APP_REF_DIST_H
#define PS_APP_REF_DIST_H

#include <stdbool.h>
#include <stdint.h>

#include "app/stats.h"
#include "core/status.h"
#include "photon/photon_map.h"
#include "photon/tracer.h"
#include "render/render.h"

typedef struct ps_ref_dist {
    void *user;
    bool root;  /* rank 0: writes the outputs, prints */
    int ranks;
    /* Photons [0, total) of map kind into the empty map m, on every rank the
     * same bytes as ps_tracer_trace(t, kind, 0, total, total, m) makes in one
     * process; max_stored (0: none) bounds the whole map as the tracer's
     * option does. */
    ps_status (*trace)(void *user, ps_tracer *t, ps_map_kind kind, uint64_t total, uint64_t max_stored,
                       ps_photon_map *m, ps_error *err);
    /* Every rank's st: the first failing rank's status and message on every
     * rank, or PS_OK when none failed. */
    ps_status (*agree)(void *user, ps_status st, ps_error *err);
    /* The run's figures of the split (phase times, ranks) for --stats. */
    void (*add_stats)(void *user, ps_run_stats *rs);
    const ps_render_share *share;
} ps_ref_dist;

#endif
