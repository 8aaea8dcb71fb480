/* path_record.c: the repair's path records (path_record.h). */
#include "photon/path_record.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/array.h"

#define QUANT_STEPS 65535.0

ps_path_quant ps_path_quant_make(ps_aabb box, double offset)
{
    ps_path_quant q;
    q.box = box;
    ps_vec3 ext = ps_v3_sub(box.hi, box.lo);
    q.step = ps_v3(ext.x / QUANT_STEPS, ext.y / QUANT_STEPS, ext.z / QUANT_STEPS);
    /* A dequantised vertex lies within half a step of the true one on each
     * axis; segments start at the ray offset from their vertex. Twice both
     * leaves room for the float rounding of the tests themselves. */
    q.margin = 2.0 * (fmax(q.step.x, fmax(q.step.y, q.step.z)) + offset);
    return q;
}

static uint16_t quant1(double v, double lo, double step)
{
    if (!(step > 0.0))
        return 0;
    double x = floor((v - lo) / step + 0.5);
    return (uint16_t)(x < 0.0 ? 0.0 : x > QUANT_STEPS ? QUANT_STEPS : x);
}

ps_path_vertex ps_path_quantize(const ps_path_quant *q, ps_vec3 p)
{
    ps_path_vertex v;
    v.q[0] = quant1(p.x, q->box.lo.x, q->step.x);
    v.q[1] = quant1(p.y, q->box.lo.y, q->step.y);
    v.q[2] = quant1(p.z, q->box.lo.z, q->step.z);
    return v;
}

ps_vec3 ps_path_dequantize(const ps_path_quant *q, ps_path_vertex v)
{
    return ps_v3(q->box.lo.x + v.q[0] * q->step.x, q->box.lo.y + v.q[1] * q->step.y,
                 q->box.lo.z + v.q[2] * q->step.z);
}

ps_vec3 ps_path_exit(const ps_path_quant *q, ps_vec3 o, ps_vec3 d)
{
    double t = INFINITY;
    const double oa[3] = {o.x, o.y, o.z}, da[3] = {d.x, d.y, d.z};
    const double lo[3] = {q->box.lo.x, q->box.lo.y, q->box.lo.z}, hi[3] = {q->box.hi.x, q->box.hi.y, q->box.hi.z};
    for (int a = 0; a < 3; a++) {
        if (da[a] > 0.0)
            t = fmin(t, (hi[a] - oa[a]) / da[a]);
        else if (da[a] < 0.0)
            t = fmin(t, (lo[a] - oa[a]) / da[a]);
    }
    if (!isfinite(t) || t < 0.0)
        t = 0.0;
    return ps_v3_madd(o, d, t);
}

void ps_path_store_init(ps_path_store *s) { memset(s, 0, sizeof *s); }

void ps_path_store_free(ps_path_store *s)
{
    free(s->rec);
    free(s->vert);
    free(s->thr);
    ps_path_store_init(s);
}

bool ps_path_store_reserve(ps_path_store *s, size_t need) { return PS_RESERVE(s->rec, s->cap, need); }

void ps_path_begin(ps_path_store *s)
{
    if (s->failed || !PS_RESERVE(s->rec, s->cap, s->count + 1)) {
        s->failed = true;
        return;
    }
    ps_path_rec *r = &s->rec[s->count++];
    memset(r, 0, sizeof *r);
    r->first = (uint32_t)s->vcount;
}

void ps_path_add_vertex(ps_path_store *s, ps_path_vertex v)
{
    if (s->failed || s->count == 0)
        return;
    if (s->vcount >= UINT32_MAX || !PS_RESERVE(s->vert, s->vcap, s->vcount + 1)) {
        s->failed = true;
        return;
    }
    s->vert[s->vcount++] = v;
    s->rec[s->count - 1].vertices++;
}

void ps_path_add_thr(ps_path_store *s, ps_path_thr t)
{
    if (s->failed || !PS_RESERVE(s->thr, s->tcap, s->tcount + 1)) {
        s->failed = true;
        return;
    }
    s->thr[s->tcount++] = t;
}

static void append_thr(ps_path_store *dst, const ps_path_store *src)
{
    if (src->tcount)
        memcpy(dst->thr + dst->tcount, src->thr, src->tcount * sizeof *src->thr);
    dst->tcount += src->tcount;
}

bool ps_path_store_append(ps_path_store *dst, const ps_path_store *src)
{
    if (src->vcount > UINT32_MAX - dst->vcount || !PS_RESERVE(dst->rec, dst->cap, dst->count + src->count) ||
        !PS_RESERVE(dst->vert, dst->vcap, dst->vcount + src->vcount) ||
        !PS_RESERVE(dst->thr, dst->tcap, dst->tcount + src->tcount))
        return false;
    append_thr(dst, src);
    for (size_t k = 0; k < src->count; k++) {
        ps_path_rec r = src->rec[k];
        r.first += (uint32_t)dst->vcount;
        dst->rec[dst->count + k] = r;
    }
    memcpy(dst->vert + dst->vcount, src->vert, src->vcount * sizeof *src->vert);
    dst->count += src->count;
    dst->vcount += src->vcount;
    return true;
}

bool ps_path_store_put(ps_path_store *dst, const ps_path_store *src, const uint64_t *idx)
{
    if (src->vcount > UINT32_MAX - dst->vcount || !PS_RESERVE(dst->vert, dst->vcap, dst->vcount + src->vcount) ||
        !PS_RESERVE(dst->thr, dst->tcap, dst->tcount + src->tcount))
        return false;
    append_thr(dst, src);
    for (size_t k = 0; k < src->count; k++) {
        ps_path_rec r = src->rec[k];
        r.first += (uint32_t)dst->vcount;
        r.flags = dst->rec[idx[k]].flags;
        dst->rec[idx[k]] = r;
    }
    memcpy(dst->vert + dst->vcount, src->vert, src->vcount * sizeof *src->vert);
    dst->vcount += src->vcount;
    return true;
}

bool ps_path_store_compact(ps_path_store *s)
{
    size_t n = 0;
    for (size_t k = 0; k < s->count; k++)
        n += s->rec[k].vertices;
    ps_path_vertex *v = malloc((n ? n : 1) * sizeof *v);
    if (!v)
        return false;
    size_t at = 0;
    for (size_t k = 0; k < s->count; k++) {
        ps_path_rec *r = &s->rec[k];
        memcpy(v + at, s->vert + r->first, r->vertices * sizeof *v);
        r->first = (uint32_t)at;
        at += r->vertices;
    }
    free(s->vert);
    s->vert = v;
    s->vcount = s->vcap = n ? n : 1;
    s->vcount = n;
    return true;
}

bool ps_segment_meets_box(ps_vec3 a, ps_vec3 b, ps_aabb box, double margin)
{
    const double pa[3] = {a.x, a.y, a.z}, pb[3] = {b.x, b.y, b.z};
    const double lo[3] = {box.lo.x - margin, box.lo.y - margin, box.lo.z - margin};
    const double hi[3] = {box.hi.x + margin, box.hi.y + margin, box.hi.z + margin};
    double t0 = 0.0, t1 = 1.0;
    for (int k = 0; k < 3; k++) {
        double d = pb[k] - pa[k];
        if (d == 0.0) {
            if (pa[k] < lo[k] || pa[k] > hi[k])
                return false;
            continue;
        }
        double u = (lo[k] - pa[k]) / d, v = (hi[k] - pa[k]) / d;
        if (u > v) {
            double w = u;
            u = v;
            v = w;
        }
        t0 = u > t0 ? u : t0;
        t1 = v < t1 ? v : t1;
        if (t0 > t1)
            return false;
    }
    return true;
}

bool ps_path_meets(const ps_path_store *s, const ps_path_rec *r, const ps_path_quant *q, ps_aabb b)
{
    if (r->vertices == 1) /* one point: a photon that left nothing but its origin */
        return ps_segment_meets_box(ps_path_dequantize(q, s->vert[r->first]),
                                    ps_path_dequantize(q, s->vert[r->first]), b, q->margin);
    for (uint32_t k = 1; k < r->vertices; k++) {
        ps_vec3 a = ps_path_dequantize(q, s->vert[r->first + k - 1]);
        ps_vec3 c = ps_path_dequantize(q, s->vert[r->first + k]);
        if (ps_segment_meets_box(a, c, b, q->margin))
            return true;
    }
    return false;
}
