/* ies.h: ANSI/IES LM-63 photometric files (1986/1991, -1995, -2002, -2019):
 * a luminaire's luminous intensity (candela) over directions.
 *
 * Only type C photometry is read (the vertical angle from the nadir, the
 * horizontal angle about the vertical axis), the kind every architectural
 * luminaire file uses; type B and type A are refused by name. Horizontal
 * symmetries as LM-63 defines them are unfolded at load: a single angle 0
 * (rotationally symmetric), 0-90 (quadrant), 0-180 (bilateral about the 0-180
 * plane), 90-270 (bilateral about the 90-270 plane, LM-63-1995), 0-360.
 *
 * Between table entries the candela is bilinear in the two angles
 * (theta = vertical, phi = horizontal); outside the file's vertical range it
 * is 0. Everything derived from the table (the total flux, the sampling
 * tables) integrates that bilinear function exactly over the sphere.
 *
 * A ps_ies is immutable once loaded, so threads may share one. */
#ifndef PS_SCENE_IES_H
#define PS_SCENE_IES_H

#include <stddef.h>

#include "core/status.h"

/* What is refused with PS_ERR_LIMIT before any allocation. */
#define PS_IES_MAX_BYTES ((size_t)16 << 20)
#define PS_IES_MAX_ANGLES 10000   /* vertical or horizontal */
#define PS_IES_MAX_VALUES 1000000 /* vertical x horizontal (real files: at most 181 x 361) */
#define PS_IES_MAX_CANDELA 1e30

typedef struct ps_ies ps_ies;

/* What the file says about itself, for messages and --stats. */
typedef struct ps_ies_info {
    const char *format;      /* "LM-63-2019", "LM-63-2002", "LM-63-1995", "LM-63-1991" or "LM-63-1986" */
    int vertical_count;      /* as in the file */
    int horizontal_count;    /* as in the file */
    double first_vertical, last_vertical;     /* degrees */
    double first_horizontal, last_horizontal; /* degrees */
    double multiplier;       /* candela multiplier x ballast factor (x ballast-lamp factor, 1995 and older) */
    double lamp_lumens;      /* lamps x lumens per lamp as written; < 0: absolute photometry */
    int has_tilt;            /* TILT=INCLUDE */
} ps_ies_info;

/* Reads an LM-63 file. Every problem is "path:line: problem" (PS_ERR_PARSE for
 * malformed text, PS_ERR_RANGE for values out of range, PS_ERR_LIMIT for sizes,
 * PS_ERR_IO for a file that cannot be read, a directory included). */
ps_status ps_ies_load(const char *path, ps_ies **out, ps_error *err);
/* The same from len bytes of text (a NUL after them is not needed); `name`
 * stands for the file in messages. */
ps_status ps_ies_parse(const char *text, size_t len, const char *name, ps_ies **out, ps_error *err);
ps_status ps_ies_clone(const ps_ies *ies, ps_ies **out, ps_error *err);
void ps_ies_destroy(ps_ies *ies); /* accepts NULL */

const ps_ies_info *ps_ies_get_info(const ps_ies *ies);
/* The file name it was loaded under. */
const char *ps_ies_name(const ps_ies *ies);

/* Candela (multiplier applied) towards vertical angle theta in [0, pi] and
 * horizontal angle phi (any real; radians): bilinear between table entries. */
double ps_ies_candela(const ps_ies *ies, double theta, double phi);
/* The largest candela of the table. */
double ps_ies_peak(const ps_ies *ies);
/* The total luminous flux in lumens: the integral of ps_ies_candela over the
 * sphere of directions, exact for the bilinear function. */
double ps_ies_flux(const ps_ies *ies);
/* The TILT=INCLUDE factor for a luminaire tilted `degrees` from its
 * photometric position (linear between the file's angles, the end values
 * beyond them); 1 without TILT data. */
double ps_ies_tilt_factor(const ps_ies *ies, double degrees);

/* A direction with density exactly ps_ies_candela / ps_ies_flux over solid
 * angle, from three numbers in [0, 1): u0 picks a table cell by its flux,
 * u1 the horizontal angle within it (the marginal is linear: inverted in
 * closed form), u2 the vertical angle (its conditional cdf inverted by
 * safeguarded Newton iteration to rounding). Angles in radians. Returns the
 * density (per steradian) of the direction. */
double ps_ies_sample(const ps_ies *ies, double u0, double u1, double u2, double *theta, double *phi);

#endif
