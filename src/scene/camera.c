/* camera.c: gluLookAt + gluPerspective as rays. */
#include "scene/camera.h"

#include <math.h>

ps_camera_frame ps_camera_frame_make(const ps_camera *c, int width, int height)
{
    ps_camera_frame f;
    f.eye = c->eye;
    f.forward = ps_v3_norm(ps_v3_sub(c->target, c->eye));
    f.right = ps_v3_norm(ps_v3_cross(f.forward, c->up));
    f.up = ps_v3_cross(f.right, f.forward);
    f.tan_half_fov = tan(0.5 * c->fov_deg * PS_PI / 180.0);
    f.width = width;
    f.height = height;
    f.aspect = (double)width / (double)height;
    return f;
}

bool ps_camera_frame_equal(const ps_camera_frame *a, const ps_camera_frame *b)
{
    return ps_v3_equal(a->eye, b->eye) && ps_v3_equal(a->forward, b->forward) && ps_v3_equal(a->right, b->right) &&
           ps_v3_equal(a->up, b->up) && a->tan_half_fov == b->tan_half_fov && a->aspect == b->aspect &&
           a->width == b->width && a->height == b->height;
}

ps_ray ps_camera_ray(const ps_camera_frame *f, double x, double y)
{
    double nx = 2.0 * x / f->width - 1.0, ny = 1.0 - 2.0 * y / f->height;
    ps_vec3 d = ps_v3_add(f->forward, ps_v3_add(ps_v3_scale(f->right, nx * f->tan_half_fov * f->aspect),
                                                ps_v3_scale(f->up, ny * f->tan_half_fov)));
    return ps_ray_make(f->eye, ps_v3_norm(d));
}

bool ps_camera_project(const ps_camera_frame *f, ps_vec3 p, double *x, double *y)
{
    ps_vec3 v = ps_v3_sub(p, f->eye);
    double z = ps_v3_dot(v, f->forward);
    if (!(z > 0.0))
        return false;
    double nx = ps_v3_dot(v, f->right) / (z * f->tan_half_fov * f->aspect);
    double ny = ps_v3_dot(v, f->up) / (z * f->tan_half_fov);
    *x = 0.5 * (nx + 1.0) * f->width;
    *y = 0.5 * (1.0 - ny) * f->height;
    return true;
}
