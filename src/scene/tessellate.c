/* tessellate.c: latitude-longitude sphere meshes with a bounded sagitta. */
#include "scene/tessellate.h"

#include <stdlib.h>
#include <string.h>

/* Below this many segments the mesh stops looking like a sphere at all. */
#define MIN_SLICES 8
/* Keeps the vertex count far inside uint32 and memory modest. */
#define MAX_SLICES 4096

void ps_trimesh_free(ps_trimesh *m)
{
    if (!m)
        return;
    free(m->positions);
    free(m->normals);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

/* Longitude segments for a tolerance in (0, 0.5]. */
static int sphere_slices(double tolerance)
{
    /* A chord spanning angle a lies r(1 - cos(a/2)) inside the sphere. A flat
     * triangle's centre lies deeper than its edges' midpoints; a quad cell of
     * angular size a x a is at most about r(1 - cos(a/sqrt2)) deep, so solve
     * for a with the cell's half-diagonal. */
    double a = sqrt(2.0) * acos(1.0 - tolerance);
    double slices = ceil(2.0 * PS_PI / a);
    return slices < MIN_SLICES ? MIN_SLICES : slices > MAX_SLICES ? MAX_SLICES : (int)slices;
}

uint32_t ps_sphere_triangle_count(double tolerance)
{
    if (!(tolerance > 0.0 && tolerance <= 0.5))
        return 0;
    int slices = sphere_slices(tolerance), stacks = (slices + 1) / 2;
    return 2u * (uint32_t)slices * (uint32_t)(stacks - 1);
}

ps_status ps_sphere_tessellate(ps_vec3 center, double radius, double tolerance, ps_trimesh *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(radius > 0.0) || !(tolerance > 0.0 && tolerance <= 0.5))
        return ps_error_set(err, PS_ERR_RANGE, "sphere tessellation: radius %g or tolerance %g out of range", radius,
                            tolerance);
    int slices = sphere_slices(tolerance);
    int stacks = (slices + 1) / 2;
    /* Ring vertices of stacks-1 latitude rings, plus the two poles. */
    uint32_t nv = (uint32_t)(stacks - 1) * (uint32_t)slices + 2;
    uint32_t nt = 2u * (uint32_t)slices * (uint32_t)(stacks - 1);
    out->positions = malloc(sizeof *out->positions * nv);
    out->normals = malloc(sizeof *out->normals * nv);
    out->indices = malloc(sizeof *out->indices * 3 * nt);
    if (!out->positions || !out->normals || !out->indices) {
        ps_trimesh_free(out);
        return ps_error_set(err, PS_ERR_NOMEM, "sphere tessellation: out of memory");
    }
    /* Vertex 0: north pole (+y); ring i (1..stacks-1), slice j at 1 + (i-1)*slices + j; last: south pole. */
    uint32_t v = 0;
    out->normals[v++] = ps_v3(0, 1, 0);
    for (int i = 1; i < stacks; i++) {
        double theta = PS_PI * i / stacks;
        for (int j = 0; j < slices; j++) {
            double phi = 2.0 * PS_PI * j / slices;
            out->normals[v++] = ps_v3(sin(theta) * cos(phi), cos(theta), -sin(theta) * sin(phi));
        }
    }
    out->normals[v++] = ps_v3(0, -1, 0);
    for (uint32_t k = 0; k < nv; k++)
        out->positions[k] = ps_v3_madd(center, out->normals[k], radius);

    uint32_t *ix = out->indices;
    uint32_t south = nv - 1, S = (uint32_t)slices;
#define RING(i, j) (1u + ((uint32_t)(i) - 1u) * S + ((uint32_t)(j) % S))
    for (uint32_t j = 0; j < S; j++) { /* north cap */
        *ix++ = 0;
        *ix++ = RING(1, j);
        *ix++ = RING(1, j + 1);
    }
    for (int i = 1; i + 1 < stacks; i++) {
        for (uint32_t j = 0; j < S; j++) {
            uint32_t a0 = RING(i, j), a1 = RING(i, j + 1), b0 = RING(i + 1, j), b1 = RING(i + 1, j + 1);
            *ix++ = a0;
            *ix++ = b0;
            *ix++ = b1;
            *ix++ = a0;
            *ix++ = b1;
            *ix++ = a1;
        }
    }
    for (uint32_t j = 0; j < S; j++) { /* south cap */
        *ix++ = south;
        *ix++ = RING(stacks - 1, j + 1);
        *ix++ = RING(stacks - 1, j);
    }
#undef RING
    out->vertex_count = nv;
    out->triangle_count = nt;
    return PS_OK;
}
