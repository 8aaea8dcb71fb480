/* pace.c: when snap starts a refresh for its checkpoints (pace.h). */
#include "app/pace.h"

#include <math.h>

double ps_pace_seconds(const ps_pace_model *m, double photons)
{
    return m->seconds + m->per_photon * fmax(0.0, photons - m->photons);
}

void ps_pace_learn(ps_pace_model *m, double seconds, double photons, bool whole)
{
    if (!whole)
        m->per_photon = 0.0;
    else if (m->seconds > 0.0 && photons >= PS_PACE_FIT_GROWTH * m->photons)
        m->per_photon = fmax(0.0, (seconds - m->seconds) / (photons - m->photons));
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

ps_pace_plan ps_pace_next(const ps_pace_model *m, double now, double photons, double due, const double *pending,
                          int count)
{
    ps_pace_plan p = {fmax(now, due), HUGE_VAL, -1};
    if (count <= 0)
        return p;
    p.start = fmax(now, fmin(due, pending[0]));
    if (m->seconds <= 0.0)
        return p;
    double d_now = ps_pace_seconds(m, photons);
    /* The first checkpoint not shown yet. (Letting one out of reach give
     * way to the next, whose frame then showed both, lost the first by up
     * to a refresh and, with 8-bit refreshes varying by a third, as often
     * missed the next too.) */
    p.target = 0;
    double cp = pending[0];
    double ideal = ideal_start(m, now, d_now, cp);
    /* Cube faces may push the checkpoint's frame to end as late as
     * PS_PACE_FACES_LATE of its time after it, or the margin if later. */
    double d_ideal = ps_pace_seconds(m, photons + m->rate * fmax(0.0, ideal - now));
    double last_end = fmax(cp * (1.0 + PS_PACE_FACES_LATE), ideal + d_ideal);
    double last_start = last_end - d_ideal;
    double s0 = now >= ideal ? now : fmax(now, due);
    double d0 = ps_pace_seconds(m, photons + m->rate * (s0 - now));
    if (now >= ideal || s0 + d0 > last_start) {
        /* The checkpoint's frame, at its start (a refresh started now
         * would delay it past last_start) or at once when that is past:
         * faces only while it ends by last_end. */
        p.start = now >= ideal ? now : ideal;
        double d = ps_pace_seconds(m, photons + m->rate * (p.start - now));
        p.faces_deadline = last_end - d > p.start ? last_end - d + fmin(m->lead, d) : p.start;
    } else {
        /* A refresh that ends before the checkpoint's frame must start:
         * faces only while they keep it so (ending after `ideal`, it is
         * followed by that frame at once, with what is left). */
        p.start = s0;
        p.faces_deadline = last_start - d0 + fmin(m->lead, d0);
    }
    return p;
}
