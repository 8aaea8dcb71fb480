/* bake.h: a complete map's splats laid once into textures on its quads, so
 * that a new view draws the textures instead of every splat again (issue 20:
 * "the full picture back within one tau of the last camera step"). GL-free:
 * the plan and the splats; src/gl draws them into the textures and the
 * textures into the view.
 *
 * Why: llvmpipe sets up 1.2-1.4*10^6 triangle splats a second on 2 cores, so
 * the view after an orbit over 1.17*10^6 photons came back 0.85-0.95 s after
 * the camera stopped however the refreshes were scheduled (docs/preview.md).
 * A splat on a Lambertian surface shows dPhi * albedo / pi / (C pi r^2) over
 * its disc whatever the eye (splat.h): only the side it shows, its lift
 * toward the eye and its clipping to the object's pixels depend on the view.
 * On a quad, the splats are triangles in the quad's plane, so drawn in the
 * quad's own (u, v) coordinates they sum to the layer's value at every point
 * of the quad; a view then draws the quad with that texture.
 *
 * Thesis departure: the thesis splats every photon into the frame for each
 * view. Here the picture of a finished map (every photon traced) is sampled
 * at texels of r / PS_BAKE_TEXELS_PER_RADIUS and filtered bilinearly instead
 * of at the view's pixels, which blurs it a little where a pixel is smaller
 * than a texel (the eye close to the surface). Only where every photon of the
 * map lies on a quad with a diffuse (Lambertian) material: a glossy lobe
 * depends on the eye, and a curved surface's splats are not in one plane;
 * elsewhere the map is splatted as before. */
#ifndef PS_PREVIEW_BAKE_H
#define PS_PREVIEW_BAKE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "photon/photon.h"
#include "preview/splat.h"
#include "scene/scene.h"

/* Texels a splat radius: the kernel (a cone: one kink at its centre) sampled
 * 8 texels across, bilinearly; a splat then covers about 80 texels. */
#define PS_BAKE_TEXELS_PER_RADIUS 4.0
/* A texture's side at most (a quad wider than this many quarter radii is
 * not baked: coarser texels would blur its splats), and at least. */
#define PS_BAKE_MAX_SIDE 2048
#define PS_BAKE_MIN_SIDE 8
/* A map's textures hold at most this many texels in all (RGBA32F: 128 MiB);
 * a map that would need more is splatted as before. */
#define PS_BAKE_MAX_TEXELS ((size_t)1 << 23)

/* A quad's side that photons of the map lie on. Texture coordinates (u, v)
 * run from (0, 0) at corner to (1, 1) at corner + edge1 + edge2. */
typedef struct ps_bake_target {
    uint32_t object;
    int side;             /* 0: the side edge1 x edge2 points to; 1: the other */
    ps_vec3 corner, edge1, edge2;
    int width, height;    /* texels along edge1 and edge2 */
} ps_bake_target;

typedef struct ps_bake ps_bake;

ps_status ps_bake_create(ps_bake **out, ps_error *err);
void ps_bake_destroy(ps_bake *b); /* accepts NULL */

/* Plans a map's textures: the photons [0, count) (parallel arrays, as in
 * ps_photon_map) at splat radius `radius`, the scene's quads where they are
 * now. *covered: whether every photon lies on a quad whose material (in
 * `materials`, indexed by the photons' ids) is diffuse, and the texels fit
 * PS_BAKE_MAX_TEXELS and each side PS_BAKE_MAX_SIDE; the targets are then
 * the quads' sides that hold photons. PS_ERR_NOMEM leaves no targets. */
ps_status ps_bake_plan(ps_bake *b, const ps_scene *scene, const ps_material *materials, const ps_photon *photons,
                       const uint16_t *ids, const uint32_t *objects, size_t count, double radius, bool *covered,
                       ps_error *err);
size_t ps_bake_target_count(const ps_bake *b);
const ps_bake_target *ps_bake_targets(const ps_bake *b);
/* Texels of all targets. */
size_t ps_bake_texels(const ps_bake *b);

/* The splats of photons [from, to) (all on the planned targets), each
 * target's in a batch of its own (cleared first), laid on the surface
 * (ps_splat_params.surface): p gives the mode (triangles), radius, kernel,
 * scale and materials; its cam and objects are the bake's. */
ps_status ps_bake_build(ps_bake *b, const ps_photon *photons, const uint16_t *ids, const uint32_t *objects,
                        size_t from, size_t to, const ps_splat_params *p, ps_error *err);
/* Target t's splats from the last build. */
const ps_splat_batch *ps_bake_batch(const ps_bake *b, size_t t);
/* Splats in the last build, all targets. */
size_t ps_bake_splats(const ps_bake *b);

/* ---- the direct light on diffuse quads (src/gl: ps_gl_options.bake_direct) ---- */

/* The direct layer (the lit passes: each light's Gouraud-interpolated
 * diffuse term times its shadow test) on a Lambertian quad is the same
 * whatever the eye, too: src/gl lays it once into a texture a quad side and
 * draws the textures for every view until the lights, the geometry or the
 * materials change. Its texels: the scene's bounding-box diagonal over
 * this many (the default box's 2 m walls 592 a side, 3.4 mm, where a pixel
 * of its 512^2 view covers 4-6 mm). */
#define PS_BAKE_DIRECT_TEXELS_PER_DIAG 1024.0

/* Both sides of every quad whose material (materials, indexed by the
 * scene's ids) is diffuse, where the quad is now, texels along each edge as
 * above (at least PS_BAKE_MIN_SIDE, at most PS_BAKE_MAX_SIDE: a larger quad
 * gets coarser texels), into *out (free()), *count of them; none (*count 0)
 * when they would hold more than PS_BAKE_MAX_TEXELS texels in all. */
ps_status ps_bake_direct_targets(const ps_scene *scene, const ps_material *materials, ps_bake_target **out,
                                 size_t *count, ps_error *err);

#endif
