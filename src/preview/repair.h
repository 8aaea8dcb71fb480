/* repair.h: after an edit, which photon paths of the preview's maps the
 * edit cannot have changed (issue 18): the session's hook between the old
 * feed and the new one (feed.h, selective repair).
 *
 * Photon i of the edited scene's map is photon (stratum, j) of its plan
 * (tracer.h). It keeps the old photon (stratum, j), exactly, when
 *  - the old plan has that stratum (the same light and target) sampling the
 *    same way (the same caustic cone; the light not moved, turned, its spot
 *    angle or mesh changed: its power and colour may differ) and emitted its
 *    photon j below the old end (ps_tracer_photon_sources), and
 *  - no segment of that photon's path meets the bounds of a moved object, at
 *    the old or the new place (path_record.h).
 * Its power is then set anew from its recorded throughput
 * (ps_tracer_repower), bit for bit what a fresh trace stores. So: a power or
 * colour edit keeps every photon (with several lights only the strata whose
 * counts grew trace more); moving object O keeps every path clear of O's
 * boxes, and the other objects' caustic cones' photons; moving a light or a
 * spot's angle keeps the other lights' photons. The repair falls back to a
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
