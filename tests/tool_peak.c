/* tool_peak.c: where an image's brightest region is, for the window tests:
 * prints "mean=M max=X cx=CX cy=CY" where (cx, cy) is the centroid, in
 * pixels from the top-left, of the pixels at least half as bright (mean of
 * the channels) as the brightest. Exit status 2 on a bad file. */
#include <stdio.h>

#include "image/image.h"

/* The brightest region: pixels at least this fraction of the maximum. */
#define PEAK_FRACTION 0.5

static double brightness(const ps_image *img, int x, int y)
{
    const float *p = ps_image_at(img, x, y);
    return (p[0] + p[1] + p[2]) / 3.0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: tool_peak IMAGE\n");
        return 2;
    }
    ps_image img;
    ps_error err;
    if (ps_image_read(argv[1], &img, NULL, &err) != PS_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    double max = 0.0, sum = 0.0;
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            double b = brightness(&img, x, y);
            sum += b;
            max = b > max ? b : max;
        }
    double wx = 0.0, wy = 0.0, w = 0.0;
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            double b = brightness(&img, x, y);
            if (max > 0.0 && b >= PEAK_FRACTION * max) {
                wx += b * (x + 0.5);
                wy += b * (y + 0.5);
                w += b;
            }
        }
    printf("mean=%.6g max=%.6g cx=%.3f cy=%.3f\n", sum / ((double)img.width * img.height), max, w > 0 ? wx / w : -1.0,
           w > 0 ? wy / w : -1.0);
    ps_image_destroy(&img);
    return 0;
}
