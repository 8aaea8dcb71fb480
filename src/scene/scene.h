/* scene.h: the scene model: camera, materials, geometry, lights and defaults,
 * as read from a .scn file (../shared/contract.md, docs/scene-format.md).
 *
 * A ps_scene is opaque: its arrays keep invariants (every index in range, every
 * number finite, light flux consistent with its geometry) that only the loader
 * establishes. Readers get const views; the arrays stay valid until destroy. */
#ifndef PS_SCENE_SCENE_H
#define PS_SCENE_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"

#define PS_NAME_MAX 64

/* Limits that keep absurd input from exhausting memory; each is refused with
 * PS_ERR_LIMIT and a message, never by a failed allocation midway. */
#define PS_SCENE_MAX_LIGHTS 100000
#define PS_SCENE_MAX_MATERIALS 65536 /* indices fit the photon maps' 16-bit material ids */
#define PS_SCENE_MAX_OBJECTS 1000000
#define PS_SCENE_MAX_TRIANGLES 50000000
#define PS_SCENE_MAX_IMAGE_SIDE 16384
#define PS_SCENE_MAX_PHOTONS 1000000000LL
/* The most flux a light may have, W per channel: a photon record's RGBE
 * power ends at 2^127 W (about 1.7e38), and three channels of more than
 * about 1e308 W no longer add up to a finite total. */
#define PS_SCENE_MAX_LIGHT_POWER 1e30
/* What a triangle is planned at against the memory budget (core/memory.h):
 * the scene's soup, the OBJ reader's text and copies, the ray accelerator
 * and the preview's mesh. Measured: 470 bytes a triangle at the peak of
 * photosplat-snap on a 980 000-triangle OBJ (320 for photosplat-ref). So
 * PS_SCENE_MAX_TRIANGLES fit only on a machine with about 32 GiB. */
#define PS_SCENE_PLAN_TRIANGLE_BYTES 512

typedef struct ps_camera {
    ps_vec3 eye, target, up; /* up need not be orthogonal to the view direction */
    double fov_deg;          /* vertical field of view, degrees, in (0, 180) */
} ps_camera;

typedef enum ps_material_type {
    PS_MAT_DIFFUSE,   /* Lambertian: albedo */
    PS_MAT_GLOSSY,    /* Lambertian albedo + normalised Phong lobe (specular, exponent) */
    PS_MAT_MIRROR,    /* perfect reflection scaled by reflectance */
    PS_MAT_DIELECTRIC /* smooth glass: Fresnel reflection + refraction with ior */
} ps_material_type;

typedef struct ps_material {
    char name[PS_NAME_MAX];
    ps_material_type type;
    ps_rgb albedo;        /* diffuse reflectance (diffuse, glossy); albedo + specular <= 1 */
    ps_rgb specular;      /* Phong reflectance (glossy) */
    double exponent;      /* Phong exponent (glossy) */
    ps_rgb reflectance;   /* mirror */
    double ior;           /* dielectric: index of refraction inside, air outside */
    ps_rgb transmittance; /* dielectric: colour of refracted light (1 = clear) */
    ps_rgb emission;      /* emitted radiance (MTL Ke), zero for non-emitters */
} ps_material;

/* Mirrors and dielectrics: what caustic photons are aimed at. */
static inline int ps_material_is_specular(const ps_material *m)
{
    return m->type == PS_MAT_MIRROR || m->type == PS_MAT_DIELECTRIC;
}

/* A triangle of the scene's one triangle soup. Vertices are per object (never
 * shared between objects) and each object's are one contiguous run of
 * ps_scene_positions, so moving an object moves only its own. */
typedef struct ps_triangle {
    uint32_t v[3];   /* indices into ps_scene_positions */
    int32_t n[3];    /* indices into ps_scene_normals, or -1: use the face normal */
    uint32_t material;
    uint32_t object;
} ps_triangle;

typedef enum ps_object_type {
    PS_OBJ_MESH,   /* triangles from an OBJ file */
    PS_OBJ_QUAD,   /* two triangles */
    PS_OBJ_SPHERE  /* analytic: no triangles; ps_sphere_tessellate for OpenGL */
} ps_object_type;

typedef struct ps_object {
    ps_object_type type;
    int line;          /* the scene line that made it, for messages */
    uint32_t first_triangle, triangle_count; /* mesh, quad */
    uint32_t material;                       /* quad, sphere; mesh: its override or its first face's */
    ps_vec3 center;                          /* sphere */
    double radius;                           /* sphere */
    ps_aabb bounds;
    int specular;      /* any of its surfaces is a mirror or dielectric */
} ps_object;

typedef enum ps_light_type {
    PS_LIGHT_POINT,
    PS_LIGHT_SPOT,
    PS_LIGHT_QUAD,
    PS_LIGHT_SPHERE,
    PS_LIGHT_DISC,
    PS_LIGHT_MESH, /* the faces of one mesh with one emissive MTL material (Ke > 0) */
    PS_LIGHT_IES   /* a point luminaire with an LM-63 candela table (scene/ies.h) */
} ps_light_type;

typedef struct ps_light {
    ps_light_type type;
    int line;            /* the scene line that made it */
    ps_rgb power;        /* total emitted flux, W per channel */
    ps_vec3 position;    /* point, spot: position; quad: corner; sphere, disc: centre */
    ps_vec3 direction;   /* unit: spot axis; quad and disc normal (the emitting side) */
    ps_vec3 edge1, edge2;/* quad */
    double radius;       /* sphere, disc */
    double angle_deg;    /* spot: half-angle of the cone, in (0, 90] */
    double cos_angle;    /* spot: cos(angle_deg) */
    double area;         /* emitting area (area lights; 0 for point and spot) */
    ps_rgb radiance;     /* area lights: emitted radiance, power / (pi * area) */
    uint32_t first_emitter, emitter_count; /* mesh: range in ps_scene_emitters */
    uint32_t object;     /* mesh: the object whose faces emit */
    /* ies: `direction` is the aim (the file's vertical angle 0, the nadir);
     * axis0 and axis90 are the unit directions of horizontal angles 0 and 90
     * (spin applied), so that vertical angle theta and horizontal angle phi
     * point along cos(theta) direction + sin(theta) (cos(phi) axis0 +
     * sin(phi) axis90). The intensity towards a direction is power times the
     * file's candela there over the file's total flux (ps_light_ies_density). */
    uint32_t profile;    /* ies: index of its table, ps_scene_ies_profile */
    double spin_deg;     /* ies: as given */
    ps_vec3 axis0, axis90;
} ps_light;

/* What programs use unless their options say otherwise (statements `image`,
 * `photons`, `radius`). Radii default to fractions of the scene's size. */
typedef struct ps_scene_defaults {
    int width, height;
    int64_t caustic_photons, global_photons;
    double caustic_radius, global_radius;
} ps_scene_defaults;

typedef struct ps_scene ps_scene;

typedef struct ps_scene_load_options {
    ps_warn_sink warn; /* where warnings go ({NULL, NULL}: stderr) */
} ps_scene_load_options;

/* Reads a .scn file and everything it refers to. On error returns the status,
 * sets err to "file:line: problem" and *out to NULL. opts may be NULL. */
ps_status ps_scene_load(const char *path, const ps_scene_load_options *opts, ps_scene **out, ps_error *err);

/* The same from text in memory; `name` stands for the file in messages and
 * paths in the text are relative to `base_dir` ("" for the current one). */
ps_status ps_scene_load_text(const char *text, const char *name, const char *base_dir,
                             const ps_scene_load_options *opts, ps_scene **out, ps_error *err);

void ps_scene_destroy(ps_scene *s); /* accepts NULL */

const char *ps_scene_path(const ps_scene *s);
const ps_camera *ps_scene_camera(const ps_scene *s);
const ps_scene_defaults *ps_scene_get_defaults(const ps_scene *s);
/* The box around all geometry and lights; what scene-scaled epsilons scale with. */
ps_aabb ps_scene_bounds(const ps_scene *s);

const ps_material *ps_scene_materials(const ps_scene *s, size_t *count);
const ps_vec3 *ps_scene_positions(const ps_scene *s, size_t *count);
const ps_vec3 *ps_scene_normals(const ps_scene *s, size_t *count); /* unit length */
const ps_triangle *ps_scene_triangles(const ps_scene *s, size_t *count);
const ps_object *ps_scene_objects(const ps_scene *s, size_t *count);
const ps_light *ps_scene_lights(const ps_scene *s, size_t *count);
/* Triangle indices of the faces of PS_LIGHT_MESH lights. */
const uint32_t *ps_scene_emitters(const ps_scene *s, size_t *count);

/* Total emitted flux of all lights, per channel. */
ps_rgb ps_scene_total_power(const ps_scene *s);
/* The same in lumens (core/photometry.h: 683 lm/W times its luminance). */
double ps_scene_total_lumens(const ps_scene *s);

/* The candela table of IES light profile index `profile` (ps_light.profile);
 * owned by the scene, valid until destroy. */
const struct ps_ies *ps_scene_ies_profile(const ps_scene *s, uint32_t profile);
size_t ps_scene_ies_profile_count(const ps_scene *s);
/* The unit world direction of an IES light's (vertical, horizontal) angles, radians. */
ps_vec3 ps_light_ies_direction(const ps_light *l, double theta, double phi);
/* The IES angles of unit world direction d from the light (inverse of the above). */
void ps_light_ies_angles(const ps_light *l, ps_vec3 d, double *theta, double *phi);
/* The density over solid angle (1/sr) with which IES light l emits towards
 * unit direction d: its candela there over its total flux. Its radiant
 * intensity is power times this. */
double ps_light_ies_density(const ps_scene *s, const ps_light *l, ps_vec3 d);
/* Area of triangle t. */
double ps_scene_triangle_area(const ps_scene *s, uint32_t t);
/* Unit geometric normal of triangle t (from its winding: (v1-v0) x (v2-v0)). */
ps_vec3 ps_scene_triangle_normal(const ps_scene *s, uint32_t t);

/* ---- editing (the preview window) ----------------------------------------------
 *
 * Edits keep every invariant the loader establishes: numbers finite, flux
 * consistent with geometry (area lights' radiance = power / (pi * area), a
 * spot's cos_angle = cos(angle_deg)), object bounds and the scene's bounds
 * (which include the lights) exact for the new geometry. The defaults
 * (ps_scene_get_defaults) stay as the file gave them, even those derived from
 * the scene's size: moving a light does not change the photon radii.
 *
 * Each edit checks its arguments (index in range, every number finite,
 * power >= 0, angle in (0, 90], results finite) and, on error, returns
 * PS_ERR_RANGE with one line naming the scene file, the scene line of the light
 * or object and its index as given here (from 0):
 *     "room.scn:12: light 3: angle 95 is not in (0, 90]"
 *     "room.scn: light 7 does not exist (the scene has 3 lights)"
 * and leaves the scene unchanged, byte for byte. On success err is cleared.
 * Edits are not synchronised: edit a scene no other thread reads (give the
 * window its own with ps_scene_clone). Views returned earlier stay valid. */

/* Moves a light's reference point as the scene file writes it (point and spot
 * `position`, quad `corner`, sphere and disc `center`) to `position`; the shape
 * moves with it, its edges, normal, radius, area and radiance unchanged. An
 * emissive mesh (PS_LIGHT_MESH) moves only with its object
 * (ps_scene_translate_object): refused. */
ps_status ps_scene_set_light_position(ps_scene *s, size_t light, ps_vec3 position, ps_error *err);

/* Sets a light's total flux (W per channel, each >= 0). Area lights get
 * radiance = power / (pi * area). An emissive mesh's faces shade with their
 * material's emission, so that material's emission becomes the new radiance
 * too (an emissive MTL material belongs to one mesh statement and so to this
 * light alone). */
ps_status ps_scene_set_light_power(ps_scene *s, size_t light, ps_rgb power, ps_error *err);

/* Sets a spot light's half-angle in degrees, in (0, 90], and its cos_angle.
 * Any other light type is refused. */
ps_status ps_scene_set_spot_angle(ps_scene *s, size_t light, double degrees, ps_error *err);

/* Moves an object by delta: a mesh's or quad's own vertices (normals
 * unchanged), a sphere's centre; then its bounds and the scene's. The emissive
 * mesh lights of the object move with it: their position (the centre of the
 * object's bounds), area (the sum of their faces' areas, recomputed) and power
 * (pi * area * radiance, as loaded). Refused when a coordinate would not be
 * finite, or when rounding at the new place would collapse a quad or an
 * emitting face to zero area (a delta far larger than the object). */
ps_status ps_scene_translate_object(ps_scene *s, size_t object, ps_vec3 delta, ps_error *err);

/* A deep copy, equal in every array and value, sharing nothing with s: the
 * window edits its copy while the photon tracer of the previous frame still
 * reads the old one. On failure (PS_ERR_NOMEM) *out is NULL. */
ps_status ps_scene_clone(const ps_scene *s, ps_scene **out, ps_error *err);

/* Writes the scene, as edited, to path as a .scn file that ps_scene_load
 * reads back to the same scene: every number (17 significant digits), every
 * material, object and light in the same order, the files it names relative
 * to path's directory (absolute when they share nothing below the root), the
 * edits to meshes and quads as `move` / `light-power` keys replayed on
 * loading. Lights are written with their flux (`power`), whatever the file
 * gave. Atomic (core/fileio.h): on error nothing appears under path. */
ps_status ps_scene_write(const ps_scene *scene, const char *path, ps_error *err);

const char *ps_material_type_name(ps_material_type t);
const char *ps_light_type_name(ps_light_type t);

#endif
