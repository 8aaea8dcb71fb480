/* compare_main.c: photosplat-compare, error metrics between two images (PNG, PFM or OpenEXR). */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "app/cli.h"
#include "image/compare.h"
#include "image/image.h"

#define PROG "photosplat-compare"

static const char usage[] =
    "usage: " PROG " A B [--mask MASK] [--linear] [--clamp MAX]\n"
    "\n"
    "Compares image A with the reference image B and prints one line:\n"
    "  rmse=... relmse=... psnr=... mean_a=... mean_b=...\n"
    "over all pixels and the 3 channels of each:\n"
    "  rmse   = sqrt(mean (a-b)^2)\n"
    "  relmse = mean (a-b)^2 / (b^2 + 0.01)        (B is the reference)\n"
    "  psnr   = 10 log10(1 / mean (a-b)^2) in dB, peak 1.0; inf when identical\n"
    "  mean_a, mean_b = mean value of A, of B\n"
    "\n"
    "A and B are PNG, PFM or OpenEXR files, told apart by their contents, not their names,\n"
    "and must have the same size.\n"
    "Values compared: PFM as stored (linear radiance); PNG as stored, the\n"
    "sRGB-encoded codes scaled to [0,1]. When one image is PNG and the other PFM,\n"
    "or with --linear, PNG values are sRGB-decoded to linear first, so the\n"
    "comparison is in linear space and assumes the PNG was written at exposure 1.\n"
    "\n"
    "options:\n"
    "  --mask MASK   only pixels where MASK (PNG or PFM, same size) is white, that\n"
    "                is where the mean of its channels is at least 0.5\n"
    "  --linear      decode PNG images to linear before comparing\n"
    "  --clamp MAX   clamp both images' values to at most MAX first: compares what a\n"
    "                display shows, e.g. MAX = 1 / exposure for radiance images\n"
    "  --help        this text\n"
    "\n"
    "Exit status 0 on success, 2 on bad input (one line on stderr).\n";

/* Everything the command line says. */
typedef struct options {
    const char *path[2]; /* A, B */
    const char *mask;
    bool linear;
    bool help;
    double clamp; /* 0: none */
} options;

static ps_status parse(int argc, char **argv, options *o, ps_error *err)
{
    ps_cli cli = ps_cli_begin(PROG, argc, argv);
    int npos = 0;
    ps_status st;
    while (ps_cli_next(&cli)) {
        if (ps_cli_positional(&cli)) {
            if (npos == 2)
                return ps_error_set(err, PS_ERR_PARSE,
                                    "%s: unexpected argument '%s': give two images A and B (see --help)", PROG,
                                    ps_cli_arg(&cli));
            o->path[npos++] = ps_cli_arg(&cli);
        } else if (ps_cli_is(&cli, "--help") || ps_cli_is(&cli, "--linear")) {
            if (cli.inline_v)
                return ps_error_set(err, PS_ERR_PARSE, "%s: option '%s' takes no value (see --help)", PROG,
                                    ps_cli_arg(&cli));
            if (ps_cli_is(&cli, "--help"))
                o->help = true;
            else
                o->linear = true;
        } else if (ps_cli_is(&cli, "--clamp")) {
            if ((st = ps_cli_double(&cli, 1e-30, 1e30, &o->clamp, err)) != PS_OK)
                return st;
        } else if (ps_cli_is(&cli, "--mask")) {
            if (o->mask)
                return ps_error_set(err, PS_ERR_PARSE, "%s: option --mask given twice", PROG);
            if ((st = ps_cli_string(&cli, &o->mask, err)) != PS_OK)
                return st;
        } else {
            return ps_cli_unknown(&cli, err);
        }
    }
    if (o->help)
        return PS_OK;
    if (npos < 2)
        return ps_error_set(err, PS_ERR_PARSE, "%s: expected two images A and B, got %d (see --help)", PROG, npos);
    return PS_OK;
}

int main(int argc, char **argv)
{
    options o;
    memset(&o, 0, sizeof o);
    ps_error err;
    ps_error_clear(&err);
    if (parse(argc, argv, &o, &err) != PS_OK)
        return ps_cli_fail(&err);
    if (o.help) {
        fputs(usage, stdout);
        return fflush(stdout) == 0 ? PS_EXIT_OK : PS_EXIT_USAGE;
    }

    ps_image img[2], mask;
    memset(img, 0, sizeof img);
    memset(&mask, 0, sizeof mask);
    ps_image_format format[2];
    ps_compare_result r;
    ps_status st = PS_OK;
    for (int k = 0; k < 2 && st == PS_OK; k++)
        st = ps_image_read(o.path[k], &img[k], &format[k], &err);
    if (st == PS_OK && o.mask)
        st = ps_image_read(o.mask, &mask, NULL, &err);
    if (st == PS_OK) {
        /* Mixed formats can only be compared in one space: linear, where PFM
         * lives. The mask is only thresholded, so it is left as stored. */
        bool linear = o.linear || format[0] != format[1];
        for (int k = 0; k < 2; k++)
            if (linear && format[k] == PS_IMAGE_PNG)
                ps_image_srgb_to_linear(&img[k]);
        /* NaN stays NaN (fminf would hide it): the comparison refuses it. */
        for (int k = 0; k < 2 && o.clamp > 0.0; k++)
            for (size_t i = 0; i < 3 * (size_t)img[k].width * (size_t)img[k].height; i++)
                if (img[k].rgb[i] > (float)o.clamp)
                    img[k].rgb[i] = (float)o.clamp;
        ps_compare_names names = {o.path[0], o.path[1], o.mask};
        st = ps_image_compare(&img[0], &img[1], o.mask ? &mask : NULL, &names, &r, &err);
    }
    ps_image_destroy(&img[0]);
    ps_image_destroy(&img[1]);
    ps_image_destroy(&mask);
    if (st != PS_OK)
        return ps_cli_fail(&err);

    printf("rmse=%.6g relmse=%.6g psnr=%.6g mean_a=%.6g mean_b=%.6g\n", r.rmse, r.relmse, r.psnr, r.mean_a, r.mean_b);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        ps_error_set(&err, PS_ERR_IO, "%s: cannot write the result to standard output", PROG);
        return ps_cli_fail(&err);
    }
    return PS_EXIT_OK;
}
