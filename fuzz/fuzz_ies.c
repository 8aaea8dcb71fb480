/* fuzz_ies.c: libFuzzer entry point for the LM-63 target (body in targets.c). */
#include "fuzz_targets.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ps_error err;
    (void)ps_fuzz_ies(data, size, "fuzz.ies", &err);
    return 0;
}
