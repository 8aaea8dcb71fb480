/* window_main.c: photosplat, the lighting designer's preview window. A
 * preview session (src/preview/session.h: tracing threads shoot
 * continuously, and every tau the picture takes in what has arrived, thesis
 * 4.1.4) drawn by src/gl into a GLFW window (src/gl/platform_glfw.c, libGL,
 * never OSMesa); this file is the options, the input and the loop. Moving the
 * camera keeps every photon; moving a light or an object restarts the maps. */
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app/cli.h"
#include "app/interrupt.h"
#include "app/latency.h"
#include "app/options.h"
#include "app/stats.h"
#include "app/workfile.h"
#include "core/fileio.h"
#include "core/memory.h"
#include "gl/gl_font.h"
#include "gl/gl_render.h"
#include "gl/gl_specular.h"
#include "gl/platform.h"
#include "image/falsecolor.h"
#include "image/image.h"
#include "preview/script.h"
#include "preview/session.h"
#include "preview/specular_glossy.h"
#include "scene/camera.h"
#include "scene/scene.h"

/* Shadow maps are remade after every light move: half the snapshot's side,
 * a quarter of the fill, for a refresh soon after the move. */
#define WIN_SHADOW_SIZE 512
/* The memory plan (ps_check_run_memory): a pixel is the float splat layers,
 * the linear and the shown composite, and the window's own colour and depth;
 * the specular layer's texture, cube maps and glossy levels come on top
 * (ps_specular_plan_bytes: 16.6 MB at most for 8 cubes, 4.2 MB more a 512^2
 * texture). */
#define WIN_PIXEL_BYTES (3 * 4 * sizeof(float) + 4 * sizeof(float) + 4 + 4 + 4)
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
/* A message (an error, a saved screenshot) shows in the overlay this long. */
#define MESSAGE_SECONDS 4.0
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
    "  --global-photons N       global photon cap likewise; edits repair both maps (--repair)\n"
    "  --max-photons N          memory cap: stop once the maps store N photons (default 2^25, 0: none)\n"
    "  --caustic-radius R       caustic splat radius, scene units\n"
    "  --global-radius R        global splat radius, scene units\n"
    "  --seed S                 photon i depends only on (scene, seed, i) (default 0)\n"
    "  --threads N              tracing threads (default: all cores but one, left to drawing)\n"
    "  --stats FILE.json        figures of the session, written at the end\n"
    "  --script FILE            timed actions (see the README), e.g. for tests\n"
    "  --tau SECONDS            time between refreshes (default 0.1)\n"
    "  --splat points|triangles|sprites  (default triangles)\n"
    "  --kernel box|cone|gauss|epanechnikov  (default cone)\n"
    "  --layers LIST            comma list of direct,caustic,global,specular (default all)\n"
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
    "  --global-layer splats|maps  the global map as splats or as illumination maps\n"
    "                           on the surfaces (default splats; key M)\n"
    "  --bake on|off            once a map is traced to its end and its photons all\n"
    "                           lie on diffuse quads, lay its splats into textures on\n"
    "                           them, and the direct light on diffuse quads once the\n"
    "                           lights hold, and draw those for each new view\n"
    "                           (default on)\n"
    "  --overlay on|off         the text overlay (default on)\n"
    "  --autosave on|off        write every edit within a second to\n"
    "                           NAME.autosave.scn (default on; off with --script,\n"
    "                           whose sessions are tests and demos)\n"
    "  --repair on|off          edits keep the photons they cannot change (default on;\n"
    "                           off: every edit restarts both maps, as before)\n"
    "  --composite gl|cpu       where the picture is encoded for display: by GL (default),\n"
    "                           or read back and encoded on the CPU (the old way, for\n"
    "                           scripts/bench-window.sh to compare)\n"
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
    "  M                global layer: splats / illumination maps\n"
    "  1 2 3 4          direct, caustic, global, specular layer on/off\n"
    "  R / Shift+R      splat radius up / down\n"
    "  T / Shift+T      tau up / down\n"
    "  E / Shift+E      exposure up / down\n"
    "  Space            pause tracing    V  overlay    P  screenshot\n"
    "  Ctrl+S           save the scene (the previous file kept as NAME.scn~)\n"
    "  Ctrl+Z / Ctrl+Shift+Z  undo / redo an edit\n"
    "  F                illuminance in false colour (lux under the cursor)\n"
    "  H                this help        Q  quit";

typedef struct win_options {
    ps_shared_options c;
    ps_preview_options p;
    const char *script;
    int overlay;
    int autosave; /* 1 on, 0 off, -1 unset: on unless scripted */
    int no_repair; /* --repair off: every edit restarts the maps (the bench's baseline) */
    int64_t max_photons; /* stored photons of both maps; 0: no bound */
    int composite;       /* 1: on the GL side (the default); 0: read back and encoded on the CPU */
    const ps_cancel_flag *cancel; /* raised by SIGINT or SIGTERM: the session ends */
} win_options;

typedef struct app {
    win_options o;
    ps_scene *scene;
    ps_session *session;
    ps_platform *platform;
    GLFWwindow *win;
    ps_gl_renderer *gl;
    ps_gl_layers *layers;
    ps_gl_specular *spec; /* the specular layer's cube maps */
    int width, height;
    ps_camera camera;
    ps_session_frame frame; /* the last refresh's */
    bool overlay, help;
    bool redraw; /* the camera or a setting changed: refresh now, not at the next tau */
    /* Selection and dragging. */
    int sel_kind;
    size_t sel_index;
    int drag;
    bool key_repeat; /* a held key's repeats: edits as a drag's */
    double drag_x, drag_y;
    ps_vec3 drag_anchor;
    bool drag_vertical;
    /* Timing and figures. */
    bool warmed_up; /* the scaled show drawn once (ps_gl_layers_warm_up) */
    double start_time, t_first_frame, first_frame_seconds, last_refresh, fps, frame_seconds;
    uint64_t frames;
    double edit_time;
    bool awaiting_edit_frame;
    /* The camera's level of detail: frames drawn while it moved, their time,
     * and how long after the last one every photon was back in the picture. */
    uint64_t moving_frames;
    double moving_seconds, moving_end, full_after_stop;
    /* When the camera last moved (an orbit, pan or zoom, a script's or the
     * user's), and from then to the full picture after the last such move. */
    double camera_step, full_after_step;
    bool relight; /* the direct light's textures were just laid: the direct layer drawn again */
    bool full_pending;
    ps_latency lat; /* an edit's first refreshed frame, phase by phase (app/latency.h) */
    /* Illuminance in false colour (key F): the last refresh's lux, a pixel
     * each (row 0 the top), the cursor that reads it, and the 8-bit picture. */
    bool false_color;
    float *lux;
    uint8_t *rgb;
    double cursor_x, cursor_y;
    ps_lux_scale lux_scale;
    double show_sum; /* the composite shown, all refreshes */
    uint64_t show_count;
    /* The script. */
    ps_script *script;
    size_t script_next;
    /* wait done: the later actions are held while waiting; then the script
     * clock is set back to the wait's time (script_delay seconds behind). */
    bool script_waiting;
    double wait_time, script_delay;
    bool quit;
    char shot_path[64]; /* a screenshot asked for with P, taken after the next refresh */
    char message[PS_ERROR_MSG_MAX + 64]; /* the last action's one-line report, shown in the overlay */
    double message_time;
    /* Save, autosave, undo (app/workfile.h); Q once more quits with unsaved edits. */
    ps_work work;
    bool quit_armed;
} app;

static void say(app *a, const char *text)
{
    /* Truncated to the overlay's line (a message names at most two paths). */
    snprintf(a->message, sizeof a->message, "%.*s", (int)sizeof a->message - 1, text);
    a->message_time = ps_now_seconds();
}

/* ---- options ---------------------------------------------------------------- */

static ps_status parse_args(int argc, char **argv, win_options *o, bool *help, ps_error *err)
{
    static const char *const on_off[] = {"off", "on", NULL};
    ps_cli cli = ps_cli_begin("photosplat", argc, argv);
    memset(o, 0, sizeof *o);
    ps_shared_options_init(&o->c);
    /* Float layers: they take in only new photons each refresh (session.h). */
    ps_preview_options_init(&o->p, true);
    o->overlay = 1;
    o->autosave = -1;
    o->max_photons = WIN_MAX_PHOTONS_DEFAULT;
    o->composite = 1;
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
        } else if (ps_cli_is(&cli, "--autosave")) {
            st = ps_cli_choice(&cli, on_off, &o->autosave, err);
        } else if (ps_cli_is(&cli, "--repair")) {
            st = ps_cli_choice(&cli, on_off, &o->no_repair, err);
            o->no_repair = !o->no_repair;
        } else if (ps_cli_is(&cli, "--composite")) {
            static const char *const where[] = {"cpu", "gl", NULL};
            st = ps_cli_choice(&cli, where, &o->composite, err);
        } else if (ps_cli_is(&cli, "--max-photons")) {
            st = ps_cli_int(&cli, 0, PS_SCENE_MAX_PHOTONS, &o->max_photons, err);
        } else {
            return ps_cli_unknown(&cli, err);
        }
    }
    if (st == PS_OK && !o->c.scene)
        o->c.scene = "data/scenes/cornell-caustic.scn";
    if (o->autosave < 0)
        o->autosave = o->script ? 0 : 1;
    return st;
}

/* ---- the session and what draws it ------------------------------------------------ */

static ps_camera_frame camera_frame(const app *a) { return ps_camera_frame_make(&a->camera, a->width, a->height); }

/* The scaled show drawn once (ps_gl_layers_warm_up), in the first wait
 * after the first picture, so that the first edit's or camera step's level
 * of detail does not build it. Drawn before the first picture, it took that
 * picture 0.06-0.07 s longer (the default box at 512^2: 0.53-0.55 s against
 * 0.47-0.48 s, docs/preview.md). Not at once after it: a script's actions
 * count from the first picture, and the first would come later. */
static bool warm_up_show(app *a)
{
    if (a->o.composite)
        ps_gl_layers_warm_up(a->layers);
    a->warmed_up = true;
    return true;
}

/* The session, its GL renderer and layers. */
static ps_status open_session(app *a, ps_error *err)
{
    ps_session_settings set = ps_preview_settings(&a->o.c, &a->o.p, a->scene);
    set.threads = ps_session_tracing_threads(a->o.c.threads, true); /* a core left to drawing */
    set.cancel = a->o.cancel;
    set.max_stored = (size_t)a->o.max_photons;
    set.incremental = true;
    set.shadow_size = a->o.p.shadows ? WIN_SHADOW_SIZE : 0;
    set.progressive_lights = true; /* the first picture (and the first after an edit) sooner */
    set.repair = !a->o.no_repair;
    ps_status st = ps_session_create(a->scene, &set, &a->session, err);
    ps_gl_options go = {a->o.p.shadows != 0, true, WIN_SHADOW_SIZE, false, a->o.p.bake, ps_platform_gl_proc};
    if (st == PS_OK) {
        ps_gl_scene gs = ps_gl_scene_of(a->session);
        st = ps_gl_renderer_create(&gs, ps_session_kernel(a->session), &go, &a->gl, err);
    }
    if (st == PS_OK)
        st = ps_gl_layers_create(a->width, a->height, set.float_buffer, &a->layers, err);
    if (st == PS_OK)
        ps_gl_layers_reserve(a->layers, a->gl, ps_session_illummap(a->session) != NULL);
    if (st == PS_OK)
        st = ps_gl_specular_create(0, &a->spec, err);
    /* The first batch is traced here, and the thread starts held until the
     * first refresh has drawn it: that refresh (its splats) then has every
     * core, and the caustic shows at once. The first view (shadow maps,
     * prepass, llvmpipe's first programs) is drawn into the layers while
     * the batch is traced, as snap's, and that refresh does not draw it
     * again (ps_gl_layers_start). */
    if (st == PS_OK) {
        ps_camera_frame cam = camera_frame(a);
        st = ps_gl_layers_start(a->layers, a->gl, a->session, &cam, err);
    }
    return st;
}

/* Edits made since the last refresh: the session restarts the maps, and the
 * renderer follows its new meshes and lights. */
static ps_status apply_edits(app *a, ps_error *err)
{
    ps_session_changes ch;
    ps_status st = ps_session_update(a->session, &ch, err);
    if (st == PS_OK) {
        ps_gl_scene gs = ps_gl_scene_of(a->session);
        st = ps_gl_renderer_set_scene(a->gl, &gs, err);
    }
    return st;
}

static void draw_overlay(app *a)
{
    if (!a->overlay && !a->help)
        return;
    const ps_session_settings *set = ps_session_get_settings(a->session);
    const ps_scene *scene = ps_session_scene(a->session);
    ps_session_counts counts;
    ps_session_get_counts(a->session, &counts);
    bool float_layers = set->float_buffer;
    bool counter_stopped = ps_session_counter_stopped(a->session, NULL);
    char text[2 * PS_ERROR_MSG_MAX + 1024];
    uint64_t ce = counts.map[0].emitted, ge = counts.map[1].emitted;
    double elapsed = ps_now_seconds() - a->edit_time;
    double rate = elapsed > 0.0 ? (double)(ce + ge) / elapsed : 0.0;
    const char *state = counter_stopped                   ? "stopped by the error counter"
                        : ps_session_paused(a->session) ? "paused"
                        : counts.store_limited            ? "memory cap reached (--max-photons)"
                        : counts.ended                    ? "cap reached"
                                                          : "tracing";
    int n = snprintf(text, sizeof text,
                     "caustic %llu/%llu  global %llu/%llu  %s\n"
                     "%.3g photons/s  %.1f fps  tau %.3g s  frame %.0f ms\n"
                     "%s splats  %s kernel  r %.3g/%.3g  layers %s%s%s%s  global %s  %s  exposure %.3g\n",
                     (unsigned long long)ce, (unsigned long long)set->caps[0], (unsigned long long)ge,
                     (unsigned long long)set->caps[1], state, rate, a->fps, set->tau, 1000.0 * a->frame_seconds,
                     ps_splat_mode_name(set->splat), ps_kernel_name(set->kernel),
                     ps_session_radius(a->session, PS_MAP_CAUSTIC), ps_session_radius(a->session, PS_MAP_GLOBAL),
                     set->layers & PS_LAYER_DIRECT ? "D" : "-", set->layers & PS_LAYER_CAUSTIC ? "C" : "-",
                     set->layers & PS_LAYER_GLOBAL ? "G" : "-", set->layers & PS_LAYER_SPECULAR ? "S" : "-",
                     ps_global_layer_name(set->global_layer),
                     float_layers ? "float" : ps_precision_name(set->precision),
                     set->exposure);
    /* The bake (--bake): how far each map is laid, once it has begun. */
    bool baking = false;
    for (int k = 0; k < PS_MAP_COUNT && n > 0 && (size_t)n < sizeof text; k++) {
        double laid = ps_session_bake_progress(a->session, (ps_map_kind)k);
        if (laid < 0.0)
            continue;
        if (laid >= 1.0)
            n += snprintf(text + n, sizeof text - (size_t)n, "%s%s baked", baking ? ", " : "", ps_map_name((ps_map_kind)k));
        else
            n += snprintf(text + n, sizeof text - (size_t)n, "%sbaking %s %.0f %%", baking ? ", " : "",
                          ps_map_name((ps_map_kind)k), 100.0 * laid);
        baking = true;
    }
    if (baking && n > 0 && (size_t)n < sizeof text)
        n += snprintf(text + n, sizeof text - (size_t)n, "\n");
    if (!float_layers && n > 0 && (size_t)n < sizeof text)
        n += snprintf(text + n, sizeof text - (size_t)n, "error counter: %.1f %% of the last refresh rounded away%s\n",
                      100.0 * a->frame.round_off, counter_stopped ? " (stopped shooting)" : "");
    if (a->sel_kind != SEL_NONE && n > 0 && (size_t)n < sizeof text) {
        size_t count;
        if (a->sel_kind == SEL_LIGHT) {
            const ps_light *L = &ps_scene_lights(scene, &count)[a->sel_index];
            n += snprintf(text + n, sizeof text - (size_t)n, "selected: light %zu (%s) at %.3g %.3g %.3g, %.3g W",
                          a->sel_index, ps_light_type_name(L->type), L->position.x, L->position.y, L->position.z,
                          ps_rgb_mean(L->power));
            if (L->type == PS_LIGHT_SPOT)
                n += snprintf(text + n, sizeof text - (size_t)n, ", %.3g deg", L->angle_deg);
        } else {
            const ps_object *ob = &ps_scene_objects(scene, &count)[a->sel_index];
            ps_vec3 c = ps_aabb_center(ob->bounds);
            n += snprintf(text + n, sizeof text - (size_t)n, "selected: object %zu (line %d) at %.3g %.3g %.3g",
                          a->sel_index, ob->line, c.x, c.y, c.z);
        }
        if (n > 0 && (size_t)n < sizeof text)
            n += snprintf(text + n, sizeof text - (size_t)n, "\n");
    }
    if (a->false_color && a->lux && n > 0 && (size_t)n < sizeof text) {
        int cx = (int)a->cursor_x, cy = (int)a->cursor_y;
        if (cx >= 0 && cx < a->width && cy >= 0 && cy < a->height)
            n += snprintf(text + n, sizeof text - (size_t)n, "illuminance: %.4g lx under the cursor (scale %.3g to %.3g lx)\n",
                          a->lux[(size_t)cy * (size_t)a->width + (size_t)cx], a->lux_scale.lo, a->lux_scale.hi);
        else
            n += snprintf(text + n, sizeof text - (size_t)n, "illuminance: %.3g to %.3g lx (F: off)\n", a->lux_scale.lo,
                          a->lux_scale.hi);
    }
    const char *note = ps_scene_note(scene);
    if (note && n > 0 && (size_t)n < sizeof text)
        n += snprintf(text + n, sizeof text - (size_t)n, "%s\n", note);
    if (a->work.dirty && n > 0 && (size_t)n < sizeof text)
        n += snprintf(text + n, sizeof text - (size_t)n, "* unsaved edits (Ctrl+S: %s; autosaved to %s)\n",
                      a->work.names.save, a->work.names.autosave);
    if (a->message[0] && ps_now_seconds() - a->message_time > MESSAGE_SECONDS)
        a->message[0] = '\0';
    if (a->message[0] && n > 0 && (size_t)n < sizeof text)
        snprintf(text + n, sizeof text - (size_t)n, "%s\n", a->message);
    ps_gl_overlay_begin(a->width, a->height);
    ps_gl_overlay_panel(a->help ? help_text : text);
    ps_gl_overlay_end();
}

/* The false-colour picture of the illuminance (the session in illuminance
 * mode: layers of E / pi), read back, in lux, and drawn with its legend over
 * the window's right edge. */
static ps_status show_false_color(app *a, const double gains[PS_MAP_COUNT], ps_error *err)
{
    size_t n = (size_t)a->width * (size_t)a->height;
    if (!a->lux)
        a->lux = malloc(n * sizeof *a->lux);
    if (!a->rgb)
        a->rgb = malloc(3 * n);
    if (!a->lux || !a->rgb)
        return ps_error_set(err, PS_ERR_NOMEM, "photosplat: out of memory for the illuminance picture");
    ps_image irr;
    ps_status st = ps_gl_layers_composite(a->layers, a->frame.direct_gain, gains, &irr, err);
    if (st != PS_OK)
        return st;
    for (size_t i = 0; i < 3 * n; i++)
        irr.rgb[i] *= (float)PS_PI; /* white Lambertian: L = E / pi */
    ps_lux_from_irradiance(&irr, a->lux);
    ps_image_destroy(&irr);
    a->lux_scale = ps_lux_scale_auto(a->lux, n);
    ps_image fc;
    st = ps_falsecolor_image(a->lux, a->width, a->height, a->lux_scale, &fc, err);
    if (st != PS_OK)
        return st;
    /* The picture's columns, then the legend (fc.width - width wide) over
     * the right edge, rows flipped for GL. */
    int legend = fc.width - a->width, split = a->width > legend ? a->width - legend : 0;
    for (int y = 0; y < a->height; y++) {
        uint8_t *dst = a->rgb + 3 * (size_t)(a->height - 1 - y) * (size_t)a->width;
        for (int x = 0; x < a->width; x++) {
            const float *src = ps_image_at(&fc, x < split ? x : x + legend, y);
            for (int c = 0; c < 3; c++)
                dst[3 * x + c] = ps_tonemap_8bit(src[c], 1.0f);
        }
    }
    ps_image_destroy(&fc);
    ps_gl_show_rgb8(a->width, a->height, a->rgb);
    return PS_OK;
}

/* Illuminance in false colour on or off (key F): the session draws white
 * Lambertian surfaces at exposure 1, the renderer follows. */
static void set_false_color(app *a, bool on)
{
    ps_error err;
    if (on && !ps_session_get_settings(a->session)->float_buffer) {
        /* 8-bit layers would clip the irradiance (E / pi at exposure 1). */
        say(a, "false colour needs float layers (--color-depth float, the default)");
        return;
    }
    if (ps_session_set_illuminance(a->session, on, &err) != PS_OK) {
        say(a, err.msg);
        return;
    }
    ps_gl_renderer_set_materials(a->gl, ps_session_materials(a->session), on);
    ps_gl_renderer_set_kernel(a->gl, ps_session_kernel(a->session));
    a->false_color = on;
    a->redraw = true;
}

/* One refresh: the session's splats drawn into the layers (a new view first
 * when it asks), the composite shown by GL, the overlay. */
static ps_status refresh(app *a, ps_error *err)
{
    double t0 = ps_now_seconds();
    ps_camera_frame cam = camera_frame(a);
    ps_status st = ps_session_refresh(a->session, &cam, &a->frame, err);
    if (st == PS_OK && a->frame.lights_changed) {
        ps_gl_scene gs = ps_gl_scene_of(a->session);
        st = ps_gl_renderer_set_scene(a->gl, &gs, err);
    }
    if (st != PS_OK)
        return st;
    double t_spec = ps_now_seconds();
    ps_latency_add(&a->lat, PS_LAT_SESSION, t_spec - t0);
    /* The specular layer's cube faces, as its time budget allows, before
     * the view (gl_specular.h); not counted in the splats' drawing time. */
    ps_gl_clear_shadow_timing(a->gl);
    st = ps_gl_specular_refresh(a->spec, a->gl, a->session, &a->frame, PS_GL_SPECULAR_FACES_PER_REFRESH, err);
    if (st != PS_OK)
        return st;
    double t_draw = ps_now_seconds();
    ps_gl_stats gst = ps_gl_get_stats(a->gl);
    ps_latency_add(&a->lat, PS_LAT_SPECULAR, t_draw - t_spec - gst.shadow_seconds_last);
    ps_latency_add(&a->lat, PS_LAT_SHADOWS, gst.shadow_seconds_last);
    ps_latency_add_faces(&a->lat, gst.shadow_faces_last);
    ps_gl_clear_shadow_timing(a->gl);
    ps_gl_layers_draw(a->layers, a->gl, &cam, &a->frame);
    /* The direct light's textures just laid: the same view's direct layer
     * from them (a new view or new lights drew it already). */
    if (a->relight && !a->frame.new_view && !a->frame.lights_changed)
        ps_gl_layers_relight(a->layers, a->gl, a->frame.view.width > 0 ? &a->frame.view : &cam,
                             a->frame.direct_exposure, a->frame.direct);
    a->relight = false;
    if (a->frame.splats > 0)
        ps_gl_finish();
    double draw_seconds = ps_now_seconds() - t_draw;
    gst = ps_gl_get_stats(a->gl);
    ps_latency_add(&a->lat, PS_LAT_SHADOWS, gst.shadow_seconds_last);
    ps_latency_add_faces(&a->lat, gst.shadow_faces_last);
    ps_latency_add(&a->lat, PS_LAT_DRAW, draw_seconds - gst.shadow_seconds_last);
    double t_layer = ps_now_seconds();
    if ((st = ps_gl_specular_layer(a->spec, a->layers, a->gl, a->session, &a->frame, err)) != PS_OK)
        return st;
    ps_latency_add(&a->lat, PS_LAT_SHOW, ps_now_seconds() - t_layer);
    double gains[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++)
        gains[k] = a->frame.map[k].gain;
    double t_show = ps_now_seconds();
    if (a->false_color) {
        if ((st = show_false_color(a, gains, err)) != PS_OK)
            return st;
    } else if (a->o.composite)
        ps_gl_layers_show(a->layers, a->frame.direct_gain, gains);
    else if ((st = ps_gl_layers_show_by_cpu(a->layers, a->frame.direct_gain, gains, err)) != PS_OK)
        return st;
    ps_gl_finish();
    ps_latency_add(&a->lat, PS_LAT_SHOW, ps_now_seconds() - t_show);
    a->show_sum += ps_now_seconds() - t_show;
    a->show_count++;
    draw_overlay(a);
    /* Only now: a feed held for the first refresh (session.h) goes on once
     * the whole refresh is done, so that the refresh had every core. */
    ps_session_drawn(a->session, draw_seconds);
    a->redraw = false;
    double t1 = ps_now_seconds();
    a->frame_seconds = t1 - t0;
    if (a->frames > 0 && t1 > a->last_refresh)
        a->fps += FPS_SMOOTHING * (1.0 / (t1 - a->last_refresh) - a->fps);
    a->last_refresh = t1;
    if (a->frames++ == 0) {
        a->t_first_frame = t1;
        a->first_frame_seconds = t1 - a->start_time;
    } else if (a->awaiting_edit_frame) {
        ps_latency_commit(&a->lat, t1, a->frame.edit_lod);
    } else if (!a->frame.moving) {
        ps_latency_full(&a->lat, t1);
    }
    a->awaiting_edit_frame = false;
    if (a->frame.moving && !a->frame.edit_lod) {
        a->moving_frames++;
        a->moving_seconds += t1 - t0;
        a->moving_end = t1;
        a->full_pending = true;
    } else if (a->full_pending && ps_session_settled(a->session)) {
        a->full_after_stop = t1 - a->moving_end;
        a->full_after_step = t1 - a->camera_step;
        a->full_pending = false;
    }
    return PS_OK;
}

/* The window as shown (before the swap), as a PNG: the 8-bit codes decoded
 * to linear and written through the same encoder, which gives them back.
 * `tell`: say so in the overlay (a key's screenshot; a script's stays quiet,
 * so that the next screenshot does not show the message). */
static ps_status screenshot(app *a, const char *path, bool tell, ps_error *err)
{
    ps_image img;
    ps_status st = ps_platform_read(a->platform, &img, err);
    if (st == PS_OK)
        st = ps_png_write(&img, path, 1.0f, err);
    ps_image_destroy(&img);
    if (st == PS_OK && tell) {
        char text[PS_ERROR_MSG_MAX];
        snprintf(text, sizeof text, "saved %s", path);
        say(a, text);
    }
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
    a->redraw = true;
    a->camera_step = ps_now_seconds();
}

static void pan(app *a, double dx, double dy)
{
    ps_camera_frame f = camera_frame(a);
    double dist = ps_v3_len(ps_v3_sub(a->camera.target, a->camera.eye));
    ps_vec3 move = ps_v3_add(ps_v3_scale(f.right, -dx * dist * PAN_PER_PIXEL), ps_v3_scale(f.up, dy * dist * PAN_PER_PIXEL));
    a->camera.eye = ps_v3_add(a->camera.eye, move);
    a->camera.target = ps_v3_add(a->camera.target, move);
    a->redraw = true;
    a->camera_step = ps_now_seconds();
}

static void zoom(app *a, double notches)
{
    ps_vec3 v = ps_v3_sub(a->camera.eye, a->camera.target);
    a->camera.eye = ps_v3_add(a->camera.target, ps_v3_scale(v, pow(ZOOM_PER_NOTCH, notches)));
    a->redraw = true;
    a->camera_step = ps_now_seconds();
}

/* ---- editing ----------------------------------------------------------------------- */

/* An edit's outcome: refused ones are said in the overlay. */
static void report(app *a, ps_status st, const ps_error *err)
{
    if (st != PS_OK)
        say(a, err->msg);
}

/* An edit's clock starts before its call, which may wait for the tracing
 * thread's batch in flight (app/latency.h). */
static double edit_begin(app *a)
{
    double t = ps_now_seconds();
    ps_latency_begin(&a->lat, t);
    return t;
}

static void edit_end(app *a, double t) { ps_latency_add(&a->lat, PS_LAT_HOLD, ps_now_seconds() - t); }

/* Moves the selection by d. */
static void move_selection(app *a, ps_vec3 d)
{
    ps_error err;
    size_t n;
    ps_status st = PS_OK;
    double t = edit_begin(a);
    if (a->sel_kind == SEL_LIGHT) {
        const ps_light *L = &ps_scene_lights(ps_session_scene(a->session), &n)[a->sel_index];
        st = ps_session_move_light(a->session, a->sel_index, ps_v3_add(L->position, d), &err);
    } else if (a->sel_kind == SEL_OBJECT) {
        st = ps_session_move_object(a->session, a->sel_index, d, &err);
    }
    edit_end(a, t);
    report(a, st, &err);
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
    const ps_light *lights = ps_scene_lights(ps_session_scene(a->session), &nl);
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
    if (ps_world_intersect(ps_session_world(a->session), ps_camera_ray(&f, x, y), INFINITY, &sp)) {
        a->sel_kind = SEL_OBJECT;
        a->sel_index = sp.object;
        a->drag_anchor = sp.p;
    }
}

static void select_next(app *a, int kind)
{
    size_t n;
    if (kind == SEL_LIGHT)
        (void)ps_scene_lights(ps_session_scene(a->session), &n);
    else
        (void)ps_scene_objects(ps_session_scene(a->session), &n);
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
    const ps_light *L = &ps_scene_lights(ps_session_scene(a->session), &n)[a->sel_index];
    ps_error err;
    double t = edit_begin(a);
    ps_status st = ps_session_set_light_power(a->session, a->sel_index, ps_rgb_scale(L->power, f), &err);
    edit_end(a, t);
    report(a, st, &err);
}

static void step_angle(app *a, double d)
{
    size_t n;
    if (a->sel_kind != SEL_LIGHT)
        return;
    const ps_light *L = &ps_scene_lights(ps_session_scene(a->session), &n)[a->sel_index];
    if (L->type != PS_LIGHT_SPOT)
        return;
    ps_error err;
    double want = fmin(90.0, fmax(KEY_ANGLE_STEP, L->angle_deg + d));
    double t = edit_begin(a);
    ps_status st = ps_session_set_spot_angle(a->session, a->sel_index, want, &err);
    edit_end(a, t);
    report(a, st, &err);
}

/* ---- settings (keys and scripts) --------------------------------------------------- */

static ps_status set_kernel(app *a, ps_kernel k, ps_error *err)
{
    ps_status st = ps_session_set_kernel(a->session, k, err);
    if (st == PS_OK)
        ps_gl_renderer_set_kernel(a->gl, ps_session_kernel(a->session));
    a->redraw = true;
    return st;
}

static void set_layers(app *a, unsigned shown)
{
    ps_session_set_layers(a->session, shown);
    a->redraw = true;
}

static void scale_radii(app *a, double f)
{
    const ps_session_settings *set = ps_session_get_settings(a->session);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_session_set_radius(a->session, (ps_map_kind)k, set->radius[k] * f);
    a->redraw = true;
}

/* ---- input ---------------------------------------------------------------------------- */

static app *app_of(GLFWwindow *w) { return glfwGetWindowUserPointer(w); }

/* A mouse drag of the selection, or a held key's repeats, edit a refresh at a
 * time: their first refreshes keep the budget (session.h). */
static void sync_dragging(app *a)
{
    if (a->session)
        ps_session_set_dragging(a->session, a->drag == DRAG_MOVE || a->key_repeat);
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    app *a = app_of(w);
    a->key_repeat = action == GLFW_REPEAT;
    sync_dragging(a);
    if (action == GLFW_RELEASE)
        return;
    bool shift = (mods & GLFW_MOD_SHIFT) != 0;
    ps_error err;
    const ps_session_settings *set = ps_session_get_settings(a->session);
    double step = KEY_STEP_FRACTION * ps_v3_len(ps_aabb_diag(ps_scene_bounds(ps_session_scene(a->session))));
    ps_camera_frame f = camera_frame(a);
    ps_vec3 up = ps_v3_norm(a->camera.up);
    /* Horizontal steps follow the view: right, and forward flattened. */
    ps_vec3 fwd = ps_v3_sub(f.forward, ps_v3_scale(up, ps_v3_dot(f.forward, up)));
    fwd = ps_v3_len2(fwd) > 1e-12 ? ps_v3_norm(fwd) : f.up;
    ps_vec3 right = ps_v3_norm(ps_v3_cross(fwd, up));
    bool ctrl = (mods & GLFW_MOD_CONTROL) != 0;
    if (ctrl && (key == GLFW_KEY_S || key == GLFW_KEY_Z)) {
        ps_status st = key == GLFW_KEY_S ? ps_work_save(&a->work, ps_session_scene(a->session), &err)
                       : shift           ? ps_work_redo(&a->work, a->session, &err)
                                         : ps_work_undo(&a->work, a->session, &err);
        say(a, st != PS_OK ? err.msg : key == GLFW_KEY_S ? a->work.where : shift ? "redone" : "undone");
        a->redraw = true;
        return;
    }
    if (key != GLFW_KEY_Q)
        a->quit_armed = false;
    switch (key) {
    case GLFW_KEY_Q:
        /* Unsaved edits: the first Q only says so (the autosave holds them anyway). */
        if (a->work.dirty && !a->quit_armed) {
            a->quit_armed = true;
            say(a, "unsaved edits: Q again quits without saving them, Ctrl+S saves");
            a->redraw = true;
        } else {
            a->quit = true;
        }
        break;
    case GLFW_KEY_H: a->help = !a->help, a->redraw = true; break;
    case GLFW_KEY_V: a->overlay = !a->overlay, a->redraw = true; break;
    case GLFW_KEY_F: set_false_color(a, !a->false_color); break;
    case GLFW_KEY_SPACE: ps_session_set_paused(a->session, !ps_session_paused(a->session)); break;
    case GLFW_KEY_S:
        ps_session_set_splat(a->session, (ps_splat_mode)((set->splat + 1) % PS_SPLAT_MODE_COUNT));
        a->redraw = true;
        break;
    case GLFW_KEY_K:
        if (set_kernel(a, (ps_kernel)((set->kernel + 1) % PS_KERNEL_COUNT), &err) != PS_OK)
            say(a, err.msg);
        break;
    case GLFW_KEY_C:
        ps_session_set_precision(a->session, (ps_precision)((set->precision + 1) % PS_PRECISION_COUNT));
        a->redraw = true;
        break;
    case GLFW_KEY_M:
        if (ps_session_set_global_layer(a->session, (ps_global_layer)((set->global_layer + 1) % PS_GLOBAL_LAYER_COUNT),
                                        &err) != PS_OK)
            say(a, err.msg);
        a->redraw = true;
        break;
    case GLFW_KEY_1: set_layers(a, set->layers ^ PS_LAYER_DIRECT); break;
    case GLFW_KEY_2: set_layers(a, set->layers ^ PS_LAYER_CAUSTIC); break;
    case GLFW_KEY_3: set_layers(a, set->layers ^ PS_LAYER_GLOBAL); break;
    case GLFW_KEY_4: set_layers(a, set->layers ^ PS_LAYER_SPECULAR); break;
    case GLFW_KEY_R: scale_radii(a, shift ? 1.0 / KEY_SCALE : KEY_SCALE); break;
    case GLFW_KEY_T: ps_session_set_tau(a->session, fmax(1e-3, set->tau * (shift ? 0.5 : 2.0))); break;
    case GLFW_KEY_E:
        ps_session_set_exposure(a->session, set->exposure * (shift ? 1.0 / KEY_SCALE : KEY_SCALE));
        a->redraw = true;
        break;
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
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    app *a = app_of(w);
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    if (action == GLFW_RELEASE) {
        a->drag = DRAG_NONE;
        sync_dragging(a);
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
        sync_dragging(a);
    }
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    app *a = app_of(w);
    double dx = x - a->drag_x, dy = y - a->drag_y;
    a->cursor_x = x;
    a->cursor_y = y;
    if (a->false_color)
        a->redraw = a->redraw || a->overlay; /* the lux under the cursor */
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

/* An index the scene has, or a located error. */
static ps_status check_index(const app *a, const ps_script_action *act, const char *what, const char *things,
                             size_t n, ps_error *err)
{
    if (act->index < n)
        return PS_OK;
    return ps_error_set(err, PS_ERR_RANGE, "%s:%d: %s %u: the scene has %zu %s", a->o.script, act->line, what,
                        act->index, n, things);
}

static ps_status run_action(app *a, const ps_script_action *act, ps_error *err)
{
    size_t nl, no;
    (void)ps_scene_lights(ps_session_scene(a->session), &nl);
    (void)ps_scene_objects(ps_session_scene(a->session), &no);
    ps_session *s = a->session;
    ps_status st;
    double t;
    switch (act->kind) {
    case PS_SCRIPT_SCREENSHOT:
        return screenshot(a, act->path, false, err);
    case PS_SCRIPT_MOVE_LIGHT:
        if (check_index(a, act, "move light", "lights", nl, err) != PS_OK)
            return err->status;
        t = edit_begin(a);
        st = ps_session_move_light(s, act->index, act->v, err);
        edit_end(a, t);
        return st;
    case PS_SCRIPT_MOVE_OBJECT:
        if (check_index(a, act, "move object", "objects", no, err) != PS_OK)
            return err->status;
        t = edit_begin(a);
        st = ps_session_move_object(s, act->index, act->v, err);
        edit_end(a, t);
        return st;
    case PS_SCRIPT_POWER:
        if (check_index(a, act, "power light", "lights", nl, err) != PS_OK)
            return err->status;
        t = edit_begin(a);
        st = ps_session_set_light_power(s, act->index, act->power, err);
        edit_end(a, t);
        return st;
    case PS_SCRIPT_ANGLE:
        if (check_index(a, act, "angle light", "lights", nl, err) != PS_OK)
            return err->status;
        t = edit_begin(a);
        st = ps_session_set_spot_angle(s, act->index, act->number, err);
        edit_end(a, t);
        return st;
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
    case PS_SCRIPT_DUMP_PHOTONS: {
        const ps_photon_map *maps = ps_session_lock_maps(s);
        st = ps_write_photon_dump(act->path, maps, err);
        ps_session_unlock_maps(s);
        return st;
    }
    case PS_SCRIPT_SAVE_SCENE:
        return ps_scene_write(ps_session_scene(s), act->path, err);
    case PS_SCRIPT_SET:
        a->redraw = true;
        switch (act->setting) {
        case PS_SET_SPLAT: ps_session_set_splat(s, (ps_splat_mode)act->choice); return PS_OK;
        case PS_SET_LAYERS: set_layers(a, act->layers); return PS_OK;
        case PS_SET_KERNEL: return set_kernel(a, (ps_kernel)act->choice, err);
        case PS_SET_RADIUS:
            ps_session_set_radius(s, PS_MAP_CAUSTIC, act->number);
            ps_session_set_radius(s, PS_MAP_GLOBAL, act->number2);
            return PS_OK;
        case PS_SET_TAU: ps_session_set_tau(s, act->number); return PS_OK;
        case PS_SET_PRECISION: ps_session_set_precision(s, (ps_precision)act->choice); return PS_OK;
        case PS_SET_EXPOSURE: ps_session_set_exposure(s, act->number); return PS_OK;
        case PS_SET_PAUSE: ps_session_set_paused(s, act->choice != 0); return PS_OK;
        case PS_SET_FALSE_COLOR: set_false_color(a, act->choice != 0); return PS_OK;
        case PS_SET_GLOBAL_LAYER: return ps_session_set_global_layer(s, (ps_global_layer)act->choice, err);
        }
        return PS_OK;
    }
    return PS_OK;
}

/* Whether a script's wait done is over: everything shown (session.h), and
 * nothing the window itself has still to redraw. */
static bool script_wait_over(app *a)
{
    /* The direct light's textures laid and shown too (where the direct
     * layer shows: else its shadow maps are never made, and nothing is
     * laid), so that what the picture is then does not depend on when they
     * were. */
    return !a->redraw && ps_session_settled(a->session) && ps_gl_specular_done(a->spec, a->session) &&
           !(a->frame.direct && ps_gl_direct_bake_pending(a->gl, a->frame.direct_exposure));
}

/* ---- the session ---------------------------------------------------------------------- */

static ps_status open_window(app *a, ps_error *err)
{
    char title[512];
    snprintf(title, sizeof title, "photosplat - %s", a->o.c.scene);
    ps_platform_config pc = {a->width, a->height, false, title};
    ps_status st = ps_platform_open(&pc, &a->platform, err);
    if (st != PS_OK) {
        char why[PS_ERROR_MSG_MAX];
        snprintf(why, sizeof why, "%s", err->msg);
        return ps_error_set(err, st, "photosplat: %s", why);
    }
    ps_platform_size(a->platform, &a->width, &a->height);
    a->win = ps_platform_window(a->platform);
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
    a->overlay = a->o.overlay != 0;
    a->start_time = ps_now_seconds();
    ps_status st = open_window(a, err);
    if (st == PS_OK)
        st = open_session(a, err);
    char notice[2 * PS_WORKFILE_PATH_MAX + 128];
    if (st == PS_OK)
        st = ps_work_open(&a->work, a->o.c.scene, ps_session_scene(a->session), notice, sizeof notice, err);
    a->work.autosave_off = a->o.autosave == 0;
    if (st == PS_OK && notice[0]) {
        fprintf(stderr, "photosplat: %s\n", notice);
        say(a, notice);
    }
    a->edit_time = ps_now_seconds();
    a->awaiting_edit_frame = true;
    a->redraw = true;
    double next = 0.0;
    while (st == PS_OK && !a->quit && !glfwWindowShouldClose(a->win)) {
        if (ps_cancelled(a->o.cancel)) {
            st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %llu frames", (unsigned long long)a->frames);
            break;
        }
        double now = ps_now_seconds();
        /* Asleep until the next refresh, an input event, or the script's
         * next action (a scripted camera step every 0.05 s is due then, not
         * at the next tau). */
        double wake = next;
        if (a->script && a->frames > 0 && !a->script_waiting && a->script_next < ps_script_count(a->script))
            wake = fmin(wake, a->t_first_frame + a->script_delay + ps_script_at(a->script, a->script_next)->time);
        if (a->work.pending)
            wake = fmin(wake, a->work.due);
        bool idle = now < wake && !a->redraw && !ps_session_edited(a->session);
        /* While waiting, work done ahead a little at a time, events polled
         * between: the still view's first work while the camera may have
         * stopped (session.h), and the direct light's textures once the
         * lights hold (gl_render.h); not while photons are traced. */
        unsigned bakes = ps_gl_get_stats(a->gl).direct_bakes;
        bool worked = idle && ((a->frames > 0 && !a->warmed_up && warm_up_show(a)) ||
                               ps_session_prepare_still(a->session, PS_SESSION_PREPARE_VERTICES) ||
                               (a->frames > 0 && a->frame.direct && !ps_session_tracing(a->session) &&
                                ps_gl_direct_bake_lay(a->gl, a->frame.direct_exposure, PS_GL_DIRECT_BAKE_STEP_SECONDS)));
        if (ps_gl_get_stats(a->gl).direct_bakes != bakes)
            a->relight = a->redraw = true; /* the view's direct layer from them at once */
        if (idle && !worked && ps_now_seconds() < wake)
            glfwWaitEventsTimeout(wake - ps_now_seconds());
        else
            glfwPollEvents();
        /* Script actions that are due, in order; times count from the first frame. */
        while (st == PS_OK && a->script && a->frames > 0 && a->script_next < ps_script_count(a->script)) {
            const ps_script_action *act = ps_script_at(a->script, a->script_next);
            if (a->script_waiting) {
                if (!script_wait_over(a))
                    break;
                a->script_waiting = false;
                a->script_delay = ps_now_seconds() - a->t_first_frame - a->wait_time;
            }
            if (act->time + a->script_delay > ps_now_seconds() - a->t_first_frame)
                break;
            a->script_next++;
            if (act->kind == PS_SCRIPT_SCREENSHOT) /* the window as it is now: refresh first */
                st = refresh(a, err);
            if (st == PS_OK)
                st = run_action(a, act, err);
        }
        if (st != PS_OK || a->quit)
            break;
        if (ps_session_edited(a->session)) {
            /* The maps keep what the edits cannot change and retrace the rest
             * (preview/repair.h); the first refresh follows at once. Edits
             * that came since the last refresh (a drag's mouse events) are
             * applied together. The latency counts the repair. */
            a->edit_time = ps_now_seconds();
            ps_latency_begin(&a->lat, a->edit_time); /* an undo's, a drag's: from here */
            ps_work_before_update(&a->work, ps_session_scene(a->session));
            st = apply_edits(a, err);
            ps_latency_add(&a->lat, PS_LAT_UPDATE, ps_now_seconds() - a->edit_time);
            if (st == PS_OK)
                st = ps_work_after_update(&a->work, ps_session_scene(a->session), ps_now_seconds(), err);
            a->awaiting_edit_frame = true;
            next = 0.0;
            if (st != PS_OK)
                break;
        }
        now = ps_now_seconds();
        ps_error save_err;
        if (ps_work_tick(&a->work, ps_session_scene(a->session), now, &save_err) != PS_OK)
            say(a, save_err.msg);
        if (now >= next || a->redraw || a->shot_path[0]) {
            st = refresh(a, err);
            if (st == PS_OK && a->shot_path[0]) {
                ps_error shot_err;
                if (screenshot(a, a->shot_path, true, &shot_err) != PS_OK)
                    say(a, shot_err.msg);
                a->shot_path[0] = '\0';
            }
            if (st == PS_OK)
                ps_platform_present(a->platform);
            /* An edit's level of detail shown: its full view at once. The
             * view drawn again after the camera stopped, nothing traced
             * meanwhile: refresh after refresh, events polled between them
             * (waiting for tau between them, the full picture came 1.12-1.46 s
             * after an orbit over 1.25*10^6 photons stopped; without, 0.85-
             * 0.95 s: scripts/bench-window.sh orbit). */
            next = a->frame.edit_lod || ps_session_catching_up(a->session)
                       ? 0.0
                       : ps_session_next_refresh(a->session, now);
        }
    }
    if (st == PS_OK && a->session)
        st = ps_session_status(a->session, err);
    /* Quitting, interrupted or failed: the last edits into the autosave. */
    ps_error save_err;
    if (a->session && ps_work_flush(&a->work, ps_session_scene(a->session), &save_err) != PS_OK)
        fprintf(stderr, "photosplat: %s\n", save_err.msg);
    ps_work_close(&a->work);
    return st;
}

static ps_status write_stats(app *a, ps_error *err)
{
    ps_run_stats rs;
    memset(&rs, 0, sizeof rs);
    ps_session_counts counts;
    memset(&counts, 0, sizeof counts);
    const ps_session_settings *set = NULL;
    if (a->session) {
        ps_session_get_counts(a->session, &counts);
        set = ps_session_get_settings(a->session);
        rs.skips = ps_tracer_skips(ps_session_tracer(a->session), &rs.skip_count);
    }
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        rs.emitted[k] = counts.map[k].emitted;
        rs.stored[k] = counts.map[k].stored;
        rs.rays += counts.map[k].rays;
    }
    double elapsed = ps_now_seconds() - a->edit_time;
    rs.trace_seconds = elapsed;
    rs.frames = a->frames;
    ps_stats_add(&rs, "width", a->width);
    ps_stats_add(&rs, "height", a->height);
    ps_stats_add(&rs, "fps", a->fps);
    ps_stats_add(&rs, "frame_seconds", a->frame_seconds);
    ps_stats_add(&rs, "first_frame_seconds", a->first_frame_seconds);
    ps_stats_add(&rs, "edits", a->session ? (double)ps_session_edits(a->session) : 0.0);
    ps_latency_stats(&a->lat, &rs);
    ps_stats_add(&rs, "tau", set ? set->tau : a->o.p.tau);
    ps_stats_add(&rs, "moving_frames", (double)a->moving_frames);
    ps_stats_add(&rs, "moving_frame_seconds_mean", a->moving_frames ? a->moving_seconds / (double)a->moving_frames : 0.0);
    ps_stats_add(&rs, "full_after_stop_seconds", a->full_after_stop);
    ps_stats_add(&rs, "full_after_step_seconds", a->full_after_step);
    ps_stats_add(&rs, "direct_light_bakes", a->gl ? (double)ps_gl_get_stats(a->gl).direct_bakes : 0.0);
    size_t baked_texels = 0;
    for (int k = 0; k < PS_MAP_COUNT && a->session; k++) {
        size_t texels;
        ps_session_baked(a->session, (ps_map_kind)k, &texels);
        baked_texels += texels;
    }
    ps_stats_add(&rs, "baked_texels", (double)baked_texels);
    ps_stats_add(&rs, "composite_seconds_mean", a->show_count ? a->show_sum / (double)a->show_count : 0.0);
    ps_stats_add(&rs, "counter_stopped", a->session && ps_session_counter_stopped(a->session, NULL) ? 1.0 : 0.0);
    ps_stats_add(&rs, "caustic_cap", set ? (double)set->caps[PS_MAP_CAUSTIC] : 0.0);
    ps_stats_add(&rs, "global_cap", set ? (double)set->caps[PS_MAP_GLOBAL] : 0.0);
    ps_stats_add(&rs, "cap_reached", counts.ended && !counts.store_limited ? 1.0 : 0.0);
    ps_stats_add(&rs, "photon_map_bytes", counts.map_bytes);
    ps_stats_add(&rs, "max_photons", (double)a->o.max_photons);
    ps_stats_add(&rs, "max_photons_reached", counts.store_limited ? 1.0 : 0.0);
    ps_stats_add(&rs, "luminous_flux_lm", ps_scene_total_lumens(a->scene));
    return ps_stats_write(a->o.c.stats, &rs, err);
}

int main(int argc, char **argv)
{
    static app a; /* large, and the callbacks reach it through the window */
    ps_memory_set_drawing_policy(); /* flat memory, llvmpipe's bins kept (core/memory.h) */
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
        if (act->kind == PS_SCRIPT_SCREENSHOT && ps_script_path_is_radiance(act->path))
            st = ps_error_at(&err, PS_ERR_PARSE, a.o.script, act->line,
                             "screenshot %s: the window shows 8-bit codes and writes PNG (linear radiance, .pfm "
                             "or .exr: photosplat-snap --script)",
                             act->path);
        else if (act->path)
            st = ps_check_output_path(act->path, &err);
    }
    if (st == PS_OK)
        st = ps_scene_load(a.o.c.scene, NULL, &a.scene, &err);
    if (st == PS_OK) {
        const ps_scene_defaults *def = ps_scene_get_defaults(a.scene);
        uint64_t photons =
            ps_shared_photons(&a.o.c, def, PS_MAP_CAUSTIC) + ps_shared_photons(&a.o.c, def, PS_MAP_GLOBAL);
        int w = a.o.c.width ? a.o.c.width : def->width, h = a.o.c.height ? a.o.c.height : def->height;
        /* With the specular layer's cube maps, levels and texture (at most). */
        st = ps_check_run_memory_extra("photosplat", photons, PS_PREVIEW_PHOTON_BYTES, w, h, WIN_PIXEL_BYTES,
                                       ps_specular_plan_bytes(PS_GL_SPECULAR_CUBE_SIZE, w, h), &err);
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
    uint64_t edits = a.session ? ps_session_edits(a.session) : 0;
    ps_session_destroy(a.session);
    ps_gl_specular_destroy(a.spec);
    ps_gl_layers_destroy(a.layers);
    ps_gl_renderer_destroy(a.gl);
    ps_platform_close(a.platform);
    free(a.lux);
    free(a.rgb);
    ps_script_destroy(a.script);
    ps_scene_destroy(a.scene);
    if (st == PS_OK)
        printf("photosplat: %llu frames, %llu edits\n", (unsigned long long)a.frames, (unsigned long long)edits);
    if (st == PS_ERR_INTERRUPTED) { /* screenshots already taken stay; the stats are not written */
        fprintf(stderr, "photosplat: %s\n", err.msg);
        return ps_interrupt_exit_status();
    }
    return st == PS_OK ? PS_EXIT_OK : ps_cli_fail(&err);
}
