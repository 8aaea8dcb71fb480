/* fuzz_pfm.c: libFuzzer entry point for the pfm target (body in targets.c). */
#include "fuzz_targets.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ps_error err;
    (void)ps_fuzz_pfm(data, size, &err);
    return 0;
}
