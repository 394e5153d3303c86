/* Fuzz target: a scan directory's per-view metadata (view_NNN/view.ini), read by scanner
 * process and colour-eval. */
#define _GNU_SOURCE
#include "fuzz_input.h"

#include "config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    long angle_mdeg = 12345;
    int rc = view_angle_load(fuzz_path(data, size), &angle_mdeg);
    FUZZ_EXPECT(rc <= 0);
    return 0;
}
