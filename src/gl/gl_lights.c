/* gl_lights.c: GL lights with shadow cubes, spot cones drawn per pixel, and
 * the emitters the eye sees (gl_render.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "gl/gl_internal.h"

/* The shadow test's slack for single-precision texgen. GL computes the
 * compared depth R/Q from eye coordinates in floats, with an error of a few
 * ulps of the coordinates' size (eye, scene and light positions, E), which
 * is E / distance-to-light depth units: tens of units for the ceiling above
 * a light (stress suite), beyond any polygon offset. Taking this many ulps
 * of E off R (not R/Q) moves the test by that error's own 1/distance law. */
#define SHADOW_TEXGEN_ULPS 32.0
#define FLOAT_ULP 1.1920928955078125e-07 /* 2^-23 */
/* Shadow maps are pushed back against self-shadowing (acne), in
 * glPolygonOffset's (factor, units). */
#define SHADOW_OFFSET_FACTOR 2.0f
#define SHADOW_OFFSET_UNITS 4.0f
/* A spot light's cone, drawn per pixel: a disc texture projected from the
 * light (thesis departure: GL's GL_SPOT_CUTOFF is applied per vertex, so the
 * cone's edge followed the mesh in steps a mesh edge wide, and photosplat-bench
 * measured the direct light of spot-lit scenes 17-24 % off in relMSE, all of
 * it along the edge). The texture is this many texels a side; the disc of the
 * cone fills it to SPOT_TEX_RADIUS, outside is 0 (and so is the border). */
#define SPOT_TEX_SIZE 512
#define SPOT_TEX_RADIUS 0.5

static const ps_preview_lights *lights_of(const ps_gl_renderer *r) { return r->in.lights; }

/* The bound texture: nearest texels, and 0 beyond its edges. */
static void nearest_with_zero_border(void)
{
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const GLfloat border[4] = {0, 0, 0, 0};
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
}

/* ---- shadow cubes ------------------------------------------------------------ */

static void face_frame(int f, ps_vec3 *forward, ps_vec3 *right, ps_vec3 *up)
{
    *forward = ps_cube_face_axes[f];
    ps_vec3 hint = fabs(forward->y) > 0.5 ? ps_v3(0, 0, 1) : ps_v3(0, 1, 0);
    *right = ps_v3_norm(ps_v3_cross(*forward, hint));
    *up = ps_v3_cross(*right, *forward);
}

/* A shadow cube's depth range: its near plane, and a far plane beyond the
 * scene's box as seen from the light. */
static void face_depth_range(const ps_gl_renderer *r, const ps_preview_light *v, double *znear, double *zfar)
{
    double nearest, farthest;
    ps_gl_box_range(r->in.bounds, v->pos, &nearest, &farthest);
    *znear = v->shadow_near;
    *zfar = fmax(farthest * 1.01, 2.0 * *znear);
}

static void light_face_matrices(const ps_gl_renderer *r, const ps_preview_light *v, int f, double proj[16], double view[16])
{
    ps_vec3 fw, rt, up;
    face_frame(f, &fw, &rt, &up);
    double znear, zfar;
    face_depth_range(r, v, &znear, &zfar);
    ps_gl_mat_perspective(1.0, 1.0, znear, zfar, proj);
    ps_gl_mat_look(v->pos, fw, rt, up, view);
}

/* ---- which faces a new scene must render again --------------------------------
 *
 * A face's depths are a function of its matrices (the light's position, near
 * and far planes: the key) and of the triangles inside its frustum; the
 * depth test keeps each texel's minimum, whatever the order they are drawn
 * in. So after a new scene a face stays as it is, texel for texel, when its
 * key is bit for bit the same and no object that changed (its triangles'
 * positions, compared by a hash and their box) lies in its frustum at its
 * old place or its new one. Changing a light's power or colour renders no
 * face; moving an object renders only the faces that see it; moving a light
 * renders all of its own. */

typedef struct ps_gl_shadow_key {
    ps_vec3 pos;
    double znear, zfar;
    unsigned fresh; /* faces whose texture holds this key's depths */
} ps_gl_shadow_key;

/* One object's triangles in the depth-only mesh. */
typedef struct ps_gl_object_sig {
    ps_aabb box;
    size_t vertices; /* 0: the mesh has no triangles of it */
    uint64_t hash;   /* FNV-1a over its positions' bits, in mesh order */
} ps_gl_object_sig;

/* A face's frustum is widened by this many shadow texels on each side
 * before it is tested against a box: a triangle can only write a texel
 * whose centre it covers, half a texel inside the face's edge, so a texel's
 * slack is far beyond GL's single-precision clipping error. */
#define SHADOW_FACE_SLACK_TEXELS 2.0

static uint64_t fnv_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

/* The signatures of mesh m's objects, *count of them (the largest object
 * index + 1); NULL with *count 0 when out of memory or empty. */
static ps_gl_object_sig *object_sigs(const ps_preview_mesh *m, size_t *count)
{
    *count = 0;
    size_t n = 0;
    for (size_t i = 0; i < m->range_count; i++)
        if ((size_t)m->ranges[i].object + 1 > n)
            n = (size_t)m->ranges[i].object + 1;
    if (n == 0)
        return NULL;
    ps_gl_object_sig *sig = calloc(n, sizeof *sig);
    if (!sig)
        return NULL;
    for (size_t o = 0; o < n; o++) {
        sig[o].box = ps_aabb_empty();
        sig[o].hash = 0xcbf29ce484222325ull;
    }
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_mesh_range *rg = &m->ranges[i];
        ps_gl_object_sig *g = &sig[rg->object];
        const float *p = m->positions + 3 * rg->first;
        g->hash = fnv_bytes(g->hash, p, 3 * rg->count * sizeof *p);
        g->vertices += rg->count;
        for (size_t k = 0; k < rg->count; k++)
            g->box = ps_aabb_point(g->box, ps_v3(p[3 * k], p[3 * k + 1], p[3 * k + 2]));
    }
    *count = n;
    return sig;
}

static bool same_sig(const ps_gl_object_sig *a, const ps_gl_object_sig *b)
{
    return a->vertices == b->vertices && a->hash == b->hash && memcmp(&a->box, &b->box, sizeof a->box) == 0;
}

/* Whether box b can meet face f's frustum of a light at pos: false only
 * when all its corners lie outside one of the four side planes (widened by
 * `slack`, a tangent), or behind the light. */
static bool box_meets_face(ps_aabb b, ps_vec3 pos, int f, double slack)
{
    ps_vec3 fw, rt, up;
    face_frame(f, &fw, &rt, &up);
    double k = 1.0 + slack;
    ps_vec3 planes[5] = {ps_v3_sub(ps_v3_scale(fw, k), rt), ps_v3_add(ps_v3_scale(fw, k), rt),
                         ps_v3_sub(ps_v3_scale(fw, k), up), ps_v3_add(ps_v3_scale(fw, k), up), fw};
    for (int p = 0; p < 5; p++) {
        bool any_inside = false;
        for (int c = 0; c < 8 && !any_inside; c++) {
            ps_vec3 q = ps_v3(c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z);
            any_inside = ps_v3_dot(planes[p], ps_v3_sub(q, pos)) >= 0.0;
        }
        if (!any_inside)
            return false;
    }
    return true;
}

static void free_shadows(ps_gl_renderer *r)
{
    for (size_t i = 0; i < r->shadow_lights; i++)
        for (int f = 0; f < PS_CUBE_FACES; f++)
            if (r->shadow[i][f])
                glDeleteTextures(1, &r->shadow[i][f]);
    free(r->shadow);
    r->shadow = NULL;
    free(r->shadow_keys);
    r->shadow_keys = NULL;
    r->shadow_lights = 0;
    r->shadows_valid = false;
}

static void free_profiles(ps_gl_renderer *r)
{
    if (r->profile_count)
        glDeleteTextures((GLsizei)r->profile_count, r->profile_tex);
    free(r->profile_tex);
    r->profile_tex = NULL;
    r->profile_count = 0;
}

void ps_gl_lights_free(ps_gl_renderer *r)
{
    free_shadows(r);
    free(r->object_sigs);
    r->object_sigs = NULL;
    r->object_sig_count = 0;
    free_profiles(r);
    if (r->spot_tex)
        glDeleteTextures(1, &r->spot_tex);
    r->spot_tex = 0;
}

/* The faces of the kept shadow cubes that stay fresh under the new scene
 * (r->in), given the old objects' signatures. */
static void keep_fresh_faces(ps_gl_renderer *r, const ps_gl_object_sig *old, size_t old_count)
{
    const ps_preview_lights *L = lights_of(r);
    const ps_gl_object_sig *now = r->object_sigs;
    size_t n = old_count > r->object_sig_count ? old_count : r->object_sig_count;
    double slack = SHADOW_FACE_SLACK_TEXELS * 2.0 / r->shadow_size; /* texels to a tangent: the face spans 2 */
    for (size_t i = 0; i < r->shadow_lights; i++) {
        const ps_preview_light *v = &L->lights[i];
        ps_gl_shadow_key *k = &r->shadow_keys[i];
        double znear, zfar;
        face_depth_range(r, v, &znear, &zfar);
        if (memcmp(&k->pos, &v->pos, sizeof v->pos) != 0 || k->znear != znear || k->zfar != zfar) {
            k->pos = v->pos;
            k->znear = znear;
            k->zfar = zfar;
            k->fresh = 0;
            continue;
        }
        for (size_t o = 0; o < n && k->fresh; o++) {
            const ps_gl_object_sig *a = o < old_count ? &old[o] : NULL, *b = o < r->object_sig_count ? &now[o] : NULL;
            if (a && b && same_sig(a, b))
                continue;
            for (int f = 0; f < PS_CUBE_FACES; f++)
                if ((k->fresh & (1u << f)) && ((a && a->vertices && box_meets_face(a->box, v->pos, f, slack)) ||
                                               (b && b->vertices && box_meets_face(b->box, v->pos, f, slack))))
                    k->fresh &= ~(1u << f);
        }
    }
}

static bool all_fresh(const ps_gl_renderer *r)
{
    for (size_t i = 0; i < r->shadow_lights; i++) {
        unsigned faces = lights_of(r)->lights[i].faces;
        if ((faces & ~r->shadow_keys[i].fresh) != 0)
            return false;
    }
    return true;
}

ps_status ps_gl_lights_reset(ps_gl_renderer *r, ps_error *err)
{
    r->lit_epoch++;
    free_profiles(r);
    size_t n = lights_of(r)->count;
    r->stats.virtual_lights = (unsigned)n;
    ps_gl_object_sig *old = r->object_sigs;
    size_t old_count = r->object_sig_count;
    r->object_sigs = object_sigs(r->in.coarse, &r->object_sig_count);
    /* The side the lights were planned at: a session's first picture has
     * coarse shadows, and its lights come again at the full side
     * (preview/session.h). */
    int size = lights_of(r)->shadow_size > 0 ? lights_of(r)->shadow_size
                                              : r->opt.shadow_size > 0 ? r->opt.shadow_size : PS_GL_SHADOW_SIZE;
    bool resized = size != r->shadow_size;
    r->shadow_size = size;
    /* The same number of GL lights at the same side: their textures are
     * kept, and so are the faces no change can reach. Otherwise (or without
     * the signatures, out of memory) every face is rendered again. */
    if (n > 0 && n == r->shadow_lights && old && r->object_sigs && !resized) {
        keep_fresh_faces(r, old, old_count);
    } else {
        free_shadows(r);
        if (n > 0) {
            r->shadow = calloc(n, sizeof *r->shadow);
            r->shadow_keys = calloc(n, sizeof *r->shadow_keys);
            if (!r->shadow || !r->shadow_keys) {
                free(old);
                free_shadows(r);
                return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the shadow maps of %zu GL lights", n);
            }
            r->shadow_lights = n;
            for (size_t i = 0; i < n; i++) {
                ps_gl_shadow_key *k = &r->shadow_keys[i];
                k->pos = lights_of(r)->lights[i].pos;
                face_depth_range(r, &lights_of(r)->lights[i], &k->znear, &k->zfar);
            }
        }
    }
    free(old);
    r->shadows_valid = all_fresh(r);
    if (n == 0)
        return PS_OK;
    const ps_preview_lights *L = lights_of(r);
    if (L->profile_count) {
        r->profile_tex = calloc(L->profile_count, sizeof *r->profile_tex);
        if (!r->profile_tex)
            return ps_error_set(err, PS_ERR_NOMEM, "out of memory for %zu IES light tables", L->profile_count);
        r->profile_count = L->profile_count;
        glGenTextures((GLsizei)r->profile_count, r->profile_tex);
        for (size_t i = 0; i < L->profile_count; i++) {
            const ps_preview_profile *p = &L->profiles[i];
            glBindTexture(GL_TEXTURE_CUBE_MAP, r->profile_tex[i]);
            glPixelStorei(GL_UNPACK_ALIGNMENT, 2);
            for (int f = 0; f < PS_CUBE_FACES; f++)
                glTexImage2D((GLenum)(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), 0, GL_LUMINANCE16, p->size, p->size, 0,
                             GL_LUMINANCE, GL_UNSIGNED_SHORT, p->texels + (size_t)f * p->size * p->size);
            /* Linear within a face and across its edges: the table's
             * intensity is continuous over directions. */
            ps_gl_cube_linear_clamped();
        }
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    }
    return PS_OK;
}

/* GL 3.3's or ARB_timer_query's: the version, else the extension. */
static bool has_timer_queries(void)
{
    const char *version = (const char *)glGetString(GL_VERSION);
    int major = 0, minor = 0;
    if (version && sscanf(version, "%d.%d", &major, &minor) == 2 && (major > 3 || (major == 3 && minor >= 3)))
        return true;
    const char *ext = (const char *)glGetString(GL_EXTENSIONS);
    return ext && strstr(ext, "GL_ARB_timer_query") != NULL;
}

void ps_gl_timer_init(ps_gl_renderer *r)
{
    if (!r->opt.gl_proc || !has_timer_queries())
        return;
    r->query_counter = (PFNGLQUERYCOUNTERPROC)r->opt.gl_proc("glQueryCounter");
    r->query_result = (PFNGLGETQUERYOBJECTUI64VPROC)r->opt.gl_proc("glGetQueryObjectui64v");
    if (r->query_counter && r->query_result)
        glGenQueries(1, &r->shadow_query);
    else
        r->query_counter = NULL, r->query_result = NULL;
}

void ps_gl_settle_shadow_timing(ps_gl_renderer *r)
{
    if (!r->shadow_query_pending)
        return;
    GLuint64 end = 0;
    r->query_result(r->shadow_query, GL_QUERY_RESULT, &end);
    r->stats.shadow_seconds_last += fmax(0.0, (double)((GLint64)end - r->shadow_gl_start) * 1e-9);
    r->shadow_query_pending = false;
}

void ps_gl_clear_shadow_timing(ps_gl_renderer *r)
{
    r->shadow_query_pending = false; /* a time to be dropped need not be waited for */
    r->stats.shadow_faces_last = 0;
    r->stats.shadow_seconds_last = 0.0;
}

void ps_gl_make_shadow_maps(ps_gl_renderer *r)
{
    /* Timed from a finish, as GL works behind the calls, to GL's end of the
     * maps: a timestamp query there, where the platform gives one, read
     * later (ps_gl_settle_shadow_timing), so that the passes after the maps
     * are issued while GL still draws them (llvmpipe draws its batches in
     * order: the lit passes sample finished maps), else a second finish. The
     * default box's first view waited 3-4 ms here for its six faces; its
     * prepass and its lit passes' first compiles now go on meanwhile. */
    ps_gl_settle_shadow_timing(r);
    glFinish();
    double t0 = ps_now_seconds();
    if (r->query_counter)
        glGetInteger64v(GL_TIMESTAMP, &r->shadow_gl_start);
    unsigned faces = 0;
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glViewport(0, 0, r->shadow_size, r->shadow_size);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(SHADOW_OFFSET_FACTOR, SHADOW_OFFSET_UNITS);
    for (size_t i = 0; i < r->shadow_lights; i++) {
        const ps_preview_light *v = &lights_of(r)->lights[i];
        GLuint *shadow = r->shadow[i];
        ps_gl_shadow_key *key = &r->shadow_keys[i];
        for (int f = 0; f < PS_CUBE_FACES; f++) {
            if (!(v->faces & (1u << f)) || (key->fresh & (1u << f)))
                continue;
            if (!shadow[f]) {
                glGenTextures(1, &shadow[f]);
                glBindTexture(GL_TEXTURE_2D, shadow[f]);
                glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, r->shadow_size, r->shadow_size, 0,
                             GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, NULL);
                /* Outside the face's square: depth 0 at the border, so the
                 * compare fails there and the neighbouring face lights it. */
                nearest_with_zero_border();
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_R_TO_TEXTURE);
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
                glTexParameteri(GL_TEXTURE_2D, GL_DEPTH_TEXTURE_MODE, GL_INTENSITY);
            }
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow[f], 0);
            glClear(GL_DEPTH_BUFFER_BIT);
            double proj[16], view[16];
            light_face_matrices(r, v, f, proj, view);
            glMatrixMode(GL_PROJECTION);
            glLoadMatrixd(proj);
            glMatrixMode(GL_MODELVIEW);
            glLoadMatrixd(view);
            ps_gl_draw_mesh(r, false, false);
            key->fresh |= 1u << f;
            r->stats.shadow_maps++;
            faces++;
        }
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    /* Draw and read buffers are per framebuffer: rebinding restores them. */
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    glBindTexture(GL_TEXTURE_2D, 0);
    r->shadows_valid = true;
    if (faces > 0)
        r->lit_epoch++; /* the lit passes' shadows are new */
    r->stats.shadow_faces_last += faces;
    if (r->query_counter) {
        r->query_counter(r->shadow_query, GL_TIMESTAMP);
        r->shadow_query_pending = true;
    } else {
        glFinish();
        r->stats.shadow_seconds_last += ps_now_seconds() - t0;
    }
}

/* Emissive faces (MTL Ke) as their own radiance, front side only. */
static void draw_emission(const ps_gl_renderer *r, double exposure)
{
    if (r->in.hide_emitters)
        return;
    const ps_preview_mesh *m = r->in.mesh;
    glEnableClientState(GL_VERTEX_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, m->positions);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_material *mat = &r->in.materials[m->ranges[i].material];
        uint32_t obj = m->ranges[i].object;
        if (ps_rgb_is_black(mat->emission))
            continue;
        /* As the lit passes: one quad's while its textures are laid, none of
         * theirs while they are drawn (gl_direct_bake.c). */
        if ((r->only_object != UINT32_MAX && obj != r->only_object) ||
            (r->skip_baked && obj < r->direct_bake.objects && r->direct_bake.object_baked[obj]))
            continue;
        glColor4f((GLfloat)(mat->emission.r * exposure), (GLfloat)(mat->emission.g * exposure),
                  (GLfloat)(mat->emission.b * exposure), 1.0f);
        glDrawArrays(GL_TRIANGLES, (GLint)m->ranges[i].first, (GLsizei)m->ranges[i].count);
    }
    glDisable(GL_CULL_FACE);
    glDisableClientState(GL_VERTEX_ARRAY);
}

/* ---- drawing ------------------------------------------------------------------ */

static void set_gl_light(const ps_preview_light *v, double exposure)
{
    GLfloat pos[4] = {(GLfloat)v->pos.x, (GLfloat)v->pos.y, (GLfloat)v->pos.z, 1.0f};
    GLfloat col[4] = {(GLfloat)(v->intensity.r * exposure), (GLfloat)(v->intensity.g * exposure),
                      (GLfloat)(v->intensity.b * exposure), 1.0f};
    GLfloat black[4] = {0, 0, 0, 1};
    glLightfv(GL_LIGHT0, GL_POSITION, pos);
    glLightfv(GL_LIGHT0, GL_AMBIENT, black);
    glLightfv(GL_LIGHT0, GL_DIFFUSE, col);
    glLightfv(GL_LIGHT0, GL_SPECULAR, col);
    glLightf(GL_LIGHT0, GL_CONSTANT_ATTENUATION, 0.0f);
    glLightf(GL_LIGHT0, GL_LINEAR_ATTENUATION, 0.0f);
    glLightf(GL_LIGHT0, GL_QUADRATIC_ATTENUATION, 1.0f);
    if (v->cutoff_deg < 180.0 && !ps_preview_light_is_spot(v)) {
        GLfloat dir[3] = {(GLfloat)v->dir.x, (GLfloat)v->dir.y, (GLfloat)v->dir.z};
        glLightfv(GL_LIGHT0, GL_SPOT_DIRECTION, dir);
        glLightf(GL_LIGHT0, GL_SPOT_CUTOFF, (GLfloat)v->cutoff_deg);
        glLightf(GL_LIGHT0, GL_SPOT_EXPONENT, (GLfloat)v->exponent);
    } else {
        glLightf(GL_LIGHT0, GL_SPOT_CUTOFF, 180.0f);
        glLightf(GL_LIGHT0, GL_SPOT_EXPONENT, 0.0f);
    }
}

/* The spot texture: 1 inside the disc, 0 outside and at the border. */
void ps_gl_make_spot_texture(ps_gl_renderer *r)
{
    if (r->spot_tex)
        return;
    uint8_t *texels = malloc((size_t)SPOT_TEX_SIZE * SPOT_TEX_SIZE);
    if (!texels)
        return; /* no texture: the cone falls back to GL's per-vertex cutoff */
    for (int y = 0; y < SPOT_TEX_SIZE; y++)
        for (int x = 0; x < SPOT_TEX_SIZE; x++) {
            double u = (x + 0.5) / SPOT_TEX_SIZE - 0.5, w = (y + 0.5) / SPOT_TEX_SIZE - 0.5;
            texels[(size_t)y * SPOT_TEX_SIZE + (size_t)x] = u * u + w * w <= SPOT_TEX_RADIUS * SPOT_TEX_RADIUS ? 255 : 0;
        }
    glGenTextures(1, &r->spot_tex);
    glBindTexture(GL_TEXTURE_2D, r->spot_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_LUMINANCE8, SPOT_TEX_SIZE, SPOT_TEX_SIZE, 0, GL_LUMINANCE, GL_UNSIGNED_BYTE, texels);
    /* Nearest: the edge is as sharp as the reference's, and a texel is far
     * finer than a mesh edge. */
    nearest_with_zero_border();
    glBindTexture(GL_TEXTURE_2D, 0);
    free(texels);
}

/* On texture unit 1: the spot texture projected from spot v, so that a point
 * p maps to 0.5 + 0.5 (p - L).(u, v) / (tan(cutoff) (p - L).axis), inside the
 * disc exactly when inside the cone; clip plane 2 keeps what lies behind the
 * light (where the projection flips) out. Set while the modelview is the
 * camera's view (world-space eye-linear planes, as the shadow texgen). */
static void begin_spot(const ps_gl_renderer *r, const ps_preview_light *v)
{
    ps_vec3 u, w;
    ps_v3_basis(v->dir, &u, &w);
    double k = SPOT_TEX_RADIUS / tan(v->cutoff_deg * PS_PI / 180.0);
    ps_vec3 rows[3] = {ps_v3_add(ps_v3_scale(v->dir, 0.5), ps_v3_scale(u, k)),
                       ps_v3_add(ps_v3_scale(v->dir, 0.5), ps_v3_scale(w, k)), v->dir};
    const GLenum coords[3] = {GL_S, GL_T, GL_Q};
    const GLenum gens[3] = {GL_TEXTURE_GEN_S, GL_TEXTURE_GEN_T, GL_TEXTURE_GEN_Q};
    glActiveTexture(GL_TEXTURE1);
    glEnable(GL_TEXTURE_2D);
    glBindTexture(GL_TEXTURE_2D, r->spot_tex);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    for (int i = 0; i < 3; i++) {
        GLdouble plane[4] = {rows[i].x, rows[i].y, rows[i].z, -ps_v3_dot(rows[i], v->pos)};
        glTexGeni(coords[i], GL_TEXTURE_GEN_MODE, GL_EYE_LINEAR);
        glTexGendv(coords[i], GL_EYE_PLANE, plane);
        glEnable(gens[i]);
    }
    glActiveTexture(GL_TEXTURE0);
    GLdouble front[4] = {v->dir.x, v->dir.y, v->dir.z, -ps_v3_dot(v->dir, v->pos)};
    glClipPlane(GL_CLIP_PLANE2, front);
    glEnable(GL_CLIP_PLANE2);
}

/* On texture unit 1: IES light v's cube table looked up towards p - L,
 * p the world point being lit (eye-linear texgen while the modelview is the
 * camera's view sees world coordinates, as the shadow texgen), modulating
 * the lit colour per pixel. */
static void begin_profile(const ps_gl_renderer *r, const ps_preview_light *v)
{
    const GLenum coords[3] = {GL_S, GL_T, GL_R};
    const GLenum gens[3] = {GL_TEXTURE_GEN_S, GL_TEXTURE_GEN_T, GL_TEXTURE_GEN_R};
    const ps_vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    glActiveTexture(GL_TEXTURE1);
    glEnable(GL_TEXTURE_CUBE_MAP);
    glBindTexture(GL_TEXTURE_CUBE_MAP, r->profile_tex[v->profile]);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    for (int i = 0; i < 3; i++) {
        GLdouble plane[4] = {axes[i].x, axes[i].y, axes[i].z, -ps_v3_dot(axes[i], v->pos)};
        glTexGeni(coords[i], GL_TEXTURE_GEN_MODE, GL_EYE_LINEAR);
        glTexGendv(coords[i], GL_EYE_PLANE, plane);
        glEnable(gens[i]);
    }
    glActiveTexture(GL_TEXTURE0);
}

static void end_profile(void)
{
    glActiveTexture(GL_TEXTURE1);
    glDisable(GL_TEXTURE_GEN_S);
    glDisable(GL_TEXTURE_GEN_T);
    glDisable(GL_TEXTURE_GEN_R);
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    glDisable(GL_TEXTURE_CUBE_MAP);
    glActiveTexture(GL_TEXTURE0);
}

static void end_spot(void)
{
    glActiveTexture(GL_TEXTURE1);
    glDisable(GL_TEXTURE_GEN_S);
    glDisable(GL_TEXTURE_GEN_T);
    glDisable(GL_TEXTURE_GEN_Q);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_TEXTURE_2D);
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_CLIP_PLANE2);
}

/* Texgen planes that take world points to the shadow map's [0,1]^3 (the
 * rows of bias * projection * view), set while the modelview is the camera's
 * view so that GL's eye-linear planes see world coordinates. */
static void set_shadow_texgen(const double light_proj[16], const double light_view[16], double slack)
{
    static const double bias[16] = {0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0.5, 0.5, 0.5, 1};
    double t[16];
    ps_gl_mat_mul(bias, light_proj, t);
    ps_gl_mat_mul(t, light_view, t);
    const GLenum coords[4] = {GL_S, GL_T, GL_R, GL_Q};
    const GLenum gens[4] = {GL_TEXTURE_GEN_S, GL_TEXTURE_GEN_T, GL_TEXTURE_GEN_R, GL_TEXTURE_GEN_Q};
    for (int k = 0; k < 4; k++) {
        GLdouble plane[4] = {t[k], t[4 + k], t[8 + k], t[12 + k] - (k == 2 ? slack : 0.0)};
        glTexGeni(coords[k], GL_TEXTURE_GEN_MODE, GL_EYE_LINEAR);
        glTexGendv(coords[k], GL_EYE_PLANE, plane);
        glEnable(gens[k]);
    }
}

static void disable_texgen(void)
{
    glDisable(GL_TEXTURE_GEN_S);
    glDisable(GL_TEXTURE_GEN_T);
    glDisable(GL_TEXTURE_GEN_R);
    glDisable(GL_TEXTURE_GEN_Q);
}

/* A shadowed pass's clip planes: the near plane, then the four sides of the
 * face's pyramid (GL_CLIP_PLANE2 is the spot's; GL has at least six). */
#define FACE_CLIP_PLANES 5
static const GLenum face_clip_planes[FACE_CLIP_PLANES] = {GL_CLIP_PLANE1, GL_CLIP_PLANE0, GL_CLIP_PLANE3,
                                                          GL_CLIP_PLANE4, GL_CLIP_PLANE5};

void ps_gl_draw_direct(ps_gl_renderer *r, double exposure, bool shadows)
{
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
    glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_TRUE);
    const GLfloat no_ambient[4] = {0, 0, 0, 1};
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, no_ambient);
    glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT, no_ambient);
    glMaterialfv(GL_FRONT_AND_BACK, GL_EMISSION, no_ambient);
    for (size_t i = 0; i < r->shadow_lights; i++) {
        const ps_preview_light *v = &lights_of(r)->lights[i];
        set_gl_light(v, exposure);
        bool spot = ps_preview_light_is_spot(v) && r->spot_tex;
        bool profile = v->profile >= 0 && (size_t)v->profile < r->profile_count;
        if (spot)
            begin_spot(r, v);
        if (profile)
            begin_profile(r, v);
        if (!shadows) {
            ps_gl_draw_mesh_within(r, NULL, 0);
            r->stats.light_passes++;
            if (spot)
                end_spot();
            if (profile)
                end_profile();
            continue;
        }
        glEnable(GL_TEXTURE_2D);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        for (int c = 0; c < FACE_CLIP_PLANES; c++)
            glEnable(face_clip_planes[c]);
        for (int f = 0; f < PS_CUBE_FACES; f++) {
            if (!(v->faces & (1u << f)))
                continue;
            const ps_vec3 axis = ps_cube_face_axes[f];
            double proj[16], view[16];
            light_face_matrices(r, v, f, proj, view);
            set_shadow_texgen(proj, view, SHADOW_TEXGEN_ULPS * FLOAT_ULP * (r->eye_extent + ps_v3_len(v->pos)));
            /* Only the face's own pyramid, a little widened: outside its
             * square the map's border (depth 0) lights nothing, so those
             * pixels need not be drawn (about a third of the fill of the
             * half-space in front of the face, which the pyramid lies in:
             * behind the light the projection would fold points back into
             * the map). */
            ps_vec3 fw, rt, up;
            face_frame(f, &fw, &rt, &up);
            double k = 1.0 + SHADOW_FACE_SLACK_TEXELS * 2.0 / r->shadow_size;
            const ps_vec3 sides[4] = {ps_v3_sub(ps_v3_scale(fw, k), rt), ps_v3_add(ps_v3_scale(fw, k), rt),
                                      ps_v3_sub(ps_v3_scale(fw, k), up), ps_v3_add(ps_v3_scale(fw, k), up)};
            double planes[FACE_CLIP_PLANES][4];
            for (int c = 0; c < 4; c++) {
                GLdouble side[4] = {sides[c].x, sides[c].y, sides[c].z, -ps_v3_dot(sides[c], v->pos)};
                glClipPlane(face_clip_planes[1 + c], side);
                memcpy(planes[1 + c], side, sizeof side);
            }
            /* Nor what lies nearer than the near plane: outside the face's
             * square its depth would pass the test against the border's 0.
             * Every point this face owns lies beyond (at least nearest /
             * sqrt 3 > PS_SHADOW_NEAR_SHARE * nearest away along the axis). */
            GLdouble plane[4] = {axis.x, axis.y, axis.z, -ps_v3_dot(axis, v->pos) - v->shadow_near};
            glClipPlane(face_clip_planes[0], plane);
            memcpy(planes[0], plane, sizeof plane);
            glBindTexture(GL_TEXTURE_2D, r->shadow[i][f]);
            /* Only the objects in the face's pyramid: a point light in a
             * box lights each wall from two or three faces and the spheres
             * from one, where every face lit all 143 070 of the default
             * scene's vertices (llvmpipe's lit passes are vertex-bound). */
            ps_gl_draw_mesh_within(r, (const double(*)[4])planes, FACE_CLIP_PLANES);
            r->stats.light_passes++;
        }
        for (int c = 0; c < FACE_CLIP_PLANES; c++)
            glDisable(face_clip_planes[c]);
        disable_texgen();
        glBindTexture(GL_TEXTURE_2D, 0);
        glDisable(GL_TEXTURE_2D);
        if (spot)
            end_spot();
        if (profile)
            end_profile();
    }
    glDisable(GL_LIGHT0);
    glDisable(GL_LIGHTING);
    draw_emission(r, exposure);
}

/* Area lights as the eye sees them (the reference renderer's emitters): quad
 * and disc lights from their emitting side, sphere lights from outside, in
 * their radiance times exposure, or black when the direct layer is off (its
 * term; the other layers still see them in the way). They are drawn over
 * the lit scene with depth writes, so splats behind them stay hidden; they
 * are not in the shadow maps, as photons and shadow rays pass through them. */
#define DISC_SEGMENTS 64

/* The emitters' shapes, in their radiance times exposure (black without
 * the direct layer), under the caller's depth and stencil state. */
static void draw_emitter_shapes(const ps_gl_renderer *r, double exposure, bool direct)
{
    const ps_preview_lights *lights = lights_of(r);
    for (size_t l = 0; l < lights->emitter_count; l++) {
        const ps_preview_emitter *L = &lights->emitters[l];
        double k = direct ? exposure : 0.0;
        glColor4f((GLfloat)(L->radiance.r * k), (GLfloat)(L->radiance.g * k), (GLfloat)(L->radiance.b * k), 1.0f);
        if (L->type == PS_LIGHT_QUAD) {
            ps_vec3 c[4] = {L->position, ps_v3_add(L->position, L->edge1),
                            ps_v3_add(ps_v3_add(L->position, L->edge1), L->edge2), ps_v3_add(L->position, L->edge2)};
            glBegin(GL_QUADS); /* counter-clockwise about edge1 x edge2, the emitting side */
            for (int i = 0; i < 4; i++)
                glVertex3d(c[i].x, c[i].y, c[i].z);
            glEnd();
        } else if (L->type == PS_LIGHT_DISC) {
            ps_vec3 t, b;
            ps_v3_basis(L->normal, &t, &b);
            glBegin(GL_TRIANGLE_FAN);
            glVertex3d(L->position.x, L->position.y, L->position.z);
            for (int i = 0; i <= DISC_SEGMENTS; i++) {
                double a = 2.0 * PS_PI * i / DISC_SEGMENTS;
                ps_vec3 q = ps_v3_add(L->position, ps_v3_add(ps_v3_scale(t, L->radius * cos(a)),
                                                             ps_v3_scale(b, L->radius * sin(a))));
                glVertex3d(q.x, q.y, q.z);
            }
            glEnd();
        } else {
            const ps_trimesh *m = &L->sphere;
            glBegin(GL_TRIANGLES);
            for (uint32_t i = 0; i < 3 * m->triangle_count; i++) {
                ps_vec3 q = m->positions[m->indices[i]];
                glVertex3d(q.x, q.y, q.z);
            }
            glEnd();
        }
    }
}

void ps_gl_draw_emitters(const ps_gl_renderer *r, double exposure, bool direct)
{
    if (r->in.hide_emitters)
        return;
    glDisable(GL_BLEND);
    glDisable(GL_LIGHTING);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    /* Their pixels belong to no object: splats are not clipped into them. */
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_ALWAYS, 0, 0xff);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    draw_emitter_shapes(r, exposure, direct);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_CULL_FACE);
}

void ps_gl_draw_emitters_colour(const ps_gl_renderer *r, double exposure, bool direct)
{
    if (r->in.hide_emitters || lights_of(r)->emitter_count == 0)
        return;
    glDisable(GL_BLEND);
    glDisable(GL_LIGHTING);
    /* Their own depth, to the bit: the same shapes and matrices. */
    glDepthFunc(GL_EQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    draw_emitter_shapes(r, exposure, direct);
    glDisable(GL_CULL_FACE);
    glDepthFunc(GL_LEQUAL);
}

