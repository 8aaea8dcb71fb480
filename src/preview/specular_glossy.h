/* specular_glossy.h: glossy lobes in the `specular` layer (issue 15), GL-free.
 *
 * A glossy material (scene/bsdf.h: f = albedo / pi + specular (e + 2) /
 * (2 pi) cos^e(alpha), alpha off the mirror direction r) reflects from its
 * lobe
 *     L_o = specular (e + 2) / (2 pi) * integral of cos^e(alpha) cos(theta) L dw.
 * Writing cos(theta) = (n . r) cos(alpha) + (terms odd about r, which cancel
 * where L is smooth across the lobe) gives
 *     L_o = specular (n . r) * B_{e+1}(r),
 * B_m the environment convolved with the normalised lobe cos^m / (2 pi /
 * (m + 1)): in a furnace (L uniform) exactly specular (n . r) L, the
 * unclipped lobe's energy. The layer draws it so: every glossy object gets
 * an environment cube map of its own (preview/specular.h: one a specular
 * object, from the centre of its bounding box), a blurred level of it B_{e+1}
 * made on the CPU from the read-back faces (ps_glossy_filter, below), and per
 * vertex one lookup: the eye ray's mirror direction traced on as a mirror's
 * (through glass, distance-corrected), weighted specular (n . r).
 *
 * Departures (docs/preview.md): the part of the lobe below the surface is
 * not cut off (the reference's gather rays there see nothing): within 1 % of
 * the lobe's energy while the mirror direction is more than 2.4 / sqrt(e + 1)
 * radians above the horizon, more at grazing; the lobe's width is that seen
 * from the cube's centre, not from the vertex; a level is at most
 * PS_GLOSSY_MAX_LEVEL texels a side, so lobes narrower than about two of its
 * texels (e above about 500) are drawn that much wider. */
#ifndef PS_PREVIEW_SPECULAR_GLOSSY_H
#define PS_PREVIEW_SPECULAR_GLOSSY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"
#include "photon/world.h"
#include "preview/specular.h"
#include "scene/scene.h"

/* A blurred level's side at most (and at least PS_GLOSSY_MIN_LEVEL): one face
 * of 32^2 weighs 32^2 texels by the lobe over the tiles of the cube it
 * reaches. */
#define PS_GLOSSY_MAX_LEVEL 32
#define PS_GLOSSY_MIN_LEVEL 8
/* A level's texels per lobe width (full width at half maximum) at least. */
#define PS_GLOSSY_TEXELS_PER_WIDTH 4.0
/* Lobe terms below this fraction of the peak are left out of the sums. */
#define PS_GLOSSY_LOBE_FLOOR 1e-4

/* Whether the layer draws material m: mirrors, dielectrics, and glossy
 * materials with a lobe. */
bool ps_specular_wants(const ps_material *m);
/* Whether m is drawn in the layer as a glossy lobe. */
bool ps_glossy_wants(const ps_material *m);
/* The exponent of the normalised lobe a glossy material's level is blurred
 * with: e + 1 (the cos(theta) factor folded in, as above). */
double ps_glossy_lobe_exponent(const ps_material *m);
/* A level's side for lobe exponent m over cube faces of base_size. */
int ps_glossy_level_size(double m, int base_size);
/* Whether any range of sp is drawn as a glossy lobe. */
bool ps_glossy_any(const ps_specular *sp, const ps_preview_mesh *mesh, const ps_material *materials);
/* materials (n) with every glossy lobe the layer draws left out (specular
 * 0), for the splats while the layer shows: the lobe is the layer's. */
void ps_glossy_diffuse_materials(const ps_material *materials, size_t n, ps_material *out);

/* The materials the splats use while the layer shows (layer_on): where sp
 * draws a glossy lobe, materials with the lobes left out (in *store,
 * reallocated to n), else materials itself. */
ps_status ps_glossy_splat_materials(const ps_specular *sp, const ps_preview_mesh *mesh, const ps_material *materials,
                                    size_t n, bool layer_on, ps_material **store, const ps_material **out,
                                    ps_error *err);

/* The lookups of a glossy vertex (as ps_specular_trace_point's): the eye ray
 * from `eye` to p reflected about n and followed as from a mirror, each
 * term's weight times specular (n . r). */
int ps_glossy_trace_point(const ps_world *world, const ps_material *materials, const ps_material *m, ps_vec3 eye,
                          ps_vec3 p, ps_vec3 n, ps_vec3 centre, ps_specular_term out[PS_SPECULAR_TERMS],
                          double *dropped);

/* The unit direction through (s, t) in [0, 1]^2 of cube face f (GL's order
 * +X, -X, +Y, -Y, +Z, -Z; the GL spec's table of major axes). */
ps_vec3 ps_cube_dir(int face, double s, double t);

/* ---- the prefilter ----------------------------------------------------------- */

typedef struct ps_glossy_filter ps_glossy_filter;

/* A filter from faces of in_size^2 RGBA floats to a level of out_size^2
 * (out_size <= in_size) blurred with the normalised lobe cos^m. */
ps_status ps_glossy_filter_create(int in_size, int out_size, double m, ps_glossy_filter **out, ps_error *err);
void ps_glossy_filter_destroy(ps_glossy_filter *f); /* accepts NULL */
int ps_glossy_filter_out_size(const ps_glossy_filter *f);
double ps_glossy_filter_exponent(const ps_glossy_filter *f);
/* Face `face` of the input (in_size^2 RGBA, rows in t): kept, brought to
 * out_size by a tent (each input texel split bilinearly over the level
 * texels about it). Faces not given yet are black. */
void ps_glossy_filter_set_face(ps_glossy_filter *f, int face, const float *rgba);
/* Face `face` of the level (out_size^2 RGBA, alpha 1): each texel the
 * solid-angle weighted sum of the kept texels times cos^m of their angle
 * to it, over the sum of those weights. */
void ps_glossy_filter_face(const ps_glossy_filter *f, int face, float *rgba);

/* ---- the memory plan ------------------------------------------------------------ */

/* What the specular layer holds at most besides its lookups: cube maps of
 * cube_size (RGBA16F, two a cube: shown and being rendered) for
 * PS_SPECULAR_MAX_CUBES cubes, their blurred levels
 * (textures and the CPU's copies), and the layer texture of width x height
 * (RGBA32F). */
uint64_t ps_specular_plan_bytes(int cube_size, int width, int height);

#endif
