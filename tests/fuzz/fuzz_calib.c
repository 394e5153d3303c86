/* Fuzz target: the calibration parser (camera, projector, turntable axis, light positions). */
#define _GNU_SOURCE
#include "fuzz_input.h"

#include "config.h"

#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct scan_calib calib;
    char err[512] = "";
    const char *path = fuzz_path(data, size);
    int rc = calib_load(&calib, path, 4, err, sizeof(err));
    FUZZ_EXPECT(rc == 0 || (rc < 0 && strstr(err, path) != NULL));
    return 0;
}
