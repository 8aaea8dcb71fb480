/* fuzz_scene.c: libFuzzer entry point for the scene target (body in targets.c). */
#include "fuzz_targets.h"

/* Relative to the repository root, where scripts/fuzz.sh runs the target: the
 * malformed-input seeds name meshes as ../good/NAME.obj from there. */
#define PS_FUZZ_SCENE_BASE_DIR "tests/data/bad"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ps_error err;
    (void)ps_fuzz_scene(data, size, "fuzz.scn", PS_FUZZ_SCENE_BASE_DIR, &err);
    return 0;
}
