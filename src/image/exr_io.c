/* exr_io.c: OpenEXR files through OpenEXR's C API (OpenEXRCore, Debian's
 * libopenexr-dev): scanline parts, ZIP-compressed, half or float channels.
 * Written through ps_outfile (a custom write function into its temporary
 * file), so a failed write leaves nothing under the name, like every output. */
#include "image/exr_io.h"

#include <OpenEXR/openexr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include "core/fileio.h"

/* The library reports through this; the status it returns is what we use. */
static void quiet(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    (void)code;
    (void)msg;
}

static int64_t write_at(exr_const_context_t ctxt, void *user, const void *buffer, uint64_t size, uint64_t offset,
                        exr_stream_error_func_ptr_t error_cb)
{
    (void)ctxt;
    (void)error_cb;
    FILE *fp = user;
    if (fseeko(fp, (off_t)offset, SEEK_SET) != 0 || fwrite(buffer, 1, size, fp) != size)
        return -1;
    return (int64_t)size;
}

/* nchan channels of rows*width floats, interleaved with stride `stride`
 * floats per pixel: names[c] at offset c. */
static ps_status write_exr(const float *data, int width, int height, int stride, int nchan, const char *const *names,
                           ps_exr_type type, const char *path, ps_error *err)
{
    ps_outfile *f = ps_outfile_open(path, err);
    if (!f)
        return err ? err->status : PS_ERR_IO;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = quiet;
    init.user_data = ps_outfile_stream(f);
    init.write_fn = write_at;
    exr_context_t ctx = NULL;
    int part = 0;
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_add_part(ctx, "image", EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, width, height, EXR_COMPRESSION_ZIP);
    exr_pixel_type_t ptype = type == PS_EXR_HALF ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;
    for (int c = 0; c < nchan && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctx, part, names[c], ptype, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctx);
    int32_t lines = 1;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    exr_encode_pipeline_t enc;
    memset(&enc, 0, sizeof enc);
    bool started = false;
    for (int y = 0; y < height && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t cinfo;
        rv = exr_write_scanline_chunk_info(ctx, part, y, &cinfo);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_encoding_update(ctx, part, &cinfo, &enc) : exr_encoding_initialize(ctx, part, &cinfo, &enc);
        if (rv != EXR_ERR_SUCCESS)
            break;
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int k = 0;
            while (k < nchan && strcmp(names[k], ch->channel_name) != 0)
                k++;
            ch->encode_from_ptr = (const uint8_t *)(data + ((size_t)cinfo.start_y * (size_t)width * (size_t)stride + (size_t)k));
            ch->user_pixel_stride = stride * (int32_t)sizeof(float);
            ch->user_line_stride = width * stride * (int32_t)sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = sizeof(float);
        }
        if (!started) {
            rv = exr_encoding_choose_default_routines(ctx, part, &enc);
            started = true;
        }
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(ctx, part, &enc);
    }
    if (started)
        exr_encoding_destroy(ctx, &enc);
    exr_result_t fin = ctx ? exr_finish(&ctx) : EXR_ERR_SUCCESS;
    if (rv == EXR_ERR_SUCCESS)
        rv = fin;
    if (rv != EXR_ERR_SUCCESS) {
        ps_outfile_abort(f);
        return ps_error_set(err, PS_ERR_IO, "%s: writing OpenEXR failed: %s", path, exr_get_error_code_as_string(rv));
    }
    return ps_outfile_commit(f, err);
}

ps_status ps_exr_write(const ps_image *img, const char *path, ps_exr_type type, ps_error *err)
{
    if (!img || !img->rgb || ps_image_check_size(img->width, img->height, NULL) != PS_OK)
        return ps_error_set(err, PS_ERR_RANGE, "%s: no valid image to write", path);
    static const char *const names[3] = {"R", "G", "B"};
    return write_exr(img->rgb, img->width, img->height, 3, 3, names, type, path, err);
}

ps_status ps_exr_write_gray(const float *values, int width, int height, ps_exr_type type, const char *path,
                            ps_error *err)
{
    if (!values || ps_image_check_size(width, height, NULL) != PS_OK)
        return ps_error_set(err, PS_ERR_RANGE, "%s: no valid image to write", path);
    static const char *const names[1] = {"Y"};
    return write_exr(values, width, height, 1, 1, names, type, path, err);
}

ps_status ps_exr_read(const char *path, ps_image *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    ps_status st = ps_check_input_file(path, err);
    if (st != PS_OK)
        return st;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = quiet;
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    exr_attr_box2i_t dw;
    exr_storage_t storage = EXR_STORAGE_SCANLINE;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_storage(ctx, 0, &storage);
    if (rv == EXR_ERR_SUCCESS && storage != EXR_STORAGE_SCANLINE) {
        exr_finish(&ctx);
        return ps_error_set(err, PS_ERR_FORMAT, "%s: only scanline OpenEXR files are read", path);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_data_window(ctx, 0, &dw);
    int64_t w = 0, h = 0;
    if (rv == EXR_ERR_SUCCESS) {
        w = (int64_t)dw.max.x - dw.min.x + 1;
        h = (int64_t)dw.max.y - dw.min.y + 1;
        /* The data window is the file's word: check it before allocating
         * (found by fuzzing: a window of 134217978 x 20). */
        ps_error sub;
        st = ps_image_check_size(w, h, &sub);
        if (st == PS_OK)
            st = ps_image_create((int)w, (int)h, out, &sub);
        if (st != PS_OK) {
            exr_finish(&ctx);
            return ps_error_set(err, st, "%s: %s", path, sub.msg);
        }
    }
    int32_t lines = 1;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
    exr_decode_pipeline_t dec;
    memset(&dec, 0, sizeof dec);
    bool started = false;
    for (int64_t y = dw.min.y; rv == EXR_ERR_SUCCESS && y <= dw.max.y; y += lines) {
        exr_chunk_info_t cinfo;
        rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &cinfo);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_decoding_update(ctx, 0, &cinfo, &dec) : exr_decoding_initialize(ctx, 0, &cinfo, &dec);
        if (rv != EXR_ERR_SUCCESS)
            break;
        bool gray = false;
        for (int c = 0; c < dec.channel_count; c++)
            gray |= !strcmp(dec.channels[c].channel_name, "Y");
        for (int c = 0; c < dec.channel_count; c++) {
            exr_coding_channel_info_t *ch = &dec.channels[c];
            const char *n = ch->channel_name;
            int k = !strcmp(n, "R") ? 0 : !strcmp(n, "G") ? 1 : !strcmp(n, "B") ? 2 : !strcmp(n, "Y") ? 0 : -1;
            if (k < 0 || (gray && strcmp(n, "Y"))) {
                ch->decode_to_ptr = NULL; /* skipped */
                continue;
            }
            ch->decode_to_ptr = (uint8_t *)ps_image_at(out, 0, (int)(cinfo.start_y - dw.min.y)) + k * sizeof(float);
            ch->user_pixel_stride = 3 * (int32_t)sizeof(float);
            ch->user_line_stride = (int32_t)w * 3 * (int32_t)sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = sizeof(float);
        }
        if (!started) {
            rv = exr_decoding_choose_default_routines(ctx, 0, &dec);
            started = true;
        }
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_decoding_run(ctx, 0, &dec);
        if (rv == EXR_ERR_SUCCESS && gray)
            for (int yy = 0; yy < cinfo.height; yy++)
                for (int64_t x = 0; x < w; x++) {
                    float *p = ps_image_at(out, (int)x, (int)(cinfo.start_y - dw.min.y + yy));
                    p[1] = p[2] = p[0];
                }
    }
    if (started)
        exr_decoding_destroy(ctx, &dec);
    if (ctx)
        exr_finish(&ctx);
    if (rv != EXR_ERR_SUCCESS) {
        ps_image_destroy(out);
        return ps_error_set(err, PS_ERR_FORMAT, "%s: not a readable OpenEXR file: %s", path,
                            exr_get_error_code_as_string(rv));
    }
    return PS_OK;
}

bool ps_path_is_exr(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && (!strcmp(path + n - 4, ".exr") || !strcmp(path + n - 4, ".EXR"));
}

ps_status ps_hdr_write(const ps_image *img, const char *path, ps_error *err)
{
    return ps_path_is_exr(path) ? ps_exr_write(img, path, PS_EXR_FLOAT, err) : ps_pfm_write(img, path, err);
}

ps_status ps_gray_write(const float *values, int width, int height, const char *path, ps_error *err)
{
    return ps_path_is_exr(path) ? ps_exr_write_gray(values, width, height, PS_EXR_FLOAT, path, err)
                                : ps_pfm_write_gray(values, width, height, path, err);
}
