/* history.h: undo and redo of the window's edits (GL-free).
 *
 * Before each edit the caller records the scene as it stands
 * (ps_history_record: a ps_scene_clone); undo gives the session that scene
 * back through ps_session_restore_scene, bit for bit (x + d - d is not x, so
 * the inverse edit would not do), keeping the scene as it was for redo. Every
 * array is copied, so a step costs the scene's size: the history keeps at
 * most max_steps steps and max_bytes of them, forgetting the oldest. */
#ifndef PS_PREVIEW_HISTORY_H
#define PS_PREVIEW_HISTORY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "preview/session.h"
#include "scene/scene.h"

#define PS_HISTORY_DEFAULT_STEPS 100
#define PS_HISTORY_DEFAULT_BYTES ((uint64_t)256 << 20)

typedef struct ps_history ps_history;

ps_status ps_history_create(size_t max_steps, uint64_t max_bytes, ps_history **out, ps_error *err);
void ps_history_destroy(ps_history *h); /* accepts NULL */

/* The scene before an edit about to be made (call it, then the edit; when the
 * edit is refused, ps_history_forget). Clears what redo could bring back. */
ps_status ps_history_record(ps_history *h, const ps_scene *before, ps_error *err);
/* The same with a snapshot the caller made (a ps_scene_clone), which the
 * history takes over, even on failure. */
ps_status ps_history_take(ps_history *h, ps_scene *snapshot, ps_error *err);
/* Drops the last record (its edit was refused). */
void ps_history_forget(ps_history *h);

size_t ps_history_undo_steps(const ps_history *h);
size_t ps_history_redo_steps(const ps_history *h);

/* The session's scene back to before the last edit (redo: after the last
 * undone one); PS_ERR_RANGE "nothing to undo" when there is none. The maps
 * are repaired as after any edit (ps_session_update). */
ps_status ps_history_undo(ps_history *h, ps_session *s, ps_error *err);
ps_status ps_history_redo(ps_history *h, ps_session *s, ps_error *err);

/* What one step of scene s is planned at (its arrays). */
uint64_t ps_history_scene_bytes(const ps_scene *s);

#endif
