/* bsdf.c: Fresnel, refraction and the Phong BRDF. */
#include "scene/bsdf.h"

#include <math.h>

double ps_fresnel_dielectric(double cos_i, double eta_i, double eta_t)
{
    /* Equal indices are no interface at all: nothing reflects, even at
     * grazing, where the formulas below round sin_t to 1 and would call it
     * total internal reflection. */
    if (eta_i == eta_t)
        return 0.0;
    cos_i = fmin(fmax(cos_i, 0.0), 1.0);
    double sin_t = eta_i / eta_t * sqrt(fmax(0.0, 1.0 - cos_i * cos_i));
    if (sin_t >= 1.0)
        return 1.0;
    double cos_t = sqrt(fmax(0.0, 1.0 - sin_t * sin_t));
    double r_par = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    double r_perp = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    return 0.5 * (r_par * r_par + r_perp * r_perp);
}

bool ps_refract(ps_vec3 d, ps_vec3 n, double eta, ps_vec3 *out)
{
    double cos_i = -ps_v3_dot(d, n);
    double sin2_t = eta * eta * fmax(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0)
        return false;
    double cos_t = sqrt(1.0 - sin2_t);
    *out = ps_v3_norm(ps_v3_add(ps_v3_scale(d, eta), ps_v3_scale(n, eta * cos_i - cos_t)));
    return true;
}

ps_rgb ps_bsdf_eval(const ps_material *m, ps_vec3 n, ps_vec3 d_in, ps_vec3 w_out)
{
    if (m->type != PS_MAT_DIFFUSE && m->type != PS_MAT_GLOSSY)
        return ps_rgb_gray(0.0); /* delta distributions have no density to evaluate */
    ps_rgb f = ps_rgb_scale(m->albedo, PS_INV_PI);
    if (m->type == PS_MAT_GLOSSY) {
        double c = ps_v3_dot(ps_reflect(d_in, n), w_out);
        if (c > 0.0)
            f = ps_rgb_add(f, ps_rgb_scale(m->specular, (m->exponent + 2.0) * 0.5 * PS_INV_PI * pow(c, m->exponent)));
    }
    return f;
}
