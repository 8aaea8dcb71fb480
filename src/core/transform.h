/* transform.h: affine transforms for placing meshes (scale, rotate, translate). */
#ifndef PS_CORE_TRANSFORM_H
#define PS_CORE_TRANSFORM_H

#include "core/vec.h"

/* Row-major 3x4 affine map: p' = M·(p, 1). Plain value type. */
typedef struct ps_xform { double m[3][4]; } ps_xform;

ps_xform ps_xform_identity(void);
ps_xform ps_xform_translate(ps_vec3 t);
ps_xform ps_xform_scale(ps_vec3 s);
/* Rotation by `degrees` about `axis` (any non-zero length), right-handed. */
ps_xform ps_xform_rotate(ps_vec3 axis, double degrees);
/* a∘b: first b, then a. */
ps_xform ps_xform_compose(ps_xform a, ps_xform b);
/* Determinant of the linear part; zero means the map flattens space. */
double ps_xform_det(ps_xform x);

static inline ps_vec3 ps_xform_point(const ps_xform *x, ps_vec3 p)
{
    return ps_v3(x->m[0][0] * p.x + x->m[0][1] * p.y + x->m[0][2] * p.z + x->m[0][3],
                 x->m[1][0] * p.x + x->m[1][1] * p.y + x->m[1][2] * p.z + x->m[1][3],
                 x->m[2][0] * p.x + x->m[2][1] * p.y + x->m[2][2] * p.z + x->m[2][3]);
}
static inline ps_vec3 ps_xform_vector(const ps_xform *x, ps_vec3 v)
{
    return ps_v3(x->m[0][0] * v.x + x->m[0][1] * v.y + x->m[0][2] * v.z,
                 x->m[1][0] * v.x + x->m[1][1] * v.y + x->m[1][2] * v.z,
                 x->m[2][0] * v.x + x->m[2][1] * v.y + x->m[2][2] * v.z);
}
/* Normals transform by the inverse transpose of the linear part; the result is
 * unit length. Uses the cofactor matrix (= det · inverse transpose), so no
 * inverse is formed; the sign is fixed so that a mirroring transform keeps
 * outward normals outward. */
ps_vec3 ps_xform_normal(const ps_xform *x, ps_vec3 n);

#endif
