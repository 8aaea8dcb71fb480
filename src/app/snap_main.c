/* snap_main.c: photosplat-snap, the preview headless: a preview session
 * (src/preview/session.h) drawn by src/gl into an OSMesa buffer (never
 * libGL, src/gl/platform_osmesa.c), one snapshot written as PNG and/or PFM.
 * The same frame the window shows, for tests and benchmarks. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app/cli.h"
#include "app/interrupt.h"
#include "app/latency.h"
#include "app/options.h"
#include "app/pace.h"
#include "app/stats.h"
#include "core/fileio.h"
#include "core/memory.h"
#include "gl/gl_render.h"
#include "gl/gl_specular.h"
#include "image/exr_io.h"
#include "gl/platform.h"
#include "preview/script.h"
#include "preview/session.h"
#include "scene/scene.h"


static const char usage[] =
    "usage: photosplat-snap SCENE.scn -o OUT.png [options]\n"
    "\n"
    "The interactive preview, headless (OSMesa): traces photons, draws the scene\n"
    "with OpenGL lights and the photons as splats, and writes one snapshot.\n"
    "Without --time it traces the maps' full photon counts and draws once; with\n"
    "--time it refines progressively, refreshing every --tau seconds.\n"
    "\n"
    "options:\n"
    "  -o FILE.png              8-bit PNG, sRGB after exposure\n"
    "  --hdr FILE.pfm           linear radiance (W sr^-1 m^-2), little-endian PFM (.exr: OpenEXR)\n"
    "  --illuminance FILE.pfm   one-channel PFM (or .exr) of the illuminance in lux falling on\n"
    "                           the surface each pixel sees, whatever its albedo (--layers apply)\n"
    "  --false-color FILE.png   the same as a false-colour picture with a labelled lux legend\n"
    "  --size WxH               image size (default from the scene)\n"
    "  --exposure E             radiance multiplier before encoding (default 1)\n"
    "  --caustic-photons N      caustic photons (the cap, in progressive mode)\n"
    "  --global-photons N       global photons (the cap, in progressive mode)\n"
    "  --caustic-radius R       caustic splat radius, scene units\n"
    "  --global-radius R        global splat radius, scene units\n"
    "  --seed S                 photon i depends only on (scene, seed, i) (default 0)\n"
    "  --threads N              tracing threads (default: all cores; float layers\n"
    "                           refining (--time, --script): all but one, left to drawing)\n"
    "  --stats FILE.json        figures of the run\n"
    "  --dump-photons FILE      every stored photon: map x y z r g b dx dy dz nx ny nz\n"
    "  --time SECONDS           progressive mode: trace and refine this long\n"
    "  --tau SECONDS            time between refreshes (default 0.1)\n"
    "  --splat points|triangles|sprites  splat primitive (default triangles)\n"
    "  --kernel box|cone|gauss|epanechnikov  splat kernel (default cone)\n"
    "  --layers LIST            comma list of direct,caustic,global,specular (default all)\n"
    "  --color-depth 8|float    colour buffer precision (default 8)\n"
    "  --precision none|diffusion|counter  8-bit handling (default diffusion)\n"
    "  --counter-threshold F    counter: stop when this fraction rounds away (default 0.1)\n"
    "  --point-size N           points: side in pixels (default 1)\n"
    "  --shadows on|off         shadow maps for the direct layer (default on)\n"
    "  --stencil-clip on|off    clip each object's splats to its pixels (default on)\n"
    "  --radius-schedule fixed|progressive  splat radius as photons arrive: fixed, or\n"
    "                           r^2 ~ n^(alpha-1), the given radius holding at the\n"
    "                           scene's photon count (default fixed)\n"
    "  --radius-alpha A         the progressive schedule's alpha in (0, 1] (default 2/3)\n"
    "  --global-layer splats|maps  the global map as splats, or as illumination maps\n"
    "                           on the surfaces (glossy lobes still splatted) (default splats)\n"
    "  --bake on|off            float layers: once a map is traced to its end and its\n"
    "                           photons all lie on diffuse quads, lay its splats into\n"
    "                           textures on them, drawn for each later view (default off)\n"
    "  --hdr-layers PREFIX      also each layer alone, linear: PREFIX-direct.pfm,\n"
    "                           PREFIX-caustic.pfm, PREFIX-global.pfm, PREFIX-specular.pfm\n"
    "  --checkpoints T1,T2,...  progressive mode: at each of these seconds, write the\n"
    "                           picture and its layers as --checkpoint-prefix P:\n"
    "                           P-I.pfm, P-I-direct.pfm ... and a row of P.csv\n"
    "                           (the writing is not counted in the seconds)\n"
    "  --checkpoint-prefix P    where checkpoints go (needed with --checkpoints)\n"
    "  --script FILE            a headless session: the window's script actions (see the\n"
    "                           README) on snap's own clock, progressive; the snapshot\n"
    "                           is written when the script ends (quit, or its last action)\n"
    "  --repair on|off          a script's edits keep the photons they cannot change\n"
    "                           (default on; off: every edit restarts both maps)\n"
    "  --help                   this text\n";

/* Progressive float refreshes may give this share of tau to new splats:
 * snap shows nothing between them (the window leaves room to show). */
#define SNAP_SPLAT_SHARE 0.9
/* --time in float layers: the tracer waits while a map holds more photons
 * not drawn than this many refreshes draw. Tracing ran 2-3 times ahead of
 * the drawing it shared the cores with: the default box's 2 s checkpoint
 * showed 65 536 caustic photons of 1.8 million traced and its 5 s one
 * 0.6 million (the rest drawn after --time, which ended at 10 s for 5);
 * waiting, 0.36 and 1.6 million, ended at 6 s (2, 4 and 8 refreshes alike;
 * 8 bits redraw whatever is there). */
#define SNAP_BACKLOG_REFRESHES 4.0
/* --time in float layers: while a refresh would find nothing new (the last
 * one drew no splat and no cube face, and no photon came since), snap looks
 * for the tracer's next batch this often instead of refreshing, until a
 * checkpoint or tau's schedule is due. Refreshed at once, the ring's
 * triangles drew nothing in 1 134 of the 1 141 refreshes of a 0.25 s run,
 * the default box's triangles in 2 569 of 2 594 of a 2 s run: the drawing
 * thread busy 4-17 ms a run for nothing (await_photons). */
#define SNAP_AWAIT_POLL 0.5e-3

/* --time in 8 bits: of the time left once every checkpoint is shown, the
 * most the redraw that teaches the last picture's cost (probe_redraw) is
 * foreseen to take, from a first frame that foresees it 2-3x long (5 us a
 * photon under the sanitizers against 1.9). */
#define SNAP_PROBE_SHARE 0.25
/* ... and the fewest photons it draws to be worth it: a photon costs 1.5-
 * 2.6 us in the first frame's 2-7*10^4, 1.7-2.1 in 0.2*10^6, 1.2-1.4 in
 * 0.3-0.5*10^6, 0.9-1.1 in the last picture's 2-7*10^6 (pace.h). Smaller,
 * it would foresee no better than the first frame. */
#define SNAP_PROBE_MIN 3e5
/* ... and the most: a photon costs little less in larger ones, which hold
 * the tracer and an interrupt longer (at --time 60, 3*10^6 photons, 3 s). */
#define SNAP_PROBE_MOST 1e6

/* Enough checkpoints for a log-spaced curve from milliseconds to hours. */
#define SNAP_MAX_CHECKPOINTS 64

typedef struct snap_options {
    ps_shared_options c;
    ps_preview_options p;
    double time; /* 0: trace the photon counts and draw once */
    const char *hdr_layers;
    const char *out_lux, *out_false; /* --illuminance, --false-color */
    const char *checkpoint_prefix;
    double checkpoints[SNAP_MAX_CHECKPOINTS]; /* ascending */
    int checkpoint_count;
    const ps_cancel_flag *cancel; /* raised by SIGINT or SIGTERM */
    const char *script_path;      /* --script */
    int no_repair;                /* --repair off: a script's edits restart the maps */
    ps_script *script;
} snap_options;

/* The memory plan (ps_check_run_memory): a pixel, besides the colour buffer,
 * is OSMesa's 24-bit depth + 8-bit stencil, the float read-back and the image. */
#define SNAP_PIXEL_BYTES (4 + 2 * 3 * sizeof(float))

static ps_status parse_args(int argc, char **argv, snap_options *o, bool *help, ps_error *err)
{
    ps_cli cli = ps_cli_begin("photosplat-snap", argc, argv);
    memset(o, 0, sizeof *o);
    ps_shared_options_init(&o->c);
    ps_preview_options_init(&o->p, false);
    ps_status st = PS_OK;
    while (st == PS_OK && ps_cli_next(&cli)) {
        if (ps_cli_is(&cli, "--help") || ps_cli_is(&cli, "-h")) {
            *help = true;
            return PS_OK;
        } else if (ps_shared_option(&cli, "photosplat-snap", &o->c, &st, err)) {
            continue;
        } else if (ps_preview_option(&cli, "photosplat-snap", &o->p, &st, err)) {
            continue;
        } else if (ps_cli_is(&cli, "--time")) {
            st = ps_cli_double(&cli, 1e-3, 1e6, &o->time, err);
        } else if (ps_cli_is(&cli, "--illuminance")) {
            st = ps_cli_string(&cli, &o->out_lux, err);
        } else if (ps_cli_is(&cli, "--false-color")) {
            st = ps_cli_string(&cli, &o->out_false, err);
        } else if (ps_cli_is(&cli, "--hdr-layers")) {
            st = ps_cli_string(&cli, &o->hdr_layers, err);
        } else if (ps_cli_is(&cli, "--checkpoint-prefix")) {
            st = ps_cli_string(&cli, &o->checkpoint_prefix, err);
        } else if (ps_cli_is(&cli, "--script")) {
            st = ps_cli_string(&cli, &o->script_path, err);
        } else if (ps_cli_is(&cli, "--repair")) {
            static const char *const on_off[] = {"on", "off", NULL};
            st = ps_cli_choice(&cli, on_off, &o->no_repair, err);
        } else if (ps_cli_is(&cli, "--checkpoints")) {
            st = ps_cli_ascending(&cli, 1e-3, 1e6, o->checkpoints, SNAP_MAX_CHECKPOINTS, &o->checkpoint_count, err);
        } else {
            return ps_cli_unknown(&cli, err);
        }
    }
    if (st != PS_OK)
        return st;
    if (!o->c.scene)
        return ps_error_set(err, PS_ERR_PARSE, "photosplat-snap: no scene given (see --help)");
    if (!o->c.out_png && !o->c.out_hdr && !o->hdr_layers && !o->checkpoint_prefix && !o->out_lux && !o->out_false &&
        !o->script_path && !o->c.dump)
        return ps_error_set(err, PS_ERR_PARSE,
                            "photosplat-snap: nothing to write: give -o FILE.png, --hdr FILE.pfm, --illuminance "
                            "FILE.pfm or --false-color FILE.png");
    if ((o->checkpoint_count > 0) != (o->checkpoint_prefix != NULL))
        return ps_error_set(err, PS_ERR_PARSE, "photosplat-snap: --checkpoints and --checkpoint-prefix go together");
    if (o->checkpoint_count > 0 && o->time < o->checkpoints[o->checkpoint_count - 1])
        return ps_error_set(err, PS_ERR_PARSE, "photosplat-snap: --checkpoints need --time of at least their last, %g s",
                            o->checkpoints[o->checkpoint_count - 1]);
    return PS_OK;
}

/* ---- frames ----------------------------------------------------------------- */

typedef struct snap_run {
    const snap_options *o;
    ps_session *session;
    ps_gl_renderer *gl;
    ps_platform *platform;
    /* Progressive with a float buffer: layers kept between refreshes, each
     * refresh adding only the photons that arrived (session.h, incremental),
     * as the window does. NULL: every refresh draws a whole frame into the
     * colour buffer (8 bits, or a fixed photon count). */
    ps_gl_layers *layers;
    ps_camera_frame cam;
    ps_camera camera;       /* what cam is made of (a script orbits it) */
    ps_session_frame frame; /* the last refresh's */
    ps_gl_specular *spec;   /* the specular layer's cube maps */
    bool all_faces;         /* the next refresh renders every cube face (the last picture) */
    uint64_t frames, splats; /* refreshes; splats drawn in all (layers) */
    /* --script: edits applied, and over them the photon indices the repairs
     * kept and retraced, per map (repair.h). */
    uint64_t updates;
    double draw_seconds;
    ps_latency lat;     /* --script: each edit's first refresh, phase by phase (app/latency.h) */
    bool awaiting_edit; /* the next refresh is the first after an update */
    ps_pace_model pace; /* --checkpoints: the last refresh, to plan the next (app/pace.h) */
    double shown[PS_MAP_COUNT]; /* ... and each map's photons emitted that the last checkpoint showed */
    double shadow_per_light;    /* ... and a virtual light's shadow cube, seconds (0: not timed) */
    bool lights_held;           /* area lights refined in the waits (ps_session_hold_lights) */
    double lit_seconds;         /* the last refresh with new lights, less its cube faces (0: none yet) */
    double view_ahead_seconds;  /* 8 bits: the first view, drawn beside the first round (view_ahead), */
    double view_ahead_shadows;  /* ... and of that, its shadow maps */
    double first_seconds;       /* the first refresh's time without cube faces, as the pace
                                 * learned it (0: not yet): a face never timed is guessed from it */
    bool probed;                /* --time, 8 bits: the last picture's cost learned (probe_redraw) */
    bool drew_nothing;          /* the last refresh drew no splat and no cube face, and took
                                 * under SNAP_AWAIT_POLL */
} snap_run;

/* One refresh: what the session says, drawn into the layers (the new
 * photons) or over the scene into the colour buffer (all of them). */
static ps_status refresh(snap_run *s, ps_error *err)
{
    double t_refresh = ps_now_seconds();
    ps_session_counts before;
    ps_session_get_counts(s->session, &before);
    ps_status st = ps_session_refresh(s->session, &s->cam, &s->frame, err);
    if (st == PS_OK && s->frame.lights_changed) {
        ps_gl_scene gs = ps_gl_scene_of(s->session);
        st = ps_gl_renderer_set_scene(s->gl, &gs, err);
    }
    if (st != PS_OK)
        return st;
    double t0 = ps_now_seconds();
    ps_latency_add(&s->lat, PS_LAT_SESSION, t0 - t_refresh);
    ps_gl_clear_shadow_timing(s->gl);
    /* A few cube faces a refresh while photons arrive (--time; --script
     * with float layers, as the window: none in the first refresh after an
     * edit); all of them for a single frame, for whole refreshes of a
     * script (each a new view, where faces would wait) and for the last
     * picture. */
    int faces = (s->o->time > 0.0 || (s->o->script && s->layers)) && !s->all_faces ? PS_GL_SPECULAR_FACES_PER_REFRESH
                                                                                   : 0;
    unsigned faces_before = ps_gl_specular_faces_rendered(s->spec);
    st = ps_gl_specular_refresh(s->spec, s->gl, s->session, &s->frame, faces, err);
    if (st != PS_OK)
        return st;
    double t_draw = ps_now_seconds(), splat_seconds = 0.0;
    ps_gl_stats gst = ps_gl_get_stats(s->gl);
    ps_latency_add(&s->lat, PS_LAT_SPECULAR, t_draw - t0 - gst.shadow_seconds_last);
    ps_latency_add(&s->lat, PS_LAT_SHADOWS, gst.shadow_seconds_last);
    ps_latency_add_faces(&s->lat, gst.shadow_faces_last);
    double shadows = gst.shadow_seconds_last, faces_seconds = t_draw - t0 - shadows;
    ps_gl_clear_shadow_timing(s->gl);
    if (s->layers) {
        /* The splats' own time, as the window's: the rate the next budget
         * comes from (session.h). With the cube faces and the specular layer
         * in it, the default box's budget stayed at one batch a map while
         * tracing, and its 2 s checkpoint showed 3 % of the photons traced. */
        ps_gl_layers_draw(s->layers, s->gl, &s->cam, &s->frame);
        if (s->frame.splats > 0)
            ps_gl_finish(); /* llvmpipe draws when flushed: time the drawing, not the queueing */
        splat_seconds = ps_now_seconds() - t_draw;
        st = ps_gl_specular_layer(s->spec, s->layers, s->gl, s->session, &s->frame, err);
        if (st != PS_OK)
            return st;
        if (s->frame.specular)
            ps_gl_finish();
    } else {
        ps_gl_draw_frame_timed(s->gl, &s->cam, &s->frame, &splat_seconds);
        if (s->frame.specular)
            ps_gl_specular_draw(s->spec, s->gl, s->session, s->frame.direct_exposure);
        ps_gl_finish();
    }
    double t1 = ps_now_seconds(), spent = t1 - t0;
    /* Nor anything else that takes time (the specular layer's per-pixel
     * paths, a slice of 1 024 of the ring's 1.2-7.4 ms). */
    s->drew_nothing = s->frame.splats == 0 && ps_gl_specular_faces_rendered(s->spec) == faces_before &&
                      t1 - t_refresh < SNAP_AWAIT_POLL;
    gst = ps_gl_get_stats(s->gl);
    /* 8 bits: the first refresh's view, when drawn before it (view_ahead)
     * and not again, counted here as the refresh's own, as every later
     * refresh draws its view: its shadow maps as the shadow maps, the rest
     * as lit passes. */
    bool first = s->frames == 0 && !s->layers && gst.drawn_ahead_last;
    double ahead = first ? s->view_ahead_seconds : 0.0, ahead_shadows = first ? s->view_ahead_shadows : 0.0;
    shadows += gst.shadow_seconds_last + ahead_shadows;
    if (shadows > 0.0 && gst.virtual_lights > 0)
        s->shadow_per_light = shadows / gst.virtual_lights;
    ps_latency_add(&s->lat, PS_LAT_SHADOWS, gst.shadow_seconds_last);
    ps_latency_add_faces(&s->lat, gst.shadow_faces_last);
    ps_latency_add(&s->lat, PS_LAT_DRAW, t1 - t_draw - gst.shadow_seconds_last);
    if (s->awaiting_edit)
        ps_latency_commit(&s->lat, t1, s->frame.edit_lod);
    else if (!s->frame.moving)
        ps_latency_full(&s->lat, t1);
    s->awaiting_edit = false;
    s->splats += s->frame.splats;
    s->draw_seconds += spent;
    s->frames++;
    ps_session_drawn(s->session, s->layers ? splat_seconds : spent);
    /* The pace's model: this refresh less its cube faces and shadow maps
     * (made once for new lights). Incremental refreshes learn nothing from
     * a new view or new lights (the direct layer drawn again, once), unless
     * nothing is known yet; whole ones redraw everything every time. */
    double plain = (t1 - t_refresh) - (t_draw - t0) - gst.shadow_seconds_last;
    ps_session_counts after;
    ps_session_get_counts(s->session, &after);
    double build_seconds = after.splat_seconds - before.splat_seconds;
    /* 8 bits: less the photons' part too, which a whole refresh has whatever
     * its lights (the redraw that teaches the --time stop, probe_redraw, of
     * 10^6 photons, came with new lights, and the area box's last picture
     * was foreseen with those photons four times over: 64^2, --time 10,
     * ended at 5.5 s). */
    if (s->frame.lights_changed || s->frames == 1)
        s->lit_seconds = t1 - t_refresh - faces_seconds - (s->layers ? 0.0 : build_seconds + splat_seconds) + ahead;
    if (!s->layers || s->pace.seconds <= 0.0 || !(s->frame.new_view || s->frame.lights_changed))
    {
        /* Incremental: the next draws up to its budget's share of tau of
         * new splats, whatever this one drew (one after a short refresh,
         * 0.007 s, drew 0.18 s of splats and took the area box's 0.5 s
         * checkpoint to 0.79 s). */
        s->pace.splats = s->layers && !after.ended ? SNAP_SPLAT_SHARE * s->o->p.tau : 0.0;
        /* The layers' drawing less the shadow maps it made, which plain
         * leaves out already: counted from the whole drawing, the first
         * frame's model lost them twice (the default box's six coarse faces,
         * 0.011 s), and its 0.1 s checkpoint's frame, foreseen at 0.013 s,
         * took 0.02-0.027 s and came at 0.11-0.12 s. */
        plain += fmax(0.0, s->pace.splats - fmax(0.0, splat_seconds - gst.shadow_seconds_last));
        /* The first refresh's work done beside the first round is the next
         * refreshes' own: left out, the default box's maps' 0.1 s frame was
         * foreseen at 0.025 s, took 0.032-0.036 s (0.011 s of it their
         * gathering) and came at 0.12 s. */
        if (s->frames == 1)
            plain += after.ahead_seconds + ahead - ahead_shadows;
        ps_pace_learn(&s->pace, fmax(plain, 1e-6), (double)(s->frame.emitted[0] + s->frame.emitted[1]),
                      build_seconds + splat_seconds, !s->layers);
        s->pace.lead = t0 - t_refresh;
    }
    return PS_OK;
}

/* The colour buffer holds radiance times exposure: back to radiance. */
static void to_radiance(const snap_run *s, ps_image *img)
{
    float inv = s->o->c.exposure > 0.0 ? (float)(1.0 / s->o->c.exposure) : 0.0f;
    size_t n = 3 * (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++)
        img->rgb[i] *= inv;
}

/* The picture as shown, radiance times exposure: the layers' composite with
 * the refresh's gains, or the colour buffer. direct, map[]: which layers. */
static ps_status read_picture(snap_run *s, bool direct, const bool map[PS_MAP_COUNT], ps_image *img, ps_error *err)
{
    if (!s->layers)
        return ps_platform_read(s->platform, img, err);
    double gains[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++)
        gains[k] = map[k] ? s->frame.map[k].gain : 0.0;
    return ps_gl_layers_composite(s->layers, direct ? s->frame.direct_gain : 0.0, gains, img, err);
}

static const bool every_map[PS_MAP_COUNT] = {true, true};

/* After a layer alone was drawn into the colour buffer: the whole frame
 * again (the layers' composite is read without drawing anything). */
static void redraw_frame(snap_run *s)
{
    if (!s->layers) {
        ps_gl_draw_frame(s->gl, &s->cam, &s->frame);
        if (s->frame.specular)
            ps_gl_specular_draw(s->spec, s->gl, s->session, s->frame.direct_exposure);
    }
}

static ps_status write_radiance(snap_run *s, const char *path, ps_error *err)
{
    ps_image img;
    ps_status st = read_picture(s, true, every_map, &img, err);
    if (st == PS_OK) {
        to_radiance(s, &img);
        st = ps_pfm_write(&img, path, err);
    }
    ps_image_destroy(&img);
    return st;
}

/* Each layer alone, as the last refresh's splats draw it, to
 * PREFIX-NAME.pfm. Leaves the colour buffer holding the last layer: draw the
 * frame again after. */
static ps_status write_layers(snap_run *s, const char *prefix, ps_error *err)
{
    static const char *const names[PS_MAP_COUNT + 1] = {"caustic", "global", "specular"};
    const ps_session_frame *f = &s->frame;
    char path[PATH_MAX];
    ps_status st = PS_OK;
    for (int layer = -1; layer <= PS_MAP_COUNT && st == PS_OK; layer++) {
        /* layer -1: the direct light alone, no splats; PS_MAP_COUNT: the
         * specular layer alone. */
        bool specular = layer == PS_MAP_COUNT;
        if (snprintf(path, sizeof path, "%s-%s.pfm", prefix, layer < 0 ? "direct" : names[layer]) >= (int)sizeof path)
            return ps_error_set(err, PS_ERR_IO, "%s: path too long", prefix);
        ps_image img;
        if (s->layers) {
            bool map[PS_MAP_COUNT] = {layer == 0, layer == 1};
            ps_gl_specular_set_gain(s->spec, s->layers, specular && f->specular ? f->direct_gain : 0.0);
            st = read_picture(s, layer < 0, map, &img, err);
            ps_gl_specular_set_gain(s->spec, s->layers, f->specular ? f->direct_gain : 0.0);
        } else {
            ps_gl_begin_frame(s->gl, &s->cam, f->direct_exposure, layer < 0 && f->direct);
            if (layer == PS_MAP_GLOBAL && !specular)
                ps_gl_draw_illummap(s->gl, f->imap_colors, f->imap_spans, f->imap_span_count);
            if (layer >= 0 && !specular)
                ps_gl_draw_splats(s->gl, f->map[layer].batch, f->splat, f->map[layer].radius, f->point_size);
            if (specular && f->specular)
                ps_gl_specular_draw(s->spec, s->gl, s->session, f->direct_exposure);
            st = ps_platform_read(s->platform, &img, err);
        }
        if (st == PS_OK) {
            to_radiance(s, &img);
            st = ps_pfm_write(&img, path, err);
        }
        ps_image_destroy(&img);
    }
    return st;
}

static ps_status write_outputs(snap_run *s, ps_error *err)
{
    const snap_options *o = s->o;
    ps_image img;
    ps_status st = read_picture(s, true, every_map, &img, err);
    if (st != PS_OK)
        return st;
    /* The buffer holds radiance times exposure: the PNG takes it as it is,
     * the PFM the radiance. */
    if (o->c.out_png)
        st = ps_png_write(&img, o->c.out_png, 1.0f, err);
    if (st == PS_OK && o->c.out_hdr) {
        to_radiance(s, &img);
        st = ps_hdr_write(&img, o->c.out_hdr, err); /* PFM, or OpenEXR for .exr */
    }
    ps_image_destroy(&img);
    if (st == PS_OK && o->hdr_layers)
        st = write_layers(s, o->hdr_layers, err);
    return st;
}

/* --illuminance and --false-color: the same photons drawn once more in the
 * session's illuminance mode (white Lambertian surfaces, exposure 1) into
 * float layers whatever the colour buffer, so that each pixel holds E / pi;
 * then E in lux. Leaves the session and the renderer in that mode. */
static ps_status write_illuminance(snap_run *s, ps_error *err)
{
    const snap_options *o = s->o;
    ps_status st = ps_session_set_illuminance(s->session, true, err);
    if (st != PS_OK)
        return st;
    ps_gl_renderer_set_materials(s->gl, ps_session_materials(s->session), true);
    ps_gl_renderer_set_kernel(s->gl, ps_session_kernel(s->session));
    ps_gl_layers *layers = NULL;
    st = ps_gl_layers_create(s->cam.width, s->cam.height, true, &layers, err);
    ps_session_frame f;
    ps_image irr;
    memset(&irr, 0, sizeof irr);
    /* Incremental sessions draw by batches: all of them before reading. */
    bool first = true;
    while (st == PS_OK && (first || !ps_session_settled(s->session))) {
        first = false;
        st = ps_session_refresh(s->session, &s->cam, &f, err);
        if (st == PS_OK && f.lights_changed) {
            ps_gl_scene gs = ps_gl_scene_of(s->session);
            st = ps_gl_renderer_set_scene(s->gl, &gs, err);
        }
        if (st == PS_OK)
            ps_gl_layers_draw(layers, s->gl, &s->cam, &f);
    }
    if (st == PS_OK) {
        double gains[PS_MAP_COUNT] = {f.map[0].gain, f.map[1].gain};
        st = ps_gl_layers_composite(layers, f.direct_gain, gains, &irr, err);
    }
    if (st == PS_OK) {
        size_t n = 3 * (size_t)irr.width * (size_t)irr.height;
        for (size_t i = 0; i < n; i++)
            irr.rgb[i] *= (float)PS_PI; /* white Lambertian: L = E / pi */
        st = ps_write_illuminance(o->out_lux, o->out_false, &irr, "photosplat-snap", err);
    }
    ps_image_destroy(&irr);
    ps_gl_layers_destroy(layers);
    return st;
}

/* Checkpoints: the pictures of a progressive run at given times, for curves
 * of error against time (photosplat-bench). Their rows are kept until the
 * end, then written as one CSV. */
typedef struct snap_checkpoint_row {
    double requested, seconds, radius[PS_MAP_COUNT], lost_fraction;
    uint64_t emitted[PS_MAP_COUNT];
} snap_checkpoint_row;

static ps_status write_checkpoint(snap_run *s, int i, double seconds, snap_checkpoint_row *row, ps_error *err)
{
    const snap_options *o = s->o;
    char path[PATH_MAX];
    if (snprintf(path, sizeof path, "%s-%d", o->checkpoint_prefix, i) >= (int)sizeof path - 16)
        return ps_error_set(err, PS_ERR_IO, "%s: path too long", o->checkpoint_prefix);
    size_t len = strlen(path);
    snprintf(path + len, sizeof path - len, ".pfm");
    ps_status st = write_radiance(s, path, err);
    path[len] = '\0';
    if (st == PS_OK)
        st = write_layers(s, path, err);
    row->requested = o->checkpoints[i];
    row->seconds = seconds;
    row->lost_fraction = s->frame.round_off;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        row->radius[k] = ps_session_radius(s->session, (ps_map_kind)k);
        row->emitted[k] = s->frame.emitted[k];
    }
    return st;
}

static ps_status write_checkpoint_csv(const snap_options *o, const snap_checkpoint_row *rows, int count, ps_error *err)
{
    char path[PATH_MAX];
    if (snprintf(path, sizeof path, "%s.csv", o->checkpoint_prefix) >= (int)sizeof path)
        return ps_error_set(err, PS_ERR_IO, "%s: path too long", o->checkpoint_prefix);
    ps_outfile *out = ps_outfile_open(path, err);
    if (!out)
        return err->status;
    FILE *fp = ps_outfile_stream(out);
    fprintf(fp, "index,requested_seconds,seconds,caustic_emitted,global_emitted,caustic_radius,global_radius,"
                "round_off_fraction\n");
    for (int i = 0; i < count; i++)
        fprintf(fp, "%d,%.6g,%.6f,%llu,%llu,%.9g,%.9g,%.6g\n", i, rows[i].requested, rows[i].seconds,
                (unsigned long long)rows[i].emitted[0], (unsigned long long)rows[i].emitted[1], rows[i].radius[0],
                rows[i].radius[1], rows[i].lost_fraction);
    return ps_outfile_commit(out, err);
}

static void sleep_until(double until)
{
    double t = ps_now_seconds();
    if (t >= until)
        return;
    struct timespec ts = {(time_t)(until - t), (long)((until - t - (double)(time_t)(until - t)) * 1e9)};
    nanosleep(&ts, NULL);
}

/* The snapshot at the end of a progressive run or a script, after status st
 * of its loop: the feed stopped, everything that arrived drawn once more
 * (layers: the batches not drawn yet, however many refreshes the budget
 * takes), and the area lights with all their virtual lights. */
static ps_status last_picture(snap_run *s, ps_status st, ps_error *err)
{
    ps_status stop = ps_session_stop(s->session, st == PS_OK ? err : NULL);
    if (st == PS_OK)
        st = stop;
    ps_session_full_lights(s->session);
    s->all_faces = true;
    /* Every face from the photons there, as one whole frame draws them
     * (last_picture_seconds foresees them all). */
    ps_gl_specular_redraw_all(s->spec);
    if (st == PS_OK)
        st = refresh(s, err);
    while (st == PS_OK && s->layers && !ps_session_settled(s->session))
        st = refresh(s, err);
    return st;
}

/* --time in 8 bits: the seconds the last picture (last_picture) would take
 * were the tracer stopped with `photons` emitted: a redraw of them all, every
 * cube face, and the area lights' virtual lights still to come (their shadow
 * cubes and lit passes, as the last refresh with new lights took for fewer). */
static double last_picture_seconds(snap_run *s, double photons)
{
    double t = ps_pace_redraw_seconds(&s->pace, photons) + ps_gl_specular_all_seconds(s->spec);
    double lights = ps_session_lights_to_come(s->session);
    return lights > 1.0 ? t + lights * s->lit_seconds : t;
}

/* Photons a second from (t0, p0) to (t1, p1); `otherwise` when that says
 * nothing (no time between, or the counts went back: a new feed). */
static double arrival_rate(double t0, double p0, double t1, double p1, double otherwise)
{
    return t1 > t0 && p1 >= p0 ? (p1 - p0) / (t1 - t0) : otherwise;
}

static double photons_emitted(ps_session *session)
{
    ps_session_counts counts;
    ps_session_get_counts(session, &counts);
    return (double)(counts.map[0].emitted + counts.map[1].emitted);
}

/* Float layers, after a refresh that drew nothing (snap_run.drew_nothing):
 * the next one waits until a photon arrives past those it showed, or
 * `until` (a checkpoint's or tau's time), whichever is first, so that it has
 * something to draw or is the frame that time wants; not while the session
 * has other work for it (new lights: waited for, the design room's refresh
 * that brought its full shadows came at its 0.5 s checkpoint, and showed it
 * at 0.59-0.63 s). */
static void await_photons(snap_run *s, double until)
{
    if (!s->layers || !s->drew_nothing)
        return;
    double shown = (double)(s->frame.emitted[0] + s->frame.emitted[1]);
    for (double now = ps_now_seconds(); now < until && !ps_cancelled(s->o->cancel); now = ps_now_seconds()) {
        if (photons_emitted(s->session) > shown || ps_session_work_pending(s->session))
            return;
        sleep_until(fmin(until, now + SNAP_AWAIT_POLL));
    }
}

/* --time in 8 bits, every checkpoint shown: a whole refresh, not shown,
 * drawing a prefix of the photons that the pace's model says takes
 * SNAP_PROBE_SHARE of the time left, so that time_to_stop foresees the last
 * picture from more than the first frame. That one draws 1.6-6.6*10^4
 * photons, llvmpipe's first compiles in it: 1.2-2.8 us a photon, against
 * 0.4-1.3 us for the last picture's 0.5-7*10^6; foreseen from it, the
 * tracer stopped right after the first frame whatever --time (the default
 * box's --time 10 at 64^2 ended at 2.7 s). Made once the photons are there
 * (s->probed then, or once it would not be worth it); the tracer is held
 * meanwhile, as the last picture has every core (sharing them, a probe of
 * 0.38*10^6 photons cost 1.6 us a photon, the last picture 0.95). */
static ps_status probe_redraw(snap_run *s, double end, ps_error *err)
{
    ps_session_counts counts;
    ps_session_get_counts(s->session, &counts);
    double there = (double)(counts.map[0].emitted + counts.map[1].emitted), left = end - ps_now_seconds();
    double scene = ps_pace_redraw_seconds(&s->pace, 0.0); /* it redraws the scene too */
    double n = s->pace.per_photon > 0.0 ? fmin((SNAP_PROBE_SHARE * left - scene) / s->pace.per_photon, SNAP_PROBE_MOST)
                                        : 0.0;
    if (n < SNAP_PROBE_MIN || n < 2.0 * s->pace.photons) { /* it would teach little more than the model's refresh */
        s->probed = true;
        return PS_OK;
    }
    if (there < n)
        return PS_OK; /* not yet (time_to_stop stops at once if the tracer ends first) */
    s->probed = true;
    double most[PS_MAP_COUNT];
    for (int k = 0; k < PS_MAP_COUNT; k++)
        most[k] = n * (double)counts.map[k].emitted / there;
    ps_session_set_whole_most(s->session, most);
    ps_session_hold(s->session, true);
    ps_session_hold_lights(s->session, true); /* drawn, it asks for no more: lights_to_come stays true */
    ps_status st = refresh(s, err);
    ps_session_hold_lights(s->session, s->lights_held);
    ps_session_hold(s->session, false);
    ps_session_set_whole_most(s->session, NULL);
    return st;
}

/* --time in 8 bits, before a refresh planned to start at `start` drawing at
 * most `most` photons emitted (`start` and `end` on ps_now_seconds' clock):
 * *stop, whether the tracer stops here for the last picture, so that the
 * run ends by --time rather than long after it (false also when interrupted
 * meanwhile), the redraw that teaches that picture's cost (probe_redraw) on
 * the way. The last picture redraws every photon, and the tracer went on to
 * --time: the default box at 256^2, bench's caps and --time 2 ended at
 * 4.6-7.0 s, redrawing 1.4-2.4*10^6 photons. Only once every checkpoint is
 * shown: the last one is most often --time itself (bench's), which keeps
 * its frame, a prefix planned to land on it (stopping for the last
 * picture, every photon redrawn with every virtual light's shadows in every
 * cube face, took the area box 3.6 s, foreseen as less, and showed its 5 s
 * checkpoint at 6.8-7.0 s). Then no
 * more refreshes, which would only be drawn and thrown away (snap is
 * headless) while the tracer shares the cores with them (each redraws
 * everything, as long as the run so far): the tracer traces alone until
 * one more step would leave the last picture ending after --time, or it
 * ends. With the error counter (--precision counter), whose verdict comes
 * from refreshes, they go on while one more still leaves the last picture
 * on time. Not in float, whose tracer has a core of its own and whose last
 * picture draws at most backlog_refreshes' photons besides the cube faces:
 * stopping it so cost 10-50 % of the photons (the default box at --time 2:
 * 0.61-0.62*10^6 against 0.67-0.95*10^6; the ring 0.8-0.9*10^6 against
 * 1.2-1.6*10^6, ending at 1.7 s) to end 0.4-0.7 s sooner. */
static ps_status time_to_stop(snap_run *s, double start, double most, double end, int cp, bool *stop, ps_error *err)
{
    *stop = false;
    if (s->layers || cp < s->o->checkpoint_count || s->frames == 0 || s->pace.seconds <= 0.0)
        return PS_OK;
    const ps_session_settings *set = ps_session_get_settings(s->session);
    double cap = (double)set->caps[0] + (double)set->caps[1]; /* the tracer ends there */
    double now = ps_now_seconds(), photons = photons_emitted(s->session), rate = s->pace.rate;
    if (set->precision == PS_PRECISION_COUNTER) {
        double begin = fmax(now, start);
        double refresh = ps_pace_redraw_seconds(&s->pace, fmin(most, fmin(cap, photons + rate * (begin - now))));
        double after = fmin(cap, photons + rate * (begin + refresh - now)); /* the tracer goes on meanwhile */
        if (begin + refresh + last_picture_seconds(s, after) < end)
            return PS_OK;
    }
    for (;;) {
        if (ps_cancelled(s->o->cancel))
            return PS_OK; /* the loop says so, as for any interrupt */
        ps_session_counts counts;
        ps_session_get_counts(s->session, &counts);
        if (counts.ended || ps_session_counter_stopped(s->session, NULL)) {
            *stop = true;
            return PS_OK;
        }
        if (!s->probed) {
            ps_status st = probe_redraw(s, end, err);
            if (st != PS_OK)
                return st;
            now = ps_now_seconds(), photons = photons_emitted(s->session);
        }
        double step = fmin(s->o->p.tau, 0.5 * (end - now));
        if (now + step + last_picture_seconds(s, fmin(cap, photons + rate * step)) >= end) {
            *stop = true;
            return PS_OK;
        }
        sleep_until(now + step);
        /* Alone, the tracer goes faster than while refreshes shared the cores. */
        double t = ps_now_seconds(), p = photons_emitted(s->session);
        rate = arrival_rate(now, photons, t, p, rate);
        now = t, photons = p;
    }
}

/* The photons' arrival rate for the pace: counted at each plan. */
typedef struct pace_rate {
    double at, photons;
} pace_rate;

/* The pace's arrival rate, from the last count to `photons` at `now`. */
static void measure_rate(snap_run *s, double now, double photons, pace_rate *rate)
{
    s->pace.rate = arrival_rate(rate->at, rate->photons, now, photons, s->pace.rate);
    rate->at = now, rate->photons = photons;
}

/* The next refresh on snap's clock (starting at `clock`), due at `due` by
 * tau's schedule, checkpoints cp on not yet shown (pace.h). */
static ps_pace_plan plan_refresh(snap_run *s, double clock, double due, int cp, pace_rate *rate)
{
    double now = ps_now_seconds() - clock, photons = photons_emitted(s->session);
    measure_rate(s, now, photons, rate);
    /* Float: the first round's faces as a refresh between checkpoints
     * draws them (held only where the plan says, refine). */
    if (s->layers)
        ps_gl_specular_hold_first_round(s->spec, false);
    if (s->first_seconds <= 0.0)
        s->first_seconds = s->pace.seconds;
    ps_gl_specular_set_face_guess(s->spec, PS_PACE_FACE_GUESS * fmax(s->pace.seconds, s->first_seconds));
    s->pace.unheld = ps_gl_specular_unheld_seconds(s->spec, s->session);
    /* A refresh draws no fewer photons than the last checkpoint showed (refine's most[]). */
    s->pace.least = s->shown[0] + s->shown[1];
    ps_pace_plan plan = ps_pace_next(&s->pace, now, photons, due, s->o->checkpoints + cp, s->o->checkpoint_count - cp);
    /* The first picture at once. Float: the tracer is held until it is
     * drawn (refine), so waiting would only idle. 8 bits: waiting for the
     * first checkpoint let the tracer add photons to it, which it then drew
     * whole: the default box's first frame (bench's caps, 256^2) drew
     * 7.7*10^4 splats from 0.05 s and came at 0.34 s; at once, the first
     * round's 1.9*10^4 at 0.27 s. */
    if (s->frames == 0)
        plan.start = now;
    return plan;
}

/* 8 bits, between checkpoints: a whole refresh of one batch, drawn and not
 * shown, the tracer held and no cube faces in it, for what it teaches the
 * pace or brings (an area light's next virtual lights). */
static ps_status unseen_batch(snap_run *s, ps_error *err)
{
    const double one[PS_MAP_COUNT] = {0.0, 0.0};
    ps_session_set_whole_most(s->session, one);
    double now = ps_now_seconds();
    ps_gl_specular_set_deadline(s->spec, now);
    ps_gl_specular_set_paths_deadline(s->spec, now); /* the waits trace them (ps_gl_specular_idle) */
    ps_session_hold(s->session, true);
    ps_status st = refresh(s, err);
    ps_session_hold(s->session, false);
    ps_gl_specular_set_paths_deadline(s->spec, 0.0);
    return st;
}

/* The first 8-bit picture's view, drawn while its photons are traced
 * (ps_session_start_beside): its shadow maps, prepass and lit passes, and
 * llvmpipe's first compiles of them, into the 8-bit buffer, where the first
 * refresh draws its splats over it (float layers: ps_gl_layers_start). */
typedef struct view_ahead_job {
    snap_run *s;
    double exposure; /* the direct layer as the first refresh asks for it */
    bool direct;
} view_ahead_job;

static void view_ahead(void *ctx)
{
    view_ahead_job *j = ctx;
    snap_run *s = j->s;
    /* Finished here, so that its time is its own: the first refresh counts
     * it as its view's (refresh). */
    double t0 = ps_now_seconds();
    ps_gl_clear_shadow_timing(s->gl);
    ps_gl_draw_view_ahead(s->gl, &s->cam, j->exposure, j->direct);
    ps_gl_finish();
    s->view_ahead_seconds = ps_now_seconds() - t0;
    s->view_ahead_shadows = ps_gl_get_stats(s->gl).shadow_seconds_last;
}

/* Progressive: trace in the background, refresh every tau. As in the window,
 * the first round is traced before the first frame, so that it already shows
 * photons. Time spent writing checkpoints is taken off the clock (the tracer
 * is held meanwhile), so they measure the preview, not the bench. */
static ps_status refine(snap_run *s, double t_start, double *first_frame, ps_error *err)
{
    const snap_options *o = s->o;
    snap_checkpoint_row rows[SNAP_MAX_CHECKPOINTS];
    /* Float: the tracer waits until the first picture is drawn, which then
     * has every core (as the window's), and is drawn at once (plan_refresh);
     * 8 bits trace meanwhile, on every core (session.h), for the first frame
     * that shows a checkpoint. (The default box's first float picture: 0.35-
     * 0.36 s; 0.43-0.50 s sharing the cores and waiting for the first
     * checkpoint or tau.) The first view is drawn while the first round is
     * traced: into the float layers, which keep it (ps_gl_layers_start), or
     * into the 8-bit buffer, whose first frame then draws only its splats
     * over it (view_ahead).
     * (Drawn beside the round as well but the frame drawing its view again,
     * the default box's and the design room's first 8-bit checkpoints came
     * 5-7 ms later, medians of eight runs; see docs/preview.md for the
     * figures of the view kept.) */
    ps_status st;
    if (s->layers) {
        st = ps_gl_layers_start(s->layers, s->gl, s->session, &s->cam, err);
    } else {
        view_ahead_job ahead = {s, 1.0, false};
        ps_session_direct_view(s->session, &ahead.exposure, &ahead.direct);
        st = ps_session_start_beside(s->session, false, view_ahead, NULL, &ahead, err);
    }
    double next = t_start + o->p.tau, end = t_start + o->time, excluded = 0.0;
    pace_rate rate = {0.0, 0.0};
    int cp = 0;
    while (st == PS_OK) {
        if (ps_cancelled(o->cancel)) {
            st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %.1f s of %.1f s",
                              ps_now_seconds() - t_start, o->time);
            break;
        }
        /* When to refresh, and how long its cube faces may take, so that
         * the frame each checkpoint shows lands soon after it (pace.h). */
        double clock = t_start + excluded;
        ps_pace_plan plan = plan_refresh(s, clock, fmin(next, end) - clock, cp, &rate);
        /* 8 bits: after the first frame, one batch drawn in the wait and
         * not shown. The first frame's time holds llvmpipe's first compiles
         * and the first specular traces (its scene's part 0.2-0.4 s at 256^2
         * against 0.04-0.06 s after), which left the 1 s checkpoint's frame
         * one batch. Only where it ends before the frame the plan starts
         * (PS_PACE_BATCH_GUESS): started in any wait, it delayed the 0.1 s
         * checkpoints' frames, the default box's to 0.12-0.14 s and the
         * ring's to 0.13-0.15 s. */
        if (!s->layers && s->pace.learned == 1 && cp < o->checkpoint_count &&
            plan.start > ps_now_seconds() - clock + PS_PACE_BATCH_GUESS * s->pace.seconds) {
            st = unseen_batch(s, err);
            if (st != PS_OK)
                break;
            plan = plan_refresh(s, clock, fmin(next, end) - clock, cp, &rate);
        }
        /* The lights' next level (the full shadow maps, an area light's
         * next virtual lights: ps_session_next_level_cost), only when it
         * keeps the next checkpoint on time. 8 bits: when its
         * shadow cubes fit in the wait (from the last level's, a light as
         * long), drawn in a batch not shown; in a checkpoint's frame they
         * made the area box's 1 s checkpoint land at 1.5-2.3 s. New virtual
         * lights only once every mirror's and glass's cube map is shown:
         * they discard the faces of one still being rendered, and with first
         * pictures 0.1 s sooner the area box's 8-bit runs took their lights
         * to 16 before 1 s and showed the mirror black there (specular
         * relMSE 0.145 against 0.006). */
        bool lights_wait =
            ps_session_next_level_lights(s->session) > 1.0 && !ps_gl_specular_all_shown(s->spec, s->session);
        if (s->lights_held && s->shadow_per_light > 0.0 && cp < o->checkpoint_count && !lights_wait) {
            unsigned lights = ps_gl_get_stats(s->gl).virtual_lights;
            double wait = clock + plan.start - ps_now_seconds();
            double cost = ps_session_next_level_cost(s->session), shadows = lights * s->shadow_per_light;
            if (!s->layers && wait > cost * shadows + s->pace.seconds &&
                ps_session_refine_lights(s->session)) {
                st = unseen_batch(s, err);
                if (st != PS_OK)
                    break;
                plan = plan_refresh(s, clock, fmin(next, end) - clock, cp, &rate);
            }
            /* Float: the next refresh draws them when it ends before the
             * next checkpoint, taken as the last refresh with new lights
             * (its cube faces left out), its shadow maps at the level's cost
             * and the rest at its virtual lights' multiple (4x the lights:
             * their shadow cubes and lit passes; the full shadows alone
             * cost their maps, the default box's six faces 0.10 s at
             * 1024^2, not four refreshes). A refresh that took the area box's lights
             * from 4 to 16 ended 0.3-0.4 s after a 0.5 s checkpoint at 64^2;
             * the shadow cubes alone, predicted, left the 1 s one 14-17 % late.
             * Never in the checkpoint's frame: with points, whose first frame
             * was quick, the refinement from 1 to 4 rode in it and its 0.5 s
             * checkpoint landed at 0.69-0.73 s. From the refresh's start, not
             * now, with its budget of new splats besides: taken from now
             * without them, a refresh due 0.1 s later drew the full shadows,
             * about 10^5 splats and cube faces and showed the design room's
             * 0.5 s checkpoint at 0.57-0.63 s, once first pictures came
             * sooner (core/memory.h). */
            double next_lit = ps_session_next_level_lights(s->session) * fmax(0.0, s->lit_seconds - shadows) +
                              cost * shadows;
            double lit_end = fmax(ps_now_seconds(), clock + plan.start) + next_lit + s->pace.splats;
            if (s->layers && !plan.shows && lit_end < clock + o->checkpoints[cp])
                ps_session_refine_lights(s->session);
        }
        /* Every checkpoint shown: the lights grow a level a refresh again. */
        if (s->lights_held && cp >= o->checkpoint_count) {
            ps_session_hold_lights(s->session, false);
            s->lights_held = false;
        }
        /* A refresh that waits for its start leaves that time to the cube
         * faces, which would otherwise ride in the frames (8 bits: the
         * first round's, which no deadline holds back, made the frame of a
         * 2 s checkpoint 0.5 s late), then is planned again with what they
         * left to it. Float too, though its tracer runs meanwhile, until
         * every mirror's and glass's first map is shown. Given every wait,
         * the bench limited to 1 s (three runs each) had the specular layer
         * wholly black at 0.5 s in 11-13 of 48 configurations against 23-28
         * with float's waits idle, the full picture's relMSE 0.88x at 0.5 s
         * and 0.91x at 1 s, for 0.87x the caustic photons at 0.5 s (the
         * picture less its specular layer 1.05x there, 0.99x at 1 s). Given
         * the waits only until the first maps are shown (two runs each,
         * budgets to 2 s): black in 7 and 12 against 15 and 10 with every
         * wait, 1.03-1.05x the photons at 1-2 s; so later rounds keep the
         * budget's share of tau, as the window's. */
        bool faces_wait = !s->layers || !ps_gl_specular_all_shown(s->spec, s->session);
        if (faces_wait && s->frames > 0 && plan.start > ps_now_seconds() - clock) {
            st = ps_gl_specular_idle(s->spec, s->gl, s->session, &s->frame, clock + plan.start, err);
            if (st != PS_OK)
                break;
            plan = plan_refresh(s, clock, fmin(next, end) - clock, cp, &rate);
        }
        bool stop;
        st = time_to_stop(s, clock + plan.start, plan.photons, end, cp, &stop, err);
        if (st != PS_OK || stop)
            break;
        if (ps_cancelled(o->cancel))
            continue; /* interrupted while it waited: said at the loop's top */
        ps_gl_specular_set_deadline(s->spec, isfinite(plan.faces_deadline) ? clock + plan.faces_deadline : 0.0);
        if (s->layers) {
            ps_gl_specular_hold_first_round(s->spec, plan.hold_faces);
            ps_session_set_budget_share(s->session, plan.share);
        }
        sleep_until(clock + plan.start);
        double due = fmin(next, end);
        await_photons(s, cp < o->checkpoint_count ? fmin(clock + o->checkpoints[cp], due) : due);
        /* 8 bits: the checkpoint's frame draws what fits from its start,
         * the photons there then (pace.h). */
        if (!s->layers && plan.shows) {
            double now = ps_now_seconds() - clock, photons = photons_emitted(s->session);
            measure_rate(s, now, photons, &rate);
            plan.photons = ps_pace_photons_at_start(&s->pace, &plan, now, photons, fmin(next, end) - clock,
                                                    o->checkpoints + cp, o->checkpoint_count - cp);
        }
        ps_session_counts counts;
        ps_session_get_counts(s->session, &counts);
        /* A whole refresh showing a checkpoint draws the photons it has time
         * for: a prefix of those there now. */
        double there = (double)(counts.map[0].emitted + counts.map[1].emitted);
        double most[PS_MAP_COUNT];
        for (int k = 0; k < PS_MAP_COUNT; k++) /* each map its part, never fewer than the last checkpoint showed */
            most[k] = there > plan.photons ? fmax(plan.photons * (double)counts.map[k].emitted / there, s->shown[k])
                                           : HUGE_VAL;
        ps_session_set_whole_most(s->session, most);
        /* 8 bits: the tracer waits while a checkpoint's frame is drawn (its
         * photons are those there now), so that llvmpipe has both cores:
         * sharing them, a photon cost 1.2-1.9 us from one frame to the
         * next, alone 0.9-1.5 us, the prediction's error the larger part of
         * a checkpoint's lateness. */
        bool hold = !s->layers && cp < o->checkpoint_count;
        if (hold)
            ps_session_hold(s->session, true);
        /* The eye paths owed while every cube was black, traced in the
         * checkpoint's frame only until PS_PACE_PATHS_LATE after it (the
         * layer black while some are left), the rest in the waits and
         * refreshes after: all of them, in the frame that first showed a
         * cube, took the ring's 8-bit 0.2 s checkpoint to 0.25 s, and with
         * the layer's first drawing the design room's float one to 0.25-
         * 0.29 s. Kept while the checkpoint is written, whose 8-bit layer
         * files draw the specular layer again: as the picture showed it
         * (reset after, the files' picture less its specular layer had
         * relMSE 18-34 where it was black). */
        if (plan.shows)
            ps_gl_specular_set_paths_deadline(s->spec, clock + plan.end_by);
        st = refresh(s, err);
        if (hold)
            ps_session_hold(s->session, false);
        if (st != PS_OK)
            break;
        double now = ps_now_seconds();
        if (*first_frame < 0.0)
            *first_frame = now - t_start;
        /* A whole refresh planned as the checkpoint's frame that ended
         * before it waits for it (pace.h). The tracer goes on meanwhile. */
        if (cp < o->checkpoint_count) {
            double ended = now - t_start - excluded;
            double shown = ps_pace_shown_at(&plan, !s->layers, ended, o->checkpoints[cp]);
            if (shown > ended) {
                sleep_until(t_start + excluded + shown);
                now = ps_now_seconds();
            }
        }
        if (cp < o->checkpoint_count && now - t_start - excluded >= o->checkpoints[cp]) {
            /* This frame is the first done at or after every checkpoint time
             * it passed (or it waited for the one it was planned for): each
             * of them shows it. */
            ps_session_hold(s->session, true);
            for (int k = 0; k < PS_MAP_COUNT; k++)
                s->shown[k] = (double)s->frame.emitted[k];
            double at = now - t_start - excluded;
            for (int first = cp; st == PS_OK && cp < o->checkpoint_count && at >= o->checkpoints[cp]; cp++) {
                if (cp > first) /* the layers of the last one overwrote it */
                    redraw_frame(s);
                st = write_checkpoint(s, cp, at, &rows[cp], err);
            }
            ps_session_hold(s->session, false);
            double spent = ps_now_seconds() - now;
            excluded += spent;
            next += spent;
            end += spent;
            if (st != PS_OK)
                break;
        }
        ps_gl_specular_set_paths_deadline(s->spec, 0.0);
        next = ps_pace_next_due(next, ps_now_seconds(), o->p.tau);
        /* Every photon traced, or the error counter stopped the tracer:
         * checkpoints still to come get their own frames, on time, and the
         * last picture follows. (An 8-bit redraw of them all takes seconds;
         * in float the last picture's every virtual light and cube face
         * did: the area box's 1 s checkpoint, at the scene's counts, came at
         * 2.7 s; the counter stopped before the area box's 5 s checkpoint,
         * the last picture showed it at 9.9 s.) */
        bool done = counts.ended || ps_session_counter_stopped(s->session, NULL);
        if ((done && cp >= o->checkpoint_count) || ps_now_seconds() >= end)
            break;
    }
    ps_gl_specular_set_deadline(s->spec, 0.0);
    ps_gl_specular_set_paths_deadline(s->spec, 0.0);
    ps_session_set_whole_most(s->session, NULL);
    ps_session_set_budget_share(s->session, 1.0); /* the last picture catches up at the whole budget */
    st = last_picture(s, st, err);
    /* Checkpoints after the end (--time spent before their frames) show
     * the final picture, at the time it was done. */
    double done = ps_now_seconds() - t_start - excluded;
    for (; st == PS_OK && cp < o->checkpoint_count; cp++) {
        st = write_checkpoint(s, cp, done, &rows[cp], err);
        if (st == PS_OK)
            redraw_frame(s);
    }
    if (st == PS_OK && o->checkpoint_count > 0)
        st = write_checkpoint_csv(o, rows, o->checkpoint_count, err);
    return st;
}

/* ---- --script: a headless session --------------------------------------------- */

/* Rotates v about unit axis k by angle (Rodrigues). */
static ps_vec3 rotate(ps_vec3 v, ps_vec3 k, double angle)
{
    double c = cos(angle), sn = sin(angle);
    return ps_v3_add(ps_v3_add(ps_v3_scale(v, c), ps_v3_scale(ps_v3_cross(k, v), sn)),
                     ps_v3_scale(k, ps_v3_dot(k, v) * (1.0 - c)));
}

/* The window's turntable orbit (window_main.c): yaw about up, pitch about
 * right, never over the pole. */
static void orbit(snap_run *s, double yaw_deg, double pitch_deg)
{
    ps_camera *cam = &s->camera;
    ps_vec3 up = ps_v3_norm(cam->up);
    ps_vec3 v = rotate(ps_v3_sub(cam->eye, cam->target), up, -yaw_deg * PS_PI / 180.0);
    double r = ps_v3_len(v);
    double elevation = asin(fmax(-1.0, fmin(1.0, ps_v3_dot(v, up) / r))) * 180.0 / PS_PI;
    double want = fmax(-89.0, fmin(89.0, elevation + pitch_deg));
    ps_vec3 right = ps_v3_norm(ps_v3_cross(v, up));
    v = rotate(v, right, -(want - elevation) * PS_PI / 180.0);
    cam->eye = ps_v3_add(cam->target, v);
    s->cam = ps_camera_frame_make(cam, s->cam.width, s->cam.height);
}

/* The maps as they stand, as --dump-photons writes them. */
static ps_status dump_photons(snap_run *s, const char *path, ps_error *err)
{
    const ps_photon_map *maps = ps_session_lock_maps(s->session);
    ps_status st = ps_write_photon_dump(path, maps, err);
    ps_session_unlock_maps(s->session);
    return st;
}

static ps_status script_index(const snap_run *s, const ps_script_action *act, size_t n, const char *things,
                              ps_error *err)
{
    if (act->index < n)
        return PS_OK;
    return ps_error_set(err, PS_ERR_RANGE, "%s:%d: %s %u: the scene has %zu %s", s->o->script_path, act->line,
                        things, act->index, n, things);
}

/* One action, as the window runs it (window_main.c, run_action). */
static ps_status script_action(snap_run *s, const ps_script_action *act, bool *wait, bool *quit, ps_error *err)
{
    ps_session *ss = s->session;
    size_t nl, no;
    (void)ps_scene_lights(ps_session_scene(ss), &nl);
    (void)ps_scene_objects(ps_session_scene(ss), &no);
    ps_status st = PS_OK;
    switch (act->kind) {
    case PS_SCRIPT_SCREENSHOT: {
        /* The picture as shown: a PNG (times exposure, 8-bit), or where the
         * path ends in .pfm or .exr its linear radiance (the layers' float
         * composite with --color-depth float), for comparisons that 8-bit
         * codes would clip. */
        ps_image img;
        st = read_picture(s, true, every_map, &img, err);
        if (st == PS_OK && ps_script_path_is_radiance(act->path)) {
            to_radiance(s, &img);
            st = ps_hdr_write(&img, act->path, err);
        } else if (st == PS_OK)
            st = ps_png_write(&img, act->path, 1.0f, err);
        ps_image_destroy(&img);
        return st;
    }
    case PS_SCRIPT_MOVE_LIGHT:
    case PS_SCRIPT_MOVE_OBJECT:
    case PS_SCRIPT_POWER:
    case PS_SCRIPT_ANGLE: {
        bool object = act->kind == PS_SCRIPT_MOVE_OBJECT;
        if (script_index(s, act, object ? no : nl, object ? "objects" : "lights", err) != PS_OK)
            return err->status;
        /* The edit's clock starts before the call, which holds the tracing
         * thread between batches (app/latency.h). */
        double t = ps_now_seconds();
        ps_latency_begin(&s->lat, t);
        st = act->kind == PS_SCRIPT_MOVE_LIGHT ? ps_session_move_light(ss, act->index, act->v, err)
             : object                          ? ps_session_move_object(ss, act->index, act->v, err)
             : act->kind == PS_SCRIPT_POWER    ? ps_session_set_light_power(ss, act->index, act->power, err)
                                               : ps_session_set_spot_angle(ss, act->index, act->number, err);
        ps_latency_add(&s->lat, PS_LAT_HOLD, ps_now_seconds() - t);
        return st;
    }
    case PS_SCRIPT_ORBIT: orbit(s, act->yaw, act->pitch); return PS_OK;
    case PS_SCRIPT_WAIT: *wait = true; return PS_OK;
    case PS_SCRIPT_QUIT: *quit = true; return PS_OK;
    case PS_SCRIPT_DUMP_PHOTONS: return dump_photons(s, act->path, err);
    case PS_SCRIPT_SAVE_SCENE: return ps_scene_write(ps_session_scene(ss), act->path, err);
    case PS_SCRIPT_SET:
        switch (act->setting) {
        case PS_SET_SPLAT: ps_session_set_splat(ss, (ps_splat_mode)act->choice); return PS_OK;
        case PS_SET_LAYERS: ps_session_set_layers(ss, act->layers); return PS_OK;
        case PS_SET_KERNEL:
            st = ps_session_set_kernel(ss, (ps_kernel)act->choice, err);
            if (st == PS_OK)
                ps_gl_renderer_set_kernel(s->gl, ps_session_kernel(ss));
            return st;
        case PS_SET_RADIUS:
            ps_session_set_radius(ss, PS_MAP_CAUSTIC, act->number);
            ps_session_set_radius(ss, PS_MAP_GLOBAL, act->number2);
            return PS_OK;
        case PS_SET_TAU: ps_session_set_tau(ss, act->number); return PS_OK;
        case PS_SET_PRECISION: ps_session_set_precision(ss, (ps_precision)act->choice); return PS_OK;
        case PS_SET_EXPOSURE: ps_session_set_exposure(ss, act->number); return PS_OK;
        case PS_SET_PAUSE: ps_session_set_paused(ss, act->choice != 0); return PS_OK;
        case PS_SET_FALSE_COLOR:
            return ps_error_set(err, PS_ERR_PARSE, "%s:%d: set false-color: the window's view (snap: --false-color)",
                                s->o->script_path, act->line);
        case PS_SET_GLOBAL_LAYER: return ps_session_set_global_layer(ss, (ps_global_layer)act->choice, err);
        }
        return PS_OK;
    }
    return PS_OK;
}

/* Edits made since the last refresh: the session repairs the maps, the
 * renderer follows its meshes and lights. */
static ps_status apply_edits(snap_run *s, ps_error *err)
{
    ps_session_changes ch;
    double t = ps_now_seconds();
    ps_latency_begin(&s->lat, t);
    ps_status st = ps_session_update(s->session, &ch, err);
    if (st == PS_OK) {
        ps_gl_scene gs = ps_gl_scene_of(s->session);
        st = ps_gl_renderer_set_scene(s->gl, &gs, err);
    }
    ps_latency_add(&s->lat, PS_LAT_UPDATE, ps_now_seconds() - t);
    s->awaiting_edit = true;
    s->updates++;
    return st;
}

/* The script on snap's clock: a refresh every tau, each action when its time
 * (counted from the first frame, and after a wait done from when it ended)
 * has come; ends at quit or after the last action (or at --time). */
static ps_status run_script(snap_run *s, double t_start, double *first_frame, ps_error *err)
{
    const snap_options *o = s->o;
    ps_status st = ps_session_start(s->session, true, err);
    size_t next = 0, count = ps_script_count(o->script);
    bool waiting = false, quit = false;
    double t0 = -1.0, delay = 0.0, wait_time = 0.0;
    while (st == PS_OK && !quit) {
        if (ps_cancelled(o->cancel)) {
            st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %.1f s", ps_now_seconds() - t_start);
            break;
        }
        if (ps_session_edited(s->session))
            st = apply_edits(s, err);
        if (st == PS_OK)
            st = refresh(s, err);
        if (st != PS_OK)
            break;
        double now = ps_now_seconds();
        if (t0 < 0.0) {
            t0 = now;
            *first_frame = now - t_start;
        }
        /* A wait is over once everything is shown; checked before the next
         * action, and also when `wait done` was the last one (then the
         * script ends here: it used to refresh for ever). As the window's:
         * with float layers the specular layer's last round too (whole
         * refreshes draw every face). */
        if (waiting && !ps_session_edited(s->session) && ps_session_settled(s->session) &&
            (!s->layers || ps_gl_specular_done(s->spec, s->session))) {
            waiting = false;
            delay = now - t0 - wait_time;
        }
        while (st == PS_OK && !quit && !waiting && next < count) {
            const ps_script_action *act = ps_script_at(o->script, next);
            if (act->time + delay > now - t0)
                break;
            next++;
            bool w = false;
            /* Files written are off the clock: tracing is held meanwhile. */
            ps_session_hold(s->session, true);
            st = script_action(s, act, &w, &quit, err);
            ps_session_hold(s->session, false);
            if (w) {
                waiting = true;
                wait_time = act->time;
            }
            /* An edit, a setting or an orbit shows at the next refresh. */
            if (act->kind != PS_SCRIPT_SCREENSHOT && act->kind != PS_SCRIPT_DUMP_PHOTONS &&
                act->kind != PS_SCRIPT_SAVE_SCENE && act->kind != PS_SCRIPT_QUIT)
                break;
        }
        if (st != PS_OK || quit || (next >= count && !waiting))
            break;
        if (o->time > 0.0 && now - t_start >= o->time)
            break;
        double due = ps_session_next_refresh(s->session, now);
        if (!waiting && next < count) {
            double at = t0 + delay + ps_script_at(o->script, next)->time;
            due = fmin(due, fmax(at, now));
        }
        /* An edit: its update and first refresh at once, as the window's,
         * and after its level of detail the full view; after a camera move,
         * the view drawn again with nothing traced meanwhile, refresh after
         * refresh (ps_session_catching_up). */
        if ((ps_session_settled(s->session) && waiting) || ps_session_edited(s->session) || s->frame.edit_lod ||
            ps_session_catching_up(s->session))
            due = now;
        /* The still view's first work while the camera may have stopped (session.h). */
        while (ps_now_seconds() < due && ps_session_prepare_still(s->session, PS_SESSION_PREPARE_VERTICES))
            ;
        sleep_until(due);
    }
    return last_picture(s, st, err);
}

static ps_status write_stats_and_report(snap_run *s, int width, int height, double t_start, double first_frame,
                                        ps_error *err)
{
    const snap_options *o = s->o;
    ps_session_counts counts;
    ps_session_get_counts(s->session, &counts);
    uint64_t counter_at = 0;
    bool counter_stopped = ps_session_counter_stopped(s->session, &counter_at);
    const ps_tracer *tracer = ps_session_tracer(s->session);
    ps_run_stats rs;
    memset(&rs, 0, sizeof rs);
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        rs.emitted[k] = counts.map[k].emitted;
        rs.stored[k] = counts.map[k].stored;
        rs.rays += counts.map[k].rays;
    }
    rs.trace_seconds = counts.trace_seconds;
    rs.splat_seconds = counts.splat_seconds + s->draw_seconds;
    rs.frames = s->frames;
    rs.skips = ps_tracer_skips(tracer, &rs.skip_count);
    ps_gl_stats gs = ps_gl_get_stats(s->gl);
    ps_stats_add(&rs, "threads", ps_tracer_threads(tracer));
    ps_stats_add(&rs, "seed", (double)o->c.seed);
    ps_stats_add(&rs, "width", width);
    ps_stats_add(&rs, "height", height);
    ps_stats_add(&rs, "seconds", ps_now_seconds() - t_start);
    ps_stats_add(&rs, "first_frame_seconds", first_frame);
    /* The splats the picture is made of: drawn over all refreshes into
     * layers, or the last whole frame's. */
    ps_stats_add(&rs, "specular_cube_faces", (double)ps_gl_specular_faces_rendered(s->spec));
    ps_stats_add(&rs, "splats", (double)(s->layers ? s->splats : s->frame.splats));
    ps_stats_add(&rs, "kernel_mean", ps_session_kernel(s->session)->mean);
    ps_stats_add(&rs, "caustic_radius", ps_session_radius(s->session, PS_MAP_CAUSTIC));
    ps_stats_add(&rs, "global_radius", ps_session_radius(s->session, PS_MAP_GLOBAL));
    ps_stats_add(&rs, "gl_lights", gs.virtual_lights);
    ps_stats_add(&rs, "shadow_maps", gs.shadow_maps);
    ps_stats_add(&rs, "round_off_fraction", s->frame.round_off);
    ps_stats_add(&rs, "counter_stopped", counter_stopped ? 1.0 : 0.0);
    ps_stats_add(&rs, "counter_stopped_at_photons", (double)counter_at);
    ps_stats_add(&rs, "counter_threshold", o->p.counter_threshold);
    ps_stats_add(&rs, "radius_progressive", o->p.radius_schedule == PS_RADIUS_PROGRESSIVE ? 1.0 : 0.0);
    ps_stats_add(&rs, "global_maps", o->p.global_layer == PS_GLOBAL_MAPS ? 1.0 : 0.0);
    ps_stats_add(&rs, "luminous_flux_lm", ps_scene_total_lumens(ps_session_scene(s->session)));
    if (o->script) {
        /* The session is stopped: the last repair's counts are whole. */
        uint64_t repairs, kept[PS_MAP_COUNT], retraced[PS_MAP_COUNT];
        ps_session_repair_totals(s->session, &repairs, kept, retraced);
        ps_stats_add(&rs, "edits_applied", (double)s->updates);
        ps_stats_add(&rs, "repairs", (double)repairs);
        ps_stats_add(&rs, "repair_kept_caustic", (double)kept[PS_MAP_CAUSTIC]);
        ps_stats_add(&rs, "repair_kept_global", (double)kept[PS_MAP_GLOBAL]);
        ps_stats_add(&rs, "repair_retraced_caustic", (double)retraced[PS_MAP_CAUSTIC]);
        ps_stats_add(&rs, "repair_retraced_global", (double)retraced[PS_MAP_GLOBAL]);
        ps_latency_stats(&s->lat, &rs);
        printf("script: %llu updates, %llu repaired; photons kept/retraced: caustic %llu/%llu, global %llu/%llu\n",
               (unsigned long long)s->updates, (unsigned long long)repairs,
               (unsigned long long)kept[PS_MAP_CAUSTIC], (unsigned long long)retraced[PS_MAP_CAUSTIC],
               (unsigned long long)kept[PS_MAP_GLOBAL], (unsigned long long)retraced[PS_MAP_GLOBAL]);
    }
    if (o->c.stats) {
        ps_status st = ps_stats_write(o->c.stats, &rs, err);
        if (st != PS_OK)
            return st;
    }
    printf("caustic: %llu emitted, %llu stored; global: %llu emitted, %llu stored; %llu frames; %s splats, %s\n",
           (unsigned long long)rs.emitted[0], (unsigned long long)rs.stored[0], (unsigned long long)rs.emitted[1],
           (unsigned long long)rs.stored[1], (unsigned long long)s->frames,
           ps_splat_mode_name((ps_splat_mode)o->p.splat), o->p.color_depth == 0 ? "8-bit" : "float buffer");
    if (counter_stopped)
        printf("error counter: stopped shooting at %llu photons: %.1f %% of a refresh's splat energy rounded "
               "away in the 8-bit buffer (threshold %.1f %%)\n",
               (unsigned long long)counter_at, 100.0 * s->frame.round_off, 100.0 * o->p.counter_threshold);
    const char *const written[] = {o->c.out_png, o->c.out_hdr, o->out_lux, o->out_false};
    ps_print_run_end(rs.skips, rs.skip_count, written, sizeof written / sizeof written[0]);
    return PS_OK;
}

/* The photons, the frames, the files. */
static ps_status run(const snap_options *o, ps_scene *scene, ps_platform *platform, ps_error *err)
{
    int width, height;
    ps_platform_size(platform, &width, &height);
    snap_run s;
    memset(&s, 0, sizeof s);
    s.o = o;
    s.platform = platform;
    s.camera = *ps_scene_camera(scene);
    s.cam = ps_camera_frame_make(&s.camera, width, height);
    ps_session_settings set = ps_preview_settings(&o->c, &o->p, scene);
    set.skip_hidden = true; /* a layer left out is not traced */
    set.cancel = o->cancel;
    /* Progressive in float: only new photons each refresh, so that a refresh
     * (and a checkpoint) comes when it is due however many have arrived. */
    bool progressive = o->time > 0.0 || o->script;
    set.incremental = progressive && set.float_buffer;
    /* Float layers draw while the tracer runs, as the window's: a core left
     * to drawing (session.h). 8 bits redraw every photon each refresh, and
     * the tracer waits while a checkpoint's frame is drawn: every core. */
    set.threads = ps_session_tracing_threads(o->c.threads, set.incremental);
    /* Only a script edits: path records for the selective repair then. */
    set.repair = o->script != NULL && !o->no_repair;
    set.splat_share = SNAP_SPLAT_SHARE;
    if (o->time > 0.0 && !o->script)
        set.backlog_refreshes = SNAP_BACKLOG_REFRESHES;
    /* Progressive: the first picture without waiting for every area light's
     * 16 shadow cubes; a fixed photon count draws once, with all of them. */
    set.progressive_lights = progressive;
    ps_status st = ps_session_create(scene, &set, &s.session, err);
    /* Never the direct light's textures: snap's pictures are compared with
     * the reference's, and with them a picture would depend on when they
     * were laid. */
    ps_gl_options gopt = {o->p.shadows != 0, o->p.color_depth != 0, 0, false, false, ps_platform_gl_proc};
    if (st == PS_OK) {
        ps_gl_scene gs = ps_gl_scene_of(s.session);
        st = ps_gl_renderer_create(&gs, ps_session_kernel(s.session), &gopt, &s.gl, err);
    }
    if (st == PS_OK && set.incremental) {
        st = ps_gl_layers_create(width, height, true, &s.layers, err);
        if (st == PS_OK)
            ps_gl_layers_reserve(s.layers, s.gl, ps_session_illummap(s.session) != NULL);
    }
    if (st == PS_OK)
        st = ps_gl_specular_create(0, &s.spec, err);
    /* --time: the first round of cube faces soon, for the checkpoints (a
     * script keeps the window's budget). */
    if (st == PS_OK && !o->script)
        ps_gl_specular_set_first_round(s.spec, PS_GL_SPECULAR_FIRST_REFRESHES);
    /* ... but 8-bit checkpoints' frames hold theirs to the pace's deadline:
     * the first round's three faces a frame were longer than the frame of a
     * 1 s checkpoint may be (PS_PACE_FRAME_SHARE); the waits before those
     * frames draw them instead (refine). */
    if (st == PS_OK && !o->script && !s.layers && o->checkpoint_count > 0)
        ps_gl_specular_hold_first_round(s.spec, true);
    /* Checkpoints: an area light's next virtual lights when their shadow
     * cubes fit before the next checkpoint (refine). */
    if (st == PS_OK && !o->script && o->checkpoint_count > 0) {
        ps_session_hold_lights(s.session, true);
        s.lights_held = true;
    }
    double t_start = ps_now_seconds(), first_frame = -1.0;
    if (st == PS_OK && o->script) {
        st = run_script(&s, t_start, &first_frame, err);
    } else if (st == PS_OK && o->time <= 0.0) {
        /* A fixed photon count: trace everything, then draw once. */
        st = ps_session_trace_all(s.session, err);
        if (st == PS_OK)
            st = refresh(&s, err);
        first_frame = ps_now_seconds() - t_start;
    } else if (st == PS_OK) {
        st = refine(&s, t_start, &first_frame, err);
    }
    if (st == PS_OK && ps_cancelled(o->cancel) && (o->time > 0.0 || o->script))
        st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted after %.1f s of %.1f s", ps_now_seconds() - t_start,
                          o->time);
    else if (st == PS_OK && ps_cancelled(o->cancel))
        st = ps_error_set(err, PS_ERR_INTERRUPTED, "interrupted before writing the snapshot");
    if (st == PS_OK && (o->c.out_png || o->c.out_hdr || o->hdr_layers))
        st = write_outputs(&s, err);
    if (st == PS_OK && (o->out_lux || o->out_false))
        st = write_illuminance(&s, err);
    if (st == PS_OK && o->c.dump)
        st = ps_write_photon_dump(o->c.dump, ps_session_maps(s.session), err);
    if (st == PS_OK)
        st = write_stats_and_report(&s, width, height, t_start, first_frame, err);
    ps_gl_specular_destroy(s.spec);
    ps_gl_layers_destroy(s.layers);
    ps_gl_renderer_destroy(s.gl);
    ps_session_destroy(s.session);
    return st;
}

/* The layer and checkpoint files, checked before any work like the others
 * (one name of each kind stands for all: they share a folder). */
static ps_status check_prefixed_outputs(const snap_options *o, ps_error *err)
{
    char path[PATH_MAX];
    if (o->hdr_layers) {
        if (snprintf(path, sizeof path, "%s-direct.pfm", o->hdr_layers) >= (int)sizeof path)
            return ps_error_set(err, PS_ERR_IO, "%s: path too long", o->hdr_layers);
        if (ps_check_output_path(path, err) != PS_OK)
            return err->status;
    }
    if (o->checkpoint_prefix) {
        if (snprintf(path, sizeof path, "%s.csv", o->checkpoint_prefix) >= (int)sizeof path)
            return ps_error_set(err, PS_ERR_IO, "%s: path too long", o->checkpoint_prefix);
        if (ps_check_output_path(path, err) != PS_OK)
            return err->status;
    }
    return PS_OK;
}

int main(int argc, char **argv)
{
    ps_error err;
    ps_error_clear(&err);
    snap_options o;
    bool help = false;
    if (parse_args(argc, argv, &o, &help, &err) != PS_OK)
        return ps_cli_fail(&err);
    /* First pictures not paid in page faults (core/memory.h), but for an
     * 8-bit --time run that no checkpoint paces: its tracer stops when the
     * last picture, foreseen linearly from a smaller redraw's, still ends by
     * --time, and with the heap it traced more and ended later (the default
     * box at 64^2, --time 8: 7.5-9.4 s in six runs, against 6.1-8.4 s in ten
     * with this policy and 6.9-8.3 s in four of the build before). */
    if (o.p.color_depth == 0 && o.time > 0.0 && o.checkpoint_count == 0 && !o.script_path)
        ps_memory_set_drawing_policy();
    else
        ps_memory_reserve_large_heap(PS_MEMORY_SNAP_HEAP);
    if (help) {
        fputs(usage, stdout);
        return PS_EXIT_OK;
    }
    if (o.script_path && ps_script_load(o.script_path, &o.script, &err) != PS_OK)
        return ps_cli_fail(&err);
    for (size_t i = 0; o.script && i < ps_script_count(o.script); i++) {
        const ps_script_action *act = ps_script_at(o.script, i);
        if (act->path && ps_check_output_path(act->path, &err) != PS_OK) {
            ps_script_destroy(o.script);
            return ps_cli_fail(&err);
        }
    }
    if (ps_check_outputs(&o.c, &err) != PS_OK || check_prefixed_outputs(&o, &err) != PS_OK ||
        (o.out_lux && ps_check_output_path(o.out_lux, &err) != PS_OK) ||
        (o.out_false && ps_check_output_path(o.out_false, &err) != PS_OK)) {
        ps_script_destroy(o.script);
        return ps_cli_fail(&err);
    }
    o.cancel = ps_interrupt_install();
    ps_scene *scene;
    if (ps_scene_load(o.c.scene, NULL, &scene, &err) != PS_OK) {
        ps_script_destroy(o.script);
        return ps_cli_fail(&err);
    }
    const ps_scene_defaults *def = ps_scene_get_defaults(scene);
    int width = o.c.width ? o.c.width : def->width, height = o.c.height ? o.c.height : def->height;
    /* Refuse what would not fit before the buffer or a photon. */
    uint64_t photons = ps_shared_photons(&o.c, def, PS_MAP_CAUSTIC) + ps_shared_photons(&o.c, def, PS_MAP_GLOBAL);
    uint64_t pixel_bytes = SNAP_PIXEL_BYTES + 4 * (o.p.color_depth == 0 ? 1 : sizeof(float));
    if (ps_check_run_memory("photosplat-snap", photons, PS_PREVIEW_PHOTON_BYTES, width, height, pixel_bytes, &err) !=
        PS_OK) {
        ps_scene_destroy(scene);
        ps_script_destroy(o.script);
        return ps_cli_fail(&err);
    }
    ps_platform_config pc = {width, height, o.p.color_depth != 0, NULL};
    ps_platform *platform = NULL;
    ps_status st = ps_platform_open(&pc, &platform, &err);
    if (st != PS_OK) {
        char why[PS_ERROR_MSG_MAX];
        snprintf(why, sizeof why, "%s", err.msg);
        ps_error_set(&err, st, "photosplat-snap: %s", why);
    } else {
        st = run(&o, scene, platform, &err);
    }
    ps_platform_close(platform);
    ps_scene_destroy(scene);
    ps_script_destroy(o.script);
    if (st == PS_ERR_INTERRUPTED)
        return ps_interrupt_fail("photosplat-snap", &err);
    return st == PS_OK ? PS_EXIT_OK : ps_cli_fail(&err);
}
