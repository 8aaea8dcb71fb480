/* png_io.c: PNG reading and writing; the only file that includes png.h.
 *
 * libpng reports errors by longjmp to a setjmp in the caller. To keep that
 * safe, each setjmp lives in a small "body" function that keeps every resource
 * in a struct owned by its caller and returns at once when the jump lands; the
 * caller frees whatever the struct holds, on success and failure alike. No
 * local of a body function is read after a longjmp, so none needs volatile. */
#include "image/image.h"

#include <png.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"

/* Bytes of the PNG signature. */
#define PNG_SIG_BYTES 8
/* Largest sample values, to scale codes to [0,1]. */
#define MAX_CODE_8 255.0f
#define MAX_CODE_16 65535.0f
/* We write 8 bits per channel: the contract's PNG is 8-bit sRGB. */
#define WRITE_BIT_DEPTH 8

/* Room for one libpng warning. */
#define WARNING_MAX 200

/* What the error callback needs to turn libpng's message into ours. */
typedef struct png_ctx {
    const char *path;
    const char *doing; /* "invalid PNG" or "cannot write PNG" */
    ps_error *err;
    char last_warning[WARNING_MAX];
} png_ctx;

static void on_error(png_structp png, png_const_charp msg)
{
    png_ctx *ctx = png_get_error_ptr(png);
    /* libpng explains a bad header in a warning ("Image width exceeds user
     * limit in IHDR") and then fails with a generic "Invalid IHDR data":
     * report the explanation. */
    if (strcmp(msg, "Invalid IHDR data") == 0 && ctx->last_warning[0])
        msg = ctx->last_warning;
    ps_error_set(ctx->err, PS_ERR_FORMAT, "%s: %s: %s", ctx->path, ctx->doing, msg);
    png_longjmp(png, 1);
}

/* Warnings (an odd ICC profile, a bad ancillary chunk we then skip) are not
 * errors, and the contract allows one stderr line only for real failures:
 * keep the last one quietly, in case an error needs it. */
static void on_warning(png_structp png, png_const_charp msg)
{
    png_ctx *ctx = png_get_error_ptr(png);
    snprintf(ctx->last_warning, sizeof ctx->last_warning, "%s", msg);
}

/* ---- reading ---------------------------------------------------------------- */

/* Like libpng's default reader, but tells a truncated file from a failed read. */
static void read_data(png_structp png, png_bytep data, size_t n)
{
    FILE *fp = png_get_io_ptr(png);
    if (fread(data, 1, n, fp) != n)
        png_error(png, ferror(fp) ? "read failed" : "file is truncated");
}

typedef struct png_reader {
    png_ctx ctx;
    FILE *fp;
    png_structp png;
    png_infop info;
    unsigned char *pixels; /* height rows of rowbytes each, as libpng delivers them */
    png_bytep *rows;
    png_uint_32 width, height;
    size_t rowbytes;
    int channels, bit_depth; /* after the transformations: 1-4 channels, 8 or 16 bits */
} png_reader;

/* Runs libpng over the whole file into r->pixels. */
static ps_status read_body(png_reader *r)
{
    if (setjmp(png_jmpbuf(r->png)))
        return PS_ERR_FORMAT; /* on_error has set the message */
    png_set_read_fn(r->png, r->fp, read_data);
    png_set_sig_bytes(r->png, PNG_SIG_BYTES);
    /* Refuse absurd headers before libpng allocates anything for them, and
     * treat any CRC error, even in an ancillary chunk, as a corrupt file. */
    png_set_user_limits(r->png, PS_IMAGE_MAX_SIDE, PS_IMAGE_MAX_SIDE);
    png_set_crc_action(r->png, PNG_CRC_ERROR_QUIT, PNG_CRC_ERROR_QUIT);
    png_read_info(r->png, r->info);

    png_uint_32 w = png_get_image_width(r->png, r->info), h = png_get_image_height(r->png, r->info);
    ps_error sub;
    ps_status st = ps_image_check_size(w, h, &sub);
    if (st != PS_OK)
        return ps_error_set(r->ctx.err, st, "%s: %s", r->ctx.path, sub.msg);

    /* Everything to 8- or 16-bit gray, gray+alpha, RGB or RGBA; alpha is then
     * ignored when converting. No gamma transformation: values stay encoded. */
    int color = png_get_color_type(r->png, r->info);
    if (color == PNG_COLOR_TYPE_PALETTE)
        png_set_palette_to_rgb(r->png);
    if (color == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(r->png, r->info) < 8)
        png_set_expand_gray_1_2_4_to_8(r->png);
    png_set_strip_alpha(r->png);
    (void)png_set_interlace_handling(r->png);
    png_read_update_info(r->png, r->info);
    r->channels = png_get_channels(r->png, r->info);
    r->bit_depth = png_get_bit_depth(r->png, r->info);
    r->rowbytes = png_get_rowbytes(r->png, r->info);
    if (r->channels < 1 || r->channels > 4 || (r->bit_depth != 8 && r->bit_depth != 16) ||
        r->rowbytes < (size_t)w * (size_t)r->channels * (size_t)(r->bit_depth / 8))
        return ps_error_set(r->ctx.err, PS_ERR_FORMAT, "%s: unsupported PNG pixel layout", r->ctx.path);

    /* The whole image at once: interlaced files fill each row over 7 passes. */
    if (r->rowbytes > SIZE_MAX / h)
        return ps_error_set(r->ctx.err, PS_ERR_LIMIT, "%s: image too large for this machine", r->ctx.path);
    r->pixels = malloc(r->rowbytes * h);
    r->rows = malloc(sizeof *r->rows * h);
    if (!r->pixels || !r->rows)
        return ps_error_set(r->ctx.err, PS_ERR_NOMEM, "%s: out of memory", r->ctx.path);
    for (png_uint_32 y = 0; y < h; y++)
        r->rows[y] = r->pixels + (size_t)y * r->rowbytes;
    png_read_image(r->png, r->rows);
    /* Reads up to IEND, so a file cut after its pixel data is refused too. */
    png_read_end(r->png, NULL);
    r->width = w;
    r->height = h;
    return PS_OK;
}

/* Converts libpng's rows to floats in [0,1]: gray replicated, alpha dropped. */
static void convert(const png_reader *r, ps_image *img)
{
    for (png_uint_32 y = 0; y < r->height; y++) {
        const unsigned char *src = r->rows[y];
        float *dst = ps_image_at(img, 0, (int)y);
        for (png_uint_32 x = 0; x < r->width; x++, dst += 3) {
            float v[4] = {0, 0, 0, 0};
            for (int c = 0; c < r->channels; c++) {
                if (r->bit_depth == 16) {
                    /* PNG stores 16-bit samples big-endian. */
                    const unsigned char *s = src + ((size_t)x * (size_t)r->channels + (size_t)c) * 2;
                    v[c] = (float)((unsigned)s[0] << 8 | s[1]) / MAX_CODE_16;
                } else {
                    v[c] = (float)src[(size_t)x * (size_t)r->channels + (size_t)c] / MAX_CODE_8;
                }
            }
            bool gray = r->channels < 3;
            dst[0] = v[0];
            dst[1] = gray ? v[0] : v[1];
            dst[2] = gray ? v[0] : v[2];
        }
    }
}

ps_status ps_png_read(const char *path, ps_image *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    ps_status st = PS_OK;
    png_reader r;
    memset(&r, 0, sizeof r);
    r.ctx.path = path;
    r.ctx.doing = "invalid PNG";
    r.ctx.err = err;
    r.fp = ps_open_input(path, err);
    if (!r.fp)
        return err ? err->status : PS_ERR_IO;

    unsigned char sig[PNG_SIG_BYTES];
    size_t got = fread(sig, 1, sizeof sig, r.fp);
    if (ferror(r.fp)) {
        st = ps_error_set(err, PS_ERR_IO, "%s: read failed", path);
    } else if (got == 0) {
        st = ps_error_set(err, PS_ERR_FORMAT, "%s: empty file, not a PNG", path);
    } else if (got != sizeof sig || png_sig_cmp(sig, 0, sizeof sig) != 0) {
        st = ps_error_set(err, PS_ERR_FORMAT, "%s: not a PNG file", path);
    } else {
        r.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r.ctx, on_error, on_warning);
        if (r.png)
            r.info = png_create_info_struct(r.png);
        if (!r.png || !r.info)
            st = ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
        else
            st = read_body(&r);
    }
    if (st == PS_OK) {
        ps_error sub;
        st = ps_image_create((int)r.width, (int)r.height, out, &sub);
        if (st == PS_OK)
            convert(&r, out);
        else
            ps_error_set(err, st, "%s: %s", path, sub.msg);
    }
    if (r.png)
        png_destroy_read_struct(&r.png, r.info ? &r.info : NULL, NULL);
    free(r.rows);
    free(r.pixels);
    fclose(r.fp);
    return st;
}

/* ---- writing ---------------------------------------------------------------- */

typedef struct png_writer {
    png_ctx ctx;
    const ps_image *img;
    float exposure;
    FILE *fp;
    png_structp png;
    png_infop info;
    png_bytep row; /* one row of 8-bit RGB */
} png_writer;

static ps_status write_body(png_writer *w)
{
    if (setjmp(png_jmpbuf(w->png)))
        return PS_ERR_IO; /* on_error has set the message; fix its status below */
    png_init_io(w->png, w->fp);
    const ps_image *img = w->img;
    png_set_IHDR(w->png, w->info, (png_uint_32)img->width, (png_uint_32)img->height, WRITE_BIT_DEPTH,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    /* The sRGB chunk (plus the gAMA and cHRM that older readers use instead)
     * says the codes are sRGB-encoded, which they are. */
    png_set_sRGB_gAMA_and_cHRM(w->png, w->info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(w->png, w->info);
    for (int y = 0; y < img->height; y++) {
        const float *src = ps_image_at(img, 0, y);
        for (size_t i = 0; i < (size_t)img->width * 3; i++)
            w->row[i] = ps_tonemap_8bit(src[i], w->exposure);
        png_write_row(w->png, w->row);
    }
    png_write_end(w->png, NULL);
    return PS_OK;
}

ps_status ps_png_write(const ps_image *img, const char *path, float exposure, ps_error *err)
{
    if (!img || !img->rgb || ps_image_check_size(img->width, img->height, NULL) != PS_OK)
        return ps_error_set(err, PS_ERR_RANGE, "%s: no valid image to write", path);
    png_writer w;
    memset(&w, 0, sizeof w);
    w.ctx.path = path;
    w.ctx.doing = "cannot write PNG";
    w.ctx.err = err;
    w.img = img;
    w.exposure = exposure;
    w.row = malloc((size_t)img->width * 3);
    if (!w.row)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    ps_outfile *f = ps_outfile_open(path, err);
    if (!f) {
        free(w.row);
        return err ? err->status : PS_ERR_IO;
    }
    w.fp = ps_outfile_stream(f);
    ps_status st;
    w.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &w.ctx, on_error, on_warning);
    if (w.png)
        w.info = png_create_info_struct(w.png);
    if (!w.png || !w.info) {
        st = ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    } else {
        st = write_body(&w);
        /* A libpng failure while writing is a failed write: an I/O error. */
        if (st != PS_OK && err)
            err->status = st;
    }
    if (w.png)
        png_destroy_write_struct(&w.png, w.info ? &w.info : NULL);
    free(w.row);
    if (st != PS_OK) {
        ps_outfile_abort(f);
        return st;
    }
    return ps_outfile_commit(f, err);
}
