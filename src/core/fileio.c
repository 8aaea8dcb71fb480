/* fileio.c: atomic output files and input file checks. */
/* realpath(3) is X/Open, not base POSIX. */
#define _XOPEN_SOURCE 700
#include "core/fileio.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

struct ps_outfile {
    FILE *fp;
    char *path;   /* as given, for messages */
    char *target; /* the file renamed over (path with links resolved); NULL when writing straight to a device */
    char *tmp;
};

/* A device or FIFO for writing. A FIFO without a reader would block open(2)
 * for ever; O_NONBLOCK makes that fail at once (ENXIO), then writes block as
 * usual. */
static FILE *open_special(const char *path)
{
    int fd = open(path, O_WRONLY | O_NONBLOCK);
    if (fd < 0)
        return NULL;
    int flags = fcntl(fd, F_GETFL);
    FILE *fp = flags >= 0 && fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == 0 ? fdopen(fd, "wb") : NULL;
    if (!fp) {
        int saved = errno;
        close(fd);
        errno = saved;
    }
    return fp;
}

ps_status ps_check_output_path(const char *path, ps_error *err)
{
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode))
        return PS_OK; /* a device or pipe: opened when written */
    ps_outfile *f = ps_outfile_open(path, err);
    if (!f)
        return err ? err->status : PS_ERR_IO;
    ps_outfile_abort(f);
    return PS_OK;
}

ps_outfile *ps_outfile_open(const char *path, ps_error *err)
{
    static const char suffix[] = ".tmp.XXXXXX";
    struct stat st, lst;
    bool exists = stat(path, &st) == 0;
    if (exists && S_ISDIR(st.st_mode)) {
        ps_error_set(err, PS_ERR_IO, "%s: is a directory, cannot write a file there", path);
        return NULL;
    }
    ps_outfile *f = calloc(1, sizeof *f);
    if (!f) {
        ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
        return NULL;
    }
    if (exists && !S_ISREG(st.st_mode)) {
        /* A device, FIFO or terminal (/dev/stdout, a pipe): write straight to
         * it. Renaming a file over it would replace the device node itself. */
        f->path = strdup(path);
        f->fp = f->path ? open_special(path) : NULL;
        if (!f->fp) {
            ps_error_set(err, PS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
            ps_outfile_abort(f);
            return NULL;
        }
        return f;
    }
    /* Through a symbolic link, replace the file it names, not the link. */
    char *target = exists && lstat(path, &lst) == 0 && S_ISLNK(lst.st_mode) ? realpath(path, NULL) : strdup(path);
    size_t n = target ? strlen(target) : 0;
    if (!target || !(f->path = strdup(path)) || !(f->tmp = malloc(n + sizeof suffix))) {
        free(target);
        ps_outfile_abort(f);
        ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
        return NULL;
    }
    f->target = target;
    memcpy(f->tmp, target, n);
    memcpy(f->tmp + n, suffix, sizeof suffix);
    int fd = mkstemp(f->tmp);
    if (fd < 0) {
        ps_error_set(err, PS_ERR_IO, "%s: cannot create: %s", path, strerror(errno));
        free(f->tmp);
        f->tmp = NULL;
        ps_outfile_abort(f);
        return NULL;
    }
    /* mkstemp creates 0600; give the result the permissions a plain fopen would. */
    mode_t mask = umask(0);
    umask(mask);
    (void)fchmod(fd, 0666 & ~mask);
    f->fp = fdopen(fd, "wb");
    if (!f->fp) {
        close(fd);
        ps_error_set(err, PS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
        ps_outfile_abort(f);
        return NULL;
    }
    return f;
}

FILE *ps_outfile_stream(ps_outfile *f) { return f->fp; }

ps_status ps_outfile_commit(ps_outfile *f, ps_error *err)
{
    int failed = ferror(f->fp) != 0;
    failed |= fflush(f->fp) != 0;
    int saved = errno;
    failed |= fclose(f->fp) != 0;
    f->fp = NULL;
    if (failed) {
        ps_error_set(err, PS_ERR_IO, "%s: write failed: %s", f->path, strerror(saved ? saved : errno));
        ps_outfile_abort(f);
        return PS_ERR_IO;
    }
    if (!f->tmp) { /* written straight to a device or pipe */
        ps_outfile_abort(f);
        return PS_OK;
    }
    if (rename(f->tmp, f->target) != 0) {
        ps_error_set(err, PS_ERR_IO, "%s: cannot rename into place: %s", f->path, strerror(errno));
        ps_outfile_abort(f);
        return PS_ERR_IO;
    }
    free(f->tmp);
    f->tmp = NULL; /* renamed: nothing left to remove */
    ps_outfile_abort(f);
    return PS_OK;
}

void ps_outfile_abort(ps_outfile *f)
{
    if (!f)
        return;
    if (f->fp)
        fclose(f->fp);
    if (f->tmp) {
        remove(f->tmp);
        free(f->tmp);
    }
    free(f->target);
    free(f->path);
    free(f);
}

ps_status ps_check_input_file(const char *path, ps_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return ps_error_set(err, PS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode))
        return ps_error_set(err, PS_ERR_IO, "%s: is a directory, not a file", path);
    if (!S_ISREG(st.st_mode))
        return ps_error_set(err, PS_ERR_IO, "%s: not a regular file", path);
    if (access(path, R_OK) != 0)
        return ps_error_set(err, PS_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    return PS_OK;
}

FILE *ps_open_input(const char *path, ps_error *err)
{
    if (ps_check_input_file(path, err) != PS_OK)
        return NULL;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        ps_error_set(err, PS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    return fp;
}

ps_status ps_read_file(const char *path, size_t max_bytes, char **out, size_t *out_len, ps_error *err)
{
    *out = NULL;
    if (out_len)
        *out_len = 0;
    FILE *fp = ps_open_input(path, err);
    if (!fp)
        return err ? err->status : PS_ERR_IO;
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    if (!buf) {
        fclose(fp);
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
    }
    for (;;) {
        if (len + 1 >= cap) {
            if (cap > max_bytes) {
                free(buf);
                fclose(fp);
                return ps_error_set(err, PS_ERR_LIMIT, "%s: file larger than %zu bytes", path, max_bytes);
            }
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                fclose(fp);
                return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", path);
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - 1 - len, fp);
        len += got;
        if (got == 0)
            break;
    }
    int bad = ferror(fp);
    fclose(fp);
    if (bad) {
        free(buf);
        return ps_error_set(err, PS_ERR_IO, "%s: read failed", path);
    }
    if (len > max_bytes) {
        free(buf);
        return ps_error_set(err, PS_ERR_LIMIT, "%s: file larger than %zu bytes", path, max_bytes);
    }
    buf[len] = '\0';
    *out = buf;
    if (out_len)
        *out_len = len;
    return PS_OK;
}

int ps_text_nul_line(const char *text, size_t len)
{
    const char *nul = memchr(text, '\0', len);
    if (!nul)
        return 0;
    int line = 1;
    for (const char *c = text; c < nul; c++)
        line += *c == '\n';
    return line;
}

ps_status ps_text_lines(const char *text, const char *name, size_t max_len, ps_line_fn fn, void *user, int *line,
                        ps_error *err)
{
    char *buf = malloc(max_len + 1);
    if (!buf)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", name);
    ps_status st = PS_OK;
    const char *at = text;
    while (st == PS_OK && *at) {
        size_t n = ps_line_length(at);
        const char *nl = at[n] ? at + n : NULL;
        (*line)++;
        if (n > max_len) {
            st = ps_error_at(err, PS_ERR_PARSE, name, *line, "line longer than %zu characters", max_len);
            break;
        }
        memcpy(buf, at, n);
        buf[n] = '\0';
        at = nl ? nl + 1 : at + n;
        st = fn(user, buf);
    }
    free(buf);
    return st;
}
