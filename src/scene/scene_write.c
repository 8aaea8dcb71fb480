/* scene_write.c: a scene, as edited, written back as a .scn file that loads to
 * the same scene (docs/scene-format.md, "Saved scenes").
 *
 * Every number is written with 17 significant digits, which a double survives
 * unchanged; geometry is written as its statement gave it (a mesh's file and
 * keys, a quad's corner and edges) followed by the edits made since, replayed
 * on loading through the same edit functions (scene_internal.h says why a sum
 * of the moves would not do). Paths are relative to the new file's directory,
 * or absolute when the two share nothing below the root. */
/* realpath(3) is X/Open, not base POSIX. */
#define _XOPEN_SOURCE 700

#include <errno.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/fileio.h"
#include "scene/scene_internal.h"

/* The one number format: the shortest form that still reads back as the same double. */
#define NUM "%.17g"
#define VEC NUM " " NUM " " NUM

char *ps_scene_abs_path(const char *path)
{
    char *real = realpath(path, NULL);
    if (real || errno == ENOMEM)
        return real;
    if (path[0] == '/')
        return strdup(path);
    char cwd[PATH_MAX];
    if (!getcwd(cwd, sizeof cwd))
        return strdup(path);
    size_t n = strlen(cwd) + strlen(path) + 2;
    char *out = malloc(n);
    if (out)
        snprintf(out, n, "%s/%s", cwd, path);
    return out;
}

/* file (absolute) as seen from directory dir (absolute, no trailing '/'):
 * "../x/y.obj", or file itself when the two part at the root. */
static void relative_path(const char *dir, const char *file, char *out, size_t size)
{
    /* The longest common run of whole components. */
    size_t common = 0;
    for (size_t i = 0;; i++) {
        bool dir_end = dir[i] == '\0' || dir[i] == '/';
        bool file_end = file[i] == '/';
        if (dir_end && file_end)
            common = i;
        if (dir[i] == '\0' || dir[i] != file[i])
            break;
    }
    if (common == 0 || strcmp(dir, "/") == 0) {
        snprintf(out, size, "%s", file);
        return;
    }
    size_t used = 0;
    for (const char *c = dir + common; *c; c++)
        if (*c == '/')
            used += (size_t)snprintf(out + used, used < size ? size - used : 0, "../");
    snprintf(out + used, used < size ? size - used : 0, "%s", file + common + 1);
}

typedef struct writer {
    FILE *f;
    const ps_scene *s;
    const char *dir; /* the new file's directory, absolute */
    const char *name;
    ps_error *err;
    ps_status st;
} writer;

/* A path as one token: quoted when it holds a blank or '#'. */
static void put_path(writer *w, const char *abs)
{
    char rel[PATH_MAX * 2];
    relative_path(w->dir, abs, rel, sizeof rel);
    if (strpbrk(rel, "\"\n\r")) {
        if (w->st == PS_OK)
            w->st = ps_error_set(w->err, PS_ERR_RANGE, "%s: the path %s cannot be written in a scene (a quote or newline)",
                                 w->name, abs);
        return;
    }
    fprintf(w->f, strpbrk(rel, " \t#") ? " \"%s\"" : " %s", rel);
}

/* ` material NAME` unless it is the loader's default, which a statement gets by naming none. */
static void put_material_key(writer *w, uint32_t m)
{
    const char *name = w->s->materials.items[m].name;
    if (strcmp(name, PS_DEFAULT_MATERIAL_NAME) != 0)
        fprintf(w->f, "  material %s", name);
}

static void put_material(writer *w, const ps_material *m)
{
    fprintf(w->f, "material %s ", m->name);
    switch (m->type) {
    case PS_MAT_DIFFUSE:
        fprintf(w->f, "diffuse albedo " VEC "\n", m->albedo.r, m->albedo.g, m->albedo.b);
        break;
    case PS_MAT_GLOSSY:
        fprintf(w->f, "glossy albedo " VEC " specular " VEC " exponent " NUM "\n", m->albedo.r, m->albedo.g,
                m->albedo.b, m->specular.r, m->specular.g, m->specular.b, m->exponent);
        break;
    case PS_MAT_MIRROR:
        fprintf(w->f, "mirror reflectance " VEC "\n", m->reflectance.r, m->reflectance.g, m->reflectance.b);
        break;
    case PS_MAT_DIELECTRIC:
        fprintf(w->f, "dielectric ior " NUM " transmittance " VEC "\n", m->ior, m->transmittance.r,
                m->transmittance.g, m->transmittance.b);
        break;
    }
}

/* The edits made to object o since its statement, in order. */
static void put_edits(writer *w, uint32_t o)
{
    const ps_scene *s = w->s;
    for (size_t k = 0; k < s->edits.count; k++) {
        const ps_scene_edit *e = &s->edits.items[k];
        if (e->object != o)
            continue;
        if (e->light == PS_SOURCE_NONE)
            fprintf(w->f, "  move " VEC, e->v.x, e->v.y, e->v.z);
        else
            fprintf(w->f, "  light-power %u " VEC, (unsigned)(e->light - s->obj_src.items[o].first_light), e->v.x,
                    e->v.y, e->v.z);
    }
}

static void put_object(writer *w, uint32_t index)
{
    const ps_scene *s = w->s;
    const ps_object *o = &s->objects.items[index];
    const ps_object_source *src = &s->obj_src.items[index];
    switch (o->type) {
    case PS_OBJ_MESH: {
        fprintf(w->f, "mesh");
        put_path(w, ps_scene_string(s, src->file));
        const char *keys = ps_scene_string(s, src->keys);
        if (keys && keys[0])
            fprintf(w->f, "  %s", keys);
        break;
    }
    case PS_OBJ_QUAD:
        fprintf(w->f, "quad corner " VEC "  edge1 " VEC "  edge2 " VEC, src->corner.x, src->corner.y, src->corner.z,
                src->edge1.x, src->edge1.y, src->edge1.z, src->edge2.x, src->edge2.y, src->edge2.z);
        put_material_key(w, o->material);
        break;
    case PS_OBJ_SPHERE:
        fprintf(w->f, "sphere center " VEC "  radius " NUM, o->center.x, o->center.y, o->center.z, o->radius);
        put_material_key(w, o->material);
        break;
    }
    put_edits(w, index);
    fprintf(w->f, "\n");
}

static void put_light(writer *w, uint32_t index)
{
    const ps_light *l = &w->s->lights.items[index];
    const ps_light_source *src = &w->s->light_src.items[index];
    ps_vec3 p = l->position, d = src->dir;
    switch (l->type) {
    case PS_LIGHT_POINT:
        fprintf(w->f, "light point position " VEC, p.x, p.y, p.z);
        break;
    case PS_LIGHT_SPOT:
        fprintf(w->f, "light spot position " VEC "  direction " VEC "  angle " NUM, p.x, p.y, p.z, d.x, d.y, d.z,
                l->angle_deg);
        break;
    case PS_LIGHT_QUAD:
        fprintf(w->f, "light quad corner " VEC "  edge1 " VEC "  edge2 " VEC, p.x, p.y, p.z, l->edge1.x, l->edge1.y,
                l->edge1.z, l->edge2.x, l->edge2.y, l->edge2.z);
        break;
    case PS_LIGHT_SPHERE:
        fprintf(w->f, "light sphere center " VEC "  radius " NUM, p.x, p.y, p.z, l->radius);
        break;
    case PS_LIGHT_DISC:
        fprintf(w->f, "light disc center " VEC "  normal " VEC "  radius " NUM, p.x, p.y, p.z, d.x, d.y, d.z,
                l->radius);
        break;
    case PS_LIGHT_IES:
        fprintf(w->f, "light ies");
        put_path(w, ps_scene_string(w->s, src->file));
        fprintf(w->f, "  position " VEC "  aim " VEC "  spin " NUM, p.x, p.y, p.z, d.x, d.y, d.z, l->spin_deg);
        break;
    case PS_LIGHT_MESH:
        return; /* written with its mesh */
    }
    /* Always as flux: lumens and candela were turned into it on loading. */
    fprintf(w->f, "  power " VEC "\n", l->power.r, l->power.g, l->power.b);
}

/* The new file's directory, absolute and resolved as ps_scene_abs_path resolves the files it names. */
static char *output_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    char dir[PATH_MAX];
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    return realpath(dir, NULL);
}

ps_status ps_scene_write(const ps_scene *scene, const char *path, ps_error *err)
{
    ps_error local;
    if (!err)
        err = &local;
    ps_error_clear(err);
    char *dir = output_dir(path);
    if (!dir)
        return ps_error_set(err, PS_ERR_IO, "%s: cannot write there: %s", path, strerror(errno));
    ps_outfile *out = ps_outfile_open(path, err);
    if (!out) {
        free(dir);
        return err->status;
    }
    writer w = {ps_outfile_stream(out), scene, dir, path, err, PS_OK};
    const ps_camera *c = &scene->camera;
    const ps_scene_defaults *d = &scene->defaults;
    fprintf(w.f, "# photosplat scene, saved from %s\n", scene->path ? scene->path : "(memory)");
    fprintf(w.f, "camera eye " VEC "  target " VEC "  up " VEC "  fov " NUM "\n", c->eye.x, c->eye.y, c->eye.z,
            c->target.x, c->target.y, c->target.z, c->up.x, c->up.y, c->up.z, c->fov_deg);
    fprintf(w.f, "image %d %d\n", d->width, d->height);
    for (size_t k = 0; k < scene->stmts.count; k++) {
        const ps_scene_stmt *st = &scene->stmts.items[k];
        switch (st->kind) {
        case PS_STMT_MATERIAL:
            put_material(&w, &scene->materials.items[st->index]);
            break;
        case PS_STMT_OBJECT:
            put_object(&w, st->index);
            break;
        case PS_STMT_LIGHT:
            put_light(&w, st->index);
            break;
        }
    }
    /* Always given: the loader derives missing radii from the scene's size,
     * which the edits changed. */
    fprintf(w.f, "photons caustic %lld global %lld\n", (long long)d->caustic_photons, (long long)d->global_photons);
    fprintf(w.f, "radius caustic " NUM " global " NUM "\n", d->caustic_radius, d->global_radius);
    free(dir);
    if (w.st != PS_OK) {
        ps_outfile_abort(out);
        return w.st;
    }
    return ps_outfile_commit(out, err);
}
