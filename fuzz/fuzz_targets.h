/* fuzz_targets.h: the bodies of the fuzz targets, shared by the libFuzzer
 * programs (fuzz/fuzz_*.c, clang) and the replay test (tests/test_fuzz_replay.c,
 * gcc), so a saved finding replays through exactly the code that found it.
 *
 * Each body feeds bytes to one reader and checks what the readers promise:
 * an error is one non-empty line naming the input, a success holds only
 * in-range, finite data. A broken promise is reported on stderr and abort()s,
 * which libFuzzer records as a finding and a test as a crash. */
#ifndef PS_FUZZ_TARGETS_H
#define PS_FUZZ_TARGETS_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"

/* Splits the OBJ target's input: the OBJ text comes before the first line
 * that is exactly this (an OBJ comment, so an unsplit input is still an OBJ),
 * the MTL text after it. */
#define PS_FUZZ_MTL_SEPARATOR "#--mtl--\n"

/* The scene parser on data as the text of a .scn file called `name`, meshes
 * resolved against base_dir. Text with a NUL byte goes through a temporary
 * file and ps_scene_load (the in-memory entry point stops at a NUL). */
ps_status ps_fuzz_scene(const uint8_t *data, size_t size, const char *name, const char *base_dir, ps_error *err);

/* A fixed scene whose one mesh is data's OBJ part, with data's MTL part as
 * the m.mtl beside it, both in a fresh temporary directory. */
ps_status ps_fuzz_obj(const uint8_t *data, size_t size, ps_error *err);

/* ps_png_read on data as a file. Chunk CRCs are recomputed first (when the
 * chunk structure allows) so mutations reach past libpng's CRC check. */
ps_status ps_fuzz_png(const uint8_t *data, size_t size, ps_error *err);

/* ps_pfm_read on data as a file. */
ps_status ps_fuzz_pfm(const uint8_t *data, size_t size, ps_error *err);

/* ps_exr_read (OpenEXR's C API) on data as a file. */
ps_status ps_fuzz_exr(const uint8_t *data, size_t size, ps_error *err);

/* ps_ies_parse on data as an LM-63 file called `name`; a table it accepts
 * must give finite, non-negative candela no larger than its peak in every
 * direction, a positive finite flux, and samples inside the sphere whose
 * density is the candela over the flux. */
ps_status ps_fuzz_ies(const uint8_t *data, size_t size, const char *name, ps_error *err);

#endif
