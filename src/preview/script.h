/* script.h: the preview window's --script FILE, parsed without GL: timed
 * actions (screenshots, moved lights and objects, runtime settings, camera
 * orbits, quit) sorted by time.
 *
 * Format (contract, "photosplat --script FILE"): one action a line,
 *     SECONDS ACTION ARGS...
 * seconds counted from the window's first frame (finite, >= 0). Words are
 * separated by spaces or tabs; '#' anywhere starts a comment; blank lines are
 * allowed. The actions:
 *     screenshot PATH                  PNG of the window as shown; PATH as given
 *                                      (relative to the current directory), no
 *                                      spaces, at most 4095 characters. In
 *                                      photosplat-snap --script a PATH ending in
 *                                      .pfm or .exr writes the picture's linear
 *                                      radiance instead (the window refuses
 *                                      those: it shows 8-bit codes)
 *     move light INDEX X Y Z           light INDEX (scene order) to a new position
 *     move object INDEX DX DY DZ       object INDEX (scene order) translated
 *     set splat points|triangles|sprites
 *     set layers LIST                  comma list of direct,caustic,global,specular (>= 1)
 *     set kernel box|cone|gauss|epanechnikov
 *     set radius R [G]                 caustic splat radius, optionally the global one (> 0)
 *     set tau SECONDS                  (> 0)
 *     set precision none|diffusion|counter
 *     set exposure E                   (> 0)
 *     set pause on|off
 *     orbit YAW PITCH                  camera yaw/pitch in degrees about the target
 *     power light INDEX R G B          new flux in watts per channel (each >= 0)
 *     angle light INDEX DEGREES        a spot's half-angle, in (0, 90]
 *     wait done                        hold the later actions until every photon
 *                                      map has reached its cap (or the memory
 *                                      cap) and all of it is drawn (or tracing
 *                                      is paused); their times
 *                                      then count on from when the wait ended
 *     quit
 *     dump photons PATH                the maps as they stand, as --dump-photons
 *                                      writes them (in index order once traced:
 *                                      after wait done, equal to photosplat-ref
 *                                      --photons-only on the edited scene)
 *     save scene PATH                  the edited scene as a .scn
 * (power, angle and wait are extras beyond the contract: editing lights, and
 * pictures at a known photon count whatever the machine's speed.)
 * Numbers are strict (core/number.h); indices are integers in [0, 2^32 - 1],
 * checked against the scene by the window, not here.
 *
 * Every error is one line "FILE:LINE: problem" with PS_ERR_PARSE; PS_ERR_IO
 * when the file cannot be read; PS_ERR_LIMIT for a file over
 * PS_SCRIPT_MAX_BYTES or more than PS_SCRIPT_MAX_ACTIONS actions. On any
 * error *out is NULL and nothing is leaked. */
#ifndef PS_PREVIEW_SCRIPT_H
#define PS_PREVIEW_SCRIPT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "core/vec.h"
#include "preview/layers.h"

#define PS_SCRIPT_MAX_BYTES ((size_t)1 << 20)
#define PS_SCRIPT_MAX_ACTIONS 100000
/* A line holds at most this many characters (its newline not counted). */
#define PS_SCRIPT_LINE_MAX 8191
/* A screenshot path holds at most this many characters (PATH_MAX - 1). */
#define PS_SCRIPT_PATH_MAX 4095

typedef enum ps_script_kind {
    PS_SCRIPT_SCREENSHOT,
    PS_SCRIPT_MOVE_LIGHT,
    PS_SCRIPT_MOVE_OBJECT,
    PS_SCRIPT_SET,
    PS_SCRIPT_ORBIT,
    PS_SCRIPT_POWER,
    PS_SCRIPT_ANGLE,
    PS_SCRIPT_WAIT,
    PS_SCRIPT_QUIT,
    PS_SCRIPT_DUMP_PHOTONS, /* dump photons PATH */
    PS_SCRIPT_SAVE_SCENE    /* save scene PATH */
} ps_script_kind;

typedef enum ps_script_setting {
    PS_SET_SPLAT,
    PS_SET_LAYERS,
    PS_SET_KERNEL,
    PS_SET_RADIUS,
    PS_SET_TAU,
    PS_SET_PRECISION,
    PS_SET_EXPOSURE,
    PS_SET_PAUSE,
    PS_SET_FALSE_COLOR, /* the window's illuminance in false colour, key F */
    PS_SET_GLOBAL_LAYER /* splats or maps (ps_global_layer_names), key M */
} ps_script_setting;

/* Bits of ps_script_action.layers. */

/* One action. Fields a kind does not use are zero (path NULL). */
typedef struct ps_script_action {
    double time;         /* seconds from the first frame, >= 0 */
    int line;            /* where it stands in the file (1-based) */
    ps_script_kind kind;
    const char *path;    /* screenshot, dump photons, save scene (owned by the script) */
    uint32_t index;      /* move/power/angle */
    ps_vec3 v;           /* move light: position; move object: delta */
    ps_rgb power;        /* power, watts per channel */
    double yaw, pitch;   /* orbit, degrees */
    double number;       /* angle degrees; set radius (caustic), tau, exposure */
    double number2;      /* set radius: the global radius, or 0 when not given */
    ps_script_setting setting; /* set */
    /* set splat/kernel/precision: the ps_splat_mode, ps_kernel or
     * ps_precision value (set global-layer: the ps_global_layer), read through their name tables (ps_splat_mode_names,
     * ps_kernel_names, ps_precision_names); set pause and false-color: 1 on, 0 off. */
    int choice;
    unsigned layers;     /* set layers: PS_LAYER_* bits (preview/layers.h) */
} ps_script_action;

typedef struct ps_script ps_script;

/* Reads and parses the file at path (messages name it as given). */
ps_status ps_script_load(const char *path, ps_script **out, ps_error *err);
/* Parses text; name stands for the file in messages. */
ps_status ps_script_parse(const char *text, const char *name, ps_script **out, ps_error *err);
void ps_script_destroy(ps_script *s); /* accepts NULL */

size_t ps_script_count(const ps_script *s);
/* The i-th action in time order; equal times keep file order. NULL when
 * i >= ps_script_count(s). */
const ps_script_action *ps_script_at(const ps_script *s, size_t i);

/* A screenshot path for linear radiance: its name ends in .pfm or .exr
 * (either case). */
bool ps_script_path_is_radiance(const char *path);

#endif
