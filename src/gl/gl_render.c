/* gl_render.c: scene, lights, shadow maps and splats in fixed-function GL. */
#include "gl/gl_render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/memory.h"
#include "core/sampling.h"
#include "scene/tessellate.h"
#include "gl/gl_api.h"

/* The near plane of a shadow cube: this share of the distance from the light
 * to the nearest geometry (so nothing is clipped), but never nearer than
 * SHADOW_NEAR_FRACTION of the scene's diagonal. Far is better: the shadow
 * test's slack below lets light leak by slack * distance / near. */
#define SHADOW_NEAR_SHARE 0.5
#define SHADOW_NEAR_FRACTION 1e-4
/* The shadow test's slack for single-precision texgen. GL computes the
 * compared depth R/Q from eye coordinates in floats, with an error of a few
 * ulps of the coordinates' size (eye, scene and light positions, E), which
 * is E / distance-to-light depth units: tens of units for the ceiling above
 * a light (stress suite), beyond any polygon offset. Taking this many ulps
 * of E off R (not R/Q) moves the test by that error's own 1/distance law. */
#define SHADOW_TEXGEN_ULPS 32.0
#define FLOAT_ULP 1.1920928955078125e-07 /* 2^-23 */
/* The camera's near plane: never nearer than this fraction of its far plane,
 * which keeps 24-bit depth fine enough for the depth prepass and the splats. */
#define CAMERA_DEPTH_RATIO 4096.0
/* Depth offsets: shadow maps are pushed back against self-shadowing (acne);
 * the depth prepass is pushed back so that later passes of the same surface
 * pass GL_LEQUAL even where a clip plane re-rasterises it; triangle splats are
 * pulled forward (thesis 4.2). In glPolygonOffset's (factor, units). */
#define SHADOW_OFFSET_FACTOR 2.0f
#define SHADOW_OFFSET_UNITS 4.0f
#define PREPASS_OFFSET 1.0f
#define SPLAT_OFFSET -1.0f
/* A spot light's cone, drawn per pixel: a disc texture projected from the
 * light (thesis departure: GL's GL_SPOT_CUTOFF is applied per vertex, so the
 * cone's edge followed the mesh in steps a mesh edge wide, and photosplat-bench
 * measured the direct light of spot-lit scenes 17-24 % off in relMSE, all of
 * it along the edge). The texture is this many texels a side; the disc of the
 * cone fills it to CONE_TEX_RADIUS, outside is 0 (and so is the border). */
#define CONE_TEX_SIZE 512
#define CONE_TEX_RADIUS 0.5
/* Blinn's (n.h)^s is about Phong's cos^e(alpha) when s = 4e; GL caps s at 128. */
#define BLINN_PER_PHONG 4.0
#define GL_MAX_SHININESS 128.0

/* The memory plan of the lights: a shadow texel (24-bit depth, stored in
 * 32 bits), and a sphere light's mesh triangle (half a vertex of double
 * position and normal, three 32-bit indices). */
#define GL_SHADOW_TEXEL_BYTES 4
#define GL_SPHERE_TRIANGLE_BYTES (24 + 3 * 4)

/* A GL light: a scene light, or one virtual point light of an area light. */
typedef struct vlight {
    ps_vec3 pos;
    ps_vec3 dir;       /* unit axis of a spot or cosine emitter; zero when omnidirectional */
    double cutoff_deg; /* 180: omnidirectional */
    double exponent;   /* GL_SPOT_EXPONENT: 0 constant, 1 Lambertian */
    ps_rgb intensity;  /* W/sr along dir (all directions when omnidirectional) */
    unsigned faces;    /* the cube faces that can see light (bit per face) */
    GLuint shadow[6];
    double znear;      /* its shadow cube's near plane (make_shadow_maps) */
} vlight;

struct ps_gl_renderer {
    const ps_scene *scene;
    const ps_preview_mesh *mesh;
    /* The scene's own triangles, not subdivided: what depth-only passes (the
     * prepass, shadow maps) draw. Subdividing changes no depth, only the
     * number of vertices lit, so these are many times cheaper. */
    ps_preview_mesh coarse;
    int shadow_size;
    const ps_material *materials;
    ps_gl_options opt;
    vlight *lights;
    size_t light_count;
    bool shadows_valid;
    GLuint fbo, kernel_tex, cone_tex;
    double kernel_extent; /* the texture's half side in splat radii */
    ps_trimesh *sphere_lights; /* the sphere lights' surfaces, in light order */
    size_t sphere_light_count;
    double scene_diag;
    /* The size of the eye coordinates GL computes this frame: the eye's
     * distance from the origin plus the farthest scene point's from the eye. */
    double eye_extent;
    ps_aabb bounds;
    int width, height;
    double view[16], proj[16];
    ps_gl_stats stats;
};

/* ---- matrices (column-major, as GL) --------------------------------------- */

static void mat_identity(double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = m[15] = 1.0;
}

static void mat_mul(const double a[16], const double b[16], double out[16])
{
    double r[16];
    for (int c = 0; c < 4; c++)
        for (int rr = 0; rr < 4; rr++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += a[k * 4 + rr] * b[c * 4 + k];
            r[c * 4 + rr] = s;
        }
    memcpy(out, r, sizeof r);
}

/* gluLookAt with an orthonormal frame (right, up, -forward). */
static void mat_look(ps_vec3 eye, ps_vec3 forward, ps_vec3 right, ps_vec3 up, double m[16])
{
    mat_identity(m);
    m[0] = right.x, m[4] = right.y, m[8] = right.z, m[12] = -ps_v3_dot(right, eye);
    m[1] = up.x, m[5] = up.y, m[9] = up.z, m[13] = -ps_v3_dot(up, eye);
    m[2] = -forward.x, m[6] = -forward.y, m[10] = -forward.z, m[14] = ps_v3_dot(forward, eye);
}

/* gluPerspective from tan(fov_y / 2). */
static void mat_perspective(double tan_half, double aspect, double znear, double zfar, double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    double f = 1.0 / tan_half;
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (zfar + znear) / (znear - zfar);
    m[11] = -1.0;
    m[14] = 2.0 * zfar * znear / (znear - zfar);
}

/* Distances from p to the nearest and farthest points of box b. */
static void box_range(ps_aabb b, ps_vec3 p, double *nearest, double *farthest)
{
    double n2 = 0.0, f2 = 0.0;
    for (int a = 0; a < 3; a++) {
        double v = ps_v3_get(p, a), lo = ps_v3_get(b.lo, a), hi = ps_v3_get(b.hi, a);
        double d = v < lo ? lo - v : v > hi ? v - hi : 0.0;
        double far = fmax(fabs(v - lo), fabs(v - hi));
        n2 += d * d;
        f2 += far * far;
    }
    *nearest = sqrt(n2);
    *farthest = sqrt(f2);
}

/* ---- lights ---------------------------------------------------------------- */

static const ps_vec3 face_dirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

static void face_frame(int f, ps_vec3 *forward, ps_vec3 *right, ps_vec3 *up)
{
    *forward = face_dirs[f];
    ps_vec3 hint = fabs(forward->y) > 0.5 ? ps_v3(0, 0, 1) : ps_v3(0, 1, 0);
    *right = ps_v3_norm(ps_v3_cross(*forward, hint));
    *up = ps_v3_cross(*right, *forward);
}

/* Which cube faces can receive light from v: a face is skipped only when all
 * of its directions lie outside the cone (a face's directions are within
 * acos(1/sqrt(3)) = 54.7 degrees of its axis). */
static unsigned lit_faces(const vlight *v)
{
    if (ps_v3_len2(v->dir) == 0.0 || v->cutoff_deg >= 180.0)
        return 0x3f;
    const double face_radius_deg = 54.7356103172;
    unsigned mask = 0;
    for (int f = 0; f < 6; f++) {
        double angle = acos(fmax(-1.0, fmin(1.0, ps_v3_dot(face_dirs[f], v->dir)))) * 180.0 / PS_PI;
        if (angle < v->cutoff_deg + face_radius_deg)
            mask |= 1u << f;
    }
    return mask;
}

static bool push_light(ps_gl_renderer *r, size_t *cap, vlight v)
{
    if (r->light_count == *cap) {
        size_t n = *cap ? 2 * *cap : 16;
        vlight *p = realloc(r->lights, n * sizeof *p);
        if (!p)
            return false;
        r->lights = p;
        *cap = n;
    }
    v.faces = lit_faces(&v);
    memset(v.shadow, 0, sizeof v.shadow);
    r->lights[r->light_count++] = v;
    return true;
}

/* Virtual point lights of an area light: stratified points (grid cells'
 * centres) over the area, each a cosine emitter of power / (pi * count). */
static bool add_area_light(ps_gl_renderer *r, size_t *cap, const ps_light *L)
{
    const int side = 4; /* 4 x 4 = PS_GL_AREA_SAMPLES */
    const int count = side * side;
    ps_rgb each = ps_rgb_scale(L->power, PS_INV_PI / count);
    if (L->type == PS_LIGHT_SPHERE) {
        /* Outside it, a Lambertian sphere lights like a point at its centre. */
        vlight v = {L->position, {0, 0, 0}, 180.0, 0.0, ps_rgb_scale(L->power, 0.25 * PS_INV_PI), 0, {0}, 0.0};
        return push_light(r, cap, v);
    }
    size_t ntri = 0, nem = 0;
    const ps_triangle *tris = ps_scene_triangles(r->scene, &ntri);
    const ps_vec3 *pos = ps_scene_positions(r->scene, &ntri);
    const uint32_t *emitters = ps_scene_emitters(r->scene, &nem);
    (void)tris;
    double total_area = 0.0;
    if (L->type == PS_LIGHT_MESH)
        for (uint32_t k = 0; k < L->emitter_count; k++)
            total_area += ps_scene_triangle_area(r->scene, emitters[L->first_emitter + k]);
    for (int j = 0; j < side; j++)
        for (int i = 0; i < side; i++) {
            double u = (i + 0.5) / side, w = (j + 0.5) / side;
            vlight v = {{0, 0, 0}, L->direction, 90.0, 1.0, each, 0, {0}, 0.0};
            if (L->type == PS_LIGHT_QUAD) {
                v.pos = ps_v3_add(L->position, ps_v3_add(ps_v3_scale(L->edge1, u), ps_v3_scale(L->edge2, w)));
            } else if (L->type == PS_LIGHT_DISC) {
                double x, y;
                ps_sample_disc(u, w, &x, &y);
                ps_vec3 a, b;
                ps_v3_basis(L->direction, &a, &b);
                v.pos = ps_v3_add(L->position, ps_v3_add(ps_v3_scale(a, x * L->radius), ps_v3_scale(b, y * L->radius)));
            } else { /* a mesh light: the face at area fraction (j * side + i + 0.5) / count */
                double target = (j * side + i + 0.5) / count * total_area, run = 0.0;
                uint32_t t = emitters[L->first_emitter];
                for (uint32_t k = 0; k < L->emitter_count; k++) {
                    t = emitters[L->first_emitter + k];
                    run += ps_scene_triangle_area(r->scene, t);
                    if (run >= target)
                        break;
                }
                const ps_triangle *tri = &tris[t];
                v.pos = ps_v3_scale(ps_v3_add(ps_v3_add(pos[tri->v[0]], pos[tri->v[1]]), pos[tri->v[2]]), 1.0 / 3.0);
                v.dir = ps_scene_triangle_normal(r->scene, t);
            }
            if (!push_light(r, cap, v))
                return false;
        }
    return true;
}

static void free_shadows(ps_gl_renderer *r)
{
    for (size_t i = 0; i < r->light_count; i++)
        for (int f = 0; f < 6; f++)
            if (r->lights[i].shadow[f]) {
                glDeleteTextures(1, &r->lights[i].shadow[f]);
                r->lights[i].shadow[f] = 0;
            }
    r->shadows_valid = false;
}

static void free_sphere_lights(ps_gl_renderer *r)
{
    for (size_t i = 0; i < r->sphere_light_count; i++)
        ps_trimesh_free(&r->sphere_lights[i]);
    free(r->sphere_lights);
    r->sphere_lights = NULL;
    r->sphere_light_count = 0;
}

static ps_status build_lights(ps_gl_renderer *r, ps_error *err)
{
    free_shadows(r);
    free_sphere_lights(r);
    r->light_count = 0;
    size_t cap = 0, n;
    const ps_light *lights = ps_scene_lights(r->scene, &n);
    free(r->lights);
    r->lights = NULL;
    for (size_t l = 0; l < n; l++) {
        const ps_light *L = &lights[l];
        bool ok;
        /* TODO(lead): an IES light drawn as a point of its average intensity
         * until the preview projects its table (preview/light_profile.h). */
        if (L->type == PS_LIGHT_POINT || L->type == PS_LIGHT_IES) {
            vlight v = {L->position, {0, 0, 0}, 180.0, 0.0, ps_rgb_scale(L->power, 0.25 * PS_INV_PI), 0, {0}, 0.0};
            ok = push_light(r, &cap, v);
        } else if (L->type == PS_LIGHT_SPOT) {
            double solid = 2.0 * PS_PI * (1.0 - L->cos_angle);
            vlight v = {L->position, L->direction, L->angle_deg, 0.0, ps_rgb_scale(L->power, 1.0 / solid), 0, {0}, 0.0};
            ok = push_light(r, &cap, v);
        } else {
            ok = add_area_light(r, &cap, L);
        }
        if (!ok)
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for GL lights", ps_scene_path(r->scene));
    }
    r->stats.virtual_lights = (unsigned)r->light_count;
    size_t spheres = 0;
    for (size_t l = 0; l < n; l++)
        spheres += lights[l].type == PS_LIGHT_SPHERE;
    /* Shadow maps (a depth texture per lit cube face of every virtual light)
     * and sphere-light meshes: thousands of lights would not fit, so they
     * are refused here rather than failing inside the GL driver. */
    uint64_t faces = 0;
    for (size_t i = 0; r->opt.shadows && i < r->light_count; i++)
        for (unsigned m = r->lights[i].faces; m; m &= m - 1)
            faces++;
    uint64_t texels = (uint64_t)r->shadow_size * (uint64_t)r->shadow_size;
    uint64_t bytes = ps_memory_mul(faces, ps_memory_mul(texels, GL_SHADOW_TEXEL_BYTES)) +
                     ps_memory_mul(spheres, ps_memory_mul(ps_sphere_triangle_count(PS_SPHERE_DEFAULT_TOLERANCE),
                                                          GL_SPHERE_TRIANGLE_BYTES));
    char what[128];
    snprintf(what, sizeof what, "%zu lights (%zu GL lights, %llu shadow maps of %dx%d)", n, r->light_count,
             (unsigned long long)faces, r->shadow_size, r->shadow_size);
    ps_status cst = ps_memory_check(bytes, ps_scene_path(r->scene), what, err);
    if (cst != PS_OK)
        return cst;
    r->sphere_lights = spheres ? calloc(spheres, sizeof *r->sphere_lights) : NULL;
    if (spheres && !r->sphere_lights)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory for GL lights", ps_scene_path(r->scene));
    for (size_t l = 0; l < n; l++) {
        if (lights[l].type != PS_LIGHT_SPHERE)
            continue;
        ps_status st = ps_sphere_tessellate(lights[l].position, lights[l].radius, PS_SPHERE_DEFAULT_TOLERANCE,
                                            &r->sphere_lights[r->sphere_light_count], err);
        if (st != PS_OK)
            return st;
        r->sphere_light_count++;
    }
    return PS_OK;
}

/* ---- drawing the mesh ----------------------------------------------------- */

/* The exposure is in the lights' intensities, not here. With `stencil`,
 * each object writes its stencil value (ps_splat_stencil). */
static void draw_mesh_stencil(const ps_gl_renderer *r, bool with_materials, bool stencil)
{
    const ps_preview_mesh *m = with_materials ? r->mesh : &r->coarse;
    glEnableClientState(GL_VERTEX_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, m->positions);
    if (with_materials) {
        glEnableClientState(GL_NORMAL_ARRAY);
        glNormalPointer(GL_FLOAT, 0, m->normals);
    }
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_mesh_range *rg = &m->ranges[i];
        if (with_materials) {
            const ps_material *mat = &r->materials[rg->material];
            GLfloat diffuse[4] = {0, 0, 0, 1}, specular[4] = {0, 0, 0, 1};
            GLfloat shininess = 0.0f;
            if (mat->type == PS_MAT_DIFFUSE || mat->type == PS_MAT_GLOSSY) {
                diffuse[0] = (GLfloat)(mat->albedo.r * PS_INV_PI);
                diffuse[1] = (GLfloat)(mat->albedo.g * PS_INV_PI);
                diffuse[2] = (GLfloat)(mat->albedo.b * PS_INV_PI);
            }
            if (mat->type == PS_MAT_GLOSSY) {
                double k = (mat->exponent + 2.0) * 0.5 * PS_INV_PI;
                specular[0] = (GLfloat)(mat->specular.r * k);
                specular[1] = (GLfloat)(mat->specular.g * k);
                specular[2] = (GLfloat)(mat->specular.b * k);
                shininess = (GLfloat)fmin(BLINN_PER_PHONG * mat->exponent, GL_MAX_SHININESS);
            }
            glMaterialfv(GL_FRONT_AND_BACK, GL_DIFFUSE, diffuse);
            glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, specular);
            glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, shininess);
        }
        if (stencil)
            glStencilFunc(GL_ALWAYS, (GLint)ps_splat_stencil(rg->object), 0xff);
        glDrawArrays(GL_TRIANGLES, (GLint)rg->first, (GLsizei)rg->count);
    }
    glDisableClientState(GL_NORMAL_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
}

static void draw_mesh(const ps_gl_renderer *r, bool with_materials) { draw_mesh_stencil(r, with_materials, false); }

/* Emissive faces (MTL Ke) as their own radiance, front side only. */
static void draw_emission(const ps_gl_renderer *r, double exposure)
{
    const ps_preview_mesh *m = r->mesh;
    glEnableClientState(GL_VERTEX_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, m->positions);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    for (size_t i = 0; i < m->range_count; i++) {
        const ps_material *mat = &r->materials[m->ranges[i].material];
        if (ps_rgb_is_black(mat->emission))
            continue;
        glColor4f((GLfloat)(mat->emission.r * exposure), (GLfloat)(mat->emission.g * exposure),
                  (GLfloat)(mat->emission.b * exposure), 1.0f);
        glDrawArrays(GL_TRIANGLES, (GLint)m->ranges[i].first, (GLsizei)m->ranges[i].count);
    }
    glDisable(GL_CULL_FACE);
    glDisableClientState(GL_VERTEX_ARRAY);
}

/* Area lights as the eye sees them (the reference renderer's emitters): quad
 * and disc lights from their emitting side, sphere lights from outside, in
 * their radiance times exposure, or black when the direct layer is off (its
 * term; the other layers still see them in the way). They are drawn over
 * the lit scene with depth writes, so splats behind them stay hidden; they
 * are not in the shadow maps, as photons and shadow rays pass through them. */
#define DISC_SEGMENTS 64

static void draw_area_lights(const ps_gl_renderer *r, double exposure, bool direct)
{
    size_t n;
    const ps_light *lights = ps_scene_lights(r->scene, &n);
    glDisable(GL_BLEND);
    glDisable(GL_LIGHTING);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    /* Their pixels belong to no object: splats are not clipped into them. */
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_ALWAYS, 0, 0xff);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    size_t sphere = 0;
    for (size_t l = 0; l < n; l++) {
        const ps_light *L = &lights[l];
        if (L->type != PS_LIGHT_QUAD && L->type != PS_LIGHT_DISC && L->type != PS_LIGHT_SPHERE)
            continue;
        double k = direct ? exposure : 0.0;
        glColor4f((GLfloat)(L->radiance.r * k), (GLfloat)(L->radiance.g * k), (GLfloat)(L->radiance.b * k), 1.0f);
        if (L->type == PS_LIGHT_QUAD) {
            ps_vec3 c[4] = {L->position, ps_v3_add(L->position, L->edge1),
                            ps_v3_add(ps_v3_add(L->position, L->edge1), L->edge2), ps_v3_add(L->position, L->edge2)};
            glBegin(GL_QUADS); /* counter-clockwise about edge1 x edge2, the emitting side */
            for (int i = 0; i < 4; i++)
                glVertex3d(c[i].x, c[i].y, c[i].z);
            glEnd();
        } else if (L->type == PS_LIGHT_DISC) {
            ps_vec3 t, b;
            ps_v3_basis(L->direction, &t, &b);
            glBegin(GL_TRIANGLE_FAN);
            glVertex3d(L->position.x, L->position.y, L->position.z);
            for (int i = 0; i <= DISC_SEGMENTS; i++) {
                double a = 2.0 * PS_PI * i / DISC_SEGMENTS;
                ps_vec3 q = ps_v3_add(L->position, ps_v3_add(ps_v3_scale(t, L->radius * cos(a)),
                                                             ps_v3_scale(b, L->radius * sin(a))));
                glVertex3d(q.x, q.y, q.z);
            }
            glEnd();
        } else if (sphere < r->sphere_light_count) {
            const ps_trimesh *m = &r->sphere_lights[sphere++];
            glBegin(GL_TRIANGLES);
            for (uint32_t i = 0; i < 3 * m->triangle_count; i++) {
                ps_vec3 q = m->positions[m->indices[i]];
                glVertex3d(q.x, q.y, q.z);
            }
            glEnd();
        }
    }
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_CULL_FACE);
}

/* ---- shadow maps ------------------------------------------------------------ */

/* Squared distance from p to the triangle abc: the closest point lies in the
 * face, on an edge or at a corner, told apart by barycentric signs
 * (Ericson, Real-Time Collision Detection, 5.1.5). */
static double point_triangle_dist2(ps_vec3 p, ps_vec3 a, ps_vec3 b, ps_vec3 c)
{
    ps_vec3 ab = ps_v3_sub(b, a), ac = ps_v3_sub(c, a), ap = ps_v3_sub(p, a);
    double d1 = ps_v3_dot(ab, ap), d2 = ps_v3_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0)
        return ps_v3_len2(ap);
    ps_vec3 bp = ps_v3_sub(p, b);
    double d3 = ps_v3_dot(ab, bp), d4 = ps_v3_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3)
        return ps_v3_len2(bp);
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
        return ps_v3_len2(ps_v3_sub(p, ps_v3_madd(a, ab, d1 / (d1 - d3))));
    ps_vec3 cp = ps_v3_sub(p, c);
    double d5 = ps_v3_dot(ab, cp), d6 = ps_v3_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6)
        return ps_v3_len2(cp);
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
        return ps_v3_len2(ps_v3_sub(p, ps_v3_madd(a, ac, d2 / (d2 - d6))));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
        return ps_v3_len2(ps_v3_sub(p, ps_v3_madd(b, ps_v3_sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    double denom = va + vb + vc;
    if (!(denom > 0.0)) /* a degenerate triangle: its corners are near enough */
        return fmin(ps_v3_len2(ap), fmin(ps_v3_len2(bp), ps_v3_len2(cp)));
    double v = vb / denom, w = vc / denom;
    return ps_v3_len2(ps_v3_sub(p, ps_v3_madd(ps_v3_madd(a, ab, v), ac, w)));
}

/* The distance from p to the nearest triangle of the depth-only mesh. */
static double nearest_geometry(const ps_gl_renderer *r, ps_vec3 p)
{
    const ps_preview_mesh *m = &r->coarse;
    double best = HUGE_VAL;
    for (size_t i = 0; i + 2 < m->vertex_count; i += 3) {
        const float *q = m->positions + 3 * i;
        ps_vec3 a = ps_v3(q[0], q[1], q[2]), b = ps_v3(q[3], q[4], q[5]), c = ps_v3(q[6], q[7], q[8]);
        best = fmin(best, point_triangle_dist2(p, a, b, c));
    }
    return sqrt(best);
}

static void light_face_matrices(const ps_gl_renderer *r, const vlight *v, int f, double proj[16], double view[16])
{
    ps_vec3 fw, rt, up;
    face_frame(f, &fw, &rt, &up);
    double nearest, farthest;
    box_range(r->bounds, v->pos, &nearest, &farthest);
    double znear = v->znear;
    mat_perspective(1.0, 1.0, znear, fmax(farthest * 1.01, 2.0 * znear), proj);
    mat_look(v->pos, fw, rt, up, view);
}

static void make_shadow_maps(ps_gl_renderer *r)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glViewport(0, 0, r->shadow_size, r->shadow_size);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(SHADOW_OFFSET_FACTOR, SHADOW_OFFSET_UNITS);
    for (size_t i = 0; i < r->light_count; i++) {
        vlight *v = &r->lights[i];
        double floor_near = fmax(SHADOW_NEAR_FRACTION * r->scene_diag, 1e-300);
        v->znear = fmax(SHADOW_NEAR_SHARE * nearest_geometry(r, v->pos), floor_near);
        if (!isfinite(v->znear)) /* no geometry at all */
            v->znear = floor_near;
        for (int f = 0; f < 6; f++) {
            if (!(v->faces & (1u << f)))
                continue;
            if (!v->shadow[f]) {
                glGenTextures(1, &v->shadow[f]);
                glBindTexture(GL_TEXTURE_2D, v->shadow[f]);
                glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, r->shadow_size, r->shadow_size, 0,
                             GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, NULL);
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
                /* Outside the face's square: depth 0 at the border, so the
                 * compare fails there and the neighbouring face lights it. */
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
                const GLfloat border[4] = {0, 0, 0, 0};
                glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_R_TO_TEXTURE);
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
                glTexParameteri(GL_TEXTURE_2D, GL_DEPTH_TEXTURE_MODE, GL_INTENSITY);
            }
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, v->shadow[f], 0);
            glClear(GL_DEPTH_BUFFER_BIT);
            double proj[16], view[16];
            light_face_matrices(r, v, f, proj, view);
            glMatrixMode(GL_PROJECTION);
            glLoadMatrixd(proj);
            glMatrixMode(GL_MODELVIEW);
            glLoadMatrixd(view);
            draw_mesh(r, false);
            r->stats.shadow_maps++;
        }
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    /* Draw and read buffers are per framebuffer: rebinding restores them. */
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    glBindTexture(GL_TEXTURE_2D, 0);
    r->shadows_valid = true;
}

/* ---- the frame ---------------------------------------------------------------- */

/* A spot of constant intensity inside a cone (not an area light's cosine
 * emitter, whose 90-degree "cone" is its own plane): its edge is drawn by
 * the cone texture, not by GL's per-vertex cutoff. */
static bool hard_cone(const vlight *v) { return v->cutoff_deg < 90.0 && v->exponent == 0.0; }

static void set_gl_light(const vlight *v, double exposure)
{
    GLfloat pos[4] = {(GLfloat)v->pos.x, (GLfloat)v->pos.y, (GLfloat)v->pos.z, 1.0f};
    GLfloat col[4] = {(GLfloat)(v->intensity.r * exposure), (GLfloat)(v->intensity.g * exposure),
                      (GLfloat)(v->intensity.b * exposure), 1.0f};
    GLfloat black[4] = {0, 0, 0, 1};
    glLightfv(GL_LIGHT0, GL_POSITION, pos);
    glLightfv(GL_LIGHT0, GL_AMBIENT, black);
    glLightfv(GL_LIGHT0, GL_DIFFUSE, col);
    glLightfv(GL_LIGHT0, GL_SPECULAR, col);
    glLightf(GL_LIGHT0, GL_CONSTANT_ATTENUATION, 0.0f);
    glLightf(GL_LIGHT0, GL_LINEAR_ATTENUATION, 0.0f);
    glLightf(GL_LIGHT0, GL_QUADRATIC_ATTENUATION, 1.0f);
    if (v->cutoff_deg < 180.0 && !hard_cone(v)) {
        GLfloat dir[3] = {(GLfloat)v->dir.x, (GLfloat)v->dir.y, (GLfloat)v->dir.z};
        glLightfv(GL_LIGHT0, GL_SPOT_DIRECTION, dir);
        glLightf(GL_LIGHT0, GL_SPOT_CUTOFF, (GLfloat)v->cutoff_deg);
        glLightf(GL_LIGHT0, GL_SPOT_EXPONENT, (GLfloat)v->exponent);
    } else {
        glLightf(GL_LIGHT0, GL_SPOT_CUTOFF, 180.0f);
        glLightf(GL_LIGHT0, GL_SPOT_EXPONENT, 0.0f);
    }
}

/* The cone texture: 1 inside the disc, 0 outside and at the border. */
static void make_cone_texture(ps_gl_renderer *r)
{
    if (r->cone_tex)
        return;
    uint8_t *texels = malloc((size_t)CONE_TEX_SIZE * CONE_TEX_SIZE);
    if (!texels)
        return; /* no texture: the cone falls back to GL's per-vertex cutoff */
    for (int y = 0; y < CONE_TEX_SIZE; y++)
        for (int x = 0; x < CONE_TEX_SIZE; x++) {
            double u = (x + 0.5) / CONE_TEX_SIZE - 0.5, w = (y + 0.5) / CONE_TEX_SIZE - 0.5;
            texels[(size_t)y * CONE_TEX_SIZE + (size_t)x] = u * u + w * w <= CONE_TEX_RADIUS * CONE_TEX_RADIUS ? 255 : 0;
        }
    glGenTextures(1, &r->cone_tex);
    glBindTexture(GL_TEXTURE_2D, r->cone_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_LUMINANCE8, CONE_TEX_SIZE, CONE_TEX_SIZE, 0, GL_LUMINANCE, GL_UNSIGNED_BYTE, texels);
    /* Nearest: the edge is as sharp as the reference's, and a texel is far
     * finer than a mesh edge. */
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const GLfloat border[4] = {0, 0, 0, 0};
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
    glBindTexture(GL_TEXTURE_2D, 0);
    free(texels);
}

/* On texture unit 1: the cone texture projected from spot v, so that a point
 * p maps to 0.5 + 0.5 (p - L).(u, v) / (tan(cutoff) (p - L).axis), inside the
 * disc exactly when inside the cone; clip plane 2 keeps what lies behind the
 * light (where the projection flips) out. Set while the modelview is the
 * camera's view (world-space eye-linear planes, as the shadow texgen). */
static void begin_cone(const ps_gl_renderer *r, const vlight *v)
{
    ps_vec3 u, w;
    ps_v3_basis(v->dir, &u, &w);
    double k = CONE_TEX_RADIUS / tan(v->cutoff_deg * PS_PI / 180.0);
    ps_vec3 rows[3] = {ps_v3_add(ps_v3_scale(v->dir, 0.5), ps_v3_scale(u, k)),
                       ps_v3_add(ps_v3_scale(v->dir, 0.5), ps_v3_scale(w, k)), v->dir};
    const GLenum coords[3] = {GL_S, GL_T, GL_Q};
    const GLenum gens[3] = {GL_TEXTURE_GEN_S, GL_TEXTURE_GEN_T, GL_TEXTURE_GEN_Q};
    glActiveTexture(GL_TEXTURE1);
    glEnable(GL_TEXTURE_2D);
    glBindTexture(GL_TEXTURE_2D, r->cone_tex);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    for (int i = 0; i < 3; i++) {
        GLdouble plane[4] = {rows[i].x, rows[i].y, rows[i].z, -ps_v3_dot(rows[i], v->pos)};
        glTexGeni(coords[i], GL_TEXTURE_GEN_MODE, GL_EYE_LINEAR);
        glTexGendv(coords[i], GL_EYE_PLANE, plane);
        glEnable(gens[i]);
    }
    glActiveTexture(GL_TEXTURE0);
    GLdouble front[4] = {v->dir.x, v->dir.y, v->dir.z, -ps_v3_dot(v->dir, v->pos)};
    glClipPlane(GL_CLIP_PLANE2, front);
    glEnable(GL_CLIP_PLANE2);
}

static void end_cone(void)
{
    glActiveTexture(GL_TEXTURE1);
    glDisable(GL_TEXTURE_GEN_S);
    glDisable(GL_TEXTURE_GEN_T);
    glDisable(GL_TEXTURE_GEN_Q);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_TEXTURE_2D);
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_CLIP_PLANE2);
}

/* Texgen planes that take world points to the shadow map's [0,1]^3 (the
 * rows of bias * projection * view), set while the modelview is the camera's
 * view so that GL's eye-linear planes see world coordinates. */
static void set_shadow_texgen(const double light_proj[16], const double light_view[16], double slack)
{
    static const double bias[16] = {0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0.5, 0.5, 0.5, 1};
    double t[16];
    mat_mul(bias, light_proj, t);
    mat_mul(t, light_view, t);
    const GLenum coords[4] = {GL_S, GL_T, GL_R, GL_Q};
    const GLenum gens[4] = {GL_TEXTURE_GEN_S, GL_TEXTURE_GEN_T, GL_TEXTURE_GEN_R, GL_TEXTURE_GEN_Q};
    for (int k = 0; k < 4; k++) {
        GLdouble plane[4] = {t[k], t[4 + k], t[8 + k], t[12 + k] - (k == 2 ? slack : 0.0)};
        glTexGeni(coords[k], GL_TEXTURE_GEN_MODE, GL_EYE_LINEAR);
        glTexGendv(coords[k], GL_EYE_PLANE, plane);
        glEnable(gens[k]);
    }
}

static void disable_texgen(void)
{
    glDisable(GL_TEXTURE_GEN_S);
    glDisable(GL_TEXTURE_GEN_T);
    glDisable(GL_TEXTURE_GEN_R);
    glDisable(GL_TEXTURE_GEN_Q);
}

static void draw_direct(ps_gl_renderer *r, double exposure)
{
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
    glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_TRUE);
    const GLfloat no_ambient[4] = {0, 0, 0, 1};
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, no_ambient);
    glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT, no_ambient);
    glMaterialfv(GL_FRONT_AND_BACK, GL_EMISSION, no_ambient);
    for (size_t i = 0; i < r->light_count; i++) {
        const vlight *v = &r->lights[i];
        set_gl_light(v, exposure);
        bool cone = hard_cone(v) && r->cone_tex;
        if (cone)
            begin_cone(r, v);
        if (!r->opt.shadows) {
            draw_mesh(r, true);
            r->stats.light_passes++;
            if (cone)
                end_cone();
            continue;
        }
        glEnable(GL_TEXTURE_2D);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        glEnable(GL_CLIP_PLANE0);
        glEnable(GL_CLIP_PLANE1);
        for (int f = 0; f < 6; f++) {
            if (!(v->faces & (1u << f)))
                continue;
            double proj[16], view[16];
            light_face_matrices(r, v, f, proj, view);
            set_shadow_texgen(proj, view, SHADOW_TEXGEN_ULPS * FLOAT_ULP * (r->eye_extent + ps_v3_len(v->pos)));
            /* Only the half-space in front of the face: behind the light the
             * projection would fold points back into the map. */
            GLdouble plane[4] = {face_dirs[f].x, face_dirs[f].y, face_dirs[f].z, -ps_v3_dot(face_dirs[f], v->pos)};
            glClipPlane(GL_CLIP_PLANE0, plane);
            /* Nor what lies nearer than the near plane: outside the face's
             * square its depth would pass the test against the border's 0.
             * Every point this face owns lies beyond (at least nearest /
             * sqrt 3 > SHADOW_NEAR_SHARE * nearest away along the axis). */
            plane[3] -= v->znear;
            glClipPlane(GL_CLIP_PLANE1, plane);
            glBindTexture(GL_TEXTURE_2D, v->shadow[f]);
            draw_mesh(r, true);
            r->stats.light_passes++;
        }
        glDisable(GL_CLIP_PLANE0);
        glDisable(GL_CLIP_PLANE1);
        disable_texgen();
        glBindTexture(GL_TEXTURE_2D, 0);
        glDisable(GL_TEXTURE_2D);
        if (cone)
            end_cone();
    }
    glDisable(GL_LIGHT0);
    glDisable(GL_LIGHTING);
    draw_emission(r, exposure);
}

void ps_gl_begin_frame(ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct)
{
    r->stats.light_passes = 0;
    if (direct && r->opt.shadows && !r->shadows_valid)
        make_shadow_maps(r);
    r->width = cam->width;
    r->height = cam->height;
    glViewport(0, 0, cam->width, cam->height);
    if (r->opt.float_buffer) {
        glClampColor(GL_CLAMP_VERTEX_COLOR, GL_FALSE);
        glClampColor(GL_CLAMP_FRAGMENT_COLOR, GL_FALSE);
    }
    glClampColor(GL_CLAMP_READ_COLOR, GL_FALSE);
    glClearColor(0, 0, 0, 0);
    glClearDepth(1.0);
    /* glClear obeys the write masks, which the last frame's splats left off. */
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glStencilMask(0xff);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);

    double nearest, farthest;
    box_range(r->bounds, cam->eye, &nearest, &farthest);
    r->eye_extent = ps_v3_len(cam->eye) + farthest;
    double zfar = fmax(farthest * 1.01, 1e-300);
    double znear = fmax(nearest * 0.5, zfar / CAMERA_DEPTH_RATIO);
    mat_perspective(cam->tan_half_fov, cam->aspect, znear, zfar, r->proj);
    mat_look(cam->eye, cam->forward, cam->right, cam->up, r->view);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(r->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(r->view);

    /* Depth first, pushed back a little (see PREPASS_OFFSET). */
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(PREPASS_OFFSET, PREPASS_OFFSET);
    /* Each visible pixel keeps its object's stencil value, for clipping splats. */
    glEnable(GL_STENCIL_TEST);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    glStencilMask(0xff);
    draw_mesh_stencil(r, false, true);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    if (direct) {
        /* Each light adds its pass on top. */
        glDepthMask(GL_FALSE);
        glDepthFunc(GL_LEQUAL);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
        draw_direct(r, exposure);
        glDisable(GL_BLEND);
    }
    draw_area_lights(r, exposure, direct);
}

/* The batch's primitives; grouped, each group only where its object shows
 * (the stencil test), else all at once. */
static void draw_groups(const ps_splat_batch *b, GLenum prim)
{
    if (!b->grouped) {
        glDrawArrays(prim, 0, (GLsizei)b->vertex_count);
        return;
    }
    glEnable(GL_STENCIL_TEST);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    for (int g = 0; g < PS_SPLAT_GROUPS; g++) {
        size_t first = b->group_first[g], n = b->group_first[g + 1] - first;
        if (n == 0)
            continue;
        if (g == 0)
            glStencilFunc(GL_ALWAYS, 0, 0xff);
        else
            glStencilFunc(GL_EQUAL, g, 0xff);
        glDrawArrays(prim, (GLint)first, (GLsizei)n);
    }
    glDisable(GL_STENCIL_TEST);
}

void ps_gl_draw_splats(ps_gl_renderer *r, const ps_splat_batch *b, ps_splat_mode mode, double radius,
                       double point_size)
{
    if (b->vertex_count == 0)
        return;
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(r->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(r->view);
    glDisable(GL_LIGHTING);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, b->positions);
    glColorPointer(4, GL_FLOAT, 0, b->colors);
    if (mode == PS_SPLAT_POINTS) {
        glBlendFunc(GL_ONE, GL_ONE);
        glPointSize((GLfloat)point_size);
        draw_groups(b, GL_POINTS);
    } else {
        glEnable(GL_TEXTURE_2D);
        glBindTexture(GL_TEXTURE_2D, r->kernel_tex);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE);
        if (mode == PS_SPLAT_TRIANGLES) {
            glEnableClientState(GL_TEXTURE_COORD_ARRAY);
            glTexCoordPointer(2, GL_FLOAT, 0, b->texcoords);
            glEnable(GL_POLYGON_OFFSET_FILL);
            glPolygonOffset(SPLAT_OFFSET, SPLAT_OFFSET);
            draw_groups(b, GL_TRIANGLES);
            glDisable(GL_POLYGON_OFFSET_FILL);
            glDisableClientState(GL_TEXTURE_COORD_ARRAY);
        } else {
            /* Point sprites whose side is the kernel square's in pixels at
             * distance d: 2 extent r f / d, f the focal length in pixels
             * (GL_POINT_DISTANCE_ATTENUATION {0, 0, 1} divides by d). */
            double focal = 0.5 * r->height / (r->proj[5] > 0.0 ? 1.0 / r->proj[5] : 1.0);
            const GLfloat atten[3] = {0.0f, 0.0f, 1.0f};
            GLfloat range[2] = {1.0f, 64.0f};
            glGetFloatv(GL_ALIASED_POINT_SIZE_RANGE, range);
            glPointParameterfv(GL_POINT_DISTANCE_ATTENUATION, atten);
            glPointParameterf(GL_POINT_SIZE_MIN, 1.0f);
            glPointParameterf(GL_POINT_SIZE_MAX, range[1]);
            glEnable(GL_POINT_SPRITE);
            glTexEnvi(GL_POINT_SPRITE, GL_COORD_REPLACE, GL_TRUE);
            glPointSize((GLfloat)(2.0 * r->kernel_extent * radius * focal));
            draw_groups(b, GL_POINTS);
            glTexEnvi(GL_POINT_SPRITE, GL_COORD_REPLACE, GL_FALSE);
            glDisable(GL_POINT_SPRITE);
            const GLfloat none[3] = {1.0f, 0.0f, 0.0f};
            glPointParameterfv(GL_POINT_DISTANCE_ATTENUATION, none);
        }
        glBindTexture(GL_TEXTURE_2D, 0);
        glDisable(GL_TEXTURE_2D);
    }
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glDisable(GL_BLEND);
}

ps_status ps_gl_read(ps_gl_renderer *r, ps_image *out, ps_error *err)
{
    ps_status st = ps_image_create(r->width, r->height, out, err);
    if (st != PS_OK)
        return st;
    float *rows = malloc(sizeof(float) * 3 * (size_t)r->width * (size_t)r->height);
    if (!rows) {
        ps_image_destroy(out);
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory reading the picture back");
    }
    glFinish();
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, r->width, r->height, GL_RGB, GL_FLOAT, rows);
    /* GL's row 0 is the bottom; ours the top. */
    for (int y = 0; y < r->height; y++)
        memcpy(ps_image_at(out, 0, y), rows + 3 * (size_t)(r->height - 1 - y) * (size_t)r->width,
               sizeof(float) * 3 * (size_t)r->width);
    free(rows);
    return PS_OK;
}

static void upload_kernel(ps_gl_renderer *r, const ps_kernel_texture *k)
{
    r->kernel_extent = k->extent;
    if (!r->kernel_tex)
        glGenTextures(1, &r->kernel_tex);
    glBindTexture(GL_TEXTURE_2D, r->kernel_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_ALPHA8, k->size, k->size, 0, GL_ALPHA, GL_UNSIGNED_BYTE, k->alpha);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
}

void ps_gl_renderer_set_kernel(ps_gl_renderer *r, const ps_kernel_texture *kernel) { upload_kernel(r, kernel); }

ps_status ps_gl_renderer_create(const ps_scene *s, const ps_preview_mesh *mesh, const ps_kernel_texture *kernel,
                                const ps_gl_options *o, ps_gl_renderer **out, ps_error *err)
{
    *out = NULL;
    ps_gl_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the GL renderer");
    r->scene = s;
    r->mesh = mesh;
    size_t n;
    r->materials = ps_scene_materials(s, &n);
    r->opt = *o;
    r->bounds = ps_scene_bounds(s);
    r->scene_diag = ps_v3_len(ps_aabb_diag(r->bounds));
    if (!(r->scene_diag > 0.0) || !isfinite(r->scene_diag))
        r->scene_diag = 1.0;
    r->shadow_size = o->shadow_size > 0 ? o->shadow_size : PS_GL_SHADOW_SIZE;
    ps_mesh_options coarse = ps_mesh_default_options(s);
    coarse.max_edge = HUGE_VAL;
    ps_status st = ps_preview_mesh_build(s, &coarse, &r->coarse, err);
    if (st == PS_OK)
        st = build_lights(r, err);
    if (st != PS_OK) {
        ps_gl_renderer_destroy(r);
        return st;
    }
    glGenFramebuffers(1, &r->fbo);
    upload_kernel(r, kernel);
    make_cone_texture(r);
    *out = r;
    return PS_OK;
}

void ps_gl_renderer_lights_changed(ps_gl_renderer *r)
{
    ps_error err;
    if (build_lights(r, &err) != PS_OK)
        r->light_count = 0; /* out of memory: draw unlit rather than fail a frame */
}

ps_gl_stats ps_gl_get_stats(const ps_gl_renderer *r) { return r->stats; }

void ps_gl_renderer_destroy(ps_gl_renderer *r)
{
    if (!r)
        return;
    free_shadows(r);
    if (r->fbo)
        glDeleteFramebuffers(1, &r->fbo);
    if (r->kernel_tex)
        glDeleteTextures(1, &r->kernel_tex);
    if (r->cone_tex)
        glDeleteTextures(1, &r->cone_tex);
    free(r->lights);
    free_sphere_lights(r);
    ps_preview_mesh_free(&r->coarse);
    free(r);
}

/* ---- layers kept between frames (the window's incremental refresh) -------- */

enum { LAYER_DIRECT_TEX, LAYER_CAUSTIC_TEX, LAYER_GLOBAL_TEX, LAYER_FINAL_TEX, LAYER_TEX_COUNT };

struct ps_gl_layers {
    int width, height;
    bool float_buffers;
    GLuint tex[LAYER_TEX_COUNT], fbo[LAYER_TEX_COUNT], depth_stencil;
};

ps_status ps_gl_layers_create(int width, int height, bool float_buffers, ps_gl_layers **out, ps_error *err)
{
    *out = NULL;
    ps_gl_layers *l = calloc(1, sizeof *l);
    if (!l)
        return ps_error_set(err, PS_ERR_NOMEM, "out of memory for the GL layers");
    l->width = width;
    l->height = height;
    l->float_buffers = float_buffers;
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    /* One depth-stencil buffer for all: the prepass drawn once serves every
     * layer's depth test and stencil clipping. */
    glGenRenderbuffers(1, &l->depth_stencil);
    glBindRenderbuffer(GL_RENDERBUFFER, l->depth_stencil);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, width, height);
    glGenTextures(LAYER_TEX_COUNT, l->tex);
    glGenFramebuffers(LAYER_TEX_COUNT, l->fbo);
    bool complete = true;
    for (int i = 0; i < LAYER_TEX_COUNT; i++) {
        glBindTexture(GL_TEXTURE_2D, l->tex[i]);
        /* The final picture is always float: it is read back and encoded
         * (exposure, sRGB) on the CPU exactly as photosplat-snap does. */
        bool is_float = float_buffers || i == LAYER_FINAL_TEX;
        glTexImage2D(GL_TEXTURE_2D, 0, is_float ? GL_RGBA32F : GL_RGBA8, width, height, 0, GL_RGBA,
                     is_float ? GL_FLOAT : GL_UNSIGNED_BYTE, NULL);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[i]);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, l->tex[i], 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, l->depth_stencil);
        complete = complete && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    if (!complete) {
        ps_gl_layers_destroy(l);
        return ps_error_set(err, PS_ERR_IO, "the GL implementation cannot render to %s textures of %dx%d",
                            float_buffers ? "RGBA32F" : "RGBA8", width, height);
    }
    *out = l;
    return PS_OK;
}

void ps_gl_layers_destroy(ps_gl_layers *l)
{
    if (!l)
        return;
    glDeleteFramebuffers(LAYER_TEX_COUNT, l->fbo);
    glDeleteTextures(LAYER_TEX_COUNT, l->tex);
    glDeleteRenderbuffers(1, &l->depth_stencil);
    free(l);
}

void ps_gl_layers_view(ps_gl_layers *l, ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_DIRECT_TEX]);
    ps_gl_begin_frame(r, cam, exposure, direct);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        ps_gl_layers_clear_map(l, k);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

void ps_gl_layers_clear_map(ps_gl_layers *l, int map)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_CAUSTIC_TEX + map]);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT); /* colour only: the shared depth is the view's */
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

void ps_gl_layers_add(ps_gl_layers *l, ps_gl_renderer *r, int map, const ps_splat_batch *b, ps_splat_mode mode,
                      double radius, double point_size)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_CAUSTIC_TEX + map]);
    glViewport(0, 0, l->width, l->height);
    ps_gl_draw_splats(r, b, mode, radius, point_size);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
}

/* A screen-filling quad of texture t times gain, added to what is there. */
static void add_texture(GLuint t, double gain)
{
    glBindTexture(GL_TEXTURE_2D, t);
    glColor4f((GLfloat)gain, (GLfloat)gain, (GLfloat)gain, 1.0f);
    glBegin(GL_QUADS);
    glTexCoord2f(0, 0), glVertex2f(-1, -1);
    glTexCoord2f(1, 0), glVertex2f(1, -1);
    glTexCoord2f(1, 1), glVertex2f(1, 1);
    glTexCoord2f(0, 1), glVertex2f(-1, 1);
    glEnd();
}

ps_status ps_gl_layers_composite(ps_gl_layers *l, double direct_gain, const double map_gain[PS_MAP_COUNT],
                                 ps_image *out, ps_error *err)
{
    GLint old_fbo = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &old_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo[LAYER_FINAL_TEX]);
    glViewport(0, 0, l->width, l->height);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    /* Gains above 1 (N/n early on) must not clamp on the way. */
    glClampColor(GL_CLAMP_VERTEX_COLOR, GL_FALSE);
    glClampColor(GL_CLAMP_FRAGMENT_COLOR, GL_FALSE);
    glClampColor(GL_CLAMP_READ_COLOR, GL_FALSE);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_LIGHTING);
    glEnable(GL_TEXTURE_2D);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    add_texture(l->tex[LAYER_DIRECT_TEX], direct_gain);
    for (int k = 0; k < PS_MAP_COUNT; k++)
        if (map_gain[k] > 0.0)
            add_texture(l->tex[LAYER_CAUSTIC_TEX + k], map_gain[k]);
    glDisable(GL_BLEND);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_TEXTURE_2D);
    ps_status st = ps_image_create(l->width, l->height, out, err);
    float *rows = st == PS_OK ? malloc(sizeof(float) * 3 * (size_t)l->width * (size_t)l->height) : NULL;
    if (st == PS_OK && !rows) {
        ps_image_destroy(out);
        st = ps_error_set(err, PS_ERR_NOMEM, "out of memory reading the picture back");
    }
    if (st == PS_OK) {
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, l->width, l->height, GL_RGB, GL_FLOAT, rows);
        for (int y = 0; y < l->height; y++)
            memcpy(ps_image_at(out, 0, y), rows + 3 * (size_t)(l->height - 1 - y) * (size_t)l->width,
                   sizeof(float) * 3 * (size_t)l->width);
    }
    free(rows);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)old_fbo);
    return st;
}
