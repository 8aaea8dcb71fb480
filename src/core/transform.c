/* transform.c: affine transform construction and composition. */
#include "core/transform.h"

ps_xform ps_xform_identity(void)
{
    ps_xform x = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    return x;
}

ps_xform ps_xform_translate(ps_vec3 t)
{
    ps_xform x = {{{1, 0, 0, t.x}, {0, 1, 0, t.y}, {0, 0, 1, t.z}}};
    return x;
}

ps_xform ps_xform_scale(ps_vec3 s)
{
    ps_xform x = {{{s.x, 0, 0, 0}, {0, s.y, 0, 0}, {0, 0, s.z, 0}}};
    return x;
}

ps_xform ps_xform_rotate(ps_vec3 axis, double degrees)
{
    ps_vec3 a = ps_v3_norm(axis);
    double th = degrees * (PS_PI / 180.0);
    double s = sin(th), c = cos(th), t = 1.0 - c;
    ps_xform x = {{{t * a.x * a.x + c, t * a.x * a.y - s * a.z, t * a.x * a.z + s * a.y, 0},
                   {t * a.x * a.y + s * a.z, t * a.y * a.y + c, t * a.y * a.z - s * a.x, 0},
                   {t * a.x * a.z - s * a.y, t * a.y * a.z + s * a.x, t * a.z * a.z + c, 0}}};
    return x;
}

ps_xform ps_xform_compose(ps_xform a, ps_xform b)
{
    ps_xform r;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++) {
            double v = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
            r.m[i][j] = v + (j == 3 ? a.m[i][3] : 0.0);
        }
    }
    return r;
}

double ps_xform_det(ps_xform x)
{
    const double(*m)[4] = x.m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

ps_vec3 ps_xform_normal(const ps_xform *x, ps_vec3 n)
{
    const double(*m)[4] = x->m;
    /* Rows of the cofactor matrix are cross products of the columns' pairs. */
    ps_vec3 c0 = ps_v3(m[0][0], m[1][0], m[2][0]);
    ps_vec3 c1 = ps_v3(m[0][1], m[1][1], m[2][1]);
    ps_vec3 c2 = ps_v3(m[0][2], m[1][2], m[2][2]);
    ps_vec3 r = ps_v3_add(ps_v3_add(ps_v3_scale(ps_v3_cross(c1, c2), n.x), ps_v3_scale(ps_v3_cross(c2, c0), n.y)),
                          ps_v3_scale(ps_v3_cross(c0, c1), n.z));
    /* cofactor = det·M^-T: for a mirroring transform (det < 0) it points
     * inward, so flip it back to M^-T's direction, which keeps "outside"
     * outside. (The mesh loader swaps the winding of mirrored triangles so that
     * their geometric normals agree.) */
    if (ps_xform_det(*x) < 0.0)
        r = ps_v3_neg(r);
    return ps_v3_norm(r);
}
