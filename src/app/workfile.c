/* workfile.c: the window's saved and autosaved scene files (workfile.h). */
#include "app/workfile.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/fileio.h"
#include "preview/history.h"
#include "preview/session.h"

/* "dir/NAME.ext" -> its length without ".ext" (the whole name when it has none). */
static size_t stem_length(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash + 1) ? (size_t)(dot - path) : strlen(path);
}

ps_status ps_workfile_names(const char *scene_path, ps_workfile *out, ps_error *err)
{
    size_t stem = stem_length(scene_path);
    bool model = ps_scene_path_is_model(scene_path);
    int n = model ? snprintf(out->save, sizeof out->save, "%.*s.scn", (int)stem, scene_path)
                  : snprintf(out->save, sizeof out->save, "%s", scene_path);
    int m = snprintf(out->autosave, sizeof out->autosave, "%.*s.autosave.scn", (int)stem, scene_path);
    if (n < 0 || m < 0 || (size_t)n >= sizeof out->save || (size_t)m >= sizeof out->autosave)
        return ps_error_set(err, PS_ERR_RANGE, "%s: the name is too long to save beside", scene_path);
    /* A directory that takes no new file (a read-only model library): the
     * autosave goes to the current directory. */
    ps_error ignored;
    if (ps_check_output_path(out->autosave, &ignored) != PS_OK) {
        const char *slash = strrchr(out->autosave, '/');
        if (slash) {
            char here[PS_WORKFILE_PATH_MAX];
            snprintf(here, sizeof here, "%s", slash + 1);
            snprintf(out->autosave, sizeof out->autosave, "%s", here);
        }
    }
    return PS_OK;
}

/* path's bytes into backup, atomically; nothing when path does not exist. */
static ps_status keep_previous(const char *path, ps_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return PS_OK;
    char backup[PS_WORKFILE_PATH_MAX + 2];
    snprintf(backup, sizeof backup, "%s~", path);
    char *text = NULL;
    size_t len = 0;
    ps_status s = ps_read_file(path, (size_t)1 << 30, &text, &len, err);
    if (s != PS_OK)
        return s;
    ps_outfile *f = ps_outfile_open(backup, err);
    if (!f) {
        free(text);
        return err->status;
    }
    fwrite(text, 1, len, ps_outfile_stream(f));
    free(text);
    return ps_outfile_commit(f, err);
}

ps_status ps_workfile_save(const ps_workfile *w, const ps_scene *scene, ps_error *err)
{
    ps_status st = keep_previous(w->save, err);
    if (st == PS_OK)
        st = ps_scene_write(scene, w->save, err);
    if (st == PS_OK)
        remove(w->autosave);
    return st;
}

ps_status ps_workfile_autosave(const ps_workfile *w, const ps_scene *scene, ps_error *err)
{
    return ps_scene_write(scene, w->autosave, err);
}

bool ps_workfile_autosave_newer(const ps_workfile *w, const char *scene_path)
{
    struct stat a, s;
    if (stat(w->autosave, &a) != 0 || stat(scene_path, &s) != 0)
        return false;
    return a.st_mtim.tv_sec > s.st_mtim.tv_sec ||
           (a.st_mtim.tv_sec == s.st_mtim.tv_sec && a.st_mtim.tv_nsec > s.st_mtim.tv_nsec);
}

/* ---- the window's work ---------------------------------------------------------- */

ps_status ps_work_open(ps_work *w, const char *scene_path, const ps_scene *scene, char *notice, size_t notice_size,
                       ps_error *err)
{
    memset(w, 0, sizeof *w);
    if (notice && notice_size)
        notice[0] = '\0';
    ps_status st = ps_workfile_names(scene_path, &w->names, err);
    if (st == PS_OK)
        st = ps_history_create(PS_HISTORY_DEFAULT_STEPS, PS_HISTORY_DEFAULT_BYTES, &w->history, err);
    if (st == PS_OK)
        st = ps_scene_clone(scene, &w->last, err);
    if (st != PS_OK) {
        ps_work_close(w);
        return st;
    }
    if (notice && notice_size && ps_workfile_autosave_newer(&w->names, scene_path))
        snprintf(notice, notice_size,
                 "%s is newer than %s: unsaved edits of an earlier session (open it with: photosplat %s)",
                 w->names.autosave, scene_path, w->names.autosave);
    return PS_OK;
}

void ps_work_close(ps_work *w)
{
    ps_history_destroy(w->history);
    ps_scene_destroy(w->last);
    w->history = NULL;
    w->last = NULL;
}

void ps_work_before_update(ps_work *w, const ps_scene *scene)
{
    (void)scene;
    if (w->restoring || !w->last)
        return;
    ps_error ignored;
    /* The scene after the last edit is this edit's undo step (taken over, no
     * copy). Out of memory for the step: the edit stands, it cannot be undone. */
    (void)ps_history_take(w->history, w->last, &ignored);
    w->last = NULL;
}

ps_status ps_work_after_update(ps_work *w, const ps_scene *scene, double now, ps_error *err)
{
    w->restoring = false;
    ps_scene_destroy(w->last); /* after an undo or redo: not taken */
    w->last = NULL;
    w->dirty = true;
    if (!w->pending && !w->autosave_off) {
        w->pending = true;
        w->due = now + PS_WORK_AUTOSAVE_DELAY;
    }
    return ps_scene_clone(scene, &w->last, err);
}

ps_status ps_work_tick(ps_work *w, const ps_scene *scene, double now, ps_error *err)
{
    if (!w->pending || now < w->due)
        return PS_OK;
    return ps_work_flush(w, scene, err);
}

ps_status ps_work_flush(ps_work *w, const ps_scene *scene, ps_error *err)
{
    if (!w->pending)
        return PS_OK;
    w->pending = false;
    return ps_workfile_autosave(&w->names, scene, err);
}

ps_status ps_work_save(ps_work *w, const ps_scene *scene, ps_error *err)
{
    ps_status st = ps_workfile_save(&w->names, scene, err);
    if (st == PS_OK) {
        w->dirty = false;
        w->pending = false;
        snprintf(w->where, sizeof w->where, "saved %s", w->names.save);
    }
    return st;
}

ps_status ps_work_undo(ps_work *w, ps_session *s, ps_error *err)
{
    ps_status st = ps_history_undo(w->history, s, err);
    w->restoring = st == PS_OK;
    return st;
}

ps_status ps_work_redo(ps_work *w, ps_session *s, ps_error *err)
{
    ps_status st = ps_history_redo(w->history, s, err);
    w->restoring = st == PS_OK;
    return st;
}
