/* ies.c: the LM-63 reader, the unfolded candela table, its exact integral and
 * its exact sampler (ies.h). */
#include "scene/ies.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/number.h"
#include "core/vec.h"

#define TOKEN_MAX 64
#define HEADER_LINE_MAX 4096
/* Horizontal angles that close the circle within this (degrees) count as 360. */
#define ANGLE_SLACK_DEG 1e-9
/* The vertical sampler stops when the cdf's step is below this fraction of the cell. */
#define NEWTON_TOLERANCE 1e-14
#define NEWTON_ITERATIONS 64

struct ps_ies {
    char *name;
    ps_ies_info info;
    char format[16];
    int nv, nh;       /* the unfolded table: nv vertical x nh horizontal, nh >= 2 */
    double *v, *h;    /* radians; h runs from h[0] to h[0] + 2 pi */
    double *cd;       /* cd[j * nv + i]: horizontal j, vertical i */
    double *cdf;      /* per cell (j * (nv - 1) + i): cumulative flux, last = 1 */
    double flux, peak;
    int tilt_count;
    double *tilt_angle, *tilt_factor; /* degrees; factors */
};

/* ---- the table ------------------------------------------------------------- */

static size_t upper_index(const double *a, int n, double x)
{
    /* The i in [0, n - 2] with a[i] <= x <= a[i + 1] (x inside [a[0], a[n-1]]). */
    int lo = 0, hi = n - 2;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (a[mid] <= x)
            lo = mid;
        else
            hi = mid - 1;
    }
    return (size_t)lo;
}

static double wrap_phi(const ps_ies *ies, double phi)
{
    double h0 = ies->h[0];
    double x = fmod(phi - h0, 2.0 * PS_PI);
    if (x < 0.0)
        x += 2.0 * PS_PI;
    return h0 + x;
}

double ps_ies_candela(const ps_ies *ies, double theta, double phi)
{
    if (!(theta >= ies->v[0] && theta <= ies->v[ies->nv - 1]) || !isfinite(phi))
        return 0.0;
    phi = wrap_phi(ies, phi);
    size_t i = upper_index(ies->v, ies->nv, theta), j = upper_index(ies->h, ies->nh, phi);
    double s = (theta - ies->v[i]) / (ies->v[i + 1] - ies->v[i]);
    double t = (phi - ies->h[j]) / (ies->h[j + 1] - ies->h[j]);
    s = fmin(fmax(s, 0.0), 1.0);
    t = fmin(fmax(t, 0.0), 1.0);
    const double *c0 = ies->cd + j * (size_t)ies->nv, *c1 = c0 + ies->nv;
    return (1.0 - t) * ((1.0 - s) * c0[i] + s * c0[i + 1]) + t * ((1.0 - s) * c1[i] + s * c1[i + 1]);
}

double ps_ies_peak(const ps_ies *ies) { return ies->peak; }
double ps_ies_flux(const ps_ies *ies) { return ies->flux; }
const ps_ies_info *ps_ies_get_info(const ps_ies *ies) { return &ies->info; }
const char *ps_ies_name(const ps_ies *ies) { return ies->name; }

double ps_ies_tilt_factor(const ps_ies *ies, double degrees)
{
    int n = ies->tilt_count;
    if (n == 0)
        return 1.0;
    if (degrees <= ies->tilt_angle[0])
        return ies->tilt_factor[0];
    if (degrees >= ies->tilt_angle[n - 1])
        return ies->tilt_factor[n - 1];
    size_t k = upper_index(ies->tilt_angle, n, degrees);
    double a = ies->tilt_angle[k], b = ies->tilt_angle[k + 1];
    double s = (degrees - a) / (b - a);
    return (1.0 - s) * ies->tilt_factor[k] + s * ies->tilt_factor[k + 1];
}

/* The two weights of a vertical cell [t0, t1] against sin(theta): K0 the
 * integral of (1 - s) sin, K1 of s sin, s = (theta - t0) / (t1 - t0). */
static void cell_weights(double t0, double t1, double *k0, double *k1)
{
    double d = t1 - t0;
    *k1 = (sin(t1) - sin(t0) - d * cos(t1)) / d;
    *k0 = (cos(t0) - cos(t1)) - *k1;
}

/* Cell fluxes, their cdf, the total flux and the peak. */
static bool build_tables(ps_ies *ies)
{
    size_t cells = (size_t)(ies->nv - 1) * (size_t)(ies->nh - 1);
    ies->cdf = malloc(cells * sizeof *ies->cdf);
    if (!ies->cdf)
        return false;
    double total = 0.0;
    for (int j = 0; j + 1 < ies->nh; j++) {
        const double *c0 = ies->cd + (size_t)j * (size_t)ies->nv, *c1 = c0 + ies->nv;
        double dphi = ies->h[j + 1] - ies->h[j];
        for (int i = 0; i + 1 < ies->nv; i++) {
            double k0, k1;
            cell_weights(ies->v[i], ies->v[i + 1], &k0, &k1);
            /* Bilinear: the phi-average of each vertical edge, times K0 / K1. */
            double a0 = 0.5 * (c0[i] + c1[i]), a1 = 0.5 * (c0[i + 1] + c1[i + 1]);
            double f = dphi * (a0 * k0 + a1 * k1);
            total += f > 0.0 ? f : 0.0;
            ies->cdf[(size_t)j * (size_t)(ies->nv - 1) + (size_t)i] = total;
        }
    }
    ies->flux = total;
    for (size_t c = 0; c < cells; c++)
        ies->cdf[c] = total > 0.0 ? ies->cdf[c] / total : (double)(c + 1) / (double)cells;
    ies->cdf[cells - 1] = 1.0;
    ies->peak = 0.0;
    for (size_t k = 0; k < (size_t)ies->nv * (size_t)ies->nh; k++)
        ies->peak = fmax(ies->peak, ies->cd[k]);
    return true;
}

double ps_ies_sample(const ps_ies *ies, double u0, double u1, double u2, double *theta, double *phi)
{
    /* A cell by its flux. */
    size_t cells = (size_t)(ies->nv - 1) * (size_t)(ies->nh - 1);
    size_t lo = 0, hi = cells - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (ies->cdf[mid] > u0)
            hi = mid;
        else
            lo = mid + 1;
    }
    size_t j = lo / (size_t)(ies->nv - 1), i = lo % (size_t)(ies->nv - 1);
    const double *c0 = ies->cd + j * (size_t)ies->nv, *c1 = c0 + ies->nv;
    double t0 = ies->v[i], t1 = ies->v[i + 1], d = t1 - t0;
    double k0, k1;
    cell_weights(t0, t1, &k0, &k1);
    /* The horizontal fraction t: its marginal density is linear, A (1 - t) + B t. */
    double A = fmax(0.0, k0 * c0[i] + k1 * c0[i + 1]), B = fmax(0.0, k0 * c1[i] + k1 * c1[i + 1]);
    double denom = A + sqrt(fmax(0.0, A * A + u1 * (B * B - A * A)));
    double t = denom > 0.0 ? u1 * (A + B) / denom : u1;
    t = fmin(fmax(t, 0.0), 1.0);
    /* The vertical angle: density ((1 - s) a + s b) sin(theta); its cdf
     * F(theta) = a (cos t0 - cos theta) + (b - a) / d (sin theta - sin t0 - (theta - t0) cos theta). */
    double a = (1.0 - t) * c0[i] + t * c1[i], b = (1.0 - t) * c0[i + 1] + t * c1[i + 1];
#define CDF(x) (a * (cos(t0) - cos(x)) + (b - a) / d * (sin(x) - sin(t0) - ((x) - t0) * cos(x)))
    double target = u2 * CDF(t1);
    double x = t0 + u2 * d, lo_x = t0, hi_x = t1;
    for (int it = 0; it < NEWTON_ITERATIONS; it++) {
        double f = CDF(x) - target;
        if (f > 0.0)
            hi_x = x;
        else
            lo_x = x;
        double s = (x - t0) / d;
        double df = ((1.0 - s) * a + s * b) * sin(x);
        double next = df > 0.0 ? x - f / df : 0.5 * (lo_x + hi_x);
        if (!(next > lo_x && next < hi_x))
            next = 0.5 * (lo_x + hi_x); /* Newton left the bracket: bisect */
        if (fabs(next - x) <= NEWTON_TOLERANCE * d) {
            x = next;
            break;
        }
        x = next;
    }
#undef CDF
    *theta = fmin(fmax(x, t0), t1);
    *phi = ies->h[j] + t * (ies->h[j + 1] - ies->h[j]);
    return ies->flux > 0.0 ? ps_ies_candela(ies, *theta, *phi) / ies->flux : 0.0;
}

/* ---- reading ------------------------------------------------------------------ */

typedef struct reader {
    const char *p, *end, *start;
    const char *name;
    int line;
    ps_error *err;
} reader;

/* The next word of the photometric data (separated by blanks, commas or line
 * ends); false at the end of the text. *line: the line it is on. */
static bool next_word(reader *r, char *buf, int *line, bool *too_long)
{
    *too_long = false;
    while (r->p < r->end && (*r->p == ' ' || *r->p == '\t' || *r->p == '\r' || *r->p == '\n' || *r->p == ',' ||
                             *r->p == '\f' || *r->p == '\v')) {
        if (*r->p == '\n')
            r->line++;
        r->p++;
    }
    if (r->p >= r->end)
        return false;
    *line = r->line;
    size_t n = 0;
    while (r->p < r->end && !(*r->p == ' ' || *r->p == '\t' || *r->p == '\r' || *r->p == '\n' || *r->p == ',' ||
                              *r->p == '\f' || *r->p == '\v')) {
        if (n + 1 < TOKEN_MAX)
            buf[n++] = *r->p;
        else
            *too_long = true;
        r->p++;
    }
    buf[n] = '\0';
    return true;
}

/* The file's last line, for problems found at its end. */
static int end_line(const reader *r)
{
    return r->line > 1 && r->p > r->start && r->p[-1] == '\n' ? r->line - 1 : r->line;
}

/* One number of the data; `what` names it in messages ("the number of vertical angles"). */
static ps_status read_number(reader *r, const char *what, double *out, int *at)
{
    char buf[TOKEN_MAX];
    bool too_long;
    int line = r->line;
    if (!next_word(r, buf, &line, &too_long))
        return ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: the file ends before %s", r->name, end_line(r), what);
    if (at)
        *at = line;
    if (too_long)
        return ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: %s: a word of more than %d characters is not a number",
                            r->name, line, what, TOKEN_MAX - 1);
    if (!ps_parse_double(buf, out))
        return ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: %s: '%s' is not a finite number", r->name, line, what, buf);
    return PS_OK;
}

static ps_status read_count(reader *r, const char *what, int lo, int hi, int *out)
{
    double v;
    int line;
    ps_status st = read_number(r, what, &v, &line);
    if (st != PS_OK)
        return st;
    if (v != floor(v))
        return ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: %s: %g is not a whole number", r->name, line, what, v);
    if (v < lo || v > hi)
        return ps_error_set(r->err, v > hi && hi >= PS_IES_MAX_ANGLES ? PS_ERR_LIMIT : PS_ERR_RANGE,
                            "%s:%d: %s: %g is outside [%d, %d]", r->name, line, what, v, lo, hi);
    *out = (int)v;
    return PS_OK;
}

/* n angles in degrees, strictly increasing, inside [lo, hi]. */
static ps_status read_angles(reader *r, const char *what, int n, double lo, double hi, double *out)
{
    for (int k = 0; k < n; k++) {
        int line;
        ps_status st = read_number(r, what, &out[k], &line);
        if (st == PS_ERR_PARSE && r->p >= r->end)
            return ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: the file ends after %d of the %d %s", r->name, end_line(r),
                                k, n, what);
        if (st != PS_OK)
            return st;
        if (out[k] < lo || out[k] > hi)
            return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: %s: %g degrees is outside [%g, %g]", r->name, line, what,
                                out[k], lo, hi);
        if (k > 0 && !(out[k] > out[k - 1]))
            return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: %s out of order: %g after %g (they must increase)",
                                r->name, line, what, out[k], out[k - 1]);
    }
    return PS_OK;
}

static const char *format_of(const char *first_line, size_t len)
{
    static const struct {
        const char *tag, *format;
    } tags[] = {{"IES:LM-63-2019", "LM-63-2019"},
                {"IESNA:LM-63-2019", "LM-63-2019"},
                {"IESNA:LM-63-2002", "LM-63-2002"},
                {"IESNA:LM-63-1995", "LM-63-1995"},
                {"IESNA91", "LM-63-1991"}};
    for (size_t k = 0; k < sizeof tags / sizeof tags[0]; k++) {
        size_t n = strlen(tags[k].tag);
        if (len >= n && !strncmp(first_line, tags[k].tag, n))
            return tags[k].format;
    }
    return "LM-63-1986";
}

/* Unfolds the file's horizontal angles (degrees) and columns into the full
 * circle by the symmetry its first and last angle name (ies.h). */
static ps_status unfold(ps_ies *ies, reader *r, int line, const double *hdeg, int nh, const double *cd)
{
    int nv = ies->nv;
    double first = hdeg[0], last = hdeg[nh - 1];
    /* Each output column: a source column and an angle. */
    int cap = 4 * nh + 2, count = 0;
    int *src = malloc((size_t)cap * sizeof *src);
    double *ang = malloc((size_t)cap * sizeof *ang);
    if (!src || !ang) {
        free(src);
        free(ang);
        return ps_error_set(r->err, PS_ERR_NOMEM, "%s: out of memory", r->name);
    }
#define PUT(s_, a_) (src[count] = (s_), ang[count] = (a_), count++)
    bool ok = true;
    if (nh == 1) {
        if (first != 0.0)
            ok = false;
        PUT(0, 0.0);
        PUT(0, 360.0);
    } else if (first == 0.0 && fabs(last - 90.0) <= ANGLE_SLACK_DEG) {
        for (int k = 0; k < nh; k++)
            PUT(k, hdeg[k]);
        for (int k = nh - 2; k >= 0; k--)
            PUT(k, 180.0 - hdeg[k]);
        for (int k = 1; k < nh; k++)
            PUT(k, 180.0 + hdeg[k]);
        for (int k = nh - 2; k >= 0; k--)
            PUT(k, 360.0 - hdeg[k]);
    } else if (first == 0.0 && fabs(last - 180.0) <= ANGLE_SLACK_DEG) {
        for (int k = 0; k < nh; k++)
            PUT(k, hdeg[k]);
        for (int k = nh - 2; k >= 0; k--)
            PUT(k, 360.0 - hdeg[k]);
    } else if (first == 0.0 && fabs(last - 360.0) <= ANGLE_SLACK_DEG) {
        for (int k = 0; k < nh; k++)
            PUT(k, hdeg[k]);
    } else if (first == 90.0 && fabs(last - 270.0) <= ANGLE_SLACK_DEG) {
        /* Symmetric about the 90-270 plane: I(phi) = I(540 - phi) beyond 270. */
        for (int k = 0; k < nh; k++)
            PUT(k, hdeg[k]);
        for (int k = nh - 2; k >= 0; k--)
            PUT(k, 540.0 - hdeg[k]);
    } else {
        ok = false;
    }
#undef PUT
    if (!ok) {
        free(src);
        free(ang);
        return ps_error_set(r->err, PS_ERR_RANGE,
                            "%s:%d: horizontal angles %g to %g: not a symmetry LM-63 defines for type C (0 alone, 0-90, "
                            "0-180, 90-270 or 0-360)",
                            r->name, line, first, last);
    }
    ies->nh = count;
    ies->h = malloc((size_t)count * sizeof *ies->h);
    ies->cd = malloc((size_t)count * (size_t)nv * sizeof *ies->cd);
    if (!ies->h || !ies->cd) {
        free(src);
        free(ang);
        return ps_error_set(r->err, PS_ERR_NOMEM, "%s: out of memory", r->name);
    }
    for (int k = 0; k < count; k++) {
        ies->h[k] = ang[k] * (PS_PI / 180.0);
        memcpy(ies->cd + (size_t)k * (size_t)nv, cd + (size_t)src[k] * (size_t)nv, (size_t)nv * sizeof *cd);
    }
    /* The last column closes the circle exactly. */
    ies->h[count - 1] = ies->h[0] + 2.0 * PS_PI;
    free(src);
    free(ang);
    return PS_OK;
}

/* The lines before the photometric data: the format line, keywords, TILT=.
 * Leaves r after the TILT line; *tilt: 0 NONE, 1 INCLUDE. */
static ps_status read_header(ps_ies *ies, reader *r, int *tilt)
{
    const char *p = r->p;
    int line = 1;
    for (;;) {
        if (p >= r->end)
            return ps_error_set(r->err, PS_ERR_PARSE,
                                "%s:%d: no TILT= line (LM-63 requires one before the photometric data)", r->name,
                                line > 1 ? line - 1 : 1);
        const char *eol = p;
        while (eol < r->end && *eol != '\n')
            eol++;
        size_t len = (size_t)(eol - p);
        if (len > HEADER_LINE_MAX)
            return ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: line longer than %d characters", r->name, line,
                                HEADER_LINE_MAX);
        char buf[HEADER_LINE_MAX + 1];
        memcpy(buf, p, len);
        buf[len] = '\0';
        while (len > 0 && (buf[len - 1] == '\r' || buf[len - 1] == ' ' || buf[len - 1] == '\t'))
            buf[--len] = '\0';
        if (line == 1)
            snprintf(ies->format, sizeof ies->format, "%s", format_of(buf, len));
        char *s = buf;
        while (*s == ' ' || *s == '\t')
            s++;
        if (!strncmp(s, "TILT", 4)) {
            char *v = s + 4;
            while (*v == ' ' || *v == '\t')
                v++;
            if (*v == '=') {
                v++;
                while (*v == ' ' || *v == '\t')
                    v++;
                if (!strcmp(v, "NONE"))
                    *tilt = 0;
                else if (!strcmp(v, "INCLUDE"))
                    *tilt = 1;
                else
                    return ps_error_set(r->err, PS_ERR_PARSE,
                                        "%s:%d: TILT=%.200s: tilt data in another file is not supported (write "
                                        "TILT=INCLUDE and the data, or TILT=NONE)",
                                        r->name, line, v);
                r->p = eol < r->end ? eol + 1 : eol;
                r->line = line + 1;
                return PS_OK;
            }
        }
        p = eol < r->end ? eol + 1 : eol;
        line++;
    }
}

static ps_status parse(ps_ies *ies, reader *r)
{
    int tilt = 0;
    ps_status st = read_header(ies, r, &tilt);
    if (st != PS_OK)
        return st;
    bool old = !strcmp(ies->format, "LM-63-1995") || !strcmp(ies->format, "LM-63-1991") ||
               !strcmp(ies->format, "LM-63-1986");
    if (tilt) {
        int geometry, n;
        if ((st = read_count(r, "the lamp-to-luminaire geometry", 1, 3, &geometry)) != PS_OK ||
            (st = read_count(r, "the number of tilt angles", 1, PS_IES_MAX_ANGLES, &n)) != PS_OK)
            return st;
        ies->tilt_count = n;
        ies->tilt_angle = malloc((size_t)n * sizeof *ies->tilt_angle);
        ies->tilt_factor = malloc((size_t)n * sizeof *ies->tilt_factor);
        if (!ies->tilt_angle || !ies->tilt_factor)
            return ps_error_set(r->err, PS_ERR_NOMEM, "%s: out of memory", r->name);
        if ((st = read_angles(r, "tilt angles", n, 0.0, 180.0, ies->tilt_angle)) != PS_OK)
            return st;
        for (int k = 0; k < n; k++) {
            int line;
            if ((st = read_number(r, "the tilt multiplying factors", &ies->tilt_factor[k], &line)) != PS_OK)
                return st;
            if (ies->tilt_factor[k] < 0.0 || ies->tilt_factor[k] > PS_IES_MAX_CANDELA)
                return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: tilt factor %g must be in [0, %g]", r->name, line,
                                    ies->tilt_factor[k], PS_IES_MAX_CANDELA);
        }
    }
    /* Line 10 of the format: lamps, lumens per lamp, multiplier, counts, type, units, size. */
    double lamps, lumens, mult, type, units, width, length, height, ballast, second, watts;
    int nv, nh, at;
    if ((st = read_number(r, "the number of lamps", &lamps, &at)) != PS_OK)
        return st;
    if (!(lamps >= 1.0 && lamps == floor(lamps) && lamps <= 1e6))
        return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: the number of lamps %g is not a whole number in [1, 1e6]",
                            r->name, at, lamps);
    if ((st = read_number(r, "the lumens per lamp", &lumens, &at)) != PS_OK)
        return st;
    if (!(lumens > 0.0 || lumens == -1.0))
        return ps_error_set(r->err, PS_ERR_RANGE,
                            "%s:%d: lumens per lamp %g must be positive, or -1 (absolute photometry)", r->name, at,
                            lumens);
    if ((st = read_number(r, "the candela multiplier", &mult, &at)) != PS_OK)
        return st;
    if (!(mult > 0.0))
        return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: the candela multiplier %g must be positive", r->name, at,
                            mult);
    if ((st = read_count(r, "the number of vertical angles", 2, PS_IES_MAX_ANGLES, &nv)) != PS_OK ||
        (st = read_count(r, "the number of horizontal angles", 1, PS_IES_MAX_ANGLES, &nh)) != PS_OK)
        return st;
    if ((size_t)nv * (size_t)nh > PS_IES_MAX_VALUES)
        return ps_error_set(r->err, PS_ERR_LIMIT, "%s:%d: %d x %d candela values are more than the %d allowed",
                            r->name, r->line, nv, nh, PS_IES_MAX_VALUES);
    if ((st = read_number(r, "the photometric type", &type, &at)) != PS_OK)
        return st;
    if (type == 2.0 || type == 3.0)
        return ps_error_set(r->err, PS_ERR_RANGE,
                            "%s:%d: photometric type %g (type %s) is not supported: only type C (1), the one "
                            "architectural luminaires use",
                            r->name, at, type, type == 2.0 ? "B" : "A");
    if (type != 1.0)
        return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: photometric type %g is not 1 (C), 2 (B) or 3 (A)", r->name,
                            at, type);
    if ((st = read_number(r, "the units type", &units, &at)) != PS_OK)
        return st;
    if (units != 1.0 && units != 2.0)
        return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: units type %g is not 1 (feet) or 2 (metres)", r->name, at,
                            units);
    if ((st = read_number(r, "the luminaire width", &width, NULL)) != PS_OK ||
        (st = read_number(r, "the luminaire length", &length, NULL)) != PS_OK ||
        (st = read_number(r, "the luminaire height", &height, NULL)) != PS_OK)
        return st;
    /* Line 11: ballast factor, then the ballast-lamp photometric factor (1995
     * and older), "future use" (2002) or the file generation type (2019). */
    if ((st = read_number(r, "the ballast factor", &ballast, &at)) != PS_OK)
        return st;
    if (!(ballast > 0.0))
        return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: the ballast factor %g must be positive", r->name, at,
                            ballast);
    if ((st = read_number(r, old ? "the ballast-lamp photometric factor" : "the file generation type", &second, &at)) !=
        PS_OK)
        return st;
    if (old && !(second > 0.0))
        return ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: the ballast-lamp photometric factor %g must be positive",
                            r->name, at, second);
    if ((st = read_number(r, "the input watts", &watts, NULL)) != PS_OK)
        return st;
    double factor = mult * ballast * (old ? second : 1.0);

    double *vdeg = malloc((size_t)nv * sizeof *vdeg), *hdeg = malloc((size_t)nh * sizeof *hdeg);
    double *cd = malloc((size_t)nv * (size_t)nh * sizeof *cd);
    ies->v = malloc((size_t)nv * sizeof *ies->v);
    if (!vdeg || !hdeg || !cd || !ies->v) {
        free(vdeg);
        free(hdeg);
        free(cd);
        return ps_error_set(r->err, PS_ERR_NOMEM, "%s: out of memory", r->name);
    }
    int hline = 0;
    st = read_angles(r, "vertical angles", nv, 0.0, 180.0, vdeg);
    if (st == PS_OK)
        st = read_angles(r, "horizontal angles", nh, 0.0, 360.0, hdeg);
    hline = r->line; /* the last horizontal angle's: where the symmetry shows */
    size_t total = (size_t)nv * (size_t)nh;
    for (size_t k = 0; st == PS_OK && k < total; k++) {
        int line;
        char buf[TOKEN_MAX];
        bool too_long;
        if (!next_word(r, buf, &line, &too_long)) {
            st = ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: the candela table ends after %zu of its %zu values",
                              r->name, end_line(r), k, total);
            break;
        }
        if (too_long || !ps_parse_double(buf, &cd[k])) {
            st = ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: candela value %zu: '%.60s' is not a finite number",
                              r->name, line, k + 1, buf);
            break;
        }
        if (cd[k] < 0.0)
            st = ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: candela value %zu is negative (%g)", r->name, line, k + 1,
                              cd[k]);
        else if (!(cd[k] * factor <= PS_IES_MAX_CANDELA))
            st = ps_error_set(r->err, PS_ERR_RANGE, "%s:%d: candela value %zu (%g, times the multiplier %g) is above %g",
                              r->name, line, k + 1, cd[k], factor, PS_IES_MAX_CANDELA);
        cd[k] *= factor;
    }
    if (st == PS_OK) {
        char buf[TOKEN_MAX];
        int line;
        bool too_long;
        if (next_word(r, buf, &line, &too_long))
            st = ps_error_set(r->err, PS_ERR_PARSE, "%s:%d: unexpected '%.60s' after the candela table (%d x %d values)",
                              r->name, line, buf, nh, nv);
    }
    if (st == PS_OK) {
        ies->nv = nv;
        for (int k = 0; k < nv; k++)
            ies->v[k] = vdeg[k] * (PS_PI / 180.0);
        st = unfold(ies, r, hline, hdeg, nh, cd);
    }
    if (st == PS_OK) {
        ps_ies_info *in = &ies->info;
        in->format = ies->format;
        in->vertical_count = nv;
        in->horizontal_count = nh;
        in->first_vertical = vdeg[0];
        in->last_vertical = vdeg[nv - 1];
        in->first_horizontal = hdeg[0];
        in->last_horizontal = hdeg[nh - 1];
        in->multiplier = factor;
        in->lamp_lumens = lumens < 0.0 ? -1.0 : lamps * lumens;
        in->has_tilt = tilt;
        if (!build_tables(ies))
            st = ps_error_set(r->err, PS_ERR_NOMEM, "%s: out of memory", r->name);
    }
    (void)width;
    (void)length;
    (void)height;
    (void)watts;
    free(vdeg);
    free(hdeg);
    free(cd);
    return st;
}

ps_status ps_ies_parse(const char *text, size_t len, const char *name, ps_ies **out, ps_error *err)
{
    *out = NULL;
    ps_error local;
    if (!err)
        err = &local;
    int bin = ps_text_nul_line(text, len);
    if (bin)
        return ps_error_set(err, PS_ERR_PARSE, "%s:%d: binary data (a NUL byte), not an IES file", name, bin);
    ps_ies *ies = calloc(1, sizeof *ies);
    size_t nlen = strlen(name);
    if (!ies || !(ies->name = malloc(nlen + 1))) {
        free(ies);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", name);
    }
    memcpy(ies->name, name, nlen + 1);
    reader r = {text, text + len, text, name, 1, err};
    ps_status st = parse(ies, &r);
    if (st == PS_OK && !(ies->flux > 0.0))
        st = ps_error_set(err, PS_ERR_RANGE, "%s:%d: the candela table is all zero: the luminaire emits nothing", name,
                          end_line(&r));
    if (st != PS_OK) {
        ps_ies_destroy(ies);
        return st;
    }
    *out = ies;
    ps_error_clear(err);
    return PS_OK;
}

ps_status ps_ies_load(const char *path, ps_ies **out, ps_error *err)
{
    *out = NULL;
    char *text = NULL;
    size_t len = 0;
    ps_status st = ps_read_file(path, PS_IES_MAX_BYTES, &text, &len, err);
    if (st != PS_OK)
        return st;
    st = ps_ies_parse(text, len, path, out, err);
    free(text);
    return st;
}

void ps_ies_destroy(ps_ies *ies)
{
    if (!ies)
        return;
    free(ies->name);
    free(ies->v);
    free(ies->h);
    free(ies->cd);
    free(ies->cdf);
    free(ies->tilt_angle);
    free(ies->tilt_factor);
    free(ies);
}

static double *dup_doubles(const double *a, size_t n, bool *ok)
{
    if (!*ok || !a || n == 0)
        return NULL;
    double *c = malloc(n * sizeof *c);
    if (!c) {
        *ok = false;
        return NULL;
    }
    return memcpy(c, a, n * sizeof *c);
}

ps_status ps_ies_clone(const ps_ies *ies, ps_ies **out, ps_error *err)
{
    *out = NULL;
    ps_ies *c = malloc(sizeof *c);
    if (!c)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", ies->name);
    *c = *ies;
    bool ok = true;
    size_t nlen = strlen(ies->name) + 1;
    c->name = malloc(nlen);
    if (c->name)
        memcpy(c->name, ies->name, nlen);
    else
        ok = false;
    c->v = dup_doubles(ies->v, (size_t)ies->nv, &ok);
    c->h = dup_doubles(ies->h, (size_t)ies->nh, &ok);
    c->cd = dup_doubles(ies->cd, (size_t)ies->nv * (size_t)ies->nh, &ok);
    c->cdf = dup_doubles(ies->cdf, (size_t)(ies->nv - 1) * (size_t)(ies->nh - 1), &ok);
    c->tilt_angle = dup_doubles(ies->tilt_angle, (size_t)ies->tilt_count, &ok);
    c->tilt_factor = dup_doubles(ies->tilt_factor, (size_t)ies->tilt_count, &ok);
    c->info.format = c->format;
    if (!ok) {
        ps_ies_destroy(c);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", ies->name);
    }
    *out = c;
    return PS_OK;
}
