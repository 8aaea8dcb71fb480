/* obj.c: OBJ/MTL pre-scan (strict checks with line numbers), then tinyobjloader. */
#include "scene/obj.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/array.h"
#include "core/fileio.h"
#include "core/memory.h"
#include "core/namemap.h"
#include "core/number.h"
#include "scene/scene.h"

/* Larger files are refused before reading: 1 GiB of OBJ text is ~20 M triangles,
 * far past what the interactive preview is for. */
#define OBJ_MAX_BYTES ((size_t)1 << 30)
#define MTL_MAX_BYTES ((size_t)64 << 20)
/* tinyobjloader stores a face's vertex count in an unsigned char. */
#define OBJ_MAX_FACE_VERTICES 255
#define OBJ_MAX_TOKENS 300
#define OBJ_MAX_MTLLIBS 16
/* Largest magnitude of any OBJ or MTL number. tinyobjloader reads some
 * finite values near 1e300 as infinite (a fuzzed "vn 0 1e300 1" became a
 * non-finite normal), and products of larger coordinates (areas, emitted
 * power) overflow; 1e30 m is far beyond any scene yet keeps those finite. */
#define OBJ_MAX_MAGNITUDE 1e30

/* Per MTL material: what tinyobjloader cannot tell us (whether Ns/Ni were given). */
typedef struct mtl_info {
    char name[PS_OBJ_NAME_MAX];
    int has_ns, has_ni;
} mtl_info;

typedef struct prescan {
    const char *path;
    const ps_warn_sink *warn;
    ps_error *err;
    size_t v, vn, vt; /* counts so far: negative indices are relative to them */
    size_t faces;     /* faces with >= 3 vertices */
    mtl_info *mtls;
    size_t mtl_count, mtl_cap;
    /* name -> index in mtls, the last of a name winning as in tinyobjloader;
     * a hash, since usemtl lines look names up (a scan made many materials
     * quadratic: found by fuzzing). */
    ps_namemap *mtl_names;
    char *mtl_text; /* every MTL library found, concatenated */
    size_t mtl_len, mtl_cap_bytes;
    char libs[OBJ_MAX_MTLLIBS][256]; /* names already loaded */
    int lib_count;
} prescan;

/* Splits a line (modified in place) into whitespace-separated tokens. A
 * backslash escapes the next character (tinyobjloader allows "\ " in names).
 * Returns the count, or -1 when there are more than max. */
static int split(char *s, char **tok, int max)
{
    int n = 0;
    for (;;) {
        while (*s == ' ' || *s == '\t' || *s == '\r')
            s++;
        if (!*s)
            return n;
        if (n == max)
            return -1;
        tok[n++] = s;
        char *w = s;
        while (*s && *s != ' ' && *s != '\t' && *s != '\r') {
            if (*s == '\\' && s[1])
                s++;
            *w++ = *s++;
        }
        if (*s)
            s++;
        *w = '\0';
    }
}

/* Copies line `at` of buf (up to the newline) into dst; returns the start of the
 * next line, or NULL at the end. */
static const char *next_line(const char *at, char *dst, size_t dst_size, bool *too_long)
{
    size_t len = ps_line_length(at), n = len;
    *too_long = n >= dst_size;
    if (*too_long)
        n = dst_size - 1;
    memcpy(dst, at, n);
    dst[n] = '\0';
    return at[len] ? at + len + 1 : (*at ? at + len : NULL);
}

static ps_status check_numbers(const char *path, int line, char **tok, int ntok, int min, int max,
                               ps_error *err)
{
    int n = ntok - 1;
    if (n < min || n > max) {
        if (min == max)
            return ps_error_at(err, PS_ERR_PARSE, path, line, "'%s' needs %d numbers, got %d", tok[0], min, n);
        return ps_error_at(err, PS_ERR_PARSE, path, line, "'%s' needs %d to %d numbers, got %d", tok[0], min, max, n);
    }
    for (int k = 1; k < ntok; k++) {
        double v;
        if (!ps_parse_double(tok[k], &v))
            return ps_error_at(err, PS_ERR_PARSE, path, line, "'%s': '%s' is not a finite number", tok[0], tok[k]);
        if (fabs(v) > OBJ_MAX_MAGNITUDE)
            return ps_error_at(err, PS_ERR_RANGE, path, line, "'%s': '%s' is out of range (magnitude above %g)", tok[0],
                               tok[k], OBJ_MAX_MAGNITUDE);
    }
    return PS_OK;
}

/* One index of a face corner: non-zero integer, resolved against count. */
static ps_status check_index(prescan *ps, int line, const char *text, size_t count, const char *what)
{
    int64_t v;
    if (!ps_parse_int64(text, &v) || v == 0)
        return ps_error_at(ps->err, PS_ERR_PARSE, ps->path, line, "face %s index '%s' is not a non-zero integer", what,
                           text);
    if ((v > 0 && (uint64_t)v > count) || (v < 0 && (uint64_t)(-v) > count))
        return ps_error_at(ps->err, PS_ERR_RANGE, ps->path, line,
                           "face %s index %s is out of range (%zu defined so far)", what, text, count);
    return PS_OK;
}

static ps_status check_face(prescan *ps, int line, char **tok, int ntok)
{
    int corners = ntok - 1;
    if (corners > OBJ_MAX_FACE_VERTICES)
        return ps_error_at(ps->err, PS_ERR_LIMIT, ps->path, line, "face has %d vertices, at most %d are supported",
                           corners, OBJ_MAX_FACE_VERTICES);
    for (int k = 1; k < ntok; k++) {
        /* v, v/vt, v//vn or v/vt/vn */
        char *parts[3] = {tok[k], NULL, NULL};
        char *s1 = strchr(tok[k], '/');
        if (s1) {
            *s1 = '\0';
            parts[1] = s1 + 1;
            char *s2 = strchr(parts[1], '/');
            if (s2) {
                *s2 = '\0';
                parts[2] = s2 + 1;
                if (strchr(parts[2], '/'))
                    return ps_error_at(ps->err, PS_ERR_PARSE, ps->path, line, "malformed face corner");
            }
        }
        ps_status st = check_index(ps, line, parts[0], ps->v, "vertex");
        if (st == PS_OK && parts[1] && parts[1][0])
            st = check_index(ps, line, parts[1], ps->vt, "texture");
        if (st == PS_OK && parts[2])
            st = check_index(ps, line, parts[2], ps->vn, "normal");
        if (st != PS_OK)
            return st;
    }
    if (corners < 3)
        ps_warn(ps->warn, "%s:%d: face with %d vertices ignored", ps->path, line, corners);
    else
        ps->faces++;
    return PS_OK;
}

/* The directory part of path, with its slash ("" for none). */
static void dir_of(const char *path, char *dst, size_t n)
{
    const char *slash = strrchr(path, '/');
    size_t len = slash ? (size_t)(slash - path + 1) : 0;
    if (len >= n)
        len = 0;
    memcpy(dst, path, len);
    dst[len] = '\0';
}

static ps_status scan_mtl_text(prescan *ps, const char *mpath, const char *text)
{
    char buf[4096];
    char *tok[OBJ_MAX_TOKENS];
    int line = 0;
    bool too_long;
    for (const char *at = text; at && *at;) {
        at = next_line(at, buf, sizeof buf, &too_long);
        line++;
        if (too_long)
            return ps_error_at(ps->err, PS_ERR_PARSE, mpath, line, "line too long");
        int ntok = split(buf, tok, OBJ_MAX_TOKENS);
        if (ntok < 0)
            return ps_error_at(ps->err, PS_ERR_PARSE, mpath, line, "too many values on one line");
        if (ntok == 0 || tok[0][0] == '#')
            continue;
        const char *k = tok[0];
        ps_status st = PS_OK;
        if (strcmp(k, "newmtl") == 0) {
            if (ntok < 2)
                return ps_error_at(ps->err, PS_ERR_PARSE, mpath, line, "newmtl without a name");
            if (!PS_RESERVE(ps->mtls, ps->mtl_cap, ps->mtl_count + 1))
                return ps_error_set(ps->err, PS_ERR_NOMEM, "%s: out of memory", mpath);
            mtl_info *m = &ps->mtls[ps->mtl_count];
            memset(m, 0, sizeof *m);
            snprintf(m->name, sizeof m->name, "%s", tok[1]);
            if (!ps_namemap_put(ps->mtl_names, m->name, (int64_t)ps->mtl_count, true))
                return ps_error_set(ps->err, PS_ERR_NOMEM, "%s: out of memory", mpath);
            ps->mtl_count++;
        } else if (!strcmp(k, "Kd") || !strcmp(k, "Ks") || !strcmp(k, "Ke") || !strcmp(k, "Ka") || !strcmp(k, "Tf")) {
            if (ntok > 1 && (!strcmp(tok[1], "spectral") || !strcmp(tok[1], "xyz")))
                return ps_error_at(ps->err, PS_ERR_PARSE, mpath, line, "'%s %s' colours are not supported, use r g b",
                                   k, tok[1]);
            st = check_numbers(mpath, line, tok, ntok, 3, 3, ps->err);
            for (int c = 1; st == PS_OK && c < 4; c++) {
                double v;
                ps_parse_double(tok[c], &v);
                if (v < 0.0)
                    st = ps_error_at(ps->err, PS_ERR_RANGE, mpath, line, "'%s' components must not be negative", k);
            }
        } else if (!strcmp(k, "Ns") || !strcmp(k, "Ni") || !strcmp(k, "d") || !strcmp(k, "Tr")) {
            st = check_numbers(mpath, line, tok, ntok, 1, 1, ps->err);
            if (st == PS_OK && ps->mtl_count) {
                if (k[1] == 's')
                    ps->mtls[ps->mtl_count - 1].has_ns = 1;
                if (k[1] == 'i')
                    ps->mtls[ps->mtl_count - 1].has_ni = 1;
            }
        } else if (!strcmp(k, "illum")) {
            int64_t v;
            if (ntok != 2 || !ps_parse_int64(tok[1], &v) || v < 0 || v > 10)
                st = ps_error_at(ps->err, PS_ERR_PARSE, mpath, line, "illum needs one integer from 0 to 10");
        }
        /* map_Kd is read by tinyobjloader (its options too); other maps and
         * statements are ignored. */
        if (st != PS_OK)
            return st;
    }
    return PS_OK;
}

static ps_status load_mtllib(prescan *ps, int line, char **tok, int ntok)
{
    char dir[1024], mpath[2048];
    dir_of(ps->path, dir, sizeof dir);
    if (ntok < 2) {
        ps_warn(ps->warn, "%s:%d: mtllib without a file name; faces use the default material", ps->path, line);
        return PS_OK;
    }
    for (int k = 1; k < ntok; k++) {
        bool seen = false;
        for (int i = 0; i < ps->lib_count; i++)
            seen |= strcmp(ps->libs[i], tok[k]) == 0;
        if (seen)
            continue;
        if (ps->lib_count == OBJ_MAX_MTLLIBS)
            return ps_error_at(ps->err, PS_ERR_LIMIT, ps->path, line, "more than %d material libraries",
                               OBJ_MAX_MTLLIBS);
        snprintf(ps->libs[ps->lib_count++], sizeof ps->libs[0], "%s", tok[k]);
        snprintf(mpath, sizeof mpath, "%s%s", dir, tok[k]);
        char *text = NULL;
        size_t len = 0;
        ps_error merr;
        ps_status st = ps_read_file(mpath, MTL_MAX_BYTES, &text, &len, &merr);
        if (st == PS_ERR_IO) {
            ps_warn(ps->warn, "%s:%d: material library '%s' not found; its materials fall back to the default", ps->path,
                    line, tok[k]);
            continue;
        }
        if (st != PS_OK) {
            *ps->err = merr;
            return st;
        }
        if (memchr(text, '\0', len)) {
            free(text);
            return ps_error_set(ps->err, PS_ERR_PARSE, "%s: binary data, not an MTL file", mpath);
        }
        st = scan_mtl_text(ps, mpath, text);
        if (st == PS_OK) {
            if (!PS_RESERVE(ps->mtl_text, ps->mtl_cap_bytes, ps->mtl_len + len + 2)) {
                free(text);
                return ps_error_set(ps->err, PS_ERR_NOMEM, "%s: out of memory", mpath);
            }
            memcpy(ps->mtl_text + ps->mtl_len, text, len);
            ps->mtl_len += len;
            ps->mtl_text[ps->mtl_len++] = '\n';
            ps->mtl_text[ps->mtl_len] = '\0';
        }
        free(text);
        if (st != PS_OK)
            return st;
    }
    return PS_OK;
}

static ps_status scan_obj(prescan *ps, const char *text)
{
    /* Long enough for any sane face; longer lines are refused, not split. */
    static const size_t line_max = 65536;
    char *buf = malloc(line_max);
    char **tok = malloc(sizeof *tok * (OBJ_MAX_FACE_VERTICES + 2));
    if (!buf || !tok) {
        free(buf);
        free(tok);
        return ps_error_set(ps->err, PS_ERR_NOMEM, "%s: out of memory", ps->path);
    }
    ps_status st = PS_OK;
    int line = 0;
    bool too_long;
    for (const char *at = text; st == PS_OK && at && *at;) {
        at = next_line(at, buf, line_max, &too_long);
        line++;
        if (too_long) {
            st = ps_error_at(ps->err, PS_ERR_PARSE, ps->path, line, "line too long");
            break;
        }
        int ntok = split(buf, tok, OBJ_MAX_FACE_VERTICES + 2);
        if (ntok < 0) {
            st = ps_error_at(ps->err, PS_ERR_LIMIT, ps->path, line, "more than %d values on one line",
                             OBJ_MAX_FACE_VERTICES + 1);
            break;
        }
        if (ntok == 0 || tok[0][0] == '#')
            continue;
        const char *k = tok[0];
        if (!strcmp(k, "v")) {
            /* x y z, optionally w or an r g b vertex colour */
            st = check_numbers(ps->path, line, tok, ntok, 3, 6, ps->err);
            ps->v++;
        } else if (!strcmp(k, "vn")) {
            st = check_numbers(ps->path, line, tok, ntok, 3, 3, ps->err);
            ps->vn++;
        } else if (!strcmp(k, "vt")) {
            st = check_numbers(ps->path, line, tok, ntok, 1, 3, ps->err);
            ps->vt++;
        } else if (!strcmp(k, "f")) {
            st = check_face(ps, line, tok, ntok);
        } else if (!strcmp(k, "mtllib")) {
            st = load_mtllib(ps, line, tok, ntok);
        } else if (!strcmp(k, "usemtl")) {
            if (ntok < 2 || ps_namemap_find(ps->mtl_names, tok[1]) < 0)
                ps_warn(ps->warn, "%s:%d: usemtl '%s' is not defined in any material library; default material",
                        ps->path, line, ntok > 1 ? tok[1] : "");
        }
        /* o, g, s, l, p and unknown statements are ignored, as tinyobjloader does. */
    }
    free(buf);
    free(tok);
    return st;
}

void ps_obj_free(ps_obj_mesh *m)
{
    if (!m)
        return;
    free(m->positions);
    free(m->normals);
    free(m->tri_v);
    free(m->tri_n);
    free(m->texcoords);
    free(m->tri_t);
    free(m->tri_mat);
    free(m->materials);
    memset(m, 0, sizeof *m);
}

ps_status ps_obj_load(const char *path, ps_obj_mesh *out, const ps_warn_sink *warn, ps_error *err)
{
    memset(out, 0, sizeof *out);
    char *text = NULL;
    size_t len = 0;
    ps_status st = ps_read_file(path, OBJ_MAX_BYTES, &text, &len, err);
    if (st != PS_OK)
        return st;
    prescan ps;
    memset(&ps, 0, sizeof ps);
    ps.path = path;
    ps.warn = warn;
    ps.err = err;
    if (!(ps.mtl_names = ps_namemap_create()))
        st = ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    if (st == PS_OK && memchr(text, '\0', len))
        st = ps_error_set(err, PS_ERR_PARSE, "%s: binary data, not an OBJ file", path);
    if (st == PS_OK)
        st = scan_obj(&ps, text);
    if (st == PS_OK && ps.faces == 0)
        st = ps_error_set(err, PS_ERR_PARSE, "%s: no faces: not a mesh (empty file, or not an OBJ file?)", path);
    /* Before tinyobjloader copies it all: every face is at least a triangle. */
    if (st == PS_OK && ps.faces > PS_SCENE_MAX_TRIANGLES)
        st = ps_error_set(err, PS_ERR_LIMIT, "%s: %zu faces, more than the limit of %d triangles", path, ps.faces,
                          PS_SCENE_MAX_TRIANGLES);
    if (st == PS_OK) {
        char what[64];
        snprintf(what, sizeof what, "%zu faces", ps.faces);
        st = ps_memory_check((uint64_t)ps.faces * PS_SCENE_PLAN_TRIANGLE_BYTES, path, what, err);
    }
    if (st == PS_OK) {
        char msg[512];
        if (ps_tinyobj_parse(text, len, ps.mtl_text ? ps.mtl_text : "", ps.mtl_len, out, msg, sizeof msg) != 0)
            st = ps_error_set(err, strstr(msg, "memory") ? PS_ERR_NOMEM : PS_ERR_PARSE, "%s: %s", path, msg);
    }
    /* The pre-scan guarantees these; check again so that a difference of
     * opinion with tinyobjloader can never index out of bounds. */
    for (size_t t = 0; st == PS_OK && t < out->triangle_count; t++) {
        for (int c = 0; c < 3; c++) {
            int32_t v = out->tri_v[t * 3 + c], n = out->tri_n[t * 3 + c];
            if (v < 0 || (size_t)v >= out->position_count || n < -1 || (n >= 0 && (size_t)n >= out->normal_count))
                st = ps_error_set(err, PS_ERR_RANGE, "%s: triangle %zu has an index out of range", path, t);
        }
        int32_t m = out->tri_mat[t];
        if (st == PS_OK && (m < -1 || (m >= 0 && (size_t)m >= out->material_count)))
            st = ps_error_set(err, PS_ERR_RANGE, "%s: triangle %zu has a material out of range", path, t);
    }
    for (size_t i = 0; st == PS_OK && i < out->position_count * 3; i++)
        if (!isfinite(out->positions[i]))
            st = ps_error_set(err, PS_ERR_RANGE, "%s: vertex %zu is not finite as read", path, i / 3 + 1);
    for (size_t i = 0; st == PS_OK && i < out->normal_count * 3; i++)
        if (!isfinite(out->normals[i]))
            st = ps_error_set(err, PS_ERR_RANGE, "%s: normal %zu is not finite as read", path, i / 3 + 1);
    if (st == PS_OK && out->triangle_count == 0)
        st = ps_error_set(err, PS_ERR_PARSE, "%s: no triangles", path);
    for (size_t i = 0; st == PS_OK && i < out->material_count; i++) {
        int64_t j = ps_namemap_find(ps.mtl_names, out->materials[i].name);
        if (j >= 0) {
            out->materials[i].has_ns = ps.mtls[j].has_ns;
            out->materials[i].has_ni = ps.mtls[j].has_ni;
        }
    }
    if (st != PS_OK)
        ps_obj_free(out);
    free(ps.mtls);
    ps_namemap_destroy(ps.mtl_names);
    free(ps.mtl_text);
    free(text);
    return st;
}
