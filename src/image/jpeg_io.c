/* jpeg_io.c: JPEG reading through libjpeg(-turbo); the only file that
 * includes jpeglib.h.
 *
 * libjpeg reports errors through error_exit, which must not return: it
 * longjmps back to a setjmp in a small body function, as png_io.c does with
 * libpng, and every resource lives in a struct its caller owns and frees. */
#include "image/image.h"

#include <setjmp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jpeglib.h>

#include "core/fileio.h"

#define MAX_CODE_8 255.0f

typedef struct jpeg_ctx {
    struct jpeg_error_mgr mgr; /* first, so that cinfo->err is the whole struct */
    jmp_buf jump;
    char msg[JMSG_LENGTH_MAX];
} jpeg_ctx;

static void on_error(j_common_ptr cinfo)
{
    jpeg_ctx *ctx = (jpeg_ctx *)cinfo->err;
    (*cinfo->err->format_message)(cinfo, ctx->msg);
    longjmp(ctx->jump, 1);
}

/* Warnings (a corrupt but readable stream) are not errors: say nothing. */
static void on_message(j_common_ptr cinfo) { (void)cinfo; }

typedef struct jpeg_read_state {
    struct jpeg_decompress_struct cinfo;
    jpeg_ctx ctx;
    bool created;
    FILE *fp;
    unsigned char *row;
    ps_image img;
} jpeg_read_state;

/* 1 on success; 0 with st->ctx.msg or err set. */
static int read_body(jpeg_read_state *st, ps_error *err)
{
    if (setjmp(st->ctx.jump))
        return 0;
    jpeg_create_decompress(&st->cinfo);
    st->created = true;
    jpeg_stdio_src(&st->cinfo, st->fp);
    jpeg_read_header(&st->cinfo, TRUE);
    /* Gray and CMYK as RGB: libjpeg converts gray and YCbCr; refuse the rest. */
    if (st->cinfo.jpeg_color_space == JCS_CMYK || st->cinfo.jpeg_color_space == JCS_YCCK) {
        snprintf(st->ctx.msg, sizeof st->ctx.msg, "CMYK JPEG is not supported");
        return 0;
    }
    st->cinfo.out_color_space = JCS_RGB;
    if (ps_image_check_size(st->cinfo.image_width, st->cinfo.image_height, err) != PS_OK) {
        snprintf(st->ctx.msg, sizeof st->ctx.msg, "%.150s", err->msg);
        return 0;
    }
    jpeg_start_decompress(&st->cinfo);
    int w = (int)st->cinfo.output_width, h = (int)st->cinfo.output_height;
    if (st->cinfo.output_components != 3 || ps_image_create(w, h, &st->img, err) != PS_OK ||
        !(st->row = malloc(3 * (size_t)w))) {
        snprintf(st->ctx.msg, sizeof st->ctx.msg, "cannot decode (%d components)", st->cinfo.output_components);
        return 0;
    }
    while (st->cinfo.output_scanline < st->cinfo.output_height) {
        int y = (int)st->cinfo.output_scanline;
        JSAMPROW rows[1] = {st->row};
        jpeg_read_scanlines(&st->cinfo, rows, 1);
        float *dst = ps_image_at(&st->img, 0, y);
        for (int i = 0; i < 3 * w; i++)
            dst[i] = (float)st->row[i] / MAX_CODE_8;
    }
    jpeg_finish_decompress(&st->cinfo);
    return 1;
}

ps_status ps_jpeg_read(const char *path, ps_image *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    jpeg_read_state *st = calloc(1, sizeof *st);
    if (!st)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    if (!(st->fp = ps_open_input(path, err))) {
        free(st);
        return err->status;
    }
    st->cinfo.err = jpeg_std_error(&st->ctx.mgr);
    st->ctx.mgr.error_exit = on_error;
    st->ctx.mgr.output_message = on_message;
    ps_status status = PS_OK;
    if (!read_body(st, err))
        status = ps_error_set(err, PS_ERR_FORMAT, "%s: invalid JPEG: %s", path, st->ctx.msg);
    if (st->created)
        jpeg_destroy_decompress(&st->cinfo);
    fclose(st->fp);
    free(st->row);
    if (status == PS_OK)
        *out = st->img;
    else
        ps_image_destroy(&st->img);
    free(st);
    return status;
}
