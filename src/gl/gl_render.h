/* gl_render.h: the preview drawn with fixed-function OpenGL 1.x/2.x: the
 * scene lit by GL lights with shadow maps (the `direct` layer), and photon
 * splats on top (the `caustic` and `global` layers), in the same physical
 * units as the reference renderer, times the exposure.
 *
 * libpsgl only draws: what it draws is prepared GL-free in src/preview (the
 * meshes in mesh.h, the GL lights and their radiometry in lights.h, the
 * splats in splat.h, what each refresh draws in session.h). Plain gl* calls
 * only; the caller owns the context (src/gl/platform.h: OSMesa in
 * photosplat-snap, GLFW + libGL in the window) and must have made it current.
 *
 * Radiometry. A GL light of intensity I (lights.h) has quadratic attenuation
 * 1 and a diffuse material has GL diffuse albedo / pi, so a vertex gets
 * albedo / pi * I cos / d^2, the radiance the reference renderer's `direct`
 * term computes. Glossy highlights use GL's Blinn term with shininess 4e
 * (capped at 128) and colour specular (e + 2) / (2 pi): close to, not equal
 * to, the normalised Phong lobe.
 *
 * Shadows: each light renders its depth into a cube of six 90-degree shadow
 * maps (depth textures in framebuffer objects), and is drawn one cube face at
 * a time with ARB_shadow's depth compare fed by eye-linear texgen, the face's
 * half-space kept by a user clip plane; faces that cannot see any lit
 * direction (behind an area light, outside a spot cone) are skipped. Shadow
 * maps are kept until the lights or the geometry change. The code is split
 * by concern: gl_render.c (the renderer, the mesh, the frame), gl_lights.c
 * (GL lights, shadow cubes, spot cones, emitters), gl_splat.c (splats),
 * gl_layers.c (layers kept between refreshes and their composite). */
#ifndef PS_GL_GL_RENDER_H
#define PS_GL_GL_RENDER_H

#include <stdbool.h>

#include "core/status.h"
#include "image/image.h"
#include "photon/photon.h"
#include "preview/lights.h"
#include "preview/mesh.h"
#include "preview/session.h"
#include "preview/splat.h"
#include "scene/camera.h"
#include "scene/scene.h"

#define PS_GL_SHADOW_SIZE PS_SHADOW_SIZE_DEFAULT

typedef struct ps_gl_renderer ps_gl_renderer;

/* A GL entry point by name, from the program's platform
 * (ps_platform_gl_proc), for those its GL library need not export: OSMesa
 * exports no glQueryCounter. NULL where there is none. */
typedef void (*ps_gl_proc)(void);
typedef ps_gl_proc ps_gl_proc_lookup(const char *name);

typedef struct ps_gl_options {
    bool shadows;      /* default true */
    bool float_buffer; /* the colour buffer keeps floats: no clamping anywhere */
    int shadow_size;   /* shadow maps' side in texels where the lights plan none
                          (ps_preview_lights.shadow_size 0); 0: PS_GL_SHADOW_SIZE */
    bool whole_face_passes; /* tests: every object in every shadowed face's lit
                             * pass, mirrors and glass in every lit pass, and
                             * every triangle in each specular lookup's pass
                             * (default false: those outside the face's
                             * pyramid or its tiles, mirrors and glass, and
                             * triangles a lookup gives no light, all of which
                             * add nothing there, are left out: the same pixels) */
    bool bake_direct;       /* the direct light of diffuse quads from textures laid once
                             * (preview/bake.h, ps_gl_direct_bake_lay), which every view,
                             * moving ones too, draws until the lights, the geometry or
                             * the materials change (default false) */
    ps_gl_proc_lookup *gl_proc; /* the platform's lookup: with GL 3.3 or ARB_timer_query, the
                                 * shadow maps are timed by a GL timestamp at their end, and
                                 * the passes after them need not wait for them; NULL: by
                                 * waiting for them (glFinish) */
} ps_gl_options;

/* What the renderer draws, prepared GL-free; everything pointed to must
 * outlive the renderer or its next set_scene. */
typedef struct ps_gl_scene {
    const ps_preview_mesh *mesh;     /* fine: what lit passes draw */
    const ps_preview_mesh *coarse;   /* the same surfaces unsubdivided: depth-only passes */
    const ps_material *materials;    /* indexed by the meshes' ranges */
    const ps_preview_lights *lights; /* GL lights and visible emitters */
    ps_aabb bounds;                  /* of geometry and lights: near and far planes */
    bool hide_emitters;              /* look through emitters (illuminance mode) */
    const ps_scene *scene;           /* its textures (map_Kd), uploaded once; NULL: none */
    const ps_preview_mesh *moving;   /* lit passes of a level of detail (ps_session_moving_mesh):
                                      * while the camera moves; NULL: the fine one */
    bool coarse_lights;              /* the lights are a progressive level with more to come
                                      * (ps_session_lights_coarse): the eye's lit passes draw
                                      * `moving` while they stand, the camera still or not */
} ps_gl_scene;

/* A session's meshes, lights and materials as they stand (its illuminance
 * mode's white materials and hidden emitters included). */
ps_gl_scene ps_gl_scene_of(const ps_session *s);

/* The kernel texture is uploaded for the splats. Needs a current context. */
ps_status ps_gl_renderer_create(const ps_gl_scene *in, const ps_kernel_texture *kernel, const ps_gl_options *o,
                                ps_gl_renderer **out, ps_error *err);
void ps_gl_renderer_destroy(ps_gl_renderer *r);

/* New geometry or lights (after an edit): shadow maps are remade on the next
 * frame. PS_ERR_NOMEM leaves the renderer drawing no lights. */
ps_status ps_gl_renderer_set_scene(ps_gl_renderer *r, const ps_gl_scene *in, ps_error *err);
/* The kernel texture changed (another kernel). */
void ps_gl_renderer_set_kernel(ps_gl_renderer *r, const ps_kernel_texture *kernel);
/* Other materials for the same meshes (as many, in the same order), and
 * whether emitters are looked through; the shadow maps stay. */
void ps_gl_renderer_set_materials(ps_gl_renderer *r, const ps_material *materials, bool hide_emitters);

/* Starts a frame of width x height: clears, sets the camera, writes depth,
 * and draws the direct layer (GL lights times exposure) or, without it, the
 * scene in black so that it still hides what lies behind. */
void ps_gl_begin_frame(ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct);
/* A whole frame into the current framebuffer as a session's refresh says it
 * (photosplat-snap: no layers kept): the scene, then each map's splats. */
void ps_gl_draw_frame(ps_gl_renderer *r, const ps_camera_frame *cam, const ps_session_frame *f);
/* The same, with the splats finished before and after: *splat_seconds is
 * their time, the part of a whole frame that grows with the photons
 * (photosplat-snap's pace, app/pace.h). */
void ps_gl_draw_frame_timed(ps_gl_renderer *r, const ps_camera_frame *cam, const ps_session_frame *f,
                            double *splat_seconds);
/* The still view of cam (ps_gl_begin_frame: shadow maps, depth, direct
 * light, emitters) drawn now into the current framebuffer, for the next
 * ps_gl_draw_frame*: photosplat-snap's 8-bit buffer draws it while its first
 * round is traced (ps_session_start_beside), as ps_gl_layers_view_ahead the
 * float layers'. That frame, if it is a still one of the same camera,
 * exposure and direct flag with the same lights and shadows, draws only its
 * splats over it; any other view begun first (a cube face), or new inputs,
 * drop it. Nothing else may draw into the framebuffer in between. */
void ps_gl_draw_view_ahead(ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct);

/* Adds a batch of splats (preview/splat.h) to the frame, depth tested against
 * the scene, additively. point_size: the points' side in pixels; sprites take
 * their size from the splat radius and the camera. */
void ps_gl_draw_splats(ps_gl_renderer *r, const ps_splat_batch *b, ps_splat_mode mode, double radius,
                       double point_size);

/* The global layer's illumination maps (--global-layer maps): the fine mesh's
 * spans with surfaces in the maps (ps_session_frame.imap_spans) with their
 * per-vertex colours (.imap_colors, one RGBA a vertex), added to the frame,
 * depth tested against the scene (gl_illummap.c). NULL colours draw nothing. */
void ps_gl_draw_illummap(ps_gl_renderer *r, const float *colors, const ps_illum_span *spans, size_t span_count);

/* Waits until GL has drawn everything asked so far (llvmpipe draws when
 * flushed): for timing the drawing, not the queueing. */
void ps_gl_finish(void);

/* Reads width x height pixels of the current read framebuffer into out
 * (created here; row 0 the top) as floats, unclamped where GL_CLAMP_READ_COLOR
 * is off. */
ps_status ps_gl_read_pixels(int width, int height, ps_image *out, ps_error *err);
/* Reads the colour buffer into out (created here; row 0 the top), as stored:
 * radiance times exposure. */
ps_status ps_gl_read(ps_gl_renderer *r, ps_image *out, ps_error *err);

/* ---- layers kept between frames -------------------------------------------
 * The window refreshes incrementally (issue: a refresh draws only the photons
 * that arrived since the last one): the direct layer and each map's splats
 * live in their own textures behind framebuffer objects, sharing one
 * depth-stencil buffer that holds the view's prepass. With float buffers the
 * splats accumulate at their stored power and the composite scales each map
 * by N/n, so old splats never need redrawing; with 8-bit buffers that would
 * lose every faint photon (thesis 5.1), so the caller clears a map's layer
 * and redraws all of it, already scaled, each refresh (session.h says which).
 * The composite is drawn and encoded for display by GL (ps_gl_layers_show):
 * nothing comes back to the CPU but a screenshot. */
typedef struct ps_gl_layers ps_gl_layers;

/* The direct, map and shown layers get their texels here; the illumination
 * maps', the texture factor's and the linear composite's when first drawn
 * into, or at ps_gl_layers_reserve: a session may never draw them. */
ps_status ps_gl_layers_create(int width, int height, bool float_buffers, ps_gl_layers **out, ps_error *err);
void ps_gl_layers_destroy(ps_gl_layers *l);
/* The layers a session will draw made now, before its first picture, and
 * not in it: the illumination maps' (maps: --global-layer maps) and, where
 * r's scene has textures, the texture factor's. */
void ps_gl_layers_reserve(ps_gl_layers *l, const ps_gl_renderer *r, bool maps);
/* The bytes of the layers' texels made so far (the depth-stencil buffer
 * not counted). */
size_t ps_gl_layers_bytes(const ps_gl_layers *l);
/* A new view: the direct layer (times exposure) or black, the prepass, and
 * empty map layers. */
void ps_gl_layers_view(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct);
/* The same, ahead of the refresh that will ask for it (while the first
 * round is traced: ps_session_start_beside): the next ps_gl_layers_draw, if
 * its frame's new view is this still one (the same camera, exposure, direct
 * flag and renderer, its lights, shadow maps and direct light's textures
 * unchanged), does not draw it again; any other view, relight or splat
 * added in between drops it. Its lit passes come with that
 * ps_gl_layers_draw, after its splats (as every new view's there). */
void ps_gl_layers_view_ahead(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure,
                             bool direct);
/* Starts session s (ps_session_start_beside, its tracing held until the
 * first refresh is drawn) with the first picture's view of cam drawn into
 * the layers while the first round is traced (ps_gl_layers_view_ahead),
 * and, while the round is still traced after it, the illumination maps'
 * programs built (ps_gl_layers_prepare_maps): snap's float runs and the
 * window. */
ps_status ps_gl_layers_start(ps_gl_layers *l, ps_gl_renderer *r, ps_session *s, const ps_camera_frame *cam,
                             ps_error *err);
/* The illumination maps' pass (--global-layer maps) drawn once with nothing
 * to add, one black triangle into their layer, so that llvmpipe builds its
 * programs now, not in the first refresh that draws the maps: work for
 * time that would be spent waiting (ps_session_start_beside's spare). The
 * layers, and a view drawn ahead, are left as they were. */
void ps_gl_layers_prepare_maps(ps_gl_layers *l, ps_gl_renderer *r);
/* The direct layer alone drawn again for the same view (new lights, or the
 * direct light's textures just laid), the map layers kept. */
void ps_gl_layers_relight(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct);
void ps_gl_layers_clear_map(ps_gl_layers *l, int map);
/* Adds splats to a map's layer, tested against the view's depth and stencil. */
void ps_gl_layers_add(ps_gl_layers *l, ps_gl_renderer *r, int map, const ps_splat_batch *b, ps_splat_mode mode,
                      double radius, double point_size);
/* One refresh as a session says it (session.h): a new view if it asks, the
 * map layers cleared if it asks, and its splats added. */
void ps_gl_layers_draw(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, const ps_session_frame *f);
/* direct * direct_gain + sum of map * map_gain[map], drawn into the default
 * framebuffer (the window) with the display's encoding applied by GL: each
 * channel clamped to [0, 1] and sRGB-encoded to 8 bits (GL_FRAMEBUFFER_SRGB
 * into an sRGB texture, then copied as it is): the PNG encoder's codes
 * (image.h, ps_tonemap_8bit) but for the GL's own rounding (llvmpipe: up to
 * two codes apart, docs/preview.md). */
void ps_gl_layers_show(ps_gl_layers *l, double direct_gain, const double map_gain[PS_MAP_COUNT]);
/* The scaled show (a moving camera's or an edit's level of detail) drawn
 * once into the back buffer, so that its first real use costs its own time
 * only: the window's, in its first wait after its first picture (the next
 * show draws over the back buffer and the shown layer). */
void ps_gl_layers_warm_up(ps_gl_layers *l);
/* The same picture the way the window showed it before the composite moved
 * to GL: read back as floats, encoded on the CPU (ps_tonemap_8bit) and drawn
 * with glDrawPixels. Kept as the baseline scripts/bench-window.sh measures
 * ps_gl_layers_show against (the window's --composite cpu). */
ps_status ps_gl_layers_show_by_cpu(ps_gl_layers *l, double direct_gain, const double map_gain[PS_MAP_COUNT],
                                   ps_error *err);
/* An 8-bit RGB picture (rows bottom-up, as GL's) drawn into the default
 * framebuffer as it is: the window's false-colour mode. */
void ps_gl_show_rgb8(int width, int height, const uint8_t *rgb);
/* The same composite, linear, read back into out (created here; row 0 the
 * top): for tests. */
ps_status ps_gl_layers_composite(ps_gl_layers *l, double direct_gain, const double map_gain[PS_MAP_COUNT],
                                 ps_image *out, ps_error *err);

/* What ran: shadow maps made so far and lighting passes in the last frame;
 * the faces the last shadow-map pass rendered (only those whose depths can
 * have changed, gl_lights.c) and its seconds (0 when no pass ran since the
 * caller last reset them with ps_gl_clear_shadow_timing): from its start to
 * GL's end of it, which ps_gl_get_stats waits for if GL has not reached it
 * (timed by a timestamp, ps_gl_options.gl_proc). */
typedef struct ps_gl_stats {
    unsigned shadow_maps, light_passes, virtual_lights;
    uint64_t light_vertices; /* vertices the lit passes of the last frame drew */
    unsigned shadow_faces_last;
    double shadow_seconds_last;
    unsigned direct_bakes;   /* times the direct light's textures were laid (bake_direct) */
    bool direct_baked_last;  /* the last view's direct layer drew them */
    bool drawn_ahead_last;   /* the last ps_gl_draw_frame* drew over the view drawn ahead */
    uint64_t views;          /* views begun (ps_gl_begin_frame*: clear, prepass, direct light), all told */
} ps_gl_stats;
void ps_gl_clear_shadow_timing(ps_gl_renderer *r);
ps_gl_stats ps_gl_get_stats(ps_gl_renderer *r);

/* With bake_direct: the direct light of diffuse quads laid into their
 * textures (preview/bake.h), a quad side at a time for about max_seconds
 * (at least one side; HUGE_VAL: all), for exposure (the frames' direct
 * exposure) and the lights, geometry and materials as they stand, once a
 * frame has made every shadow map; anything changed meanwhile starts it
 * over. Returns whether it laid sides and more are left to lay; false when
 * all are laid, there are none, or it cannot lay yet (a shadow map not fresh:
 * the next frame makes them, and ps_gl_direct_bake_pending still says they
 * are to be laid). The window calls it while it would wait, nothing being
 * traced (snap does not bake the direct light): the default box's ten sides
 * took 0.11 s, the gallery's 42 0.63 s, which a still view laying them would
 * have waited for. */
bool ps_gl_direct_bake_lay(ps_gl_renderer *r, double exposure, double max_seconds);
/* Whether they are still to be laid for exposure and what stands now
 * (false without bake_direct, or with nothing to lay). */
bool ps_gl_direct_bake_pending(const ps_gl_renderer *r, double exposure);
/* Seconds a call while the window waits: a side or two of the default box. */
#define PS_GL_DIRECT_BAKE_STEP_SECONDS 0.01

#endif
