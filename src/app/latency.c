/* latency.c: an edit's first refreshed frame, phase by phase (latency.h). */
#include "app/latency.h"

static const char *const names[PS_LAT_COUNT] = {"hold", "update", "session", "specular",
                                                "shadows", "draw", "show", "other"};

const char *ps_lat_phase_name(ps_lat_phase p) { return p >= 0 && p < PS_LAT_COUNT ? names[p] : "?"; }

void ps_latency_begin(ps_latency *l, double now)
{
    if (l->start > 0.0)
        return;
    l->start = now;
    for (int p = 0; p < PS_LAT_COUNT; p++)
        l->cur[p] = 0.0;
    l->shadow_faces_cur = 0;
}

bool ps_latency_pending(const ps_latency *l) { return l->start > 0.0; }

void ps_latency_add(ps_latency *l, ps_lat_phase p, double seconds)
{
    if (l->start > 0.0 && p >= 0 && p < PS_LAT_COUNT)
        l->cur[p] += seconds;
}

void ps_latency_add_faces(ps_latency *l, unsigned faces)
{
    if (l->start > 0.0)
        l->shadow_faces_cur += faces;
}

void ps_latency_commit(ps_latency *l, double now, bool lod)
{
    if (!(l->start > 0.0))
        return;
    l->full_start = l->start;
    if (!lod)
        ps_latency_full(l, now);
    double total = now - l->start, known = 0.0;
    for (int p = 0; p < PS_LAT_COUNT; p++)
        if (p != PS_LAT_OTHER)
            known += l->cur[p];
    l->cur[PS_LAT_OTHER] += total > known ? total - known : 0.0;
    for (int p = 0; p < PS_LAT_COUNT; p++)
        l->sum[p] += l->cur[p];
    l->total_sum += total;
    if (total > l->total_max)
        l->total_max = total;
    l->shadow_faces_sum += l->shadow_faces_cur;
    l->count++;
    l->start = 0.0;
}

void ps_latency_full(ps_latency *l, double now)
{
    if (!(l->full_start > 0.0))
        return;
    double total = now - l->full_start;
    l->full_sum += total;
    if (total > l->full_max)
        l->full_max = total;
    l->full_count++;
    l->full_start = 0.0;
}

void ps_latency_stats(const ps_latency *l, ps_run_stats *rs)
{
    double n = l->count ? (double)l->count : 1.0;
    ps_stats_add(rs, "edit_to_frame_seconds_max", l->total_max);
    ps_stats_add(rs, "edit_to_frame_seconds_mean", l->total_sum / n);
    /* ps_stats_add keeps the key's pointer: fixed strings. */
    static const char *const keys[PS_LAT_COUNT] = {
        "edit_hold_seconds_mean",  "edit_update_seconds_mean", "edit_session_seconds_mean",
        "edit_specular_seconds_mean", "edit_shadows_seconds_mean", "edit_draw_seconds_mean",
        "edit_show_seconds_mean",  "edit_other_seconds_mean"};
    for (int p = 0; p < PS_LAT_COUNT; p++)
        ps_stats_add(rs, keys[p], l->sum[p] / n);
    ps_stats_add(rs, "edit_shadow_faces_mean", l->shadow_faces_sum / n);
    ps_stats_add(rs, "edit_to_full_frame_seconds_max", l->full_max);
    ps_stats_add(rs, "edit_to_full_frame_seconds_mean", l->full_sum / (l->full_count ? (double)l->full_count : 1.0));
}
