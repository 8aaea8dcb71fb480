/* fuzz_exr.c: libFuzzer entry point for the OpenEXR target (body in targets.c). */
#include "fuzz_targets.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ps_error err;
    (void)ps_fuzz_exr(data, size, &err);
    return 0;
}
