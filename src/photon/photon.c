/* photon.c: packing and unpacking the 20-byte photon record. */
#include "photon/photon.h"

#include <math.h>
#include <string.h>

/* RGBE exponents are stored biased by 128 in one byte (Ward, Graphics Gems II). */
#define RGBE_BIAS 128
#define RGBE_MANTISSA 256.0 /* 8-bit mantissas: values are m * 2^(e - 8) */
#define RGBE_MANTISSA_BITS 8
/* Octahedral coordinates in [-1, 1] are quantised to `bits` bits each, over
 * an even number of steps (2^bits - 2) so that 0 (the axes and the fold
 * lines) is exact. */
static double oct_levels(int bits) { return (double)((1u << bits) - 2u); }
/* The normal shares its 16 bits with the flags: 7 + 7 bits, flags on top. */
#define NORMAL_BITS 7
#define NORMAL_MASK 0x3fffu
#define FLAGS_SHIFT 14

const char *const ps_map_names[PS_MAP_COUNT + 1] = {"caustic", "global", NULL};

const char *ps_map_name(ps_map_kind k) { return (unsigned)k < PS_MAP_COUNT ? ps_map_names[k] : "?"; }

static double clean(double v) { return v > 0.0 && isfinite(v) ? v : (v > 0.0 ? HUGE_VAL : 0.0); }

void ps_rgbe_encode(ps_rgb c, double dither, uint8_t out[4])
{
    double r = clean(c.r), g = clean(c.g), b = clean(c.b);
    double v = fmax(r, fmax(g, b));
    int e;
    (void)frexp(v, &e); /* v = m 2^e, m in [0.5, 1) */
    if (!(v > 0.0) || e + RGBE_BIAS < 1) {
        out[0] = out[1] = out[2] = out[3] = 0;
        return;
    }
    if (!isfinite(v) || e + RGBE_BIAS > 255) { /* beyond 2^127 W: clamp, never wrap */
        out[0] = out[1] = out[2] = 255;
        out[3] = 255;
        return;
    }
    /* Rounding may carry the largest mantissa to 256: then use the next exponent. */
    double scale = ldexp(RGBE_MANTISSA, -e);
    if (!(dither >= 0.0 && dither < 1.0))
        dither = 0.5;
    if (floor(v * scale + dither) > 255.0) {
        e++;
        scale *= 0.5;
        if (e + RGBE_BIAS > 255) {
            out[0] = out[1] = out[2] = out[3] = 255;
            return;
        }
    }
    out[0] = (uint8_t)fmin(floor(r * scale + dither), 255.0);
    out[1] = (uint8_t)fmin(floor(g * scale + dither), 255.0);
    out[2] = (uint8_t)fmin(floor(b * scale + dither), 255.0);
    out[3] = (uint8_t)(e + RGBE_BIAS);
}

ps_rgb ps_rgbe_decode(const uint8_t in[4])
{
    if (in[3] == 0)
        return ps_rgb_gray(0.0);
    /* 2^(e - 128 - 8), built from its bits rather than by ldexp (a library
     * call on every photon of every splat and estimate): exponents 1..255
     * give -135..119, all normal doubles. */
    uint64_t bits = (uint64_t)((int)in[3] - RGBE_BIAS - RGBE_MANTISSA_BITS + 1023) << 52;
    double f;
    memcpy(&f, &bits, sizeof f);
    return ps_rgb_make(in[0] * f, in[1] * f, in[2] * f);
}

uint16_t ps_oct_encode_bits(ps_vec3 v, int bits)
{
    const double levels = oct_levels(bits);
    double l1 = fabs(v.x) + fabs(v.y) + fabs(v.z);
    if (!(l1 > 0.0) || !isfinite(l1))
        v = ps_v3(0.0, 0.0, 1.0), l1 = 1.0;
    v = ps_v3_scale(v, 1.0 / l1);
    double x = v.x, y = v.y;
    if (v.z < 0.0) { /* fold the lower hemisphere over the diagonals */
        double fx = (1.0 - fabs(y)) * (x >= 0.0 ? 1.0 : -1.0);
        double fy = (1.0 - fabs(x)) * (y >= 0.0 ? 1.0 : -1.0);
        x = fx;
        y = fy;
    }
    /* Of the four codes around (x, y), keep the one that decodes closest to v
     * (Cigolle et al. 2014): worst error 0.7 instead of 0.95 degrees. */
    double gx = fmin(fmax((x * 0.5 + 0.5) * levels, 0.0), levels);
    double gy = fmin(fmax((y * 0.5 + 0.5) * levels, 0.0), levels);
    ps_vec3 unit = ps_v3_norm(v);
    uint16_t best = 0;
    double best_dot = -2.0;
    for (int k = 0; k < 4; k++) {
        double qx = (k & 1) ? ceil(gx) : floor(gx), qy = (k & 2) ? ceil(gy) : floor(gy);
        uint16_t code = (uint16_t)((unsigned)qx << bits | (unsigned)qy);
        double d = ps_v3_dot(ps_oct_decode_bits(code, bits), unit);
        if (d > best_dot) {
            best_dot = d;
            best = code;
        }
    }
    return best;
}

ps_vec3 ps_oct_decode_bits(uint16_t code, int bits)
{
    const double levels = oct_levels(bits);
    double x = (code >> bits) / levels * 2.0 - 1.0;
    double y = (code & ((1u << bits) - 1u)) / levels * 2.0 - 1.0;
    double z = 1.0 - fabs(x) - fabs(y);
    if (z < 0.0) {
        double fx = (1.0 - fabs(y)) * (x >= 0.0 ? 1.0 : -1.0);
        double fy = (1.0 - fabs(x)) * (y >= 0.0 ? 1.0 : -1.0);
        x = fx;
        y = fy;
    }
    return ps_v3_norm(ps_v3(x, y, z));
}

ps_photon ps_photon_pack(ps_vec3 pos, ps_rgb power, ps_vec3 dir, ps_vec3 normal, double dither)
{
    ps_photon p;
    p.pos[0] = (float)pos.x;
    p.pos[1] = (float)pos.y;
    p.pos[2] = (float)pos.z;
    ps_rgbe_encode(power, dither, p.rgbe);
    p.dir = ps_oct_encode_bits(dir, PS_OCT_DIR_BITS);
    p.normal_flags = ps_oct_encode_bits(normal, NORMAL_BITS); /* flags 0 */
    return p;
}

ps_rgb ps_photon_power(const ps_photon *p) { return ps_rgbe_decode(p->rgbe); }
ps_vec3 ps_photon_dir(const ps_photon *p) { return ps_oct_decode_bits(p->dir, PS_OCT_DIR_BITS); }
ps_vec3 ps_photon_normal(const ps_photon *p)
{
    return ps_oct_decode_bits((uint16_t)(p->normal_flags & NORMAL_MASK), NORMAL_BITS);
}
unsigned ps_photon_flags(const ps_photon *p) { return (unsigned)p->normal_flags >> FLAGS_SHIFT; }
void ps_photon_set_flags(ps_photon *p, unsigned flags)
{
    p->normal_flags = (uint16_t)((p->normal_flags & NORMAL_MASK) | (flags & 3u) << FLAGS_SHIFT);
}
