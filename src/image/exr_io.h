/* exr_io.h: OpenEXR images (Debian's libopenexr-dev, its C API), what
 * lighting designers' tools read, beside PFM. Written atomically like every
 * output (core/fileio.h's ps_outfile). */
#ifndef PS_IMAGE_EXR_IO_H
#define PS_IMAGE_EXR_IO_H

#include <stdbool.h>

#include "core/status.h"
#include "image/image.h"

typedef enum ps_exr_type {
    PS_EXR_FLOAT, /* 32-bit channels: exact */
    PS_EXR_HALF   /* 16-bit: half the size; values above 65504 become infinite */
} ps_exr_type;

/* A scanline, ZIP-compressed EXR with channels R, G, B (linear, as given). */
ps_status ps_exr_write(const ps_image *img, const char *path, ps_exr_type type, ps_error *err);
/* One channel, Y (an illuminance image): width x height values, rows top first. */
ps_status ps_exr_write_gray(const float *values, int width, int height, ps_exr_type type, const char *path,
                            ps_error *err);
/* A scanline EXR's R, G, B (or Y, replicated; other channels ignored) as floats. */
ps_status ps_exr_read(const char *path, ps_image *out, ps_error *err);

/* The name ends in .exr (or .EXR). */
bool ps_path_is_exr(const char *path);
/* --hdr: OpenEXR (float) when the name ends in .exr, PFM otherwise. */
ps_status ps_hdr_write(const ps_image *img, const char *path, ps_error *err);
/* --illuminance: one channel, OpenEXR when the name ends in .exr, else a "Pf" PFM. */
ps_status ps_gray_write(const float *values, int width, int height, const char *path, ps_error *err);

#endif
