/* session.h: one preview session, GL-free: the progressive policy that the
 * window and photosplat-snap share (thesis 4.1.4, 5.1).
 *
 * A session owns what a scene needs to be previewed: the ray accelerator
 * (world), the photon tracer and its background feed, the GL-ready meshes
 * and lights (preview/mesh.h, preview/lights.h), the kernel texture and the
 * splat batches. Each refresh, a program asks it what to draw
 * (ps_session_refresh): which photons become splats, at which radius (the
 * radius schedule), with which gains (N / n), whether the layers start over;
 * after drawing it says how long that took (ps_session_drawn), which sets the
 * next refresh's splat budget. Edits (lights, objects) and settings go
 * through the session, which restarts what they invalidate.
 *
 * Two ways to refresh, one policy:
 *  - whole: every refresh splats every photon that has arrived, scaled for
 *    display (exposure N / n) into layers cleared first. What an 8-bit
 *    colour buffer needs (thesis 5.1: faint photons must be drawn at their
 *    displayed value, or they round away), and photosplat-snap's single
 *    frame of a fixed photon count.
 *  - incremental: layers keep their float sums between refreshes; a refresh
 *    splats only the batches not drawn yet, at their stored power, at most
 *    the budget's worth, and the composite scales each map by exposure N / n.
 *    Float buffers in progressive mode: the window's layers, and
 *    photosplat-snap --time.
 * Either way the photons drawn are a prefix of each map ending at a batch the
 * feed handed over, so the picture after n photons is the same picture
 * however fast they came. */
#ifndef PS_PREVIEW_SESSION_H
#define PS_PREVIEW_SESSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/cancel.h"
#include "core/status.h"
#include "photon/estimate.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "preview/bake.h"
#include "preview/illummap.h"
#include "preview/layers.h"
#include "preview/lights.h"
#include "preview/mesh.h"
#include "preview/splat.h"
#include "scene/camera.h"
#include "scene/scene.h"

/* An incremental refresh splats at most as many photons a map as fit in this
 * share of tau (by default: the window's, which also composites and shows
 * the picture) at the rate the last refreshes drew them, so that a refresh
 * comes every tau however fast photons arrive (llvmpipe draws a few hundred
 * thousand large splats a second); never fewer than the first bound. */
#define PS_SESSION_SPLAT_TIME_SHARE 0.5
#define PS_SESSION_BUDGET_MIN 2048
#define PS_SESSION_BUDGET_START 16384
/* While the camera moves (a new camera every refresh), an incremental
 * refresh draws a level of detail: this share of the budget (still at least
 * one batch: a prefix of each map, which in index order is an unbiased subset
 * scaled by N / n), its splats' radius grown by sqrt(arrived / drawn) (at
 * most PS_RADIUS_GROWTH_MAX) so that the fewer photons still cover; the
 * first refresh with the camera still starts the view over in full. */
#define PS_SESSION_MOVING_SHARE 0.25
/* ... and the level of detail's radius grows at most this much (not
 * PS_RADIUS_GROWTH_MAX): the share is at least one batch (PS_FEED_BATCH), so
 * over a million photons the cover asked for is sqrt(60) r, and a grown
 * splat's pixels, not the count, set a moving frame's time (llvmpipe fills a
 * few hundred million a second): 2 r draws a quarter of 4 r's. */
#define PS_SESSION_MOVING_GROWTH_MAX 2.0
/* ... and is drawn at 1/PS_SESSION_MOVING_SCALE of the camera's pixels a
 * side (ps_session_frame.view), shown scaled up, as viewports do while
 * navigating: llvmpipe's fill (the direct layer's lit mesh, the splats, the
 * specular objects) was most of a moving frame (0.11 s at 512^2 over 10^6
 * photons in the default scene, 95 % of it in llvmpipe's threads). */
#define PS_SESSION_MOVING_SCALE 2
/* ... and the global map's layer, as triangle splats grown this much or
 * more, at 1/PS_SESSION_MOVING_GLOBAL_SHRINK of that view's pixels a side
 * again (ps_session_layer.shrink): a splat grown 2x then covers as many of
 * its pixels as a full-detail splat covers of the full view's, and the
 * global map's wide splats (the default scene's r0 is 5x the caustic's)
 * filled 7-25 ms of a moving frame at 256^2, llvmpipe's fill; the caustic
 * layer keeps its pixels (its small splats cost their setup, not fill, and
 * are the picture's sharp part). */
#define PS_SESSION_MOVING_GLOBAL_SHRINK 2
/* Once the camera stops, until the view is drawn in full again, a refresh
 * from the second on draws this much more than the budget (1.5 tau of
 * splats at the default share of 0.5 instead of half of it): the picture the
 * user waits for comes back sooner, its refreshes' fixed costs (the direct
 * layer, the composite, the show) paid fewer times; the first still refresh
 * keeps the budget, so that a camera that only paused between two steps is
 * not held up by a long one (at 3x from the first, an orbit of 60 steps
 * 0.05 s apart drew 49-58 frames against 58-59). The full picture after an
 * orbit over 1.25*10^6 photons: 1.6-2.0 s, against 2.8-4.0 s at 1.6x from
 * the first. Moving refreshes teach the budget nothing (their time is the
 * level of detail's). */
#define PS_SESSION_CATCH_UP_GAIN 3.0
/* The specular layer's eye paths an incremental refresh traces at most
 * (distinct vertices of mirrors and glass; preview/specular.h). */
#define PS_SESSION_SPECULAR_VERTICES 32768
/* ... and while the camera moves (the level of detail): the vertices not
 * traced again keep their last eye's lookups, and the next refreshes trace
 * the rest (the default scene's 10^4 in 12 ms were a fifth of a moving frame). */
#define PS_SESSION_SPECULAR_VERTICES_MOVING 2048
/* After an edit that repairs the maps, the photons it changed are retraced
 * before the first picture when they are at most this many in both maps
 * (else all by the tracing thread, first thing, and the first picture comes
 * at once with a hole where they were): at the default caps a move of the
 * default scene's mirror retraces about 9*10^4, 0.05 s on 2 cores, and its
 * first picture is whole (docs/repair.md). A count, not a share of tau: a
 * time bound was met or missed with the machine's load, and the first
 * picture with it. */
#define PS_SESSION_RETRACE_FIRST 131072
/* A still camera's per-pixel specular paths (specular.h) are traced whole in
 * one refresh when at most this many eye rays are left, else
 * PS_SPECULAR_PIXEL_RAYS a refresh: the default scene's spheres at 256^2
 * take 6.8*10^4 rays, 0.06-0.08 s on one core, so the first picture after an edit
 * shows them, where per-vertex lookups left the default scene's mirror,
 * moved 10 cm, at relMSE 0.051 against the converged picture (0.0085 with
 * its paths; docs/repair.md). At 512^2 (2.6*10^5) the last of them come
 * whole. A count, as above. */
#define PS_SESSION_PIXEL_RAYS_WHOLE 131072
/* The first refresh after an edit draws every stored photon, not a budget's
 * prefix, when both maps hold at most this many at a view of
 * PS_SESSION_EDIT_WHOLE_PIXELS (and in proportion to fewer or more pixels:
 * a splat fills pixels in proportion to them), unless the edit is part of a
 * drag (ps_session_set_dragging): the picture after a single edit is then as
 * full as the one before it (issue 18: "the first frame after an edit shows
 * every kept photon at once"). At the default caps (2.5*10^5) and 256^2 the
 * budget drew 7*10^4 to 2.5*10^5 of them with the refreshes' timing, and the
 * first picture after moving the mirror 10 cm was at relMSE 0.015 to 0.026
 * against the converged edited scene. Past it the first picture is the
 * level of detail (ps_session_frame.edit_lod). A count, as above, not a
 * time: a count by itself let the area-light scene at 512^2 draw 2.6*10^5
 * photons in 0.9 s, and the refreshes' own splat rates went from 3*10^4 to
 * 1.5*10^6 a second from one refresh to the next. */
#define PS_SESSION_EDIT_SPLATS_WHOLE 262144
#define PS_SESSION_EDIT_WHOLE_PIXELS (256 * 256)

typedef struct ps_session_settings {
    /* The photons. */
    uint64_t caps[PS_MAP_COUNT];   /* photons each map emits: the cap of refinement */
    double radius[PS_MAP_COUNT];   /* r0, scene units (> 0) */
    uint64_t seed;
    int threads;                   /* tracing threads; 0: every core */
    int first_round_threads;       /* ... of the first round (ps_session_start), which nothing
                                    * is drawn beside; 0: every core (the default) */
    const ps_cancel_flag *cancel;  /* NULL, or a flag that stops tracing */
    size_t max_stored;             /* the feed's store limit for both maps (0: none) */
    uint64_t max_map_photons;      /* the most photons one map may hold (the memory budget's
                                    * share, ps_tracer_options.max_stored; 0: none) */
    bool skip_hidden;              /* a layer not shown is not traced (snap); else traced anyway,
                                    * to be shown when switched on (the window) */
    /* How they are drawn. */
    unsigned layers;               /* PS_LAYER_* shown */
    ps_splat_mode splat;
    ps_kernel kernel;
    double point_size;             /* points: their side in pixels */
    bool float_buffer;             /* the colour buffer or layers keep floats; else 8 bits */
    ps_precision precision;        /* 8 bits only */
    double counter_threshold;      /* PS_PRECISION_COUNTER: stop past this fraction rounded away */
    bool stencil_clip;             /* clip each object's splats to its pixels */
    ps_radius_schedule radius_schedule;
    double radius_alpha;
    double exposure;
    bool incremental;              /* see above: only with float_buffer */
    double tau;                    /* seconds between refreshes: the budget's time */
    double backlog_refreshes;      /* incremental: the tracer waits while a map holds more
                                    * photons not drawn than this many refreshes' budgets
                                    * (0: never; photosplat-snap) */
    double splat_share;            /* incremental: the share of tau new splats may take
                                    * (PS_SESSION_SPLAT_TIME_SHARE; more where nothing else
                                    * waits, as in photosplat-snap) */
    int shadow_size;               /* the GL lights' shadow maps (texels a side), 0: none;
                                    * only planned here, against the memory budget */
    bool progressive_lights;       /* the first picture sooner: its shadow maps coarse
                                    * (PS_SESSION_COARSE_SHADOW_DIVISOR), area lights as
                                    * one virtual light each, refined a level a refresh
                                    * (the full shadows, with 2 x 2 virtual lights, then
                                    * PS_PREVIEW_AREA_SAMPLES; area lights again after each
                                    * edit), so that the first picture does not wait
                                    * for every shadow cube; else all from the start */
    ps_global_layer global_layer;  /* the global layer as splats or as illumination maps
                                    * (illummap.h) with only the glossy lobes splatted */
    bool repair;                   /* edits keep the photons they cannot change (repair.h):
                                    * path records cost PS_PATH_PLAN_BYTES an emitted
                                    * photon (default on) */
    uint64_t retrace_first;        /* ... and retrace the others before the first picture
                                    * after an edit when they are at most this many, else in
                                    * the background (PS_SESSION_RETRACE_FIRST) */
    uint64_t pixel_rays_whole;     /* the per-pixel specular paths whole in a refresh when at
                                    * most this many rays are left (PS_SESSION_PIXEL_RAYS_WHOLE) */
    uint64_t edit_splats_whole;    /* an edit's first refresh draws every photon when the maps
                                    * hold at most this many at 256^2, in proportion to the
                                    * view's pixels (PS_SESSION_EDIT_SPLATS_WHOLE) */
    bool bake;                     /* incremental, triangle splats: a map traced to its end
                                    * whose photons all lie on diffuse quads is laid into
                                    * textures on them (bake.h), a budget a refresh once the
                                    * view shows all of it, and each later view draws the
                                    * textures instead of its splats (the window; default off) */
    bool specular_wait;            /* the first refreshes leave the specular layer's eye paths
                                    * owed (ps_session_set_specular_wait): a drawing side that
                                    * keeps that setting (src/gl's specular layer) shows no
                                    * cube map yet; default off */
} ps_session_settings;

/* A progressive start's first shadow maps: this many times fewer texels a
 * side than settings.shadow_size, never fewer than
 * PS_SESSION_COARSE_SHADOW_MIN (snap's 1024 as 512, the window's 512 as
 * 256). A shadow face is a depth texture faulted in page by page (about
 * 10 us a 4 KiB page here): the default box's six 1024^2 faces took 0.10 s
 * of its first float picture at 256^2, which came at 0.26 s; at 512^2 it came
 * at 0.18 s, its direct layer at relMSE 0.0039 against the reference
 * (0.0036 at 1024^2); at 256^2 0.17 s, but the ring's direct layer went from
 * 0.026 to 0.11 (0.041 at 512^2). Refined at the next level
 * (ps_session_refine_lights), once: after an edit the lights keep the full
 * side, so that the faces the edit cannot reach are kept (src/gl). */
#define PS_SESSION_COARSE_SHADOW_DIVISOR 2
#define PS_SESSION_COARSE_SHADOW_MIN 128
/* The full shadow maps' time against the coarse ones', taken as 2 (the
 * default box's six faces: 0.097-0.10 s at 1024^2, 0.036 s at 256^2): the
 * next level's cost (ps_session_next_level_cost), and
 * ps_session_lights_to_come's factor. */
#define PS_SESSION_COARSE_SHADOW_COST 2.0

/* Defaults: the scene's photon counts and radii, every layer, triangles, the
 * cone kernel, 8 bits with error diffusion, fixed radius, exposure 1, whole
 * refreshes, tau 0.1, shadow maps of 1024. */
ps_session_settings ps_session_default_settings(const ps_scene *scene);
/* The tracing threads of a session whose refreshes draw while it traces
 * (incremental: the window, photosplat-snap's float layers): those asked
 * for (requested > 0), else every core but one, left to drawing (llvmpipe
 * draws on the CPU too; with every core tracing, the window's picture after
 * a light move took four times as long, and snap's float refreshes drew
 * 0.4-0.55 M splats a second at 256^2 while the tracer ran 2-3 times ahead
 * of them). A session that draws only once it has traced takes every core
 * (0). */
int ps_session_tracing_threads(int64_t requested, bool draws_while_tracing);

typedef struct ps_session ps_session;

/* A session of `scene`, which it edits and which must outlive it. Builds the
 * world, meshes, lights, tracer and feed; traces nothing yet. */
ps_status ps_session_create(ps_scene *scene, const ps_session_settings *set, ps_session **out, ps_error *err);
void ps_session_destroy(ps_session *s); /* stops the feed; accepts NULL */

/* ---- tracing ---------------------------------------------------------------- */

/* Traces every map to its cap on the calling thread. */
ps_status ps_session_trace_all(ps_session *s, ps_error *err);
/* Traces the first round here (so that the first picture shows photons),
 * then goes on in a background thread. held: the thread waits until the
 * first refresh after this has been drawn (ps_session_drawn), so that the
 * refresh has every core. */
ps_status ps_session_start(ps_session *s, bool held, ps_error *err);
/* Work a caller does while the first round is traced. */
typedef void ps_session_beside_fn(void *ctx);
/* ps_session_start, the first round traced on a thread of its own while
 * beside(ctx) runs on this one: the first picture's work that needs no
 * photon, such as its view (ps_gl_layers_view_ahead). The round runs at a
 * low priority (ps_thread_low_priority) on the first round's threads, so
 * the work takes the cores it wants and the round the rest: llvmpipe's
 * first compiles leave all but one idle. beside (and spare) must not call
 * this session, but for ps_session_get_counts. With nothing to trace first
 * (after a repair), or no thread for it, beside runs after the round. The photons are the same either way.
 * After the round, on its thread, the illumination maps (--global-layer
 * maps) gather its global photons, which the first refresh would: they do
 * not depend on the view (ps_session_counts.ahead_seconds).
 * After beside, spare(ctx) (NULL: none) runs only if the round and that
 * gathering are still going, where the caller would otherwise wait: work
 * of the first refresh worth doing ahead only then
 * (ps_gl_layers_prepare_maps: 4-6 ms of the first refresh's, which would
 * delay it by as much where the round had ended first). */
ps_status ps_session_start_beside(ps_session *s, bool held, ps_session_beside_fn *beside,
                                  ps_session_beside_fn *spare, void *ctx, ps_error *err);
/* Stops the background thread and waits for it; how tracing ended. */
ps_status ps_session_stop(ps_session *s, ps_error *err);
/* How tracing went so far: the tracer's error if it failed, else PS_OK. */
ps_status ps_session_status(const ps_session *s, ps_error *err);
/* Holds tracing (the user's pause) or lets it go on (unless the error
 * counter stopped it). */
void ps_session_set_paused(ps_session *s, bool paused);
/* Holds the background thread without changing the user's pause (while a
 * program writes files off its clock). */
void ps_session_hold(ps_session *s, bool held);
bool ps_session_paused(const ps_session *s);
/* Whether the error counter stopped shooting (thesis 5.1), and at how many
 * photons emitted (both maps). Until the next edit. */
bool ps_session_counter_stopped(const ps_session *s, uint64_t *at_photons);

/* ---- refreshing ---------------------------------------------------------------- */

/* What one map's layer gets this refresh. */
typedef struct ps_session_layer {
    bool clear;                  /* empty the layer first (whole refreshes) */
    const ps_splat_batch *batch; /* splats to add (possibly none) */
    double radius;               /* the radius they were built with */
    double gain;                 /* the layer's weight in the composite (0: not shown) */
    int shrink;                  /* drawn at 1/shrink of the view's pixels a side, scaled up in
                                  * the composite (PS_SESSION_MOVING_GLOBAL_SHRINK; 1: all of
                                  * them); read at a new view, kept until the next */
    /* settings.bake (bake.h): */
    bool bake_reset;             /* drop the map's baked textures (its photons or their look changed) */
    const ps_bake *bake;         /* this refresh's splats to lay into the textures of its plan
                                  * (made when the first come); NULL: none */
    bool baked;                  /* the layer is the textures: draw them into it (after clear) */
} ps_session_layer;

typedef struct ps_session_frame {
    /* The layers hold nothing valid (a new camera, setting or edit): draw the
     * depth prepass and the direct layer again, and empty the map layers. */
    bool new_view;
    /* The GL lights are new (progressive area lights refined): give the
     * renderer ps_gl_scene_of again; the direct layer is to be drawn again
     * (implied by new_view), the map layers kept. */
    bool lights_changed;
    /* ... by their shadow maps' side alone (a progressive start's coarse
     * shadows refined): the same lights, so the specular layer's cube faces
     * keep their round (a new round lost the default box's 9 faces of 12
     * drawn, and its mirror stayed black past the 1 s checkpoint). */
    bool shadows_refined;
    bool direct;             /* the direct layer is shown (else the scene is drawn black) */
    bool specular;           /* the specular layer is shown and the scene has mirrors or glass:
                              * its lookups are traced for this camera (ps_session_specular) */
    double direct_exposure;  /* the exposure GL lights are drawn with */
    double direct_gain;      /* the direct layer's weight in the composite */
    ps_session_layer map[PS_MAP_COUNT];
    ps_splat_mode splat;
    double point_size;
    bool moving;             /* the camera moved: this picture is the level of detail */
    bool edit_lod;           /* ... or an edit: its first picture, unless it draws every
                              * photon, is the level of detail too, with shadows */
    ps_camera_frame view;    /* what this refresh draws at: the camera, or while it moves the
                              * same view at 1/PS_SESSION_MOVING_SCALE of its pixels a side */
    uint64_t emitted[PS_MAP_COUNT]; /* the photons emitted that this picture shows */
    size_t splats;           /* splats built this refresh */
    double round_off;        /* 8 bits: the fraction of this refresh's splat energy rounded away */
    /* --global-layer maps: the global map's illumination maps as one RGBA
     * colour a fine-mesh vertex for this view (ps_illummap_view_colors: each
     * triangle the side the eye sees), times the gain the splats get (1 in
     * incremental layers, exposure N / n in whole ones); NULL when not shown.
     * map[PS_MAP_GLOBAL]'s batch then holds only the glossy lobes' splats. */
    const float *imap_colors;
    const ps_illum_span *imap_spans; /* the vertices to draw (ps_illummap_spans) */
    size_t imap_span_count;
    bool imap_redraw;        /* the colours are new (or the view): draw the maps again */
} ps_session_frame;

/* Builds this refresh's splats for camera cam (a camera unlike the last
 * refresh's starts a new view). Briefly holds the feed's lock. */
ps_status ps_session_refresh(ps_session *s, const ps_camera_frame *cam, ps_session_frame *out, ps_error *err);
/* Progressive lights: the full shadow maps and every virtual light from the
 * next refresh on (a snapshot's last picture). */
void ps_session_full_lights(ps_session *s);
/* Whether progressive area lights grow only when asked (ps_session_refine_lights)
 * instead of a level a refresh: photosplat-snap's checkpoints refine them
 * where their shadow cubes (1.2-1.9 s for the area box's 16 virtual lights at
 * 256^2) keep the next checkpoint on time (8 bits: in the waits between
 * frames), not in a checkpoint's frame. */
void ps_session_hold_lights(ps_session *s, bool held);
/* The next level from the next refresh on: twice the virtual lights a side
 * (area lights), and the full shadow maps if they are coarse; false when
 * all are there. */
bool ps_session_refine_lights(ps_session *s);
/* Progressive lights: what ps_session_full_lights would draw, as a multiple
 * of what is drawn now (virtual lights, times PS_SESSION_COARSE_SHADOW_COST
 * while the shadows are coarse; 1: all there). */
double ps_session_lights_to_come(const ps_session *s);
/* Whether the lights last built (those ps_session_lights gives) are a level
 * with more to come: a progressive start's, or an edit's area lights. Their
 * lit passes may then draw ps_session_moving_mesh, Gouraud's interpolation
 * error 4x coarser (about 0.4 % where the fine mesh's is 0.1 %), far below
 * what the coarse shadow maps or fewer virtual lights of that level cost
 * (the ring's direct layer: relMSE 0.041 at 512^2 against 0.026); the
 * refinement that follows draws the direct light again, on the fine mesh. */
bool ps_session_lights_coarse(const ps_session *s);
/* The next level's virtual lights as a multiple of those drawn now (4 for
 * twice as many a side, else 1), and what its shadow maps cost as a
 * multiple of the current ones' (that, times PS_SESSION_COARSE_SHADOW_COST
 * while the shadows are coarse). */
double ps_session_next_level_lights(const ps_session *s);
double ps_session_next_level_cost(const ps_session *s);
/* After the refresh's splats were drawn, in draw_seconds (finished, not only
 * queued): the budget for the next, a held feed let go, and the error
 * counter's verdict (which pauses tracing). */
void ps_session_drawn(ps_session *s, double draw_seconds);

/* Whether the refreshes are drawing a view again after the camera stopped
 * (PS_SESSION_CATCH_UP_GAIN) with nothing traced meanwhile (the maps at
 * their end, or tracing held), or laying a bake (settings.bake, the maps at
 * their end): the next refresh need not wait for tau, as no tracer shares
 * the cores and the user waits for the full picture, or for the camera to
 * move freely. */
bool ps_session_catching_up(ps_session *s);

/* Whether photons are being traced now (an incremental session's tracer
 * running: its maps short of their caps, not paused, not stopped by the
 * error counter). Work done ahead of need waits while they are: it would
 * take the tracer's cores. */
bool ps_session_tracing(ps_session *s);

/* While `wait` holds (a drawing side that shows no cube map yet, every one
 * black, and so adds nothing), a refresh leaves the layer's eye paths (its
 * lookups and per-pixel paths, specular.h) owed; ps_session_trace_specular
 * traces what the last refresh left owed, once the layer is drawn. They
 * depend on the eye alone, so the layer is the same picture; the first
 * pictures, before any cube map is shown, come sooner (the default box's
 * first at 256^2: 0.045 s of its 0.11 s). From settings.specular_wait. */
void ps_session_set_specular_wait(ps_session *s, bool wait);
void ps_session_trace_specular(ps_session *s);
/* The same ahead of need, in a wait that ends at `deadline` (on
 * ps_now_seconds' clock): as much of them as fits, the rest still owed. */
void ps_session_trace_specular_until(ps_session *s, double deadline);
/* Whether the last refresh's eye paths are still owed (some not traced). */
bool ps_session_specular_owed(const ps_session *s);

/* While the program would sleep after a moving camera's picture (until
 * ps_session_next_refresh), the work that camera's still view starts with,
 * done ahead: the specular layer's lookups for its eye, at most max_vertices
 * a call, then its per-pixel paths, PS_SESSION_PREPARE_SECONDS a call. They
 * depend on the camera alone (specular.h), so the still view is the same
 * picture, only sooner (the default box's 9 804 sphere vertices were 13-15
 * ms of its 0.07 s at 512^2; its per-pixel paths, 3.5-4.5 ms of the 0.02-
 * 0.04 s still view left after the lookups). Only while nothing is traced:
 * the tracer would lose the cores. Returns whether any is left (false:
 * done, or nothing to do); a camera step meanwhile makes them the next
 * camera's. */
bool ps_session_prepare_still(ps_session *s, size_t max_vertices);
/* Vertices a call while the window waits: 2-3 ms, its events polled between. */
#define PS_SESSION_PREPARE_VERTICES 1024
/* The per-pixel paths' time a call, as the vertices'. */
#define PS_SESSION_PREPARE_SECONDS 0.002

/* After a moving camera's picture, the next refresh is due this share of tau
 * later (else a tau): a camera step before then draws its own picture at
 * once (the window and snap's scripts refresh on a camera move), so that
 * refresh finds the camera stopped and draws the full view. Longer than an
 * orbit's steps 0.05 s apart (a quarter of tau after the picture ended let
 * still views come between them: the orbit drew 37-52 moving frames of its
 * 60 steps, against 60 at this share); with baked
 * maps (settings.bake) the full view over 10^6 photons at 512^2 is one
 * refresh, and waiting a whole tau for it was most of its return after an
 * orbit (0.14 s). */
#define PS_SESSION_STILL_SHARE 0.6
/* When the next refresh is due after the one at `at` (the caller's clock, the
 * instant it counts tau from): at + tau, or at + PS_SESSION_STILL_SHARE tau
 * after a moving camera's picture. */
double ps_session_next_refresh(const ps_session *s, double at);

/* The direct layer as the next refresh draws it (ps_session_frame.direct_exposure
 * and .direct). */
void ps_session_direct_view(const ps_session *s, double *exposure, bool *direct);

/* Whether everything is shown: no edit or new view pending, and every map at
 * its end and drawn (and baked, where settings.bake lays it), or tracing
 * held for good (paused, counter stopped). */
bool ps_session_settled(ps_session *s);
/* Whether the next refresh has work besides the photons that arrived: an
 * edit or a new view to draw, lights to rebuild (ps_session_refine_lights),
 * a bake to start or lay (once the feed is over). A caller may wait for
 * photons only when not (photosplat-snap's float checkpoints). */
bool ps_session_work_pending(ps_session *s);

/* ---- settings ----------------------------------------------------------------- */

const ps_session_settings *ps_session_get_settings(const ps_session *s);
void ps_session_set_layers(ps_session *s, unsigned layers);
void ps_session_set_splat(ps_session *s, ps_splat_mode mode);
ps_status ps_session_set_kernel(ps_session *s, ps_kernel kernel, ps_error *err);
void ps_session_set_precision(ps_session *s, ps_precision precision);
void ps_session_set_exposure(ps_session *s, double exposure);
/* Map k's r0; radius <= 0 leaves it. */
void ps_session_set_radius(ps_session *s, ps_map_kind k, double radius);
void ps_session_set_tau(ps_session *s, double tau);
/* Whole refreshes draw of map k at most most[k] photons emitted: the prefix
 * up to the last batch the feed handed over within it (at least one batch),
 * scaled by N / n for the photons it holds, so an unbiased picture of fewer
 * photons. NULL, or HUGE_VAL (the default): all of them. For a refresh that
 * must end by a time (photosplat-snap's 8-bit checkpoints: a redraw of
 * every photon took seconds). The illumination maps keep all theirs.
 * Incremental refreshes ignore it. */
void ps_session_set_whole_most(ps_session *s, const double most[PS_MAP_COUNT]);
/* Incremental refreshes draw at most this share of their budget of new
 * splats (at least one batch a map still), and the illumination maps take
 * this share of theirs, until set again: 1, the default, is the whole
 * budget. For a refresh that must end by a time with little
 * room for the budget's error (photosplat-snap's float checkpoints: the
 * splat rate the budget comes from varied 2x from one refresh to the next,
 * and a refresh meant to take 0.09 s of splats took 0.15). Whole refreshes
 * ignore it (ps_session_set_whole_most). */
void ps_session_set_budget_share(ps_session *s, double share);
/* Splats or illumination maps for the global layer; the maps are made (and
 * checked against the memory budget) when first asked for. */
ps_status ps_session_set_global_layer(ps_session *s, ps_global_layer g, ps_error *err);
/* The illumination maps (NULL unless --global-layer maps). */
const ps_illummap *ps_session_illummap(const ps_session *s);

/* Illuminance mode (for lux: --illuminance, the window's false colour): every
 * surface drawn as white Lambertian (albedo 1, ps_session_materials), so that
 * a pixel's radiance is the irradiance E / pi arriving where it looks,
 * whatever the surface's own material; at exposure 1, in float (no 8-bit
 * handling, the smooth kernel: re-upload ps_session_kernel), and the emitters
 * looked through, as the reference renderer's illuminance does. Starts a new
 * view; the photons stay. */
ps_status ps_session_set_illuminance(ps_session *s, bool on, ps_error *err);
bool ps_session_illuminance(const ps_session *s);
/* The materials splats and GL draw with: the scene's, or in illuminance mode
 * white Lambertian ones (as many, in the same order). */
const ps_material *ps_session_materials(const ps_session *s);

/* ---- edits ------------------------------------------------------------------------
 * Each checks its arguments as the scene's edits do (scene.h: an error names
 * the scene line, and leaves everything as it was) and marks what it
 * invalidates; ps_session_update then rebuilds it. With settings.repair the
 * maps keep every photon the edits cannot have changed and retrace the rest
 * first (preview/repair.h), exactly: once traced to the caps, the maps equal
 * a fresh trace of the edited scene photon for photon; else both maps
 * restart from photon 0. */
ps_status ps_session_move_light(ps_session *s, size_t light, ps_vec3 position, ps_error *err);
ps_status ps_session_move_object(ps_session *s, size_t object, ps_vec3 delta, ps_error *err);
ps_status ps_session_set_light_power(ps_session *s, size_t light, ps_rgb power, ps_error *err);
ps_status ps_session_set_spot_angle(ps_session *s, size_t light, double degrees, ps_error *err);
/* The scene made equal to `snapshot` again (ps_scene_restore): an edit like
 * the others, how undo and redo (preview/history.h) go back exactly. */
ps_status ps_session_restore_scene(ps_session *s, const ps_scene *snapshot, ps_error *err);

/* What ps_session_update rebuilt, for the drawing side to follow. */
typedef struct ps_session_changes {
    bool geometry; /* meshes are new (ps_session_mesh, _coarse_mesh, _moving_mesh); the lights always are */
} ps_session_changes;
/* Whether edits wait for ps_session_update. */
bool ps_session_edited(const ps_session *s);
/* Applies pending edits: new world and meshes if geometry moved, new lights,
 * new maps from photon 0 (traced as ps_session_start(held) does once the
 * session has been started). Number of edits so far: ps_session_edits. */
ps_status ps_session_update(ps_session *s, ps_session_changes *changes, ps_error *err);
uint64_t ps_session_edits(const ps_session *s);
/* Whether the edits come from a drag (the window's mouse held on a light or
 * an object, or a held key's repeats: an edit a refresh): their first
 * refreshes keep the budget's prefix (PS_SESSION_EDIT_SPLATS_WHOLE), so the
 * drag stays interactive. */
void ps_session_set_dragging(ps_session *s, bool dragging);

/* ---- what it holds ------------------------------------------------------------ */

const ps_scene *ps_session_scene(const ps_session *s);
const ps_world *ps_session_world(const ps_session *s);
const ps_preview_mesh *ps_session_mesh(const ps_session *s);        /* fine: lit passes */
const ps_preview_mesh *ps_session_coarse_mesh(const ps_session *s); /* the scene's own triangles: depth only */
/* Lit passes of a level of detail (mesh.h, ps_mesh_moving_options): while
 * the camera moves, and while the lights are a coarse level
 * (ps_session_lights_coarse). The fine mesh where a lighter one would not
 * save much, or in sessions that draw neither (a fixed count's whole
 * refreshes). */
const ps_preview_mesh *ps_session_moving_mesh(const ps_session *s);
const ps_preview_lights *ps_session_lights(const ps_session *s);
const ps_kernel_texture *ps_session_kernel(const ps_session *s);
const ps_tracer *ps_session_tracer(const ps_session *s);
/* The specular layer's lookups over the fine mesh (preview/specular.h). */
struct ps_specular *ps_session_specular(ps_session *s);
/* The drawing side shows cube map `cube` rendered from `centre` now: its
 * lookups and per-pixel points look from there (ps_specular_set_lookup_centre:
 * re-aimed, nothing traced). Kept across edits that rebuild the lookups,
 * while the cubes stay the same in number (the maps shown are the old ones
 * until new ones are whole). */
void ps_session_set_specular_centre(ps_session *s, int cube, ps_vec3 centre);
/* For the specular layer's cube maps: map k's photons so far (at most
 * max_photons, a prefix ending at a feed mark, scaled by N / n to radiance
 * at exposure 1) as triangle splats seen from `view` (photons behind its eye
 * plane are left out), at the radius of that many photons (the schedule's)
 * grown by sqrt(arrived / drawn) (at most PS_RADIUS_GROWTH_MAX, and never
 * past the larger map radius); *radius: that radius. Empty when map k's layer is off. Briefly holds the
 * lock. */
ps_status ps_session_env_splats(ps_session *s, ps_map_kind k, const ps_camera_frame *view, size_t max_photons,
                                ps_splat_batch *b, double *radius, ps_error *err);
/* The pixels those splats (max_photons[k] of map k) would cover on each face
 * of a cube map at `centre` with faces face_side pixels square, none hidden:
 * each splat's disc as seen along the face's axis, at most a face, summed
 * per face in cube map order (+x, -x, +y, -y, +z, -z). What a face's time
 * grows with (gl_specular.h): the default box's face over the caustic under
 * its mirror sphere covers 5*10^6 such pixels, the others 0.2-1.1*10^6. */
void ps_session_env_fill(ps_session *s, ps_vec3 centre, int face_side, const size_t max_photons[PS_MAP_COUNT],
                         double fill[6]);
/* A count that changes whenever the maps hold other photons, or the same in
 * another order, than a prefix of what they held (a new feed, a repair, the
 * repair's end putting a map back in index order): what was made from the
 * maps (the specular layer's cube maps) is to be made again. */
uint64_t ps_session_maps_epoch(const ps_session *s);
/* Whether map k's layer is drawn from its baked textures (bake.h) from now
 * on; *texels: theirs (0 when not). */
bool ps_session_baked(const ps_session *s, ps_map_kind k, size_t *texels);
/* How far map k's bake is laid: the share of its photons in the textures
 * (1 once drawn from them), or -1 when it is not being baked (not planned
 * yet, refused, or settings.bake off). */
double ps_session_bake_progress(const ps_session *s, ps_map_kind k);
/* Map k's splat radius for the last refresh (under the radius schedule). */
double ps_session_radius(const ps_session *s, ps_map_kind k);

/* Counts, read under the feed's lock: the one call that work beside the
 * first round (ps_session_start_beside) may make. */
typedef struct ps_session_counts {
    ps_trace_counters map[PS_MAP_COUNT];
    bool ended;          /* every map at its cap, stopped, or failed */
    bool store_limited;  /* ended at the store limit */
    double trace_seconds;/* the feed's time tracing */
    double map_bytes;    /* what the maps hold allocated */
    double splat_seconds;/* building splats, all refreshes */
    double ahead_seconds;/* of that, the first refresh's done before it, beside the first round
                          * (ps_session_start_beside: the illumination maps' first gathering) */
    uint64_t refreshes;
} ps_session_counts;
void ps_session_get_counts(ps_session *s, ps_session_counts *out);
/* The maps; only while tracing is stopped (after trace_all or stop). */
const ps_photon_map *ps_session_maps(const ps_session *s);
/* The maps under the feed's lock, while tracing may go on (a script's dump
 * photons); unlock soon. */
const ps_photon_map *ps_session_lock_maps(ps_session *s);
void ps_session_unlock_maps(ps_session *s);
/* What the last ps_session_update did: whether it repaired (else restarted),
 * and per map the photon indices kept and those to retrace (zeros until the
 * tracing thread has tested every index: see ps_feed_repair_ahead). */
void ps_session_repair_counts(const ps_session *s, bool *repaired, uint64_t kept[PS_MAP_COUNT],
                              uint64_t retraced[PS_MAP_COUNT]);
/* Every ps_session_update's together: how many repaired, and per map the
 * photon indices kept and retraced (the last repair's are whole once
 * ps_session_stop has returned). */
void ps_session_repair_totals(const ps_session *s, uint64_t *repairs, uint64_t kept[PS_MAP_COUNT],
                              uint64_t retraced[PS_MAP_COUNT]);

#endif
