/* emit.h: where photons leave the lights, and in which directions.
 *
 * Each light emits with its own distribution (contract, "Lights"):
 *   point   uniform over the sphere of directions
 *   spot    uniform inside its cone (constant intensity)
 *   quad, disc, mesh (MTL Ke faces)
 *           uniform position, cosine-weighted direction about the emitting side
 *   sphere  uniform position on the sphere, cosine-weighted about the outward normal
 *   ies     from its position, directions with the density of its candela table exactly
 *
 * Caustic photons are emitted only inside caustic cones (thesis 4.1.1): from
 * the light around a specular object's bounding sphere, that sphere's radius
 * widened by the light's own bounding radius, so the caustic cone holds every
 * direction from any point of the light towards the object. Inside a caustic
 * cone, directions are uniform and each photon's power is the flux the light
 * sends into it, estimated from that one sample: E[power] over the caustic
 * cone equals that flux exactly. */
#ifndef PS_PHOTON_EMIT_H
#define PS_PHOTON_EMIT_H

#include <stdbool.h>
#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"
#include "scene/scene.h"

/* A caustic cone: the directions from a light towards one specular object,
 * those within acos(cos_half) of the unit axis. cos_half <= -1 is every
 * direction (the light is inside the object's widened bounding sphere).
 * Not the spot light's own cone (ps_light.cos_angle). */
typedef struct ps_caustic_cone {
    ps_vec3 axis;
    double cos_half;
} ps_caustic_cone;

/* What one emitted photon is: where it starts, where it goes, what it carries.
 * power is in watts for one photon that stands for all of the light's flux
 * (or of the flux into the caustic cone); the tracer divides by the photon count. */
typedef struct ps_emission {
    ps_ray ray;     /* unit direction */
    ps_rgb power;   /* the light's power times weight */
    double weight;  /* what the sample carries of the light's power, whatever that power is:
                     * the tracer carries it apart from the power, so that a power or colour
                     * edit is an exact rescale (docs/repair.md) */
    ps_vec3 normal; /* the emitter's normal at the origin (0 for point and spot) */
} ps_emission;

/* Per-scene data for sampling its lights: face tables of mesh lights and each
 * light's bounding sphere. Immutable once made; safe to share between threads. */
typedef struct ps_light_sampler ps_light_sampler;

ps_status ps_light_sampler_create(const ps_scene *s, ps_light_sampler **out, ps_error *err);
void ps_light_sampler_destroy(ps_light_sampler *ls);

/* The smallest sphere we know around light l: radius 0 for point and spot. */
void ps_light_bounding_sphere(const ps_light_sampler *ls, uint32_t l, ps_vec3 *center, double *radius);

/* The caustic cone from light l around the sphere (center, radius). False when
 * no photon of the light can reach the sphere at all (it lies wholly behind a
 * one-sided light or outside a spot's cone): then no caustic photons go there. */
bool ps_light_caustic_cone(const ps_light_sampler *ls, uint32_t l, ps_vec3 center, double radius,
                           ps_caustic_cone *out);

/* Roughly which fraction of light l's flux goes into the caustic cone; used
 * only to share photons between caustic cones (the photon powers make the
 * estimate exact anyway). */
double ps_light_caustic_cone_share(const ps_light_sampler *ls, uint32_t l, const ps_caustic_cone *caustic);

/* Emits one photon from light l using the four numbers u in [0, 1): u[0], u[1]
 * choose the point on the light, u[2], u[3] the direction. caustic == NULL:
 * the light's own distribution. False when the sample carries no power (a
 * direction in the caustic cone that the light does not emit into); it still
 * counts as emitted, which is what keeps the estimate unbiased. */
bool ps_light_emit(const ps_light_sampler *ls, uint32_t l, const ps_caustic_cone *caustic, const double u[4],
                   ps_emission *out);

/* A point on area light l (quad, disc, sphere, mesh) and the unit normal of
 * its emitting side there, uniform over its area, from u0, u1 in [0, 1). For
 * the reference renderer's shadow rays: density 1 / light area. */
void ps_light_sample_point(const ps_light_sampler *ls, uint32_t l, double u0, double u1, ps_vec3 *p, ps_vec3 *n);

#endif
