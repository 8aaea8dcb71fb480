/* pace.h: when photosplat-snap --checkpoints starts a refresh, so that the
 * frame a checkpoint shows (the first finished at or after its time, or a
 * whole refresh planned as its frame that finished early and waits for it:
 * ps_pace_shown_at) lands soon after it rather than a whole refresh later.
 *
 * A refresh is predicted from the last one: its time without cube faces,
 * for whole refreshes (8 bits redraw every photon, so their time grows with
 * the run) split into the photons' part (building their splats, and drawing
 * them, finished before and after), which scales with the photons it will
 * draw (PS_PACE_GROWTH), and the scene's (the rest); incremental ones at a
 * whole budget's splats, whatever the last drew.
 * (Fitting the photon's cost from two refreshes' difference was up to 3x
 * low: their scene parts vary as much as the photons' parts differ.) The
 * refresh that will show the checkpoint starts when it would end
 * PS_PACE_MARGIN of its time after it (incremental: drawing
 * PS_PACE_SHOWN_BUDGET of its budget, less if it starts later than that:
 * ps_pace_plan.share); a refresh that would end after that
 * start holds its first round of cube faces if that is enough, and waits
 * for it otherwise (snap is headless: a wait leaves the cores to the tracer,
 * and to cube faces while they fit in it, ps_gl_specular_idle); cube faces
 * run only while the checkpoint's frame still ends within
 * PS_PACE_FACES_LATE of it (or the margin, if later): in that
 * frame, those of the first round too, which the refreshes further from a
 * checkpoint draw as the pace counts on them, each started before the
 * deadline whatever its time (ps_gl_specular_set_first_round).
 * A whole refresh showing a checkpoint lasts at most PS_PACE_FRAME_SHARE of
 * the checkpoint's time (ps_pace_plan.photons: a prefix of the photons, an
 * unbiased picture of fewer), so that its prediction's error stays within
 * bench's 20 %. Which photons are drawn, a prefix in index order, stays a
 * function of the count alone: only when pictures are made, and how many
 * photons they show, is timing's. */
#ifndef PS_APP_PACE_H
#define PS_APP_PACE_H

#include <stdbool.h>
#include <stdint.h>

/* The checkpoint's frame aims to end this share of its own time after it:
 * room for the prediction's error (an incremental one that ends before the
 * checkpoint leaves it to the next refresh; a whole one waits for it,
 * ps_pace_shown_at, its photons then older than they could have been;
 * 8-bit refreshes of 1-3 s varied by a third from one to the next on a
 * loaded 2-core machine). */
#define PS_PACE_MARGIN 0.3

/* Cube faces may make the checkpoint's frame end up to this share of its
 * time after it (half of bench's goal of 20 %, the rest for the prediction's
 * error), where that is later than the margin: without them the specular
 * layer stayed black through every checkpoint of a 2 s run. */
#define PS_PACE_FACES_LATE 0.1

/* What comes last in the checkpoint's frame, after its faces and splats
 * (photosplat-snap's owed eye paths, ps_gl_specular_set_paths_deadline), may
 * make it end up to this share of its time after the checkpoint, where that
 * is later than its aim: the prediction's error is spent by then, and of
 * bench's 20 % this leaves the rest to the layer those paths feed. (At
 * PS_PACE_FACES_LATE, the area box's 8-bit 0.5 s checkpoints showed the
 * mirror black in 5 of 12, where drawn whole they had come at 0.50-0.61 s.) */
#define PS_PACE_PATHS_LATE 0.15

/* A whole refresh that shows a checkpoint lasts at most this share of the
 * checkpoint's time: aimed to end PS_PACE_MARGIN of its length after the
 * checkpoint, a prediction off by up to that margin then ends it between the
 * checkpoint and PS_PACE_FRAME_SHARE * 2 * PS_PACE_MARGIN = 20 % after
 * (8-bit refreshes of 1-3 s varied by a third on a loaded 2-core machine; a
 * redraw of all 3*10^6 photons that had arrived by the 5 s checkpoint took
 * 3.5-4.7 s and landed it at 7.2-9.6 s). */
#define PS_PACE_FRAME_SHARE (1.0 / 3.0)

/* Incremental: a checkpoint's frame draws this share of a refresh's budget
 * of new splats (ps_session_set_budget_share), so that its time varies less
 * than the budget's error (the splat rate it comes from varied 2x from one
 * refresh to the next: the default box's 0.5 s checkpoint landed at 0.62-
 * 0.68 s). What it leaves, the next refreshes draw. */
#define PS_PACE_SHOWN_BUDGET 0.25

/* A cube face never timed, where a deadline foresees it (a wait, a held
 * first round: ps_gl_specular_set_face_guess), as this share of the first
 * refresh's time without faces, or of the last one's where that is longer.
 * (The bench's first faces took 0.1-0.4x the first frame at 256^2, which
 * holds llvmpipe's first compiles as the first face does; foreseen from the
 * ring's 8-bit refreshes of 0.007-0.008 s after it, its first face, 0.015-
 * 0.022 s, rode in the 0.1 s checkpoint's frame and landed it at 0.115-
 * 0.129 s. Let start at once, the first rode in the 0.1 s
 * checkpoint's frame and made it late; kept out of those frames with the
 * waits' guess the whole last frame, it waited past 0.2 s, and the mirrors
 * were wholly black there in 42-44 of the bench's 48 configurations
 * against 35-37.) */
#define PS_PACE_FACE_GUESS 0.5

/* 8 bits: the batch drawn and not shown after the first frame (refine),
 * foreseen as this share of the first frame, which holds llvmpipe's first
 * compiles: it took 0.023-0.030 s after first frames of 0.05-0.058 s. */
#define PS_PACE_BATCH_GUESS 0.5
/* Whole refreshes cost more a photon the more they draw (building 4*10^6
 * photons' splats, their diffusion in screen order, took 0.59 us a photon
 * against 0.26 at 7.6*10^5): predicted from a smaller one, the photons'
 * part grows as n^(1 + PS_PACE_GROWTH). Fitted to the default box's 8-bit
 * runs, 0.7-1.0 us a photon learned at 0.76-1.45*10^6 and 1.08-1.13 us
 * drawn at 3.3-4.8*10^6 (linear, the 10 s checkpoint's frame took 4.9 s
 * where 3.3 were planned, and landed at 11.3-12.9 s). */
#define PS_PACE_GROWTH 0.2

typedef struct ps_pace_model {
    double seconds;    /* the last refresh's time without cube faces (0: nothing known yet) */
    double photons;    /* the photons emitted that it drew */
    double per_photon; /* whole refreshes: seconds a photon costs (0: incremental) */
    double splats;     /* incremental: of seconds, the new splats' (a whole budget's) */
    double rate;       /* photons emitted a second */
    double lead;       /* of seconds, what comes before the faces (the session's splats) */
    int learned;       /* whole refreshes learned in a row */
    double least;      /* whole: the photons emitted the next refresh draws at least, which its
                        * time is foreseen for (snap's checkpoints never show fewer than the last
                        * one did: a plan for fewer foresaw the default box's 0.1 s frame at
                        * 0.019-0.023 s, it took 0.023-0.032 s and landed at 0.11-0.13 s) */
    double unheld;     /* the next refresh's cube faces that no deadline holds back, seconds
                        * (the first round's: ps_gl_specular_unheld_seconds; HUGE_VAL: not
                        * known yet), unless it shows a checkpoint (ps_pace_plan.shows) */
} ps_pace_model;

/* After a refresh of `seconds` (no cube faces) drawing `photons`, of which
 * `photon_seconds` grew with the photons (building and drawing their
 * splats): whole refreshes take a photon's cost as that part over the
 * photons, the rest of the time as the scene's. (The part has a constant
 * of its own, 0.01-0.1 s, so a larger refresh costs a little less a photon
 * than predicted and ends early, which the margin absorbs; fitting the
 * constant from two refreshes' difference predicted a 3*10^6-photon frame
 * 35 % short, and it landed late.) */
void ps_pace_learn(ps_pace_model *m, double seconds, double photons, double photon_seconds, bool whole);
/* The cube faces come after the session's part of a refresh (`lead`
 * seconds of it, the last time): the faces deadline is later by that. */

/* A refresh's predicted time when it draws `photons` emitted, its unheld
 * faces included (a checkpoint's frame holds them: it is planned without). */
double ps_pace_seconds(const ps_pace_model *m, double photons);
/* A whole redraw of `photons` emitted with the tracer stopped, no cube
 * faces (snap's last picture in 8 bits): linear in the photons, without
 * PS_PACE_GROWTH. Measured on the default box and the ring at 64^2, the
 * cost of a photon falls as their number grows: 1.5-2.6 us at 2-7*10^4
 * (the first frame), 1.2-1.4 at 0.3-0.5*10^6 (the tracer held; 1.7-2.1 at
 * 0.2*10^6), 0.9-1.1 at 2-7*10^6; the ring 0.55 at 0.6*10^6, 0.44-0.47 at
 * 8-13*10^6. So this foresees a redraw from a model learned at 0.3-0.6*10^6
 * 1.2-1.4x long, and the run ends early by about that, where the growth law
 * (checkpoints' pacing) foresaw 2x; a power of the photons fitted through
 * the first frame and such a model foresaw 1.3-2x short, and a line through
 * two refreshes of n/4 and n photons no better than n's alone. */
double ps_pace_redraw_seconds(const ps_pace_model *m, double photons);

typedef struct ps_pace_plan {
    double start;           /* when to start the next refresh (>= now) */
    double faces_deadline;  /* its cube faces end by then (<= start: none); HUGE_VAL: no limit */
    int target;             /* the checkpoint planned for (index into the list: 0), -1: none */
    double photons;         /* whole: the most photons emitted it draws (0: one batch); HUGE_VAL: all */
    bool shows;             /* planned as the checkpoint's frame: an incremental one draws
                             * PS_PACE_SHOWN_BUDGET of its budget (share), and holds its faces */
    double share;           /* incremental: the share of its budget of new splats it draws
                             * (ps_session_set_budget_share): 1, or for the checkpoint's frame
                             * PS_PACE_SHOWN_BUDGET, less when it starts late (after its ideal
                             * start, as when the frame before ended just short of the
                             * checkpoint): what still ends it by its aim */
    bool hold_faces;        /* the first round's cube faces, otherwise unheld, keep to
                             * faces_deadline too (ps_gl_specular_hold_first_round): the
                             * checkpoint's frame, and a refresh before it that would
                             * delay it with them */
    double end_by;          /* shows: when what comes last in it, after its faces and
                             * splats, stops (snap's owed eye paths): PS_PACE_PATHS_LATE
                             * after the checkpoint, or its aim if later. Else HUGE_VAL */
} ps_pace_plan;

/* The next refresh, at `now` with `photons` emitted, due at `due` (tau's
 * schedule; may be past), the checkpoints not yet shown ascending in
 * pending[0..count), all times on one clock. */
ps_pace_plan ps_pace_next(const ps_pace_model *m, double now, double photons, double due, const double *pending,
                          int count);

/* 8 bits: the photons the whole refresh planned as `planned` (shows) draws
 * once it starts, re-planned at `now` with the `photons` emitted then (the
 * other arguments as ps_pace_next's): at most what still ends it by its aim.
 * A plan made before a wait foresees the photons it will find from the
 * arrival rate, measured while frames shared the cores; alone the tracer
 * went 2-3x faster, and the frame drew all it found: the ring's 0.5 s
 * checkpoint, planned at 1.1-2.0*10^5 photons, drew 2.4-4.1*10^5 and landed
 * at 0.68-0.90 s. */
double ps_pace_photons_at_start(const ps_pace_model *m, const ps_pace_plan *planned, double now, double photons,
                                double due, const double *pending, int count);

/* When a refresh that ended at `ended` (before `checkpoint`, the next not
 * shown) shows it: a whole refresh planned as its frame (planned->shows:
 * every whole one once the pace has learned one) waits for it, so at
 * `checkpoint`; any other is not its frame (returns `ended`), and the next
 * refresh is. The waiting frame's photons are those the plan chose for the
 * checkpoint (there at the start it planned; 8 bits hold the tracer while
 * the frame draws), as an on-time frame's are. A frame drawn faster than
 * foreseen was otherwise followed by a whole redraw: in three runs to 1 s
 * of the bench's 24 8-bit configurations, 4 of the 5 late 0.1 s
 * checkpoints (0.120-0.126 s) came that way. Incremental (float) refreshes
 * go on: their next frame draws only new splats. */
double ps_pace_shown_at(const ps_pace_plan *planned, bool whole, double ended, double checkpoint);

/* tau's schedule: the refresh after one that ended at `now`, the last due at
 * `due`: tau after that, never more than tau after now. (Adding tau at every
 * refresh let a burst of refreshes run the schedule ahead: the ring's first
 * float frame, done 1 ms before its 0.2 s checkpoint, was followed by
 * hundreds of empty refreshes aimed at that checkpoint, each adding tau, and
 * the next refresh due was the run's end; refreshes then came only for
 * checkpoints, the tracer waited for a picture that did not come, and the
 * 3 s checkpoint showed 1.3*10^5 photons where other runs showed 2.3*10^6.) */
double ps_pace_next_due(double due, double now, double tau);

#endif
