/* tool_checker.c: the textured-quad scene of tests/cli_textures.sh.
 *
 *   tool_checker write DIR    writes DIR/checker.png (64x64, 16-bit, a 2x2
 *                             checker of linear albedos 0.2 and 0.8, sRGB-
 *                             encoded as exporters write), DIR/quad.obj and
 *                             .mtl (a 2 m square at z = 0 facing +z, vt 0..1,
 *                             Kd 1 and map_Kd checker.png) and DIR/scene.scn
 *                             (that mesh under a point light on its axis)
 *   tool_checker check IMAGE.pfm TOL
 *                             the radiance at the centres of the top two
 *                             squares against albedo * E / pi there: prints
 *                             "dark=.. bright=.. err_dark=.. err_bright=..
 *                             ratio=.." and exits 1 when an error is above TOL
 *                             (relative) or the ratio is off 4 by more than 2 TOL.
 *
 * The albedos are the 16-bit codes' decoded values (within 1e-5 of 0.2, 0.8). */
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/photometry.h"
#include "image/image.h"

#define SIDE 64
#define LIGHT_Z 1.5   /* the point light on the square's axis */
#define POWER 40.0    /* W per channel */
#define EYE_Z 4.0
#define FOV_DEG 40.0
#define IMAGE 256
#define BLOCK 2       /* pixels each side of the measured centre */

static double srgb_encode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055; }
static double srgb_decode(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }
static unsigned code_of(double albedo) { return (unsigned)lround(srgb_encode(albedo) * 65535.0); }
static double albedo_of(double albedo) { return srgb_decode(code_of(albedo) / 65535.0); }

/* Top-left and bottom-right squares dark, the others bright. */
static double texel(int x, int y) { return (x < SIDE / 2) == (y < SIDE / 2) ? 0.2 : 0.8; }

static int write_png(const char *path)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return 1;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info || setjmp(png_jmpbuf(png))) {
        fclose(fp);
        return 1;
    }
    png_init_io(png, fp);
    png_set_IHDR(png, info, SIDE, SIDE, 16, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    static unsigned char row[SIDE * 6];
    for (int y = 0; y < SIDE; y++) {
        for (int x = 0; x < SIDE; x++) {
            unsigned c = code_of(texel(x, y));
            for (int k = 0; k < 3; k++) {
                row[6 * x + 2 * k] = (unsigned char)(c >> 8); /* PNG samples are big-endian */
                row[6 * x + 2 * k + 1] = (unsigned char)(c & 0xff);
            }
        }
        png_write_row(png, row);
    }
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return fclose(fp) != 0;
}

static int write_text(const char *dir, const char *name, const char *text)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return 1;
    fputs(text, fp);
    return fclose(fp) != 0;
}

static int write_scene(const char *dir)
{
    char path[4096], scn[512];
    snprintf(path, sizeof path, "%s/checker.png", dir);
    snprintf(scn, sizeof scn,
             "camera eye 0 0 %g target 0 0 0 up 0 1 0 fov %g\n"
             "image %d %d\n"
             "mesh quad.obj\n"
             "light point position 0 0 %g power %g %g %g\n",
             EYE_Z, FOV_DEG, IMAGE, IMAGE, LIGHT_Z, POWER, POWER, POWER);
    return write_png(path) ||
           write_text(dir, "quad.obj",
                      "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl checker\nf 1/1/1 2/2/1 3/3/1 4/4/1\n") ||
           write_text(dir, "quad.mtl", "newmtl checker\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd checker.png\n") ||
           write_text(dir, "scene.scn", scn);
}

static double irradiance_at(double x, double y)
{
    double r2 = x * x + y * y + LIGHT_Z * LIGHT_Z;
    return POWER / (4.0 * PS_PI) * LIGHT_Z / (r2 * sqrt(r2));
}

/* Over the block of pixels around the one that sees (x, y, 0): the mean of
 * the channels, and the mean of E / pi at the points the pixels' centres see. */
static double radiance_at(const ps_image *img, double x, double y, double *e_over_pi)
{
    double t = tan(0.5 * FOV_DEG * PS_PI / 180.0);
    double px = 0.5 * img->width * (1.0 + x / (EYE_Z * t)), py = 0.5 * img->height * (1.0 - y / (EYE_Z * t));
    int cx = (int)floor(px), cy = (int)floor(py);
    double sum = 0.0, e = 0.0;
    int n = 0;
    for (int j = cy - BLOCK; j <= cy + BLOCK; j++)
        for (int i = cx - BLOCK; i <= cx + BLOCK; i++, n++) {
            const float *p = ps_image_at(img, i, j);
            sum += (p[0] + p[1] + p[2]) / 3.0;
            double wx = (2.0 * (i + 0.5) / img->width - 1.0) * EYE_Z * t;
            double wy = (1.0 - 2.0 * (j + 0.5) / img->height) * EYE_Z * t;
            e += irradiance_at(wx, wy) * PS_INV_PI;
        }
    *e_over_pi = e / n;
    return sum / n;
}

static int check(const char *path, double tol)
{
    ps_image img;
    ps_error err;
    if (ps_image_read(path, &img, NULL, &err) != PS_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    /* Square centres at (-0.5, 0.5) (dark: the texture's top-left) and (0.5, 0.5). */
    double e_dark, e_bright;
    double dark = radiance_at(&img, -0.5, 0.5, &e_dark), bright = radiance_at(&img, 0.5, 0.5, &e_bright);
    double want_dark = albedo_of(0.2) * e_dark, want_bright = albedo_of(0.8) * e_bright;
    double err_dark = dark / want_dark - 1.0, err_bright = bright / want_bright - 1.0, ratio = bright / dark;
    printf("dark=%.6g bright=%.6g want_dark=%.6g want_bright=%.6g err_dark=%.4f err_bright=%.4f ratio=%.4f\n", dark,
           bright, want_dark, want_bright, err_dark, err_bright, ratio);
    ps_image_destroy(&img);
    return fabs(err_dark) <= tol && fabs(err_bright) <= tol && fabs(ratio / 4.0 - 1.0) <= 2.0 * tol ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "write"))
        return write_scene(argv[2]) ? 2 : 0;
    if (argc == 4 && !strcmp(argv[1], "check"))
        return check(argv[2], atof(argv[3]));
    fprintf(stderr, "usage: tool_checker write DIR | check IMAGE.pfm TOLERANCE\n");
    return 2;
}
