/* workfile.h: where the window keeps the user's work (GL-free).
 *
 * For a scene SCENE: Ctrl+S writes the edited scene to `save` (NAME.scn:
 * the scene file itself, or beside an opened NAME.obj), the file it replaces
 * kept as NAME.scn~; every edit is also written within a second to
 * `autosave`, NAME.autosave.scn beside the scene, or in the current
 * directory when that one takes no new file. Writes are atomic
 * (ps_scene_write). */
#ifndef PS_APP_WORKFILE_H
#define PS_APP_WORKFILE_H

#include <stdbool.h>
#include <stddef.h>

#include "core/status.h"
#include "scene/scene.h"

#define PS_WORKFILE_PATH_MAX 4096

typedef struct ps_workfile {
    char save[PS_WORKFILE_PATH_MAX];     /* what Ctrl+S writes */
    char autosave[PS_WORKFILE_PATH_MAX]; /* what every edit writes */
} ps_workfile;

/* The two names for the scene (or model) at scene_path. PS_ERR_RANGE when
 * a name would not fit. */
ps_status ps_workfile_names(const char *scene_path, ps_workfile *out, ps_error *err);

/* Writes scene to w->save, the file there before kept as SAVE~ (copied: the
 * new file replaces the old in one rename), then removes the autosave, which
 * is no newer. */
ps_status ps_workfile_save(const ps_workfile *w, const ps_scene *scene, ps_error *err);
ps_status ps_workfile_autosave(const ps_workfile *w, const ps_scene *scene, ps_error *err);

/* Whether w->autosave exists and is newer than scene_path: an earlier
 * session's edits that were never saved. */
bool ps_workfile_autosave_newer(const ps_workfile *w, const char *scene_path);

/* ---- the window's work: history, unsaved edits, autosave ------------------------
 * What the window calls around its edits (window_main.c), GL-free. Every edit
 * of the session, whatever made it (keys, mouse, script), is seen once where
 * the window applies pending edits: before (ps_work_before_update) the scene
 * as it was is kept for undo; after (ps_work_after_update) an autosave is due
 * within PS_WORK_AUTOSAVE_DELAY seconds. */
#define PS_WORK_AUTOSAVE_DELAY 0.5

struct ps_session;
struct ps_history;

typedef struct ps_work {
    ps_workfile names;
    struct ps_history *history;
    ps_scene *last;       /* the scene after the last applied edit (what undo records) */
    bool dirty;           /* edits since the last Ctrl+S */
    bool pending;         /* an autosave is due at `due` */
    bool restoring;       /* the pending edit is an undo or redo: not a new step */
    bool autosave_off;    /* no autosave written (a scripted session) */
    double due;
    char where[PS_WORKFILE_PATH_MAX + 64]; /* the last save's report */
} ps_work;

/* Names, an empty history, and the scene as loaded. `notice` (may be NULL,
 * size notice_size) gets a line when an earlier session's autosave is
 * newer than the scene, saying how to open it; else "". */
ps_status ps_work_open(ps_work *w, const char *scene_path, const ps_scene *scene, char *notice, size_t notice_size,
                       ps_error *err);
void ps_work_close(ps_work *w); /* frees; accepts a zeroed one */
void ps_work_before_update(ps_work *w, const ps_scene *scene);
ps_status ps_work_after_update(ps_work *w, const ps_scene *scene, double now, ps_error *err);
/* The autosave, when due by now; PS_OK when none is. */
ps_status ps_work_tick(ps_work *w, const ps_scene *scene, double now, ps_error *err);
/* The autosave now if one is pending (at exit, on SIGTERM). */
ps_status ps_work_flush(ps_work *w, const ps_scene *scene, ps_error *err);
ps_status ps_work_save(ps_work *w, const ps_scene *scene, ps_error *err);
ps_status ps_work_undo(ps_work *w, struct ps_session *s, ps_error *err);
ps_status ps_work_redo(ps_work *w, struct ps_session *s, ps_error *err);

#endif
