/* window_main.c: photosplat, the lighting designer's preview window (GLFW +
 * libGL, never OSMesa). It shows the scene at once and refines it while
 * photons arrive: tracing threads shoot continuously, and every tau the
 * picture takes in what has arrived (thesis 4.1.4). Moving the camera keeps
 * every photon; moving a light or an object restarts the maps. */
#include "gl/gl_api.h"
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app/cli.h"
#include "app/interrupt.h"
#include "core/fileio.h"
#include "app/options.h"
#include "app/stats.h"
#include "gl/gl_font.h"
#include "gl/gl_render.h"
#include "image/image.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "preview/feed.h"
#include "preview/mesh.h"
#include "preview/script.h"
#include "preview/splat.h"
#include "scene/camera.h"
#include "scene/scene.h"

/* Shadow maps are remade after every light move: half the snapshot's side,
 * a quarter of the fill, for a refresh soon after the move. */
#define WIN_SHADOW_SIZE 512
/* The memory plan (ps_check_run_memory): a pixel is the 8-bit picture, its
 * float copy, the float splat layers and the window's own colour and depth. */
#define WIN_PIXEL_BYTES (3 + 3 * sizeof(float) + 3 * 3 * sizeof(float) + 4 + 4)
/* Camera controls, as in Blender: degrees of orbit per pixel dragged, the
 * dolly factor per wheel notch, pan in units of the target distance per pixel. */
#define ORBIT_DEG_PER_PIXEL 0.4
#define ZOOM_PER_NOTCH 0.9
#define PAN_PER_PIXEL 0.0015
/* Pitch stays this far from straight up or down, where yaw is undefined. */
#define PITCH_LIMIT_DEG 89.0
/* Picking a light: its projected position within this many pixels. */
#define PICK_RADIUS_PX 12.0
/* Keys move the selection by this fraction of the scene's diagonal. */
#define KEY_STEP_FRACTION 0.02
/* Keys scale radii, exposure and power by this, and spot angles by steps. */
#define KEY_SCALE 1.25
#define KEY_ANGLE_STEP 2.0
/* The frame-rate figure is smoothed over about this many frames. */
#define FPS_SMOOTHING 0.2
/* A refresh draws at most as many new splats a map as fit in this share of
 * tau at the rate the last refreshes drew them, so that a refresh comes every
 * tau however fast photons arrive (llvmpipe draws a few hundred thousand
 * large splats a second); never fewer than the first bound. */
#define SPLAT_TIME_SHARE 0.5
#define SPLAT_BUDGET_MIN 2048
#define SPLAT_BUDGET_START 16384
/* --max-photons: the maps store at most this many photons together by
 * default (26 bytes each: 0.8 GiB, 1.6 GiB of capacity at worst), whatever
 * the scene's albedo makes of the caps (preview/feed.h). */
#define WIN_MAX_PHOTONS_DEFAULT ((int64_t)1 << 25)

enum { SEL_NONE, SEL_LIGHT, SEL_OBJECT };
enum { DRAG_NONE, DRAG_ORBIT, DRAG_PAN, DRAG_MOVE };

static const char usage[] =
    "usage: photosplat [SCENE.scn] [options]\n"
    "\n"
    "The interactive preview: photons traced continuously and drawn as splats\n"
    "over the scene lit by OpenGL lights, refreshed every tau seconds. Without a\n"
    "scene it opens data/scenes/cornell-caustic.scn. Press H in the window for\n"
    "the keys.\n"
    "\n"
    "options:\n"
    "  --size WxH               window size (default from the scene)\n"
    "  --exposure E             radiance multiplier before display (default 1)\n"
    "  --caustic-photons N      caustic photon cap: traced, then refining stops (default from the scene)\n"
    "  --global-photons N       global photon cap likewise; each edit restarts both maps\n"
    "  --max-photons N          memory cap: stop once the maps store N photons (default 2^25, 0: none)\n"
    "  --caustic-radius R       caustic splat radius, scene units\n"
    "  --global-radius R        global splat radius, scene units\n"
    "  --seed S                 photon i depends only on (scene, seed, i) (default 0)\n"
    "  --threads N              tracing threads (default: all cores)\n"
    "  --stats FILE.json        figures of the session, written at the end\n"
    "  --script FILE            timed actions (see the README), e.g. for tests\n"
    "  --tau SECONDS            time between refreshes (default 0.1)\n"
    "  --splat points|triangles|sprites  (default triangles)\n"
    "  --kernel box|cone|gauss|epanechnikov  (default cone)\n"
    "  --layers LIST            comma list of direct,caustic,global (default all)\n"
    "  --color-depth 8|float    splat layers' precision (default float)\n"
    "  --precision none|diffusion|counter  8-bit handling (default diffusion)\n"
    "  --counter-threshold F    counter: stop shooting past this round-off (default 0.1)\n"
    "  --point-size N           points: side in pixels (default 1)\n"
    "  --shadows on|off         shadow maps (default on)\n"
    "  --stencil-clip on|off    clip splats to their object's pixels (default on)\n"
    "  --radius-schedule fixed|progressive  splat radius as photons arrive (default\n"
    "                           fixed; progressive: r^2 ~ n^(alpha-1), the given\n"
    "                           radius holding at the scene's photon count)\n"
    "  --radius-alpha A         the progressive schedule's alpha (default 2/3)\n"
    "  --overlay on|off         the text overlay (default on)\n"
    "  --help                   this text\n";

static const char help_text[] =
    "mouse (as in Blender)\n"
    "  middle drag      orbit about the target   (or Alt + left drag)\n"
    "  Shift + middle   pan\n"
    "  wheel            zoom\n"
    "  left click       select the light or object under the cursor\n"
    "  left drag        move it in the horizontal plane (Ctrl: vertical)\n"
    "keys\n"
    "  Tab / Shift+Tab  select the next light / object     Esc: none\n"
    "  arrows, PgUp/Dn  move the selection\n"
    "  + / -            selected light's power x/÷ 1.25\n"
    "  [ / ]            selected spot's angle -/+ 2 degrees\n"
    "  S  splat mode     K  kernel        C  precision mode\n"
    "  1 2 3            direct, caustic, global layer on/off\n"
    "  R / Shift+R      splat radius up / down\n"
    "  T / Shift+T      tau up / down\n"
    "  E / Shift+E      exposure up / down\n"
    "  Space            pause tracing    V  overlay    P  screenshot\n"
    "  H                this help        Q  quit";

typedef struct win_options {
    ps_shared_options c;
    ps_preview_options p;
    const char *script;
    int overlay;
    int64_t max_photons; /* stored photons of both maps; 0: no bound */
    const ps_cancel_flag *cancel; /* raised by SIGINT or SIGTERM: the session ends */
} win_options;

typedef struct app {
    win_options o;
    ps_scene *scene;
    ps_world *world;
    ps_tracer *tracer;
    ps_feed *feed;
    ps_preview_mesh mesh;
    ps_kernel_texture kernel;
    ps_gl_renderer *gl;
    ps_gl_layers *layers;
    ps_splat_batch batch[PS_MAP_COUNT];
    GLFWwindow *win;
    int width, height;
    ps_camera camera;
    /* Runtime settings. */
    ps_splat_mode splat;
    ps_kernel kernel_kind;
    ps_precision precision;
    unsigned shown;
    double radius[PS_MAP_COUNT], tau, exposure;
    /* The radius the newest splats were built with: radius[] under the
     * radius schedule (--radius-schedule), for the photons emitted so far. */
    double splat_radius[PS_MAP_COUNT];
    bool paused, overlay, help;
    /* What the frames need redone. */
    bool view_dirty, scene_dirty, geometry_dirty;
    size_t drawn[PS_MAP_COUNT];     /* photons already in the float layers */
    uint64_t emitted[PS_MAP_COUNT]; /* ... and the emitted count they came from */
    uint64_t cap[PS_MAP_COUNT];
    double budget; /* new splats a map per refresh (float layers) */
    /* Selection and dragging. */
    int sel_kind;
    size_t sel_index;
    int drag;
    double drag_x, drag_y;
    ps_vec3 drag_anchor;
    bool drag_vertical;
    /* Timing and figures. */
    double start_time, t_first_frame, first_frame_seconds, last_refresh, fps, frame_seconds;
    uint64_t frames, edits;
    double edit_time, edit_latency_max, edit_latency_sum;
    uint64_t edit_latency_count;
    bool awaiting_edit_frame;
    double lost_fraction;
    bool counter_stopped;
    uint64_t counter_at;
    uint8_t *pixels; /* the displayed picture, 8-bit sRGB, GL's row order */
    ps_image picture;
    /* The script. */
    ps_script *script;
    size_t script_next;
    /* wait done: the later actions are held while waiting; then the script
     * clock is set back to the wait's time (script_delay seconds behind). */
    bool script_waiting;
    double wait_time, script_delay;
    bool quit;
    bool release_feed; /* the feed is held until the next refresh is done */
    char shot_path[64]; /* a screenshot asked for with P, taken after the next refresh */
    ps_status status;
    ps_error err;
    char message[PS_ERROR_MSG_MAX + 64]; /* the last action's one-line report, shown in the overlay */
} app;

/* ---- options ---------------------------------------------------------------- */

static ps_status parse_args(int argc, char **argv, win_options *o, bool *help, ps_error *err)
{
    static const char *const on_off[] = {"off", "on", NULL};
    ps_cli cli = ps_cli_begin("photosplat", argc, argv);
    memset(o, 0, sizeof *o);
    ps_shared_options_init(&o->c);
    /* Float layers: they take in only new photons each refresh (see gl_render.h). */
    ps_preview_options_init(&o->p, true);
    o->overlay = 1;
    o->max_photons = WIN_MAX_PHOTONS_DEFAULT;
    ps_status st = PS_OK;
    while (st == PS_OK && ps_cli_next(&cli)) {
        if (ps_cli_is(&cli, "--help") || ps_cli_is(&cli, "-h")) {
            *help = true;
            return PS_OK;
        } else if (ps_cli_is(&cli, "-o") || ps_cli_is(&cli, "--hdr") || ps_cli_is(&cli, "--dump-photons")) {
            return ps_error_set(err, PS_ERR_PARSE,
                                "photosplat: %s is for photosplat-snap; the window saves screenshots with P or a script",
                                ps_cli_arg(&cli));
        } else if (ps_shared_option(&cli, "photosplat", &o->c, &st, err)) {
            continue;
        } else if (ps_preview_option(&cli, "photosplat", &o->p, &st, err)) {
            continue;
        } else if (ps_cli_is(&cli, "--script")) {
            st = ps_cli_string(&cli, &o->script, err);
        } else if (ps_cli_is(&cli, "--overlay")) {
            st = ps_cli_choice(&cli, on_off, &o->overlay, err);
        } else if (ps_cli_is(&cli, "--max-photons")) {
            st = ps_cli_int(&cli, 0, PS_SCENE_MAX_PHOTONS, &o->max_photons, err);
        } else {
            return ps_cli_unknown(&cli, err);
        }
    }
    if (st == PS_OK && !o->c.scene)
        o->c.scene = "data/scenes/cornell-caustic.scn";
    return st;
}

/* ---- building and restarting the photon maps ----------------------------------- */

static void teardown_maps(app *a)
{
    ps_feed_destroy(a->feed);
    a->feed = NULL;
    ps_tracer_destroy(a->tracer);
    a->tracer = NULL;
}

/* (Re)builds what depends on the scene: the accelerator and GL mesh when
 * geometry moved, the tracer (its caustic cones follow lights and objects),
 * the GL lights and shadow maps, and a new photon feed from photon 0. */
static ps_status rebuild(app *a, bool geometry, ps_error *err)
{
    teardown_maps(a);
    ps_status st = PS_OK;
    if (geometry || !a->world) {
        ps_gl_renderer_destroy(a->gl);
        a->gl = NULL;
        ps_world_destroy(a->world);
        a->world = NULL;
        ps_preview_mesh_free(&a->mesh);
        st = ps_world_create(a->scene, NULL, &a->world, err);
        ps_mesh_options mo = ps_mesh_default_options(a->scene);
        if (st == PS_OK)
            st = ps_preview_mesh_build(a->scene, &mo, &a->mesh, err);
        ps_gl_options go = {a->o.p.shadows != 0, true, WIN_SHADOW_SIZE};
        if (st == PS_OK)
            st = ps_gl_renderer_create(a->scene, &a->mesh, &a->kernel, &go, &a->gl, err);
    } else {
        ps_gl_renderer_lights_changed(a->gl);
    }
    ps_tracer_options to = ps_tracer_default_options();
    to.seed = (uint64_t)a->o.c.seed;
    /* One core is left to drawing (llvmpipe draws on the CPU too): with every
     * core tracing, the picture after a light move took four times as long. */
    to.threads = a->o.c.threads > 0 ? (int)a->o.c.threads : (ps_online_cores() > 1 ? ps_online_cores() - 1 : 1);
    to.cancel = a->o.cancel;
    to.max_stored = ps_photon_cap(PS_PREVIEW_MAPS, PS_PREVIEW_PHOTON_BYTES);
    if (st == PS_OK)
        st = ps_tracer_create(a->world, &to, &a->tracer, err);
    bool active[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++)
        active[k] = st == PS_OK && ps_tracer_map_enabled(a->tracer, (ps_map_kind)k);
    /* The first batch is traced here, and the thread starts held until the
     * first refresh has drawn it: that refresh (shadow maps, direct light,
     * those splats) then has every core, and the caustic shows at once. */
    if (st == PS_OK)
        st = ps_feed_create(a->tracer, a->cap, active, &a->feed, err);
    if (st == PS_OK)
        ps_feed_set_store_limit(a->feed, (size_t)a->o.max_photons);
    if (st == PS_OK)
        st = ps_feed_prime(a->feed, err);
    if (st == PS_OK) {
        ps_feed_pause(a->feed, true);
        st = ps_feed_start(a->feed, err);
        a->release_feed = true;
    }
    a->counter_stopped = false;
    a->view_dirty = true;
    return st;
}

/* ---- the frame -------------------------------------------------------------------- */

static ps_camera_frame camera_frame(const app *a) { return ps_camera_frame_make(&a->camera, a->width, a->height); }

static bool float_layers(const app *a) { return a->o.p.color_depth == 1; }

/* How far into map k this refresh draws: with float layers, whole batches
 * beyond what is drawn, at most the budget (but at least one batch); with
 * 8-bit layers everything. *emitted: the photons emitted for that prefix,
 * which its splats are scaled by. Under the feed's lock. */
static size_t prefix(const app *a, int k, uint64_t *emitted)
{
    size_t n;
    const ps_feed_mark *m = ps_feed_marks(a->feed, (ps_map_kind)k, &n);
    size_t end = a->drawn[k];
    *emitted = a->emitted[k];
    for (size_t i = 0; i < n; i++) {
        if (m[i].stored < a->drawn[k] || m[i].emitted < *emitted)
            continue;
        bool over = float_layers(a) && (double)(m[i].stored - a->drawn[k]) > a->budget;
        if (over && end > a->drawn[k])
            break;
        end = m[i].stored;
        *emitted = m[i].emitted;
        if (over)
            break;
    }
    return end;
}

/* Builds splats of the photons that have arrived (under the feed's lock):
 * with float layers only those not drawn yet, at their stored power; with
 * 8-bit layers all of them, scaled for display (thesis 5.1). */
static ps_status build_splats(app *a, size_t first[PS_MAP_COUNT], ps_error *err)
{
    size_t nmat;
    const ps_material *materials = ps_scene_materials(a->scene, &nmat);
    ps_camera_frame cam = camera_frame(a);
    double wanted = 0.0, lost = 0.0;
    ps_feed_lock(a->feed);
    const ps_photon_map *maps = ps_feed_maps(a->feed);
    ps_status st = PS_OK;
    for (int k = 0; k < PS_MAP_COUNT && st == PS_OK; k++) {
        ps_splat_batch *b = &a->batch[k];
        ps_splat_batch_clear(b);
        b->carry[0] = b->carry[1] = b->carry[2] = 0.0;
        b->wanted = b->lost = 0.0;
        const ps_photon_map *m = &maps[k];
        unsigned layer = k == PS_MAP_CAUSTIC ? PS_LAYER_CAUSTIC : PS_LAYER_GLOBAL;
        uint64_t emitted;
        size_t end = prefix(a, k, &emitted);
        first[k] = float_layers(a) ? a->drawn[k] : 0;
        a->emitted[k] = emitted;
        if (!(a->shown & layer) || end <= first[k] || emitted == 0) {
            first[k] = end;
            continue;
        }
        ps_splat_params p;
        memset(&p, 0, sizeof p);
        p.mode = a->splat;
        a->splat_radius[k] = ps_preview_radius(&a->o.p, a->radius[k], ps_scene_get_defaults(a->scene), (ps_map_kind)k,
                                               a->cap[k], emitted);
        p.radius = a->splat_radius[k];
        p.kernel_mean = a->kernel.mean;
        p.kernel_extent = a->kernel.extent;
        p.scale = float_layers(a) ? 1.0 : a->exposure * (double)a->cap[k] / (double)emitted;
        p.point_size = a->o.p.point_size;
        p.precision = a->precision;
        p.levels = float_layers(a) ? 0 : 255;
        p.materials = materials;
        p.objects = a->o.p.stencil_clip ? m->objects + first[k] : NULL;
        p.cam = cam;
        st = ps_splat_build(m->photons + first[k], m->materials + first[k], end - first[k], &p, b, err);
        wanted += b->wanted;
        lost += b->lost;
        first[k] = end;
    }
    ps_feed_unlock(a->feed);
    a->lost_fraction = wanted > 0.0 ? lost / wanted : 0.0;
    return st;
}

/* The picture as the window shows it: layers composited, encoded like a
 * snapshot (exposure, sRGB, 8 bits), drawn with glDrawPixels. */
static ps_status compose(app *a, ps_error *err)
{
    double gain[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        unsigned layer = k == PS_MAP_CAUSTIC ? PS_LAYER_CAUSTIC : PS_LAYER_GLOBAL;
        gain[k] = !(a->shown & layer) || a->emitted[k] == 0 ? 0.0
                  : float_layers(a)                         ? a->exposure * (double)a->cap[k] / (double)a->emitted[k]
                                                            : 1.0;
    }
    ps_image_destroy(&a->picture);
    ps_status st = ps_gl_layers_composite(a->layers, float_layers(a) ? a->exposure : 1.0, gain, &a->picture, err);
    if (st != PS_OK)
        return st;
    for (int y = 0; y < a->height; y++) {
        const float *src = ps_image_at(&a->picture, 0, a->height - 1 - y);
        uint8_t *dst = a->pixels + 3 * (size_t)y * (size_t)a->width;
        for (int i = 0; i < 3 * a->width; i++)
            dst[i] = ps_tonemap_8bit(src[i], 1.0f);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, a->width, a->height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_BLEND);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glWindowPos2i(0, 0);
    glDrawPixels(a->width, a->height, GL_RGB, GL_UNSIGNED_BYTE, a->pixels);
    return PS_OK;
}

static void draw_overlay(app *a)
{
    if (!a->overlay && !a->help)
        return;
    char text[2 * PS_ERROR_MSG_MAX + 1024];
    ps_feed_lock(a->feed);
    const ps_photon_map *maps = ps_feed_maps(a->feed);
    uint64_t ce = maps[0].counters.emitted, ge = maps[1].counters.emitted;
    bool ended = ps_feed_ended(a->feed), limited = ps_feed_store_limited(a->feed);
    ps_feed_unlock(a->feed);
    double elapsed = glfwGetTime() - a->edit_time;
    double rate = elapsed > 0.0 ? (double)(ce + ge) / elapsed : 0.0;
    const char *state = a->counter_stopped ? "stopped by the error counter"
                        : a->paused        ? "paused"
                        : limited          ? "memory cap reached (--max-photons)"
                        : ended            ? "cap reached"
                                           : "tracing";
    int n = snprintf(text, sizeof text,
                     "caustic %llu/%llu  global %llu/%llu  %s\n"
                     "%.3g photons/s  %.1f fps  tau %.3g s  frame %.0f ms\n"
                     "%s splats  %s kernel  r %.3g/%.3g  layers %s%s%s  %s  exposure %.3g\n",
                     (unsigned long long)ce, (unsigned long long)a->cap[0], (unsigned long long)ge,
                     (unsigned long long)a->cap[1], state, rate, a->fps, a->tau, 1000.0 * a->frame_seconds,
                     ps_splat_mode_name(a->splat), ps_kernel_name(a->kernel_kind), a->splat_radius[0],
                     a->splat_radius[1],
                     a->shown & PS_LAYER_DIRECT ? "D" : "-", a->shown & PS_LAYER_CAUSTIC ? "C" : "-",
                     a->shown & PS_LAYER_GLOBAL ? "G" : "-", float_layers(a) ? "float" : ps_precision_name(a->precision),
                     a->exposure);
    if (!float_layers(a) && n > 0 && (size_t)n < sizeof text)
        n += snprintf(text + n, sizeof text - (size_t)n, "error counter: %.1f %% of the last refresh rounded away%s\n",
                      100.0 * a->lost_fraction, a->counter_stopped ? " (stopped shooting)" : "");
    if (a->sel_kind != SEL_NONE && n > 0 && (size_t)n < sizeof text) {
        size_t count;
        if (a->sel_kind == SEL_LIGHT) {
            const ps_light *L = &ps_scene_lights(a->scene, &count)[a->sel_index];
            n += snprintf(text + n, sizeof text - (size_t)n, "selected: light %zu (%s) at %.3g %.3g %.3g, %.3g W",
                          a->sel_index, ps_light_type_name(L->type), L->position.x, L->position.y, L->position.z,
                          ps_rgb_mean(L->power));
            if (L->type == PS_LIGHT_SPOT)
                n += snprintf(text + n, sizeof text - (size_t)n, ", %.3g deg", L->angle_deg);
        } else {
            const ps_object *ob = &ps_scene_objects(a->scene, &count)[a->sel_index];
            ps_vec3 c = ps_aabb_center(ob->bounds);
            n += snprintf(text + n, sizeof text - (size_t)n, "selected: object %zu (line %d) at %.3g %.3g %.3g",
                          a->sel_index, ob->line, c.x, c.y, c.z);
        }
        if (n > 0 && (size_t)n < sizeof text)
            n += snprintf(text + n, sizeof text - (size_t)n, "\n");
    }
    if (a->message[0] && n > 0 && (size_t)n < sizeof text)
        snprintf(text + n, sizeof text - (size_t)n, "%s\n", a->message);
    ps_gl_overlay_begin(a->width, a->height);
    const char *shown = a->help ? help_text : text;
    const int pad = 4;
    ps_gl_overlay_rect(0, 0, ps_gl_text_width(shown) + 2 * pad, ps_gl_text_height(shown) + 2 * pad, 0, 0, 0, 0.6f);
    glColor3f(1.0f, 1.0f, 0.85f);
    ps_gl_text(pad, pad, shown);
    ps_gl_overlay_end();
}

/* One refresh: a new view if needed, the new splats, the composite, the
 * overlay, and the swap. */
static ps_status refresh(app *a, ps_error *err)
{
    double t0 = glfwGetTime();
    ps_camera_frame cam = camera_frame(a);
    if (a->view_dirty) {
        ps_gl_layers_view(a->layers, a->gl, &cam, float_layers(a) ? 1.0 : a->exposure, (a->shown & PS_LAYER_DIRECT) != 0);
        a->drawn[0] = a->drawn[1] = 0;
        a->emitted[0] = a->emitted[1] = 0;
        a->view_dirty = false;
    }
    size_t upto[PS_MAP_COUNT];
    double t_splat = glfwGetTime();
    ps_status st = build_splats(a, upto, err);
    if (st != PS_OK)
        return st;
    size_t splats = 0;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        if (!float_layers(a))
            ps_gl_layers_clear_map(a->layers, k);
        ps_gl_layers_add(a->layers, a->gl, k, &a->batch[k], a->splat, a->splat_radius[k], a->o.p.point_size);
        a->drawn[k] = upto[k];
        splats += a->batch[k].splats;
    }
    if (float_layers(a) && splats > 0) {
        glFinish(); /* llvmpipe draws when flushed: time the drawing, not the queueing */
        double rate = (double)splats / fmax(glfwGetTime() - t_splat, 1e-6);
        a->budget = fmax(SPLAT_BUDGET_MIN, rate * a->tau * SPLAT_TIME_SHARE / PS_MAP_COUNT);
    }
    /* Thesis 5.1: once a refresh loses this much to round-off, more photons
     * only add noise: stop shooting (until the next edit). */
    if (!float_layers(a) && a->precision == PS_PRECISION_COUNTER && !a->counter_stopped &&
        a->lost_fraction > a->o.p.counter_threshold) {
        a->counter_stopped = true;
        ps_feed_pause(a->feed, true);
    }
    st = compose(a, err);
    if (st != PS_OK)
        return st;
    draw_overlay(a);
    double t1 = glfwGetTime();
    a->frame_seconds = t1 - t0;
    if (a->frames > 0 && t1 > a->last_refresh)
        a->fps += FPS_SMOOTHING * (1.0 / (t1 - a->last_refresh) - a->fps);
    a->last_refresh = t1;
    if (a->frames++ == 0)
        a->t_first_frame = t1;
    if (a->release_feed) {
        a->release_feed = false;
        if (!a->paused && !a->counter_stopped)
            ps_feed_pause(a->feed, false);
    }
    if (a->frames == 1)
        a->first_frame_seconds = t1 - a->start_time;
    else if (a->awaiting_edit_frame) {
        double latency = t1 - a->edit_time;
        a->edit_latency_sum += latency;
        a->edit_latency_count++;
        if (latency > a->edit_latency_max)
            a->edit_latency_max = latency;
        a->awaiting_edit_frame = false;
    }
    return PS_OK;
}

/* The window as shown (before the swap), as a PNG: the 8-bit codes decoded
 * to linear and written through the same encoder, which gives them back. */
static ps_status screenshot(app *a, const char *path, ps_error *err)
{
    ps_image img;
    ps_status st = ps_image_create(a->width, a->height, &img, err);
    uint8_t *rgb = st == PS_OK ? malloc(3 * (size_t)a->width * (size_t)a->height) : NULL;
    if (st == PS_OK && !rgb) {
        ps_image_destroy(&img);
        return ps_error_set(err, PS_ERR_NOMEM, "photosplat: out of memory for a screenshot");
    }
    if (st != PS_OK)
        return st;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, a->width, a->height, GL_RGB, GL_UNSIGNED_BYTE, rgb);
    for (int y = 0; y < a->height; y++) {
        float *dst = ps_image_at(&img, 0, y);
        const uint8_t *src = rgb + 3 * (size_t)(a->height - 1 - y) * (size_t)a->width;
        for (int i = 0; i < 3 * a->width; i++)
            dst[i] = ps_srgb_decode((float)src[i] / 255.0f);
    }
    free(rgb);
    st = ps_png_write(&img, path, 1.0f, err);
    ps_image_destroy(&img);
    if (st == PS_OK)
        snprintf(a->message, sizeof a->message, "saved %s", path);
    return st;
}

/* ---- camera ------------------------------------------------------------------------- */

/* Rotates v about unit axis k by angle (Rodrigues). */
static ps_vec3 rotate(ps_vec3 v, ps_vec3 k, double angle)
{
    double c = cos(angle), s = sin(angle);
    return ps_v3_add(ps_v3_add(ps_v3_scale(v, c), ps_v3_scale(ps_v3_cross(k, v), s)),
                     ps_v3_scale(k, ps_v3_dot(k, v) * (1.0 - c)));
}

/* Turntable orbit about the target, as Blender's: yaw about the camera's up
 * axis, pitch about its right axis, never over the pole. */
static void orbit(app *a, double yaw_deg, double pitch_deg)
{
    ps_vec3 up = ps_v3_norm(a->camera.up);
    ps_vec3 v = ps_v3_sub(a->camera.eye, a->camera.target);
    v = rotate(v, up, -yaw_deg * PS_PI / 180.0);
    double r = ps_v3_len(v);
    double elevation = asin(fmax(-1.0, fmin(1.0, ps_v3_dot(v, up) / r))) * 180.0 / PS_PI;
    double want = fmax(-PITCH_LIMIT_DEG, fmin(PITCH_LIMIT_DEG, elevation + pitch_deg));
    ps_vec3 right = ps_v3_norm(ps_v3_cross(v, up));
    v = rotate(v, right, -(want - elevation) * PS_PI / 180.0);
    a->camera.eye = ps_v3_add(a->camera.target, v);
    a->view_dirty = true;
}

static void pan(app *a, double dx, double dy)
{
    ps_camera_frame f = camera_frame(a);
    double dist = ps_v3_len(ps_v3_sub(a->camera.target, a->camera.eye));
    ps_vec3 move = ps_v3_add(ps_v3_scale(f.right, -dx * dist * PAN_PER_PIXEL), ps_v3_scale(f.up, dy * dist * PAN_PER_PIXEL));
    a->camera.eye = ps_v3_add(a->camera.eye, move);
    a->camera.target = ps_v3_add(a->camera.target, move);
    a->view_dirty = true;
}

static void zoom(app *a, double notches)
{
    ps_vec3 v = ps_v3_sub(a->camera.eye, a->camera.target);
    a->camera.eye = ps_v3_add(a->camera.target, ps_v3_scale(v, pow(ZOOM_PER_NOTCH, notches)));
    a->view_dirty = true;
}

/* ---- editing ----------------------------------------------------------------------- */

static void edited(app *a, bool geometry)
{
    a->scene_dirty = true;
    a->geometry_dirty = a->geometry_dirty || geometry;
    a->edits++;
}

static ps_status move_light_to(app *a, size_t light, ps_vec3 p, ps_error *err)
{
    ps_status st = ps_scene_set_light_position(a->scene, light, p, err);
    if (st == PS_OK)
        edited(a, false);
    return st;
}

static ps_status move_object_by(app *a, size_t object, ps_vec3 d, ps_error *err)
{
    ps_status st = ps_scene_translate_object(a->scene, object, d, err);
    if (st == PS_OK)
        edited(a, true);
    return st;
}

/* Moves the selection by d. */
static void move_selection(app *a, ps_vec3 d)
{
    ps_error err;
    size_t n;
    ps_status st = PS_OK;
    if (a->sel_kind == SEL_LIGHT) {
        const ps_light *L = &ps_scene_lights(a->scene, &n)[a->sel_index];
        st = move_light_to(a, a->sel_index, ps_v3_add(L->position, d), &err);
    } else if (a->sel_kind == SEL_OBJECT) {
        st = move_object_by(a, a->sel_index, d, &err);
    }
    if (st != PS_OK)
        snprintf(a->message, sizeof a->message, "%s", err.msg);
}

/* The point where the cursor's ray meets the drag plane through the anchor. */
static bool drag_point(const app *a, double x, double y, ps_vec3 *p)
{
    ps_camera_frame f = camera_frame(a);
    ps_ray r = ps_camera_ray(&f, x, y);
    ps_vec3 up = ps_v3_norm(a->camera.up);
    ps_vec3 n = up;
    if (a->drag_vertical) { /* the vertical plane facing the camera */
        n = ps_v3_sub(f.forward, ps_v3_scale(up, ps_v3_dot(f.forward, up)));
        if (ps_v3_len2(n) < 1e-12)
            return false;
        n = ps_v3_norm(n);
    }
    double dn = ps_v3_dot(r.d, n);
    if (fabs(dn) < 1e-9)
        return false;
    double t = ps_v3_dot(ps_v3_sub(a->drag_anchor, r.o), n) / dn;
    if (!(t > 0.0))
        return false;
    *p = ps_ray_at(r, t);
    return true;
}

/* Selects the light near the cursor, else the object under it. */
static void pick(app *a, double x, double y)
{
    ps_camera_frame f = camera_frame(a);
    size_t nl;
    const ps_light *lights = ps_scene_lights(a->scene, &nl);
    double best = PICK_RADIUS_PX * PICK_RADIUS_PX;
    a->sel_kind = SEL_NONE;
    for (size_t l = 0; l < nl; l++) {
        double px, py;
        if (lights[l].type == PS_LIGHT_MESH || !ps_camera_project(&f, lights[l].position, &px, &py))
            continue;
        double d2 = (px - x) * (px - x) + (py - y) * (py - y);
        if (d2 < best) {
            best = d2;
            a->sel_kind = SEL_LIGHT;
            a->sel_index = l;
            a->drag_anchor = lights[l].position;
        }
    }
    if (a->sel_kind != SEL_NONE)
        return;
    ps_surface sp;
    if (ps_world_intersect(a->world, ps_camera_ray(&f, x, y), INFINITY, &sp)) {
        a->sel_kind = SEL_OBJECT;
        a->sel_index = sp.object;
        a->drag_anchor = sp.p;
    }
}

static void select_next(app *a, int kind)
{
    size_t n;
    if (kind == SEL_LIGHT)
        (void)ps_scene_lights(a->scene, &n);
    else
        (void)ps_scene_objects(a->scene, &n);
    if (n == 0)
        return;
    a->sel_index = a->sel_kind == kind ? (a->sel_index + 1) % n : 0;
    a->sel_kind = kind;
}

static void scale_power(app *a, double f)
{
    size_t n;
    if (a->sel_kind != SEL_LIGHT)
        return;
    const ps_light *L = &ps_scene_lights(a->scene, &n)[a->sel_index];
    ps_error err;
    if (ps_scene_set_light_power(a->scene, a->sel_index, ps_rgb_scale(L->power, f), &err) == PS_OK)
        edited(a, false);
    else
        snprintf(a->message, sizeof a->message, "%s", err.msg);
}

static void step_angle(app *a, double d)
{
    size_t n;
    if (a->sel_kind != SEL_LIGHT)
        return;
    const ps_light *L = &ps_scene_lights(a->scene, &n)[a->sel_index];
    if (L->type != PS_LIGHT_SPOT)
        return;
    ps_error err;
    double want = fmin(90.0, fmax(KEY_ANGLE_STEP, L->angle_deg + d));
    if (ps_scene_set_spot_angle(a->scene, a->sel_index, want, &err) == PS_OK)
        edited(a, false);
    else
        snprintf(a->message, sizeof a->message, "%s", err.msg);
}

/* ---- settings (keys and scripts) --------------------------------------------------- */

static ps_status set_kernel(app *a, ps_kernel k, ps_error *err)
{
    ps_kernel_texture t;
    ps_status st = ps_kernel_texture_make(k, PS_KERNEL_TEXTURE_SIZE, &t, err);
    if (st != PS_OK)
        return st;
    ps_kernel_texture_free(&a->kernel);
    a->kernel = t;
    a->kernel_kind = k;
    ps_gl_renderer_set_kernel(a->gl, &a->kernel);
    a->view_dirty = true;
    return PS_OK;
}

static void set_layers(app *a, unsigned shown)
{
    a->shown = shown;
    a->view_dirty = true;
}

static void set_exposure(app *a, double e)
{
    a->exposure = e;
    if (!float_layers(a)) /* 8-bit layers hold exposed values */
        a->view_dirty = true;
}

static void set_paused(app *a, bool paused)
{
    a->paused = paused;
    if (!a->counter_stopped)
        ps_feed_pause(a->feed, paused);
}

/* ---- input ---------------------------------------------------------------------------- */

static app *app_of(GLFWwindow *w) { return glfwGetWindowUserPointer(w); }

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    app *a = app_of(w);
    if (action == GLFW_RELEASE)
        return;
    bool shift = (mods & GLFW_MOD_SHIFT) != 0;
    ps_error err;
    size_t n;
    double step = KEY_STEP_FRACTION * ps_v3_len(ps_aabb_diag(ps_scene_bounds(a->scene)));
    ps_camera_frame f = camera_frame(a);
    ps_vec3 up = ps_v3_norm(a->camera.up);
    /* Horizontal steps follow the view: right, and forward flattened. */
    ps_vec3 fwd = ps_v3_sub(f.forward, ps_v3_scale(up, ps_v3_dot(f.forward, up)));
    fwd = ps_v3_len2(fwd) > 1e-12 ? ps_v3_norm(fwd) : f.up;
    ps_vec3 right = ps_v3_norm(ps_v3_cross(fwd, up));
    switch (key) {
    case GLFW_KEY_Q: a->quit = true; break;
    case GLFW_KEY_H: a->help = !a->help; break;
    case GLFW_KEY_V: a->overlay = !a->overlay; break;
    case GLFW_KEY_SPACE: set_paused(a, !a->paused); break;
    case GLFW_KEY_S: a->splat = (ps_splat_mode)((a->splat + 1) % PS_SPLAT_MODE_COUNT), a->view_dirty = true; break;
    case GLFW_KEY_K:
        if (set_kernel(a, (ps_kernel)((a->kernel_kind + 1) % PS_KERNEL_COUNT), &err) != PS_OK)
            snprintf(a->message, sizeof a->message, "%s", err.msg);
        break;
    case GLFW_KEY_C:
        a->precision = (ps_precision)((a->precision + 1) % PS_PRECISION_COUNT), a->view_dirty = true;
        break;
    case GLFW_KEY_1: set_layers(a, a->shown ^ PS_LAYER_DIRECT); break;
    case GLFW_KEY_2: set_layers(a, a->shown ^ PS_LAYER_CAUSTIC); break;
    case GLFW_KEY_3: set_layers(a, a->shown ^ PS_LAYER_GLOBAL); break;
    case GLFW_KEY_R:
        for (int k = 0; k < PS_MAP_COUNT; k++)
            a->radius[k] *= shift ? 1.0 / KEY_SCALE : KEY_SCALE;
        a->view_dirty = true;
        break;
    case GLFW_KEY_T: a->tau = fmax(1e-3, a->tau * (shift ? 0.5 : 2.0)); break;
    case GLFW_KEY_E: set_exposure(a, a->exposure * (shift ? 1.0 / KEY_SCALE : KEY_SCALE)); break;
    case GLFW_KEY_TAB: select_next(a, shift ? SEL_OBJECT : SEL_LIGHT); break;
    case GLFW_KEY_ESCAPE: a->sel_kind = SEL_NONE; break;
    case GLFW_KEY_P: {
        /* Taken by the main loop after its next refresh: after a swap the
         * back buffer holds nothing defined. */
        time_t now = time(NULL);
        strftime(a->shot_path, sizeof a->shot_path, "photosplat-%Y%m%d-%H%M%S.png", localtime(&now));
        break;
    }
    case GLFW_KEY_LEFT: move_selection(a, ps_v3_scale(right, -step)); break;
    case GLFW_KEY_RIGHT: move_selection(a, ps_v3_scale(right, step)); break;
    case GLFW_KEY_UP: move_selection(a, ps_v3_scale(fwd, step)); break;
    case GLFW_KEY_DOWN: move_selection(a, ps_v3_scale(fwd, -step)); break;
    case GLFW_KEY_PAGE_UP: move_selection(a, ps_v3_scale(up, step)); break;
    case GLFW_KEY_PAGE_DOWN: move_selection(a, ps_v3_scale(up, -step)); break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: scale_power(a, KEY_SCALE); break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: scale_power(a, 1.0 / KEY_SCALE); break;
    case GLFW_KEY_LEFT_BRACKET: step_angle(a, -KEY_ANGLE_STEP); break;
    case GLFW_KEY_RIGHT_BRACKET: step_angle(a, KEY_ANGLE_STEP); break;
    default: break;
    }
    (void)n;
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    app *a = app_of(w);
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    if (action == GLFW_RELEASE) {
        a->drag = DRAG_NONE;
        return;
    }
    a->drag_x = x;
    a->drag_y = y;
    if (button == GLFW_MOUSE_BUTTON_MIDDLE)
        a->drag = (mods & GLFW_MOD_SHIFT) ? DRAG_PAN : DRAG_ORBIT;
    else if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_ALT))
        a->drag = DRAG_ORBIT;
    else if (button == GLFW_MOUSE_BUTTON_LEFT) {
        pick(a, x, y);
        a->drag_vertical = (mods & GLFW_MOD_CONTROL) != 0;
        a->drag = a->sel_kind != SEL_NONE ? DRAG_MOVE : DRAG_NONE;
    }
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    app *a = app_of(w);
    double dx = x - a->drag_x, dy = y - a->drag_y;
    if (a->drag == DRAG_ORBIT)
        orbit(a, dx * ORBIT_DEG_PER_PIXEL, dy * ORBIT_DEG_PER_PIXEL);
    else if (a->drag == DRAG_PAN)
        pan(a, dx, dy);
    else if (a->drag == DRAG_MOVE) {
        ps_vec3 from, to;
        if (drag_point(a, a->drag_x, a->drag_y, &from) && drag_point(a, x, y, &to)) {
            move_selection(a, ps_v3_sub(to, from));
            a->drag_anchor = ps_v3_add(a->drag_anchor, ps_v3_sub(to, from));
        }
    }
    a->drag_x = x;
    a->drag_y = y;
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    zoom(app_of(w), dy);
}

/* ---- the script ------------------------------------------------------------------------- */

static ps_status run_action(app *a, const ps_script_action *act, ps_error *err)
{
    size_t n;
    switch (act->kind) {
    case PS_SCRIPT_SCREENSHOT:
        return screenshot(a, act->path, err);
    case PS_SCRIPT_MOVE_LIGHT:
        (void)ps_scene_lights(a->scene, &n);
        if (act->index >= n)
            return ps_error_set(err, PS_ERR_RANGE, "%s:%d: move light %u: the scene has %zu lights", a->o.script,
                                act->line, act->index, n);
        return move_light_to(a, act->index, act->v, err);
    case PS_SCRIPT_MOVE_OBJECT:
        (void)ps_scene_objects(a->scene, &n);
        if (act->index >= n)
            return ps_error_set(err, PS_ERR_RANGE, "%s:%d: move object %u: the scene has %zu objects", a->o.script,
                                act->line, act->index, n);
        return move_object_by(a, act->index, act->v, err);
    case PS_SCRIPT_POWER:
        (void)ps_scene_lights(a->scene, &n);
        if (act->index >= n)
            return ps_error_set(err, PS_ERR_RANGE, "%s:%d: power light %u: the scene has %zu lights", a->o.script,
                                act->line, act->index, n);
        if (ps_scene_set_light_power(a->scene, act->index, act->power, err) != PS_OK)
            return err->status;
        edited(a, false);
        return PS_OK;
    case PS_SCRIPT_ANGLE:
        (void)ps_scene_lights(a->scene, &n);
        if (act->index >= n)
            return ps_error_set(err, PS_ERR_RANGE, "%s:%d: angle light %u: the scene has %zu lights", a->o.script,
                                act->line, act->index, n);
        if (ps_scene_set_spot_angle(a->scene, act->index, act->number, err) != PS_OK)
            return err->status;
        edited(a, false);
        return PS_OK;
    case PS_SCRIPT_ORBIT:
        orbit(a, act->yaw, act->pitch);
        return PS_OK;
    case PS_SCRIPT_WAIT:
        a->script_waiting = true;
        a->wait_time = act->time;
        return PS_OK;
    case PS_SCRIPT_QUIT:
        a->quit = true;
        return PS_OK;
    case PS_SCRIPT_SET:
        switch (act->setting) {
        case PS_SET_SPLAT: a->splat = (ps_splat_mode)act->choice, a->view_dirty = true; return PS_OK;
        case PS_SET_LAYERS: set_layers(a, act->layers); return PS_OK;
        case PS_SET_KERNEL: return set_kernel(a, (ps_kernel)act->choice, err);
        case PS_SET_RADIUS:
            a->radius[PS_MAP_CAUSTIC] = act->number;
            if (act->number2 > 0.0)
                a->radius[PS_MAP_GLOBAL] = act->number2;
            a->view_dirty = true;
            return PS_OK;
        case PS_SET_TAU: a->tau = act->number; return PS_OK;
        case PS_SET_PRECISION: a->precision = (ps_precision)act->choice, a->view_dirty = true; return PS_OK;
        case PS_SET_EXPOSURE: set_exposure(a, act->number); return PS_OK;
        case PS_SET_PAUSE: set_paused(a, act->choice != 0); return PS_OK;
        }
        return PS_OK;
    }
    return PS_OK;
}

/* Whether a script's wait done is over: every map at its cap and all of it
 * drawn, with no edit or view change pending; or tracing paused (by the
 * user, a script or the error counter), which would otherwise never end it. */
static bool script_wait_over(app *a)
{
    if (a->scene_dirty || a->view_dirty)
        return false;
    if (a->paused || a->counter_stopped)
        return true;
    ps_feed_lock(a->feed);
    bool over = ps_feed_ended(a->feed);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        over = over && a->drawn[k] >= ps_feed_maps(a->feed)[k].count;
    ps_feed_unlock(a->feed);
    return over;
}

/* ---- the session ---------------------------------------------------------------------- */

static ps_status open_window(app *a, ps_error *err)
{
    if (!glfwInit())
        return ps_error_set(err, PS_ERR_IO, "photosplat: cannot open a window (no display?); "
                                            "photosplat-snap renders headless");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    glfwWindowHint(GLFW_STENCIL_BITS, 8);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    char title[512];
    snprintf(title, sizeof title, "photosplat - %s", a->o.c.scene);
    a->win = glfwCreateWindow(a->width, a->height, title, NULL, NULL);
    if (!a->win)
        return ps_error_set(err, PS_ERR_IO, "photosplat: cannot create a %dx%d OpenGL 2.1 window", a->width, a->height);
    glfwMakeContextCurrent(a->win);
    glfwSwapInterval(0); /* refresh on our tau, not the monitor's */
    int fw, fh;
    glfwGetFramebufferSize(a->win, &fw, &fh);
    a->width = fw;
    a->height = fh;
    glfwSetWindowUserPointer(a->win, a);
    glfwSetKeyCallback(a->win, on_key);
    glfwSetMouseButtonCallback(a->win, on_button);
    glfwSetCursorPosCallback(a->win, on_cursor);
    glfwSetScrollCallback(a->win, on_scroll);
    return PS_OK;
}

static ps_status session(app *a, ps_error *err)
{
    const ps_scene_defaults *def = ps_scene_get_defaults(a->scene);
    a->width = a->o.c.width ? a->o.c.width : def->width;
    a->height = a->o.c.height ? a->o.c.height : def->height;
    a->camera = *ps_scene_camera(a->scene);
    a->splat = (ps_splat_mode)a->o.p.splat;
    a->kernel_kind = (ps_kernel)a->o.p.kernel;
    a->precision = (ps_precision)a->o.p.precision;
    a->shown = a->o.p.layers;
    a->tau = a->o.p.tau;
    a->exposure = a->o.c.exposure;
    a->overlay = a->o.overlay != 0;
    a->budget = SPLAT_BUDGET_START;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        a->radius[k] = a->splat_radius[k] = ps_shared_radius(&a->o.c, def, (ps_map_kind)k);
        a->cap[k] = ps_shared_photons(&a->o.c, def, (ps_map_kind)k);
        ps_splat_batch_init(&a->batch[k]);
    }
    a->start_time = glfwGetTime();
    ps_status st = open_window(a, err);
    if (st == PS_OK)
        st = ps_kernel_texture_make(a->kernel_kind, PS_KERNEL_TEXTURE_SIZE, &a->kernel, err);
    if (st == PS_OK)
        st = ps_gl_layers_create(a->width, a->height, float_layers(a), &a->layers, err);
    a->pixels = malloc(3 * (size_t)a->width * (size_t)a->height);
    if (st == PS_OK && !a->pixels)
        st = ps_error_set(err, PS_ERR_NOMEM, "photosplat: out of memory for a %dx%d picture", a->width, a->height);
    if (st == PS_OK)
        st = rebuild(a, true, err);
    a->edit_time = glfwGetTime();
    a->awaiting_edit_frame = true;
    double next = 0.0;
    while (st == PS_OK && !a->quit && !glfwWindowShouldClose(a->win)) {
        if (ps_cancelled(a->o.cancel)) {
            st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %llu frames", (unsigned long long)a->frames);
            break;
        }
        double now = glfwGetTime();
        if (now < next && !a->view_dirty && !a->scene_dirty)
            glfwWaitEventsTimeout(next - now);
        else
            glfwPollEvents();
        /* Script actions that are due, in order; times count from the first frame. */
        while (st == PS_OK && a->script && a->frames > 0 && a->script_next < ps_script_count(a->script)) {
            const ps_script_action *act = ps_script_at(a->script, a->script_next);
            if (a->script_waiting) {
                if (!script_wait_over(a))
                    break;
                a->script_waiting = false;
                a->script_delay = glfwGetTime() - a->t_first_frame - a->wait_time;
            }
            if (act->time + a->script_delay > glfwGetTime() - a->t_first_frame)
                break;
            a->script_next++;
            if (act->kind == PS_SCRIPT_SCREENSHOT) /* the window as it is now: refresh first */
                st = refresh(a, err);
            if (st == PS_OK)
                st = run_action(a, act, err);
        }
        if (st != PS_OK || a->quit)
            break;
        if (a->scene_dirty) {
            /* Every edit restarts the maps (thesis 4.1.4); the first refresh
             * follows at once, with whatever the first batch brings. */
            st = rebuild(a, a->geometry_dirty, err);
            a->scene_dirty = a->geometry_dirty = false;
            a->edit_time = glfwGetTime();
            a->awaiting_edit_frame = true;
            next = 0.0;
            if (st != PS_OK)
                break;
        }
        now = glfwGetTime();
        if (now >= next || a->view_dirty || a->shot_path[0]) {
            st = refresh(a, err);
            if (st == PS_OK && a->shot_path[0]) {
                ps_error shot_err;
                if (screenshot(a, a->shot_path, &shot_err) != PS_OK)
                    snprintf(a->message, sizeof a->message, "%s", shot_err.msg);
                a->shot_path[0] = '\0';
            }
            if (st == PS_OK)
                glfwSwapBuffers(a->win);
            next = now + a->tau;
        }
    }
    if (st == PS_OK && a->feed)
        st = ps_feed_status(a->feed, err);
    return st;
}

static ps_status write_stats(app *a, ps_error *err)
{
    ps_run_stats rs;
    memset(&rs, 0, sizeof rs);
    bool cap_reached = false, store_limited = false;
    double map_bytes = 0.0; /* what the current maps hold allocated: bounded by the caps */
    if (a->feed) {
        ps_feed_lock(a->feed);
        for (int k = 0; k < PS_MAP_COUNT; k++) {
            const ps_photon_map *m = &ps_feed_maps(a->feed)[k];
            rs.emitted[k] = m->counters.emitted;
            rs.stored[k] = m->counters.stored;
            rs.rays += m->counters.rays;
            map_bytes += (double)ps_photon_map_bytes(m);
        }
        store_limited = ps_feed_store_limited(a->feed);
        cap_reached = ps_feed_ended(a->feed) && !store_limited;
        ps_feed_unlock(a->feed);
        rs.skips = ps_tracer_skips(a->tracer, &rs.skip_count);
    }
    double elapsed = glfwGetTime() - a->edit_time;
    rs.trace_seconds = elapsed;
    rs.frames = a->frames;
    ps_stats_add(&rs, "width", a->width);
    ps_stats_add(&rs, "height", a->height);
    ps_stats_add(&rs, "fps", a->fps);
    ps_stats_add(&rs, "frame_seconds", a->frame_seconds);
    ps_stats_add(&rs, "first_frame_seconds", a->first_frame_seconds);
    ps_stats_add(&rs, "edits", (double)a->edits);
    ps_stats_add(&rs, "edit_to_frame_seconds_max", a->edit_latency_max);
    ps_stats_add(&rs, "edit_to_frame_seconds_mean",
                 a->edit_latency_count ? a->edit_latency_sum / (double)a->edit_latency_count : 0.0);
    ps_stats_add(&rs, "tau", a->tau);
    ps_stats_add(&rs, "counter_stopped", a->counter_stopped ? 1.0 : 0.0);
    ps_stats_add(&rs, "caustic_cap", (double)a->cap[PS_MAP_CAUSTIC]);
    ps_stats_add(&rs, "global_cap", (double)a->cap[PS_MAP_GLOBAL]);
    ps_stats_add(&rs, "cap_reached", cap_reached ? 1.0 : 0.0);
    ps_stats_add(&rs, "photon_map_bytes", map_bytes);
    ps_stats_add(&rs, "max_photons", (double)a->o.max_photons);
    ps_stats_add(&rs, "max_photons_reached", store_limited ? 1.0 : 0.0);
    return ps_stats_write(a->o.c.stats, &rs, err);
}

int main(int argc, char **argv)
{
    static app a; /* large, and the callbacks reach it through the window */
    ps_error err;
    ps_error_clear(&err);
    bool help = false;
    if (parse_args(argc, argv, &a.o, &help, &err) != PS_OK)
        return ps_cli_fail(&err);
    if (help) {
        fputs(usage, stdout);
        fputs("\nin the window:\n", stdout);
        fputs(help_text, stdout);
        fputc('\n', stdout);
        return PS_EXIT_OK;
    }
    /* Bad input is refused before a window opens. */
    if (a.o.script && ps_script_load(a.o.script, &a.script, &err) != PS_OK)
        return ps_cli_fail(&err);
    ps_status st = ps_check_outputs(&a.o.c, &err);
    for (size_t i = 0; st == PS_OK && a.script && i < ps_script_count(a.script); i++) {
        const ps_script_action *act = ps_script_at(a.script, i);
        if (act->kind == PS_SCRIPT_SCREENSHOT)
            st = ps_check_output_path(act->path, &err);
    }
    if (st == PS_OK)
        st = ps_scene_load(a.o.c.scene, NULL, &a.scene, &err);
    if (st == PS_OK) {
        const ps_scene_defaults *def = ps_scene_get_defaults(a.scene);
        uint64_t photons =
            ps_shared_photons(&a.o.c, def, PS_MAP_CAUSTIC) + ps_shared_photons(&a.o.c, def, PS_MAP_GLOBAL);
        st = ps_check_run_memory("photosplat", photons, PS_PREVIEW_PHOTON_BYTES, a.o.c.width ? a.o.c.width : def->width,
                                 a.o.c.height ? a.o.c.height : def->height, WIN_PIXEL_BYTES, &err);
    }
    if (st != PS_OK) {
        ps_script_destroy(a.script);
        ps_scene_destroy(a.scene);
        return ps_cli_fail(&err);
    }
    a.o.cancel = ps_interrupt_install();
    st = session(&a, &err);
    if (st == PS_OK && a.o.c.stats)
        st = write_stats(&a, &err);
    teardown_maps(&a);
    ps_gl_layers_destroy(a.layers);
    ps_gl_renderer_destroy(a.gl);
    ps_kernel_texture_free(&a.kernel);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_splat_batch_free(&a.batch[k]);
    ps_preview_mesh_free(&a.mesh);
    ps_world_destroy(a.world);
    ps_image_destroy(&a.picture);
    free(a.pixels);
    if (a.win)
        glfwDestroyWindow(a.win);
    glfwTerminate();
    ps_script_destroy(a.script);
    ps_scene_destroy(a.scene);
    if (st == PS_OK)
        printf("photosplat: %llu frames, %llu edits\n", (unsigned long long)a.frames, (unsigned long long)a.edits);
    if (st == PS_ERR_INTERRUPTED) { /* screenshots already taken stay; the stats are not written */
        fprintf(stderr, "photosplat: %s\n", err.msg);
        return ps_interrupt_exit_status();
    }
    return st == PS_OK ? PS_EXIT_OK : ps_cli_fail(&err);
}
