/* camera.h: the pinhole camera shared by the reference renderer and the
 * OpenGL preview, so that both put the same point in the same pixel.
 *
 * It is gluLookAt(eye, target, up) followed by gluPerspective(fov, w / h):
 * image position (x, y) in pixels, x from the left edge and y from the top
 * edge, maps to normalised device coordinates (2x/w - 1, 1 - 2y/h); pixel
 * (i, j)'s centre is (i + 0.5, j + 0.5), the point GL samples. */
#ifndef PS_SCENE_CAMERA_H
#define PS_SCENE_CAMERA_H

#include "core/vec.h"
#include "scene/scene.h"

typedef struct ps_camera_frame {
    ps_vec3 eye;
    ps_vec3 forward, right, up; /* orthonormal; right = forward x up (gluLookAt's s) */
    double tan_half_fov;        /* tan(fov_y / 2) */
    double aspect;              /* width / height */
    int width, height;
} ps_camera_frame;

/* width, height >= 1. */
ps_camera_frame ps_camera_frame_make(const ps_camera *c, int width, int height);

/* Whether a and b are the same view: eye, axes, field of view and pixels
 * (what the preview compares to tell a camera move, and the specular
 * layer's per-pixel paths to tell their frame). */
bool ps_camera_frame_equal(const ps_camera_frame *a, const ps_camera_frame *b);

/* The ray from the eye through image position (x, y); unit direction. */
ps_ray ps_camera_ray(const ps_camera_frame *f, double x, double y);

/* Where point p lands in the image (pixels, as above); false when p is not in
 * front of the camera. */
bool ps_camera_project(const ps_camera_frame *f, ps_vec3 p, double *x, double *y);

#endif
