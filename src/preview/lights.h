/* lights.h: the scene's lights as fixed-function GL can draw them, GL-free.
 *
 * GL lights are points: a point light is one, a spot one with a cone, and an
 * area light (quad, disc, emissive mesh) becomes PS_PREVIEW_AREA_SAMPLES
 * virtual point lights spread over its area in strata, each a cosine emitter
 * (GL spot, cutoff 90, exponent 1). The radiometry, in the reference
 * renderer's units (src/gl draws these numbers as they are):
 *   point  P / (4 pi)                     W/sr in every direction
 *   spot   P / (2 pi (1 - cos angle))     W/sr inside the cone, constant
 *   area   P / (pi * samples) cos(theta)  W/sr for each of the samples
 *   sphere P / (4 pi) at its centre        (outside it a Lambertian sphere
 *                                          lights like a point)
 *   ies    P d_max, times a cube table of d(w) / d_max drawn per pixel,
 *          d the file's candela over its flux towards w (scene.h)
 * so that every light's virtual lights emit its flux P in all: pi I for a
 * cosine emitter, 4 pi I for a point. 16 samples keep the irradiance a
 * light's width away within about 1 % of the area integral (a midpoint
 * rule's error falls with the square of the stratum size), and each costs a
 * shadow cube.
 *
 * Besides the GL lights, the emitters the eye sees (quad, disc and sphere
 * lights drawn in their radiance; point and spot lights are invisible, as in
 * the reference renderer), and each GL light's shadow-cube near plane. */
#ifndef PS_PREVIEW_LIGHTS_H
#define PS_PREVIEW_LIGHTS_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "accel/accel.h"
#include "core/vec.h"
#include "preview/mesh.h"
#include "scene/scene.h"
#include "scene/tessellate.h"

#define PS_PREVIEW_AREA_SIDE 4 /* the strata of an area light: a 4 x 4 grid ... */
#define PS_PREVIEW_AREA_SAMPLES (PS_PREVIEW_AREA_SIDE * PS_PREVIEW_AREA_SIDE) /* ... 16 GL lights */

/* The six faces of a light's shadow cube, in GL's cube-map order: +x, -x,
 * +y, -y, +z, -z. */
#define PS_CUBE_FACES 6
extern const ps_vec3 ps_cube_face_axes[PS_CUBE_FACES];

/* A GL light: a scene light, or one virtual point light of an area light. */
typedef struct ps_preview_light {
    ps_vec3 pos;
    ps_vec3 dir;       /* unit axis of a spot or cosine emitter; zero when omnidirectional */
    double cutoff_deg; /* 180: omnidirectional; 90 with exponent 1: a cosine emitter */
    double exponent;   /* GL_SPOT_EXPONENT: 0 constant, 1 Lambertian */
    ps_rgb intensity;  /* W/sr along dir (all directions when omnidirectional) */
    unsigned faces;    /* the shadow-cube faces that can see light (bit f: face f) */
    double shadow_near;/* its shadow cube's near plane: see PS_SHADOW_NEAR_SHARE */
    uint32_t light;    /* the scene light it belongs to */
    int profile;       /* an IES light's table in ps_preview_lights.profiles, or -1 */
} ps_preview_light;

/* An IES luminaire's distribution as GL draws it: its relative intensity
 * over world directions as a cube map, to be looked up per pixel towards
 * (p - light) with texgen (GL normalises a cube map's direction itself).
 * Faces in GL's order (+x, -x, +y, -y, +z, -z), each PS_PREVIEW_PROFILE_SIZE
 * texels a side in GL's cube-map orientation, texel (i, j) at face
 * coordinates ((i + 0.5) / size, (j + 0.5) / size); values d(w) / d_max in
 * [0, 1] at 16 bits, so a direction at a hundredth of the peak is still kept
 * to 1.5 %. */
#define PS_PREVIEW_PROFILE_SIZE 64
typedef struct ps_preview_profile {
    int size;
    uint16_t *texels; /* 6 * size * size */
} ps_preview_profile;

/* The world direction of texel (i, j) of cube face f (GL's cube-map rules),
 * not normalised. */
ps_vec3 ps_cube_texel_direction(int f, int size, int i, int j);

/* A spot of constant intensity inside a cone narrower than a half-space (not
 * a cosine emitter, whose 90-degree "cone" is its own plane): GL's per-vertex
 * cutoff would show its edge in mesh-sized steps, so src/gl draws that edge
 * per pixel instead. */
static inline int ps_preview_light_is_spot(const ps_preview_light *v)
{
    return v->cutoff_deg < 90.0 && v->exponent == 0.0;
}

/* An area light as the eye sees it: quad (corner + edges), disc (centre,
 * normal, radius) or sphere (its tessellation), in its radiance. */
typedef struct ps_preview_emitter {
    ps_light_type type;
    ps_vec3 position, edge1, edge2, normal;
    double radius;
    ps_rgb radiance;
    ps_trimesh sphere; /* sphere lights only */
} ps_preview_emitter;

typedef struct ps_preview_lights {
    ps_preview_light *lights;
    size_t count;
    ps_preview_emitter *emitters;
    size_t emitter_count;
    ps_preview_profile *profiles;
    size_t profile_count;
    uint64_t shadow_faces; /* lit faces of all lights: the shadow maps drawn */
    int shadow_size;       /* their side in texels, as planned (0: no shadows) */
} ps_preview_lights;

/* The near plane of a shadow cube: this share of the distance from the light
 * to the nearest geometry (so nothing is clipped), but never nearer than
 * PS_SHADOW_NEAR_FRACTION of the scene's diagonal. Far is better: the shadow
 * test's slack lets light leak by slack * distance / near. */
#define PS_SHADOW_NEAR_SHARE 0.5
#define PS_SHADOW_NEAR_FRACTION 1e-4

/* The shadow maps' side in texels unless a program asks for another. */
#define PS_SHADOW_SIZE_DEFAULT 1024

/* What a shadow texel (24-bit depth, stored in 32 bits) and a sphere light's
 * mesh triangle (half a vertex of double position and normal, three 32-bit
 * indices) are planned at against the memory budget. */
#define PS_SHADOW_TEXEL_BYTES 4
#define PS_SPHERE_TRIANGLE_BYTES (24 + 3 * 4)

/* The GL lights and emitters of scene s, an area light as area_side x
 * area_side virtual lights (1 to PS_PREVIEW_AREA_SIDE: fewer draw the first
 * picture sooner, a shadow cube each). The near planes come from accel (the
 * scene's ray accelerator, ps_accel_nearest_distance: exact spheres, which
 * lie nearer than their tessellation, so nothing the depth pass draws is
 * clipped) or, given NULL, from brute force over `coarse` (its depth-only
 * mesh). shadow_size: the shadow maps' side in texels (src/gl draws them
 * at out->shadow_size), 0 for none;
 * their memory and the sphere meshes' are planned against the budget first
 * (PS_ERR_LIMIT names the scene). out is overwritten; on error it is empty. */
ps_status ps_preview_lights_build(const ps_scene *s, const ps_accel *accel, const ps_preview_mesh *coarse,
                                  int shadow_size, int area_side, ps_preview_lights *out, ps_error *err);
void ps_preview_lights_free(ps_preview_lights *l); /* and zero it; accepts a zeroed one */

/* Which shadow-cube faces can receive light from v: a face is left out only
 * when all of its directions lie outside the cone (a face's directions are
 * within acos(1/sqrt(3)) = 54.7 degrees of its axis). */
unsigned ps_preview_light_faces(const ps_preview_light *v);

/* The distance from p to the nearest triangle of mesh m (HUGE_VAL when it
 * has none): brute force over its triangles. */
double ps_preview_mesh_distance(const ps_preview_mesh *m, ps_vec3 p);

#endif
