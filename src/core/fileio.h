/* fileio.h: output files that appear whole or not at all, and input checks. */
#ifndef PS_CORE_FILEIO_H
#define PS_CORE_FILEIO_H

#include <stdio.h>

#include "core/status.h"

/* An output file under construction. Everything is written to a temporary file
 * beside the target (same directory, so the final rename is atomic); only
 * ps_outfile_commit renames it into place. An interrupted or failed run
 * therefore never leaves a truncated file under the requested name. */
typedef struct ps_outfile ps_outfile;

/* Opens a temporary file for `path`. On failure returns NULL and sets err. */
ps_outfile *ps_outfile_open(const char *path, ps_error *err);
/* The stream to write to (binary mode). */
FILE *ps_outfile_stream(ps_outfile *f);
/* Flushes, checks every write succeeded, closes and renames into place, then
 * frees f. On failure removes the temporary file, sets err and frees f. */
ps_status ps_outfile_commit(ps_outfile *f, ps_error *err);
/* Discards the temporary file and frees f (f may be NULL). */
void ps_outfile_abort(ps_outfile *f);

/* Checks, before any work, that an output file can be made at `path`: not a
 * directory, its directory exists and takes a new file (a temporary file is
 * created there and removed again). A device or FIFO passes unopened. The
 * message is the one ps_outfile_open would give. */
ps_status ps_check_output_path(const char *path, ps_error *err);

/* Checks that `path` names a readable regular file (not a directory, device or
 * FIFO, which would make a reader hang or fail obscurely). */
ps_status ps_check_input_file(const char *path, ps_error *err);

/* ps_check_input_file, then fopen(path, "rb"): a stream, or NULL with err set. */
FILE *ps_open_input(const char *path, ps_error *err);

/* Reads a whole regular file into a NUL-terminated buffer the caller frees.
 * Refuses files larger than max_bytes with PS_ERR_LIMIT. */
ps_status ps_read_file(const char *path, size_t max_bytes, char **out, size_t *out_len, ps_error *err);

/* The line (from 1) holding the first NUL byte of text[0, len), or 0 when
 * there is none: text readers refuse binary input by naming where it starts. */
int ps_text_nul_line(const char *text, size_t len);

/* The characters before the next '\n' or the text's end. A plain loop rather
 * than strchr: under ASan's strict_string_checks (as `make test` runs it)
 * strchr measures all the remaining text, so reading a long file line by
 * line became quadratic (found while fuzzing, docs/fuzzing.md). */
static inline size_t ps_line_length(const char *at)
{
    size_t n = 0;
    while (at[n] && at[n] != '\n')
        n++;
    return n;
}

/* Calls fn once for each line of the NUL-terminated text, with its number
 * (from 1, also kept in *line) and its characters copied without the newline
 * into a NUL-terminated buffer: the shape every text reader here shares. A
 * line over max_len characters is "NAME:LINE: line longer than MAX
 * characters" (PS_ERR_PARSE); the first status other than PS_OK from fn ends
 * the walk and is returned. */
typedef ps_status (*ps_line_fn)(void *user, char *text);
ps_status ps_text_lines(const char *text, const char *name, size_t max_len, ps_line_fn fn, void *user, int *line,
                        ps_error *err);

#endif
