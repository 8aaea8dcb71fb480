/* gl_render.h: the preview drawn with fixed-function OpenGL 1.x/2.x: the
 * scene lit by GL lights with shadow maps (the `direct` layer), and photon
 * splats on top (the `caustic` and `global` layers), in the same physical
 * units as the reference renderer, times the exposure.
 *
 * Plain gl* calls only; the caller owns the context (OSMesa in
 * photosplat-snap, GLFW + libGL in the window) and must have made it current.
 *
 * Radiometry. A point light of flux P is a GL light of intensity P / (4 pi)
 * (spot: P over its cone's solid angle, GL_SPOT_EXPONENT 0) with quadratic
 * attenuation 1, and a diffuse material has GL diffuse albedo / pi, so a
 * vertex gets albedo / pi * I cos / d^2, the radiance the reference renderer's
 * `direct` term computes. Area lights become PS_GL_AREA_SAMPLES virtual point
 * lights spread over their area in strata, each a cosine-falloff GL spot
 * (cutoff 90, exponent 1) of intensity P / (pi * samples): 16 keep the
 * irradiance a light's width away within about 1 % of the area integral
 * (a midpoint rule's error falls with the square of the stratum size), and
 * every one costs a shadow map. Glossy highlights use GL's Blinn term with
 * shininess 4e (capped at 128) and colour specular (e + 2) / (2 pi): close to,
 * not equal to, the normalised Phong lobe.
 *
 * Shadows: each light renders its depth into a cube of six 90-degree shadow
 * maps (depth textures in framebuffer objects), and is drawn one cube face at
 * a time with ARB_shadow's depth compare fed by eye-linear texgen, the face's
 * half-space kept by a user clip plane; faces that cannot see any lit
 * direction (behind an area light, outside a spot cone) are skipped. Shadow
 * maps are kept until the lights or the scene change. */
#ifndef PS_GL_GL_RENDER_H
#define PS_GL_GL_RENDER_H

#include <stdbool.h>

#include "core/status.h"
#include "image/image.h"
#include "photon/photon.h"
#include "preview/mesh.h"
#include "preview/splat.h"
#include "scene/camera.h"
#include "scene/scene.h"

#define PS_GL_AREA_SAMPLES 16
#define PS_GL_SHADOW_SIZE 1024

typedef struct ps_gl_renderer ps_gl_renderer;

typedef struct ps_gl_options {
    bool shadows;      /* default true */
    bool float_buffer; /* the colour buffer keeps floats: no clamping anywhere */
    int shadow_size;   /* shadow maps' side in texels; 0: PS_GL_SHADOW_SIZE */
} ps_gl_options;

/* The scene's fine mesh for lighting (it must outlive the renderer; the
 * renderer makes its own coarse one for depth-only passes) and its lights; the kernel
 * texture is uploaded for the splats. Needs a current context. */
ps_status ps_gl_renderer_create(const ps_scene *s, const ps_preview_mesh *mesh, const ps_kernel_texture *kernel,
                                const ps_gl_options *o, ps_gl_renderer **out, ps_error *err);
void ps_gl_renderer_destroy(ps_gl_renderer *r);

/* Re-reads the lights (after an edit): their shadow maps are remade on the
 * next frame. */
void ps_gl_renderer_lights_changed(ps_gl_renderer *r);
/* The kernel texture changed (another kernel). */
void ps_gl_renderer_set_kernel(ps_gl_renderer *r, const ps_kernel_texture *kernel);

/* Starts a frame of width x height: clears, sets the camera, writes depth,
 * and draws the direct layer (GL lights times exposure) or, without it, the
 * scene in black so that it still hides what lies behind. */
void ps_gl_begin_frame(ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct);

/* Adds a batch of splats (preview/splat.h) to the frame, depth tested against
 * the scene, additively. point_size: the points' side in pixels; sprites take
 * their size from the splat radius and the camera. */
void ps_gl_draw_splats(ps_gl_renderer *r, const ps_splat_batch *b, ps_splat_mode mode, double radius,
                       double point_size);

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
 * and redraws all of it, already scaled, each refresh. The composite is read
 * back as radiance times exposure, for the same CPU encoding as snapshots. */
typedef struct ps_gl_layers ps_gl_layers;

ps_status ps_gl_layers_create(int width, int height, bool float_buffers, ps_gl_layers **out, ps_error *err);
void ps_gl_layers_destroy(ps_gl_layers *l);
/* A new view: the direct layer (times exposure) or black, the prepass, and
 * empty map layers. */
void ps_gl_layers_view(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct);
void ps_gl_layers_clear_map(ps_gl_layers *l, int map);
/* Adds splats to a map's layer, tested against the view's depth and stencil. */
void ps_gl_layers_add(ps_gl_layers *l, ps_gl_renderer *r, int map, const ps_splat_batch *b, ps_splat_mode mode,
                      double radius, double point_size);
/* direct * direct_gain + sum of map * map_gain[map], read back into out
 * (created here; row 0 the top). */
ps_status ps_gl_layers_composite(ps_gl_layers *l, double direct_gain, const double map_gain[PS_MAP_COUNT],
                                 ps_image *out, ps_error *err);

/* What ran: shadow maps made so far and lighting passes in the last frame. */
typedef struct ps_gl_stats {
    unsigned shadow_maps, light_passes, virtual_lights;
} ps_gl_stats;
ps_gl_stats ps_gl_get_stats(const ps_gl_renderer *r);

#endif
