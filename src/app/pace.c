/* pace.c: when snap starts a refresh for its checkpoints (pace.h). */
#include "app/pace.h"

#include <math.h>

/* Of a whole refresh's time, what does not grow with the photons. */
static double scene_part(const ps_pace_model *m) { return fmax(0.0, m->seconds - m->per_photon * m->photons); }

/* The photons' part of a whole refresh drawing n (never fewer than
 * m->least), beyond the n0 it was learned at growing as n (n / n0)^PS_PACE_GROWTH. */
static double photons_part(const ps_pace_model *m, double n)
{
    n = fmax(n, m->least);
    double part = m->per_photon * fmax(0.0, n);
    return n > m->photons && m->photons > 0.0 ? part * pow(n / m->photons, PS_PACE_GROWTH) : part;
}

/* A refresh with its first round of cube faces held to the deadline. */
static double held_seconds(const ps_pace_model *m, double photons)
{
    return scene_part(m) + photons_part(m, photons);
}

double ps_pace_seconds(const ps_pace_model *m, double photons) { return held_seconds(m, photons) + m->unheld; }
double ps_pace_redraw_seconds(const ps_pace_model *m, double photons)
{
    return scene_part(m) + m->per_photon * fmax(0.0, photons);
}

/* The checkpoint's frame (ps_pace_plan.shows) holds its first round of cube
 * faces to the deadline like any others, and draws a share of the budget
 * (PS_PACE_SHOWN_BUDGET, or `share`). */
static double share_seconds(const ps_pace_model *m, double photons, double share)
{
    return held_seconds(m, photons) - (1.0 - share) * m->splats;
}
static double shown_seconds(const ps_pace_model *m, double photons)
{
    return share_seconds(m, photons, PS_PACE_SHOWN_BUDGET);
}

void ps_pace_learn(ps_pace_model *m, double seconds, double photons, double photon_seconds, bool whole)
{
    double part = fmin(seconds, fmax(0.0, photon_seconds));
    m->per_photon = whole && photons > 0.0 ? part / photons : 0.0;
    m->learned = whole ? m->learned + 1 : 0;
    m->seconds = seconds;
    m->photons = photons;
}

/* When the refresh showing checkpoint cp should start: t + d(t) = cp +
 * margin, d growing at `slope` seconds a second while photons arrive (whole
 * refreshes). */
static double ideal_start(const ps_pace_model *m, double now, double d_now, double cp)
{
    double slope = m->per_photon * m->rate;
    return now + (cp + PS_PACE_MARGIN * d_now - now - d_now) / (1.0 + slope);
}

/* The photons a whole refresh draws to last `d` seconds (0: one batch). */
static double photons_for(const ps_pace_model *m, double d)
{
    double part = fmax(0.0, d - scene_part(m)), at_n0 = m->per_photon * m->photons;
    if (part <= at_n0 || m->photons <= 0.0)
        return part / m->per_photon;
    return m->photons * pow(part / at_n0, 1.0 / (1.0 + PS_PACE_GROWTH)); /* photons_part inverted */
}

ps_pace_plan ps_pace_next(const ps_pace_model *m, double now, double photons, double due, const double *pending,
                          int count)
{
    ps_pace_plan p = {fmax(now, due), HUGE_VAL, -1, HUGE_VAL, false, 1.0, false, HUGE_VAL};
    if (count <= 0)
        return p;
    p.start = fmax(now, fmin(due, pending[0]));
    if (m->seconds <= 0.0)
        return p;
    double d_now = shown_seconds(m, photons);
    /* The first checkpoint not shown yet. (Letting one out of reach give
     * way to the next, whose frame then showed both, lost the first by up
     * to a refresh and, with 8-bit refreshes varying by a third, as often
     * missed the next too.) */
    p.target = 0;
    double cp = pending[0];
    double ideal = ideal_start(m, now, d_now, cp);
    double d_ideal = shown_seconds(m, photons + m->rate * fmax(0.0, ideal - now));
    /* A whole refresh longer than its share of the checkpoint's time draws
     * fewer photons, to last that share, started later (pace.h). */
    double cap = m->per_photon > 0.0 ? PS_PACE_FRAME_SHARE * cp : HUGE_VAL;
    if (d_ideal > cap) {
        d_ideal = cap;
        ideal = cp - (1.0 - PS_PACE_MARGIN) * cap;
    }
    double aim = ideal + d_ideal; /* when the checkpoint's frame should end */
    /* Cube faces may push the checkpoint's frame to end as late as
     * PS_PACE_FACES_LATE of its time after it, or the margin if later. */
    double last_end = fmax(cp * (1.0 + PS_PACE_FACES_LATE), aim);
    double last_start = last_end - d_ideal;
    double s0 = now >= ideal ? now : fmax(now, due);
    double d0_held = held_seconds(m, photons + m->rate * (s0 - now));
    double d0 = d0_held + m->unheld; /* unheld faces in it (HUGE_VAL: not known) */
    /* Whole refreshes no checkpoint shows are only drawn and thrown away
     * (snap is headless): the checkpoint's frame is the next. */
    if (now >= ideal || s0 + d0_held > last_start || m->per_photon > 0.0) {
        /* The checkpoint's frame, at its start (a refresh started now
         * would delay it past last_start) or at once when that is past:
         * faces only while it ends by last_end. A whole one started late
         * draws what ends it by the aim (at least one batch). Its first
         * round of faces is held too (an unheld quarter of the design
         * room's 84 faces, 0.3-0.4 s, landed its 0.5 and 1 s checkpoints
         * at 0.86 and 1.32 s). */
        p.shows = p.hold_faces = true;
        p.end_by = fmax(cp * (1.0 + PS_PACE_PATHS_LATE), aim);
        p.start = now >= ideal ? now : ideal;
        double n = photons + m->rate * (p.start - now);
        double d = fmin(shown_seconds(m, n), cap);
        /* Incremental, started late: a smaller share, to end by the aim
         * (at least one batch a map: the session's prefix). Started late
         * with its whole share, after a frame that ended just short of the
         * checkpoint, the design room's and the area box's 0.1 s
         * checkpoints came at 0.12-0.15 s. */
        p.share = PS_PACE_SHOWN_BUDGET;
        if (m->per_photon <= 0.0 && m->splats > 0.0 && p.start + d > aim)
            p.share = fmax(0.0, PS_PACE_SHOWN_BUDGET - (p.start + d - aim) / m->splats);
        if (m->per_photon > 0.0 && p.start + d > aim)
            d = fmax(aim - p.start, 0.0);
        if (m->per_photon > 0.0 && photons_for(m, d) < n) {
            p.photons = photons_for(m, d);
            n = p.photons;
        }
        d = share_seconds(m, n, p.share);
        p.faces_deadline = last_end - d > p.start ? last_end - d + fmin(m->lead, d) : p.start;
    } else {
        /* A refresh that ends before the checkpoint's frame must start:
         * faces only while they keep it so (ending after `ideal`, it is
         * followed by that frame at once, with what is left), the first
         * round's too when its unheld faces would not. (Waiting for the
         * frame's start instead left the design room 0.4 s without a
         * refresh before its 1 s checkpoint, its tracer held meanwhile by
         * the photons not drawn; holding the first round in every refresh
         * instead let its faces fill whole seconds between checkpoints, a
         * batch of photons shown for each second of faces.) The deadline
         * is where all its faces end, the unheld ones counted on included:
         * those too start only before it (ps_gl_specular_set_deadline), so
         * that a round foreseen short delays the frame by one face at most. */
        p.start = s0;
        p.hold_faces = s0 + d0 > last_start;
        p.faces_deadline = last_start - d0_held + fmin(m->lead, d0_held);
    }
    return p;
}

double ps_pace_next_due(double due, double now, double tau) { return fmin(due, now) + tau; }

double ps_pace_shown_at(const ps_pace_plan *planned, bool whole, double ended, double checkpoint)
{
    return whole && planned->shows && ended < checkpoint ? checkpoint : ended;
}

double ps_pace_photons_at_start(const ps_pace_model *m, const ps_pace_plan *planned, double now, double photons,
                                double due, const double *pending, int count)
{
    if (!planned->shows || m->per_photon <= 0.0)
        return planned->photons;
    ps_pace_plan again = ps_pace_next(m, now, photons, due, pending, count);
    return again.shows ? fmin(planned->photons, again.photons) : planned->photons;
}
