/* gl_specular.c: the specular layer's cube maps and lookups (gl_specular.h). */
#include "gl/gl_specular.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"

#include "gl/gl_internal.h"
#include "gl/gl_specular_blur.h"
#include "preview/specular_glossy.h"

/* GL's cube faces in order (+X, -X, +Y, -Y, +Z, -Z) and, for each, the
 * camera that renders it: texel (s, t) of face +X looks along
 * (1, -(2t - 1), -(2s - 1)) (the GL spec's table 3.19, sc = -rz, tc = -ry),
 * so the face's camera has right = (0, 0, -1) and up = (0, -1, 0); likewise
 * for the others. right x up = -forward: proper rotations, no mirror image. */
static const float face_axes[6][3][3] = {
    /* forward, right, up */
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},  {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
    {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},    {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
    {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},   {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}},
};

struct ps_gl_specular {
    int size;
    /* Two maps a cube: the one shown, and the one its faces are rendered
     * into (back), which is shown once all six faces of it were rendered
     * from one centre since the last change (back_faces, a bit a face). A
     * map is never shown with faces from two places or two scenes: after
     * an edit the old one shows (its lookups looking from the old centre,
     * ps_specular_set_lookup_centre) until the new one is whole. A cube
     * never shown shows `black`; its back map is made when its first face
     * is rendered into it (0 until then). */
    GLuint cube[PS_SPECULAR_MAX_CUBES], back[PS_SPECULAR_MAX_CUBES];
    GLuint black; /* a 1x1 black cube map, shared */
    unsigned back_faces[PS_SPECULAR_MAX_CUBES];
    ps_vec3 back_centre[PS_SPECULAR_MAX_CUBES];
    int cube_count;
    GLuint fbo, depth_stencil;
    ps_splat_batch batch;
    /* The round-robin over (cube, face): the next face, and how many have
     * been rendered since the scene last changed and since it settled. */
    int cursor;
    int since_change, since_settled;
    unsigned layers;   /* what the cubes were rendered with: the frame's layers */
    uint64_t edits, epoch; /* what the cubes were drawn from (a change starts a round) */
    bool frozen;       /* filled by a test: never rendered over */
    bool cubes_changed;  /* a cube completed (or all faces drawn): the layer to redraw */
    unsigned faces_rendered;
    /* A front map holds a picture (a cube shown, or filled by a test): until
     * then every cube is black and the layer adds nothing, so its eye paths
     * wait (ps_session_set_specular_wait). New cubes are black again. */
    bool lit;
    /* The time budget: seconds a face took (the last one, finished), and
     * the share of tau saved up for the next. */
    double face_seconds, credit;
    uint64_t arrived; /* photons emitted (both maps) when last looked */
    /* The layered path's texture. */
    GLuint layer_tex, layer_fbo;
    int layer_w, layer_h;
    GLuint layer_depth;
    bool layer_valid;
    float *scaled; /* weights times exposure */
    size_t scaled_cap;
    ps_gl_glossy *glossy; /* the glossy objects' blurred levels (gl_specular_blur.h) */
    float *xy; /* the per-pixel points' window coordinates */
    size_t xy_cap;
    unsigned *tris; /* a term's lit triangles of one range (ps_specular_weighted_triangles) */
    size_t tris_cap;
    int first_refreshes; /* the first round over this many refreshes; 0: budgeted */
    /* ps_gl_specular_set_deadline: faces past the first round end by
     * `deadline` (0: none), as each face's last time predicts: the faces
     * differ several-fold (one looking down on the caustic, the shadows of
     * an area light's virtual lights). face_max: the dearest seen, for a
     * face not timed yet. */
    double deadline;
    bool idle; /* ps_gl_specular_idle: faces while they fit, the first round's too */
    double face_guess; /* ps_gl_specular_set_face_guess */
    double paths_deadline; /* ps_gl_specular_set_paths_deadline (0: none) */
    bool first_held; /* ps_gl_specular_hold_first_round */
    /* Cubes shown since the last edit, layer set or cube set (bit c). The
     * first round shows each once, quick and whatever the budget; new
     * virtual lights of the same lights (an area light refined,
     * ps_session_refine_lights) keep them shown, and their faces come again
     * in budgeted rounds with every shadow. (A refinement used to start a
     * first round: its quick faces left out the shadows of the area box's
     * 16 virtual lights, lighting the floor under the mirror sphere in its
     * reflection where one virtual light's faces had them, the specular
     * layer's relMSE 0.047 from then on against 0.005.) */
    unsigned shown;
    float face_time[PS_SPECULAR_MAX_CUBES * 6];
    double face_max;
    /* Fill (ps_session_env_fill): each face's now (fill_now, for the photons
     * emitted, layers and edits in fill_key), and what the times above were
     * measured at: face_fill a face's, face_seconds_fill the mean of the
     * last refresh's faces (face_foreseen). */
    double fill_now[PS_SPECULAR_MAX_CUBES * 6];
    float face_fill[PS_SPECULAR_MAX_CUBES * 6];
    double face_seconds_fill;
    uint64_t fill_key[3];
    bool fill_known;
};

void ps_gl_specular_set_deadline(ps_gl_specular *g, double at) { g->deadline = at > 0.0 ? at : 0.0; }

void ps_gl_specular_set_paths_deadline(ps_gl_specular *g, double at) { g->paths_deadline = at > 0.0 ? at : 0.0; }

bool ps_gl_specular_face_fits(double now, double at, double estimate) { return at <= 0.0 || now + estimate <= at; }

double ps_gl_specular_face_foreseen(double seconds, double fill_then, double fill_now)
{
    if (!(fill_then > 0.0) || !(fill_now > fill_then))
        return seconds;
    return seconds * pow(fill_now / fill_then, PS_GL_SPECULAR_FILL_GROWTH);
}

/* Each face's fill for the photons there now (fill_now), made again only
 * when they, the layers or the scene changed (a pass over at most
 * PS_GL_SPECULAR_ENV_CAUSTIC + _GLOBAL photons a cube). */
static void update_fill(ps_gl_specular *g, ps_session *s)
{
    ps_session_counts counts;
    ps_session_get_counts(s, &counts);
    uint64_t key[3] = {counts.map[0].emitted + counts.map[1].emitted, ps_session_get_settings(s)->layers,
                       ps_session_edits(s)};
    if (g->fill_known && memcmp(key, g->fill_key, sizeof key) == 0)
        return;
    const size_t most[PS_MAP_COUNT] = {PS_GL_SPECULAR_ENV_CAUSTIC, PS_GL_SPECULAR_ENV_GLOBAL};
    const ps_specular *sp = ps_session_specular(s);
    for (int c = 0; c < g->cube_count; c++)
        ps_session_env_fill(s, ps_specular_cube_centre(sp, c), g->size, most, g->fill_now + 6 * c);
    memcpy(g->fill_key, key, sizeof key);
    g->fill_known = true;
}

/* Face i's foreseen time: its own last, scaled up by the fill it has now;
 * never timed, the timed face nearest it in fill (the last refresh's mean
 * face when none was timed), scaled either way. (Taken from the dearest
 * face seen, faces of 1.0-1.3*10^6 pixels were foreseen at 0.08-0.09 s
 * where they took 0.03-0.05 s, behind the 0.26-0.28 s of one over the
 * caustic.) */
static double face_foreseen(const ps_gl_specular *g, int i)
{
    double now = g->fill_now[i]; /* update_fill first */
    if (g->face_time[i] > 0.0)
        return ps_gl_specular_face_foreseen(g->face_time[i], g->face_fill[i], now);
    double t = g->face_seconds, then = g->face_seconds_fill, gap = HUGE_VAL;
    for (int j = 0; j < 6 * g->cube_count && now > 0.0; j++) {
        double d = g->face_time[j] > 0.0 && g->face_fill[j] > 0.0 ? fabs(log(g->face_fill[j] / now)) : HUGE_VAL;
        if (d < gap)
            gap = d, t = g->face_time[j], then = g->face_fill[j];
    }
    if (!(t > 0.0))
        return g->face_max;
    return then > 0.0 && now > 0.0 ? t * pow(now / then, PS_GL_SPECULAR_FILL_GROWTH) : t;
}

/* The face at the cursor's predicted time (nothing timed yet: the guess
 * where a wait or a held first round foresees it, else 0, the first comes). */
static double face_estimate(ps_gl_specular *g, ps_session *s)
{
    if (g->face_time[g->cursor] <= 0.0 && g->face_max <= 0.0)
        return g->idle || g->first_held ? g->face_guess : 0.0;
    update_fill(g, s);
    return face_foreseen(g, g->cursor);
}

void ps_gl_specular_set_first_round(ps_gl_specular *g, int refreshes) { g->first_refreshes = refreshes > 0 ? refreshes : 0; }

void ps_gl_specular_hold_first_round(ps_gl_specular *g, bool held) { g->first_held = held; }

void ps_gl_specular_set_face_guess(ps_gl_specular *g, double seconds) { g->face_guess = seconds > 0.0 ? seconds : 0.0; }

/* A cube map of side `size`, its texels as `texels` (RGBA floats, the same
 * for every face) or left undefined (NULL) for one whose six faces are all
 * rendered before it is shown. */
static GLuint new_cube_texture(int size, const float *texels)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_CUBE_MAP, tex);
    for (int f = 0; f < 6; f++)
        glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, GL_RGBA16F, size, size, 0, GL_RGBA, GL_FLOAT, texels);
    ps_gl_cube_linear_clamped();
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    return tex;
}

/* Cube c's back map, made when a face is first rendered into it. */
static GLuint back_map(ps_gl_specular *g, int c)
{
    if (!g->back[c])
        g->back[c] = new_cube_texture(g->size, NULL);
    return g->back[c];
}

static void delete_cubes(ps_gl_specular *g)
{
    for (int c = 0; c < g->cube_count; c++) {
        if (g->cube[c] != g->black)
            glDeleteTextures(1, &g->cube[c]);
        if (g->back[c])
            glDeleteTextures(1, &g->back[c]);
        g->cube[c] = g->back[c] = 0;
    }
}

ps_status ps_gl_specular_create(int cube_size, ps_gl_specular **out, ps_error *err)
{
    *out = NULL;
    ps_gl_specular *g = calloc(1, sizeof *g);
    if (!g)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the specular layer");
    g->size = cube_size > 0 ? cube_size : PS_GL_SPECULAR_CUBE_SIZE;
    ps_status st = ps_gl_glossy_create(&g->glossy, err);
    if (st != PS_OK) {
        free(g);
        return st;
    }
    ps_splat_batch_init(&g->batch);
    glGenFramebuffers(1, &g->fbo);
    glGenRenderbuffers(1, &g->depth_stencil);
    glBindRenderbuffer(GL_RENDERBUFFER, g->depth_stencil);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, g->size, g->size);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    *out = g;
    return PS_OK;
}

void ps_gl_specular_destroy(ps_gl_specular *g)
{
    if (!g)
        return;
    delete_cubes(g);
    if (g->black)
        glDeleteTextures(1, &g->black);
    glDeleteFramebuffers(1, &g->fbo);
    glDeleteRenderbuffers(1, &g->depth_stencil);
    if (g->layer_tex)
        glDeleteTextures(1, &g->layer_tex);
    if (g->layer_fbo)
        glDeleteFramebuffers(1, &g->layer_fbo);
    ps_splat_batch_free(&g->batch);
    ps_gl_glossy_destroy(g->glossy);
    free(g->scaled);
    free(g->xy);
    free(g->tris);
    free(g);
}

unsigned ps_gl_specular_faces_rendered(const ps_gl_specular *g) { return g->faces_rendered; }

int ps_gl_specular_maps(const ps_gl_specular *g)
{
    int n = 0;
    for (int c = 0; c < g->cube_count; c++)
        n += (g->cube[c] != g->black) + (g->back[c] != 0);
    return n;
}

void ps_gl_specular_redraw_all(ps_gl_specular *g)
{
    /* A settled round from here, its back maps begun afresh. */
    g->since_change = g->since_settled = 0;
    memset(g->back_faces, 0, sizeof g->back_faces);
}

/* n cubes, each showing the shared black map until its back map is whole.
 * Maps of their own only as faces are rendered: black ones made here for
 * every cube, shown and back, took the design room's first frame (eight
 * cubes, 12 MiB) 6-25 ms, before any face was rendered. */
static void ensure_cubes(ps_gl_specular *g, int n)
{
    if (n == g->cube_count)
        return;
    delete_cubes(g);
    g->cube_count = n;
    g->cursor = 0;
    memset(g->face_time, 0, sizeof g->face_time); /* other cubes: other faces */
    memset(g->face_fill, 0, sizeof g->face_fill);
    g->fill_known = false;
    g->since_change = g->since_settled = 0;
    g->shown = 0; /* black cubes: a first round */
    g->lit = g->frozen;
    memset(g->back_faces, 0, sizeof g->back_faces);
    if (n == 0)
        return;
    if (!g->black) {
        const float texel[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        g->black = new_cube_texture(1, texel);
    }
    for (int c = 0; c < n; c++)
        g->cube[c] = g->black;
}

/* Whether a back map holds some faces of a round but not all six. */
static bool any_partial(const ps_gl_specular *g)
{
    for (int c = 0; c < g->cube_count; c++)
        if (g->back_faces[c] != 0)
            return true;
    return false;
}

/* Cube c's back map has all six faces from one centre: shown from now on,
 * its lookups and per-pixel points looking from that centre (re-aimed at
 * once when it moved, so that this refresh's layer is drawn with lookups
 * that match). */
static void show_back(ps_gl_specular *g, ps_session *s, int c)
{
    GLuint t = g->cube[c];
    g->cube[c] = g->back[c];
    g->back[c] = t != g->black ? t : 0;
    g->back_faces[c] = 0;
    g->shown |= 1u << c;
    g->lit = true;
    ps_session_set_specular_centre(s, c, g->back_centre[c]);
    g->cubes_changed = true;
}

void ps_gl_specular_fill(ps_gl_specular *g, ps_session *s, float value)
{
    ensure_cubes(g, ps_specular_cube_count(ps_session_specular(s)));
    size_t n = (size_t)g->size * (size_t)g->size;
    float *texels = malloc(4 * n * sizeof *texels);
    if (!texels)
        return;
    for (size_t i = 0; i < n; i++)
        texels[4 * i] = texels[4 * i + 1] = texels[4 * i + 2] = value, texels[4 * i + 3] = 1.0f;
    for (int c = 0; c < g->cube_count; c++) {
        if (g->cube[c] != g->black)
            glDeleteTextures(1, &g->cube[c]);
        g->cube[c] = new_cube_texture(g->size, texels);
        g->back_faces[c] = 0;
    }
    free(texels);
    /* The glossy levels blurred from those faces, as a refresh would. */
    ps_error err;
    if (ps_gl_glossy_sync(g->glossy, s, g->cube_count, g->size, &err) == PS_OK) {
        for (int c = 0; c < g->cube_count; c++)
            for (int f = 0; f < 6; f++)
                ps_gl_glossy_read_face(g->glossy, c, f, g->cube[c], g->size);
        ps_gl_glossy_blur(g->glossy, 0);
    }
    g->frozen = g->lit = true;
    g->cubes_changed = true;
}

/* Face f of cube c: the preview seen from the cube's centre, mirrors and
 * glass left out, at exposure 1. */
static ps_status render_face(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, const ps_session_frame *fr, int c,
                             int f, bool quick, ps_error *err)
{
    const ps_specular *sp = ps_session_specular(s);
    ps_camera_frame cam;
    memset(&cam, 0, sizeof cam);
    cam.eye = ps_specular_cube_centre(sp, c);
    cam.forward = ps_v3(face_axes[f][0][0], face_axes[f][0][1], face_axes[f][0][2]);
    cam.right = ps_v3(face_axes[f][1][0], face_axes[f][1][1], face_axes[f][1][2]);
    cam.up = ps_v3(face_axes[f][2][0], face_axes[f][2][1], face_axes[f][2][2]);
    cam.tan_half_fov = 1.0;
    cam.aspect = 1.0;
    cam.width = cam.height = g->size;
    /* The shadow maps hold every object: made before the objects are left out. */
    if (fr->direct && r->opt.shadows && !r->shadows_valid)
        ps_gl_make_shadow_maps(r);

    /* Into the back map, whose faces must all be from one centre. */
    if (g->back_faces[c] != 0 && !ps_v3_equal(g->back_centre[c], cam.eye))
        g->back_faces[c] = 0;
    g->back_centre[c] = cam.eye;
    g->back_faces[c] |= 1u << f;
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, back_map(g, c), 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, g->depth_stencil);
    r->skip_specular = true;
    bool hide = r->in.hide_emitters;
    if (ps_gl_glossy_only(g->glossy, c)) /* their lobes' are the direct layer's (gl_specular_blur.h) */
        r->in.hide_emitters = true;
    /* A quick face (the first round while photons arrive) leaves out the
     * shadow cubes of many lights: each costs a pass over the fine mesh per
     * lit cube face, some 80 passes a face for the area-light box's 16
     * virtual lights (its faces 5-6x the default box's). The rounds after
     * draw them (the area box's specular relMSE 0.052 without, 0.016 with). */
    bool shadows = r->opt.shadows && !(quick && r->shadow_lights > PS_GL_SPECULAR_QUICK_SHADOW_LIGHTS);
    /* The lit passes, not the direct light's textures (gl_direct_bake.c):
     * a face drawn before they are laid and one after would differ by their
     * sampling, and the faces of one round come over many refreshes. */
    r->direct_bake_off = true;
    ps_gl_begin_frame_shadows(r, &cam, 1.0, fr->direct, shadows, false, false);
    r->direct_bake_off = false;
    ps_status st = PS_OK;
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++) {
        double radius;
        st = ps_session_env_splats(s, (ps_map_kind)k, &cam,
                                   k == PS_MAP_CAUSTIC ? PS_GL_SPECULAR_ENV_CAUSTIC : PS_GL_SPECULAR_ENV_GLOBAL,
                                   &g->batch, &radius, err);
        if (st == PS_OK)
            ps_gl_draw_splats(r, &g->batch, PS_SPLAT_TRIANGLES, radius, 1.0);
    }
    /* Textured surfaces (map_Kd) as the eye sees them: the face times T. */
    if (st == PS_OK)
        ps_gl_multiply_albedo(r);
    r->skip_specular = false;
    r->in.hide_emitters = hide;
    g->faces_rendered++;
    return st;
}

/* The first round: a cube not shown since the last change (above). */
static bool in_first_round(const ps_gl_specular *g)
{
    unsigned all = (1u << g->cube_count) - 1u;
    return g->first_refreshes > 0 && (g->shown & all) != all;
}

/* Every photon has arrived, or tracing is held for good (paused, or the
 * error counter stopped it): *arrived, the photons emitted in both maps. */
static bool photons_settled(ps_session *s, uint64_t *arrived)
{
    ps_session_counts counts;
    ps_session_get_counts(s, &counts);
    *arrived = counts.map[0].emitted + counts.map[1].emitted;
    return counts.ended || ps_session_paused(s) || ps_session_counter_stopped(s, NULL);
}

double ps_gl_specular_unheld_seconds(ps_gl_specular *g, ps_session *s)
{
    int total = 6 * g->cube_count;
    if (g->frozen || total == 0 || g->first_held || !in_first_round(g))
        return 0.0;
    /* As ps_gl_specular_refresh decides a quick face: the first round, not settled. */
    uint64_t arrived;
    if (photons_settled(s, &arrived))
        return 0.0;
    /* Each face as it took last, or the dearest seen (faces differ several-fold).
     * None drawn yet: not known (taken as none, the area box's quarter
     * round of 0.27 s rode in the refresh before its 0.5 s checkpoint's
     * frame and landed it at 0.73-0.77 s). */
    if (g->face_max <= 0.0 && g->face_seconds <= 0.0)
        return HUGE_VAL;
    int n = (total + g->first_refreshes - 1) / g->first_refreshes;
    double t = 0.0;
    update_fill(g, s);
    for (int i = 0; i < n; i++)
        t += face_foreseen(g, (g->cursor + i) % total);
    return t;
}

double ps_gl_specular_all_seconds(const ps_gl_specular *g)
{
    int total = 6 * g->cube_count;
    double t = 0.0;
    for (int i = 0; !g->frozen && i < total; i++)
        t += g->face_time[i] > 0.0 ? g->face_time[i] : g->face_seconds > 0.0 ? g->face_seconds : g->face_max;
    return t;
}

ps_status ps_gl_specular_idle(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, const ps_session_frame *f,
                              double deadline, ps_error *err)
{
    if (deadline <= 0.0)
        return PS_OK;
    /* Not a new view's refresh: nothing waits for the picture. */
    ps_session_frame idle = *f;
    idle.new_view = idle.lights_changed = false;
    double keep = g->deadline;
    g->deadline = deadline;
    g->idle = true;
    ps_status st = ps_gl_specular_refresh(g, r, s, &idle, 6 * PS_SPECULAR_MAX_CUBES, err);
    g->idle = false;
    g->deadline = keep;
    /* The eye paths the session left owed (ps_session_set_specular_wait),
     * with what the faces left of the wait, rather than all in the picture
     * that first shows a cube (the default box's 0.045 s made it late for
     * its checkpoint). Not before the faces: the bench's specular layer
     * came later, its error 1.26x at 0.2 s and 1.41x at 0.5 s. */
    if (st == PS_OK && f->specular)
        ps_session_trace_specular_until(s, deadline);
    return st;
}

ps_status ps_gl_specular_refresh(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, const ps_session_frame *f,
                                 int faces, ps_error *err)
{
    if (!f->specular || g->frozen)
        return PS_OK;
    ps_specular *sp = ps_session_specular(s);
    ensure_cubes(g, ps_specular_cube_count(sp));
    int total = 6 * g->cube_count;
    if (total == 0)
        return PS_OK;
    /* The glossy levels: a face a refresh from what was read before (not in
     * a new view's refresh, which comes as fast as without the layer). */
    ps_status gst = ps_gl_glossy_sync(g->glossy, s, g->cube_count, g->size, err);
    if (gst != PS_OK)
        return gst;
    if (faces > 0 && !f->new_view && ps_gl_glossy_blur(g->glossy, PS_GL_GLOSSY_FACES_PER_REFRESH) &&
        !ps_gl_glossy_pending(g->glossy))
        g->cubes_changed = true;
    /* What the cubes show changed: a new round. */
    unsigned layers = ps_session_get_settings(s)->layers;
    bool other = layers != g->layers || ps_session_edits(s) != g->edits || ps_session_maps_epoch(s) != g->epoch;
    if (other || (f->lights_changed && !f->shadows_refined)) {
        if (other)
            g->shown = 0;
        g->layers = layers;
        g->edits = ps_session_edits(s);
        g->epoch = ps_session_maps_epoch(s);
        g->since_change = g->since_settled = 0;
        memset(g->back_faces, 0, sizeof g->back_faces); /* faces of before the change */
    }
    /* Settled: every photon has arrived (the feed ended; a new view of the
     * same photons changes no cube), and since the last arrived a whole
     * round was drawn: nothing new to show. */
    uint64_t arrived;
    bool settled = photons_settled(s, &arrived); /* held for good: as ended */
    if (arrived != g->arrived || !settled) {
        g->arrived = arrived;
        /* The last photons arrived: the round from here on is every face
         * from them (a back map half drawn before would complete a cube
         * with older faces, and leave newer ones unshown at the round's end). */
        if (settled)
            memset(g->back_faces, 0, sizeof g->back_faces);
        g->since_settled = 0;
    }
    if (settled && g->since_settled >= total && g->since_change >= total && !any_partial(g))
        return PS_OK;
    /* Settled but not yet drawn from the last photons: the round is finished
     * over the next PS_GL_SPECULAR_SETTLE_REFRESHES refreshes whatever the
     * budget, so that the picture is soon whole as a snapshot's. */
    /* The first round after a change is likewise drawn over
     * PS_GL_SPECULAR_FIRST_REFRESHES refreshes whatever the budget: under the
     * budget alone it took seconds (a face a refresh at most, one when 15 %
     * of tau had saved up for it), and the objects stayed black that long
     * (relMSE 0.145 against the reference's specular term at 2 s, 0.021 once
     * drawn, in the default scene). */
    bool first_round = in_first_round(g);
    int n = faces <= 0 || faces > total ? total
            : g->idle ? faces
            : settled ? (total + PS_GL_SPECULAR_SETTLE_REFRESHES - 1) / PS_GL_SPECULAR_SETTLE_REFRESHES
            : first_round ? (total + g->first_refreshes - 1) / g->first_refreshes
                          : faces;
    /* A new view (the first picture, the first after an edit, a moving
     * camera) comes as soon as without the layer: its faces wait. */
    if (faces > 0 && f->new_view)
        return PS_OK;
    bool quick = faces > 0 && first_round && !settled;
    /* The first round after a change is not held back by a deadline: held,
     * it starved behind snap's dense early checkpoints and the mirrors
     * stayed black past 2 s (the default box's specular relMSE 0.145 at 1
     * and 2 s against 0.053 and 0.008-0.053 with it drawn), a worse picture
     * at each time for the sake of the time it is shown at. A program that
     * gives the faces its waits instead holds it (photosplat-snap's 8-bit
     * checkpoints: ps_gl_specular_hold_first_round, ps_gl_specular_idle). */
    bool timed = faces > 0 && g->deadline > 0.0 && (!quick || g->idle || g->first_held);
    if (timed && !ps_gl_specular_face_fits(ps_now_seconds(), g->deadline, face_estimate(g, s)))
        return PS_OK; /* before the budget's credit is spent on it */
    if (faces > 0 && !settled && !first_round && !g->idle) {
        /* A face only when the refreshes' share of tau has saved up for one
         * (it took face_seconds last time; the first comes at once). */
        g->credit = fmin(g->credit + PS_GL_SPECULAR_TIME_SHARE * ps_session_get_settings(s)->tau,
                         fmax(g->face_seconds, PS_GL_SPECULAR_TIME_SHARE * ps_session_get_settings(s)->tau));
        if (g->credit < g->face_seconds)
            return PS_OK;
        g->credit -= g->face_seconds;
    }
    GLint old_fbo = 0, vp[4];
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glGetIntegerv(GL_VIEWPORT, vp);
    double view[16], proj[16];
    memcpy(view, r->view, sizeof view);
    memcpy(proj, r->proj, sizeof proj);
    int width = r->width, height = r->height;
    double eye_extent = r->eye_extent;
    ps_status st = PS_OK;
    double t0 = ps_now_seconds();
    /* Timed faces: the shadow maps (new GL lights) first, which the view's
     * drawing would make anyway, so that they are no face's time. */
    if (timed && f->direct && r->opt.shadows && !r->shadows_valid) {
        ps_gl_make_shadow_maps(r);
        glFinish();
    }
    int drawn = 0;
    /* What each face's time is measured at, where faces are foreseen (a
     * deadline; snap's first rounds: ps_gl_specular_unheld_seconds). */
    bool foresee = timed || g->first_refreshes > 0;
    double fill_drawn = 0.0;
    if (foresee)
        update_fill(g, s);
    for (int i = 0; i < n && st == PS_OK; i++) {
        /* The settled round ends with its whole cubes: a face past it would
         * leave a back map begun, and the layer never done (a window's wait
         * done hung so under ASan's timing). */
        if (settled && g->since_settled + drawn >= total && g->since_change + drawn >= total && !any_partial(g))
            break;
        /* The first round draws only the cubes not shown yet, and ends
         * once every one is (its other faces wait for the budget). */
        if (first_round && !settled) {
            if (!in_first_round(g))
                break;
            while (g->shown >> (g->cursor / 6) & 1u)
                g->cursor = (g->cursor / 6 + 1) * 6 % total;
        }
        int c = g->cursor / 6;
        if (timed && i > 0 && !ps_gl_specular_face_fits(ps_now_seconds(), g->deadline, face_estimate(g, s)))
            break;
        /* A quick face that no deadline holds (the pace counted on it) still
         * starts only before the deadline, as the clock says now: a face
         * never timed is foreseen from others, and the design room's came
         * up to 7x dearer than foreseen (a refresh planned to end before its
         * 0.5 s checkpoint's frame drew twelve, foreseen at 0.12-0.20 s,
         * which took 0.30-0.46 s and showed it at 0.72-0.94 s). */
        if (!timed && quick && g->deadline > 0.0 && ps_now_seconds() >= g->deadline)
            break;
        double tf = ps_now_seconds(), fill = foresee ? g->fill_now[g->cursor] : 0.0;
        st = render_face(g, r, s, f, c, g->cursor % 6, quick, err);
        ps_gl_glossy_read_face(g->glossy, c, g->cursor % 6, g->back[c], g->size);
        if (timed) {
            glFinish(); /* llvmpipe draws when flushed */
            double spent = ps_now_seconds() - tf;
            g->face_time[g->cursor] = (float)spent;
            g->face_fill[g->cursor] = (float)fill;
            g->face_max = fmax(g->face_max, spent);
        }
        fill_drawn += fill;
        drawn++;
        g->cursor = (g->cursor + 1) % total;
        /* The layer is redrawn when a cube is whole again, not each face. */
        if (st == PS_OK && g->back_faces[c] == 0x3fu)
            show_back(g, s, c);
    }
    n = drawn;
    if (faces <= 0 && ps_gl_glossy_blur(g->glossy, 0)) /* all at once: the levels too */
        g->cubes_changed = true;
    if (faces > 0 && n > 0) {
        glFinish(); /* llvmpipe draws when flushed: the face's own time */
        g->face_seconds = (ps_now_seconds() - t0) / n;
        g->face_seconds_fill = fill_drawn / n;
    }
    g->since_change += n;
    g->since_settled += n;
    /* Back to the view. */
    memcpy(r->view, view, sizeof view);
    memcpy(r->proj, proj, sizeof proj);
    r->width = width, r->height = height;
    r->eye_extent = eye_extent;
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    glViewport(vp[0], vp[1], vp[2], vp[3]);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(r->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(r->view);
    return st;
}

/* No cube to show: the layer off, illuminance shown, or no mirror or glass
 * (*cubes: the session's cubes). */
static bool no_cubes(ps_session *s, int *cubes)
{
    *cubes = ps_specular_cube_count(ps_session_specular(s));
    return !(ps_session_get_settings(s)->layers & PS_LAYER_SPECULAR) || ps_session_illuminance(s) || *cubes == 0;
}

/* g's cubes were rendered for s's cubes, layers and edits as they are now. */
static bool cubes_current(const ps_gl_specular *g, ps_session *s, int cubes)
{
    return g->cube_count == cubes && g->layers == ps_session_get_settings(s)->layers && g->edits == ps_session_edits(s);
}

bool ps_gl_specular_all_shown(const ps_gl_specular *g, ps_session *s)
{
    int cubes;
    if (no_cubes(s, &cubes))
        return true;
    unsigned all = (1u << cubes) - 1u;
    return cubes_current(g, s, cubes) && (g->shown & all) == all;
}

bool ps_gl_specular_done(const ps_gl_specular *g, ps_session *s)
{
    int cubes;
    if (g->frozen || no_cubes(s, &cubes))
        return true;
    if (!cubes_current(g, s, cubes) || g->cubes_changed || ps_gl_glossy_pending(g->glossy))
        return false;
    for (int c = 0; c < cubes; c++)
        if (g->back_faces[c] != 0) /* a map still being rendered */
            return false;
    /* The still camera's per-pixel paths traced (and so drawn: they mark the
     * layer changed), not the per-vertex lookups shown until then. */
    if (!ps_specular_pixel_points(ps_session_specular(s)).ready)
        return false;
    int total = 6 * cubes;
    uint64_t arrived;
    bool settled = photons_settled(s, &arrived);
    return settled && arrived == g->arrived && g->since_settled >= total && g->since_change >= total;
}

/* The weights of term k times exposure (the arrays as they are at 1). */
static const float *weights(ps_gl_specular *g, const ps_specular *sp, int k, size_t n, double exposure)
{
    const float *w = ps_specular_weights(sp, k);
    if (exposure == 1.0)
        return w;
    if (g->scaled_cap < 3 * n) {
        float *p = realloc(g->scaled, 3 * n * sizeof *p);
        if (!p)
            return w;
        g->scaled = p;
        g->scaled_cap = 3 * n;
    }
    for (size_t i = 0; i < 3 * n; i++)
        g->scaled[i] = (float)(w[i] * exposure);
    return g->scaled;
}

/* The first `terms` lookups of every vertex (the heaviest first). */
/* glossy_only: the glossy ranges alone (beside the per-pixel points, which
 * trace mirrors and glass only). */
static void draw_terms(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, double exposure, int terms,
                       bool glossy_only)
{
    ps_specular *sp = ps_session_specular(s);
    const ps_preview_mesh *mesh = ps_session_mesh(s);
    size_t nr = ps_specular_range_count(sp);
    if (nr == 0 || g->cube_count == 0)
        return;
    const ps_specular_range *ranges = ps_specular_ranges(sp);
    size_t n = ranges[nr - 1].offset + mesh->ranges[ranges[nr - 1].range].count;
    ps_gl_begin_additive_pass(r);
    glBlendFunc(GL_ONE, GL_ONE);
    ps_gl_unclamp_colour();
    glActiveTexture(GL_TEXTURE0);
    glEnable(GL_TEXTURE_CUBE_MAP);
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glEnableClientState(GL_TEXTURE_COORD_ARRAY);
    for (int k = 0; k < terms; k++) {
        const float *w = weights(g, sp, k, n, exposure);
        const float *d = ps_specular_dirs(sp, k);
        for (size_t i = 0; i < nr; i++) {
            const ps_mesh_range *rg = &mesh->ranges[ranges[i].range];
            /* Glossy ranges read the cube's blurred level (gl_specular_blur.h). */
            GLuint level = ps_gl_glossy_texture(g->glossy, ranges[i].cube);
            bool glossy = level && ps_glossy_wants(&ps_session_materials(s)[rg->material]);
            if (glossy_only && !glossy)
                continue;
            if (g->tris_cap < rg->count) {
                unsigned *t = realloc(g->tris, rg->count * sizeof *t);
                if (t)
                    g->tris = t, g->tris_cap = rg->count;
            }
            /* Only the triangles the term lights; all of them where there
             * is no room for the list, or for tests (the same picture). */
            bool listed = g->tris_cap >= rg->count && !r->opt.whole_face_passes;
            size_t lit = listed ? ps_specular_weighted_triangles(ps_specular_weights(sp, k) + 3 * ranges[i].offset,
                                                                 rg->count, g->tris)
                                : rg->count;
            if (lit == 0)
                continue;
            glBindTexture(GL_TEXTURE_CUBE_MAP, glossy ? level : g->cube[ranges[i].cube]);
            glVertexPointer(3, GL_FLOAT, 0, mesh->positions + 3 * rg->first);
            glColorPointer(3, GL_FLOAT, 0, w + 3 * ranges[i].offset);
            glTexCoordPointer(3, GL_FLOAT, 0, d + 3 * ranges[i].offset);
            if (listed)
                glDrawElements(GL_TRIANGLES, (GLsizei)lit, GL_UNSIGNED_INT, g->tris);
            else
                glDrawArrays(GL_TRIANGLES, 0, (GLsizei)rg->count);
        }
    }
    glDisableClientState(GL_TEXTURE_COORD_ARRAY);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    glDisable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glDisable(GL_TEXTURE_CUBE_MAP);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
}

/* The per-pixel points (specular.h), each a one-pixel GL point at its
 * pixel's centre with its lookup as the texture coordinate and its weight
 * times exposure as the colour, added; no depth test: the CPU's eye rays
 * found what each pixel sees first. */
static void draw_points(ps_gl_specular *g, ps_gl_renderer *r, const ps_specular_points *p, double exposure)
{
    if (p->count == 0 || g->cube_count == 0)
        return;
    if (g->xy_cap < 2 * p->count) {
        float *xy = realloc(g->xy, 2 * p->count * sizeof *xy);
        if (!xy)
            return;
        g->xy = xy;
        g->xy_cap = 2 * p->count;
    }
    /* Window coordinates: GL's rows count from the bottom. */
    for (size_t i = 0; i < p->count; i++) {
        g->xy[2 * i] = p->xy[2 * i] + 0.5f;
        g->xy[2 * i + 1] = (float)r->height - p->xy[2 * i + 1] - 0.5f;
    }
    const float *w = p->weights;
    if (exposure != 1.0) {
        if (g->scaled_cap < 3 * p->count) {
            float *q = realloc(g->scaled, 3 * p->count * sizeof *q);
            if (!q)
                return;
            g->scaled = q;
            g->scaled_cap = 3 * p->count;
        }
        for (size_t i = 0; i < 3 * p->count; i++)
            g->scaled[i] = (float)(p->weights[i] * exposure);
        w = g->scaled;
    }
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glOrtho(0.0, r->width, 0.0, r->height, -1.0, 1.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glDisable(GL_LIGHTING);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    ps_gl_unclamp_colour();
    glPointSize(1.0f);
    glActiveTexture(GL_TEXTURE0);
    glEnable(GL_TEXTURE_CUBE_MAP);
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glEnableClientState(GL_TEXTURE_COORD_ARRAY);
    glVertexPointer(2, GL_FLOAT, 0, g->xy);
    glColorPointer(3, GL_FLOAT, 0, w);
    glTexCoordPointer(3, GL_FLOAT, 0, p->dirs);
    /* Runs of one cube. */
    for (size_t i = 0; i < p->count;) {
        size_t j = i + 1;
        while (j < p->count && p->cube[j] == p->cube[i])
            j++;
        glBindTexture(GL_TEXTURE_CUBE_MAP, g->cube[p->cube[i]]);
        glDrawArrays(GL_POINTS, (GLint)i, (GLsizei)(j - i));
        i = j;
    }
    glDisableClientState(GL_TEXTURE_COORD_ARRAY);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    glDisable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glDisable(GL_TEXTURE_CUBE_MAP);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(r->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(r->view);
}

/* The layer at full detail: the per-pixel points once the current camera
 * frame is traced whole, else the per-vertex lookups. */
static void draw_full(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, double exposure)
{
    ps_specular_points p = ps_specular_pixel_points(ps_session_specular(s));
    if (p.ready) {
        draw_points(g, r, &p, exposure);
        draw_terms(g, r, s, exposure, PS_SPECULAR_TERMS, true);
    } else {
        draw_terms(g, r, s, exposure, PS_SPECULAR_TERMS, false);
    }
}

/* Whether the layer is drawn: until a cube shows a picture to look up, it
 * is black and the session leaves its eye paths owed
 * (ps_session_set_specular_wait); once one does, what it left owed is traced
 * before the layer is drawn, under ps_gl_specular_set_paths_deadline only
 * until then, and the layer stays black while some are still owed. */
static bool eye_paths_for_cubes(ps_gl_specular *g, ps_session *s)
{
    if (g->lit && g->paths_deadline > 0.0)
        ps_session_trace_specular_until(s, g->paths_deadline);
    else if (g->lit)
        ps_session_trace_specular(s);
    bool drawn = g->lit && !ps_session_specular_owed(s);
    ps_session_set_specular_wait(s, !drawn);
    return drawn;
}

void ps_gl_specular_draw(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, double exposure)
{
    if (eye_paths_for_cubes(g, s)) /* black cubes add nothing */
        draw_full(g, r, s, exposure);
}

ps_status ps_gl_specular_layer(ps_gl_specular *g, ps_gl_layers *l, ps_gl_renderer *r, ps_session *s,
                               const ps_session_frame *f, ps_error *err)
{
    /* Black cubes add nothing: no layer is drawn (nor made, the first
     * pictures' time) until a cube is shown. */
    if (f->specular && !eye_paths_for_cubes(g, s)) {
        g->layer_valid = false;
        ps_gl_specular_set_gain(g, l, 0.0);
        return PS_OK;
    }
    /* As big as the other layers, drawn at the refresh's view in its corner
     * (a moving camera's level of detail is smaller: gl_layers.c). */
    GLuint depth = ps_gl_layers_depth_stencil(l);
    int lw, lh;
    ps_gl_layers_size(l, &lw, &lh);
    if (!g->layer_tex || g->layer_w != lw || g->layer_h != lh || g->layer_depth != depth) {
        if (!g->layer_tex)
            glGenTextures(1, &g->layer_tex);
        if (!g->layer_fbo)
            glGenFramebuffers(1, &g->layer_fbo);
        g->layer_w = lw, g->layer_h = lh, g->layer_depth = depth;
        glBindTexture(GL_TEXTURE_2D, g->layer_tex);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, g->layer_w, g->layer_h, 0, GL_RGBA, GL_FLOAT, NULL);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glBindTexture(GL_TEXTURE_2D, 0);
        GLint old_fbo = 0;
        glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, g->layer_fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, g->layer_tex, 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth);
        bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
        glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
        g->layer_valid = false;
        if (!complete)
            return ps_error_set(err, PS_ERR_IO, "the GL implementation cannot render the specular layer (RGBA32F %dx%d)",
                                g->layer_w, g->layer_h);
    }
    bool changed = ps_specular_take_changed(ps_session_specular(s));
    if (f->specular && (changed || g->cubes_changed || f->new_view || f->lights_changed || !g->layer_valid)) {
        GLint old_fbo = 0;
        glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, g->layer_fbo);
        glViewport(0, 0, r->width, r->height);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glClearColor(0, 0, 0, 0);
        glClear(GL_COLOR_BUFFER_BIT); /* colour only: the depth is the view's prepass */
        /* A moving camera's level of detail: the heaviest lookup only (one
         * pass instead of PS_SPECULAR_TERMS); all again once it stops. */
        if (f->moving) {
            draw_terms(g, r, s, f->direct_exposure, 1, false);
        } else {
            draw_full(g, r, s, f->direct_exposure);
        }
        glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
        g->cubes_changed = false;
        g->layer_valid = true;
    }
    ps_gl_specular_set_gain(g, l, f->specular ? f->direct_gain : 0.0);
    return PS_OK;
}

void ps_gl_specular_set_gain(ps_gl_specular *g, ps_gl_layers *l, double gain)
{
    /* Not while every cube is black: the layer holds nothing of them (or an
     * older cube set's picture). */
    ps_gl_layers_set_extra(l, g->layer_tex, g->lit ? gain : 0.0);
}
