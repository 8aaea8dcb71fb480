/* pfm_io.c: Portable Float Map files (linear HDR images), read and written byte by byte. */
#include "image/image.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/fileio.h"
#include "core/number.h"

/* Samples are IEEE-754 binary32; the byte order is written and read explicitly
 * (never by casting the buffer), so the code is the same on any host. */
_Static_assert(sizeof(float) == 4 && sizeof(uint32_t) == 4, "PFM needs 32-bit floats");
#define SAMPLE_BYTES 4

/* The scale we write: negative means little-endian; its magnitude 1 means the
 * values are the radiance itself. */
#define PFM_WRITE_SCALE "-1.0"

/* A header token (magic, width, height, scale) longer than this is not a
 * number any writer produces. */
#define TOKEN_MAX 64

static bool is_space(int c)
{
    /* The PFM header separates its tokens with any white space, as PPM does. */
    return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}

static void put_le32(unsigned char *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    p[0] = (unsigned char)(u & 0xff);
    p[1] = (unsigned char)((u >> 8) & 0xff);
    p[2] = (unsigned char)((u >> 16) & 0xff);
    p[3] = (unsigned char)(u >> 24);
}

static float get32(const unsigned char *p, bool big_endian)
{
    uint32_t u = big_endian ? (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]
                            : (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0];
    float v;
    memcpy(&v, &u, sizeof v);
    return v;
}

ps_status ps_pfm_write(const ps_image *img, const char *path, ps_error *err)
{
    if (!img || !img->rgb || ps_image_check_size(img->width, img->height, NULL) != PS_OK)
        return ps_error_set(err, PS_ERR_RANGE, "%s: no valid image to write", path);
    size_t row_bytes = (size_t)img->width * 3 * SAMPLE_BYTES;
    unsigned char *row = malloc(row_bytes);
    if (!row)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    ps_outfile *f = ps_outfile_open(path, err);
    if (!f) {
        free(row);
        return err ? err->status : PS_ERR_IO;
    }
    FILE *fp = ps_outfile_stream(f);
    fprintf(fp, "PF\n%d %d\n" PFM_WRITE_SCALE "\n", img->width, img->height);
    /* PFM stores the bottom row first. */
    for (int y = img->height - 1; y >= 0; y--) {
        const float *src = ps_image_at(img, 0, y);
        for (size_t i = 0; i < (size_t)img->width * 3; i++)
            put_le32(row + i * SAMPLE_BYTES, src[i]);
        if (fwrite(row, 1, row_bytes, fp) != row_bytes)
            break; /* the stream's error flag is set; commit reports it */
    }
    free(row);
    return ps_outfile_commit(f, err);
}

ps_status ps_pfm_write_gray(const float *values, int width, int height, const char *path, ps_error *err)
{
    if (!values || ps_image_check_size(width, height, NULL) != PS_OK)
        return ps_error_set(err, PS_ERR_RANGE, "%s: no valid image to write", path);
    size_t row_bytes = (size_t)width * SAMPLE_BYTES;
    unsigned char *row = malloc(row_bytes);
    if (!row)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    ps_outfile *f = ps_outfile_open(path, err);
    if (!f) {
        free(row);
        return err ? err->status : PS_ERR_IO;
    }
    FILE *fp = ps_outfile_stream(f);
    fprintf(fp, "Pf\n%d %d\n" PFM_WRITE_SCALE "\n", width, height);
    for (int y = height - 1; y >= 0; y--) {
        const float *src = values + (size_t)y * (size_t)width;
        for (size_t i = 0; i < (size_t)width; i++)
            put_le32(row + i * SAMPLE_BYTES, src[i]);
        if (fwrite(row, 1, row_bytes, fp) != row_bytes)
            break;
    }
    free(row);
    return ps_outfile_commit(f, err);
}

/* Reads one white-space separated header token (`what` names it in messages).
 * The white space character that ends it is consumed: after the scale that is
 * the single separator before the binary data (if the file ends right after the
 * scale there is no data, which the size check reports). */
static ps_status read_token(FILE *fp, const char *path, const char *what, bool skip_leading, char tok[TOKEN_MAX + 1],
                            ps_error *err)
{
    int c = getc(fp);
    if (skip_leading)
        while (c != EOF && is_space(c))
            c = getc(fp);
    size_t n = 0;
    while (c != EOF && !is_space(c)) {
        if (n == TOKEN_MAX)
            return ps_error_set(err, PS_ERR_FORMAT, "%s: PFM %s is longer than %d characters", path, what, TOKEN_MAX);
        tok[n++] = (char)c;
        c = getc(fp);
    }
    tok[n] = '\0';
    if (ferror(fp))
        return ps_error_set(err, PS_ERR_IO, "%s: read failed", path);
    if (n == 0)
        return ps_error_set(err, PS_ERR_FORMAT, "%s: PFM header ends before the %s", path, what);
    return PS_OK;
}

/* Everything the header says. */
typedef struct pfm_header {
    int64_t width, height;
    int channels;
    bool big_endian;
} pfm_header;

static ps_status read_header(FILE *fp, const char *path, pfm_header *h, ps_error *err)
{
    char tok[TOKEN_MAX + 1];
    /* The magic is the first two bytes, with nothing before it. */
    int c0 = getc(fp), c1 = getc(fp), c2 = getc(fp);
    if (c0 != 'P' || (c1 != 'F' && c1 != 'f') || c2 == EOF || !is_space(c2))
        return ps_error_set(err, PS_ERR_FORMAT, "%s: not a PFM file (expected 'PF' or 'Pf' at the start)", path);
    h->channels = c1 == 'F' ? 3 : 1;
    static const char *const names[2] = {"width", "height"};
    int64_t *sides[2] = {&h->width, &h->height};
    ps_status st;
    for (int k = 0; k < 2; k++) {
        if ((st = read_token(fp, path, names[k], true, tok, err)) != PS_OK)
            return st;
        if (!ps_parse_int64(tok, sides[k]))
            return ps_error_set(err, PS_ERR_FORMAT, "%s: PFM %s '%s' is not an integer", path, names[k], tok);
        if (*sides[k] < 1)
            return ps_error_set(err, PS_ERR_FORMAT, "%s: PFM %s %s must be at least 1", path, names[k], tok);
    }
    if ((st = read_token(fp, path, "scale", true, tok, err)) != PS_OK)
        return st;
    double scale;
    if (!ps_parse_double(tok, &scale))
        return ps_error_set(err, PS_ERR_FORMAT, "%s: PFM scale '%s' is not a finite number", path, tok);
    if (scale == 0.0)
        return ps_error_set(err, PS_ERR_FORMAT, "%s: PFM scale is 0 (its sign must give the byte order)", path);
    h->big_endian = scale > 0.0;
    return PS_OK;
}

/* Reads the pixel rows (bottom row first in the file) into img. */
static ps_status read_pixels(FILE *fp, const char *path, const pfm_header *h, ps_image *img, ps_error *err)
{
    size_t row_bytes = (size_t)h->width * (size_t)h->channels * SAMPLE_BYTES;
    unsigned char *row = malloc(row_bytes);
    if (!row)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    for (int y = img->height - 1; y >= 0; y--) {
        if (fread(row, 1, row_bytes, fp) != row_bytes) {
            free(row);
            /* The size was checked against the header: only a file that
             * shrank meanwhile, or a read error, gets here. */
            return ps_error_set(err, ferror(fp) ? PS_ERR_IO : PS_ERR_FORMAT, "%s: %s", path,
                                ferror(fp) ? "read failed" : "truncated pixel data");
        }
        float *dst = ps_image_at(img, 0, y);
        for (int x = 0; x < img->width; x++, dst += 3) {
            if (h->channels == 3) {
                for (int c = 0; c < 3; c++)
                    dst[c] = get32(row + ((size_t)x * 3 + (size_t)c) * SAMPLE_BYTES, h->big_endian);
            } else {
                float v = get32(row + (size_t)x * SAMPLE_BYTES, h->big_endian);
                dst[0] = dst[1] = dst[2] = v;
            }
        }
    }
    free(row);
    return PS_OK;
}

ps_status ps_pfm_read(const char *path, ps_image *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    FILE *fp = ps_open_input(path, err);
    if (!fp)
        return err ? err->status : PS_ERR_IO;
    ps_status st;
    pfm_header h;
    ps_error sub;
    ps_error_clear(&sub);
    st = read_header(fp, path, &h, err);
    if (st != PS_OK)
        goto done;
    if ((st = ps_image_check_size(h.width, h.height, &sub)) != PS_OK) {
        ps_error_set(err, st, "%s: %s", path, sub.msg);
        goto done;
    }
    /* Compare the data with what the header promises before allocating, so a
     * lying header costs nothing. Sizes are at most 2^28·3·4 bytes here. */
    struct stat sb;
    long header_len = ftell(fp);
    if (fstat(fileno(fp), &sb) != 0 || header_len < 0) {
        st = ps_error_set(err, PS_ERR_IO, "%s: cannot determine the file size: %s", path, strerror(errno));
        goto done;
    }
    uint64_t expect = (uint64_t)h.width * (uint64_t)h.height * (uint64_t)h.channels * SAMPLE_BYTES;
    uint64_t have = sb.st_size > header_len ? (uint64_t)sb.st_size - (uint64_t)header_len : 0;
    if (have < expect) {
        st = ps_error_set(err, PS_ERR_FORMAT,
                          "%s: truncated: %llu bytes of pixel data, the %lldx%lld header needs %llu", path,
                          (unsigned long long)have, (long long)h.width, (long long)h.height,
                          (unsigned long long)expect);
        goto done;
    }
    if (have > expect) {
        st = ps_error_set(err, PS_ERR_FORMAT, "%s: %llu byte%s of unexpected data after the %lldx%lld pixels", path,
                          (unsigned long long)(have - expect), have - expect == 1 ? "" : "s", (long long)h.width,
                          (long long)h.height);
        goto done;
    }
    if ((st = ps_image_create((int)h.width, (int)h.height, out, &sub)) != PS_OK) {
        ps_error_set(err, st, "%s: %s", path, sub.msg);
        goto done;
    }
    st = read_pixels(fp, path, &h, out, err);
done:
    fclose(fp);
    if (st != PS_OK)
        ps_image_destroy(out);
    return st;
}
