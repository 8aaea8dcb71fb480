/* pace.h: when photosplat-snap --checkpoints starts a refresh, so that the
 * frame a checkpoint shows (the first finished at or after its time) lands
 * soon after it rather than a whole refresh later.
 *
 * A refresh is predicted from the last one: its time without cube faces,
 * plus, for whole refreshes (8 bits redraw every photon, so their time grows
 * with the run), the time a photon took between the last two times the
 * photons it will draw beyond the last's; as is for incremental ones. (Time
 * proportional to the photons overstated it several-fold: the first frames
 * are mostly the direct layer, and a frame predicted too long starts early,
 * ends before the checkpoint and leaves it to the next, a refresh late.) The
 * refresh that will show the checkpoint starts when it would end
 * PS_PACE_MARGIN of its time after it; a refresh that would end after that
 * start waits for it instead (snap is headless: an idle moment only leaves
 * the cores to the tracer), and cube faces run only while the checkpoint's
 * frame still ends within PS_PACE_FACES_LATE of it (or the margin, if later).
 * Which photons a picture shows is untouched: only when pictures are made. */
#ifndef PS_APP_PACE_H
#define PS_APP_PACE_H

#include <stdbool.h>
#include <stdint.h>

/* The checkpoint's frame aims to end this share of its own time after it:
 * room for the prediction's error (one that ends before the checkpoint
 * leaves it to the next refresh, a whole refresh late; 8-bit refreshes of
 * 1-3 s varied by a third from one to the next on a loaded 2-core machine). */
#define PS_PACE_MARGIN 0.3

/* Cube faces may make the checkpoint's frame end up to this share of its
 * time after it (half of bench's goal of 20 %, the rest for the prediction's
 * error), where that is later than the margin: without them the specular
 * layer stayed black through every checkpoint of a 2 s run. */
#define PS_PACE_FACES_LATE 0.1

typedef struct ps_pace_model {
    double seconds;    /* the last refresh's time without cube faces (0: nothing known yet) */
    double photons;    /* the photons emitted that it drew */
    double per_photon; /* whole refreshes: seconds a photon more costs (0: incremental) */
    double rate;       /* photons emitted a second */
    double lead;       /* of seconds, what comes before the faces (the session's splats) */
} ps_pace_model;

/* After a refresh of `seconds` (no cube faces) drawing `photons`: whole
 * refreshes fit the photon's cost from this one and the last (once the
 * photons grew PS_PACE_FIT_GROWTH-fold, never below 0). */
#define PS_PACE_FIT_GROWTH 1.2
void ps_pace_learn(ps_pace_model *m, double seconds, double photons, bool whole);
/* The cube faces come after the session's part of a refresh (`lead`
 * seconds of it, the last time): the faces deadline is later by that. */

/* A refresh's predicted time when it starts with `photons` emitted. */
double ps_pace_seconds(const ps_pace_model *m, double photons);

typedef struct ps_pace_plan {
    double start;           /* when to start the next refresh (>= now) */
    double faces_deadline;  /* its cube faces end by then (<= start: none); HUGE_VAL: no limit */
    int target;             /* the checkpoint planned for (index into the list: 0), -1: none */
} ps_pace_plan;

/* The next refresh, at `now` with `photons` emitted, due at `due` (tau's
 * schedule; may be past), the checkpoints not yet shown ascending in
 * pending[0..count), all times on one clock. */
ps_pace_plan ps_pace_next(const ps_pace_model *m, double now, double photons, double due, const double *pending,
                          int count);

#endif
