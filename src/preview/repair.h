/* repair.h: after an edit, which photon paths of the preview's maps the
 * edit cannot have changed (issue 18): the session's hook between the old
 * feed and the new one (feed.h, selective repair).
 *
 * Photon i of a map is kept, exactly, when
 *  - it leaves the same light the same way under the old and the new plan
 *    (ps_tracer_same_source: light, caustic cone, first-hit target and the
 *    normalisation 1 / photons of its stratum, bit for bit),
 *  - that light did not change (its ps_light, bit for bit; a mesh light also
 *    changes when its object moves), and
 *  - no segment of its path meets the bounds of a moved object, at the old
 *    or the new place (path_record.h).
 * So: moving object O keeps every path clear of O's boxes; moving a light,
 * changing its power or a spot's angle retraces that light's photons; an
 * edit that changes any stratum's share (another caustic cone, another
 * light's flux) changes every photon count of that map, hence every photon's
 * power, and the whole map is retraced (a rescale is not bit-identical: the
 * tracer multiplies the power along the path in an order a rescale cannot
 * reproduce, and RGBE rounds it with a dither). The repair falls back to a
 * restart when the scene's ray offset changed, a moved box left the record
 * box, or the maps the scene needs changed. */
#ifndef PS_PREVIEW_REPAIR_H
#define PS_PREVIEW_REPAIR_H

#include <stdbool.h>
#include <stddef.h>

#include "core/status.h"
#include "photon/tracer.h"
#include "preview/feed.h"
#include "scene/scene.h"

/* The scene as the maps were traced for it. */
typedef struct ps_repair_state {
    ps_light *lights;
    size_t light_count;
    ps_aabb *bounds; /* each object's */
    size_t object_count;
    double epsilon;  /* the world's ray offset */
} ps_repair_state;

/* A copy of scene's lights and object bounds with the world's offset. */
ps_status ps_repair_state_take(const ps_scene *scene, double epsilon, ps_repair_state *out, ps_error *err);
void ps_repair_state_free(ps_repair_state *st);

/* The box path vertices are quantised in for the whole session: the scene's
 * bounds widened by their extent on every side. */
ps_aabb ps_repair_record_box(const ps_scene *scene);

/* The feed after an edit: old (stopped) repaired on new_tracer, the edited
 * scene's, when it can be (*out, *repaired true), else *out NULL and
 * *repaired false (the caller starts over). was: the scene before;
 * epsilon: the edited world's offset. */
ps_status ps_repair_feed(ps_feed *old, ps_tracer *old_tracer, ps_tracer *new_tracer, const ps_repair_state *was,
                         const ps_scene *scene, double epsilon, ps_feed **out, bool *repaired, ps_error *err);

#endif
