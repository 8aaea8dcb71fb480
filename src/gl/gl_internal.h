/* gl_internal.h: what the files of libpsgl share and nobody else sees: the
 * renderer's layout and the helpers one file draws with and another calls. */
#ifndef PS_GL_GL_INTERNAL_H
#define PS_GL_GL_INTERNAL_H

#include <stdbool.h>

#include "gl/gl_api.h"
#include "gl/gl_render.h"

/* The direct light of diffuse quads laid into textures (preview/bake.h's
 * ps_bake_direct_targets, gl_direct_bake.c; ps_gl_options.bake_direct):
 * valid while r->lit_epoch, the exposure and the shadows it was laid with
 * hold. */
typedef struct ps_gl_direct_bake {
    size_t count;
    ps_bake_target *targets;
    GLuint *tex, *fbo;
    bool *flip;          /* a target's texture rows run against edge2 (its lay kept GL's winding) */
    bool *object_baked;  /* per scene object: the textures are its direct light */
    size_t objects;
    size_t next;         /* targets laid so far */
    bool laid;           /* all of them */
    bool none;           /* nothing to lay (no diffuse quad, too many texels, no memory) */
    uint64_t epoch;      /* what they are laid for */
    double exposure;
    bool shadows;
} ps_gl_direct_bake;

/* A still view drawn ahead, while the first round is traced (into the
 * colour buffer, ps_gl_draw_view_ahead, or the float layers,
 * ps_gl_layers_view_ahead): for cam, with this exposure and direct flag, by
 * renderer at its lit epoch (lights and shadows) with `bakes` direct
 * textures laid (a new laying draws them). held until used or dropped. */
typedef struct ps_gl_ahead {
    bool held;
    ps_camera_frame cam;
    double exposure;
    bool direct;
    const ps_gl_renderer *renderer;
    uint64_t epoch;
    unsigned bakes;
} ps_gl_ahead;
/* Holds the view r has just drawn for cam (after the drawing: its shadow maps count the epoch up). */
void ps_gl_ahead_hold(ps_gl_ahead *a, const ps_gl_renderer *r, const ps_camera_frame *cam, double exposure,
                      bool direct);
/* Whether a held view is the still view of cam that f asks r for. */
bool ps_gl_ahead_is(const ps_gl_ahead *a, const ps_gl_renderer *r, const ps_camera_frame *cam,
                    const ps_session_frame *f);

/* A view's lit passes left for later (defer_lit): what they need of
 * the view, its target, size, matrices and mesh, kept until they are drawn
 * (ps_gl_draw_deferred_lit). */
typedef struct ps_gl_deferred_lit {
    bool pending;   /* a view's lit passes not drawn yet */
    GLint fbo;      /* the view's target (the framebuffer bound when it began) */
    int width, height;
    double proj[16], view[16], eye_extent;
    const ps_preview_mesh *lit;
    ps_vec3 eye;
    double exposure;
    bool shadows, baked;
    bool skip_specular, hide_emitters; /* as the view had them (a cube face sets both its own way) */
    uint64_t epoch; /* lit_epoch at the view: another, and the passes are dropped */
} ps_gl_deferred_lit;

struct ps_gl_renderer {
    ps_gl_scene in;
    /* The mesh this frame's lit passes draw: in.mesh, or in.moving for a
     * level of detail (ps_gl_begin_frame_shadows). */
    const ps_preview_mesh *lit;
    ps_gl_options opt;
    int shadow_size;
    /* shadow[i][f]: GL light i's depth texture of cube face f (0: none yet). */
    GLuint (*shadow)[PS_CUBE_FACES];
    size_t shadow_lights; /* lights that shadow[] has room for */
    bool shadows_valid;   /* every lit face of every light is fresh */
    /* What each light's faces were rendered for, and the depth-only mesh's
     * objects they saw (gl_lights.c): a new scene keeps the faces no change
     * can reach, so an edit renders only those. */
    struct ps_gl_shadow_key *shadow_keys; /* shadow_lights of them */
    struct ps_gl_object_sig *object_sigs;
    size_t object_sig_count;
    /* The shadow maps timed without waiting for them (ps_gl_make_shadow_maps):
     * GL's time at their start, and a timestamp query at their end, read by
     * ps_gl_settle_shadow_timing. NULL entry points: timed by glFinish. */
    PFNGLQUERYCOUNTERPROC query_counter;
    PFNGLGETQUERYOBJECTUI64VPROC query_result;
    GLuint shadow_query;
    bool shadow_query_pending;
    GLint64 shadow_gl_start; /* ns, GL's clock */
    GLuint fbo, kernel_tex, spot_tex;
    GLuint *profile_tex; /* the IES lights' cube maps, as lights->profiles */
    size_t profile_count;
    double kernel_extent; /* the kernel texture's half side in splat radii */
    double scene_diag;
    /* The size of the eye coordinates GL computes this frame: the eye's
     * distance from the origin plus the farthest scene point's from the eye. */
    double eye_extent;
    int width, height;
    double view[16], proj[16];
    ps_gl_stats stats;
    /* The scene's map_Kd textures (gl_albedo.c): GL names, and what each was made from. */
    GLuint *albedo_tex;
    const struct ps_texture **albedo_src;
    size_t albedo_count;
    /* Mirrors and glass left out of every mesh pass (the specular layer's
     * cube maps, gl_specular.c, which look from inside them). */
    bool skip_specular;
    /* Each range of the fine mesh's bounds, for the shadowed lit passes'
     * culling (ps_gl_draw_mesh_within); made for the positions named
     * (NULL when out of memory: nothing culled). */
    ps_aabb *range_bounds;
    const float *range_bounds_of;
    /* What the lit passes draw: counted up whenever what they would draw
     * changes (new inputs, materials, shadow faces); the direct light's
     * textures are valid for one count. */
    uint64_t lit_epoch;
    ps_gl_direct_bake direct_bake;
    /* Lit passes of only this object (UINT32_MAX: every one), for laying
     * its textures; and without the objects drawn from them. */
    uint32_t only_object;
    bool skip_baked;
    bool direct_bake_off; /* this frame draws the lit passes whatever is laid (cube faces) */
    /* ps_gl_draw_view_ahead: the still view in the framebuffer; dropped by
     * the next view begun. */
    ps_gl_ahead ahead;
    ps_gl_deferred_lit deferred;
};

/* Textures (gl_albedo.c). The lit passes and the splats use the materials'
 * plain albedo (Kd); textured surfaces are then multiplied by their texture
 * (the factor T, 1 elsewhere): in the layers' composite each layer times a
 * T layer, in a single colour buffer a last pass multiplying what is there. */
ps_status ps_gl_albedo_sync(ps_gl_renderer *r, ps_error *err); /* uploads the scene's textures once */
void ps_gl_albedo_free(ps_gl_renderer *r);
bool ps_gl_has_albedo(const ps_gl_renderer *r);
/* The visible surfaces' T, unlit, against the depth drawn (GL_LEQUAL), into the bound buffer. */
void ps_gl_draw_albedo(const ps_gl_renderer *r);
/* The bound buffer times T (nothing when the scene has no textures). */
void ps_gl_multiply_albedo(const ps_gl_renderer *r);

/* An additive pass over what the frame drew (splats, illumination maps, the
 * specular lookups): the camera's matrices, no lighting, the depth test
 * against the prepass (GL_LEQUAL, no writes), blending on; the caller picks
 * the blend function (gl_render.c). */
void ps_gl_begin_additive_pass(const ps_gl_renderer *r);

/* The bound cube map sampled linearly, clamped at its faces' edges (IES
 * tables, the specular layer's environment maps; gl_render.c). */
void ps_gl_cube_linear_clamped(void);

/* Matrices, column-major as GL's (gl_render.c). */
void ps_gl_mat_mul(const double a[16], const double b[16], double out[16]);
/* gluLookAt with an orthonormal frame (right, up, -forward). */
void ps_gl_mat_look(ps_vec3 eye, ps_vec3 forward, ps_vec3 right, ps_vec3 up, double m[16]);
/* gluPerspective from tan(fov_y / 2). */
void ps_gl_mat_perspective(double tan_half, double aspect, double znear, double zfar, double m[16]);
/* Distances from p to the nearest and farthest points of box b. */
void ps_gl_box_range(ps_aabb b, ps_vec3 p, double *nearest, double *farthest);

/* The mesh (gl_render.c): fine with materials for lit passes, else the
 * coarse one for depth; with `stencil` each object writes its stencil value
 * (ps_splat_stencil). The exposure is in the lights, not here. */
void ps_gl_draw_mesh(const ps_gl_renderer *r, bool with_materials, bool stencil);
/* The fine mesh with materials, but the ranges that lie wholly on the
 * clipped side of one of the planes (world (a, b, c, d), GL keeping
 * a x + b y + c z + d >= 0, as glClipPlane) left out: they would draw
 * nothing. A shadowed lit pass draws one cube face's pyramid, which most of
 * a scene's objects lie outside; GL clips only after it has lit them. */
void ps_gl_draw_mesh_within(ps_gl_renderer *r, const double (*planes)[4], int plane_count);

/* GL's colour clamps off, vertex, fragment and read: radiance is kept as it
 * is on the way, and only an 8-bit buffer's store clamps it. Context state;
 * the renderer sets it when made and every pass that relies on it again. */
void ps_gl_unclamp_colour(void);

/* Lights (gl_lights.c). */
ps_status ps_gl_lights_reset(ps_gl_renderer *r, ps_error *err); /* new lights: shadow slots, maps remade */
void ps_gl_lights_free(ps_gl_renderer *r);
void ps_gl_make_spot_texture(ps_gl_renderer *r);
void ps_gl_make_shadow_maps(ps_gl_renderer *r);
/* The timestamp query's answer added to the shadow maps' seconds, if one is
 * pending: waits for GL to reach the maps' end if it has not. */
void ps_gl_settle_shadow_timing(ps_gl_renderer *r);
/* Where GL has timer queries and the platform gives them: the entry points
 * and the query (ps_gl_options.gl_proc). */
void ps_gl_timer_init(ps_gl_renderer *r);
/* Each GL light's pass added to the frame, times exposure, then emissive
 * faces; shadows: through the shadow cubes (else one pass a light). */
void ps_gl_draw_direct(ps_gl_renderer *r, double exposure, bool shadows);
/* ps_gl_begin_frame with the shadows said here instead of by the options
 * (the window's moving camera draws without them), and lod: the lit
 * passes (and the texture factor) on the scene's moving mesh (in.moving),
 * a level of detail: a moving camera's, or the eye's while the lights are
 * a coarse level (in.coarse_lights, which ps_gl_begin_frame follows; a
 * cube face, which outlives that level, passes false). defer_lit: the view
 * draws its shadow maps, depth prepass and emitters, and leaves its lit passes to
 * ps_gl_draw_deferred_lit, for a caller whose view has a target of its own
 * (the float layers' direct layer): llvmpipe rasterises what is drawn
 * meanwhile (the splats, into the other layers) while the lit passes are
 * issued, and the direct layer is the same. */
void ps_gl_begin_frame_shadows(ps_gl_renderer *r, const ps_camera_frame *cam, double exposure, bool direct,
                               bool shadows, bool lod, bool defer_lit);
/* Area lights as the eye sees them, in their radiance times exposure, or
 * black when the direct layer is off. */
void ps_gl_draw_emitters(const ps_gl_renderer *r, double exposure, bool direct);
/* Their colour again, where ps_gl_draw_emitters drew them (GL_EQUAL against
 * the depth they wrote, which nothing after them writes): over passes
 * drawn after them that they would have covered. */
void ps_gl_draw_emitters_colour(const ps_gl_renderer *r, double exposure, bool direct);

/* A view's lit passes left (ps_gl_begin_frame_shadows' defer_lit), drawn into its target, and
 * the emitters' colour over them (ps_gl_draw_emitters_colour: the view drew
 * them after its lit passes). Nothing when none are left, or when the
 * lights or shadows have changed since (lit_epoch): that view is stale and
 * is drawn again before it is shown (ps_gl_ahead_is; ps_gl_layers_draw
 * draws its own in one call). The framebuffer bound is kept; the matrices
 * and the viewport are the view's after. ps_gl_begin_frame_shadows draws
 * them first when it begins a view into another target, and drops them
 * when into theirs (the new view clears it). */
void ps_gl_draw_deferred_lit(ps_gl_renderer *r);

/* Layers (gl_layers.c): the depth-stencil buffer every layer shares, and
 * one more texture (the specular layer, gl_specular.c) added to the
 * composite times its gain (0: left out). */
GLuint ps_gl_layers_depth_stencil(const ps_gl_layers *l);
/* The layers' texture size (the view drawn may be smaller: ps_gl_layers_draw). */
void ps_gl_layers_size(const ps_gl_layers *l, int *width, int *height);
void ps_gl_layers_set_extra(ps_gl_layers *l, GLuint texture, double gain);

/* Splats (gl_splat.c). */
void ps_gl_upload_kernel(ps_gl_renderer *r, const ps_kernel_texture *k);
/* A map's baked textures (preview/bake.h, gl_bake.c): one RGBA32F texture
 * and FBO a target of the session's plan, made when the plan's first splats
 * come, dropped when the session says the plan is new. */
typedef struct ps_gl_bake {
    size_t count;
    ps_bake_target *targets;
    GLuint *tex, *fbo;
    bool complete; /* every FBO could be made (else nothing is baked or drawn) */
} ps_gl_bake;
void ps_gl_bake_reset(ps_gl_bake *g);
/* tex an RGBA32F texture of width x height, bilinear and clamped to its
 * edge, cleared, and fbo's colour attachment (left bound): whether GL can
 * render into it. The baked maps' and the direct light's. */
bool ps_gl_float_target(GLuint tex, GLuint fbo, int width, int height);
/* The plan's splats of this refresh added to its textures (made first). */
void ps_gl_bake_lay(ps_gl_bake *g, ps_gl_renderer *r, const ps_bake *plan);
/* Each target on the side the eye sees, textured, added to the bound
 * framebuffer under the view's matrices where its object shows. */
void ps_gl_bake_draw(const ps_gl_bake *g, const ps_gl_renderer *r, ps_vec3 eye);

void ps_gl_direct_bake_free(ps_gl_renderer *r);
/* Whether the textures hold this exposure's direct light for the lights,
 * geometry and materials as they stand: a view then draws them. */
bool ps_gl_direct_bake_ready(const ps_gl_renderer *r, double exposure);
/* The textures on their quads, the side the eye sees, added to the bound
 * framebuffer under the view's matrices against the prepass's depth. */
void ps_gl_direct_bake_draw(const ps_gl_renderer *r, ps_vec3 eye);


#endif
