/* targets.c: the fuzz target bodies (fuzz_targets.h). */
#include "fuzz_targets.h"

#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/exr_io.h"
#include "image/image.h"
#include "scene/ies.h"
#include "scene/scene.h"

/* Room for a temporary directory, and for it with a file name appended. */
#define DIR_CAP 3072
#define PATH_CAP 4096
/* The PNG signature and a chunk's length, type and CRC fields, in bytes. */
#define PNG_SIG_BYTES 8
#define PNG_FIELD_BYTES 4
/* CRC-32 as PNG defines it (ISO 3309, reflected polynomial). */
#define CRC32_POLY 0xedb88320u
#define CRC32_INIT 0xffffffffu

/* A broken promise: say which and stop, so the input is kept as a finding. */
static void broken(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2), noreturn))
#endif
    ;
static void broken(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("fuzz: broken promise: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    abort();
}

/* An error must be one non-empty line that names `name` and matches st. */
static void check_error(ps_status st, const ps_error *err, const char *name)
{
    if (err->status != st)
        broken("returned status %d but the error records %d", (int)st, (int)err->status);
    if (!err->msg[0])
        broken("status %d with an empty message", (int)st);
    if (strchr(err->msg, '\n'))
        broken("message has a newline: %s", err->msg);
    if (!strstr(err->msg, name))
        broken("message does not name '%s': %s", name, err->msg);
}

/* Warnings must be single non-empty lines too; they are otherwise dropped,
 * since the fuzzer would print millions. */
static void check_warning(void *user, const char *msg)
{
    (void)user;
    if (!msg[0] || strchr(msg, '\n'))
        broken("malformed warning: '%s'", msg);
}

/* ---- temporary files ---------------------------------------------------- */

/* A fresh directory under $TMPDIR (or /tmp) for one input's files. */
static bool make_tmpdir(char dir[DIR_CAP])
{
    const char *base = getenv("TMPDIR");
    if (!base || !base[0])
        base = "/tmp";
    int n = snprintf(dir, DIR_CAP, "%s/psfuzz-XXXXXX", base);
    return n > 0 && n < DIR_CAP && mkdtemp(dir) != NULL;
}

static bool write_file(const char *path, const void *data, size_t size)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return false;
    bool ok = fwrite(data, 1, size, fp) == size;
    return fclose(fp) == 0 && ok;
}

/* dir/name into out; false when it does not fit. */
static bool join(char out[PATH_CAP], const char dir[DIR_CAP], const char *name)
{
    int n = snprintf(out, PATH_CAP, "%s/%s", dir, name);
    return n > 0 && n < PATH_CAP;
}

/* A harness that cannot write its scratch files has nothing to test; that is
 * the machine's problem, not the reader's, so it is reported and skipped. */
static ps_status no_scratch(ps_error *err)
{
    return ps_error_set(err, PS_ERR_IO, "fuzz: cannot write scratch files under $TMPDIR");
}

/* ---- scene -------------------------------------------------------------- */

/* What the loader promises of a scene it accepts (scene.h). */
static void check_scene(const ps_scene *s)
{
    size_t npos, nnorm, ntri, nmat, nobj, nlight, nemit;
    const ps_vec3 *pos = ps_scene_positions(s, &npos);
    const ps_vec3 *norm = ps_scene_normals(s, &nnorm);
    const ps_triangle *tri = ps_scene_triangles(s, &ntri);
    (void)ps_scene_materials(s, &nmat);
    const ps_object *obj = ps_scene_objects(s, &nobj);
    const ps_light *light = ps_scene_lights(s, &nlight);
    const uint32_t *emit = ps_scene_emitters(s, &nemit);
    for (size_t i = 0; i < npos; i++)
        if (!isfinite(pos[i].x) || !isfinite(pos[i].y) || !isfinite(pos[i].z))
            broken("position %zu is not finite", i);
    for (size_t i = 0; i < nnorm; i++)
        if (!isfinite(norm[i].x) || !isfinite(norm[i].y) || !isfinite(norm[i].z))
            broken("normal %zu is not finite", i);
    for (size_t i = 0; i < ntri; i++) {
        for (int k = 0; k < 3; k++) {
            if (tri[i].v[k] >= npos)
                broken("triangle %zu vertex %u of %zu", i, tri[i].v[k], npos);
            if (tri[i].n[k] < -1 || (tri[i].n[k] >= 0 && (size_t)tri[i].n[k] >= nnorm))
                broken("triangle %zu normal %d of %zu", i, tri[i].n[k], nnorm);
        }
        if (tri[i].material >= nmat || tri[i].object >= nobj)
            broken("triangle %zu material %u/%zu object %u/%zu", i, tri[i].material, nmat, tri[i].object, nobj);
    }
    for (size_t i = 0; i < nobj; i++)
        if ((uint64_t)obj[i].first_triangle + obj[i].triangle_count > ntri)
            broken("object %zu triangles [%u, +%u) of %zu", i, obj[i].first_triangle, obj[i].triangle_count, ntri);
    if (nlight == 0)
        broken("a scene without lights was accepted");
    for (size_t i = 0; i < nlight; i++) {
        ps_rgb p = light[i].power;
        if (!isfinite(p.r) || !isfinite(p.g) || !isfinite(p.b) || p.r < 0 || p.g < 0 || p.b < 0)
            broken("light %zu power is not finite and non-negative", i);
        if ((uint64_t)light[i].first_emitter + light[i].emitter_count > nemit)
            broken("light %zu emitters out of range", i);
    }
    for (size_t i = 0; i < nemit; i++)
        if (emit[i] >= ntri)
            broken("emitter %zu is triangle %u of %zu", i, emit[i], ntri);
    const ps_camera *cam = ps_scene_camera(s);
    if (!(cam->fov_deg > 0 && cam->fov_deg < 180))
        broken("camera fov %g", cam->fov_deg);
}

/* Loads, checks the promises, frees. `file` is the file to load, or NULL to
 * parse `text` (NUL-terminated) in memory; an error must mention `named`. */
static ps_status load_scene(const char *text, const char *file, const char *name, const char *base_dir,
                            const char *named, ps_error *err)
{
    ps_scene_load_options opts = {{check_warning, NULL}};
    ps_scene *s = NULL;
    ps_error_clear(err);
    ps_status st = file ? ps_scene_load(file, &opts, &s, err)
                        : ps_scene_load_text(text, name, base_dir, &opts, &s, err);
    if (st == PS_OK) {
        if (!s)
            broken("PS_OK without a scene");
        check_scene(s);
        ps_scene_destroy(s);
    } else {
        if (s)
            broken("status %d with a scene", (int)st);
        check_error(st, err, named);
    }
    return st;
}

ps_status ps_fuzz_scene(const uint8_t *data, size_t size, const char *name, const char *base_dir, ps_error *err)
{
    if (memchr(data, '\0', size)) {
        char dir[DIR_CAP], path[PATH_CAP] = "";
        if (!make_tmpdir(dir))
            return no_scratch(err);
        ps_status st = join(path, dir, "fuzz.scn") && write_file(path, data, size)
                           ? load_scene(NULL, path, NULL, NULL, path, err)
                           : no_scratch(err);
        remove(path);
        rmdir(dir);
        return st;
    }
    char *text = malloc(size + 1);
    if (!text)
        return ps_error_set(err, PS_ERR_NOMEM, "fuzz: out of memory");
    memcpy(text, data, size);
    text[size] = '\0';
    ps_status st = load_scene(text, NULL, name, base_dir, name, err);
    free(text);
    return st;
}

/* ---- OBJ + MTL ---------------------------------------------------------- */

/* The scene around the fuzzed mesh: a camera, a light (so that a mesh without
 * emissive faces still makes a valid scene) and the mesh, found beside it. */
static const char obj_scene[] = "camera eye 0 0 5 target 0 0 0 fov 40\n"
                                "light point position 0 3 0 power 10 10 10\n"
                                "mesh m.obj\n";

ps_status ps_fuzz_obj(const uint8_t *data, size_t size, ps_error *err)
{
    const char *sep = PS_FUZZ_MTL_SEPARATOR;
    size_t sep_len = strlen(sep), obj_len = size, mtl_at = size;
    for (size_t i = 0; i + sep_len <= size; i++) {
        if ((i == 0 || data[i - 1] == '\n') && memcmp(data + i, sep, sep_len) == 0) {
            obj_len = i;
            mtl_at = i + sep_len;
            break;
        }
    }
    char dir[DIR_CAP], obj[PATH_CAP] = "", mtl[PATH_CAP] = "", scn[PATH_CAP] = "";
    if (!make_tmpdir(dir))
        return no_scratch(err);
    ps_status st;
    if (join(obj, dir, "m.obj") && join(mtl, dir, "m.mtl") && join(scn, dir, "fuzz.scn") &&
        write_file(obj, data, obj_len) && write_file(mtl, data + mtl_at, size - mtl_at) &&
        write_file(scn, obj_scene, sizeof obj_scene - 1))
        st = load_scene(NULL, scn, NULL, NULL, dir, err); /* the scene's, OBJ's or MTL's path */
    else
        st = no_scratch(err);
    remove(obj);
    remove(mtl);
    remove(scn);
    rmdir(dir);
    return st;
}

/* ---- images ------------------------------------------------------------- */

static uint32_t crc32_png(const uint8_t *p, size_t n)
{
    uint32_t c = CRC32_INIT;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (CRC32_POLY & (0u - (c & 1u)));
    }
    return c ^ CRC32_INIT;
}

static uint32_t get_be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* Rewrites each whole chunk's CRC so that a mutated chunk is parsed rather
 * than refused for its checksum (the CRC check itself has unit tests). */
static void fix_png_crcs(uint8_t *p, size_t n)
{
    size_t at = PNG_SIG_BYTES;
    while (n - at >= 3 * PNG_FIELD_BYTES && at < n) {
        uint32_t len = get_be32(p + at);
        if (len > n - at - 3 * PNG_FIELD_BYTES)
            return;
        size_t crc_at = at + 2 * PNG_FIELD_BYTES + len;
        uint32_t c = crc32_png(p + at + PNG_FIELD_BYTES, PNG_FIELD_BYTES + (size_t)len);
        p[crc_at] = (uint8_t)(c >> 24);
        p[crc_at + 1] = (uint8_t)(c >> 16);
        p[crc_at + 2] = (uint8_t)(c >> 8);
        p[crc_at + 3] = (uint8_t)c;
        at = crc_at + PNG_FIELD_BYTES;
    }
}

/* What a reader promises of an image it returns; PNG values are codes
 * scaled to [0, 1]. */
static void check_image(const ps_image *img, bool unit_range)
{
    if (!img->rgb || ps_image_check_size(img->width, img->height, NULL) != PS_OK)
        broken("image %dx%d, pixels %p", img->width, img->height, (void *)img->rgb);
    if (unit_range) {
        size_t n = (size_t)img->width * (size_t)img->height * 3;
        for (size_t i = 0; i < n; i++)
            if (!(img->rgb[i] >= 0.0f && img->rgb[i] <= 1.0f))
                broken("PNG sample %zu is %g", i, (double)img->rgb[i]);
    }
}

typedef ps_status (*image_reader)(const char *path, ps_image *out, ps_error *err);

static ps_status read_image(const uint8_t *data, size_t size, const char *file, image_reader read, bool unit_range,
                            ps_error *err)
{
    char dir[DIR_CAP], path[PATH_CAP] = "";
    if (!make_tmpdir(dir))
        return no_scratch(err);
    ps_status st;
    if (!join(path, dir, file) || !write_file(path, data, size)) {
        st = no_scratch(err);
    } else {
        ps_image img = {0};
        ps_error_clear(err);
        st = read(path, &img, err);
        if (st == PS_OK) {
            check_image(&img, unit_range);
            ps_image_destroy(&img);
        } else {
            if (img.rgb)
                broken("status %d with pixels", (int)st);
            check_error(st, err, path);
        }
    }
    remove(path);
    rmdir(dir);
    return st;
}

ps_status ps_fuzz_png(const uint8_t *data, size_t size, ps_error *err)
{
    uint8_t *copy = malloc(size ? size : 1);
    if (!copy)
        return ps_error_set(err, PS_ERR_NOMEM, "fuzz: out of memory");
    memcpy(copy, data, size);
    if (size > PNG_SIG_BYTES)
        fix_png_crcs(copy, size);
    ps_status st = read_image(copy, size, "fuzz.png", ps_png_read, true, err);
    free(copy);
    return st;
}

ps_status ps_fuzz_pfm(const uint8_t *data, size_t size, ps_error *err)
{
    return read_image(data, size, "fuzz.pfm", ps_pfm_read, false, err);
}

ps_status ps_fuzz_exr(const uint8_t *data, size_t size, ps_error *err)
{
    return read_image(data, size, "fuzz.exr", ps_exr_read, false, err);
}

/* Directions probed in an accepted table: a fixed grid, so a finding replays. */
#define IES_PROBES 24

ps_status ps_fuzz_ies(const uint8_t *data, size_t size, const char *name, ps_error *err)
{
    ps_ies *ies = NULL;
    ps_status st = ps_ies_parse((const char *)data, size, name, &ies, err);
    if (st != PS_OK) {
        check_error(st, err, name);
        if (ies)
            broken("ies: an error returned a table");
        return st;
    }
    double flux = ps_ies_flux(ies), peak = ps_ies_peak(ies);
    if (!(flux > 0.0) || !isfinite(flux) || !(peak > 0.0) || !isfinite(peak))
        broken("ies: accepted with flux %g, peak %g", flux, peak);
    const double pi = 3.14159265358979323846;
    for (int i = 0; i <= IES_PROBES; i++)
        for (int j = 0; j <= IES_PROBES; j++) {
            double t = pi * i / IES_PROBES, p = 2.0 * pi * j / IES_PROBES - pi;
            double c = ps_ies_candela(ies, t, p);
            if (!(c >= 0.0) || !(c <= peak * (1.0 + 1e-9)))
                broken("ies: candela %g at (%g, %g), peak %g", c, t, p, peak);
            double u0 = (i + 0.5) / (IES_PROBES + 1), u1 = (j + 0.5) / (IES_PROBES + 1), u2 = (i * 7 + j) % 25 / 25.0;
            double th, ph, pdf = ps_ies_sample(ies, u0, u1, u2, &th, &ph);
            if (!(th >= 0.0 && th <= pi) || !isfinite(ph) || !(pdf >= 0.0) || !isfinite(pdf))
                broken("ies: sample (%g, %g) with density %g", th, ph, pdf);
        }
    ps_ies *copy = NULL;
    if (ps_ies_clone(ies, &copy, err) == PS_OK && ps_ies_flux(copy) != flux)
        broken("ies: the clone's flux differs");
    ps_ies_destroy(copy);
    ps_ies_destroy(ies);
    return PS_OK;
}
