/* gl_specular_blur.c: blurred cube-map levels for glossy lobes (gl_specular_blur.h). */
#include "gl/gl_specular_blur.h"

#include <stdlib.h>
#include <string.h>

#include "gl/gl_internal.h"
#include "preview/specular.h"
#include "preview/specular_glossy.h"

typedef struct level {
    bool has, only;
    double m;              /* the lobe's exponent */
    int in_size;
    ps_glossy_filter *filter;
    GLuint tex;
    unsigned pending;      /* bit f: face f to redo */
} level;

struct ps_gl_glossy {
    level lv[PS_SPECULAR_MAX_CUBES];
    int count;
    int cursor;            /* the next (cube, face) looked at, round-robin */
    float *face;           /* one read-back face or one level face, RGBA */
    size_t face_cap;
};

ps_status ps_gl_glossy_create(ps_gl_glossy **out, ps_error *err)
{
    *out = calloc(1, sizeof **out);
    return *out ? PS_OK : ps_error_set(err, PS_ERR_NOMEM, "out of memory for the glossy levels");
}

static void drop_level(level *l)
{
    ps_glossy_filter_destroy(l->filter);
    if (l->tex)
        glDeleteTextures(1, &l->tex);
    memset(l, 0, sizeof *l);
}

void ps_gl_glossy_destroy(ps_gl_glossy *g)
{
    if (!g)
        return;
    for (int c = 0; c < PS_SPECULAR_MAX_CUBES; c++)
        drop_level(&g->lv[c]);
    free(g->face);
    free(g);
}

static float *face_buffer(ps_gl_glossy *g, int size)
{
    size_t n = 4 * (size_t)size * (size_t)size;
    if (g->face_cap < n) {
        float *p = realloc(g->face, n * sizeof *p);
        if (!p)
            return NULL;
        g->face = p;
        g->face_cap = n;
    }
    return g->face;
}

ps_status ps_gl_glossy_sync(ps_gl_glossy *g, ps_session *s, int cube_count, int cube_size, ps_error *err)
{
    const ps_specular *sp = ps_session_specular(s);
    const ps_preview_mesh *mesh = ps_session_mesh(s);
    const ps_material *mats = ps_session_materials(s);
    bool has[PS_SPECULAR_MAX_CUBES] = {false}, other[PS_SPECULAR_MAX_CUBES] = {false};
    double m[PS_SPECULAR_MAX_CUBES] = {0};
    const ps_specular_range *r = ps_specular_ranges(sp);
    for (size_t i = 0; i < ps_specular_range_count(sp); i++) {
        const ps_material *mat = &mats[mesh->ranges[r[i].range].material];
        int c = r[i].cube;
        if (!ps_glossy_wants(mat)) {
            other[c] = true;
        } else if (!has[c]) {
            has[c] = true;
            m[c] = ps_glossy_lobe_exponent(mat);
        }
    }
    g->count = cube_count;
    for (int c = 0; c < PS_SPECULAR_MAX_CUBES; c++) {
        level *l = &g->lv[c];
        if (c >= cube_count || !has[c]) {
            drop_level(l);
            continue;
        }
        l->only = !other[c];
        if (l->has && l->m == m[c] && l->in_size == cube_size)
            continue;
        drop_level(l);
        int b = ps_glossy_level_size(m[c], cube_size);
        ps_status st = ps_glossy_filter_create(cube_size, b, m[c], &l->filter, err);
        if (st != PS_OK)
            return st;
        l->has = true;
        l->only = !other[c];
        l->m = m[c];
        l->in_size = cube_size;
        l->pending = 0; /* black, as the cube is, until its faces are read */
        float *black = calloc(4 * (size_t)b * b, sizeof *black);
        if (!black) {
            drop_level(l);
            return ps_error_set(err, PS_ERR_NOMEM, "out of memory for a glossy level of %d^2", b);
        }
        glGenTextures(1, &l->tex);
        glBindTexture(GL_TEXTURE_CUBE_MAP, l->tex);
        for (int f = 0; f < 6; f++)
            glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, GL_RGBA16F, b, b, 0, GL_RGBA, GL_FLOAT, black);
        free(black);
        ps_gl_cube_linear_clamped();
        glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    }
    return PS_OK;
}

bool ps_gl_glossy_has(const ps_gl_glossy *g, int c) { return c >= 0 && c < g->count && g->lv[c].has; }
bool ps_gl_glossy_only(const ps_gl_glossy *g, int c) { return ps_gl_glossy_has(g, c) && g->lv[c].only; }
GLuint ps_gl_glossy_texture(const ps_gl_glossy *g, int c) { return ps_gl_glossy_has(g, c) ? g->lv[c].tex : 0; }

void ps_gl_glossy_read_face(ps_gl_glossy *g, int c, int f, GLuint tex, int size)
{
    if (!ps_gl_glossy_has(g, c) || size != g->lv[c].in_size)
        return;
    float *buf = face_buffer(g, size);
    if (!buf)
        return; /* the level keeps its last face */
    glBindTexture(GL_TEXTURE_CUBE_MAP, tex);
    glGetTexImage(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, GL_RGBA, GL_FLOAT, buf);
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    ps_glossy_filter_set_face(g->lv[c].filter, f, buf);
    g->lv[c].pending = 0x3f; /* every level face sees every cube face */
}

bool ps_gl_glossy_pending(const ps_gl_glossy *g)
{
    for (int c = 0; c < g->count; c++)
        if (g->lv[c].has && g->lv[c].pending)
            return true;
    return false;
}

bool ps_gl_glossy_blur(ps_gl_glossy *g, int faces)
{
    int total = 6 * g->count, done = 0;
    if (total == 0)
        return false;
    g->cursor %= total;
    for (int i = 0; i < total && (faces <= 0 || done < faces); i++) {
        int c = g->cursor / 6, f = g->cursor % 6;
        g->cursor = (g->cursor + 1) % total;
        level *l = &g->lv[c];
        if (!l->has || !(l->pending & (1u << f)))
            continue;
        int b = ps_glossy_filter_out_size(l->filter);
        float *buf = face_buffer(g, b);
        if (!buf)
            return done > 0;
        ps_glossy_filter_face(l->filter, f, buf);
        glBindTexture(GL_TEXTURE_CUBE_MAP, l->tex);
        glTexSubImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, 0, 0, b, b, GL_RGBA, GL_FLOAT, buf);
        glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
        l->pending &= ~(1u << f);
        done++;
    }
    return done > 0;
}
